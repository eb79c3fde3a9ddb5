//! The scene's bounding polytope (`--lines-through polytope`): the convex polytope bounded by the
//! 26 planes that touch the scene across 13 directions, the 3 axes, the 6 diagonals of the axis
//! planes and the 4 diagonals of space (a 26-DOP: the bounding box with its edges and corners cut
//! off). It hugs convex solids and objects in open space far closer than the box or the sphere: the
//! octahedron's is the octahedron itself, while its box reaches out of its sphere.
//!
//! Its lines are drawn as the box's are ([`super::bounds`]): an oriented line meeting a convex body
//! enters it at one point, where the invariant density of lines is `|cos theta| dA d omega`, so a
//! face triangle chosen in proportion to its area, a uniform point on it and a cosine-distributed
//! direction into the polytope give the sphere's lines that meet the polytope, each traced along
//! its whole chord of the bounding sphere (which holds every scene point the line crosses). The
//! point on a triangle is `a + sqrt(s) ((1 - t) (b - a) + t (c - a))`: each of the triangle's edges
//! is a line `s = 1`, `t = 0` or `t = 1` of the unit square, so the logarithmic singularity of eq.
//! (27) along the lines through an edge of a solid lies along the axes of a Sobol' point set, as it
//! does for the box's faces.
//!
//! `--lines-through auto` draws through it, for the Sobol' sampler, only where most of the scene's
//! area lies in its faces' planes ([`share_of_area_on_faces`]): on curved objects, and on solids or
//! rooms turned off its 13 directions, the Sobol' lines through the sphere measured better.

use super::lines::concentric_discs;
use crate::geom::DVec3;
use crate::scene::Scene;
use crate::trace::Line;

/// How far the box and the polytope reach beyond the scene, in bounding radii: a flat scene still
/// gets a container of positive volume, and the scene stays inside it whatever the rounding of its
/// planes. No more: where a scene's faces lie in the container's, the lines through the scene's edges
/// (eq. 27's logarithmic singularity) enter the container along its own edges, which the Sobol'
/// points stratify; a wider margin moves them into the container's faces at angles to the sequence's
/// axes and into slivers of the polytope along the edges (a margin of 1e-3 left I_s^c's spread 1.5x
/// wider on the octahedron, 1.3x on `@cube:30`, docs/sampling.md).
pub(super) const CONTAINER_MARGIN: f64 = 1e-6;

/// The traced chord reaches this factor beyond the bounding sphere (as the sphere's own lines do),
/// so that f32 rounding never clips a vertex lying on the sphere.
const CHORD_REACH: f64 = 1.001;

/// The 13 directions of the bounding planes (unit vectors): the axes, the diagonals of the axis
/// planes, the diagonals of space.
fn directions() -> [DVec3; 13] {
    let (h, t) = (std::f64::consts::FRAC_1_SQRT_2, 1.0 / 3f64.sqrt());
    [
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(h, h, 0.0),
        DVec3::new(h, -h, 0.0),
        DVec3::new(h, 0.0, h),
        DVec3::new(h, 0.0, -h),
        DVec3::new(0.0, h, h),
        DVec3::new(0.0, h, -h),
        DVec3::new(t, t, t),
        DVec3::new(t, t, -t),
        DVec3::new(t, -t, t),
        DVec3::new(-t, t, t),
    ]
}

/// Lines a polytope makes at a time ([`BoundingPolytope::lines`]).
const CHUNK: usize = 16;

/// A half-space `normal . x <= offset` (`normal` a unit vector pointing out of the polytope).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Plane {
    normal: DVec3,
    offset: f64,
}

/// One triangle of the polytope's surface, with what drawing a line through it needs.
#[derive(Clone, Copy, Debug, PartialEq)]
struct FaceTriangle {
    /// The running sum of the areas of the triangles before it.
    start: f64,
    area: f64,
    /// Its corner `a` and the edges `b - a`, `c - a`.
    a: DVec3,
    ab: DVec3,
    ac: DVec3,
    /// The inward normal, and two unit vectors across the face, orthogonal to it and each other.
    inward: DVec3,
    across_b: DVec3,
    across_c: DVec3,
}

/// The bounding polytope of a scene, as the triangles of its faces.
#[derive(Clone, Debug, PartialEq)]
pub struct BoundingPolytope {
    triangles: Vec<FaceTriangle>,
    area: f64,
    /// The radius of the sphere whose chords are traced.
    reach: f64,
}

/// The part of the convex polygon `poly` where `plane` holds (Sutherland and Hodgman).
fn clipped(poly: &[DVec3], plane: &Plane) -> Vec<DVec3> {
    let side = |p: DVec3| plane.normal.dot(p) - plane.offset;
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (k, &p) in poly.iter().enumerate() {
        let q = poly[(k + 1) % poly.len()];
        let (sp, sq) = (side(p), side(q));
        if sp <= 0.0 {
            out.push(p);
        }
        if (sp < 0.0 && sq > 0.0) || (sp > 0.0 && sq < 0.0) {
            let t = sp / (sp - sq);
            out.push(p + (q - p) * t);
        }
    }
    out
}

/// The 26 planes touching `points` (pointing out of them), each moved out by `margin`.
fn support_planes(points: impl Iterator<Item = DVec3> + Clone, margin: f64) -> Vec<Plane> {
    let mut planes = Vec::with_capacity(26);
    for d in directions() {
        let (lo, hi) = points
            .clone()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                let x = d.dot(p);
                (lo.min(x), hi.max(x))
            });
        let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 0.0) };
        planes.push(Plane {
            normal: d,
            offset: hi + margin,
        });
        planes.push(Plane {
            normal: -d,
            offset: -lo + margin,
        });
    }
    planes
}

/// The vertices of `scene`'s triangles in tracing space.
fn scene_points(scene: &Scene) -> impl Iterator<Item = DVec3> + Clone + '_ {
    scene
        .triangles
        .iter()
        .flatten()
        .map(|&v| DVec3::from(scene.positions[v as usize].map(f64::from)))
}

/// The share of `scene`'s area that lies in the planes of its polytope's faces (its triangles with
/// every corner within a millionth of the bounding radius of one of them): 1 for the octahedron and
/// the tetrahedron, whose faces are among the polytope's, 0 for the icosahedron or a curved object.
/// Where it is high the Sobol' sampler gains through the polytope as it does through the box of a
/// room ([`super::bounds::tightest_container`]).
pub fn share_of_area_on_faces(scene: &Scene) -> f64 {
    let planes = support_planes(scene_points(scene), 0.0);
    let tolerance = 1e-6 * scene.bounding_radius();
    let (mut on, mut all) = (0.0, 0.0);
    for t in &scene.triangles {
        let corners = t.map(|v| DVec3::from(scene.positions[v as usize].map(f64::from)));
        let [a, b, c] = corners;
        let area = 0.5 * (b - a).cross(c - a).length();
        all += area;
        let in_plane = |p: &Plane| {
            corners
                .iter()
                .all(|&v| p.normal.dot(v) >= p.offset - tolerance)
        };
        if planes.iter().any(in_plane) {
            on += area;
        }
    }
    if all > 0.0 {
        on / all
    } else {
        0.0
    }
}

/// `poly` without its repeated corners and the corners on a straight edge (touching planes leave
/// such corners behind), so that a face is fanned into as few triangles as it has true corners less
/// two.
fn without_straight_corners(poly: Vec<DVec3>, scale: f64) -> Vec<DVec3> {
    let mut corners = poly;
    let tiny = 1e-12 * scale * scale;
    let mut k = 0;
    while corners.len() >= 3 && k < corners.len() {
        let n = corners.len();
        let (prev, here, next) = (corners[(k + n - 1) % n], corners[k], corners[(k + 1) % n]);
        if (here - prev).cross(next - here).length() <= tiny {
            corners.remove(k);
            k = k.saturating_sub(1);
        } else {
            k += 1;
        }
    }
    corners
}

impl BoundingPolytope {
    /// The polytope of the points `points` (tracing space), each plane moved out by `margin`, whose
    /// lines are traced along their chords of the sphere of radius `radius` about the origin (which
    /// must hold the points).
    pub fn of_points(
        points: impl Iterator<Item = DVec3> + Clone,
        margin: f64,
        radius: f64,
    ) -> Self {
        let planes = support_planes(points, margin);
        // Every face lies within the cube of side 4 radii about the origin.
        let extent = 4.0 * radius.max(margin);
        let mut triangles = Vec::new();
        let mut area = 0.0;
        for (k, plane) in planes.iter().enumerate() {
            let n = plane.normal;
            let helper = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
            let u = n.cross(helper).normalize();
            let v = n.cross(u);
            let centre = n * plane.offset;
            let corner = |a: f64, b: f64| centre + (u * a + v * b) * extent;
            let mut face = vec![
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
            ];
            for (j, other) in planes.iter().enumerate() {
                if j != k && face.len() >= 3 {
                    face = clipped(&face, other);
                }
            }
            let face = without_straight_corners(face, extent);
            for w in 1..face.len().saturating_sub(1) {
                let (a, b, c) = (face[0], face[w], face[w + 1]);
                let (ab, ac) = (b - a, c - a);
                let t_area = 0.5 * ab.cross(ac).length();
                if t_area <= 1e-10 * radius * radius {
                    continue;
                }
                let (inward, across_b) = (-n, ab.normalize());
                triangles.push(FaceTriangle {
                    start: area,
                    area: t_area,
                    a,
                    ab,
                    ac,
                    inward,
                    across_b,
                    across_c: inward.cross(across_b),
                });
                area += t_area;
            }
        }
        BoundingPolytope {
            triangles,
            area,
            reach: CHORD_REACH * radius,
        }
    }

    /// `scene`'s polytope in tracing space, its planes moved out by [`CONTAINER_MARGIN`] bounding
    /// radii, as the box is grown.
    pub fn of(scene: &Scene) -> Self {
        let radius = scene.bounding_radius();
        Self::of_points(scene_points(scene), CONTAINER_MARGIN * radius, radius)
    }

    /// The polytope's surface area.
    pub fn surface_area(&self) -> f64 {
        self.area
    }

    /// `S / (4 pi R^2)` for the sphere of radius `radius`: the share of that sphere's lines that
    /// meet the polytope when the polytope is inside the sphere (Cauchy), more than 1 when it
    /// reaches out of it ([`super::bounds::BoundingBox::share_of_sphere`]).
    pub fn share_of_sphere(&self, radius: f64) -> f64 {
        self.area / (4.0 * std::f64::consts::PI * radius * radius)
    }

    /// The triangles' count (every face of positive area, fanned into triangles).
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The line of the unit point `u`: `u[0]` chooses the triangle (in proportion to the areas)
    /// and, rescaled within its share, the distance from the triangle's first corner (as `sqrt`),
    /// `u[1]` the way across; `(u[2], u[3])` the direction, as the box's lines do
    /// ([`super::bounds::BoundingBox::line`]). The line is traced along its chord of the sphere of
    /// the polytope's reach.
    pub fn line(&self, u: [f64; 4]) -> Line {
        let mut out = Vec::with_capacity(1);
        self.lines(&[u], &mut out);
        out[0]
    }

    /// The lines of `units`, [`BoundingPolytope::line`] of each, appended to `out`: made
    /// [`CHUNK`] at a time, stage by stage across the chunk (disc points, triangles, distances from
    /// their corners, lines), so that one line's search, division and square roots overlap the
    /// next's rather than wait for them.
    pub fn lines(&self, units: &[[f64; 4]], out: &mut Vec<Line>) {
        out.reserve(units.len());
        if self.triangles.is_empty() {
            let none = Line {
                origin: [0.0; 3],
                dir: [0.0, 0.0, 1.0],
                t_max: 0.0,
            };
            out.extend(units.iter().map(|_| none));
            return;
        }
        for chunk in units.chunks(CHUNK) {
            self.chunk_lines(chunk, out);
        }
    }

    /// [`BoundingPolytope::lines`] of at most [`CHUNK`] points (the polytope has triangles): `u[0]`
    /// picks a triangle by area and, rescaled within its share, the distance from its first corner
    /// (as `sqrt`), `u[1]` the way across; `(u[2], u[3])` the direction.
    #[inline(never)]
    fn chunk_lines(&self, chunk: &[[f64; 4]], out: &mut Vec<Line>) {
        const N: usize = CHUNK;
        let (mut a, mut b) = ([0.0; N], [0.0; N]);
        for (k, u) in chunk.iter().enumerate() {
            a[k] = 2.0 * u[2] - 1.0;
            b[k] = 2.0 * u[3] - 1.0;
        }
        let (dx, dy) = concentric_discs(&a, &b);
        let last = self.triangles.len() - 1;
        let mut triangle = [0usize; N];
        for (k, u) in chunk.iter().enumerate() {
            let at = u[0] * self.area;
            triangle[k] = self
                .triangles
                .partition_point(|t| t.start + t.area <= at)
                .min(last);
        }
        let mut s = [0.0; N];
        for (k, u) in chunk.iter().enumerate() {
            let t = &self.triangles[triangle[k]];
            s[k] = ((u[0] * self.area - t.start) / t.area)
                .clamp(0.0, 1.0)
                .sqrt();
        }
        for (k, u) in chunk.iter().enumerate() {
            let t = &self.triangles[triangle[k]];
            let entry = t.a + (t.ab * (1.0 - u[1]) + t.ac * u[1]) * s[k];
            let dz = (1.0 - dx[k] * dx[k] - dy[k] * dy[k]).max(0.0).sqrt();
            let dir = t.inward * dz + t.across_b * dx[k] + t.across_c * dy[k];
            out.push(self.chord(entry, dir));
        }
    }

    /// The line through `entry` along the unit `dir`, from where it enters the sphere of the
    /// polytope's reach to where it leaves it (a line that misses that sphere meets no scene point:
    /// an empty segment).
    fn chord(&self, entry: DVec3, dir: DVec3) -> Line {
        let b = entry.dot(dir);
        let disc = b * b - (entry.dot(entry) - self.reach * self.reach);
        let f32s = |v: DVec3| v.to_array().map(|x| x as f32);
        if disc <= 0.0 {
            return Line {
                origin: f32s(entry),
                dir: f32s(dir),
                t_max: 0.0,
            };
        }
        let half = disc.sqrt();
        Line {
            origin: f32s(entry + dir * (-b - half)),
            dir: f32s(dir),
            t_max: (2.0 * half) as f32,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform numbers in [0, 1) from a xorshift stream seeded with `seed` (non-zero).
    fn uniforms(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn octahedron() -> Vec<DVec3> {
        vec![
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ]
    }

    /// The outward normal (+-1, +-1, +-1) of the octahedron's face in octant `k` (bit i: axis i
    /// negative), unnormalised: the face is `normal . x = 1`.
    fn octant_normal(k: usize) -> DVec3 {
        DVec3::from([0, 1, 2].map(|i| if k >> i & 1 == 1 { -1.0 } else { 1.0 }))
    }

    /// The octahedron's polytope is the octahedron (8 equilateral faces of side sqrt 2, area 4 sqrt
    /// 3); the cube's is the cube (area 24 for side 2), its diagonal planes touching it at edges
    /// and corners.
    #[test]
    fn the_polytope_of_an_octahedron_or_a_cube_is_itself() {
        let p = BoundingPolytope::of_points(octahedron().into_iter(), 0.0, 1.0);
        assert!(
            (p.surface_area() - 4.0 * 3f64.sqrt()).abs() < 1e-9,
            "{}",
            p.surface_area()
        );
        assert_eq!(p.triangle_count(), 8);
        let corners: Vec<DVec3> = (0..8)
            .map(|k| DVec3::from([0, 1, 2].map(|i| if k >> i & 1 == 1 { 1.0 } else { -1.0 })))
            .collect();
        let c = BoundingPolytope::of_points(corners.into_iter(), 0.0, 3f64.sqrt());
        assert!(
            (c.surface_area() - 24.0).abs() < 1e-9,
            "{}",
            c.surface_area()
        );
    }

    /// Lines through the octahedron's polytope enter its faces as often as their areas say, with
    /// the cosine about the inward normal averaging 2/3 (the density `|cos| dA d omega`); every
    /// chord passes through the octahedron, from outside the unit sphere to outside it.
    #[test]
    fn its_lines_meet_it_with_the_invariant_density() {
        let p = BoundingPolytope::of_points(octahedron().into_iter(), 0.0, 1.0);
        let n = 1 << 16;
        let mut cos_sum = 0.0;
        let mut seen = [0u32; 8];
        let mut next = uniforms(0x9e37_79b9_7f4a_7c15u64);
        for _ in 0..n {
            let u = [next(), next(), next(), next()];
            let line = p.line(u);
            let d = DVec3::from(line.dir.map(f64::from));
            let o = DVec3::from(line.origin.map(f64::from));
            assert!(o.length() > 1.0 && line.t_max > 0.0);
            // The entry face: the octant of the entry point, whose outward normal is (+-1, +-1, +-1).
            let (t_in, face) = (0..8)
                .map(|k| {
                    let nrm = octant_normal(k);
                    let denom = nrm.dot(d);
                    ((1.0 - nrm.dot(o)) / denom, k, denom)
                })
                .filter(|&(_, _, denom)| denom < 0.0)
                .map(|(t, k, _)| (t, k))
                .fold((f64::NEG_INFINITY, 0), |a, b| if b.0 > a.0 { b } else { a });
            assert!(t_in > 0.0 && t_in < f64::from(line.t_max));
            seen[face] += 1;
            cos_sum += -octant_normal(face).dot(d) / 3f64.sqrt();
        }
        let expected = f64::from(n) / 8.0;
        for s in seen {
            assert!(
                (f64::from(s) - expected).abs() < 4.5 * (expected * 7.0 / 8.0).sqrt(),
                "{seen:?}"
            );
        }
        let mean_cos = cos_sum / f64::from(n);
        assert!(
            (mean_cos - 2.0 / 3.0).abs() < 4.5 * (1.0 / 18.0 / f64::from(n)).sqrt(),
            "{mean_cos}"
        );
    }

    /// The straightforward construction of one line: the triangle by a linear search of the running
    /// areas, its entry point and direction, and the chord of the reach's sphere through them.
    fn reference_line(p: &BoundingPolytope, u: [f64; 4]) -> Line {
        let at = u[0] * p.area;
        let k = (0..p.triangles.len())
            .find(|&k| p.triangles[k].start + p.triangles[k].area > at)
            .unwrap_or(p.triangles.len() - 1);
        let t = &p.triangles[k];
        let s = ((at - t.start) / t.area).clamp(0.0, 1.0).sqrt();
        let entry = t.a + (t.ab * (1.0 - u[1]) + t.ac * u[1]) * s;
        let (dx, dy) = concentric_discs(&[2.0 * u[2] - 1.0], &[2.0 * u[3] - 1.0]);
        let (dx, dy) = (dx[0], dy[0]);
        let dz = (1.0 - dx * dx - dy * dy).max(0.0).sqrt();
        let dir = t.inward * dz + t.across_b * dx + t.across_c * dy;
        p.chord(entry, dir)
    }

    /// Lines made 16 at a time are the reference construction's one at a time, bit for bit: full and
    /// partial chunks, the ends of [0, 1), every triangle's share, the disc's centre and diagonals, on
    /// the octahedron's polytope and a cube's (whose 26 planes cut corners and edges of area zero).
    #[test]
    fn lines_made_in_chunks_are_the_reference_lines() {
        let cube: Vec<DVec3> = (0..8)
            .map(|k| DVec3::from([0, 1, 2].map(|i| if k >> i & 1 == 1 { 1.0 } else { -1.0 })))
            .collect();
        let mut next = uniforms(0x2545_f491_4f6c_dd1du64);
        for points in [octahedron(), cube] {
            let p = BoundingPolytope::of_points(points.into_iter(), 1e-6, 1.0);
            let mut units: Vec<[f64; 4]> = (0..3001)
                .map(|_| [next(), next(), next(), next()])
                .collect();
            let below_one = 1.0 - f64::EPSILON / 2.0;
            let n = p.triangles.len() as f64;
            for edge in [0.0, 0.5, below_one] {
                for k in 0..p.triangles.len() {
                    let u0 = (k as f64 + edge.min(0.999)) / n;
                    units.push([u0, edge, edge, 0.5]);
                    units.push([u0, 1.0 - edge, 0.5, edge]);
                    units.push([u0, 0.5, edge, 1.0 - edge]);
                }
            }
            let mut chunked = Vec::new();
            p.lines(&units, &mut chunked);
            assert_eq!(chunked.len(), units.len());
            let bits = |l: &Line| {
                (
                    l.origin.map(f32::to_bits),
                    l.dir.map(f32::to_bits),
                    l.t_max.to_bits(),
                )
            };
            for (u, line) in units.iter().zip(&chunked) {
                assert_eq!(bits(line), bits(&reference_line(&p, *u)), "{u:?}");
            }
        }
    }
}
