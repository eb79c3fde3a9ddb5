//! Aimed lines: global lines cast at the places where two tracers could ever disagree.
//!
//! Uniformly distributed lines practically never pass within rounding distance of a vertex or an edge,
//! nor lie in a triangle's plane, yet these are the lines where the watertight test leans on its f64
//! fallback and where a backend's candidates (boxes) could miss a true hit. Each [`AimKind`] makes lines
//! through one sort of target ([`AimTargets`]): vertices, the vertices shared by the most triangles,
//! edges, faces; along edges, in faces' planes, or at tiny angles to them.
//!
//! The lines are in tracing space (the scene in its unit bounding sphere) and are built like random
//! global lines: the segment `origin + t dir`, `t` in `[0, t_max]`, runs from outside the bounding sphere
//! to outside it again, through the chosen point, in f64 and then rounded to f32. A line therefore
//! passes through its target up to the f32 rounding of its origin and direction (~2e-7), except where
//! the rounding is exact: a line along a coordinate axis through a vertex ([`AimKind::VertexAxis`]), or
//! along an axis-parallel edge, passes through it exactly.
//!
//! # What agreement means on these lines
//!
//! Both tracers decide every candidate with the same watertight test in the same f32 operations, and
//! both propose every triangle whose box, grown on every side by the tracers' margin (1/65536 of the
//! scene's size), the line crosses. So they can only differ on a hit that the test grants to a triangle one of
//! them does not propose: a hit far from its triangle. Such hits exist: on a line in a triangle's plane to
//! within rounding (`in-face`, `edge-in-face`, the smallest `grazing` angles) the projected triangle is a
//! sliver across which the line's position is rounding, and so is the test's verdict (its distance `t`
//! could put the hit anywhere along the line, up to 1.3 away on `@cornell`, until such distances were
//! kept within the triangle's box: `crate::trace::rust::watertight`, "The distance of a grazing
//! crossing"). But the
//! rounding acts only across the plane: within the plane the line's side of each edge is well defined,
//! so the test grants the triangle only to lines that pass through it (within 4e-8 in every such case
//! measured, on the built-in scenes and the public OBJ files, against a margin of at least 1.5e-5),
//! which cross its grown box, where both tracers propose it. Stray hits are thus ambiguous geometrically
//! (whether a line lying in a face meets it is not a question f32 can answer) but decided identically by
//! both tracers; the report counts hits outside the grown box (`stray`, now 0) and a test checks that
//! none is.
//!
//! # Targets and streams
//!
//! Line `i` of a kind aims at target `i * P mod n` of the kind's `n` targets (`P` a prime above any
//! target count): the first `n` lines aim at every target once, spread over the scene, and later lines
//! go round again. Everything random about a line (its direction, the point on an edge or face, the
//! angle) comes from the stream of its batch, numbered by kind and batch: the lines depend on the seed,
//! the kind and the line count only, never on the threads.

use std::collections::{HashMap, HashSet};
use std::fmt;

use rand::RngCore;
use rand_pcg::Pcg64;

use crate::geom::{orthonormal_basis, uniform01, uniform_direction, unit_vector, DVec3};
use crate::run::BatchPlan;
use crate::sample::lines::batch_rng;
use crate::scene::Scene;
use crate::trace::Line;

/// How far beyond the bounding sphere (radius 1) a line starts and ends, as for random global lines: a
/// line through any point of the sphere stays outside it at `t = 0` and `t = t_max`.
const REACH: f64 = 1.001;

/// The smallest and largest angles (radians) between a grazing line and the face it grazes; the angle
/// of each line is log-uniform in between. At 1e-7 the f32 rounding of the direction (~6e-8) is as large
/// as the angle itself; at 1e-3 Embree once lost crossings when it was given inflated triangles.
pub const GRAZING_ANGLES: (f64, f64) = (1e-7, 1e-3);

/// A prime above any target count (2^61 - 1): `i * P mod n` visits every target once in `n` lines.
const STRIDE: u128 = (1 << 61) - 1;

/// What an aimed line is aimed at, and how.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AimKind {
    /// Through a vertex, in a uniformly random direction.
    Vertex,
    /// Through a vertex along a coordinate axis: exactly through it in f32 (the other two coordinates of
    /// the origin are the vertex's own).
    VertexAxis,
    /// Through a vertex along a face or space diagonal (components of equal size: the tracers choose
    /// the axes of their shear from the largest component, so ties must be broken alike).
    VertexDiagonal,
    /// Through one of the vertices shared by the most triangles (fans, poles), in a random direction.
    Fan,
    /// Through a uniformly random point of an edge, in a random direction.
    Edge,
    /// Through a random point of an edge, in the plane of one of the triangles that own it.
    EdgeInFace,
    /// Along an edge: its direction, through both its ends.
    AlongEdge,
    /// In the plane of a triangle, through a uniformly random point of it, in a random direction of
    /// the plane.
    InFace,
    /// Through a triangle's centroid at a tiny angle ([`GRAZING_ANGLES`]) to its plane.
    Grazing,
    /// Through a vertex at a tiny angle ([`GRAZING_ANGLES`]) to the plane of one triangle around it.
    GrazingVertex,
}

impl AimKind {
    /// Every kind, in the order reports list them.
    pub const ALL: [AimKind; 10] = [
        AimKind::Vertex,
        AimKind::VertexAxis,
        AimKind::VertexDiagonal,
        AimKind::Fan,
        AimKind::Edge,
        AimKind::EdgeInFace,
        AimKind::AlongEdge,
        AimKind::InFace,
        AimKind::Grazing,
        AimKind::GrazingVertex,
    ];

    /// The kind's name in reports and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            AimKind::Vertex => "vertex",
            AimKind::VertexAxis => "vertex-axis",
            AimKind::VertexDiagonal => "vertex-diagonal",
            AimKind::Fan => "fan",
            AimKind::Edge => "edge",
            AimKind::EdgeInFace => "edge-in-face",
            AimKind::AlongEdge => "along-edge",
            AimKind::InFace => "in-face",
            AimKind::Grazing => "grazing",
            AimKind::GrazingVertex => "grazing-vertex",
        }
    }

    /// The kind named `name` ([`AimKind::name`]).
    pub fn from_name(name: &str) -> Option<AimKind> {
        AimKind::ALL.into_iter().find(|k| k.name() == name)
    }

    /// Its position in [`AimKind::ALL`]: numbers the kind's random streams.
    fn index(self) -> u64 {
        AimKind::ALL.iter().position(|&k| k == self).unwrap_or(0) as u64
    }
}

impl fmt::Display for AimKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What one aimed line was aimed at, in f64 tracing space, before its rounding to f32: what a test
/// checks the line against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aim {
    /// The kind of line.
    pub kind: AimKind,
    /// The triangle whose vertex, edge or face the line is aimed at.
    pub triangle: u32,
    /// A point the line passes through (a vertex, a point of an edge or of a face).
    pub through: DVec3,
    /// A second point it passes through: the other end of the edge, for [`AimKind::AlongEdge`].
    pub also_through: Option<DVec3>,
    /// The unit normal of the face whose plane the line lies in or grazes, and the angle (radians, 0
    /// for a line in the plane) between the line and that plane.
    pub plane: Option<(DVec3, f64)>,
}

/// A corner of a triangle, and the side that runs from it to the next corner.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Side {
    triangle: u32,
    corner: u8,
}

/// The targets of a scene's aimed lines: its vertices, edges and faces, from the f32 positions the
/// tracers see. Triangles without an area (in f64, from those positions) have no plane and are left out.
#[derive(Clone, Debug)]
pub struct AimTargets {
    /// Each vertex (position) of a triangle with an area, once, as a corner of one such triangle.
    vertices: Vec<Side>,
    /// The vertices shared by the most triangles ([`fan_vertices`]), as corners.
    fans: Vec<Side>,
    /// Each edge (pair of vertex positions) once, as a side of one triangle.
    edges: Vec<Side>,
    /// Every side of every triangle: an edge with each triangle that owns it, or a corner of a triangle.
    sides: Vec<Side>,
    /// The triangles with an area.
    faces: Vec<u32>,
    /// Each triangle's corners (f64, tracing space).
    corners: Vec<[DVec3; 3]>,
    /// Each triangle's unit normal (zero for one without an area).
    normals: Vec<DVec3>,
}

impl AimTargets {
    /// Collects the targets of `scene`.
    pub fn new(scene: &Scene) -> Self {
        let corners: Vec<[DVec3; 3]> = scene
            .triangles
            .iter()
            .map(|t| t.map(|v| DVec3::from_array(scene.positions[v as usize].map(f64::from))))
            .collect();
        let normals: Vec<DVec3> = corners.iter().map(face_normal).collect();
        let faces: Vec<u32> = (0..corners.len() as u32)
            .filter(|&t| normals[t as usize] != DVec3::ZERO)
            .collect();
        let sides: Vec<Side> = faces
            .iter()
            .flat_map(|&triangle| (0..3).map(move |corner| Side { triangle, corner }))
            .collect();
        // Vertices by position, not by index: files often repeat a vertex for each face around it.
        let at = |s: &Side, k: usize| {
            let v = scene.triangles[s.triangle as usize][(s.corner as usize + k) % 3];
            // + 0.0 makes -0.0 and 0.0 one coordinate.
            scene.positions[v as usize].map(|c| (c + 0.0).to_bits())
        };
        let vertex = |s: &Side| at(s, 0);
        let edge = |s: &Side| {
            let (a, b) = (at(s, 0), at(s, 1));
            (a.min(b), a.max(b))
        };
        let vertices = first_of_each(&sides, vertex);
        let edges = first_of_each(&sides, edge);
        let fans = fan_vertices(&sides, &vertices, vertex);
        AimTargets {
            vertices,
            fans,
            edges,
            sides,
            faces,
            corners,
            normals,
        }
    }

    /// How many targets lines of `kind` go round (0: the scene has none, and the kind casts no line).
    pub fn count(&self, kind: AimKind) -> usize {
        match kind {
            AimKind::Vertex | AimKind::VertexAxis | AimKind::VertexDiagonal => self.vertices.len(),
            AimKind::Fan => self.fans.len(),
            AimKind::Edge | AimKind::AlongEdge => self.edges.len(),
            AimKind::EdgeInFace | AimKind::GrazingVertex => self.sides.len(),
            AimKind::InFace | AimKind::Grazing => self.faces.len(),
        }
    }

    /// The target of line `line`: a side (for a face, its first corner).
    fn target(&self, kind: AimKind, line: u64) -> Side {
        let n = self.count(kind);
        let pick = (u128::from(line) * STRIDE % n as u128) as usize;
        match kind {
            AimKind::Vertex | AimKind::VertexAxis | AimKind::VertexDiagonal => self.vertices[pick],
            AimKind::Fan => self.fans[pick],
            AimKind::Edge | AimKind::AlongEdge => self.edges[pick],
            AimKind::EdgeInFace | AimKind::GrazingVertex => self.sides[pick],
            AimKind::InFace | AimKind::Grazing => Side {
                triangle: self.faces[pick],
                corner: 0,
            },
        }
    }

    /// Appends the lines of batch `batch` of `plan` for `kind` (and what each is aimed at) to `lines`
    /// and `aims`. Needs targets of that kind ([`AimTargets::count`] > 0).
    pub(crate) fn draw(
        &self,
        kind: AimKind,
        seed: u64,
        plan: &BatchPlan,
        batch: u64,
        lines: &mut Vec<Line>,
        aims: &mut Vec<Aim>,
    ) {
        let mut rng = kind_rng(kind, seed, batch);
        let first = plan.first_line(batch);
        for i in first..first + plan.batch_len(batch) as u64 {
            let aim = self.aim(kind, self.target(kind, i), &mut rng);
            lines.push(line_for(&aim, &mut rng));
            aims.push(aim);
        }
    }

    /// The first `count` lines of `kind` from `seed` (the batches of a run of `count` lines in turn), with
    /// their aims; none when the scene has no target of that kind.
    pub fn lines(&self, kind: AimKind, seed: u64, count: u64) -> (Vec<Line>, Vec<Aim>) {
        let (mut lines, mut aims) = (Vec::new(), Vec::new());
        if self.count(kind) > 0 {
            let plan = BatchPlan::new(count);
            for b in 0..plan.batches() {
                self.draw(kind, seed, &plan, b, &mut lines, &mut aims);
            }
        }
        (lines, aims)
    }

    /// Where a line of `kind` at `side` passes, and the plane it keeps to.
    fn aim(&self, kind: AimKind, side: Side, rng: &mut Pcg64) -> Aim {
        let t = side.triangle as usize;
        let [a, b, _] = rotated(self.corners[t], side.corner);
        let normal = self.normals[t];
        let point_of_edge = |rng: &mut Pcg64| a + uniform01(rng) * (b - a);
        let (through, also_through, plane) = match kind {
            AimKind::Vertex | AimKind::VertexAxis | AimKind::VertexDiagonal | AimKind::Fan => {
                (a, None, None)
            }
            AimKind::Edge => (point_of_edge(rng), None, None),
            AimKind::EdgeInFace => (point_of_edge(rng), None, Some((normal, 0.0))),
            AimKind::AlongEdge => (a, Some(b), None),
            AimKind::InFace => (
                point_in_triangle(self.corners[t], rng),
                None,
                Some((normal, 0.0)),
            ),
            AimKind::Grazing => {
                let c = self.corners[t];
                let centroid = (c[0] + c[1] + c[2]) / 3.0;
                (centroid, None, Some((normal, grazing_angle(rng))))
            }
            AimKind::GrazingVertex => (a, None, Some((normal, grazing_angle(rng)))),
        };
        Aim {
            kind,
            triangle: side.triangle,
            through,
            also_through,
            plane,
        }
    }
}

/// The random stream of batch `batch` of `kind`: streams numbered apart from those of random lines
/// (which use the batch index itself), one range of 2^40 batches per kind.
fn kind_rng(kind: AimKind, seed: u64, batch: u64) -> Pcg64 {
    batch_rng(seed, ((kind.index() + 1) << 40) | batch)
}

/// The unit normal of a triangle (zero when it has no area in f64).
fn face_normal(c: &[DVec3; 3]) -> DVec3 {
    let n = (c[1] - c[0]).cross(c[2] - c[0]);
    if n.length() > 0.0 {
        unit_vector(n)
    } else {
        DVec3::ZERO
    }
}

/// The corners starting at `corner`, in the triangle's order.
fn rotated(c: [DVec3; 3], corner: u8) -> [DVec3; 3] {
    let k = corner as usize;
    [c[k], c[(k + 1) % 3], c[(k + 2) % 3]]
}

/// The first side of each key (vertex, edge), in side order.
fn first_of_each<K: std::hash::Hash + Eq>(sides: &[Side], key: impl Fn(&Side) -> K) -> Vec<Side> {
    let mut seen = HashSet::new();
    sides
        .iter()
        .filter(|s| seen.insert(key(s)))
        .copied()
        .collect()
}

/// The vertices shared by the most triangles: the tenth of the vertices (at least one) with the most
/// triangles around them, ties to the first in `vertices`' order; as one corner each.
fn fan_vertices<K: std::hash::Hash + Eq>(
    sides: &[Side],
    vertices: &[Side],
    vertex: impl Fn(&Side) -> K,
) -> Vec<Side> {
    let mut valence: HashMap<K, u32> = HashMap::new();
    for s in sides {
        *valence.entry(vertex(s)).or_default() += 1;
    }
    let mut ranked: Vec<(u32, usize)> = vertices
        .iter()
        .enumerate()
        .map(|(k, s)| (valence[&vertex(s)], k))
        .collect();
    ranked.sort_by(|x, y| y.0.cmp(&x.0).then(x.1.cmp(&y.1)));
    let keep = vertices.len().div_ceil(10);
    ranked[..keep].iter().map(|&(_, k)| vertices[k]).collect()
}

/// A uniformly random point of a triangle.
fn point_in_triangle(c: [DVec3; 3], rng: &mut Pcg64) -> DVec3 {
    let (mut u, mut v) = (uniform01(rng), uniform01(rng));
    if u + v > 1.0 {
        (u, v) = (1.0 - u, 1.0 - v);
    }
    c[0] + u * (c[1] - c[0]) + v * (c[2] - c[0])
}

/// A log-uniform angle within [`GRAZING_ANGLES`].
fn grazing_angle(rng: &mut Pcg64) -> f64 {
    let (lo, hi) = GRAZING_ANGLES;
    lo * (hi / lo).powf(uniform01(rng))
}

/// A uniformly random direction.
fn random_direction(rng: &mut impl RngCore) -> DVec3 {
    let u1 = uniform01(rng);
    uniform_direction(u1, uniform01(rng))
}

/// The line of an aim: its direction (random where the kind leaves it free), through its point.
fn line_for(aim: &Aim, rng: &mut Pcg64) -> Line {
    let dir = match (aim.kind, aim.plane) {
        (AimKind::VertexAxis, _) => axis_direction(rng),
        (AimKind::VertexDiagonal, _) => diagonal_direction(rng),
        (AimKind::AlongEdge, _) => {
            unit_vector(aim.also_through.unwrap_or(aim.through) - aim.through)
        }
        (_, Some((normal, angle))) => tilted_direction(normal, angle, rng),
        (_, None) => random_direction(rng),
    };
    line_through(aim.through, dir)
}

/// One of the six axis directions, at random.
fn axis_direction(rng: &mut impl RngCore) -> DVec3 {
    let draw = rng.next_u64() % 6;
    let sign = if draw >= 3 { -1.0 } else { 1.0 };
    let mut d = [0.0; 3];
    d[(draw % 3) as usize] = sign;
    DVec3::from_array(d)
}

/// One of the 12 face diagonals (two components of equal size, the third 0) or 8 space diagonals, at
/// random.
fn diagonal_direction(rng: &mut impl RngCore) -> DVec3 {
    let draw = rng.next_u64() % 20;
    let sign = |bit: u64| if draw >> bit & 1 == 0 { 1.0 } else { -1.0 };
    let (s0, s1) = (sign(0), sign(1));
    // Draws 0..12: the component that is zero (draw / 4) and two signs; 12..20: three signs.
    let d = match draw / 4 {
        0 => [0.0, s0, s1],
        1 => [s0, 0.0, s1],
        2 => [s0, s1, 0.0],
        _ => [s0, s1, sign(2)],
    };
    unit_vector(DVec3::from_array(d))
}

/// A direction at `angle` to the plane of `normal`, toward either side: a random direction within the
/// plane, tilted toward the normal.
fn tilted_direction(normal: DVec3, angle: f64, rng: &mut impl RngCore) -> DVec3 {
    let (u, w) = orthonormal_basis(normal);
    let phi = std::f64::consts::TAU * uniform01(rng);
    let side = if rng.next_u64() & 1 == 0 { 1.0 } else { -1.0 };
    let within = phi.cos() * u + phi.sin() * w;
    angle.cos() * within + side * angle.sin() * normal
}

/// The traced line through `point` along the unit `dir`: from [`REACH`] before the point of the line
/// nearest the centre to [`REACH`] beyond it (as random global lines), rounded to f32.
fn line_through(point: DVec3, dir: DVec3) -> Line {
    let foot = point - point.dot(dir) * dir;
    Line {
        origin: (foot - REACH * dir).as_vec3().to_array(),
        dir: dir.as_vec3().to_array(),
        t_max: (2.0 * REACH) as f32,
    }
}
