//! Arguments shared by several commands, and the parsers of their values. Numbers accept `1e6`; a value
//! out of range is refused with a sentence that says what is allowed.

use std::path::PathBuf;

use clap::ValueEnum;
use scene_complexity::EntropyEstimator;
use scene_complexity::Measure;
use scene_complexity::{Backend, Query};
use scene_complexity::{
    ErrorMethod, Measures, RunSpec, Tracing, DEFAULT_ESTIMATOR, DEFAULT_GROUPS,
};
use scene_complexity::{ObjectSet, Planarity, SceneOptions, DEFAULT_PLANARITY};

/// How a scene file is read: non-planar polygons, and objects to flip or make two-sided.
#[derive(clap::Args, Debug, Clone)]
pub struct SceneArgs {
    /// A polygon whose corners leave its plane by at most this fraction of its size is planar (one
    /// patch); a less planar one is split into planar triangles (one warning per file).
    #[arg(long, default_value_t = DEFAULT_PLANARITY, value_parser = parse_tolerance)]
    pub planarity: f64,
    /// Refuse non-planar polygons (exit 2, naming the first) instead of splitting them.
    #[arg(long)]
    pub strict_planarity: bool,
    /// Reverse the normals of these objects (comma separated names: OBJ `o`/`g`, glTF node or mesh, the
    /// file name for PLY and STL); without a list, of every object. Put it after the scene.
    #[arg(long, value_name = "OBJECT,...", num_args = 0..=1, value_delimiter = ',', default_missing_value = "")]
    pub flip_normals: Option<Vec<String>>,
    /// Make these objects two-sided (two patches back to back, one per side, each with the face's area
    /// and material); without a list, every object. Put it after the scene.
    #[arg(long, value_name = "OBJECT,...", num_args = 0..=1, value_delimiter = ',', default_missing_value = "")]
    pub two_sided: Option<Vec<String>>,
}

impl SceneArgs {
    /// The loading options these flags ask for.
    pub fn options(&self) -> SceneOptions {
        let set = |names: &Option<Vec<String>>| match names {
            None => ObjectSet::None,
            Some(list) if list.iter().all(|n| n.is_empty()) => ObjectSet::All,
            Some(list) => {
                ObjectSet::Named(list.iter().filter(|n| !n.is_empty()).cloned().collect())
            }
        };
        SceneOptions {
            planarity: Planarity {
                tolerance: self.planarity,
                strict: self.strict_planarity,
            },
            flip_normals: set(&self.flip_normals),
            two_sided: set(&self.two_sided),
        }
    }
}

/// `--seed`: the seed of the random line streams.
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct Seed {
    /// Seed of the random line streams (a whole number >= 0; accepts `1e3`): the same seed gives the
    /// same lines, and the same numbers, whatever the threads or the tracer.
    #[arg(id = "seed", long = "seed", value_name = "SEED", default_value = "1", value_parser = parse_seed,
          allow_negative_numbers = true)]
    pub value: u64,
}

/// `--threads`: how many worker threads.
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct Threads {
    /// Worker threads; 0 or absent: all cores. Results do not depend on it.
    #[arg(id = "threads", long = "threads", value_name = "THREADS", value_parser = parse_threads,
          allow_negative_numbers = true)]
    pub value: Option<usize>,
}

/// `--tracer`: the tracing backend.
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct Tracer {
    /// Tracing backend (default: rust, the faster; embree when a packet query is asked for). Both give
    /// the same hits (`scx crosscheck`).
    #[arg(id = "tracer", long = "tracer", value_name = "TRACER", value_enum)]
    pub value: Option<TracerArg>,
}

/// Options of every command that casts lines and measures them: how the scene is read, the seed, how
/// the run runs, and how its standard errors and corrections are made.
#[derive(clap::Args, Debug)]
pub struct RunOptions {
    #[command(flatten)]
    pub input: SceneArgs,
    #[command(flatten)]
    pub seed: Seed,
    #[command(flatten)]
    pub threads: Threads,
    #[command(flatten)]
    pub tracer: Tracer,
    /// Ray query: `single`, or `packet4`/`packet8`/`packet16` (Embree, native widths only).
    #[arg(long, default_value = "single", value_parser = parse_query)]
    pub query: Query,
    /// Independent groups of lines behind each standard error (2 to 1024).
    #[arg(long, default_value_t = DEFAULT_GROUPS as u16,
          value_parser = clap::value_parser!(u16).range(2..=1024))]
    pub groups: u16,
    /// Estimator of the bias-corrected H_s and I_s: plug-in, miller-madow, grassberger, chao-shen,
    /// chao-wang-jost.
    #[arg(long, default_value = DEFAULT_ESTIMATOR.name(), value_parser = parse_estimator)]
    pub estimator: EntropyEstimator,
    /// Standard errors of the count-based measures: `groups` (batch means, conservative when rows are
    /// undersampled) or `jackknife` (delete-a-group, closer to the real scatter, ~15% slower on large
    /// meshes). I_s^c always gets batch means.
    #[arg(long, default_value = "groups", value_parser = parse_errors)]
    pub errors: ErrorMethod,
}

impl RunOptions {
    /// The spec of a run of `lines` lines from `seed` with these options: the visibility measures (a
    /// command that wants others says so).
    pub fn spec(&self, lines: u64, seed: u64) -> RunSpec {
        RunSpec {
            measures: Measures::VISIBILITY,
            groups: usize::from(self.groups),
            estimator: self.estimator,
            errors: self.errors,
            ..RunSpec::new(lines, seed)
        }
    }

    /// The tracer these options ask for.
    pub fn tracing(&self) -> Tracing {
        Tracing {
            backend: TracerArg::backend_for(self.tracer.value, self.query),
            query: self.query,
        }
    }
}

/// Where a report goes.
#[derive(clap::Args, Debug, Clone)]
pub struct ReportOutput {
    /// Write the report to FILE instead of standard output (checked writable before any line is cast).
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
}

/// The tracing backends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TracerArg {
    /// Embree 3 or 4 (when built in).
    Embree,
    /// The pure-Rust tracer.
    Rust,
}

impl TracerArg {
    /// The backend to use: the one named, or the default.
    pub fn backend(choice: Option<TracerArg>) -> Backend {
        Self::backend_for(choice, Query::Single)
    }

    /// The backend to use for `query`: the one named, else Embree for packets (only Embree has them),
    /// else the default.
    pub fn backend_for(choice: Option<TracerArg>, query: Query) -> Backend {
        match choice {
            Some(TracerArg::Embree) => Backend::Embree,
            Some(TracerArg::Rust) => Backend::Rust,
            None if query != Query::Single => Backend::Embree,
            None => Backend::default_available(),
        }
    }
}

/// A whole number written as `1000000`, `1e6` or `2.5e6`, within `[min, 1e15]`; `what` names it in
/// messages.
fn parse_whole(s: &str, what: &str, min: u64) -> Result<u64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if v.is_finite() && v < 0.0 {
        return Err(format!("{what} cannot be negative (`{s}`)"));
    }
    if !(v.is_finite() && v.fract() == 0.0 && v >= min as f64 && v <= 1e15) {
        return Err(format!(
            "`{s}`: {what} must be a whole number from {min} to 1e15"
        ));
    }
    Ok(v as u64)
}

/// A line count: a whole number >= 1.
pub fn parse_count(s: &str) -> Result<u64, String> {
    parse_whole(s, "a line count", 1)
}

/// A seed: a whole number >= 0.
pub fn parse_seed(s: &str) -> Result<u64, String> {
    parse_whole(s, "a seed", 0)
}

/// A thread count: 0 means all cores.
pub fn parse_threads(s: &str) -> Result<usize, String> {
    let n = parse_whole(s, "a thread count", 0)?;
    if n > 4096 {
        return Err(format!("`{s}`: at most 4096 threads"));
    }
    Ok(n as usize)
}

/// A planarity tolerance: a fraction of a polygon's size, >= 0.
fn parse_tolerance(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!(
            "`{s}`: need a number >= 0 (a fraction of the polygon's size)"
        )),
    }
}

/// A positive number (seconds, a standard error).
pub fn parse_positive(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(v) if v <= 0.0 => Err(format!("`{s}`: need a positive number, not {v}")),
        _ => Err(format!("`{s}` is not a number")),
    }
}

fn parse_estimator(s: &str) -> Result<EntropyEstimator, String> {
    EntropyEstimator::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = EntropyEstimator::ALL.iter().map(|e| e.name()).collect();
        format!("`{s}`: expected one of {}", names.join(", "))
    })
}

fn parse_errors(s: &str) -> Result<ErrorMethod, String> {
    ErrorMethod::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = ErrorMethod::NAMES.iter().map(|(n, _)| *n).collect();
        format!("`{s}`: expected one of {}", names.join(", "))
    })
}

/// The measures a precision target can watch (`--target-measure`), each with its label in `--help`.
pub fn target_measure_parser() -> impl clap::builder::TypedValueParser<Value = Measure> {
    let values =
        Measure::targets().map(|m| clap::builder::PossibleValue::new(m.key()).help(m.info().label));
    clap::builder::TypedValueParser::map(clap::builder::PossibleValuesParser::new(values), |key| {
        Measure::target_named(&key).expect("a possible value names a target")
    })
}

fn parse_query(s: &str) -> Result<Query, String> {
    Query::parse(s).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_accept_exponents_and_refuse_negatives_with_a_sentence() {
        assert_eq!(parse_count("1e3"), Ok(1000));
        assert_eq!(parse_count("2.5e6"), Ok(2_500_000));
        assert_eq!(parse_seed("1e3"), Ok(1000));
        assert_eq!(parse_seed("0"), Ok(0));
        assert!(parse_count("-5")
            .unwrap_err()
            .contains("cannot be negative"));
        assert!(parse_count("0").unwrap_err().contains("from 1"));
        assert!(parse_count("1.5").is_err());
        assert_eq!(parse_threads("0"), Ok(0));
        assert!(parse_positive("-1").unwrap_err().contains("positive"));
    }
}
