//! What a run is: [`RunSpec`], every setting that determines its numbers.
//!
//! A spec is a value: the command line is parsed into one once, a saved state stores it as it is
//! ([`super::persist`]), and a resumed or merged run compares specs by their derived equality
//! ([`RunSpec::difference`] says how two differ). How a run runs (its threads, its tracer, its
//! progress display, where its outputs go) is not part of it: none of that changes a number. The
//! tracer and its query are left out on purpose: Embree and the pure-Rust tracer give the same hits by
//! design (`scx crosscheck` checks it line by line), so parts of one run may be traced by either.

use serde::{Deserialize, Serialize};

use super::control::Budget;
use super::errors::ErrorMethod;
use super::plan::BatchPlan;
use crate::measure::estimators::EntropyEstimator;
use crate::measure::radiosity::SolveOptions;
use crate::sample::bounds::{
    lines_to_draw, smallest_container, sphere_lines_for_drawn, sphere_lines_of_drawn,
    tightest_container, LineBound,
};
use crate::sample::lines::{LineSource, Sampler};
use crate::scene::Scene;

/// Default number of independent groups of lines behind every standard error of a run of independent
/// lines.
pub const DEFAULT_GROUPS: usize = 16;

/// Default number of standard-error groups of a run of randomised quasi-Monte Carlo lines: each group is
/// one scrambled Sobol' sequence, which converges faster than independent draws, so fewer and longer
/// sequences give a tighter estimate (docs/sampling.md, "The number of groups").
pub const DEFAULT_SOBOL_GROUPS: usize = 8;

/// The standard-error groups of a run drawn by `sampler` when none are asked for.
pub fn default_groups(sampler: Sampler) -> usize {
    match sampler {
        Sampler::Independent => DEFAULT_GROUPS,
        Sampler::Sobol => DEFAULT_SOBOL_GROUPS,
    }
}

/// The entropy estimator behind the bias-corrected H_s and I_s, chosen by measurement against the exact
/// I_s of `@cube:N` (docs/results.md, "The default estimator").
pub const DEFAULT_ESTIMATOR: EntropyEstimator = EntropyEstimator::ChaoWangJost;

/// Which families of measures a run computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Measures {
    /// The discrete measures from pair counts (H_s, I_s, E(MSE), ..., paper sec. 3.1).
    pub discrete: bool,
    /// The continuous mutual information I_s^c (eq. 27, sec. 3.2).
    pub continuous: bool,
    /// The radiosity measures (sec. 4), when the scene emits; they need the pair counts, which are then
    /// gathered whatever `discrete` says.
    pub radiosity: bool,
}

impl Measures {
    /// Every measure.
    pub const ALL: Measures = Measures {
        discrete: true,
        continuous: true,
        radiosity: true,
    };

    /// The visibility measures only (no radiosity).
    pub const VISIBILITY: Measures = Measures {
        discrete: true,
        continuous: true,
        radiosity: false,
    };
}

/// Where a run is asked to draw its lines (`--lines-through`): through a given bound, or `auto`, the
/// bound chosen for the scene and the sampler ([`RunSpec::auto_bound`]). A spec holds the bound chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LinesThrough {
    /// The bound [`RunSpec::auto_bound`] chooses.
    #[default]
    Auto,
    /// This bound.
    Bound(LineBound),
}

impl LinesThrough {
    /// Every choice with its name.
    pub const NAMES: [(&'static str, LinesThrough); 4] = [
        ("auto", LinesThrough::Auto),
        ("sphere", LinesThrough::Bound(LineBound::Sphere)),
        ("box", LinesThrough::Bound(LineBound::Box)),
        ("polytope", LinesThrough::Bound(LineBound::Polytope)),
    ];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            LinesThrough::Auto => "auto",
            LinesThrough::Bound(b) => b.name(),
        }
    }

    /// Parses a name as printed by [`LinesThrough::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, t)| t)
    }
}

/// How a run is asked to draw its lines (`--sampler`): by a given sampler, or `auto`, the sampler chosen
/// for the run's measures ([`RunSpec::auto_sampler`]). A spec holds the sampler chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SamplerChoice {
    /// The sampler [`RunSpec::auto_sampler`] chooses.
    #[default]
    Auto,
    /// This sampler.
    Given(Sampler),
}

impl SamplerChoice {
    /// Every choice with its name.
    pub const NAMES: [(&'static str, SamplerChoice); 3] = [
        ("auto", SamplerChoice::Auto),
        ("independent", SamplerChoice::Given(Sampler::Independent)),
        ("sobol", SamplerChoice::Given(Sampler::Sobol)),
    ];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SamplerChoice::Auto => "auto",
            SamplerChoice::Given(s) => s.name(),
        }
    }

    /// Parses a name as printed by [`SamplerChoice::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, c)| c)
    }
}

/// A run: every setting that determines its numbers.
///
/// Two runs can be parts of one run (shards to merge, a state to resume) when their specs are equal but
/// for [`RunSpec::lines`] and [`RunSpec::per_patch`] ([`RunSpec::common`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSpec {
    /// Global lines to cast (a cap when a budget is set): the lines drawn, through [`RunSpec::bound`]
    /// (as many as asked through the sphere; [`RunSpec::through`] turns the sphere's lines asked into
    /// those to draw). Parts of one run may differ: a resumed run goes on to more lines.
    pub lines: u64,
    /// Seed of the line streams.
    pub seed: u64,
    /// Independent lines, or bundles of parallel lines ([`LineSource`]); a bundle never straddles two
    /// batches, so the group spread includes the correlation within a bundle.
    pub source: LineSource,
    /// Independent lines, or randomised quasi-Monte Carlo lines: one scrambled Sobol' sequence per
    /// standard-error group ([`Sampler`]; not with bundles). Absent from states saved before it existed,
    /// which read as independent lines.
    #[serde(default)]
    pub sampler: Sampler,
    /// Lines through the bounding sphere or the bounding box ([`LineBound`]; not with bundles, nor with
    /// `enclose`). Absent from states saved before it existed, which read as the sphere.
    #[serde(default)]
    pub bound: LineBound,
    /// Groups for the standard errors ([`super::errors`]).
    pub groups: usize,
    /// Which measures to compute.
    pub measures: Measures,
    /// The estimator of the bias-corrected H_s and I_s.
    pub estimator: EntropyEstimator,
    /// How the standard errors of the count-based measures are estimated.
    pub errors: ErrorMethod,
    /// Close an open scene with the environment patch ([`crate::sample::environment`]): escapes become
    /// pairs with it, and every measure is that of the enclosed scene. Changes nothing when nothing
    /// escapes.
    pub enclose: bool,
    /// When to stop before `lines`.
    pub budget: Budget,
    /// How the radiosity system is solved.
    pub solve: SolveOptions,
    /// Also share the measures out among the patches (the per-patch results); gathers eq. (27)'s terms
    /// per patch, which costs nothing when left off. With `enclose` on an open scene, the enclosed
    /// scene's, the environment's row among them (gathering the terms of each patch's escapes too).
    /// Parts of one run may differ: their merge keeps the per-patch sums only when every part has them.
    pub per_patch: bool,
}

impl RunSpec {
    /// `lines` lines from `seed`, every measure, default groups and estimator, no budget, independent
    /// lines through the bounding sphere; [`RunSpec::through`] with [`LinesThrough::Auto`] draws them
    /// where `scx analyze` does (the smallest container, the same estimates for less time).
    pub fn new(lines: u64, seed: u64) -> Self {
        RunSpec {
            lines,
            seed,
            source: LineSource::Independent,
            sampler: Sampler::Independent,
            bound: LineBound::Sphere,
            groups: DEFAULT_GROUPS,
            measures: Measures::ALL,
            estimator: DEFAULT_ESTIMATOR,
            errors: ErrorMethod::Groups,
            enclose: false,
            budget: Budget::default(),
            solve: SolveOptions::default(),
            per_patch: false,
        }
    }

    /// Whether the settings go together: the Sobol' sampler and lines through the box are single lines,
    /// not bundles; the environment of `enclose` is the bounding sphere, which lines through the box do
    /// not sample.
    pub fn check(&self) -> Result<(), SpecError> {
        match (self.sampler, self.source, self.bound) {
            (Sampler::Sobol, LineSource::Bundles { grid }, _) => {
                Err(SpecError::SobolBundles { grid })
            }
            (_, LineSource::Bundles { grid }, bound) if bound != LineBound::Sphere => {
                Err(SpecError::BoxBundles { grid, bound })
            }
            (_, _, bound) if bound != LineBound::Sphere && self.enclose => {
                Err(SpecError::BoxEnclose { bound })
            }
            _ => Ok(()),
        }
    }

    /// The sampler `--sampler auto` chooses: Sobol' lines for a run that counts no patch pairs (its
    /// measures I_s^c alone, eq. 27, an integral over the lines that randomised quasi-Monte Carlo lines
    /// estimate with far less spread at about the same cost, with honest group errors: docs/sampling.md,
    /// "The default"); independent lines for a run that counts pairs, whose bias-corrected readings are
    /// honest under Sobol' lines only once debiased by the groups' jackknife, which leaves them looser
    /// where rows are undersampled and leaves the per-patch corrected columns biased; and for bundles.
    pub fn auto_sampler(&self) -> Sampler {
        let counts_pairs = self.measures.discrete || self.measures.radiosity || self.per_patch;
        if counts_pairs || self.source != LineSource::Independent {
            Sampler::Independent
        } else {
            Sampler::Sobol
        }
    }

    /// This spec with its lines drawn by `choice` (`auto`: [`RunSpec::auto_sampler`]); settled before
    /// its bound ([`RunSpec::through`]), which depends on the sampler.
    pub fn drawn_by(self, choice: SamplerChoice) -> RunSpec {
        let sampler = match choice {
            SamplerChoice::Auto => self.auto_sampler(),
            SamplerChoice::Given(s) => s,
        };
        RunSpec { sampler, ..self }
    }

    /// This spec with the standard-error groups asked for, or its sampler's default ones
    /// ([`default_groups`]) when none are; settled after its sampler ([`RunSpec::drawn_by`]).
    pub fn grouped(self, asked: Option<usize>) -> RunSpec {
        RunSpec {
            groups: asked.unwrap_or(default_groups(self.sampler)),
            ..self
        }
    }

    /// The bound `--lines-through auto` chooses for `scene`: for the Sobol' sampler, the tightest
    /// container of the scene ([`tightest_container`]: the box for rooms, the polytope for solids and
    /// objects, the sphere when neither is smaller), whose lines cover the space of lines far more evenly
    /// (docs/sampling.md, "Lines through the bounding box"); for independent lines, the smallest container
    /// ([`smallest_container`]), which leaves every estimate's distribution as the sphere's lines give it
    /// and does not draw the lines that would miss the scene. Bundles and the environment of `enclose`
    /// need the sphere.
    pub fn auto_bound(&self, scene: &Scene) -> LineBound {
        if self.source != LineSource::Independent || self.enclose {
            return LineBound::Sphere;
        }
        match self.sampler {
            Sampler::Sobol => tightest_container(scene),
            Sampler::Independent => smallest_container(scene),
        }
    }

    /// This spec for `scene`, its lines drawn through `through`, with its line count, given in lines
    /// through the bounding sphere (the paper's unit, and `--lines`'s), turned into the lines to draw
    /// ([`RunSpec::lines_for`]).
    pub fn through(self, scene: &Scene, through: LinesThrough) -> RunSpec {
        let bound = match through {
            LinesThrough::Auto => self.auto_bound(scene),
            LinesThrough::Bound(b) => b,
        };
        let placed = RunSpec { bound, ..self };
        RunSpec {
            lines: placed.lines_for(scene, self.lines),
            ..placed
        }
    }

    /// How many lines this run draws on `scene` to be worth `sphere_lines` lines through its bounding
    /// sphere ([`lines_to_draw`]): as many through the sphere, fewer through a box smaller than it.
    pub fn lines_for(&self, scene: &Scene, sphere_lines: u64) -> u64 {
        lines_to_draw(scene, self.bound, sphere_lines)
    }

    /// How the run's lines are cut into batches: fixed by the line count, or full batches when a budget
    /// may end the run anywhere.
    pub fn plan(&self) -> BatchPlan {
        if self.budget.is_open_ended() {
            BatchPlan::open_ended(self.lines, self.source)
        } else {
            BatchPlan::for_source(self.lines, self.source)
        }
    }

    /// The standard-error groups of the run: the groups asked for, but one per batch when a short run
    /// has fewer batches than that (and always at least 2).
    pub fn group_count(&self) -> usize {
        let batches = self.plan().batches();
        (self.groups.max(2) as u64).min(batches.max(2)) as usize
    }

    /// The settings two parts of one run must share: the spec without its line count and per-patch
    /// flag.
    pub fn common(&self) -> RunSpec {
        RunSpec {
            lines: 0,
            per_patch: false,
            ..self.clone()
        }
    }

    /// The same run continued to `lines` lines (a resume): refused when `lines` is fewer than the run's,
    /// or when the longer run would cut its lines differently (other batches or groups), which would
    /// change the numbers of the lines already cast.
    pub fn extended_to(&self, lines: u64) -> Result<RunSpec, ExtendError> {
        let longer = RunSpec {
            lines,
            ..self.clone()
        };
        if lines < self.lines {
            return Err(ExtendError::Fewer {
                lines: self.lines,
                asked: lines,
            });
        }
        let (old, new) = (self.plan(), longer.plan());
        if new.batch_size != old.batch_size || longer.group_count() != self.group_count() {
            return Err(ExtendError::CutDifferently {
                lines: self.lines,
                most: BatchPlan::most_lines_with_batch(old.batch_size).max(self.lines),
                batch_size: old.batch_size,
                asked: lines,
                asked_batch_size: new.batch_size,
                asked_groups: longer.group_count(),
                full_from: BatchPlan::FULL_FROM,
            });
        }
        Ok(longer)
    }

    /// The first settings in which two runs that should be parts of one run differ, as `(setting, ours,
    /// theirs)` in words (nested settings as `budget.target`); `None` when they can be combined. The
    /// line counts are compared too unless `lines_may_differ`.
    pub fn difference(&self, other: &RunSpec, lines_may_differ: bool) -> Option<SpecDifference> {
        let (ours, theirs) = (self.common(), other.common());
        let lines_differ = !lines_may_differ && self.lines != other.lines;
        if ours == theirs && !lines_differ {
            return None;
        }
        // The settings before the line count: a part drawn through another bound draws another number
        // of lines too, and the bound is the cause to name.
        let as_json = |s: &RunSpec| serde_json::to_value(s).expect("a spec always serialises");
        first_difference("", &as_json(&ours), &as_json(&theirs)).or_else(|| {
            lines_differ.then(|| SpecDifference {
                setting: "lines".to_string(),
                ours: self.lines.to_string(),
                theirs: other.lines.to_string(),
            })
        })
    }
}

/// A setting in which two specs differ, with both values in words.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SpecDifference {
    /// The setting (`seed`, `budget.target`).
    pub setting: String,
    /// Its value in the first spec.
    pub ours: String,
    /// Its value in the second.
    pub theirs: String,
}

/// The first differing leaf of two JSON values, by path.
fn first_difference(
    path: &str,
    a: &serde_json::Value,
    b: &serde_json::Value,
) -> Option<SpecDifference> {
    use serde_json::Value;
    if let (Value::Object(x), Value::Object(y)) = (a, b) {
        for (key, va) in x {
            let vb = y.get(key).unwrap_or(&Value::Null);
            let inner = if path.is_empty() {
                key.clone()
            } else {
                format!("{path}.{key}")
            };
            if let Some(d) = first_difference(&inner, va, vb) {
                return Some(d);
            }
        }
        return None;
    }
    (a != b).then(|| SpecDifference {
        setting: path.to_string(),
        ours: in_words(a),
        theirs: in_words(b),
    })
}

/// A JSON value as a reader would write it: strings bare, `null` as `none`, switches as `on`/`off`,
/// whole numbers without a decimal point, lists and objects (`key value`) joined by commas.
fn in_words(v: &serde_json::Value) -> String {
    use serde_json::Value;
    match v {
        Value::Null => "none".into(),
        Value::Bool(b) => if *b { "on" } else { "off" }.into(),
        Value::String(s) => s.clone(),
        Value::Number(n) => match n.as_f64() {
            // Exact in an f64 up to 2^53: beyond, serde's own text keeps every digit.
            Some(x) if n.is_f64() && x.fract() == 0.0 && x.abs() < 9e15 => format!("{x:.0}"),
            _ => n.to_string(),
        },
        Value::Array(items) => items.iter().map(in_words).collect::<Vec<_>>().join(", "),
        Value::Object(m) => m
            .iter()
            .map(|(k, v)| format!("{k} {}", in_words(v)))
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// Settings of a run that contradict each other.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SpecError {
    /// The Sobol' sampler with bundles.
    #[error(
        "the sobol sampler draws single lines, each a point of one randomised Sobol' sequence, and does \
         not take bundles (asked: bundles of {grid} x {grid}); use independent lines for bundles"
    )]
    SobolBundles {
        /// The bundle grid asked for.
        grid: u32,
    },
    /// Lines through the bounding box or polytope with bundles.
    #[error(
        "lines through the bounding {} are drawn one by one, each from a face of it, and do not \
         come in bundles (asked: bundles of {grid} x {grid}); use lines through the sphere for bundles",
        .bound.name()
    )]
    BoxBundles {
        /// The bundle grid asked for.
        grid: u32,
        /// Where the lines were to be drawn.
        bound: LineBound,
    },
    /// Lines through the bounding box or polytope with the environment patch.
    #[error(
        "--enclose makes the bounding sphere the environment patch, and its area is counted from the \
         lines that meet the sphere but not the scene, which lines through the bounding {} leave out; \
         use lines through the sphere with --enclose",
        .bound.name()
    )]
    BoxEnclose {
        /// Where the lines were to be drawn.
        bound: LineBound,
    },
    /// Only the radiosity measures asked for, of a scene where nothing emits: nothing to compute.
    #[error(
        "the radiosity measures need light, and nothing in this scene emits (no material has an \
         emission above 0): nothing to compute; ask for the visibility measures too (--measures)"
    )]
    NothingToCompute,
    /// A precision target on a measure the run's measures do not include.
    #[error(
        "the precision target watches {measure}, which this run does not compute: its measures gather \
         {gathered} (--measures); watch a measure the run computes (--target-measure), or add the \
         measures it needs"
    )]
    TargetNotGathered {
        /// The watched measure's key.
        measure: &'static str,
        /// What the run gathers, in words.
        gathered: &'static str,
    },
}

/// Why a run cannot be continued to more lines.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ExtendError {
    /// Fewer lines than the run has.
    #[error("a run of {lines} lines cannot be continued to fewer lines ({asked})")]
    Fewer {
        /// The run's lines.
        lines: u64,
        /// The lines asked for.
        asked: u64,
    },
    /// The longer run would have other batches or groups.
    #[error(
        "a run of {lines} lines is cut into batches of {batch_size}, and a run can be continued only to \
         line counts cut the same way, here at most {most}: {asked} lines would be batches of \
         {asked_batch_size} in {asked_groups} groups. Runs of {full_from} lines or more all have batches of \
         {} and can be continued to any count: start a run with at least that many lines to continue it \
         freely",
        BatchPlan::MAX_BATCH
    )]
    CutDifferently {
        /// The run's lines.
        lines: u64,
        /// The most lines it can be continued to.
        most: u64,
        /// Its batch size.
        batch_size: u64,
        /// The lines asked for.
        asked: u64,
        /// Their batch size.
        asked_batch_size: u64,
        /// Their groups.
        asked_groups: usize,
        /// The lines from which every run has full batches ([`BatchPlan::FULL_FROM`] lines drawn).
        full_from: u64,
    },
}

impl ExtendError {
    /// This error with its line counts given as `--lines` (and Python's `lines=`) counts them, in lines
    /// through `scene`'s bounding sphere, for a run drawn as `bound` says; its batch sizes stay in lines
    /// drawn.
    pub fn in_sphere_lines(self, scene: &Scene, bound: LineBound) -> ExtendError {
        let worth = |n: u64| sphere_lines_of_drawn(scene, bound, n);
        match self {
            ExtendError::Fewer { lines, asked } => ExtendError::Fewer {
                lines: worth(lines),
                asked: worth(asked),
            },
            ExtendError::CutDifferently {
                lines,
                most,
                batch_size,
                asked,
                asked_batch_size,
                asked_groups,
                full_from,
            } => ExtendError::CutDifferently {
                lines: worth(lines),
                // The most sphere lines that draw no more than `most`.
                most: match most {
                    u64::MAX => most,
                    _ => sphere_lines_for_drawn(scene, bound, most + 1).saturating_sub(1),
                },
                batch_size,
                asked: worth(asked),
                asked_batch_size,
                asked_groups,
                full_from: sphere_lines_for_drawn(scene, bound, full_from),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::Measure;
    use crate::run::control::Target;

    /// Specs that differ only in lines and per-patch sums combine; any other setting is named, nested
    /// ones by their path, in words.
    #[test]
    fn differences_are_named_in_words() {
        let a = RunSpec::new(1_000_000, 1);
        let more = RunSpec {
            per_patch: true,
            ..RunSpec::new(2_000_000, 1)
        };
        assert_eq!(a.difference(&more, true), None);
        let d = a.difference(&more, false).unwrap();
        assert_eq!((d.setting.as_str(), d.ours.as_str()), ("lines", "1000000"));
        let seeded = RunSpec::new(1_000_000, 7);
        let d = a.difference(&seeded, true).unwrap();
        assert_eq!(
            (d.setting, d.ours, d.theirs),
            ("seed".into(), "1".into(), "7".into())
        );
        let targeted = RunSpec {
            budget: Budget {
                seconds: None,
                target: Some(Target {
                    measure: Measure::Entropy,
                    stderr: 0.01,
                }),
            },
            ..a.clone()
        };
        let d = a.difference(&targeted, true).unwrap();
        assert_eq!(d.setting, "budget.target");
        assert_eq!(
            (d.ours.as_str(), d.theirs.as_str()),
            ("none", "measure entropy, stderr 0.01")
        );
    }

    /// A run continues to more lines only when they are cut the same way.
    #[test]
    fn runs_extend_only_when_cut_the_same_way() {
        let run = RunSpec::new(300_000, 1);
        assert_eq!(run.extended_to(700_000).unwrap().lines, 700_000);
        assert!(matches!(
            run.extended_to(100_000),
            Err(ExtendError::Fewer { .. })
        ));
        let short = RunSpec::new(100_000, 1);
        let e = short.extended_to(200_000).unwrap_err().to_string();
        assert!(e.contains("batches of 3125") && e.contains("131072"), "{e}");
        // 100,000 / 32 = 3125 lines a batch, as long as lines / 32 rounds down to 3125: up to 100,031.
        assert!(e.contains("at most 100031"), "{e}");
        assert_eq!(short.extended_to(100_031).unwrap().lines, 100_031);
        assert!(short.extended_to(100_032).is_err());
    }
}
