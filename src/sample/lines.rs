//! Uniformly distributed global lines through the bounding sphere (paper sec. 2.1.1, fig. 1b).
//!
//! A line is drawn as a uniform direction on the unit sphere, then a uniform point on the disc of radius
//! R through the sphere's centre and perpendicular to that direction. Lines drawn so are uniformly
//! distributed in the invariant measure of integral geometry: the number hitting a convex patch is
//! proportional to its area (Crofton: a planar patch of area A is met by a fraction A / (2 pi R^2) of them).
//!
//! Randomness: PCG-64 (`rand_pcg::Pcg64`, a fixed algorithm, so its output never changes with crate
//! versions) with one *stream* per batch of lines, seeded from `(seed, batch index)`. A batch's lines are
//! therefore the same whatever thread draws them, and results never depend on the number of threads.
//! Independent lines ([`batch_lines`]) make that stream's draws in blocks (`pcg_lanes`), bit for bit the
//! draws of `Pcg64`, and so the very lines [`global_line`] draws from [`batch_rng`], only faster.
//!
//! Randomised quasi-Monte Carlo ([`Sampler::Sobol`], [`sobol_lines`]): the same construction from the
//! points of an Owen-scrambled 4D Sobol' sequence ([`super::sobol`]) instead of independent draws, two
//! coordinates for the direction and two for the point on the disc. Each point is uniform, so each line
//! is a uniformly distributed global line; together a sequence's lines cover the space of lines more
//! evenly than independent ones.

mod pcg_lanes;

use rand::RngCore;
use rand_pcg::Pcg64;

use super::sobol::{splitmix64, ScrambledSobol};
use crate::geom::{orthonormal_basis, uniform01, unit_from_draw, DVec3};
use crate::trace::Line;
use pcg_lanes::{PcgLanes, LANES};

/// The traced segment reaches this factor beyond the bounding sphere on both sides, so that f32 rounding
/// never clips a vertex lying exactly on the sphere.
const SPHERE_MARGIN: f64 = 1.001;

/// The random stream for one batch of lines.
pub fn batch_rng(seed: u64, batch: u64) -> Pcg64 {
    let (state, stream) = batch_stream(seed, batch);
    Pcg64::new(state, stream)
}

/// The arguments of `Pcg64::new` for batch `batch`'s stream (shared by [`batch_rng`] and
/// [`batch_lines`], so that both always draw the same stream).
fn batch_stream(seed: u64, batch: u64) -> (u128, u128) {
    let state =
        (u128::from(splitmix64(seed)) << 64) | u128::from(splitmix64(seed ^ 0x5eed_5eed_5eed_5eed));
    (state, u128::from(batch))
}

/// Appends the `count` lines of batch `batch` to `out` (tracing space, bounding radius `radius`).
///
/// The lines are those of [`global_line`] called `count` times on [`batch_rng`], bit for bit; only
/// faster, drawing in blocks and without the rejection loops' branches (see `DiscPoints`).
pub fn batch_lines(seed: u64, batch: u64, count: usize, radius: f64, out: &mut Vec<Line>) {
    let (state, stream) = batch_stream(seed, batch);
    let mut points = DiscPoints::new(PcgLanes::new(state, stream));
    out.reserve(count);
    let mut left = count;
    while left > 0 {
        let lines = left.min(CHUNK_LINES);
        points.top_up(2 * lines);
        lines_from_points(&points.kept[..2 * lines], radius, out);
        points.drop_front(2 * lines);
        left -= lines;
    }
}

/// Calls `visit` with the unit points of batch `batch`'s stream, `count` in all and [`UNIT_CHUNK`] at a
/// time (the last chunk shorter): four draws per point, each [`unit_from_draw`]. Bit for bit the points
/// of `[uniform01(rng); 4]` called point after point on [`batch_rng`], only drawn in blocks (`pcg_lanes`)
/// and without a buffer of the whole batch.
pub(super) fn batch_units(seed: u64, batch: u64, count: usize, mut visit: impl FnMut(&[[f64; 4]])) {
    let (state, stream) = batch_stream(seed, batch);
    let mut lanes = PcgLanes::new(state, stream);
    let mut draws = [0u64; 4 * UNIT_CHUNK];
    let mut units = [[0.0f64; 4]; UNIT_CHUNK];
    let mut left = count;
    while left > 0 {
        let n = left.min(UNIT_CHUNK);
        // Four draws per point: always whole rounds of the lanes.
        lanes.fill(&mut draws[..4 * n]);
        for (unit, d) in units.iter_mut().zip(draws.chunks_exact(4)).take(n) {
            *unit = std::array::from_fn(|k| unit_from_draw(d[k]));
        }
        visit(&units[..n]);
        left -= n;
    }
}

/// Unit points made at a time by [`batch_units`]: a whole number of the containers' chunks of 16 lines
/// ([`super::bounds::BoundingBox::lines`], [`super::polytope::BoundingPolytope::lines`]), few
/// enough that the draws and points stay in L1.
const UNIT_CHUNK: usize = 64;

// A point's four draws are whole rounds of the lanes, and the chunks are whole chunks of the discs'.
const _: () = assert!(4 % LANES == 0 && UNIT_CHUNK % 16 == 0);

/// Appends the lines of consecutive pairs of disc points ([`line_from_discs`]). A function of its own,
/// called once per [`CHUNK_LINES`] lines, so that profiles name the drawing's arithmetic.
#[inline(never)]
fn lines_from_points(points: &[DiscPoint], radius: f64, out: &mut Vec<Line>) {
    for pair in points.chunks_exact(2) {
        out.push(line_from_discs(pair[0], pair[1], radius));
    }
}

/// Lines made from the points kept at a time: enough to amortise a refill, few enough that the points
/// stay in L1.
const CHUNK_LINES: usize = 32;

/// Draws made at a time: whole rounds of the lanes, an even number (a candidate point takes two).
const BLOCK_DRAWS: usize = 16 * LANES;

/// Room for kept points: fewer than `2 * CHUNK_LINES` before a block, and at most a block's candidates.
const KEPT_ROOM: usize = 2 * CHUNK_LINES + BLOCK_DRAWS / 2;

/// A point of the unit disc and its squared radius, as [`point_in_unit_disc`] returns them.
type DiscPoint = (f64, f64, f64);

/// The points that [`point_in_unit_disc`] would return, call after call, from one stream.
///
/// [`global_line`]'s two calls take draws two at a time: pair after pair until one lands in the disc. So
/// the stream is a sequence of candidate points (draws `2i`, `2i + 1`), and the points returned are the
/// accepted candidates in order, whichever call asked for them: line `j` takes accepted points `2j` and
/// `2j + 1`. Here the candidates of a block are all tested and the accepted ones written one after the
/// other (each candidate is written, and the count advances by the test's result): no branch to
/// mispredict on the 21% rejected, and the draws of a block come from independent lanes.
struct DiscPoints {
    /// The stream.
    lanes: PcgLanes,
    /// A block of draws.
    draws: [u64; BLOCK_DRAWS],
    /// Accepted points not yet used, in order (`kept[..len]`).
    kept: [DiscPoint; KEPT_ROOM],
    /// Number of points in `kept`.
    len: usize,
}

impl DiscPoints {
    /// No points yet, draws from `lanes`.
    fn new(lanes: PcgLanes) -> Self {
        DiscPoints {
            lanes,
            draws: [0; BLOCK_DRAWS],
            kept: [(0.0, 0.0, 0.0); KEPT_ROOM],
            len: 0,
        }
    }

    /// Draws blocks until at least `want` (at most `2 * CHUNK_LINES`) points are kept.
    fn top_up(&mut self, want: usize) {
        debug_assert!(want <= 2 * CHUNK_LINES);
        while self.len < want {
            self.draw_block();
        }
    }

    /// One block of draws: its candidates tested in order, the accepted ones appended to `kept`.
    fn draw_block(&mut self) {
        self.lanes.fill(&mut self.draws);
        // A local count: kept in a register, not stored and reloaded between candidates.
        let mut len = self.len;
        for pair in self.draws.chunks_exact(2) {
            // Exactly `point_in_unit_disc`'s arithmetic.
            let x = 2.0 * unit_from_draw(pair[0]) - 1.0;
            let y = 2.0 * unit_from_draw(pair[1]) - 1.0;
            let s = x * x + y * y;
            self.kept[len] = (x, y, s);
            len += usize::from(s < 1.0);
        }
        self.len = len;
    }

    /// Forgets the first `used` kept points.
    fn drop_front(&mut self, used: usize) {
        self.kept.copy_within(used..self.len, 0);
        self.len -= used;
    }
}

/// How a run's lines are drawn: independently of each other, or as randomised quasi-Monte Carlo
/// points (docs/sampling.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampler {
    /// Independent lines from one PCG stream per batch ([`batch_lines`], or bundles as
    /// [`LineSource`] says).
    #[default]
    Independent,
    /// One Owen-scrambled Sobol' sequence per standard-error group ([`sobol_lines`]): batch `b` of a run
    /// of G groups takes the points `k * batch_size ..` of group `b mod G`'s sequence, `k = b / G` its
    /// index within the group. The groups stay independent replicates (independent scrambles); the lines
    /// within a group do not, so only the groups' spread measures the error.
    Sobol,
}

impl Sampler {
    /// Every sampler with its name.
    pub const NAMES: [(&'static str, Sampler); 2] = [
        ("independent", Sampler::Independent),
        ("sobol", Sampler::Sobol),
    ];

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Sampler::Independent => "independent",
            Sampler::Sobol => "sobol",
        }
    }

    /// Parses a name as printed by [`Sampler::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, s)| s)
    }
}

/// Appends the lines of points `first..first + count` of group `group`'s randomised Sobol' sequence
/// (seed `seed`) to `out`, tracing space, bounding radius `radius`: each point `(u1, u2, u3, u4)` is the
/// line of direction `(u1, u2)` (Archimedes: `z = 1 - 2 u1`, azimuth `2 pi u2`) through the point
/// `(u3, u4)` of the disc perpendicular to it (the concentric map), built as [`global_line`] builds its
/// lines.
pub fn sobol_lines(
    seed: u64,
    group: u64,
    first: u64,
    count: usize,
    radius: f64,
    out: &mut Vec<Line>,
) {
    out.reserve(count);
    let mut units = [[0.0; 4]; UNITS_AT_A_TIME];
    let mut held = 0;
    ScrambledSobol::new(seed, group).for_each_unit(first, count, |u| {
        units[held] = u;
        held += 1;
        if held == UNITS_AT_A_TIME {
            lines_from_units(&units, radius, out);
            held = 0;
        }
    });
    lines_from_units(&units[..held], radius, out);
}

/// Points made into lines at a time by [`lines_from_units`].
const UNITS_AT_A_TIME: usize = 16;

/// The global lines of unit points (see [`sobol_lines`]), stage by stage over all of them, each stage a
/// loop over arrays: the polynomials are long chains of dependent operations, which overlap (and share
/// vector registers) when the points' chains are computed side by side rather than a line at a time.
/// The arithmetic of each line is that of [`turn`] and [`concentric_disc_polynomial`], operation for
/// operation.
#[inline]
fn lines_from_units(units: &[[f64; 4]], radius: f64, out: &mut Vec<Line>) {
    const N: usize = UNITS_AT_A_TIME;
    let column = |d: usize| {
        let mut c = [0.0; N];
        c.iter_mut().zip(units).for_each(|(c, u)| *c = u[d]);
        c
    };
    let (s, azimuth, a, b) = (column(0), column(1), column(2), column(3));
    // Marsaglia's disc point with squared radius u1 and angle 2 pi u2 gives the direction of z = 1 - 2 u1
    // and azimuth 2 pi u2: uniform on the sphere when u1 and u2 are uniform.
    let (cos, sin) = turns(&azimuth);
    let (a, b) = (a.map(|a| 2.0 * a - 1.0), b.map(|b| 2.0 * b - 1.0));
    let (px, py) = concentric_discs(&a, &b);
    for i in 0..units.len() {
        let r = s[i].sqrt();
        let direction = (r * cos[i], r * sin[i], s[i]);
        let point = (px[i], py[i], px[i] * px[i] + py[i] * py[i]);
        out.push(line_from_discs(direction, point, radius));
    }
}

/// [`turn`] of each of `t`, without a branch: the quarter selects operands and signs.
#[inline(always)]
fn turns<const N: usize>(t: &[f64; N]) -> ([f64; N], [f64; N]) {
    use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2};
    let mut x = [0.0; N];
    let mut quarter = [0u64; N];
    for i in 0..N {
        let quarters = 4.0 * t[i];
        // `floor` for 0 <= quarters < 4.
        let q = quarters as u8;
        quarter[i] = u64::from(q);
        x[i] = (quarters - f64::from(q) - 0.5) * FRAC_PI_2;
    }
    let (s, c) = sin_cos_small_all(&x);
    let (mut cos, mut sin) = ([0.0; N], [0.0; N]);
    for i in 0..N {
        let (c, s) = (FRAC_1_SQRT_2 * (c[i] - s[i]), FRAC_1_SQRT_2 * (c[i] + s[i]));
        // Quarters 0..4 give (c, s), (-s, c), (-c, -s), (s, -c).
        let q = quarter[i];
        let swap = q & 1 == 1;
        let (first, second) = if swap { (s, c) } else { (c, s) };
        let negate_first = ((q ^ (q >> 1)) & 1) << 63;
        let negate_second = ((q >> 1) & 1) << 63;
        cos[i] = f64::from_bits(first.to_bits() ^ negate_first);
        sin[i] = f64::from_bits(second.to_bits() ^ negate_second);
    }
    (cos, sin)
}

/// [`concentric_disc_polynomial`] of each `(a[i], b[i])`.
#[inline(always)]
pub(super) fn concentric_discs<const N: usize>(a: &[f64; N], b: &[f64; N]) -> ([f64; N], [f64; N]) {
    use std::f64::consts::FRAC_PI_4;
    let (mut major, mut x) = ([0.0; N], [0.0; N]);
    let mut a_major = [false; N];
    for i in 0..N {
        a_major[i] = a[i].abs() > b[i].abs();
        let (big, small) = (
            select(a_major[i], a[i], b[i]),
            select(a_major[i], b[i], a[i]),
        );
        major[i] = big;
        x[i] = FRAC_PI_4 * (small / big);
    }
    let (s, c) = sin_cos_small_all(&x);
    let (mut px, mut py) = ([0.0; N], [0.0; N]);
    for i in 0..N {
        // For |b| >= |a| the angle is pi/2 - x: its cosine is sin x, its sine cos x.
        let (cos, sin) = (
            select(a_major[i], c[i], s[i]),
            select(a_major[i], s[i], c[i]),
        );
        // The centre (0 / 0 above) maps to itself.
        let centre = a[i] == 0.0 && b[i] == 0.0;
        px[i] = if centre { 0.0 } else { major[i] * cos };
        py[i] = if centre { 0.0 } else { major[i] * sin };
    }
    (px, py)
}

/// `if take_a { a } else { b }` by masks on the bits rather than a branch: a side chosen by a random
/// point's octant is mispredicted half the time, and the masks keep the lanes of a chunk in step.
#[inline(always)]
pub(super) fn select(take_a: bool, a: f64, b: f64) -> f64 {
    let mask = (take_a as u64).wrapping_neg();
    f64::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

/// [`sin_cos_small`] of each of `x`.
#[inline(always)]
fn sin_cos_small_all<const N: usize>(x: &[f64; N]) -> ([f64; N], [f64; N]) {
    let (mut s, mut c) = ([0.0; N], [0.0; N]);
    for i in 0..N {
        (s[i], c[i]) = sin_cos_small(x[i]);
    }
    (s, c)
}

/// `(cos 2 pi t, sin 2 pi t)` for `t` in [0, 1), a point at a time: the reference [`turns`] must equal
/// bit for bit. The quarter turn and the angle within it are exact (`4 t` splits exactly), the angle's
/// sine and cosine by [`sin_cos_small`].
#[cfg(test)]
fn turn(t: f64) -> (f64, f64) {
    use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2};
    let quarters = 4.0 * t;
    let q = quarters.floor();
    // The angle is q pi/2 + pi/4 + x, |x| <= pi/4.
    let x = (quarters - q - 0.5) * FRAC_PI_2;
    let (s, c) = sin_cos_small(x);
    let (c, s) = (FRAC_1_SQRT_2 * (c - s), FRAC_1_SQRT_2 * (c + s));
    match q as u8 & 3 {
        0 => (c, s),
        1 => (-s, c),
        2 => (-c, -s),
        _ => (s, -c),
    }
}

/// `(sin x, cos x)` for `|x| <= pi/4` by their Taylor polynomials to x^13 and x^14 (truncation error
/// below 3e-14, far below the f32 a traced line is rounded to): `f64::sin_cos` costs about as much as
/// the rest of a line.
#[inline(always)]
fn sin_cos_small(x: f64) -> (f64, f64) {
    /// `(-1)^k / (2k + 1)!` and `(-1)^k / (2k)!`, k = 0..=6 and 0..=7.
    const SIN: [f64; 7] = taylor(1);
    const COS: [f64; 8] = taylor(0);
    let x2 = x * x;
    let sin = SIN.iter().rev().fold(0.0, |acc, &k| acc * x2 + k) * x;
    let cos = COS.iter().rev().fold(0.0, |acc, &k| acc * x2 + k);
    (sin, cos)
}

/// The Taylor coefficients `(-1)^k / (2k + first)!` of sine (`first` 1) or cosine (0).
const fn taylor<const N: usize>(first: u32) -> [f64; N] {
    let mut out = [0.0; N];
    let mut factorial = 1.0;
    let mut n = 1;
    while n <= first {
        factorial *= n as f64;
        n += 1;
    }
    let mut k = 0;
    while k < N {
        out[k] = if k % 2 == 0 { 1.0 } else { -1.0 } / factorial;
        // The next coefficient's factorial: two more factors.
        factorial *= (n * (n + 1)) as f64;
        n += 2;
        k += 1;
    }
    out
}

/// [`concentric_disc`] with the angle's sine and cosine by [`sin_cos_small`] (the angle is within
/// pi/4 of an axis): the same map to within 1e-13.
#[inline(always)]
#[cfg(test)]
fn concentric_disc_polynomial(a: f64, b: f64) -> (f64, f64) {
    use std::f64::consts::FRAC_PI_4;
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    if a.abs() > b.abs() {
        let (s, c) = sin_cos_small(FRAC_PI_4 * (b / a));
        (a * c, a * s)
    } else {
        // The angle pi/2 - x: its cosine is sin x, its sine cos x.
        let (s, c) = sin_cos_small(FRAC_PI_4 * (a / b));
        (b * s, b * c)
    }
}

/// Where a run's lines come from: independent global lines, or bundles of parallel ones.
///
/// Either way every line is a uniformly distributed global line (its marginal law is the invariant
/// measure), so every estimate stays unbiased; bundles make the lines of one bundle correlated, which the
/// standard errors see because a batch always holds whole bundles (see [`LineSource::lines_per_unit`]) and
/// the standard-error groups are made of whole batches.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LineSource {
    /// Every line drawn on its own ([`global_line`]).
    #[default]
    Independent,
    /// Bundles of `grid x grid` parallel lines ([`bundle_lines`]).
    Bundles {
        /// Lines per side of a bundle's grid, 1 to [`MAX_BUNDLE_GRID`].
        grid: u32,
    },
}

/// A bundle grid beyond [`MAX_BUNDLE_GRID`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "a bundle grid of {grid} x {grid} lines: need 0 (independent lines) to {}",
    MAX_BUNDLE_GRID
)]
pub struct BundleError {
    /// The grid asked for.
    pub grid: u32,
}

/// The largest bundle grid: 64 x 64 = 4096 lines, the largest batch.
pub const MAX_BUNDLE_GRID: u32 = 64;

impl LineSource {
    /// Bundles of `grid x grid` lines, or independent lines for `grid == 0`; errors beyond
    /// [`MAX_BUNDLE_GRID`].
    pub fn bundles(grid: u32) -> Result<Self, BundleError> {
        match grid {
            0 => Ok(LineSource::Independent),
            1..=MAX_BUNDLE_GRID => Ok(LineSource::Bundles { grid }),
            _ => Err(BundleError { grid }),
        }
    }

    /// The lines drawn together: 1 for independent lines, `grid^2` for bundles. Batches (and so the
    /// standard-error groups) hold whole units, never part of a bundle.
    pub fn lines_per_unit(&self) -> u64 {
        match *self {
            LineSource::Independent => 1,
            LineSource::Bundles { grid } => u64::from(grid) * u64::from(grid),
        }
    }

    /// Appends the `count` lines of batch `batch` to `out`; `count` must be a whole number of units
    /// (bundles), as [`crate::run::BatchPlan::for_source`] makes it.
    pub fn batch_lines(
        &self,
        seed: u64,
        batch: u64,
        count: usize,
        radius: f64,
        out: &mut Vec<Line>,
    ) {
        match *self {
            LineSource::Independent => batch_lines(seed, batch, count, radius, out),
            LineSource::Bundles { grid } => {
                let mut rng = batch_rng(seed, batch);
                let per = (grid * grid) as usize;
                debug_assert_eq!(count % per, 0, "batches hold whole bundles");
                for _ in 0..count / per {
                    bundle_lines(&mut rng, grid, radius, out);
                }
            }
        }
    }
}

/// Appends one bundle of `grid x grid` parallel global lines: a uniform direction, then one uniform point
/// in each cell of a `grid x grid` grid over the square [-1, 1]^2, carried onto the disc of radius
/// `radius` perpendicular to the direction by the concentric map of Shirley and Chiu (1997).
///
/// Why this is unbiased: the concentric map preserves area fractions, so a point uniform in a cell of the
/// square lands uniformly in the cell's image, and the images of the cells tile the disc with equal areas.
/// Each line is therefore a uniform point of the disc on a uniform direction: a uniformly distributed
/// global line, exactly as [`global_line`] draws them. The bundle is a stratified (jittered) sample of the
/// disc, with exactly `grid^2` lines (rejecting the points of a square grid that fall outside the disc
/// would make the count random, and bundles could then not fill batches exactly).
///
/// The lines come in Morton (Z) order of their cells, so 4, 8 or 16 consecutive lines are neighbours:
/// packets of adjacent parallel lines, which Embree traces coherently.
pub fn bundle_lines(rng: &mut impl RngCore, grid: u32, radius: f64, out: &mut Vec<Line>) {
    let (x, y, s) = point_in_unit_disc(rng);
    let k = 2.0 * (1.0 - s).sqrt();
    let dir = DVec3::new(x * k, y * k, 1.0 - 2.0 * s);
    let (e1, e2) = orthonormal_basis(dir);
    let reach = radius * SPHERE_MARGIN;
    let cell = 2.0 / f64::from(grid);
    let side = grid.next_power_of_two();
    for code in 0..side * side {
        let (i, j) = morton_decode(code);
        if i >= grid || j >= grid {
            continue;
        }
        let a = -1.0 + cell * (f64::from(i) + uniform01(rng));
        let b = -1.0 + cell * (f64::from(j) + uniform01(rng));
        let (px, py) = concentric_disc(a, b);
        out.push(line_through(radius * (px * e1 + py * e2), dir, reach));
    }
}

/// The cell `(i, j)` whose Morton code (bits of `i` at even, of `j` at odd positions) is `code`.
fn morton_decode(code: u32) -> (u32, u32) {
    let compact = |mut v: u32| {
        v &= 0x5555_5555;
        v = (v | (v >> 1)) & 0x3333_3333;
        v = (v | (v >> 2)) & 0x0f0f_0f0f;
        v = (v | (v >> 4)) & 0x00ff_00ff;
        (v | (v >> 8)) & 0x0000_ffff
    };
    (compact(code), compact(code >> 1))
}

/// Shirley and Chiu's concentric map, "A low distortion map between disk and square" (JGT 1997): the
/// square [-1, 1]^2 onto the unit disc, area-preserving (up to the constant pi / 4) and continuous.
pub fn concentric_disc(a: f64, b: f64) -> (f64, f64) {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, FRAC_PI_4 * (b / a))
    } else {
        (b, FRAC_PI_2 - FRAC_PI_4 * (a / b))
    };
    let (s, c) = phi.sin_cos();
    (r * c, r * s)
}

/// One uniformly distributed global line through the sphere of radius `radius` centred at the origin.
///
/// Both draws use rejection from the unit disc instead of trigonometry (sin/cos cost more than the
/// 4/pi expected tries): Marsaglia's method for the direction, then the disc point itself.
pub fn global_line(rng: &mut impl RngCore, radius: f64) -> Line {
    let direction = point_in_unit_disc(rng);
    let point = point_in_unit_disc(rng);
    line_from_discs(direction, point, radius)
}

/// The global line of [`global_line`] from its two points of the unit disc: `direction` becomes the
/// direction, `point` the point on the disc of radius `radius` perpendicular to it.
#[inline(always)]
fn line_from_discs(direction: DiscPoint, point: DiscPoint, radius: f64) -> Line {
    let (x, y, s) = direction;
    // Marsaglia (1972): (2x sqrt(1-s), 2y sqrt(1-s), 1-2s) is uniform on the sphere.
    let k = 2.0 * (1.0 - s).sqrt();
    let dir = DVec3::new(x * k, y * k, 1.0 - 2.0 * s);
    let (e1, e2) = orthonormal_basis(dir);
    let (px, py, _) = point;
    let reach = radius * SPHERE_MARGIN;
    line_through(radius * (px * e1 + py * e2), dir, reach)
}

/// The traced line through `point` (on the disc through the centre) along the unit `dir`, from `reach`
/// before that point to `reach` beyond it, rounded to f32.
fn line_through(point: DVec3, dir: DVec3, reach: f64) -> Line {
    Line {
        origin: (point - reach * dir).as_vec3().to_array(),
        dir: dir.as_vec3().to_array(),
        t_max: (2.0 * reach) as f32,
    }
}

/// A point uniform in the unit disc, by rejection from the square, and its squared radius.
fn point_in_unit_disc(rng: &mut impl RngCore) -> DiscPoint {
    loop {
        let x = 2.0 * uniform01(rng) - 1.0;
        let y = 2.0 * uniform01(rng) - 1.0;
        let s = x * x + y * y;
        if s < 1.0 {
            return (x, y, s);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batches_are_reproducible_and_distinct() {
        let mut a = Vec::new();
        let mut b = Vec::new();
        let mut c = Vec::new();
        batch_lines(7, 3, 16, 1.0, &mut a);
        batch_lines(7, 3, 16, 1.0, &mut b);
        batch_lines(7, 4, 16, 1.0, &mut c);
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    /// The straightforward path: `global_line` on `Pcg64`, line after line.
    fn reference_lines(seed: u64, batch: u64, count: usize, radius: f64) -> Vec<Line> {
        let mut rng = batch_rng(seed, batch);
        (0..count).map(|_| global_line(&mut rng, radius)).collect()
    }

    /// `batch_lines`'s blocks give the reference's lines bit for bit (`Line`'s equality compares f32s,
    /// and then their bits), for counts on and off the chunk and block sizes: 10^5+ lines.
    #[test]
    fn batch_lines_are_the_reference_lines_bit_for_bit() {
        let counts = [
            0, 1, 2, 3, 31, 32, 33, 63, 64, 65, 127, 255, 256, 257, 1000, 4095, 4096,
        ];
        let mut total = 0;
        for seed in [0, 1, 7, 0x5eed, u64::MAX] {
            for batch in [0, 1, 2, 1234, u64::MAX] {
                for (i, &count) in counts.iter().enumerate() {
                    let radius = [1.0, 37.25, 1e-3][i % 3];
                    let expected = reference_lines(seed, batch, count, radius);
                    let mut lines = reference_lines(seed, batch ^ 1, 2, radius);
                    batch_lines(seed, batch, count, radius, &mut lines);
                    assert_eq!(lines.len(), 2 + count, "appends");
                    assert_eq!(
                        &lines[2..],
                        &expected[..],
                        "seed {seed} batch {batch} count {count}"
                    );
                    let bits = |l: &Line| {
                        let all = [l.origin, l.dir, [l.t_max; 3]];
                        all.map(|v| v.map(f32::to_bits))
                    };
                    assert!(lines[2..]
                        .iter()
                        .zip(&expected)
                        .all(|(a, b)| bits(a) == bits(b)));
                    total += count;
                }
            }
        }
        assert!(total >= 100_000, "{total} lines compared");
    }

    #[test]
    fn morton_order_visits_every_cell_once() {
        let mut seen = std::collections::HashSet::new();
        for code in 0..64 * 64 {
            let (i, j) = morton_decode(code);
            assert!(i < 64 && j < 64 && seen.insert((i, j)));
        }
        assert_eq!(morton_decode(0b1110), (0b10, 0b11));
    }

    /// Equal area: the concentric images of a square's quarters by area are the disc's, and points
    /// land in rings with the ring's share of the disc's area.
    #[test]
    fn concentric_map_preserves_area_fractions() {
        let n = 200usize;
        let mut ring = [0usize; 4];
        for i in 0..n {
            for j in 0..n {
                let a = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                let b = -1.0 + 2.0 * (j as f64 + 0.5) / n as f64;
                let (x, y) = concentric_disc(a, b);
                let r2 = x * x + y * y;
                assert!(r2 <= 1.0 + 1e-12);
                ring[((r2 * 4.0) as usize).min(3)] += 1;
            }
        }
        for count in ring {
            let share = count as f64 / (n * n) as f64;
            assert!((share - 0.25).abs() < 0.01, "{ring:?}");
        }
    }

    #[test]
    fn bundles_are_parallel_and_fill_batches() {
        let source = LineSource::bundles(8).unwrap();
        assert_eq!(source.lines_per_unit(), 64);
        let mut lines = Vec::new();
        source.batch_lines(3, 2, 192, 1.0, &mut lines);
        assert_eq!(lines.len(), 192);
        for bundle in lines.chunks(64) {
            assert!(bundle.iter().all(|l| l.dir == bundle[0].dir));
        }
        assert_ne!(lines[0].dir, lines[64].dir);
        assert_eq!(LineSource::bundles(0), Ok(LineSource::Independent));
        assert!(LineSource::bundles(65).is_err());
    }

    #[test]
    fn lines_span_the_sphere() {
        let mut lines = Vec::new();
        batch_lines(1, 0, 1000, 1.0, &mut lines);
        assert_lines_cross_the_unit_sphere(&lines);
    }

    /// Each line has a unit direction and runs from outside the unit sphere to outside it on the other
    /// side.
    fn assert_lines_cross_the_unit_sphere(lines: &[Line]) {
        for l in lines {
            let d = l.dir.map(f64::from);
            let o = l.origin.map(f64::from);
            let dn = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            assert!((dn - 1.0).abs() < 1e-6);
            // The origin is outside the unit sphere and the segment ends outside it on the other side.
            let on = (o[0] * o[0] + o[1] * o[1] + o[2] * o[2]).sqrt();
            assert!(on >= 1.0);
            let end = [0, 1, 2].map(|a| o[a] + l.t_max as f64 * d[a]);
            assert!((end[0] * end[0] + end[1] * end[1] + end[2] * end[2]).sqrt() >= 1.0);
        }
    }

    /// The chord of a line through the axis-aligned cube of centre `c` and half-side `h` (0 when it
    /// misses), by the slab method.
    fn chord_in_box(l: &Line, c: [f64; 3], h: f64) -> f64 {
        let o = l.origin.map(f64::from);
        let d = l.dir.map(f64::from);
        let (mut t0, mut t1) = (0.0f64, f64::from(l.t_max));
        for a in 0..3 {
            let (lo, hi) = ((c[a] - h - o[a]) / d[a], (c[a] + h - o[a]) / d[a]);
            t0 = t0.max(lo.min(hi));
            t1 = t1.min(lo.max(hi));
        }
        (t1 - t0).max(0.0)
    }

    /// The mean and standard error over groups of `f`'s mean per line, for the lines of 16 groups.
    fn over_groups(lines_of: impl Fn(u64) -> Vec<Line>, f: impl Fn(&Line) -> f64) -> (f64, f64) {
        let means: Vec<f64> = (0..16)
            .map(|g| {
                let lines = lines_of(g);
                lines.iter().map(&f).sum::<f64>() / lines.len() as f64
            })
            .collect();
        let mean = means.iter().sum::<f64>() / 16.0;
        let var = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / 15.0;
        (mean, (var / 16.0).sqrt())
    }

    #[test]
    fn sobol_lines_span_the_sphere_and_are_reproducible() {
        let mut lines = Vec::new();
        sobol_lines(1, 0, 0, 1000, 1.0, &mut lines);
        assert_lines_cross_the_unit_sphere(&lines);
        let mut again = Vec::new();
        sobol_lines(1, 0, 500, 500, 1.0, &mut again);
        assert_eq!(
            &lines[500..],
            &again[..],
            "a batch is its stretch of the sequence"
        );
        let mut other = Vec::new();
        sobol_lines(1, 1, 0, 1000, 1.0, &mut other);
        assert!(
            lines.iter().zip(&other).all(|(a, b)| a != b),
            "groups differ"
        );
    }

    /// Crofton and Cauchy with randomised QMC lines, for a cube off the sphere's centre: the share of
    /// lines that meet it is its surface over the sphere's, S / (4 pi R^2), and the mean chord per line
    /// is V / (pi R^2) (so the mean chord of the lines that meet it is 4V/S). Each to 4.5 standard errors
    /// of the 16 independent groups; and the groups scatter less than those of independent lines (the
    /// sequence is low-discrepancy; fixed seeds, so no chance in it).
    #[test]
    fn sobol_lines_are_uniformly_distributed() {
        let (c, h) = ([0.1, -0.05, 0.02], 0.3);
        let n = 1 << 14;
        let sobol = |g| {
            let mut v = Vec::new();
            sobol_lines(3, g, 0, n, 1.0, &mut v);
            v
        };
        let independent = |g| {
            let mut v = Vec::new();
            batch_lines(3, g, n, 1.0, &mut v);
            v
        };
        let hit = |l: &Line| f64::from(u8::from(chord_in_box(l, c, h) > 0.0));
        let chord = |l: &Line| chord_in_box(l, c, h);
        let (surface, volume) = (6.0 * (2.0 * h) * (2.0 * h), (2.0 * h).powi(3));
        let pi = std::f64::consts::PI;
        for (name, f, exact) in [
            ("hits", &hit as &dyn Fn(&Line) -> f64, surface / (4.0 * pi)),
            ("chord", &chord, volume / pi),
        ] {
            let (mean, se) = over_groups(sobol, f);
            assert!(
                (mean - exact).abs() < 4.5 * se,
                "{name}: {mean} +- {se}, exact {exact}"
            );
            let (_, se_independent) = over_groups(independent, f);
            assert!(
                se < se_independent / 2.0,
                "{name}: se {se} vs {se_independent}"
            );
        }
    }

    /// The global line of one unit point, a point at a time (the code the Sobol' lines were first made
    /// with): the reference for [`lines_from_units`].
    fn line_from_unit(u: [f64; 4], radius: f64) -> Line {
        let s = u[0];
        let (cos, sin) = turn(u[1]);
        let r = s.sqrt();
        let direction = (r * cos, r * sin, s);
        let (px, py) = concentric_disc_polynomial(2.0 * u[2] - 1.0, 2.0 * u[3] - 1.0);
        line_from_discs(direction, (px, py, px * px + py * py), radius)
    }

    /// Lines made stage by stage over many points are those made a point at a time, bit for bit: on a
    /// stretch of the scrambled sequence (whole and partial chunks), and on points at the quarter turns,
    /// the disc's centre and its diagonals (where |a| = |b|), and the ends of [0, 1).
    #[test]
    fn lines_made_side_by_side_are_the_lines_made_one_by_one() {
        let below_one = 1.0 - f64::EPSILON / 2.0;
        let special = [
            0.0, 0.25, 0.5, 0.75, below_one, 0.125, 0.375, 0.625, 0.875, 1e-300,
        ];
        let mut units = Vec::new();
        for &x in &special {
            for &y in &special {
                units.push([x, y, x, y]);
                units.push([y, x, 0.5, y]);
                units.push([x, y, y, 1.0 - y]);
            }
        }
        ScrambledSobol::new(9, 3).for_each_unit(1000, 20_000, |u| units.push(u));
        for radius in [1.0, 37.5] {
            let expected: Vec<Line> = units.iter().map(|&u| line_from_unit(u, radius)).collect();
            for len in [units.len(), 5, UNITS_AT_A_TIME, UNITS_AT_A_TIME + 3] {
                let mut got = Vec::new();
                for chunk in units[..len].chunks(UNITS_AT_A_TIME) {
                    lines_from_units(chunk, radius, &mut got);
                }
                let bits = |l: &Line| {
                    (
                        l.origin.map(f32::to_bits),
                        l.dir.map(f32::to_bits),
                        l.t_max.to_bits(),
                    )
                };
                for (k, (g, e)) in got.iter().zip(&expected[..len]).enumerate() {
                    assert_eq!(bits(g), bits(e), "unit {k}: {:?}", units[k]);
                }
                assert_eq!(got.len(), len);
            }
            let mut batch = Vec::new();
            sobol_lines(9, 3, 1000, 20_000, radius, &mut batch);
            assert_eq!(batch, expected[expected.len() - 20_000..], "sobol_lines");
        }
    }

    /// The polynomial sines and cosines of the Sobol' lines against the library's, on a fine grid and
    /// at the ends of every quarter.
    #[test]
    fn polynomial_trigonometry_matches_the_library() {
        let tau = std::f64::consts::TAU;
        let mut worst = 0.0f64;
        for k in 0..=100_000 {
            let t = (k as f64 / 100_000.0).min(1.0 - f64::EPSILON);
            let (c, s) = turn(t);
            let (s0, c0) = (tau * t).sin_cos();
            worst = worst.max((c - c0).abs()).max((s - s0).abs());
        }
        for q in 0..4 {
            let t = q as f64 / 4.0;
            let (c, s) = turn(t);
            let (s0, c0) = (tau * t).sin_cos();
            worst = worst.max((c - c0).abs()).max((s - s0).abs());
        }
        for i in -200..=200 {
            for j in -200..=200 {
                let (a, b) = (i as f64 / 200.0, j as f64 / 200.0);
                let (x, y) = concentric_disc_polynomial(a, b);
                let (x0, y0) = concentric_disc(a, b);
                worst = worst.max((x - x0).abs()).max((y - y0).abs());
            }
        }
        assert!(worst < 1e-13, "{worst}");
    }
}
