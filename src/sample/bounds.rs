//! Where a run's global lines are drawn: through the scene's bounding sphere (the paper's lines, sec.
//! 2.1.1, [`super::lines`]), through its bounding box (`--lines-through box`, here) or through its
//! bounding polytope (`--lines-through polytope`, [`super::polytope`]), and which of them `auto` takes
//! ([`tightest_container`]).
//!
//! **Lines through the box.** An oriented line that meets a convex body enters it at exactly one point,
//! and the invariant density of lines, written at that entry point `x` of the body's surface, is
//! `|cos theta| dA(x) d omega` (integral geometry; Santaló, *Integral Geometry and Geometric
//! Probability*, ch. 12). So a line uniformly distributed among those that meet the box is: a face chosen
//! in proportion to its area, a uniform point on it, and a direction cosine-distributed about the inward
//! normal (a uniform point of the unit disc lifted to the hemisphere, Malley's method). These are the
//! sphere's lines conditioned on meeting the box: every count of hits, segments and pairs, and every
//! measure made from them, is the same in distribution per line that meets the scene, and the sphere's
//! lines that miss the box (`1 - S_box / (4 pi R^2)` of them: 36% for a cube, two thirds and more for a
//! flat scene) are never drawn. What changes is the meaning of a line count: `n` lines through the box
//! are worth `n / p` lines through the sphere, `p = S_box / (4 pi R^2)` ([`BoundingBox::share_of_sphere`]).
//! A box can also be the larger container: the octahedron's reaches out of its sphere (`p` = 1.9), and
//! its lines then miss the scene more often than the sphere's.
//!
//! With the Sobol' sampler the first two coordinates of each point choose the face and the point on it,
//! the last two the direction: where a scene's walls lie in the box's faces or parallel to them (rooms,
//! `@cube:N`), the patches a line enters through are rectangles aligned with the sequence's axes, which a
//! low-discrepancy sequence integrates far better than the curved regions of the sphere's
//! parametrisation (docs/sampling.md).

use super::lines::{batch_units, concentric_discs};
use super::polytope::{share_of_area_on_faces, BoundingPolytope, CONTAINER_MARGIN};
use super::sobol::ScrambledSobol;
use crate::scene::Scene;
use crate::trace::Line;

/// Lines a box makes at a time ([`BoundingBox::lines`]): enough for each stage's operations to overlap,
/// few enough that the chunk's lanes stay in L1.
const CHUNK: usize = 16;

/// How far the box reaches beyond the scene on every side, in bounding radii ([`CONTAINER_MARGIN`]): a
/// flat scene still gets a box with six faces of positive area. The traced segments start further
/// out (a box's lead), so that f32 rounding never puts an origin on a triangle.
const BOX_MARGIN: f64 = CONTAINER_MARGIN;

/// Where the lines of a run are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LineBound {
    /// Through the bounding sphere (the paper's global lines).
    #[default]
    Sphere,
    /// Through the bounding box, grown by a thousandth of the bounding radius on every side: the
    /// sphere's lines that meet it (module documentation).
    Box,
    /// Through the bounding polytope ([`super::polytope`]: the box with its edges and corners cut
    /// off), grown as the box is: the sphere's lines that meet it.
    Polytope,
}

impl LineBound {
    /// Every bound with its name.
    pub const NAMES: [(&'static str, LineBound); 3] = [
        ("sphere", LineBound::Sphere),
        ("box", LineBound::Box),
        ("polytope", LineBound::Polytope),
    ];

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            LineBound::Sphere => "sphere",
            LineBound::Box => "box",
            LineBound::Polytope => "polytope",
        }
    }

    /// Parses a name as printed by [`LineBound::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, b)| b)
    }
}

/// An axis-aligned box that lines are drawn through, with its faces' areas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingBox {
    lo: [f64; 3],
    hi: [f64; 3],
    /// The running sums of the faces' areas, in the order x-, x+, y-, y+, z-, z+.
    cumulative: [f64; 6],
    /// The faces, in the same order.
    faces: [Face; 6],
    /// How far before its face a line's traced segment starts (a thousandth of the box's diagonal).
    lead: f64,
}

/// One face of a [`BoundingBox`], as whole vectors, so that a line is made without indexing by axis.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Face {
    /// The running sum of the areas of the faces before it.
    start: f64,
    area: f64,
    /// Its lower corner, and its two sides as vectors (along the next axis, then the one after).
    corner: [f64; 3],
    side_b: [f64; 3],
    side_c: [f64; 3],
    /// The inward normal, and the unit vectors of its two sides.
    inward: [f64; 3],
    unit_b: [f64; 3],
    unit_c: [f64; 3],
}

impl Face {
    fn new(face: usize, lo: [f64; 3], hi: [f64; 3], start: f64) -> Self {
        let (axis, upper) = (face / 2, face % 2 == 1);
        let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
        let unit = |k: usize, length: f64| {
            let mut v = [0.0; 3];
            v[k] = length;
            v
        };
        let mut corner = lo;
        if upper {
            corner[axis] = hi[axis];
        }
        Face {
            start,
            area: (hi[b] - lo[b]) * (hi[c] - lo[c]),
            corner,
            side_b: unit(b, hi[b] - lo[b]),
            side_c: unit(c, hi[c] - lo[c]),
            inward: unit(axis, if upper { -1.0 } else { 1.0 }),
            unit_b: unit(b, 1.0),
            unit_c: unit(c, 1.0),
        }
    }
}

impl BoundingBox {
    /// The box from `lo` to `hi` (every `lo[k] < hi[k]`).
    pub fn new(lo: [f64; 3], hi: [f64; 3]) -> Self {
        let side = |k: usize| hi[k] - lo[k];
        let mut cumulative = [0.0; 6];
        let mut sum = 0.0;
        let mut faces = [Face::new(0, lo, hi, 0.0); 6];
        for (face, c) in cumulative.iter_mut().enumerate() {
            let axis = face / 2;
            faces[face] = Face::new(face, lo, hi, sum);
            sum += side((axis + 1) % 3) * side((axis + 2) % 3);
            *c = sum;
        }
        let lead = 1e-3 * (0..3).map(|k| side(k) * side(k)).sum::<f64>().sqrt();
        BoundingBox {
            lo,
            hi,
            cumulative,
            faces,
            lead,
        }
    }

    /// The box of `scene`'s triangles in tracing space, grown by [`BOX_MARGIN`] bounding radii.
    pub fn of(scene: &Scene) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for &v in scene.triangles.iter().flatten() {
            for (k, &x) in scene.positions[v as usize].iter().enumerate() {
                lo[k] = lo[k].min(f64::from(x));
                hi[k] = hi[k].max(f64::from(x));
            }
        }
        let grow = BOX_MARGIN * scene.bounding_radius();
        if !lo[0].is_finite() {
            // No triangle: any small box (its lines meet nothing).
            (lo, hi) = ([0.0; 3], [0.0; 3]);
        }
        BoundingBox::new(lo.map(|x| x - grow), hi.map(|x| x + grow))
    }

    /// The box's surface area.
    pub fn surface_area(&self) -> f64 {
        self.cumulative[5]
    }

    /// The measure of the lines that meet the box relative to those that meet a sphere of radius
    /// `radius`, `S_box / (4 pi R^2)` (Cauchy: the lines meeting a convex body are in proportion to its
    /// surface area): the share of the sphere's lines that meet the box when the box is inside the
    /// sphere, and more than 1 when it reaches out of it (an octahedron's box pokes out of its sphere).
    /// Either way, with both containing the scene, `n` lines through the box meet the scene as often as
    /// `n / share` through the sphere.
    pub fn share_of_sphere(&self, radius: f64) -> f64 {
        self.surface_area() / (4.0 * std::f64::consts::PI * radius * radius)
    }

    /// The line of the unit point `u`: `u[0]` chooses the face (in proportion to the faces' areas) and,
    /// rescaled within the face's share, the first coordinate on it, `u[1]` the second; `(u[2], u[3])`
    /// is mapped onto the unit disc (the concentric map, its sine and cosine the polynomials of
    /// the sphere's Sobol' lines) and lifted to the hemisphere about the face's inward normal, which
    /// makes the direction cosine-distributed. The traced segment runs from a little before the face
    /// (the box's lead) to as far beyond where the line leaves the box.
    pub fn line(&self, u: [f64; 4]) -> Line {
        let (dx, dy) = concentric_discs(&[2.0 * u[2] - 1.0], &[2.0 * u[3] - 1.0]);
        self.line_with_disc(u[0], u[1], (dx[0], dy[0]))
    }

    /// The lines of `units`, [`BoundingBox::line`] of each bit for bit, appended to `out`: made
    /// [`CHUNK`] at a time, stage by stage across the chunk (disc points, faces, entries, directions,
    /// exits), so that each stage's divisions, square roots and polynomial chains run side by side
    /// rather than one line's waiting on the last.
    pub fn lines(&self, units: &[[f64; 4]], out: &mut Vec<Line>) {
        out.reserve(units.len());
        for chunk in units.chunks(CHUNK) {
            self.chunk_lines(chunk, out);
        }
    }

    /// [`BoundingBox::lines`] of at most [`CHUNK`] points: the arithmetic of
    /// [`BoundingBox::line_with_disc`], operation for operation, on every lane (lanes past the
    /// chunk's end compute from zeros and are not kept).
    #[inline(never)]
    fn chunk_lines(&self, chunk: &[[f64; 4]], out: &mut Vec<Line>) {
        const N: usize = CHUNK;
        let mut u: [[f64; N]; 4] = [[0.0; N]; 4];
        for (i, p) in chunk.iter().enumerate() {
            for d in 0..4 {
                u[d][i] = p[d];
            }
        }
        let (dx, dy) = concentric_discs(&u[2].map(|x| 2.0 * x - 1.0), &u[3].map(|x| 2.0 * x - 1.0));
        let area = self.surface_area();
        let at = u[0].map(|x| x * area);
        let mut face = [0usize; N];
        for i in 0..N {
            face[i] = self.cumulative[..5].iter().filter(|&&c| c <= at[i]).count();
        }
        let mut s = [0.0; N];
        for i in 0..N {
            let f = &self.faces[face[i]];
            s[i] = ((at[i] - f.start) / f.area).clamp(0.0, 1.0);
        }
        let mut dz = [0.0; N];
        for i in 0..N {
            dz[i] = (1.0 - dx[i] * dx[i] - dy[i] * dy[i]).max(0.0).sqrt();
        }
        let (mut origin, mut dir) = ([[0.0; N]; 3], [[0.0; N]; 3]);
        for i in 0..N {
            let f = &self.faces[face[i]];
            for k in 0..3 {
                origin[k][i] = f.corner[k] + s[i] * f.side_b[k] + u[1][i] * f.side_c[k];
                dir[k][i] = dz[i] * f.inward[k] + dx[i] * f.unit_b[k] + dy[i] * f.unit_c[k];
            }
        }
        let mut exit = [f64::INFINITY; N];
        for k in 0..3 {
            for i in 0..N {
                let end = if dir[k][i] > 0.0 {
                    self.hi[k]
                } else {
                    self.lo[k]
                };
                let t = (end - origin[k][i]) / dir[k][i];
                exit[i] = exit[i].min(if t >= 0.0 { t } else { f64::INFINITY });
            }
        }
        let back = self.lead;
        for i in 0..chunk.len() {
            out.push(Line {
                origin: std::array::from_fn(|k| (origin[k][i] - back * dir[k][i]) as f32),
                dir: std::array::from_fn(|k| dir[k][i] as f32),
                t_max: (exit[i] + 2.0 * back) as f32,
            });
        }
    }

    /// [`BoundingBox::line`] once its direction's disc point is known.
    #[inline(always)]
    fn line_with_disc(&self, u0: f64, u1: f64, (dx, dy): (f64, f64)) -> Line {
        let at = u0 * self.surface_area();
        let face = &self.faces[self.cumulative.iter().take(5).filter(|&&c| c <= at).count()];
        let s = ((at - face.start) / face.area).clamp(0.0, 1.0);
        let origin: [f64; 3] =
            std::array::from_fn(|k| face.corner[k] + s * face.side_b[k] + u1 * face.side_c[k]);
        let dz = (1.0 - dx * dx - dy * dy).max(0.0).sqrt();
        let dir: [f64; 3] = std::array::from_fn(|k| {
            dz * face.inward[k] + dx * face.unit_b[k] + dy * face.unit_c[k]
        });
        // The traced segment starts a little before the face and ends a little beyond the exit: the box
        // lies a millionth of the radius off the walls, within a few f32 steps, and an f32 origin or
        // end on the face could round onto or past the wall the line enters or leaves by.
        let back = self.lead;
        let start: [f64; 3] = std::array::from_fn(|k| origin[k] - back * dir[k]);
        Line {
            origin: start.map(|x| x as f32),
            dir: dir.map(|x| x as f32),
            t_max: (self.exit(origin, dir) + 2.0 * back) as f32,
        }
    }

    /// Where the line from `origin` (on the box) along `dir` leaves the box: the least exit parameter
    /// through a face it heads towards, each chosen and bounded by selects rather than branches (a zero
    /// component gives an infinite or NaN parameter, which counts as no exit).
    #[inline(always)]
    fn exit(&self, origin: [f64; 3], dir: [f64; 3]) -> f64 {
        let mut t = f64::INFINITY;
        for k in 0..3 {
            let end = if dir[k] > 0.0 { self.hi[k] } else { self.lo[k] };
            let at = (end - origin[k]) / dir[k];
            t = t.min(if at >= 0.0 { at } else { f64::INFINITY });
        }
        t
    }
}

/// A convex region whose lines are made from points of the unit 4-cube: a face (by area) and a point on
/// it from the first two coordinates, a cosine-distributed direction into the region from the last two.
pub trait UnitLines {
    /// The lines of `units`, appended to `out`.
    fn lines(&self, units: &[[f64; 4]], out: &mut Vec<Line>);
}

impl UnitLines for BoundingBox {
    fn lines(&self, units: &[[f64; 4]], out: &mut Vec<Line>) {
        BoundingBox::lines(self, units, out);
    }
}

impl UnitLines for BoundingPolytope {
    fn lines(&self, units: &[[f64; 4]], out: &mut Vec<Line>) {
        BoundingPolytope::lines(self, units, out);
    }
}

/// Appends `count` independent lines through `bounds` to `out`, four draws of batch `batch`'s stream
/// ([`super::lines::batch_rng`]) per line: a batch's lines depend on `seed` and its index only.
pub fn batch_lines_through(
    seed: u64,
    batch: u64,
    count: usize,
    bounds: &impl UnitLines,
    out: &mut Vec<Line>,
) {
    out.reserve(count);
    batch_units(seed, batch, count, |units| bounds.lines(units, out));
}

/// Appends the lines through `bounds` of points `first..first + count` of group `group`'s randomised
/// Sobol' sequence (seed `seed`) to `out` (the points of [`super::lines::sobol_lines`]).
pub fn sobol_lines_through(
    seed: u64,
    group: u64,
    first: u64,
    count: usize,
    bounds: &impl UnitLines,
    out: &mut Vec<Line>,
) {
    out.reserve(count);
    let mut units = Vec::with_capacity(count);
    ScrambledSobol::new(seed, group).for_each_unit(first, count, |u| units.push(u));
    bounds.lines(&units, out);
}

/// How many lines through `scene`'s bounding sphere `lines` lines drawn as `bound` says are worth: as
/// many for the sphere, `lines / p` through the box or the polytope ([`share_of_sphere`]; fewer than
/// `lines` when it is the larger container).
pub fn sphere_lines(scene: &Scene, bound: LineBound, lines: u64) -> f64 {
    lines as f64 / share_of_sphere(scene, bound)
}

/// The measure of the lines drawn as `bound` says relative to those through `scene`'s bounding sphere:
/// 1 for the sphere, `S / (4 pi R^2)` for the box or the polytope (Cauchy).
pub fn share_of_sphere(scene: &Scene, bound: LineBound) -> f64 {
    let radius = scene.bounding_radius();
    match bound {
        LineBound::Sphere => 1.0,
        LineBound::Box => BoundingBox::of(scene).share_of_sphere(radius),
        LineBound::Polytope => BoundingPolytope::of(scene).share_of_sphere(radius),
    }
}

/// The count of lines through `scene`'s bounding sphere that a report gives for `drawn` lines drawn as
/// `bound` says: of the counts whose lines to draw ([`lines_to_draw`]) are exactly `drawn`, the
/// roundest (most trailing decimal zeros; the smallest of equals). Each is worth no more than the lines
/// drawn are, so the report's "as many as" holds for any of them. `--lines 1e6` through a cube's box
/// draws 636,620 lines, worth 1,000,000.4 sphere lines ([`sphere_lines`]): the report says 1000000,
/// the count asked, rather than 1000000 or 1000001 by rounding's luck. The count asked always draws
/// `drawn`, so the one given differs from it by at most the few counts that draw as many (one or two
/// for a box smaller than the sphere). A count no sphere count draws (a run stopped early through a
/// container larger than the sphere) gives its worth, rounded.
pub fn sphere_lines_of_drawn(scene: &Scene, bound: LineBound, drawn: u64) -> u64 {
    if bound == LineBound::Sphere {
        return drawn;
    }
    let worth = sphere_lines(scene, bound, drawn);
    let around = worth.floor() as u64;
    (around.saturating_sub(4)..=around.saturating_add(4))
        .filter(|&n| lines_to_draw(scene, bound, n) == drawn)
        .max_by_key(|&n| (trailing_decimal_zeros(n), std::cmp::Reverse(n)))
        .unwrap_or(worth.round() as u64)
}

/// The fewest lines through `scene`'s bounding sphere (the unit of `--lines`) whose run draws at least
/// `drawn` lines as `bound` says ([`lines_to_draw`]): how a count of lines drawn that a run needs (for
/// its batches, its groups) is given back to the user.
pub fn sphere_lines_for_drawn(scene: &Scene, bound: LineBound, drawn: u64) -> u64 {
    if bound == LineBound::Sphere {
        return drawn;
    }
    let mut n = sphere_lines(scene, bound, drawn).ceil() as u64;
    // The f64 worth is within a line or two of the count: walk to the fewest that draws enough.
    while n > 0 && lines_to_draw(scene, bound, n - 1) >= drawn {
        n -= 1;
    }
    while lines_to_draw(scene, bound, n) < drawn {
        n += 1;
    }
    n
}

/// How many decimal zeros end `n` (none for 0).
fn trailing_decimal_zeros(mut n: u64) -> u32 {
    let mut zeros = 0;
    while n > 0 && n % 10 == 0 {
        n /= 10;
        zeros += 1;
    }
    zeros
}

/// How many lines to draw as `bound` says for a run worth `sphere_lines` lines through `scene`'s
/// bounding sphere: as many through the sphere; through the box the fewest whose worth
/// ([`sphere_lines`]) is at least that many, `ceil(p * sphere_lines)` ([`BoundingBox::share_of_sphere`]),
/// and at least one. A line count asked of a run (`--lines`) is read in the sphere's lines, the paper's
/// unit, whatever the bound: the same count buys the same precision of the bound-free part of every
/// estimate, and through a box smaller than the sphere it costs less.
pub fn lines_to_draw(scene: &Scene, bound: LineBound, sphere_lines: u64) -> u64 {
    match bound {
        LineBound::Sphere => sphere_lines,
        LineBound::Box | LineBound::Polytope => {
            let drawn = (sphere_lines as f64 * share_of_sphere(scene, bound)).ceil();
            // Beyond 2^64 the f64 saturates on the cast; a run that long is capped anyway.
            (drawn as u64).max(u64::from(sphere_lines > 0))
        }
    }
}

/// The container the Sobol' sampler draws through on `scene` (`--lines-through auto`), by what was
/// measured (docs/sampling.md): the box when it is smaller than the sphere and within
/// [`BOX_PREFERENCE`] of the polytope (rooms: its rectangular faces align the walls with the sequence's
/// axes); else the polytope when it is smaller than the sphere and at least [`ON_FACES`] of the scene's
/// area lies in its faces' planes (solids such as the octahedron, whose faces it shares); else the
/// sphere (through which `sobol` gained more on curved objects and on solids or rooms turned off the
/// polytope's directions).
pub fn tightest_container(scene: &Scene) -> LineBound {
    let boxed = share_of_sphere(scene, LineBound::Box);
    let polytope = share_of_sphere(scene, LineBound::Polytope);
    if boxed < 1.0 && boxed <= BOX_PREFERENCE * polytope {
        LineBound::Box
    } else if polytope < 1.0 && share_of_area_on_faces(scene) >= ON_FACES {
        LineBound::Polytope
    } else {
        LineBound::Sphere
    }
}

/// The container independent lines are drawn through on `scene` (`--lines-through auto`): the smaller
/// of the box and the polytope when it is smaller than the sphere (the box when it is within
/// [`BOX_PREFERENCE`] of the polytope: its lines are cheaper to draw), else the sphere. Independent lines
/// through a container are distributed as the sphere's lines that meet it, so every estimate keeps its
/// distribution for the same `--lines`; the lines that would have missed the container, and so the
/// scene, are simply not drawn (docs/sampling.md, "Lines through the bounding box").
pub fn smallest_container(scene: &Scene) -> LineBound {
    let boxed = share_of_sphere(scene, LineBound::Box);
    let polytope = share_of_sphere(scene, LineBound::Polytope);
    if boxed < 1.0 && boxed <= BOX_PREFERENCE * polytope {
        LineBound::Box
    } else if polytope < 1.0 {
        LineBound::Polytope
    } else {
        LineBound::Sphere
    }
}

/// The share of a scene's area in the planes of its polytope's faces from which `auto` draws through
/// the polytope.
pub const ON_FACES: f64 = 0.5;

/// How much larger than the polytope the box may be and still be preferred (a room's box is its
/// polytope; an octahedron's box is 3.5 times its polytope).
pub const BOX_PREFERENCE: f64 = 1.1;

/// Where a run draws its lines: the bounding sphere's radius, or the bounding box.
#[derive(Clone, Debug, PartialEq)]
pub enum LineRegion {
    /// Through the sphere of this radius about the origin.
    Sphere(f64),
    /// Through this box (boxed: its faces are prepared, about a kilobyte).
    Box(std::boxed::Box<BoundingBox>),
    /// Through this polytope.
    Polytope(std::boxed::Box<BoundingPolytope>),
}

impl LineRegion {
    /// `scene`'s region for lines drawn as `bound` says.
    pub fn of(scene: &Scene, bound: LineBound) -> Self {
        match bound {
            LineBound::Sphere => LineRegion::Sphere(scene.bounding_radius()),
            LineBound::Box => LineRegion::Box(std::boxed::Box::new(BoundingBox::of(scene))),
            LineBound::Polytope => {
                LineRegion::Polytope(std::boxed::Box::new(BoundingPolytope::of(scene)))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::uniform01;
    use crate::sample::lines::batch_rng;
    use rand::RngCore;

    fn draw4(rng: &mut impl RngCore) -> [f64; 4] {
        [(); 4].map(|_| uniform01(rng))
    }

    /// A batch's lines through a box or a polytope are those of its stream's draws four at a time,
    /// [`BoundingBox::line`] and [`BoundingPolytope::line`] of each, bit for bit: for counts that fill no
    /// chunk of points, one, and several with a partial last one.
    #[test]
    fn batch_lines_are_the_lines_of_the_streams_draws() {
        let cube = BoundingBox::new(LO, HI);
        let octahedron = BoundingPolytope::of(&crate::scenes::load("@octahedron").unwrap());
        let bits = |l: &Line| {
            (
                l.origin.map(f32::to_bits),
                l.dir.map(f32::to_bits),
                l.t_max.to_bits(),
            )
        };
        for count in [0, 1, 3, 63, 64, 65, 1000] {
            for (seed, batch) in [(1, 0), (7, 12345)] {
                let mut rng = batch_rng(seed, batch);
                let units: Vec<[f64; 4]> = (0..count).map(|_| draw4(&mut rng)).collect();
                let (mut through_box, mut through_polytope) = (Vec::new(), Vec::new());
                batch_lines_through(seed, batch, count, &cube, &mut through_box);
                batch_lines_through(seed, batch, count, &octahedron, &mut through_polytope);
                assert_eq!(through_box.len(), count);
                assert_eq!(through_polytope.len(), count);
                for (k, u) in units.iter().enumerate() {
                    assert_eq!(bits(&through_box[k]), bits(&cube.line(*u)), "{count} {k}");
                    assert_eq!(
                        bits(&through_polytope[k]),
                        bits(&octahedron.line(*u)),
                        "{count} {k}"
                    );
                }
            }
        }
    }

    const LO: [f64; 3] = [-0.5, -1.0, 0.25];
    const HI: [f64; 3] = [0.5, 1.0, 3.25];

    /// A report's sphere lines for the lines a count draws through a cube's box or an octahedron's
    /// polytope are that count when it is round, and otherwise a count that draws the same lines,
    /// within two of it and worth no more than they are.
    #[test]
    fn reports_give_the_round_count_that_draws_the_lines() {
        for (spec, bound) in [
            ("@cube:4", LineBound::Box),
            ("@octahedron", LineBound::Polytope),
        ] {
            let scene = crate::scenes::load(spec).unwrap();
            for asked in [100_000u64, 1_000_000, 30_000_000, 2_000, 123_457, 1_001, 7] {
                let drawn = lines_to_draw(&scene, bound, asked);
                let given = sphere_lines_of_drawn(&scene, bound, drawn);
                assert_eq!(lines_to_draw(&scene, bound, given), drawn, "{spec} {asked}");
                assert!(given.abs_diff(asked) <= 2, "{spec}: {asked} gave {given}");
                assert!(
                    given as f64 <= sphere_lines(&scene, bound, drawn),
                    "{spec} {asked}"
                );
                if asked % 1000 == 0 {
                    assert_eq!(given, asked, "{spec}");
                }
            }
        }
        let cube = crate::scenes::load("@cube:4").unwrap();
        assert_eq!(
            sphere_lines_of_drawn(&cube, LineBound::Sphere, 12_345),
            12_345
        );
    }

    /// 2^16 lines through the box `LO..HI` from both samplers (independent: 16 batches; Sobol': the first
    /// points of group 0).
    fn both_samplers() -> [(&'static str, Vec<Line>); 2] {
        let b = BoundingBox::new(LO, HI);
        let mut independent = Vec::new();
        for batch in 0..16 {
            batch_lines_through(5, batch, 4096, &b, &mut independent);
        }
        let mut sobol = Vec::new();
        sobol_lines_through(5, 0, 0, 1 << 16, &b, &mut sobol);
        [("independent", independent), ("sobol", sobol)]
    }

    /// Where a line through the box `LO..HI` enters it, and its chord of the box: the traced segment
    /// reaches the box's lead beyond the chord at both ends.
    fn entry_and_chord(l: &Line) -> ([f64; 3], f64) {
        let lead = BoundingBox::new(LO, HI).lead;
        let (o, d) = (l.origin.map(f64::from), l.dir.map(f64::from));
        (
            [0, 1, 2].map(|k| o[k] + lead * d[k]),
            f64::from(l.t_max) - 2.0 * lead,
        )
    }

    fn on_the_surface(p: [f64; 3]) -> bool {
        let inside = (0..3).all(|k| p[k] >= LO[k] - 1e-6 && p[k] <= HI[k] + 1e-6);
        let on_a_face = (0..3).any(|k| (p[k] - LO[k]).abs() < 1e-6 || (p[k] - HI[k]).abs() < 1e-6);
        inside && on_a_face
    }

    /// Mean and standard error of the mean.
    fn mean_se(x: &[f64]) -> (f64, f64) {
        let n = x.len() as f64;
        let mean = x.iter().sum::<f64>() / n;
        let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        (mean, (var / n).sqrt())
    }

    /// Every line enters the box's surface (its traced segment starts the box's lead before it), has
    /// a unit direction into the box, and leaves by the surface again; the chords' mean is Cauchy's 4 V / S for uniformly distributed lines meeting a
    /// convex body (to 4 standard errors for independent lines; Sobol' lines, whose spread is not that
    /// of independent draws, to 1%).
    #[test]
    fn lines_cross_the_box_with_cauchys_mean_chord() {
        let side = |k: usize| HI[k] - LO[k];
        let volume = side(0) * side(1) * side(2);
        let area = 2.0 * (side(0) * side(1) + side(1) * side(2) + side(2) * side(0));
        assert!((BoundingBox::new(LO, HI).surface_area() - area).abs() < 1e-12);
        let cauchy = 4.0 * volume / area;
        for (name, lines) in both_samplers() {
            let mut chords = Vec::with_capacity(lines.len());
            for l in &lines {
                let (o, t) = entry_and_chord(l);
                let d = l.dir.map(f64::from);
                let norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                assert!((norm - 1.0).abs() < 1e-6, "{name}: {l:?}");
                assert!(on_the_surface(o), "{name}: entry {o:?} of {l:?}");
                let end = [0, 1, 2].map(|k| o[k] + t * d[k]);
                assert!(on_the_surface(end), "{name}: end {end:?} of {l:?}");
                let step = [0, 1, 2].map(|k| o[k] + 1e-3 * t * d[k]);
                assert!(
                    (0..3).all(|k| step[k] > LO[k] && step[k] < HI[k]),
                    "{name}: {l:?} does not head into the box"
                );
                chords.push(t);
            }
            let (mean, se) = mean_se(&chords);
            let tolerance = if name == "sobol" {
                0.01 * cauchy
            } else {
                4.0 * se
            };
            assert!(
                (mean - cauchy).abs() < tolerance,
                "{name}: mean chord {mean} (se {se}), Cauchy {cauchy}"
            );
        }
    }

    /// The faces are entered in proportion to their areas, and the directions are cosine-distributed
    /// about the inward normal: the cosine's mean is 2/3 and its square's 1/2.
    #[test]
    fn faces_by_area_and_directions_by_cosine() {
        let side = |k: usize| HI[k] - LO[k];
        let area = 2.0 * (side(0) * side(1) + side(1) * side(2) + side(2) * side(0));
        for (name, lines) in both_samplers() {
            let n = lines.len() as f64;
            let mut per_axis = [0.0; 3];
            let (mut cosines, mut squares) = (Vec::new(), Vec::new());
            for l in &lines {
                let (o, _) = entry_and_chord(l);
                let axis = (0..3)
                    .find(|&k| (o[k] - LO[k]).abs() < 1e-6 || (o[k] - HI[k]).abs() < 1e-6)
                    .unwrap();
                per_axis[axis] += 1.0;
                let c = f64::from(l.dir[axis]).abs();
                cosines.push(c);
                squares.push(c * c);
            }
            for (axis, count) in per_axis.iter().enumerate() {
                let p = 2.0 * side((axis + 1) % 3) * side((axis + 2) % 3) / area;
                let se = (p * (1.0 - p) / n).sqrt();
                assert!(
                    (count / n - p).abs() < 4.5 * se,
                    "{name}: axis {axis}: {count}"
                );
            }
            for (x, exact) in [(&cosines, 2.0 / 3.0), (&squares, 0.5)] {
                let (mean, se) = mean_se(x);
                assert!(
                    (mean - exact).abs() < 4.5 * se,
                    "{name}: {mean} against {exact}"
                );
            }
        }
    }

    /// A box's share of the lines through a sphere about it is its surface over the sphere's (a cube
    /// inscribed in the unit sphere: 6 (2 / sqrt 3)^2 / (4 pi) = 2 / pi).
    #[test]
    fn an_inscribed_cube_meets_two_lines_in_pi() {
        let h = 1.0 / 3f64.sqrt();
        let cube = BoundingBox::new([-h; 3], [h; 3]);
        let share = cube.share_of_sphere(1.0);
        assert!(
            (share - 2.0 / std::f64::consts::PI).abs() < 1e-12,
            "{share}"
        );
    }

    /// Lines made 16 at a time are [`BoundingBox::line`]'s one at a time, bit for bit: full and partial
    /// chunks, the disc's centre and diagonals, the ends of [0, 1) and every face.
    #[test]
    fn lines_made_in_chunks_are_the_lines_made_one_by_one() {
        let b = BoundingBox::new(LO, HI);
        let mut rng = batch_rng(11, 0);
        let mut units: Vec<[f64; 4]> = (0..5003).map(|_| draw4(&mut rng)).collect();
        let below_one = 1.0 - f64::EPSILON / 2.0;
        for edge in [0.0, 0.5, 0.25, 0.75, below_one] {
            for face in 0..6 {
                units.push([(face as f64 + 0.5) / 6.0, edge, edge, 0.5]);
                units.push([(face as f64 + 0.5) / 6.0, edge, 0.5, edge]);
                units.push([edge, 0.5, edge, 1.0 - edge]);
            }
        }
        let mut chunked = Vec::new();
        b.lines(&units, &mut chunked);
        let one_by_one: Vec<Line> = units.iter().map(|&u| b.line(u)).collect();
        assert_eq!(chunked.len(), one_by_one.len());
        for (k, (x, y)) in chunked.iter().zip(&one_by_one).enumerate() {
            let bits = |l: &Line| {
                (
                    l.origin.map(f32::to_bits),
                    l.dir.map(f32::to_bits),
                    l.t_max.to_bits(),
                )
            };
            assert_eq!(bits(x), bits(y), "unit {k}: {:?}", units[k]);
        }
    }

    /// The straightforward construction, coordinate by coordinate: the face by the running areas, the
    /// entry and direction by axis index, the exit by the faces the line heads towards, and the traced
    /// segment reaching the lead beyond both.
    fn reference_line(b: &BoundingBox, u: [f64; 4]) -> ([f64; 3], [f64; 3], f64) {
        let at = u[0] * b.surface_area();
        let face = (0..5).filter(|&f| b.cumulative[f] <= at).count();
        let before = if face == 0 {
            0.0
        } else {
            b.cumulative[face - 1]
        };
        let s = ((at - before) / (b.cumulative[face] - before)).clamp(0.0, 1.0);
        let (axis, upper) = (face / 2, face % 2 == 1);
        let (j, k) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut origin = [0.0; 3];
        origin[axis] = if upper { b.hi[axis] } else { b.lo[axis] };
        origin[j] = b.lo[j] + s * (b.hi[j] - b.lo[j]);
        origin[k] = b.lo[k] + u[1] * (b.hi[k] - b.lo[k]);
        let (dx, dy) = concentric_discs(&[2.0 * u[2] - 1.0], &[2.0 * u[3] - 1.0]);
        let (dx, dy) = (dx[0], dy[0]);
        let dz = (1.0 - dx * dx - dy * dy).max(0.0).sqrt();
        let mut dir = [0.0; 3];
        dir[axis] = if upper { -dz } else { dz };
        dir[j] = dx;
        dir[k] = dy;
        let t = (0..3)
            .filter(|&a| dir[a] != 0.0)
            .map(|a| ((if dir[a] > 0.0 { b.hi[a] } else { b.lo[a] }) - origin[a]) / dir[a])
            .filter(|t| *t >= 0.0)
            .fold(f64::INFINITY, f64::min);
        // The traced segment: from the lead before the face to the lead beyond the exit.
        let start = [0, 1, 2].map(|k| origin[k] - b.lead * dir[k]);
        (start, dir, t + 2.0 * b.lead)
    }

    /// [`BoundingBox::line`] (whole face vectors, exits by selects) is the reference construction:
    /// equal origins, directions and exits, over random points and the special ones.
    #[test]
    fn lines_are_the_reference_construction() {
        let b = BoundingBox::new(LO, HI);
        let mut rng = batch_rng(12, 3);
        let mut units: Vec<[f64; 4]> = (0..20_000).map(|_| draw4(&mut rng)).collect();
        let below_one = 1.0 - f64::EPSILON / 2.0;
        for edge in [0.0, 0.5, below_one] {
            for face in 0..6 {
                let u0 = (face as f64 + edge.min(0.999)) / 6.0;
                units.push([u0, edge, edge, edge]);
                units.push([u0, edge, 0.5, 0.0]);
                units.push([u0, 1.0 - edge, 0.0, 0.5]);
            }
        }
        for u in units {
            let line = b.line(u);
            let (origin, dir, t) = reference_line(&b, u);
            assert_eq!(line.origin, origin.map(|x| x as f32), "{u:?}");
            assert_eq!(line.dir, dir.map(|x| x as f32), "{u:?}");
            assert_eq!(line.t_max, t as f32, "{u:?}");
        }
    }

    #[test]
    fn bounds_have_names() {
        for (name, b) in LineBound::NAMES {
            assert_eq!(b.name(), name);
            assert_eq!(LineBound::from_name(name), Some(b));
        }
        assert_eq!(LineBound::from_name("cube"), None);
        assert_eq!(LineBound::default(), LineBound::Sphere);
    }
}
