//! The form-factor channel of the paper (sec. 2.2): its input distribution, the patch areas
//! `a_i = A_i / A_T`, and its transition probabilities, the form factors estimated from global-line pair
//! counts as `F_ij = N_ij / N_i` (eq. (3) with the lines of sec. 2.1.1), where `N_i` counts the segments
//! leaving patch i's front side (to another patch, or escaping an open scene).

use ndarray::Array1;

use crate::sample::counts::PairCounts;

/// Area distribution `a_i = A_i / A_T`.
pub fn area_distribution(areas: &[f64]) -> Array1<f64> {
    let a = Array1::from(areas.to_vec());
    let total = a.sum();
    a / total
}

/// `N_i`: segments leaving each patch's front side (pair counts in both directions plus escapes).
pub fn row_totals(patches: usize, counts: &PairCounts, escapes: &[u64]) -> Array1<f64> {
    let mut n = Array1::<f64>::zeros(patches);
    counts.for_each(|i, j, c| {
        n[i as usize] += c as f64;
        n[j as usize] += c as f64;
    });
    for (t, &e) in n.iter_mut().zip(escapes) {
        *t += e as f64;
    }
    n
}

/// Visits every estimated form factor `(i, j, F_ij)` with `F_ij > 0` (both directions of each pair).
pub fn for_each_form_factor(
    counts: &PairCounts,
    row_totals: &Array1<f64>,
    mut f: impl FnMut(usize, usize, f64),
) {
    counts.for_each(|i, j, c| {
        let (i, j) = (i as usize, j as usize);
        let c = c as f64;
        if i == j {
            // One segment from a patch back to itself enters N_ii twice (i -> j and j -> i).
            f(i, i, 2.0 * c / row_totals[i]);
        } else {
            f(i, j, c / row_totals[i]);
            f(j, i, c / row_totals[j]);
        }
    });
}
