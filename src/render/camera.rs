//! The pinhole camera of a picture, and the view chosen when none is given.
//!
//! Every built-in scene is an enclosure (a room seen from inside: its walls face inwards), and a room
//! seen from outside shows only the back of one wall. So the default view first tries to stand inside:
//! near the middle of the room's `-z` wall, looking along `+z` at the far wall with `+y` up (the Cornell
//! box's own view, and OBJ's usual up), the field of view a little wider than the far wall. A place
//! counts as inside when almost every ray from it meets the front side of a surface. A scene with no
//! such place (an object in open space) is seen from outside its bounding sphere, from the front, above
//! and to the right.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use crate::geom::{uniform_direction, unit_vector, Point, Vector};
use crate::scene::Scene;
use crate::trace::{Line, TraceError, Tracer};

/// A pinhole camera in the scene's own units and frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Where the eye is.
    pub eye: Point,
    /// A point the eye looks at (the middle of the picture).
    pub target: Point,
    /// Which way is up in the picture (need not be perpendicular to the view).
    pub up: Vector,
    /// The vertical field of view, in degrees (0 to 180, exclusive).
    pub fov_degrees: f64,
}

/// A camera that cannot form a picture.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct CameraError(pub String);

impl Camera {
    /// Checks that the camera can form a picture: finite values, the target away from the eye, an up
    /// direction not along the view, a field of view strictly between 0 and 180 degrees.
    pub fn validate(&self) -> Result<(), CameraError> {
        let finite = [self.eye, self.target, self.up]
            .iter()
            .all(|v| v.is_finite())
            && self.fov_degrees.is_finite();
        if !finite {
            return Err(CameraError("the camera needs finite numbers".into()));
        }
        let view = self.target - self.eye;
        if view.length() == 0.0 {
            return Err(CameraError(
                "the camera's eye and target are the same point".into(),
            ));
        }
        if self.up.length() == 0.0 || view.normalize().cross(self.up.normalize()).length() < 1e-6 {
            return Err(CameraError(
                "the camera's up direction is zero or along the view".into(),
            ));
        }
        if !(self.fov_degrees > 0.0 && self.fov_degrees < 180.0) {
            return Err(CameraError(format!(
                "the field of view must be between 0 and 180 degrees, not {}",
                self.fov_degrees
            )));
        }
        Ok(())
    }

    /// The eye and an orthonormal frame (right, up, forward) in tracing space.
    pub(crate) fn frame(&self, scene: &Scene) -> (Point, [Vector; 3]) {
        let norm = scene.normalization;
        let eye = (self.eye - norm.center) / norm.scale;
        let forward = unit_vector(self.target - self.eye);
        let right = unit_vector(forward.cross(self.up));
        let up = right.cross(forward);
        (eye, [right, up, forward])
    }
}

/// Rays from a point of tracing space that meet a front side, out of those cast, for the test of
/// being inside an enclosure.
const INSIDE_PROBES: usize = 512;

/// The share of the probes that must meet a front side for a place to count as inside.
const INSIDE_SHARE: f64 = 0.98;

/// The default view of a scene (module documentation).
pub fn default_camera(scene: &Scene, tracer: &dyn Tracer) -> Result<Camera, TraceError> {
    let (lo, hi) = bounds(scene);
    let size = hi - lo;
    let middle = 0.5 * (lo + hi);
    // In from the -z wall by a few per cent of the depth; further in when an object stands there.
    for depth in [0.01, 0.03, 0.08, 0.15, 0.25] {
        for offset in [(0.0, 0.0), (0.1, 0.0), (-0.1, 0.0), (0.0, 0.1), (0.0, -0.1)] {
            let eye = Point::new(
                middle.x + offset.0 * size.x,
                middle.y + offset.1 * size.y,
                lo.z + depth * size.z,
            );
            if inside_share(scene, tracer, eye)? >= INSIDE_SHARE {
                let far = hi.z - eye.z;
                let half = 0.5 * size.x.max(size.y);
                return Ok(Camera {
                    eye,
                    target: Point::new(middle.x, middle.y, hi.z),
                    up: Vector::Y,
                    // Wider than the far wall, so that the floor, the ceiling and the side walls show.
                    fov_degrees: (2.0 * (1.3 * half / far).atan()).to_degrees().min(120.0),
                });
            }
        }
    }
    let radius = 0.5 * size.length();
    let direction = unit_vector(Vector::new(0.45, 0.55, -1.0));
    Ok(Camera {
        eye: middle + 2.6 * radius * direction,
        target: middle,
        up: Vector::Y,
        fov_degrees: 46.0,
    })
}

/// The scene's axis-aligned bounds in its own units.
fn bounds(scene: &Scene) -> (Point, Point) {
    scene.vertices.iter().fold(
        (Point::splat(f64::INFINITY), Point::splat(f64::NEG_INFINITY)),
        |(lo, hi), v| (lo.min(*v), hi.max(*v)),
    )
}

/// The share of rays from `eye` (scene units), in uniform directions, whose first hit is a front side.
fn inside_share(scene: &Scene, tracer: &dyn Tracer, eye: Point) -> Result<f64, TraceError> {
    let norm = scene.normalization;
    let origin = (eye - norm.center) / norm.scale;
    // A fixed stream: the same scene always gets the same view.
    let mut rng = Pcg64::seed_from_u64(17);
    let dirs: Vec<Vector> = (0..INSIDE_PROBES)
        .map(|_| uniform_direction(rng.gen(), rng.gen()))
        .collect();
    let lines: Vec<Line> = dirs
        .iter()
        .map(|d| Line {
            origin: origin.as_vec3().to_array(),
            dir: d.as_vec3().to_array(),
            t_max: (origin.length() + 2.0 * scene.bounding_radius()) as f32,
        })
        .collect();
    let mut hits = Vec::new();
    tracer.first_hits(&lines, &mut hits)?;
    let front = hits
        .iter()
        .zip(&dirs)
        .filter(|(h, d)| {
            h.is_some_and(|h| {
                let patch = scene.triangle_patch[h.triangle as usize] as usize;
                scene.patches[patch].normal.dot(**d) < 0.0
            })
        })
        .count();
    Ok(front as f64 / INSIDE_PROBES as f64)
}
