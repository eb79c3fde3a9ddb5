//! The pinhole camera of a picture, and the view chosen when none is given.
//!
//! The default view is chosen from the geometry, by tracing. Candidate views are each traced as a
//! small probe picture and scored by what they show:
//!
//! `score = F x A - B`
//!
//! where `F` is the share of the probe's samples that see a front side, `B` the share that see a back
//! side (a wall seen from behind says nothing about the colours, and hides what is behind it), and `A`
//! the share of the scene's area seen from the front in the probe (each sample stands for the surface
//! its pixel covers: a view of one wall, or of a box just in front of the eye, scores less than a view
//! of the whole room). `+y` is up (OBJ's usual up).
//!
//! The candidates, each a way to look at a room or at an object:
//!
//! * from inside, near each vertical wall of the bounding box (`-z` first: the Cornell box's own view,
//!   the classic view), three quarters of the way up, the eye moved further in or aside until almost
//!   every ray from it meets a front side (a closed room: the picture draws the wall behind the eye
//!   from behind, so the eye must be inside to see anything else); looking towards the opposite wall,
//!   tilted and as wide as it takes to show that wall whole, the floor from the middle of the room on
//!   and the lights ahead (the emitting patches), up to 100 degrees;
//! * from outside the bounding sphere, above and from each of the four diagonals around it, front and
//!   right first (an object in open space);
//! * from outside, in front of each of the four vertical faces of the bounding box and above it,
//!   looking in with the face filling the picture (a room open on one side is seen through its
//!   opening; from a closed side the probe sees back sides and scores below zero).
//!
//! The first candidate (the classic view) is kept unless another scores more than 10% higher, so that
//! a room whose classic view already shows the room keeps the same picture.

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

/// Rays cast in uniform directions from a place, to tell what surrounds it.
const INSIDE_PROBES: usize = 512;

/// The share of those rays that must meet a front side for a place to count as inside a room.
const INSIDE_SHARE: f64 = 0.98;

/// The probe picture each candidate view is scored on (4:3, the default picture's shape).
const PROBE: (usize, usize) = (64, 48);

/// The smallest cosine a surface seen at a grazing angle counts with (its area in view would grow
/// without bound).
const GRAZING: f64 = 0.2;

/// How high the eye stands in a room, as a share of its height: above the middle, as a person looking
/// in, so that the floor shows at a slant and a ceiling light not far above the view.
const EYE_HEIGHT: f64 = 0.75;

/// How far towards the far wall the floor must show from inside, as a share of the depth.
const FLOOR_DEPTH: f64 = 0.5;

/// The steepest tilt up or down of a view from inside, degrees.
const MOST_TILT: i32 = 60;

/// The widest field of view from inside, degrees: wider distorts the picture's edges beyond reading.
const WIDEST: f64 = 100.0;

/// The width over the height the views are framed for.
const ASPECT: f64 = 4.0 / 3.0;

/// The field of view from outside a room's bounding box, degrees.
const OUTSIDE_FOV: f64 = 40.0;

/// How much of the bounding box's face fills the picture from outside: a little under 1, so that the
/// edges of an opening fall just outside the picture.
const FRAMING: f64 = 0.88;

/// The same for a flat scene (a cut-out figure, one sheet) seen face on: all of it, with a margin.
const FLAT_FRAMING: f64 = 1.08;

/// How much more another view must score to replace the classic view.
const KEEP_CLASSIC: f64 = 1.1;

/// The thinnest side of the box the views are framed on, as a share of the longest.
const THINNEST: f64 = 0.05;

/// The default view of a scene (module documentation).
pub fn default_camera(scene: &Scene, tracer: &dyn Tracer) -> Result<Camera, TraceError> {
    let bounds = Bounds::of(scene);
    let lights = light_corners(scene);
    let mut candidates = Vec::new();
    for (axis, sign) in [(2, 1.0), (2, -1.0), (0, 1.0), (0, -1.0)] {
        let eye = inside_place(scene, tracer, &bounds, axis, sign)?;
        candidates.push(bounds.inside_view(eye, axis, sign, &lights));
    }
    candidates.extend(bounds.object_views());
    candidates.extend(
        [(2, 1.0), (2, -1.0), (0, 1.0), (0, -1.0), (1, -1.0)]
            .map(|(axis, sign)| bounds.outside_view(axis, sign)),
    );
    best_view(scene, tracer, &candidates)
}

/// The candidate that scores best, the first kept unless beaten by more than [`KEEP_CLASSIC`].
fn best_view(
    scene: &Scene,
    tracer: &dyn Tracer,
    candidates: &[Camera],
) -> Result<Camera, TraceError> {
    // A candidate that cannot form a picture (on a degenerate scene) is never chosen.
    let scores = candidates
        .iter()
        .map(|c| match c.validate() {
            Ok(()) => view_score(scene, tracer, c).map(|s| s.score()),
            Err(_) => Ok(f64::NEG_INFINITY),
        })
        .collect::<Result<Vec<f64>, _>>()?;
    let (best, top) =
        scores.iter().enumerate().fold(
            (0, f64::NEG_INFINITY),
            |(b, t), (k, &s)| {
                if s > t {
                    (k, s)
                } else {
                    (b, t)
                }
            },
        );
    // Scores may be negative: "within 10%" is measured on the distance to the best.
    let classic_kept = scores[0] >= top - (KEEP_CLASSIC - 1.0) * top.abs();
    Ok(candidates[if classic_kept { 0 } else { best }])
}

/// What a view shows, as shares (module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewScore {
    /// The share of the picture's samples that see a front side.
    pub front: f64,
    /// The share that see a back side.
    pub back: f64,
    /// The share of the scene's area seen from the front in the picture.
    pub area: f64,
}

impl ViewScore {
    /// `front x area - back`: how good the view is (module documentation).
    pub fn score(&self) -> f64 {
        self.front * self.area - self.back
    }
}

/// Scores the view `camera` gives of `scene` on a small probe picture (`PROBE` samples, one ray
/// each). A sample that sees a front side stands for the surface its pixel covers there (its solid
/// angle x distance² / |cos|, the cosine at least `GRAZING`); a patch shows at most its own area.
pub fn view_score(
    scene: &Scene,
    tracer: &dyn Tracer,
    camera: &Camera,
) -> Result<ViewScore, TraceError> {
    let (eye, [right, up, forward]) = camera.frame(scene);
    let (w, h) = PROBE;
    let half_height = (0.5 * camera.fov_degrees.to_radians()).tan();
    let pixel = 2.0 * half_height / h as f64;
    let dirs: Vec<Vector> = (0..w * h)
        .map(|k| {
            let u = ((k % w) as f64 + 0.5 - 0.5 * w as f64) * pixel;
            let v = half_height - ((k / w) as f64 + 0.5) * pixel;
            (forward + u * right + v * up).normalize()
        })
        .collect();
    let t_max = (eye.length() + 2.0 * scene.bounding_radius()) as f32;
    let lines: Vec<Line> = dirs
        .iter()
        .map(|d| Line {
            origin: eye.as_vec3().to_array(),
            dir: d.as_vec3().to_array(),
            t_max,
        })
        .collect();
    let mut hits = Vec::new();
    tracer.first_hits(&lines, &mut hits)?;
    let mut shown = vec![0.0; scene.patch_count()];
    let (mut front, mut back) = (0usize, 0usize);
    for (hit, d) in hits.iter().zip(&dirs) {
        let Some(hit) = hit else { continue };
        let patch = scene.triangle_patch[hit.triangle as usize] as usize;
        let cos = scene.patches[patch].normal.dot(*d);
        if cos >= 0.0 {
            back += 1;
            continue;
        }
        front += 1;
        // The pixel's solid angle: pixel² on the image plane at distance 1, seen at d·forward.
        let solid_angle = pixel * pixel * d.dot(forward).powi(3);
        let t = f64::from(hit.t);
        shown[patch] += solid_angle * t * t / cos.abs().max(GRAZING);
    }
    let area: f64 = scene
        .patches
        .iter()
        .zip(&shown)
        .map(|(p, &s)| s.min(p.area))
        .sum();
    let n = (w * h) as f64;
    Ok(ViewScore {
        front: front as f64 / n,
        back: back as f64 / n,
        area: area / scene.total_area(),
    })
}

/// The first place near the wall at the `-sign` end of `axis`, [`EYE_HEIGHT`] up, in from the wall by a
/// growing share of the depth and moved aside a little, from which almost every ray meets a front side;
/// the best-surrounded place tried when none does.
fn inside_place(
    scene: &Scene,
    tracer: &dyn Tracer,
    bounds: &Bounds,
    axis: usize,
    sign: f64,
) -> Result<Point, TraceError> {
    let (size, middle) = (bounds.size(), bounds.middle());
    let across = 2 - axis;
    let mut best: Option<(Point, f64)> = None;
    for depth in [0.01, 0.03, 0.08, 0.15, 0.25] {
        for (a, b) in [(0.0, 0.0), (0.1, 0.0), (-0.1, 0.0), (0.0, 0.1), (0.0, -0.1)] {
            let mut eye = middle.to_array();
            eye[axis] = bounds.wall(axis, -sign) + sign * depth * size[axis];
            eye[across] += a * size[across];
            eye[1] = bounds.lo.y + (EYE_HEIGHT + b) * size.y;
            let eye = Point::from_array(eye);
            let surround = surround(scene, tracer, eye)?;
            if surround.front >= INSIDE_SHARE {
                return Ok(eye);
            }
            if best.is_none_or(|(_, front)| surround.front > front) {
                best = Some((eye, surround.front));
            }
        }
    }
    Ok(best.expect("places were tried").0)
}

/// The half-height of the picture, as a tangent, that shows every one of `points` from `eye` looking
/// along `forward` (up +y) in a picture of [`ASPECT`]; infinite when one is behind the eye.
fn spread(eye: Point, forward: Vector, points: &[Point]) -> f64 {
    let right = unit_vector(forward.cross(Vector::Y));
    let up = right.cross(forward);
    points
        .iter()
        .map(|&p| {
            let to = p - eye;
            let depth = to.dot(forward);
            if depth <= 1e-9 * to.length() {
                return f64::INFINITY;
            }
            (to.dot(up) / depth)
                .abs()
                .max((to.dot(right) / depth).abs() / ASPECT)
        })
        .fold(0.0, f64::max)
}

/// The corners of the box around the emitting patches (scene units); none when nothing emits.
fn light_corners(scene: &Scene) -> Vec<Point> {
    let emitting = scene
        .patches
        .iter()
        .filter(|p| scene.materials[p.material as usize].emission > 0.0);
    let (lo, hi) = emitting
        .flat_map(|p| scene.polygon(p))
        .map(|&v| scene.vertices[v as usize])
        .fold(
            (Point::splat(f64::INFINITY), Point::splat(f64::NEG_INFINITY)),
            |(lo, hi), v| (lo.min(v), hi.max(v)),
        );
    if !lo.is_finite() {
        return Vec::new();
    }
    (0..8)
        .map(|k| {
            Point::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect()
}

/// The scene's axis-aligned bounds in its own units.
struct Bounds {
    lo: Point,
    hi: Point,
}

impl Bounds {
    /// The bounds of the scene's vertices, each side at least [`THINNEST`] of the longest: a flat
    /// scene (one triangle, a height field) still has a box to stand in and look across.
    fn of(scene: &Scene) -> Self {
        let (mut lo, mut hi) = scene.vertices.iter().fold(
            (Point::splat(f64::INFINITY), Point::splat(f64::NEG_INFINITY)),
            |(lo, hi), v| (lo.min(*v), hi.max(*v)),
        );
        let thinnest = THINNEST * (hi - lo).max_element();
        for axis in 0..3 {
            let missing = thinnest - (hi[axis] - lo[axis]);
            if missing > 0.0 {
                lo[axis] -= 0.5 * missing;
                hi[axis] += 0.5 * missing;
            }
        }
        Bounds { lo, hi }
    }

    fn size(&self) -> Vector {
        self.hi - self.lo
    }

    fn middle(&self) -> Point {
        0.5 * (self.lo + self.hi)
    }

    /// The coordinate of the bounding box's wall at the `sign` end of `axis`.
    fn wall(&self, axis: usize, sign: f64) -> f64 {
        if sign > 0.0 {
            self.hi[axis]
        } else {
            self.lo[axis]
        }
    }

    /// From `eye` inside, looking along `sign` x `axis` towards the far wall, tilted and as wide as it
    /// takes to show [`Bounds::must_see`] with a margin (at most [`WIDEST`]).
    fn inside_view(&self, eye: Point, axis: usize, sign: f64, lights: &[Point]) -> Camera {
        let mut level = Vector::ZERO;
        level[axis] = sign;
        let must = self.must_see(eye, axis, sign, lights);
        let (forward, spread) = (-MOST_TILT..=MOST_TILT)
            .map(|degrees| {
                let tilt = f64::from(degrees).to_radians();
                let forward = tilt.cos() * level + tilt.sin() * Vector::Y;
                (forward, spread(eye, forward, &must))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("tilts were tried");
        let far = (self.wall(axis, sign) - eye[axis]).abs();
        Camera {
            eye,
            target: eye + far * forward,
            up: Vector::Y,
            fov_degrees: (2.0 * (1.05 * spread).atan()).to_degrees().min(WIDEST),
        }
    }

    /// What a view from inside must show: the far wall's corners, the floor across the middle
    /// [`FLOOR_DEPTH`] of the way to the far wall, and the corners of the lights' box where they are
    /// ahead of the eye (a light above or behind the eye cannot be framed with the far wall).
    fn must_see(&self, eye: Point, axis: usize, sign: f64, lights: &[Point]) -> Vec<Point> {
        let across = 2 - axis;
        let far = self.wall(axis, sign);
        let mut points: Vec<Point> = [(0, 0), (0, 1), (1, 0), (1, 1)]
            .map(|(a, b)| {
                let mut p = [0.0; 3];
                p[axis] = far;
                p[across] = if a == 0 {
                    self.lo[across]
                } else {
                    self.hi[across]
                };
                p[1] = if b == 0 { self.lo.y } else { self.hi.y };
                Point::from_array(p)
            })
            .to_vec();
        let mut floor = self.middle().to_array();
        floor[axis] = eye[axis] + FLOOR_DEPTH * (far - eye[axis]);
        floor[1] = self.lo.y;
        points.push(Point::from_array(floor));
        let ahead = |p: &&Point| sign * (p[axis] - eye[axis]) > 0.1 * (far - eye[axis]).abs();
        points.extend(lights.iter().filter(ahead));
        points
    }

    /// From outside the face at the `-sign` end of `axis`, looking along `sign` x `axis` at the middle,
    /// the face filling the picture ([`FRAMING`]).
    fn outside_view(&self, axis: usize, sign: f64) -> Camera {
        let size = self.size();
        // The picture's vertical is y, or z when looking along y.
        let (vertical, up) = if axis == 1 {
            (2, Vector::Z)
        } else {
            (1, Vector::Y)
        };
        let horizontal = 3 - axis - vertical;
        let half = (0.5 * size[vertical]).max(0.5 * size[horizontal] / ASPECT);
        // A flat scene seen face on has no walls whose edges to hide: all of it shows, with a margin.
        let flat = size[axis] <= 2.0 * THINNEST * size.max_element();
        let framing = if flat { FLAT_FRAMING } else { FRAMING };
        let distance = framing * half / (0.5 * OUTSIDE_FOV).to_radians().tan();
        let middle = self.middle();
        let mut eye = middle.to_array();
        eye[axis] = self.wall(axis, -sign) - sign * distance;
        Camera {
            eye: Point::from_array(eye),
            target: middle,
            up,
            fov_degrees: OUTSIDE_FOV,
        }
    }

    /// From outside the bounding sphere, above and from each diagonal (front and right first), the
    /// field of view closed in on the bounding box (a long, flat object fills the picture).
    fn object_views(&self) -> Vec<Camera> {
        let radius = 0.5 * self.size().length();
        [(0.45, -1.0), (-0.45, -1.0), (0.45, 1.0), (-0.45, 1.0)]
            .map(|(x, z)| {
                let camera = Camera {
                    eye: self.middle() + 2.6 * radius * unit_vector(Vector::new(x, 0.55, z)),
                    target: self.middle(),
                    up: Vector::Y,
                    fov_degrees: 46.0,
                };
                Camera {
                    fov_degrees: self.fitting_fov(&camera).min(camera.fov_degrees),
                    ..camera
                }
            })
            .to_vec()
    }

    /// The vertical field of view in which the bounding box's corners all show, with a margin, in a
    /// picture of [`ASPECT`] (the eye outside the box).
    fn fitting_fov(&self, camera: &Camera) -> f64 {
        let forward = unit_vector(camera.target - camera.eye);
        let right = unit_vector(forward.cross(camera.up));
        let up = right.cross(forward);
        let half = (0..8)
            .map(|k| {
                let corner = Point::new(
                    if k & 1 == 0 { self.lo.x } else { self.hi.x },
                    if k & 2 == 0 { self.lo.y } else { self.hi.y },
                    if k & 4 == 0 { self.lo.z } else { self.hi.z },
                );
                let to = corner - camera.eye;
                let depth = to.dot(forward);
                (to.dot(up) / depth)
                    .abs()
                    .max((to.dot(right) / depth).abs() / ASPECT)
            })
            .fold(0.0, f64::max);
        (2.0 * (1.05 * half).atan()).to_degrees()
    }
}

/// What the rays from a place meet first, as shares of the rays.
#[derive(Clone, Copy, Debug)]
struct Surround {
    front: f64,
}

/// What rays from `eye` (scene units) in uniform directions meet first.
fn surround(scene: &Scene, tracer: &dyn Tracer, eye: Point) -> Result<Surround, TraceError> {
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
    Ok(Surround {
        front: front as f64 / INSIDE_PROBES as f64,
    })
}
