//! The picture itself: one first-hit ray per sample through a pinhole camera, traced with the run's own
//! tracer ([`Tracer::first_hits`]), each sample coloured by the patch it sees.

use rayon::prelude::*;

use super::camera::Camera;
use crate::scene::Scene;
use crate::trace::{Line, TraceError, Tracer};

/// What one sample of the picture sees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sample {
    /// Nothing (the ray leaves the scene).
    Background,
    /// A patch's front side, with `|cos|` between the patch normal and the view of its centroid (flat
    /// shading: one shade per patch).
    Front {
        /// The patch.
        patch: u32,
        /// `|cos|` of the angle the patch is seen at.
        cos: f32,
    },
    /// A patch's back side (the camera is behind it).
    Back {
        /// The patch.
        patch: u32,
        /// `|cos|` of the angle the patch is seen at.
        cos: f32,
    },
}

impl Sample {
    /// The patch seen, front or back.
    pub fn patch(&self) -> Option<u32> {
        match *self {
            Sample::Background => None,
            Sample::Front { patch, .. } | Sample::Back { patch, .. } => Some(patch),
        }
    }
}

/// The samples of a picture, row by row from the top.
#[derive(Clone, Debug)]
pub struct PatchImage {
    /// Samples per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// `width * height` samples, row-major from the top left.
    pub samples: Vec<Sample>,
}

/// Traces the picture `camera` takes of `scene`: one ray through the middle of each of `width` x
/// `height` samples (square samples; the vertical field of view spans the height).
pub fn trace_view(
    scene: &Scene,
    tracer: &dyn Tracer,
    camera: &Camera,
    width: usize,
    height: usize,
) -> Result<PatchImage, TraceError> {
    let (eye, [right, up, forward]) = camera.frame(scene);
    let half_height = (0.5 * camera.fov_degrees.to_radians()).tan();
    let pixel = 2.0 * half_height / height as f64;
    let t_max = (eye.length() + 2.0 * scene.bounding_radius()) as f32;
    // Flat shading: one shade per patch (a picture of flat colours also compresses well).
    let seen_at: Vec<f32> = (0..scene.patch_count())
        .map(|p| {
            let to_patch = (centroid(scene, p) - eye).normalize_or_zero();
            scene.patches[p].normal.dot(to_patch).abs() as f32
        })
        .collect();
    let rows: Vec<Vec<Sample>> = (0..height)
        .into_par_iter()
        .map(|y| {
            let v = half_height - (y as f64 + 0.5) * pixel;
            let dirs: Vec<_> = (0..width)
                .map(|x| {
                    let u = (x as f64 + 0.5 - 0.5 * width as f64) * pixel;
                    (forward + u * right + v * up).normalize()
                })
                .collect();
            let lines: Vec<Line> = dirs
                .iter()
                .map(|d| Line {
                    origin: eye.as_vec3().to_array(),
                    dir: d.as_vec3().to_array(),
                    t_max,
                })
                .collect();
            let mut hits = Vec::with_capacity(width);
            tracer.first_hits(&lines, &mut hits)?;
            Ok(hits
                .iter()
                .zip(&dirs)
                .map(|(h, d)| {
                    let Some(h) = h else {
                        return Sample::Background;
                    };
                    let patch = scene.triangle_patch[h.triangle as usize];
                    let cos = scene.patches[patch as usize].normal.dot(*d);
                    let c = seen_at[patch as usize];
                    if cos < 0.0 {
                        Sample::Front { patch, cos: c }
                    } else {
                        Sample::Back { patch, cos: c }
                    }
                })
                .collect())
        })
        .collect::<Result<_, TraceError>>()?;
    Ok(PatchImage {
        width,
        height,
        samples: rows.into_iter().flatten().collect(),
    })
}

/// The centroid of a patch's corners in tracing space.
fn centroid(scene: &Scene, patch: usize) -> crate::geom::Point {
    let corners: Vec<crate::geom::Point> = scene
        .polygon(&scene.patches[patch])
        .iter()
        .map(|&v| crate::geom::DVec3::from_array(scene.positions[v as usize].map(f64::from)))
        .collect();
    crate::geom::centroid(&corners)
}

/// The grey of a back side: darker than any "no data" patch and outside the colour maps.
pub const BACK_SIDE: [u8; 3] = [96, 96, 96];
/// The colour behind the scene.
pub const BACKGROUND: [u8; 3] = [255, 255, 255];

/// Shading: how much of a patch's colour a sample keeps, from the angle it is seen at. A narrow range, so
/// that the colour still reads against the colour bar, and shapes stay readable.
fn shade(cos: f32) -> f32 {
    0.72 + 0.28 * cos
}

impl PatchImage {
    /// The picture as RGB bytes (row-major, 3 per pixel) with `colour[p]` for patch `p`'s front side,
    /// shaded by the angle it is seen at; back sides grey; the outlines of patches darkened, so that the
    /// mesh shows; every `factor x factor` block of samples averaged into one pixel (anti-aliasing).
    pub fn to_rgb(&self, colour: &[[u8; 3]], factor: usize) -> (usize, usize, Vec<u8>) {
        let (w, h) = (self.width / factor, self.height / factor);
        let mut out = vec![0u8; 3 * w * h];
        let k = (factor * factor) as f32;
        for py in 0..h {
            for px in 0..w {
                let mut sum = [0f32; 3];
                for sy in 0..factor {
                    for sx in 0..factor {
                        let (x, y) = (px * factor + sx, py * factor + sy);
                        let c = self.sample_colour(x, y, colour);
                        for (s, v) in sum.iter_mut().zip(c) {
                            *s += v;
                        }
                    }
                }
                let at = 3 * (py * w + px);
                for (o, s) in out[at..at + 3].iter_mut().zip(sum) {
                    *o = (s / k).round().clamp(0.0, 255.0) as u8;
                }
            }
        }
        (w, h, out)
    }

    fn sample_colour(&self, x: usize, y: usize, colour: &[[u8; 3]]) -> [f32; 3] {
        let s = self.samples[y * self.width + x];
        let (base, cos) = match s {
            Sample::Background => return BACKGROUND.map(f32::from),
            Sample::Front { patch, cos } => (colour[patch as usize], cos),
            Sample::Back { cos, .. } => (BACK_SIDE, cos),
        };
        let edge = self.on_outline(x, y);
        let f = shade(cos) * if edge { 0.55 } else { 1.0 };
        base.map(|c| f32::from(c) * f)
    }

    /// Whether the sample's right or lower neighbour sees another patch.
    fn on_outline(&self, x: usize, y: usize) -> bool {
        let here = self.samples[y * self.width + x].patch();
        let differs = |xx: usize, yy: usize| self.samples[yy * self.width + xx].patch() != here;
        (x + 1 < self.width && differs(x + 1, y)) || (y + 1 < self.height && differs(x, y + 1))
    }
}
