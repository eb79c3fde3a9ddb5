//! Independent truth for the tests: closed-form form factors (textbook formulas, e.g. Howell's catalogue,
//! C-11 and C-14), brute-force helpers and small scene writers.
#![allow(dead_code)]

use std::f64::consts::PI;

use scene_complexity::scene::Scene;
use scene_complexity::trace::rust::BruteForceTracer;
use scene_complexity::trace::{make_tracer, Backend, Query, Tracer};

/// Form factor between two identical, directly opposed parallel rectangles `a x b` at distance `c`.
pub fn ff_parallel_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (x2, y2) = (x * x, y * y);
    2.0 / (PI * x * y)
        * (((1.0 + x2) * (1.0 + y2) / (1.0 + x2 + y2)).sqrt().ln()
            + x * (1.0 + y2).sqrt() * (x / (1.0 + y2).sqrt()).atan()
            + y * (1.0 + x2).sqrt() * (y / (1.0 + x2).sqrt()).atan()
            - x * x.atan()
            - y * y.atan())
}

/// Form factor from a rectangle `w x l` to a perpendicular rectangle `h x l` sharing the edge of length `l`.
pub fn ff_perpendicular_rectangles(w: f64, h: f64, l: f64) -> f64 {
    let (ww, hh) = (w / l, h / l);
    let (w2, h2) = (ww * ww, hh * hh);
    let s = (w2 + h2).sqrt();
    let a = (1.0 + w2) * (1.0 + h2) / (1.0 + w2 + h2);
    let b = (w2 * (1.0 + w2 + h2) / ((1.0 + w2) * (w2 + h2))).powf(w2);
    let c = (h2 * (1.0 + h2 + w2) / ((1.0 + h2) * (h2 + w2))).powf(h2);
    1.0 / (PI * ww)
        * (ww * (1.0 / ww).atan() + hh * (1.0 / hh).atan() - s * (1.0 / s).atan()
            + 0.25 * (a * b * c).ln())
}

/// Every tracer this build has, for tests that must hold for all of them: the pure-Rust BVH, the
/// brute-force reference (on scenes small enough for it) and Embree when built in.
pub fn all_tracers(scene: &Scene) -> Vec<Box<dyn Tracer>> {
    let mut v =
        vec![make_tracer(Backend::Rust, scene, Query::Single)
            .expect("the Rust tracer always builds")];
    if scene.triangles.len() <= 4000 {
        v.push(Box::new(BruteForceTracer::new(scene)));
    }
    if cfg!(feature = "embree") {
        v.push(make_tracer(Backend::Embree, scene, Query::Single).expect("Embree tracer"));
    }
    v
}

/// Writes an OBJ of a room (unit cube, inward faces as quads) holding a box, scaled by `scale`.
pub fn room_with_box_obj(scale: f64) -> String {
    let mut s = String::new();
    let mut verts = Vec::new();
    let mut faces = Vec::new();
    // Room: inward normals. Box: outward normals. Quads counter-clockwise seen from the front.
    let mut add_box = |lo: [f64; 3], hi: [f64; 3], inward: bool| {
        let base = verts.len();
        for i in 0..8 {
            verts.push([
                if i & 1 == 0 { lo[0] } else { hi[0] },
                if i & 2 == 0 { lo[1] } else { hi[1] },
                if i & 4 == 0 { lo[2] } else { hi[2] },
            ]);
        }
        // Outward-facing quads of a box with corner bits (x=1, y=2, z=4).
        let quads = [
            [0, 4, 6, 2],
            [1, 3, 7, 5],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 2, 3, 1],
            [4, 5, 7, 6],
        ];
        for q in quads {
            let mut f: Vec<usize> = q.iter().map(|&k| base + k + 1).collect();
            if inward {
                f.reverse();
            }
            faces.push(f);
        }
    };
    add_box([0.0; 3], [1.0; 3], true);
    add_box([0.3, 0.2, 0.25], [0.6, 0.5, 0.7], false);
    for v in &verts {
        s.push_str(&format!(
            "v {} {} {}\n",
            v[0] * scale,
            v[1] * scale,
            v[2] * scale
        ));
    }
    for f in &faces {
        let idx: Vec<String> = f.iter().map(|i| i.to_string()).collect();
        s.push_str(&format!("f {}\n", idx.join(" ")));
    }
    s
}
