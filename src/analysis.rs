//! One analysis run: lines -> hits -> pairs -> counts -> measures, with standard errors from groups.

use std::time::Instant;

use crate::measure::visibility::{self, ContinuousValues, DiscreteValues};
use crate::measure::Estimate;
use crate::sample::lines::LineSource;
use crate::sample::tally::{trace_batches, BatchPlan, Tally, TracedBatches, Wanted};
use crate::scene::Scene;
use crate::trace::{TraceError, Tracer};

/// Default number of independent groups of lines behind every standard error.
pub const DEFAULT_GROUPS: usize = 16;

/// What to run.
#[derive(Clone, Copy, Debug)]
pub struct AnalysisConfig {
    /// Global lines to cast.
    pub lines: u64,
    /// Seed of the line streams.
    pub seed: u64,
    /// Which measures to gather.
    pub wanted: Wanted,
    /// Groups for the standard errors (see [`crate::measure::estimate`]).
    pub groups: usize,
}

/// The visibility measures of a run, each with its standard error; `None` when not computed.
#[derive(Clone, Debug, Default)]
pub struct VisibilityEstimates {
    /// Eq. (19), exact.
    pub positional_entropy: Option<Estimate>,
    /// Eq. (17).
    pub entropy: Option<Estimate>,
    /// H(X, Y).
    pub joint_entropy: Option<Estimate>,
    /// Eq. (21).
    pub mutual_information: Option<Estimate>,
    /// Eq. (27).
    pub continuous_mutual_information: Option<Estimate>,
    /// Sec. 3.3: discretisation accuracy I_s / I_s^c.
    pub accuracy: Option<Estimate>,
    /// Sec. 3.3: discretisation relative error (I_s^c - I_s) / I_s^c.
    pub relative_error: Option<Estimate>,
    /// Eq. (22), per line.
    pub mse_per_line: Option<Estimate>,
}

/// Everything a run found.
#[derive(Clone, Debug)]
pub struct Analysis {
    /// Lines cast.
    pub lines: u64,
    /// Seed.
    pub seed: u64,
    /// Wall-clock seconds of tracing, counting and measuring.
    pub seconds: f64,
    /// Groups behind the standard errors.
    pub groups: usize,
    /// Canonical hits.
    pub hits: u64,
    /// Visible pairs.
    pub pairs: u64,
    /// Segments escaping from a front side (0 in a closed scene).
    pub escapes: u64,
    /// Segments joining no two front sides.
    pub unpaired: u64,
    /// Pairs with coincident points, left out of eq. (27).
    pub degenerate_pairs: u64,
    /// Distinct patch pairs seen (when counted).
    pub distinct_pairs: Option<usize>,
    /// Patches no segment left from, and their area fraction (when counted).
    pub unsampled: Option<(usize, f64)>,
    /// The measures.
    pub visibility: VisibilityEstimates,
    /// The full-run counts, for form factors (when counted).
    pub tally: Tally,
}

/// Measures of one group (or of the whole run).
#[derive(Clone, Copy, Debug)]
struct GroupValues {
    discrete: Option<DiscreteValues>,
    continuous: Option<ContinuousValues>,
}

impl GroupValues {
    fn of(scene: &Scene, areas: &[f64], t: &Tally) -> Self {
        GroupValues {
            discrete: t
                .counts
                .as_ref()
                .map(|c| visibility::discrete(areas, c, &t.escapes_by_patch)),
            continuous: ContinuousValues::from_sum(t.cmi_sum, t.cmi_pairs)
                .filter(|_| scene.patch_count() > 0),
        }
    }

    fn accuracy(&self) -> Option<f64> {
        Some(self.discrete?.mutual_information / self.continuous?.mutual_information)
    }
}

/// Runs an analysis: casts `cfg.lines` independent global lines through `scene` with `tracer`.
///
/// Uses the current rayon thread pool; results do not depend on its size.
pub fn analyze(
    scene: &Scene,
    tracer: &dyn Tracer,
    cfg: &AnalysisConfig,
) -> Result<Analysis, TraceError> {
    analyze_with(scene, tracer, cfg, LineSource::Independent)
}

/// Runs an analysis with lines from `source`: independent lines as [`analyze`], or bundles of parallel
/// lines (the line count then rounds up to whole bundles). A bundle never straddles two standard-error
/// groups, so the group-to-group spread, and with it every standard error, includes the correlation of
/// the lines within a bundle.
pub fn analyze_with(
    scene: &Scene,
    tracer: &dyn Tracer,
    cfg: &AnalysisConfig,
    source: LineSource,
) -> Result<Analysis, TraceError> {
    let start = Instant::now();
    let plan = BatchPlan::for_source(cfg.lines, source);
    let batches = plan.batches();
    let groups = (cfg.groups.max(1) as u64).min(batches.max(1));
    let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();

    let mut merged = MergeStack::default();
    let mut per_group = Vec::with_capacity(groups as usize);
    // Group g's counting (sorting its pair keys), measures and merge into the total run while group
    // g + 1 is traced (rayon::join lets an idle thread take them), so this serial work hides behind the
    // parallel tracing.
    let mut done: Option<TracedBatches> = None;
    for g in 0..=groups {
        let range = g * batches / groups..(g + 1) * batches / groups;
        let (next, ()) = rayon::join(
            || {
                (g < groups)
                    .then(|| {
                        trace_batches(scene, tracer, &plan, source, cfg.seed, range, cfg.wanted)
                    })
                    .transpose()
            },
            || {
                if let Some(traced) = done.take() {
                    let tally = traced.into_tally(scene, cfg.wanted);
                    per_group.push(GroupValues::of(scene, &areas, &tally));
                    merged.push(tally);
                }
            },
        );
        done = next?;
    }
    let total = merged
        .finish()
        .unwrap_or_else(|| Tally::empty(scene, cfg.wanted));
    let all = GroupValues::of(scene, &areas, &total);
    let visibility = estimates(&areas, &all, &per_group, cfg.wanted);

    Ok(Analysis {
        lines: total.lines,
        seed: cfg.seed,
        seconds: start.elapsed().as_secs_f64(),
        groups: groups as usize,
        hits: total.hits,
        pairs: total.pairs,
        escapes: total.escapes,
        unpaired: total.unpaired,
        degenerate_pairs: total.degenerate_pairs,
        distinct_pairs: total.counts.as_ref().map(|c| c.distinct_pairs()),
        unsampled: all
            .discrete
            .map(|d| (d.unsampled_patches, d.unsampled_area_fraction)),
        visibility,
        tally: total,
    })
}

/// Merges group tallies like a binary counter: two tallies of equal weight merge into one of the next, so
/// every count is merged O(log G) times (merging each group into one running total would touch all
/// distinct pairs G times) and at most log2(G) tallies are alive.
#[derive(Default)]
struct MergeStack {
    /// (weight, tally), weights strictly decreasing from bottom to top.
    stack: Vec<(u32, Tally)>,
}

impl MergeStack {
    fn push(&mut self, tally: Tally) {
        let mut item = (0u32, tally);
        while let Some(top) = self.stack.last() {
            if top.0 != item.0 {
                break;
            }
            let (weight, mut below) = self.stack.pop().expect("checked non-empty");
            // Merge in group order so that f64 sums are added in a fixed order.
            below.merge(&item.1);
            item = (weight + 1, below);
        }
        self.stack.push(item);
    }

    fn finish(mut self) -> Option<Tally> {
        let mut acc = self.stack.pop()?.1;
        while let Some((_, mut below)) = self.stack.pop() {
            below.merge(&acc);
            acc = below;
        }
        Some(acc)
    }
}

fn estimates(
    areas: &[f64],
    all: &GroupValues,
    groups: &[GroupValues],
    wanted: Wanted,
) -> VisibilityEstimates {
    let est = |f: &dyn Fn(&GroupValues) -> Option<f64>| -> Option<Estimate> {
        let value = f(all)?;
        let per: Vec<f64> = groups.iter().filter_map(f).collect();
        Some(if per.len() == groups.len() {
            Estimate::from_groups(value, &per)
        } else {
            Estimate {
                value,
                stderr: None,
            }
        })
    };
    let hp = -visibility::area_distribution(areas)
        .iter()
        .map(|&x| crate::measure::entropy::xlog2x(x))
        .sum::<f64>();
    VisibilityEstimates {
        positional_entropy: Some(Estimate::exact(hp)),
        entropy: est(&|g| Some(g.discrete?.entropy)),
        joint_entropy: est(&|g| Some(g.discrete?.joint_entropy)),
        mutual_information: est(&|g| Some(g.discrete?.mutual_information)),
        continuous_mutual_information: est(&|g| Some(g.continuous?.mutual_information)),
        accuracy: if wanted.discrete && wanted.continuous {
            est(&|g| g.accuracy())
        } else {
            None
        },
        relative_error: if wanted.discrete && wanted.continuous {
            est(&|g| Some(1.0 - g.accuracy()?))
        } else {
            None
        },
        mse_per_line: est(&|g| Some(g.discrete?.mse_per_line)),
    }
}
