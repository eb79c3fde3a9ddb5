//! What a refinement round measures: pair counts with the sum of `log2 F(x, y)` per patch pair, and the
//! per-patch scores of the strategies (the `information` score is the per-patch module's,
//! [`crate::measure::shares::information_loss`]).

use rayon::prelude::*;

use crate::geom::{orthonormal_basis, Direction};
use crate::measure::radiosity::{FormFactors, Solution};
use crate::measure::shares::PairKernelSums;
use crate::run::{all_batches, map_traced_batches, LineStream};
use crate::sample::counts::{pair_key, PairCounts};
use crate::sample::kernel::kernel_without_pi;
use crate::sample::pairs::{batch_segments, LineF64, Segment};
use crate::scene::Scene;
use crate::trace::{TraceError, Tracer};

/// Traces `lines` global lines in batches (in parallel) and hands every segment, with its line, to
/// `visit`, which fills one `T` per batch; the results come back in batch order, so whatever is merged
/// from them does not depend on the thread count.
fn trace_segments<T: Default + Send>(
    scene: &Scene,
    tracer: &dyn Tracer,
    lines: u64,
    seed: u64,
    visit: impl Fn(&LineF64, Segment, &mut T) + Sync + Send,
) -> Result<Vec<T>, TraceError> {
    let stream = LineStream::independent(lines, seed);
    let (per_batch, _) = map_traced_batches(
        &stream,
        tracer,
        scene,
        &all_batches(&stream),
        &|_| false,
        |_: &mut (), batch, hits| {
            let mut out = T::default();
            let lines: Vec<LineF64> = batch.lines.iter().map(LineF64::from).collect();
            batch_segments(scene, batch.lines, hits, |k, seg| {
                visit(&lines[k], seg, &mut out)
            });
            out
        },
    )?;
    Ok(per_batch.into_iter().map(|(_, t)| t).collect())
}

/// Casts `lines` global lines and gathers, per unordered patch pair, its count and the sum of
/// `log2 F(x, y)` over its pairs of points, in tracing space ([`PairKernelSums`]).
pub fn sample_pairs(
    scene: &Scene,
    tracer: &dyn Tracer,
    lines: u64,
    seed: u64,
) -> Result<PairKernelSums, TraceError> {
    let log2_pi = std::f64::consts::PI.log2();
    let per_batch = trace_segments(
        scene,
        tracer,
        lines,
        seed,
        |_, seg, out: &mut (Vec<(u64, f64)>, Vec<u32>)| match seg {
            Segment::Pair {
                from,
                to,
                distance,
                cos_from,
                cos_to,
            } => {
                // A degenerate pair (coincident points, d = 0) has no finite kernel: NaN keeps it out
                // of the sum.
                let term = kernel_without_pi(cos_from * cos_to, distance)
                    .map_or(f64::NAN, |v| v.log2() - log2_pi);
                out.0.push((pair_key(from, to), term));
            }
            Segment::Escape { patch, .. } => out.1.push(patch),
            Segment::BackSeen { .. } | Segment::Unpaired => {}
        },
    )?;
    let mut escapes = vec![0u64; scene.patch_count()];
    let mut terms: Vec<(u64, f64)> = Vec::new();
    for (t, e) in per_batch {
        terms.extend(t);
        for p in e {
            escapes[p as usize] += 1;
        }
    }
    // A stable sort keeps equal keys in batch order: the sums are added in a fixed order.
    terms.par_sort_by_key(|t| t.0);
    let (mut list, mut sums, mut used) = (Vec::new(), Vec::new(), Vec::new());
    for (key, term) in terms {
        if list.last().map(|&(k, _)| k) != Some(key) {
            list.push((key, 0u64));
            sums.push(0.0);
            used.push(0u64);
        }
        let last = list.len() - 1;
        list[last].1 += 1;
        if term.is_finite() {
            sums[last] += term;
            used[last] += 1;
        }
    }
    Ok(PairKernelSums {
        counts: PairCounts::from_entries(scene.patch_count(), list),
        log_kernel_sums: sums,
        log_kernel_pairs: used,
        escapes,
    })
}

/// Power: `A_i B_i`, the light leaving each patch.
pub fn power(areas: &[f64], s: &Solution) -> Vec<f64> {
    areas.iter().zip(&s.radiosity).map(|(a, b)| a * b).collect()
}

/// Moments of the radiosity arriving at one patch, against the arrival point `(u, v)` in the patch's
/// plane: enough for a least-squares plane `w = a + g . (u, v)` through the samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ArrivalMoments {
    n: f64,
    su: f64,
    sv: f64,
    sw: f64,
    suu: f64,
    suv: f64,
    svv: f64,
    suw: f64,
    svw: f64,
    sww: f64,
}

impl ArrivalMoments {
    fn add(&mut self, u: f64, v: f64, w: f64) {
        self.n += 1.0;
        self.su += u;
        self.sv += v;
        self.sw += w;
        self.suu += u * u;
        self.suv += u * v;
        self.svv += v * v;
        self.suw += u * w;
        self.svw += v * w;
        self.sww += w * w;
    }

    /// The spatial variance of the fitted plane over the arrival points, `g^T Cov(u, v) g`, less its
    /// expected excess from noise (2 fitted slopes: `2 sigma^2 / n`), at least 0; 0 with fewer than 4
    /// samples or collinear ones.
    pub fn explained_variance(&self) -> f64 {
        let n = self.n;
        if n < 4.0 {
            return 0.0;
        }
        let c = |sxy: f64, sx: f64, sy: f64| sxy - sx * sy / n;
        let (uu, uv, vv) = (
            c(self.suu, self.su, self.su),
            c(self.suv, self.su, self.sv),
            c(self.svv, self.sv, self.sv),
        );
        let (uw, vw, ww) = (
            c(self.suw, self.su, self.sw),
            c(self.svw, self.sv, self.sw),
            c(self.sww, self.sw, self.sw),
        );
        let det = uu * vv - uv * uv;
        if det.is_nan() || det <= 1e-12 * (uu * vv).max(f64::MIN_POSITIVE) {
            return 0.0;
        }
        let (gu, gv) = ((vv * uw - uv * vw) / det, (uu * vw - uv * uw) / det);
        let explained = gu * uw + gv * vw;
        let residual = (ww - explained).max(0.0) / (n - 3.0);
        ((explained - 2.0 * residual) / n).max(0.0)
    }
}

/// Casts the round's lines again (same seed: the same lines as the form factors came from) and gathers,
/// per patch, the moments of the radiosity `B_j` arriving from each visible patch `j` against the
/// arrival point. Given a point x of patch i, the patch a line from x reaches is distributed by the
/// point-to-patch form factors, so the mean of the arriving `B_j` there is the received radiosity
/// `B^in(x)`: the fitted plane is its linear trend over the patch.
pub fn arrivals(
    scene: &Scene,
    tracer: &dyn Tracer,
    lines: u64,
    seed: u64,
    radiosity: &[f64],
) -> Result<Vec<ArrivalMoments>, TraceError> {
    let bases: Vec<(Direction, Direction)> = scene
        .patches
        .iter()
        .map(|p| orthonormal_basis(p.normal))
        .collect();
    let point_on = |p: usize, l: &LineF64| -> (f64, f64) {
        let patch = &scene.patches[p];
        let t = (patch.offset - patch.normal.dot(l.origin)) / patch.normal.dot(l.dir);
        let x = l.origin + t * l.dir;
        (x.dot(bases[p].0), x.dot(bases[p].1))
    };
    let per_batch = trace_segments(
        scene,
        tracer,
        lines,
        seed,
        |l, seg, out: &mut Vec<(u32, f64, f64, f64)>| {
            if let Segment::Pair { from, to, .. } = seg {
                let (f, t) = (from as usize, to as usize);
                let (u, v) = point_on(t, l);
                out.push((to, u, v, radiosity[f]));
                let (u, v) = point_on(f, l);
                out.push((from, u, v, radiosity[t]));
            }
        },
    )?;
    let mut moments = vec![ArrivalMoments::default(); scene.patch_count()];
    for batch in per_batch {
        for (p, u, v, w) in batch {
            moments[p as usize].add(u, v, w);
        }
    }
    Ok(moments)
}

/// Smoothness: how far the received radiosity departs from a constant over each patch, the jump of
/// `B^in` across the patch. From the linear trend `g` fitted to the arriving radiosity
/// ([`arrivals`]), the score is `A_i g^T Cov_i g`: the squared L2 error of a constant `B^in` over the
/// patch, which splitting into 4 cuts by about 4 (each child has a quarter of the area and of the
/// spread). A trend over the patch itself, rather than a jump to a neighbour, also serves a face that
/// is still a single patch with no coplanar neighbour.
pub fn smoothness(areas: &[f64], moments: &[ArrivalMoments]) -> Vec<f64> {
    areas
        .iter()
        .zip(moments)
        .map(|(a, m)| a * m.explained_variance())
        .collect()
}

/// The form factors of a sample.
pub fn form_factors(scene: &Scene, sample: &PairKernelSums) -> FormFactors {
    FormFactors::from_counts(scene.patch_count(), &sample.counts, &sample.escapes)
}
