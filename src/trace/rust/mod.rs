//! The pure-Rust backends: our own watertight triangle test, over the candidates of a BVH
//! ([`bvh::BvhTracer`], what `--tracer rust` runs) or over every triangle of the scene
//! ([`BruteForceTracer`]).
//!
//! Brute force (every line against every triangle) is exact and needs no acceleration structure, so it
//! serves as the reference for small scenes and for tests.

pub mod bvh;
mod collapse;
pub mod grids;
mod ploc;
pub mod watertight;

pub use bvh::BvhTracer;

use super::{HitRules, Line, RawHit, TraceError, Tracer};
use crate::scene::Scene;
use watertight::ShearedRay;

/// Tests every line against every triangle with the watertight test.
#[derive(Clone, Debug)]
pub struct BruteForceTracer {
    triangles: Vec<[[f32; 3]; 3]>,
    rules: HitRules,
}

impl BruteForceTracer {
    /// Prepares a scene's triangles.
    pub fn new(scene: &Scene) -> Self {
        BruteForceTracer {
            triangles: scene
                .triangles
                .iter()
                .map(|t| t.map(|v| scene.positions[v as usize]))
                .collect(),
            rules: HitRules::new(scene),
        }
    }
}

impl Tracer for BruteForceTracer {
    fn name(&self) -> &'static str {
        "rust-brute"
    }

    fn rules(&self) -> &HitRules {
        &self.rules
    }

    fn raw_hits(&self, lines: &[Line], out: &mut Vec<RawHit>) -> Result<(), TraceError> {
        out.clear();
        for (k, line) in lines.iter().enumerate() {
            let ray = ShearedRay::new(line.origin, line.dir);
            for (i, [a, b, c]) in self.triangles.iter().enumerate() {
                if let Some(t) = ray.intersect(*a, *b, *c, 0.0, line.t_max) {
                    out.push(RawHit {
                        t,
                        triangle: i as u32,
                        line: k as u32,
                    });
                }
            }
        }
        Ok(())
    }
}
