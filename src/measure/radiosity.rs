//! Scene radiosity complexity (paper sec. 4): the radiosity system solved on the estimated form
//! factors, the null-variance transition matrix and the entropies of the "transformed scene".
//!
//! With the radiosities `B` of the discretised system (eq. (2)) `B_i = E_i + R_i sum_j F_ij B_j`, the
//! paper maps the scene to an imaginary one whose areas and form factors are (eqs. (28), (30)-(32))
//!
//! ```text
//!   𝒜_i = A_i B_i^in B_i,        𝓕_ij = R_i F_ij B_j / (B_i - E_i) = F_ij B_j / B_i^in,
//! ```
//!
//! and measures that scene's visibility complexity (eqs. (33)-(35)). We compute the incoming radiosity
//! directly as `B_i^in = sum_j F_ij B_j`, not as `(B_i - E_i) / R_i`: the two agree wherever `R_i > 0`,
//! and the direct form needs no division, so black (`R_i = 0`) patches and patches no light reaches are
//! handled like any other. `R_i` then cancels from `𝓕`, whose rows sum to 1 by construction.
//!
//! Patches with `𝒜_i = 0` (no light arrives, or none leaves) have no place in the transformed scene and
//! leave the channel; they are counted. No transition from a patch in the channel leads to one outside it
//! (if `𝒜_j = 0` then either `B_j = 0`, or `B_j^in = 0`, which makes every `B_i` with `F_ji > 0` zero, and
//! `F_ij > 0` exactly when `F_ji > 0` because pair counts are symmetric), so no `log(x / 0)` arises.
//!
//! Form factors come from the same global-line pair counts as the visibility measures, `F_ij = N_ij / N_i`
//! ([`super::visibility`]), held row by row in a sparse [`FormFactors`] (never an n_p x n_p matrix).

use ndarray::Array1;

use super::channel::{for_each_form_factor, row_totals};
use super::entropy::xlog2x;
use crate::sample::counts::PairCounts;
use crate::scene::Scene;

/// The estimated form factors `F_ij = N_ij / N_i` as sparse rows (compressed sparse row layout).
#[derive(Clone, Debug)]
pub struct FormFactors {
    /// Row `i` is `columns[start[i]..start[i + 1]]`, `values[..]` likewise.
    start: Vec<usize>,
    columns: Vec<u32>,
    values: Vec<f64>,
}

impl FormFactors {
    /// Rows from pair counts and escapes (eq. (3) estimated with global lines, paper sec. 2.1.1).
    pub fn from_counts(patches: usize, counts: &PairCounts, escapes: &[u64]) -> Self {
        let totals: Array1<f64> = row_totals(patches, counts, escapes);
        let mut start = vec![0usize; patches + 1];
        for_each_form_factor(counts, &totals, |i, _, _| start[i + 1] += 1);
        for i in 0..patches {
            start[i + 1] += start[i];
        }
        let mut next = start.clone();
        let mut columns = vec![0u32; start[patches]];
        let mut values = vec![0.0; start[patches]];
        for_each_form_factor(counts, &totals, |i, j, f| {
            columns[next[i]] = j as u32;
            values[next[i]] = f;
            next[i] += 1;
        });
        FormFactors {
            start,
            columns,
            values,
        }
    }

    /// Rows given directly, as `(i, j, F_ij)` entries with `F_ij > 0` (for exact form factors in tests
    /// and small hand-made systems).
    pub fn from_entries(patches: usize, entries: &[(usize, usize, f64)]) -> Self {
        let mut sorted: Vec<(usize, usize, f64)> =
            entries.iter().copied().filter(|e| e.2 > 0.0).collect();
        sorted.sort_by_key(|e| (e.0, e.1));
        let mut start = vec![0usize; patches + 1];
        for e in &sorted {
            start[e.0 + 1] += 1;
        }
        for i in 0..patches {
            start[i + 1] += start[i];
        }
        FormFactors {
            start,
            columns: sorted.iter().map(|e| e.1 as u32).collect(),
            values: sorted.iter().map(|e| e.2).collect(),
        }
    }

    /// Number of patches (rows).
    pub fn patches(&self) -> usize {
        self.start.len() - 1
    }

    /// Stored non-zero form factors.
    pub fn nonzeros(&self) -> usize {
        self.values.len()
    }

    /// The non-zero entries `(j, F_ij)` of row `i`.
    pub fn row(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let r = self.start[i]..self.start[i + 1];
        self.columns[r.clone()]
            .iter()
            .map(|&j| j as usize)
            .zip(self.values[r].iter().copied())
    }

    /// `sum_j F_ij` (1 in a closed scene, less where lines escape, 0 for a patch no line left).
    pub fn row_sum(&self, i: usize) -> f64 {
        self.row(i).map(|(_, f)| f).sum()
    }

    /// `sum_j F_ij x_j`: what patch i gathers from a field `x` over the patches.
    pub fn gather(&self, i: usize, x: &[f64]) -> f64 {
        self.row(i).map(|(j, f)| f * x[j]).sum()
    }
}

/// Per-patch emission `E_i` and reflectance `R_i` (eq. (2)), checked: `E_i >= 0`, `0 <= R_i <= 1`.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchMaterials {
    /// `E_i`.
    pub emission: Vec<f64>,
    /// `R_i`.
    pub reflectance: Vec<f64>,
}

/// A material that cannot take part in a radiosity solve.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{scene}: material `{material}`: {problem}")]
pub struct MaterialError {
    /// The scene (a file path, or a built-in name).
    pub scene: String,
    /// The material's name.
    pub material: String,
    /// What is wrong with it.
    pub problem: MaterialProblem,
}

/// What makes a material unfit for the radiosity system.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum MaterialProblem {
    /// A reflectance outside [0, 1] (or not a number).
    #[error("reflectance (Kd, mean of RGB) is {0}; the radiosity system needs 0 <= R <= 1")]
    Reflectance(f64),
    /// A negative emission (or not a number).
    #[error("emission (Ke, mean of RGB) is {0}; the radiosity system needs E >= 0")]
    Emission(f64),
}

impl PatchMaterials {
    /// The materials of a scene's patches. Only materials that some patch uses are checked; one with a
    /// reflectance outside [0, 1], a negative emission or a non-finite value is an error naming it.
    pub fn of_scene(scene: &Scene) -> Result<Self, MaterialError> {
        let mut used = vec![false; scene.materials.len()];
        for p in &scene.patches {
            used[p.material as usize] = true;
        }
        for (m, _) in scene.materials.iter().zip(&used).filter(|(_, &u)| u) {
            check_material(m.emission, m.reflectance).map_err(|problem| MaterialError {
                scene: scene.name.clone(),
                material: m.name.clone(),
                problem,
            })?;
        }
        let of = |f: fn(&crate::scene::Material) -> f64| -> Vec<f64> {
            scene
                .patches
                .iter()
                .map(|p| f(&scene.materials[p.material as usize]))
                .collect()
        };
        Ok(PatchMaterials {
            emission: of(|m| m.emission),
            reflectance: of(|m| m.reflectance),
        })
    }

    /// Whether any patch emits light (otherwise every radiosity is 0 and there is nothing to measure).
    pub fn any_emission(&self) -> bool {
        self.emission.iter().any(|&e| e > 0.0)
    }
}

fn check_material(emission: f64, reflectance: f64) -> Result<(), MaterialProblem> {
    if !reflectance.is_finite() || !(0.0..=1.0).contains(&reflectance) {
        return Err(MaterialProblem::Reflectance(reflectance));
    }
    if !emission.is_finite() || emission < 0.0 {
        return Err(MaterialProblem::Emission(emission));
    }
    Ok(())
}

/// When the Gauss-Seidel iteration stops.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SolveOptions {
    /// Stop when `max_i |B_i - E_i - R_i sum_j F_ij B_j| / max_i B_i` is at most this.
    pub tolerance: f64,
    /// Give up (an error) after this many sweeps.
    pub max_sweeps: usize,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            tolerance: 1e-10,
            max_sweeps: 10_000,
        }
    }
}

/// The solved radiosity system.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// `B_i` (outgoing radiosity, eq. (2)).
    pub radiosity: Vec<f64>,
    /// `B_i^in = sum_j F_ij B_j` (incoming radiosity, eq. (28)).
    pub incoming: Vec<f64>,
    /// Gauss-Seidel sweeps done.
    pub sweeps: usize,
    /// The final relative residual `max_i |B_i - E_i - R_i B_i^in| / max_i B_i`.
    pub residual: f64,
}

/// Why the radiosity system could not be solved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// Light emitted into a part of the scene that reflects everything and lets nothing escape grows
    /// without bound: `I - R F` is singular there (spectral radius of `R F` is 1).
    #[error(
        "the radiosity system B = E + R F B has no finite solution: {patches} patch(es), among them {emitters} \
         emitting one(s), form a closed part of the scene where every reflectance is 1 and no light escapes, \
         so the emitted light is never absorbed"
    )]
    NoAbsorption {
        /// Patches in the non-absorbing closed part.
        patches: usize,
        /// How many of them emit.
        emitters: usize,
        /// One emitting patch, to name its material.
        example_emitter: usize,
    },
    /// The iteration did not reach the tolerance.
    #[error(
        "the radiosity solve did not converge: relative residual {residual:.3e} after {sweeps} Gauss-Seidel \
         sweeps (tolerance {tolerance:.0e}); reflectances very close to 1 make it converge slowly"
    )]
    NoConvergence {
        /// Sweeps done.
        sweeps: usize,
        /// Residual reached.
        residual: f64,
        /// Residual wanted.
        tolerance: f64,
    },
}

/// Solves `B = E + R F B` (eq. (2)) by Gauss-Seidel sweeps from `B = E`.
///
/// The iteration converges when the spectral radius of `R F` is below 1, which holds unless light can
/// stay forever in a closed group of patches with `R = 1` (checked first: [`SolveError::NoAbsorption`]
/// when such a group holds an emitter; without an emitter it stays dark, `B = 0` there, which is the
/// physical solution). Nothing emits: `B = 0`, no sweep.
pub fn solve(
    ff: &FormFactors,
    m: &PatchMaterials,
    opts: &SolveOptions,
) -> Result<Solution, SolveError> {
    let n = ff.patches();
    let (e, r) = (&m.emission, &m.reflectance);
    if !m.any_emission() {
        return Ok(Solution {
            radiosity: vec![0.0; n],
            incoming: vec![0.0; n],
            sweeps: 0,
            residual: 0.0,
        });
    }
    check_absorption(ff, m)?;
    let mut b = e.clone();
    let mut sweeps = 0;
    loop {
        let residual = relative_residual(ff, m, &b);
        if residual <= opts.tolerance {
            let incoming = (0..n).map(|i| ff.gather(i, &b)).collect();
            return Ok(Solution {
                radiosity: b,
                incoming,
                sweeps,
                residual,
            });
        }
        if sweeps >= opts.max_sweeps || !residual.is_finite() {
            return Err(SolveError::NoConvergence {
                sweeps,
                residual,
                tolerance: opts.tolerance,
            });
        }
        for i in 0..n {
            b[i] = e[i] + r[i] * ff.gather(i, &b);
        }
        sweeps += 1;
    }
}

/// `max_i |B_i - E_i - R_i sum_j F_ij B_j| / max_i B_i` (0 when every B is 0).
pub fn relative_residual(ff: &FormFactors, m: &PatchMaterials, b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |acc, &x| acc.max(x.abs()));
    if scale == 0.0 {
        return 0.0;
    }
    let worst = (0..ff.patches())
        .map(|i| (b[i] - m.emission[i] - m.reflectance[i] * ff.gather(i, b)).abs())
        .fold(0.0f64, f64::max);
    worst / scale
}

/// A patch loses light when it absorbs some (`R_i < 1`) or some of its lines escape (`sum_j F_ij < 1`).
/// The margin keeps round-off in a closed row sum (1 +- 1e-16) from counting as a loss.
fn loses_light(ff: &FormFactors, m: &PatchMaterials, i: usize) -> bool {
    m.reflectance[i] * ff.row_sum(i) < 1.0 - 1e-12
}

/// Fails when an emitter sits in a closed group of patches none of which loses light.
///
/// Light moves between i and j exactly when `F_ij > 0`, which (pair counts being symmetric) is when
/// `F_ji > 0`: the groups are the connected components of the form-factor graph, and a component loses
/// light when any of its patches does.
fn check_absorption(ff: &FormFactors, m: &PatchMaterials) -> Result<(), SolveError> {
    let n = ff.patches();
    let mut drains = vec![false; n];
    let mut stack: Vec<usize> = (0..n).filter(|&i| loses_light(ff, m, i)).collect();
    for &i in &stack {
        drains[i] = true;
    }
    while let Some(i) = stack.pop() {
        for (j, _) in ff.row(i) {
            if !drains[j] {
                drains[j] = true;
                stack.push(j);
            }
        }
    }
    let trapped: Vec<usize> = (0..n).filter(|&i| !drains[i]).collect();
    let emitters: Vec<usize> = trapped
        .iter()
        .copied()
        .filter(|&i| m.emission[i] > 0.0)
        .collect();
    match emitters.first() {
        None => Ok(()),
        Some(&example) => Err(SolveError::NoAbsorption {
            patches: trapped.len(),
            emitters: emitters.len(),
            example_emitter: example,
        }),
    }
}

/// The radiosity measures of one solution (paper eqs. (33)-(35)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadiosityValues {
    /// Eq. (33): 𝓗_p = -sum_i (𝒜_i / 𝒜_T) log(𝒜_i / 𝒜_T).
    pub positional_entropy: f64,
    /// Eq. (34): 𝓗_s = -sum_i (𝒜_i / 𝒜_T) sum_j 𝓕_ij log 𝓕_ij.
    pub entropy: f64,
    /// Eq. (35): 𝓘_s = sum_ij (𝒜_i 𝓕_ij / 𝒜_T) log(𝓕_ij 𝒜_T / 𝒜_j).
    pub mutual_information: f64,
    /// Eq. (34) with every row's entropy raised by its visibility row's bias correction (see
    /// [`corrected`]).
    pub entropy_corrected: f64,
    /// Eq. (35) less the same correction.
    pub mutual_information_corrected: f64,
    /// Patches with 𝒜_i = 0, outside the channel.
    pub excluded_patches: usize,
    /// Their share of the (geometric) area.
    pub excluded_area_fraction: f64,
}

/// Eq. (30) with eq. (28): the transformed areas `𝒜_i = A_i B_i^in B_i`.
pub fn transformed_areas(areas: &[f64], s: &Solution) -> Vec<f64> {
    areas
        .iter()
        .zip(&s.incoming)
        .zip(&s.radiosity)
        .map(|((&a, &bin), &b)| a * bin * b)
        .collect()
}

/// Visits every non-zero entry `(i, j, 𝓕_ij)` of the null-variance transition matrix (eq. (32)),
/// `𝓕_ij = F_ij B_j / B_i^in`, for the patches `i` in the channel (`𝒜_i > 0`). Each such row sums to 1.
pub fn for_each_transition(
    ff: &FormFactors,
    s: &Solution,
    transformed: &[f64],
    mut f: impl FnMut(usize, usize, f64),
) {
    for (i, &t) in transformed.iter().enumerate() {
        if t <= 0.0 {
            continue;
        }
        let bin = s.incoming[i];
        for (j, fij) in ff.row(i) {
            let p = fij * s.radiosity[j] / bin;
            if p > 0.0 {
                f(i, j, p);
            }
        }
    }
}

/// The radiosity measures (eqs. (33)-(35)) from the geometric areas, the form factors and a solution;
/// `None` when no patch is in the channel (every 𝒜_i is 0: nothing emits, or no light comes back).
pub fn measures(areas: &[f64], ff: &FormFactors, s: &Solution) -> Option<RadiosityValues> {
    let t = transformed_areas(areas, s);
    let total: f64 = t.iter().sum();
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    let a: Vec<f64> = t.iter().map(|x| x / total).collect();
    let positional_entropy = -a.iter().map(|&x| xlog2x(x)).sum::<f64>();
    let (mut entropy, mut mi) = (0.0, 0.0);
    for_each_transition(ff, s, &t, |i, j, p| {
        entropy -= a[i] * xlog2x(p);
        // a_j > 0 whenever p > 0 (module docs); the guard keeps a rounding accident from making inf.
        if a[j] > 0.0 {
            mi += a[i] * p * (p / a[j]).log2();
        }
    });
    let area_total: f64 = areas.iter().sum();
    let excluded: Vec<usize> = (0..areas.len()).filter(|&i| t[i] <= 0.0).collect();
    Some(RadiosityValues {
        positional_entropy,
        entropy,
        mutual_information: mi,
        entropy_corrected: entropy,
        mutual_information_corrected: mi,
        excluded_patches: excluded.len(),
        excluded_area_fraction: excluded.iter().fold(0.0, |acc, &i| acc + areas[i]) / area_total,
    })
}

/// Applies per-row bias corrections (bits, from [`crate::measure::bias::row_corrections`]) to radiosity
/// values: 𝓗_s gains `sum_i (𝒜_i/𝒜_T) delta_i` and 𝓘_s loses it (𝓘_s = X - 𝓗_s with X linear in 𝓕).
///
/// Row i of the radiosity channel reweights row i of F by the radiosities `B_j` it reaches, so the patches
/// its undersampled sample missed are missing from both; using the visibility row's correction assumes
/// the missed patches carry about the row's mean radiosity. It is exact when B is constant (paper
/// Table 8: the radiosity channel is then the visibility channel) and first order otherwise.
pub fn corrected(
    values: &mut RadiosityValues,
    areas: &[f64],
    s: &Solution,
    row_corrections: &[f64],
) {
    let t = transformed_areas(areas, s);
    let total: f64 = t.iter().sum();
    if !(total > 0.0 && total.is_finite()) {
        return;
    }
    let shift: f64 = t
        .iter()
        .zip(row_corrections)
        .map(|(ti, d)| ti / total * d)
        .sum();
    values.entropy_corrected = values.entropy + shift;
    values.mutual_information_corrected = values.mutual_information - shift;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::counts::pair_key;

    fn mats(e: &[f64], r: &[f64]) -> PatchMaterials {
        PatchMaterials {
            emission: e.to_vec(),
            reflectance: r.to_vec(),
        }
    }

    /// Two parallel patches that see each other with F_01 = F_10 = f and the rest of the scene black:
    /// B_0 = E + R f B_1, B_1 = R f B_0 gives B_0 = E / (1 - (R f)^2), B_1 = R f B_0.
    #[test]
    fn two_patches_solved_by_hand() {
        let f = 0.3;
        let ff = FormFactors::from_entries(2, &[(0, 1, f), (1, 0, f)]);
        let m = mats(&[2.0, 0.0], &[0.6, 0.6]);
        let s = solve(&ff, &m, &SolveOptions::default()).unwrap();
        let b0 = 2.0 / (1.0 - (0.6 * f).powi(2));
        // The error is at most the residual (1e-10 of max B) over 1 - (spectral radius of R F).
        assert!((s.radiosity[0] - b0).abs() < 2e-10 * b0);
        assert!((s.radiosity[1] - 0.6 * f * b0).abs() < 2e-10 * b0);
        assert!((s.incoming[0] - f * s.radiosity[1]).abs() < 1e-15);
        assert!(s.residual <= 1e-10);
    }

    /// A black patch (R = 0) that receives light: in the channel, and no division by R anywhere.
    #[test]
    fn black_and_unlit_patches_need_no_division() {
        // 0 emits, 1 is black, 2 is white; everyone sees everyone equally (F = 1/2 off the diagonal).
        let ff = FormFactors::from_entries(
            3,
            &[
                (0, 1, 0.5),
                (0, 2, 0.5),
                (1, 0, 0.5),
                (1, 2, 0.5),
                (2, 0, 0.5),
                (2, 1, 0.5),
            ],
        );
        let m = mats(&[1.0, 0.0, 0.0], &[0.0, 0.0, 0.5]);
        let s = solve(&ff, &m, &SolveOptions::default()).unwrap();
        // B_1 = 0 (black), B_2 = 0.5 (0.5 * 1 + 0.5 * 0) = 0.25, B_0 = 1.
        assert!((s.radiosity[2] - 0.25).abs() < 1e-12);
        assert_eq!(s.radiosity[1], 0.0);
        let v = measures(&[1.0, 1.0, 1.0], &ff, &s).unwrap();
        // Patch 1 has B = 0, so 𝒜_1 = 0: it leaves the channel.
        assert_eq!(v.excluded_patches, 1);
        assert!(v.entropy.is_finite() && v.mutual_information.is_finite());
        // The channel is {0, 2}: 𝓕_02 = F_02 B_2 / B_0^in = 1, 𝓕_20 = 1: H_s = 0, I_s = H_p.
        assert!(v.entropy.abs() < 1e-12);
        assert!((v.mutual_information - v.positional_entropy).abs() < 1e-12);
    }

    #[test]
    fn rows_of_the_transition_matrix_sum_to_one() {
        let keys = &mut [
            pair_key(0, 1),
            pair_key(0, 1),
            pair_key(0, 2),
            pair_key(1, 2),
            pair_key(2, 3),
            pair_key(1, 3),
            pair_key(1, 3),
            pair_key(0, 3),
        ];
        let counts = PairCounts::from_keys(4, keys);
        let ff = FormFactors::from_counts(4, &counts, &[0, 0, 1, 0]);
        let m = mats(&[1.0, 0.0, 0.0, 0.0], &[0.2, 0.9, 1.0, 0.0]);
        let s = solve(&ff, &m, &SolveOptions::default()).unwrap();
        let t = transformed_areas(&[1.0, 2.0, 1.0, 3.0], &s);
        let mut sums = [0.0; 4];
        for_each_transition(&ff, &s, &t, |i, _, p| sums[i] += p);
        for (i, sum) in sums.iter().enumerate() {
            if t[i] > 0.0 {
                assert!((sum - 1.0).abs() < 1e-14, "row {i}: {sum}");
            }
        }
    }

    #[test]
    fn light_trapped_by_perfect_mirrors_has_no_finite_solution() {
        // A closed pair (rows sum to 1) of white patches, one emitting.
        let ff = FormFactors::from_entries(2, &[(0, 1, 1.0), (1, 0, 1.0)]);
        let e = solve(
            &ff,
            &mats(&[1.0, 0.0], &[1.0, 1.0]),
            &SolveOptions::default(),
        );
        assert!(
            matches!(e, Err(SolveError::NoAbsorption { emitters: 1, .. })),
            "{e:?}"
        );
        // One absorbing patch is enough: converges.
        let ok = solve(
            &ff,
            &mats(&[1.0, 0.0], &[1.0, 0.5]),
            &SolveOptions::default(),
        )
        .unwrap();
        // B_0 = 1 + B_1, B_1 = 0.5 B_0: B_0 = 2, B_1 = 1.
        assert!((ok.radiosity[0] - 2.0).abs() < 1e-9 && (ok.radiosity[1] - 1.0).abs() < 1e-9);
        // A dark closed group with R = 1 but no emitter is fine: it stays at B = 0.
        let ff4 =
            FormFactors::from_entries(4, &[(0, 1, 0.5), (1, 0, 0.5), (2, 3, 1.0), (3, 2, 1.0)]);
        let s = solve(
            &ff4,
            &mats(&[1.0, 0.0, 0.0, 0.0], &[1.0, 1.0, 1.0, 1.0]),
            &SolveOptions::default(),
        )
        .unwrap();
        assert_eq!(&s.radiosity[2..], &[0.0, 0.0]);
    }

    #[test]
    fn slow_convergence_is_a_clear_error_not_a_hang() {
        let ff = FormFactors::from_entries(2, &[(0, 1, 1.0), (1, 0, 1.0)]);
        let e = solve(
            &ff,
            &mats(&[1.0, 0.0], &[1.0, 0.999_999]),
            &SolveOptions {
                tolerance: 1e-10,
                max_sweeps: 50,
            },
        );
        assert!(
            matches!(e, Err(SolveError::NoConvergence { sweeps: 50, .. })),
            "{e:?}"
        );
    }

    #[test]
    fn invalid_materials_are_named() {
        assert!(check_material(0.0, 1.0).is_ok());
        assert!(check_material(0.0, 0.0).is_ok());
        assert!(check_material(0.0, 1.01)
            .unwrap_err()
            .to_string()
            .contains("0 <= R <= 1"));
        assert!(check_material(0.0, -0.1).is_err());
        assert!(check_material(-1.0, 0.5)
            .unwrap_err()
            .to_string()
            .contains("E >= 0"));
        assert!(check_material(f64::NAN, 0.5).is_err());
        assert!(check_material(0.0, f64::INFINITY).is_err());
    }

    #[test]
    fn nothing_emitting_has_no_channel() {
        let ff = FormFactors::from_entries(2, &[(0, 1, 1.0), (1, 0, 1.0)]);
        let s = solve(
            &ff,
            &mats(&[0.0, 0.0], &[0.5, 0.5]),
            &SolveOptions::default(),
        )
        .unwrap();
        assert_eq!(s.sweeps, 0);
        assert!(measures(&[1.0, 1.0], &ff, &s).is_none());
    }
}
