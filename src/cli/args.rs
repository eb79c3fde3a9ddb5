//! Arguments shared by several commands, and the parsers of their values. Numbers accept `1e6`; a value
//! out of range is refused with a sentence that says what is allowed.

use std::path::PathBuf;

use clap::ValueEnum;
use scene_complexity::{Backend, EntropyEstimator, Measure, Query};
use scene_complexity::{ErrorMethod, Measures, RunSpec, Tracing, DEFAULT_ESTIMATOR};
use scene_complexity::{ObjectSet, Planarity, Reach, ReadPolicy, SceneOptions, DEFAULT_PLANARITY};

/// How a scene file is read: non-planar polygons, and objects to flip or make two-sided.
#[derive(clap::Args, Debug, Clone)]
pub struct SceneArgs {
    /// A polygon whose corners leave its plane by at most this fraction of its size is planar (one
    /// patch); a less planar one is split into planar triangles (one warning per file).
    #[arg(long, default_value_t = DEFAULT_PLANARITY, value_parser = parse_tolerance,
          allow_negative_numbers = true)]
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
    #[command(flatten)]
    pub reading: ReadArgs,
}

impl SceneArgs {
    /// The reading policy these flags ask for: where references may point, how large a file may be.
    pub fn policy(&self) -> ReadPolicy {
        self.reading.policy()
    }

    /// The loading options these flags ask for. The reading policy is not among them: a saved run keeps
    /// the options, and the policy belongs to one reading ([`SceneArgs::policy`]).
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

/// What reading a scene may touch: how far its references reach, how large a file may be (a scene file
/// is untrusted input). Not part of a run: a resume or a merge may read the same scene under others.
#[derive(clap::Args, Debug, Clone)]
pub struct ReadArgs {
    /// Let the scene's references (glTF buffer URIs, OBJ `mtllib`) name files anywhere: absolute paths,
    /// `..`, `file:` URIs, links out of the folder. Without it they are read only inside the scene's
    /// folder (a scene file is untrusted input).
    #[arg(long)]
    pub read_anywhere: bool,
    /// The largest file read for the scene (the scene file or standard input, each glTF buffer, each
    /// MTL library): a number of bytes, or with a unit (`512MB`, `2GiB`; K, M, G, T are powers of 1000,
    /// KiB, MiB, GiB, TiB of 1024). Memory grows with the scene, so this bounds it too.
    #[arg(long, value_name = "SIZE", default_value = "256MiB", value_parser = parse_size)]
    pub max_file_size: u64,
}

impl ReadArgs {
    /// The reading policy these flags ask for: where references may point, how large a file may be.
    pub fn policy(&self) -> ReadPolicy {
        ReadPolicy {
            reach: if self.read_anywhere {
                Reach::Anywhere
            } else {
                Reach::SceneFolder
            },
            max_bytes: self.max_file_size,
        }
    }
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
    /// Independent groups of lines behind each standard error, 2 to 1024 [default: 16, or 8 for sobol
    /// lines, whose groups are each one randomised sequence and tighter when longer].
    #[arg(long, value_parser = parse_groups, allow_negative_numbers = true)]
    pub groups: Option<u16>,
    /// Estimator of the bias-corrected H_s and I_s: plug-in, miller-madow, grassberger, chao-shen,
    /// chao-wang-jost.
    #[arg(long, default_value = DEFAULT_ESTIMATOR.name(), value_parser = parse_estimator)]
    pub estimator: EntropyEstimator,
    /// Standard errors of the count-based measures: `groups` (batch means, conservative when rows are
    /// undersampled) or `jackknife` (delete-a-group, closer to the real scatter, ~15% slower on large
    /// meshes; below a row coverage of 0.5 only its error can make the corrected E(MSE) ok). I_s^c
    /// always gets batch means.
    #[arg(long, default_value = "groups", value_parser = parse_errors)]
    pub errors: ErrorMethod,
}

impl RunOptions {
    /// The spec of a run of `lines` lines from `seed` with these options: the visibility measures (a
    /// command that wants others says so).
    pub fn spec(&self, lines: u64, seed: u64) -> RunSpec {
        RunSpec {
            measures: Measures::VISIBILITY,
            estimator: self.estimator,
            errors: self.errors,
            ..RunSpec::new(lines, seed)
        }
        .grouped(self.groups_asked())
    }

    /// The standard-error groups asked for, if any (else the sampler's default, [`RunSpec::grouped`]).
    pub fn groups_asked(&self) -> Option<usize> {
        self.groups.map(usize::from)
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
    /// Write the report to FILE instead of standard output (`-`: standard output; checked writable
    /// before any line is cast). A `.json` or `.csv` name picks that format when --format is not given;
    /// one that names a format the command does not write, or that --format contradicts, is refused.
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

/// The largest count any flag takes (lines, seeds): far beyond any run, small enough that every
/// such number is exact in an f64.
pub const MAX_WHOLE: u64 = 1_000_000_000_000_000;

/// A bound as the user would write it: `1e15` rather than its sixteen digits.
fn shown(n: u64) -> String {
    if n == MAX_WHOLE {
        "1e15".into()
    } else {
        n.to_string()
    }
}

/// Refuses a value that is a flag (`--quiet`, `-q`): list flags take values that start with `-`
/// (`--camera -1,0,2,...`), so a flag whose value was forgotten would take the next flag for it.
pub fn not_a_flag(s: &str) -> Result<(), String> {
    let mut chars = s.trim().chars();
    let flag = chars.next() == Some('-')
        && chars
            .next()
            .is_some_and(|c| c == '-' || c.is_ascii_alphabetic())
        && s.trim().parse::<f64>().is_err();
    if flag {
        return Err(format!(
            "`{s}` is a flag, not a value: the flag before it needs its value first"
        ));
    }
    Ok(())
}

/// A whole number written as `1000000`, `1e6` or `2.5e6`, within `[min, max]` (`max` at most 1e15);
/// `what` names it in messages, which always give the range.
pub fn parse_whole_in(s: &str, what: &str, min: u64, max: u64) -> Result<u64, String> {
    not_a_flag(s)?;
    let range = format!(
        "{what} must be a whole number from {} to {}",
        shown(min),
        shown(max)
    );
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number: {range}"))?;
    if v.is_finite() && v < 0.0 {
        return Err(format!(
            "`{s}`: {what} cannot be negative: it is a whole number from {} to {}",
            shown(min),
            shown(max)
        ));
    }
    if !(v.is_finite() && v.fract() == 0.0 && v >= min as f64 && v <= max as f64) {
        return Err(format!("`{s}`: {range}"));
    }
    Ok(v as u64)
}

fn parse_whole(s: &str, what: &str, min: u64) -> Result<u64, String> {
    parse_whole_in(s, what, min, MAX_WHOLE)
}

/// A line count: a whole number >= 1.
pub fn parse_count(s: &str) -> Result<u64, String> {
    parse_whole(s, "a line count", 1)
}

/// A seed: a whole number >= 0.
pub fn parse_seed(s: &str) -> Result<u64, String> {
    parse_whole(s, "a seed", 0)
}

/// The most worker threads a run may ask for.
const MAX_THREADS: u64 = 4096;

/// A thread count: 0 means all cores.
pub fn parse_threads(s: &str) -> Result<usize, String> {
    parse_whole_in(s, "a thread count (0: all cores)", 0, MAX_THREADS).map(|n| n as usize)
}

/// `--groups`: the independent groups behind each standard error, 2 to 1024 (fewer gives no error
/// bar; more makes each group too small to be normal).
pub fn parse_groups(s: &str) -> Result<u16, String> {
    parse_whole_in(s, "the number of groups", 2, 1024).map(|n| n as u16)
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

/// A size in bytes: a whole number (`1e9` too), or a number with a unit: K, M, G, T (powers of 1000,
/// a trailing `B` allowed) or KiB, MiB, GiB, TiB (powers of 1024), in any case.
pub fn parse_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| c.is_ascii_alphabetic() && c != 'e' && c != 'E')
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let scale: f64 = match unit.to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "k" | "kb" => 1e3,
        "m" | "mb" => 1e6,
        "g" | "gb" => 1e9,
        "t" | "tb" => 1e12,
        "kib" => 1024.0,
        "mib" => 1024.0 * 1024.0,
        "gib" => 1024.0 * 1024.0 * 1024.0,
        "tib" => 1024.0 * 1024.0 * 1024.0 * 1024.0,
        _ => {
            return Err(format!(
                "`{s}`: unknown unit `{unit}`; use bytes, K, M, G, T (powers of 1000) or KiB, MiB, GiB, \
                 TiB (powers of 1024)"
            ))
        }
    };
    let value = number
        .trim()
        .parse::<f64>()
        .ok()
        .map(|v| v * scale)
        .filter(|v| v.is_finite() && *v >= 1.0 && *v <= 1e18)
        .ok_or_else(|| {
            format!("`{s}`: need a size from 1 byte to 1e18 bytes, such as 512MB or 2GiB")
        })?;
    Ok(value.round() as u64)
}

/// A positive number (seconds, a standard error).
pub fn parse_positive(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(v) if v <= 0.0 => Err(format!("`{s}`: need a positive number, not {v}")),
        _ => Err(format!("`{s}` is not a number")),
    }
}

/// The forms a duration may take, for messages.
const DURATION_FORMS: &str =
    "seconds (`90`, `1e3`, `0.5`) or a duration with units (`30s`, `5m`, `2h`, `1h30m`, `1d`)";

/// A duration in seconds (`--seconds`, `--checkpoint-every`): a plain number of seconds, or a duration
/// with units as humantime reads it. One longer than any clock is returned as it is (a plain number)
/// or as 2^64 seconds (with units): the run treats both as no limit.
pub fn parse_seconds(s: &str) -> Result<f64, String> {
    let t = s.trim();
    if let Ok(v) = t.parse::<f64>() {
        return match v {
            v if v.is_finite() && v > 0.0 => Ok(v),
            v if v <= 0.0 => Err(format!("`{s}`: need a duration above 0: {DURATION_FORMS}")),
            _ => Err(format!("`{s}` is not a duration: need {DURATION_FORMS}")),
        };
    }
    match humantime::parse_duration(t) {
        Ok(d) if d.is_zero() => Err(format!("`{s}`: need a duration above 0: {DURATION_FORMS}")),
        Ok(d) => Ok(d.as_secs_f64()),
        // Whole units beyond humantime's range (thousands of years) are no limit, as plain seconds
        // are; a fraction may instead be below a nanosecond, which no clock counts.
        Err(humantime::DurationError::NumberOverflow) if !t.contains('.') => Ok(u64::MAX as f64),
        Err(humantime::DurationError::NumberOverflow) => Err(format!(
            "`{s}`: too long, or more precise than a nanosecond; for no limit leave the flag out"
        )),
        Err(_) => Err(format!("`{s}` is not a duration: need {DURATION_FORMS}")),
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

/// Refuses `--target-measure` without `--target-stderr`: it names the measure a precision target
/// watches, and with no target it would be accepted and do nothing.
pub fn check_target_measure(measure: Option<Measure>, stderr: Option<f64>) -> Result<(), String> {
    match (measure, stderr) {
        (Some(m), None) => Err(format!(
            "--target-measure {} needs --target-stderr E: it names the measure a precision target \
             watches, and there is no target without --target-stderr",
            m.key()
        )),
        _ => Ok(()),
    }
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
        assert_eq!(parse_size("256MiB"), Ok(256 << 20));
        assert_eq!(parse_size("2GB"), Ok(2_000_000_000));
        assert_eq!(parse_size("1e9"), Ok(1_000_000_000));
        assert_eq!(parse_size("1.5 kib"), Ok(1536));
        assert_eq!(parse_size("100"), Ok(100));
        assert!(parse_size("2 parsecs")
            .unwrap_err()
            .contains("unknown unit"));
        assert!(parse_size("-1GB").is_err());
        assert!(parse_size("0").is_err());
    }

    #[test]
    fn ranges_are_named_and_durations_take_units() {
        assert_eq!(parse_groups("1e2"), Ok(100));
        assert!(parse_groups("1e9").unwrap_err().contains("from 2 to 1024"));
        assert!(parse_threads("5000")
            .unwrap_err()
            .contains("from 0 to 4096"));
        assert!(parse_count("x").unwrap_err().contains("from 1 to 1e15"));
        assert_eq!(parse_seconds("90"), Ok(90.0));
        assert_eq!(parse_seconds("1e3"), Ok(1000.0));
        assert_eq!(parse_seconds("30s"), Ok(30.0));
        assert_eq!(parse_seconds("5m"), Ok(300.0));
        assert_eq!(parse_seconds("2h"), Ok(7200.0));
        assert_eq!(parse_seconds("1h30m"), Ok(5400.0));
        assert_eq!(parse_seconds("1e30"), Ok(1e30));
        assert_eq!(parse_seconds("99999999999999999999h"), Ok(u64::MAX as f64));
        for bad in ["abc", "0", "0s", "-1", "inf", "NaN", "5 parsecs", ""] {
            assert!(parse_seconds(bad).is_err(), "{bad}");
        }
        assert!(parse_seconds("abc").unwrap_err().contains("1h30m"));
    }
}
