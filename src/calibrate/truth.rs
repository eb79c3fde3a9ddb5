//! The exact values ("truth") of the calibration scenes: every measure the suite judges, from exact form
//! factors and exact pair integrals, never from lines.
//!
//! * `@cube:N`: form factors in closed form ([`super::rectangles`]); the cube's symmetry maps every face
//!   onto face 0, so the rows of face 0 suffice for H_s (eq. 17), I_s (eq. 21) and E(MSE) (eq. 22).
//! * the regular solids (`@tetrahedron:k` ...): form factors by quadrature of the kernel over every pair
//!   of patches ([`super::kernel`]); every two points of different faces of a convex solid see each other.
//! * I_s^c (eq. 25, estimated by eq. 27) depends on the geometry only: `I_s^c = (1 / A_T) sum_(i != j)
//!   int int K log2(A_T K)` over ordered pairs of faces, taken by quadrature over the faces; for the cube
//!   by the hand reductions of [`super::rectangles`] (the triangle quadrature is checked against them).
//! * the open scenes (two squares) and the cube with a flipped face: exact values under both readings of
//!   a scene whose rows do not sum to 1 ([`Basis`]), so that the table shows which one the program
//!   follows (since its "one footing" change, per area for every measure) and how far off the other is.
//! * the cube with an emitting face: the radiosity system solved on the exact form factors, and the
//!   measures of sec. 4 (eqs. 33-35) of that solution.

use rayon::prelude::*;

use super::kernel::{pair_integral, Integrand, KernelError, Precision, Triangle};
use super::rectangles::{
    form_factor_row, parallel_squares_integral, perpendicular_squares_integral, AxisRect,
};
use super::scenes::CalibrationScene;
use crate::measure::radiosity::{self, FormFactors, PatchMaterials, SolveOptions};
use crate::measure::Measure;
use crate::scene::{Scene, SceneError};

/// How a measure is normalised when segments leaving a front side arrive at no front side (they escape
/// an open scene, or reach a face from behind).
///
/// In a closed scene every row of F sums to 1, `sum_ij A_i F_ij = A_T`, and both readings coincide.
/// Otherwise eq. (25) can be read as written, every pair weighted `1 / A_T` (and eqs. 17 and 21 with the
/// geometric form factors of eq. 3, rows summing to 1 less what is lost), or as the channel of the pairs
/// that were seen (each row renormalised to 1, the input distribution `A_i sum_j F_ij`, and eq. 27's
/// mean over the visible pairs). Both are computed so that the table shows which one the program
/// follows, and how far the other is: a wrong footing shows as a mean z far from 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Basis {
    /// A closed scene: one exact value.
    Closed,
    /// Eq. (25) with `1 / A_T`; eqs. (17), (21), (22) with the rows of eq. (3): the program's footing
    /// (it counts the lost segments in each row `N_i` and in eq. (27)'s denominator).
    PerArea,
    /// The channel of the visible pairs.
    PerVisiblePair,
}

impl Basis {
    /// The name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Basis::Closed => "closed",
            Basis::PerArea => "per area",
            Basis::PerVisiblePair => "per visible pair",
        }
    }
}

/// One exact value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExactValue {
    /// The measure.
    pub measure: Measure,
    /// Under which reading.
    pub basis: Basis,
    /// The value (bits, or lines for E(MSE)).
    pub value: f64,
}

/// The exact values of a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Truth {
    /// The scene's name.
    pub scene: String,
    /// Every exact value known.
    pub values: Vec<ExactValue>,
}

impl Truth {
    /// The exact values of `measure` (one per basis).
    pub fn of(&self, measure: Measure) -> impl Iterator<Item = &ExactValue> {
        self.values.iter().filter(move |v| v.measure == measure)
    }

    /// The exact value of `measure` under `basis`.
    pub fn value(&self, measure: Measure, basis: Basis) -> Option<f64> {
        self.of(measure).find(|v| v.basis == basis).map(|v| v.value)
    }
}

/// Why the exact values of a scene could not be computed.
#[derive(Debug, thiserror::Error)]
pub enum TruthError {
    /// The scene could not be built.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A pair of patches the quadrature cannot take.
    #[error("{scene}: {source}")]
    Kernel {
        /// The scene.
        scene: String,
        /// What went wrong.
        source: KernelError,
    },
    /// Too many patches for a dense matrix of exact form factors.
    #[error("{scene}: {patches} patches; exact form factors are computed for at most {MAX_DENSE_PATCHES}")]
    TooManyPatches {
        /// The scene.
        scene: String,
        /// Its patches.
        patches: usize,
    },
    /// The radiosity system on the exact form factors has no solution.
    #[error("{scene}: the radiosity system on the exact form factors failed: {message}")]
    Radiosity {
        /// The scene.
        scene: String,
        /// The solver's message.
        message: String,
    },
}

/// The most patches whose form factors are held as a dense matrix (the cube's own symmetry lifts it).
pub const MAX_DENSE_PATCHES: usize = 2000;

/// Exact form factors as dense rows: `rows[i][j] = F_ij`.
pub type FormFactorRows = Vec<Vec<f64>>;

/// The exact values of a calibration scene.
pub fn truth(scene: &CalibrationScene) -> Result<Truth, TruthError> {
    let values = match *scene {
        CalibrationScene::Cube(n) => closed_values(cube_discrete(n)?, cube_pair_sums()),
        CalibrationScene::Solid(..) => solid_values(scene)?,
        CalibrationScene::ParallelSquares { distance, .. } => {
            open_values(&scene.build()?, squares_pair_sums(Some(distance)))?
        }
        CalibrationScene::PerpendicularSquares { .. } => {
            open_values(&scene.build()?, squares_pair_sums(None))?
        }
        CalibrationScene::FlippedCube(n) => flipped_cube_values(&scene.build()?, n)?,
        CalibrationScene::LitCube(n) => {
            let mut values = closed_values(cube_discrete(n)?, cube_pair_sums());
            values.extend(radiosity_values(&scene.build()?)?);
            values
        }
    };
    Ok(Truth {
        scene: scene.name(),
        values,
    })
}

/// The discrete measures of a set of exact form factors (sec. 3.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscreteExact {
    /// Eq. (17).
    pub entropy: f64,
    /// H(X, Y) (eq. 7): `H_p + H_s` in a closed scene; over the rows' mass on patches otherwise.
    pub joint_entropy: f64,
    /// Eq. (21).
    pub mutual_information: f64,
    /// Eq. (22) times the lines, `n_p - sum_ij F_ij^2` (`None` under a basis it has no reading in).
    pub mse_per_line: Option<f64>,
}

/// `-x log2 x` with `0 log 0 = 0`.
fn neg_xlog2x(x: f64) -> f64 {
    if x > 0.0 {
        -x * x.log2()
    } else {
        0.0
    }
}

/// Eqs. (17), (21) and (22) with `a_i = A_i / A_T` and the rows as given (they may sum to less than 1:
/// the escapes are no patch), as the program reads an open scene ([`Basis::PerArea`]).
pub fn discrete_per_area(areas: &[f64], rows: &[Vec<f64>]) -> DiscreteExact {
    let total: f64 = areas.iter().sum();
    let a: Vec<f64> = areas.iter().map(|x| x / total).collect();
    let (mut entropy, mut joint_entropy, mut mutual_information, mut sum_f2) = (0.0, 0.0, 0.0, 0.0);
    for (&a_i, row) in a.iter().zip(rows) {
        for (&f, &a_j) in row.iter().zip(&a) {
            if f > 0.0 {
                entropy += a_i * neg_xlog2x(f);
                joint_entropy += neg_xlog2x(a_i * f);
                mutual_information += a_i * f * (f / a_j).log2();
                sum_f2 += f * f;
            }
        }
    }
    DiscreteExact {
        entropy,
        joint_entropy,
        mutual_information,
        mse_per_line: Some(a.len() as f64 - sum_f2),
    }
}

/// Eqs. (17) and (21) of the channel of the visible pairs ([`Basis::PerVisiblePair`]): input
/// `p_i ~ A_i sum_j F_ij`, rows renormalised to 1 (by reciprocity the output distribution is `p` too).
pub fn discrete_per_visible_pair(areas: &[f64], rows: &[Vec<f64>]) -> DiscreteExact {
    let sums: Vec<f64> = rows.iter().map(|r| r.iter().sum()).collect();
    let weights: Vec<f64> = areas.iter().zip(&sums).map(|(a, s)| a * s).collect();
    let total: f64 = weights.iter().sum();
    let p: Vec<f64> = weights.iter().map(|w| w / total).collect();
    let (mut entropy, mut joint_entropy, mut mutual_information) = (0.0, 0.0, 0.0);
    for ((&p_i, row), &sum) in p.iter().zip(rows).zip(&sums) {
        for (&f, &p_j) in row.iter().zip(&p) {
            let q = if sum > 0.0 { f / sum } else { 0.0 };
            if q > 0.0 {
                entropy += p_i * neg_xlog2x(q);
                joint_entropy += neg_xlog2x(p_i * q);
                mutual_information += p_i * q * (q / p_j).log2();
            }
        }
    }
    DiscreteExact {
        entropy,
        joint_entropy,
        mutual_information,
        mse_per_line: None,
    }
}

/// The sums over ordered pairs of faces behind eq. (25): `int int K` (`sum_ij A_i F_ij`, the visible
/// pairs' measure), `int int K log2 K`, and the scene's area `A_T`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairSums {
    /// `sum_(i != j) int_i int_j K`.
    pub kernel: f64,
    /// `sum_(i != j) int_i int_j K log2 K`.
    pub kernel_log: f64,
    /// `A_T`.
    pub total_area: f64,
}

impl PairSums {
    /// `sum int int K log2(A_T K)`.
    fn numerator(&self) -> f64 {
        self.total_area.log2() * self.kernel + self.kernel_log
    }

    /// Eq. (25) as written: the pairs weighted `1 / A_T`.
    pub fn per_area(&self) -> f64 {
        self.numerator() / self.total_area
    }

    /// Eq. (25) as the mean over the visible pairs (what eq. 27 averages).
    pub fn per_visible_pair(&self) -> f64 {
        self.numerator() / self.kernel
    }
}

/// The exact values of a closed scene: every row sums to 1, one basis.
fn closed_values(discrete: DiscreteExact, sums: PairSums) -> Vec<ExactValue> {
    visibility_values(Basis::Closed, discrete, sums.per_area())
}

/// H_s, H(X, Y), I_s (plug-in and corrected share their exact value: the correction changes the
/// estimator, not the estimand), I_s^c, the accuracies, the relative error and E(MSE) under one basis.
fn visibility_values(basis: Basis, d: DiscreteExact, continuous: f64) -> Vec<ExactValue> {
    let mut out = Vec::new();
    let mut push = |measure, value| {
        out.push(ExactValue {
            measure,
            basis,
            value,
        })
    };
    let accuracy = d.mutual_information / continuous;
    push(Measure::Entropy, d.entropy);
    push(Measure::EntropyCorrected, d.entropy);
    push(Measure::JointEntropy, d.joint_entropy);
    push(Measure::MutualInformation, d.mutual_information);
    push(Measure::MutualInformationCorrected, d.mutual_information);
    push(Measure::ContinuousMutualInformation, continuous);
    push(Measure::Accuracy, accuracy);
    push(Measure::AccuracyCorrected, accuracy);
    push(Measure::RelativeError, 1.0 - accuracy);
    if let Some(mse) = d.mse_per_line {
        push(Measure::MsePerLine, mse);
        push(Measure::MsePerLineCorrected, mse);
    }
    out
}

/// The exact values of an open scene under both bases.
fn open_values(scene: &Scene, sums: PairSums) -> Result<Vec<ExactValue>, TruthError> {
    let (areas, rows) = rectangle_form_factors(scene)?;
    Ok(both_bases(&areas, &rows, sums))
}

/// Both readings of a scene whose rows need not sum to 1.
fn both_bases(areas: &[f64], rows: &[Vec<f64>], sums: PairSums) -> Vec<ExactValue> {
    let mut values = visibility_values(
        Basis::PerArea,
        discrete_per_area(areas, rows),
        sums.per_area(),
    );
    values.extend(visibility_values(
        Basis::PerVisiblePair,
        discrete_per_visible_pair(areas, rows),
        sums.per_visible_pair(),
    ));
    values
}

/// The rectangles of a scene's patches and their exact form factors, dense (every patch an
/// axis-aligned rectangle; rectangles see each other unless coplanar).
fn rectangle_form_factors(scene: &Scene) -> Result<(Vec<f64>, FormFactorRows), TruthError> {
    let n = scene.patch_count();
    if n > MAX_DENSE_PATCHES {
        return Err(TruthError::TooManyPatches {
            scene: scene.name.clone(),
            patches: n,
        });
    }
    let rects: Vec<AxisRect> = (0..n)
        .map(|p| {
            AxisRect::of_patch(scene, p).ok_or_else(|| {
                SceneError::Builtin(format!(
                    "{}: patch {p} is not an axis-aligned rectangle",
                    scene.name
                ))
            })
        })
        .collect::<Result<_, _>>()?;
    let rows = (0..n)
        .into_par_iter()
        .map(|i| form_factor_row(&rects, i))
        .collect();
    Ok((rects.iter().map(AxisRect::area).collect(), rows))
}

/// Gauss–Legendre nodes per dimension of the smooth integral over parallel squares (converged to
/// rounding well before; see the tests).
const PARALLEL_NODES: usize = 48;

/// Tanh–sinh level of the integrals over perpendicular squares.
const PERPENDICULAR_LEVEL: u32 = 5;

/// Eq. (25)'s sums for two unit squares: facing each other at `distance`, or (`None`) at a right angle
/// along a common edge. Both ordered pairs count.
fn squares_pair_sums(distance: Option<f64>) -> PairSums {
    let integral = |g| match distance {
        Some(c) => parallel_squares_integral(c, g, PARALLEL_NODES),
        None => perpendicular_squares_integral(g, PERPENDICULAR_LEVEL),
    };
    PairSums {
        kernel: 2.0 * integral(Integrand::Kernel),
        kernel_log: 2.0 * integral(Integrand::KernelLog),
        total_area: 2.0,
    }
}

/// The integrals over one ordered pair of unit squares: `(int int K, int int K log2 K)`, parallel at
/// distance 1 and perpendicular.
fn unit_square_integrals() -> ((f64, f64), (f64, f64)) {
    let parallel = (
        parallel_squares_integral(1.0, Integrand::Kernel, PARALLEL_NODES),
        parallel_squares_integral(1.0, Integrand::KernelLog, PARALLEL_NODES),
    );
    let perpendicular = (
        perpendicular_squares_integral(Integrand::Kernel, PERPENDICULAR_LEVEL),
        perpendicular_squares_integral(Integrand::KernelLog, PERPENDICULAR_LEVEL),
    );
    (parallel, perpendicular)
}

/// Eq. (25)'s sums for the unit cube: each of its 6 faces sees 4 perpendicular faces and 1 parallel one.
pub fn cube_pair_sums() -> PairSums {
    let ((k_par, l_par), (k_perp, l_perp)) = unit_square_integrals();
    PairSums {
        kernel: 6.0 * (4.0 * k_perp + k_par),
        kernel_log: 6.0 * (4.0 * l_perp + l_par),
        total_area: 6.0,
    }
}

/// The largest `n` of `@cube:n` whose exact values calibrate computes: face 0's rows are `6 n^4` closed-form
/// factors (6 x 10^8 at 100, a minute or two on two cores), and the count grows as the fourth power.
pub const MAX_CUBE_DIVISIONS: usize = 100;

/// Whether the exact values of `scene` (built as `built`) are within what [`truth`] computes: `@cube:n`
/// and `lit-cube:n` up to [`MAX_CUBE_DIVISIONS`], every other scene (and `lit-cube`'s radiosity) up to
/// [`MAX_DENSE_PATCHES`] patches. Checked before a calibration starts, so that a scene too large is
/// refused at once rather than after the work of the cells before it.
pub fn check_computable(scene: &CalibrationScene, built: &Scene) -> Result<(), TruthError> {
    let dense = || {
        if built.patch_count() > MAX_DENSE_PATCHES {
            return Err(TruthError::TooManyPatches {
                scene: built.name.clone(),
                patches: built.patch_count(),
            });
        }
        Ok(())
    };
    match *scene {
        CalibrationScene::Cube(n) => Ok(cube_within_limit(n)?),
        CalibrationScene::LitCube(n) => {
            cube_within_limit(n)?;
            dense()
        }
        _ => dense(),
    }
}

/// Errors when `@cube:n`'s exact values are beyond [`MAX_CUBE_DIVISIONS`].
fn cube_within_limit(n: usize) -> Result<(), SceneError> {
    if n > MAX_CUBE_DIVISIONS {
        return Err(SceneError::Builtin(format!(
            "@cube:{n}: its exact values need 6 n^4 = {:.1e} closed-form factors; calibrate computes \
             them for @cube:N up to N = {MAX_CUBE_DIVISIONS}",
            6.0 * (n as f64).powi(4)
        )));
    }
    Ok(())
}

/// Face 0's rows computed and consumed this many at a time: the memory stays a few rows' worth (a
/// row of `@cube:100` is 60,000 factors) instead of all `n^2` of them.
const CUBE_ROWS_AT_ONCE: usize = 64;

/// Eqs. (17), (7), (21) and (22) of `@cube:n` from the rows of face 0: every patch has the same area and
/// the cube's symmetry maps every face onto face 0, so H_s is the mean row entropy of face 0,
/// H(X, Y) = H_p + H_s, I_s = H_p - H_s (eq. 20) and `sum_ij F_ij^2` is 6 times face 0's share.
///
/// Errors when `n` is above [`MAX_CUBE_DIVISIONS`].
pub fn cube_discrete(n: usize) -> Result<DiscreteExact, SceneError> {
    cube_within_limit(n)?;
    let scene = crate::scenes::load(&format!("@cube:{n}"))?;
    let rects: Vec<AxisRect> = (0..scene.patch_count())
        .map(|p| AxisRect::of_patch(&scene, p).expect("@cube:N has square patches"))
        .collect();
    let row_entropy = |row: &Vec<f64>| row.iter().map(|&f| neg_xlog2x(f)).sum::<f64>();
    // Summed in row order, one entry after the other, as one pass over every row would.
    let (mut entropy_sum, mut sum_f2) = (0.0, 0.0);
    let face: Vec<usize> = (0..n * n).collect();
    for chunk in face.chunks(CUBE_ROWS_AT_ONCE) {
        let rows: Vec<Vec<f64>> = chunk
            .par_iter()
            .map(|&i| form_factor_row(&rects, i))
            .collect();
        for row in &rows {
            entropy_sum += row_entropy(row);
            sum_f2 = row.iter().fold(sum_f2, |acc, f| acc + f * f);
        }
    }
    let entropy = entropy_sum / (n * n) as f64;
    let patches = scene.patch_count();
    let positional_entropy = (patches as f64).log2();
    Ok(DiscreteExact {
        entropy,
        joint_entropy: positional_entropy + entropy,
        mutual_information: positional_entropy - entropy,
        mse_per_line: Some(patches as f64 - 6.0 * sum_f2),
    })
}

/// The patches of a scene as triangles (each polygon fanned from its first corner), scene units.
fn patch_triangles(scene: &Scene) -> Vec<Vec<Triangle>> {
    scene
        .patches
        .iter()
        .map(|p| {
            let c: Vec<_> = scene
                .polygon(p)
                .iter()
                .map(|&v| scene.vertices[v as usize])
                .collect();
            (1..c.len() - 1)
                .map(|k| Triangle::new([c[0], c[k], c[k + 1]]))
                .collect()
        })
        .collect()
}

/// `sum int int g(K)` over every pair of triangles of two patches.
fn patch_pair_integral(
    first: &[Triangle],
    second: &[Triangle],
    integrand: Integrand,
    precision: Precision,
) -> Result<f64, KernelError> {
    let mut sum = 0.0;
    for t1 in first {
        for t2 in second {
            sum += pair_integral(t1, t2, integrand, precision)?;
        }
    }
    Ok(sum)
}

/// The exact form factors of a scene of flat convex patches on the boundary of a convex solid, seen
/// from inside (every two points of different planes see each other), by quadrature; with the patch
/// areas (scene units).
pub fn convex_form_factors(
    scene: &Scene,
    precision: Precision,
) -> Result<(Vec<f64>, FormFactorRows), TruthError> {
    let n = scene.patch_count();
    if n > MAX_DENSE_PATCHES {
        return Err(TruthError::TooManyPatches {
            scene: scene.name.clone(),
            patches: n,
        });
    }
    let triangles = patch_triangles(scene);
    let areas: Vec<f64> = triangles
        .iter()
        .map(|ts| ts.iter().map(Triangle::area).sum())
        .collect();
    let kernel_error = |source| TruthError::Kernel {
        scene: scene.name.clone(),
        source,
    };
    // A_i F_ij for i < j, by rows; reciprocity gives the rest.
    let upper: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map(|i| {
            ((i + 1)..n)
                .map(|j| {
                    patch_pair_integral(&triangles[i], &triangles[j], Integrand::Kernel, precision)
                })
                .collect::<Result<Vec<f64>, _>>()
        })
        .collect::<Result<_, _>>()
        .map_err(kernel_error)?;
    let mut rows = vec![vec![0.0; n]; n];
    for (i, row) in upper.iter().enumerate() {
        for (k, &exchange) in row.iter().enumerate() {
            let j = i + 1 + k;
            rows[i][j] = exchange / areas[i];
            rows[j][i] = exchange / areas[j];
        }
    }
    Ok((areas, rows))
}

/// Eq. (25)'s sums for a scene of flat convex faces bounding a convex solid, by quadrature over every
/// ordered pair of patches.
pub fn convex_pair_sums(scene: &Scene, precision: Precision) -> Result<PairSums, TruthError> {
    let triangles = patch_triangles(scene);
    let n = triangles.len();
    let pairs: Vec<(usize, usize)> = (0..n)
        .flat_map(|i| ((i + 1)..n).map(move |j| (i, j)))
        .collect();
    // Each unordered pair counts twice: K and K log K are symmetric in x and y.
    let sums = pairs
        .par_iter()
        .map(|&(i, j)| {
            let (a, b) = (&triangles[i], &triangles[j]);
            Ok((
                2.0 * patch_pair_integral(a, b, Integrand::Kernel, precision)?,
                2.0 * patch_pair_integral(a, b, Integrand::KernelLog, precision)?,
            ))
        })
        .collect::<Result<Vec<(f64, f64)>, KernelError>>()
        .map_err(|source| TruthError::Kernel {
            scene: scene.name.clone(),
            source,
        })?;
    Ok(PairSums {
        kernel: sums.iter().map(|s| s.0).sum(),
        kernel_log: sums.iter().map(|s| s.1).sum(),
        total_area: triangles.iter().flatten().map(Triangle::area).sum(),
    })
}

/// The exact values of a regular solid cut into patches: form factors of its patches, and I_s^c of the
/// solid's faces (it does not depend on the patches).
fn solid_values(scene: &CalibrationScene) -> Result<Vec<ExactValue>, TruthError> {
    let CalibrationScene::Solid(which, _) = *scene else {
        unreachable!("solid_values is called for solids")
    };
    let built = scene.build()?;
    let (areas, rows) = convex_form_factors(&built, Precision::STANDARD)?;
    let faces = CalibrationScene::Solid(which, 1).build()?;
    let sums = convex_pair_sums(&faces, Precision::STANDARD)?;
    Ok(closed_values(discrete_per_area(&areas, &rows), sums))
}

/// The exact values of `flipped-cube:n`: a segment from a front side to the flipped face's back joins
/// no pair and is absorbed, counting in its row as an escape does, so each other patch's row is its
/// `@cube:n` row of geometric form factors with the flipped face's entries 0 (the row sums to 1 less
/// them); the flipped face's front sees only out of the cube, so its segments all escape and its row is
/// empty (its area still counts in `A_T`). I_s^c's pairs are those between the five other faces.
fn flipped_cube_values(scene: &Scene, n: usize) -> Result<Vec<ExactValue>, TruthError> {
    let (areas, rows) = rectangle_form_factors(scene)?;
    let flipped: Vec<bool> = (0..rows.len())
        .map(|k| super::scenes::on_flipped_face(k, n))
        .collect();
    let seen_rows: FormFactorRows = rows
        .iter()
        .enumerate()
        .map(|(i, row)| {
            row.iter()
                .zip(&flipped)
                .map(|(&f, &off)| if off || flipped[i] { 0.0 } else { f })
                .collect()
        })
        .collect();
    // Ordered pairs among the five faces: the face opposite the flipped one and the four sides see each
    // other at right angles (8 + 8 ordered pairs), the two pairs of opposite sides are parallel (4).
    let ((k_par, l_par), (k_perp, l_perp)) = unit_square_integrals();
    let sums = PairSums {
        kernel: 16.0 * k_perp + 4.0 * k_par,
        kernel_log: 16.0 * l_perp + 4.0 * l_par,
        total_area: 6.0,
    };
    Ok(both_bases(&areas, &seen_rows, sums))
}

/// The radiosity measures (eqs. 33-35) of a scene of axis-aligned rectangles, solved on its exact form
/// factors with its own materials.
fn radiosity_values(scene: &Scene) -> Result<Vec<ExactValue>, TruthError> {
    let (areas, rows) = rectangle_form_factors(scene)?;
    let entries: Vec<(usize, usize, f64)> = rows
        .iter()
        .enumerate()
        .flat_map(|(i, row)| row.iter().enumerate().map(move |(j, &f)| (i, j, f)))
        .collect();
    let ff = FormFactors::from_entries(rows.len(), &entries);
    let failed = |message: String| TruthError::Radiosity {
        scene: scene.name.clone(),
        message,
    };
    let materials = PatchMaterials::of_scene(scene).map_err(|e| failed(e.to_string()))?;
    let options = SolveOptions {
        tolerance: 1e-14,
        ..SolveOptions::default()
    };
    let solution =
        radiosity::solve(&ff, &materials, &options).map_err(|e| failed(e.to_string()))?;
    let values = radiosity::measures(&areas, &ff, &solution)
        .ok_or_else(|| failed("no patch receives and sends light".into()))?;
    Ok([
        (
            Measure::RadiosityPositionalEntropy,
            values.positional_entropy,
        ),
        (Measure::RadiosityEntropy, values.entropy),
        (Measure::RadiosityEntropyCorrected, values.entropy),
        (
            Measure::RadiosityMutualInformation,
            values.mutual_information,
        ),
        (
            Measure::RadiosityMutualInformationCorrected,
            values.mutual_information,
        ),
    ]
    .into_iter()
    .map(|(measure, value)| ExactValue {
        measure,
        basis: Basis::Closed,
        value,
    })
    .collect())
}

/// I_s^c of the unit cube to the precision of its integrals, in bits.
pub fn cube_continuous_mutual_information() -> f64 {
    cube_pair_sums().per_area()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::solids::Solid;

    fn closed_value(truth: &Truth, measure: Measure) -> f64 {
        truth.value(measure, Basis::Closed).unwrap()
    }

    /// I_s^c of the unit cube two ways: the hand reductions of two squares, and the quadrature over the
    /// triangles of `@cube:1` (each face cut in two: common edges, common vertices, and separate
    /// triangles touching the other's plane at a corner). Paper Table 4 has 1.6093 from 10^6 lines.
    #[test]
    fn the_cubes_continuous_mutual_information_agrees_two_ways() {
        let reduced = cube_pair_sums();
        assert!((reduced.kernel / reduced.total_area - 1.0).abs() < 1e-14);
        let faces = CalibrationScene::Cube(1).build().unwrap();
        let fine = convex_pair_sums(&faces, Precision::FINE).unwrap();
        let standard = convex_pair_sums(&faces, Precision::STANDARD).unwrap();
        assert!(
            (fine.per_area() - reduced.per_area()).abs() < 1e-12,
            "{} vs {}",
            fine.per_area(),
            reduced.per_area()
        );
        assert!((standard.per_area() - reduced.per_area()).abs() < 1e-9);
        assert!((reduced.per_area() - 1.6093).abs() < 2e-3);
    }

    /// The regular solids: every row of F sums to 1 (the solid is closed), the quadrature has converged
    /// (standard and fine precision agree), and I_s^c is near the paper's Monte Carlo values (Table 4,
    /// 10^6 lines each).
    #[test]
    fn regular_solids_are_closed_converged_and_near_table_4() {
        for (which, paper) in [
            (Solid::Tetrahedron, 2.6227),
            (Solid::Octahedron, 1.2583),
            (Solid::Icosahedron, 0.5428),
        ] {
            let faces = CalibrationScene::Solid(which, 1).build().unwrap();
            let standard = convex_pair_sums(&faces, Precision::STANDARD).unwrap();
            let fine = convex_pair_sums(&faces, Precision::FINE).unwrap();
            assert!((standard.kernel / standard.total_area - 1.0).abs() < 1e-12);
            assert!(
                (standard.per_area() - fine.per_area()).abs() < 1e-9,
                "{which:?}: {} vs {}",
                standard.per_area(),
                fine.per_area()
            );
            assert!(
                (standard.per_area() - paper).abs() < 5e-3,
                "{which:?}: {} vs the paper's {paper}",
                standard.per_area()
            );
        }
    }

    /// The tetrahedron's faces see each other equally: F = 1/3, H_s = log2 3, I_s = 2 - log2 3, and
    /// `n_p - sum F^2 = 4 - 4/3`.
    #[test]
    fn the_tetrahedron_has_its_symmetric_values() {
        let t = truth(&CalibrationScene::Solid(Solid::Tetrahedron, 1)).unwrap();
        let log3 = 3f64.log2();
        assert!((closed_value(&t, Measure::Entropy) - log3).abs() < 1e-12);
        assert!((closed_value(&t, Measure::MutualInformation) - (2.0 - log3)).abs() < 1e-12);
        assert!((closed_value(&t, Measure::MsePerLine) - 8.0 / 3.0).abs() < 1e-12);
    }

    /// Subdivided solids: rows sum to 1 and reciprocity holds (`A_i F_ij = A_j F_ji` by construction,
    /// so the check is on the row sums, which the quadrature does not impose).
    #[test]
    fn subdivided_solids_have_rows_summing_to_one() {
        for scene in [
            CalibrationScene::Solid(Solid::Octahedron, 2),
            CalibrationScene::Solid(Solid::Dodecahedron, 1),
        ] {
            let built = scene.build().unwrap();
            let (_, rows) = convex_form_factors(&built, Precision::STANDARD).unwrap();
            for (i, row) in rows.iter().enumerate() {
                let sum: f64 = row.iter().sum();
                assert!(
                    (sum - 1.0).abs() < 1e-9,
                    "{}: row {i} sums to {sum}",
                    scene.name()
                );
            }
        }
    }

    /// The quadrature of the kernel over the triangles of `@cube:3`'s patches reproduces the closed-form
    /// form factors of their rectangles.
    #[test]
    fn quadrature_form_factors_match_the_closed_forms_on_a_cut_cube() {
        let scene = CalibrationScene::Cube(3).build().unwrap();
        let (_, quadrature) = convex_form_factors(&scene, Precision::STANDARD).unwrap();
        let (_, closed) = rectangle_form_factors(&scene).unwrap();
        for (i, (q, c)) in quadrature.iter().zip(&closed).enumerate() {
            for (j, (a, b)) in q.iter().zip(c).enumerate() {
                assert!((a - b).abs() < 1e-10, "F[{i}][{j}]: {a} vs {b}");
            }
        }
    }

    /// The cube's values from face 0's rows (its symmetry) equal those from every row.
    #[test]
    fn the_cubes_symmetry_shortcut_equals_the_full_sums() {
        let n = 3;
        let scene = CalibrationScene::Cube(n).build().unwrap();
        let (areas, rows) = rectangle_form_factors(&scene).unwrap();
        let full = discrete_per_area(&areas, &rows);
        let shortcut = cube_discrete(n).unwrap();
        assert!((full.entropy - shortcut.entropy).abs() < 1e-12);
        assert!((full.mutual_information - shortcut.mutual_information).abs() < 1e-12);
        assert!((full.mse_per_line.unwrap() - shortcut.mse_per_line.unwrap()).abs() < 1e-10);
    }

    /// Two parallel squares, one patch each, F = F_par both ways: per area, `H_s = -F log2 F` and
    /// `I_s = F log2(2 F)`; per visible pair each row is certain, `H_s = 0` and `I_s = 1` bit. I_s^c per
    /// visible pair is 1 bit (`log2 A_T`) plus the mean of `log2 K`, and per area that times `F`.
    #[test]
    fn two_parallel_squares_have_both_readings() {
        let scene = CalibrationScene::ParallelSquares {
            patches: 1,
            distance: 1.0,
        };
        let t = truth(&scene).unwrap();
        let f = super::super::rectangles::ff_parallel(1.0, 1.0, 1.0);
        let per_area = |m| t.value(m, Basis::PerArea).unwrap();
        let per_pair = |m| t.value(m, Basis::PerVisiblePair).unwrap();
        assert!((per_area(Measure::Entropy) + f * f.log2()).abs() < 1e-12);
        assert!((per_area(Measure::MutualInformation) - f * (2.0 * f).log2()).abs() < 1e-12);
        assert!(per_pair(Measure::Entropy).abs() < 1e-12);
        assert!((per_pair(Measure::MutualInformation) - 1.0).abs() < 1e-12);
        let continuous = (
            per_area(Measure::ContinuousMutualInformation),
            per_pair(Measure::ContinuousMutualInformation),
        );
        assert!(
            (continuous.0 - f * continuous.1).abs() < 1e-12,
            "{continuous:?}"
        );
        assert!((per_area(Measure::MsePerLine) - (2.0 - 2.0 * f * f)).abs() < 1e-12);
    }

    /// The lit cube: the radiosity system solved by elimination on the closed-form form factors, and
    /// eqs. (33)-(35) written out as in the paper, with the incoming radiosity `(B_i - E_i) / R_i`.
    #[test]
    fn the_lit_cubes_radiosity_measures_match_a_hand_solution() {
        let t = truth(&CalibrationScene::LitCube(1)).unwrap();
        let (fp, fq) = (
            super::super::rectangles::ff_parallel(1.0, 1.0, 1.0),
            super::super::rectangles::ff_perpendicular(1.0, 1.0, 1.0),
        );
        // Faces x = 0 (emitting), x = 1, y = 0, y = 1, z = 0, z = 1: i / 2 == j / 2 are opposite.
        let f = |i: usize, j: usize| match (i == j, i / 2 == j / 2) {
            (true, _) => 0.0,
            (false, true) => fp,
            (false, false) => fq,
        };
        let (r, e) = (0.5, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let mut m: Vec<Vec<f64>> = (0..6)
            .map(|i| {
                let mut row: Vec<f64> = (0..6).map(|j| -r * f(i, j)).collect();
                row[i] += 1.0;
                row.push(e[i]);
                row
            })
            .collect();
        for k in 0..6 {
            let pivot = m[k].clone();
            for row in m.iter_mut().skip(k + 1) {
                let factor = row[k] / pivot[k];
                for (x, p) in row.iter_mut().zip(&pivot).skip(k) {
                    *x -= factor * p;
                }
            }
        }
        let mut b = [0.0; 6];
        for i in (0..6).rev() {
            let known: f64 = ((i + 1)..6).map(|c| m[i][c] * b[c]).sum();
            b[i] = (m[i][6] - known) / m[i][i];
        }
        let weights: Vec<f64> = (0..6).map(|i| (b[i] - e[i]) / r * b[i]).collect();
        let total: f64 = weights.iter().sum();
        let p: Vec<f64> = weights.iter().map(|w| w / total).collect();
        let (mut hp, mut hs, mut is) = (0.0, 0.0, 0.0);
        for i in 0..6 {
            hp -= p[i] * p[i].log2();
            for j in (0..6).filter(|&j| j != i) {
                let q = r * f(i, j) * b[j] / (b[i] - e[i]);
                hs -= p[i] * q * q.log2();
                is += p[i] * q * (q / p[j]).log2();
            }
        }
        for (measure, hand) in [
            (Measure::RadiosityPositionalEntropy, hp),
            (Measure::RadiosityEntropy, hs),
            (Measure::RadiosityMutualInformation, is),
        ] {
            let exact = closed_value(&t, measure);
            assert!(
                (exact - hand).abs() < 1e-10,
                "{measure:?}: {exact} vs {hand}"
            );
        }
    }

    /// The flipped face: the rows of the five other faces are the cube's without it (what reached it is
    /// absorbed, so they sum to less than 1); its own row is empty. With one patch per face, the face
    /// opposite the flipped one sees the four sides, each `F_perp`; a side sees three perpendicular faces
    /// and one parallel one.
    #[test]
    fn the_flipped_cube_follows_the_programs_reading() {
        let t = truth(&CalibrationScene::FlippedCube(1)).unwrap();
        let (fp, fq) = (
            super::super::rectangles::ff_parallel(1.0, 1.0, 1.0),
            super::super::rectangles::ff_perpendicular(1.0, 1.0, 1.0),
        );
        let h = |x: f64| -x * x.log2();
        let opposite_row = 4.0 * h(fq);
        let side_row = 3.0 * h(fq) + h(fp);
        // Every face weighs 1/6 (the flipped face's area counts; its row is empty).
        let expected = (opposite_row + 4.0 * side_row) / 6.0;
        let got = t.value(Measure::Entropy, Basis::PerArea).unwrap();
        assert!((got - expected).abs() < 1e-12, "{got} vs {expected}");
        // Its pairs are those of the cube less one face's: per visible pair, I_s^c is the cube's.
        let continuous = t
            .value(Measure::ContinuousMutualInformation, Basis::PerVisiblePair)
            .unwrap();
        assert!((continuous - cube_continuous_mutual_information()).abs() < 1e-12);
    }
}
