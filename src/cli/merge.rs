//! `scx merge`: the saved states of a run's shards (or of any parts of one run) joined into its report,
//! identical to the report of the whole run cast at once.

use std::path::{Path, PathBuf};

use scene_complexity::{files, finish};
use scene_complexity::{LineBound, RunSpec, RunState, SavedRun, Scene, StateFile, StopReason};

use super::analyze::persist_failure;
use super::args::{ReadArgs, ReportOutput, Threads};
use super::exit::{Exit, Failure};
use super::file_kind::report_format;
use super::output::{self, check_all, warn};
use super::patch_files::PatchFiles;
use super::report;
use super::report::Format;
use super::runner::Runner;

/// Arguments of `scx merge`.
#[derive(clap::Args, Debug)]
pub struct MergeArgs {
    /// The state files (`scx analyze ... --save`), in any order.
    #[arg(required = true)]
    states: Vec<PathBuf>,
    /// Report even when batches are missing (the report then says which lines it covers); without it a
    /// missing batch is an error naming the missing lines.
    #[arg(long)]
    partial: bool,
    /// The scene, when it is not where the states say: a file in OBJ, glTF/GLB, PLY or STL, or a
    /// built-in such as `@cube:10` (it must be the same scene: its fingerprint is checked).
    #[arg(long)]
    scene: Option<String>,
    /// Also save the merged state to FILE (to continue it with `scx analyze --resume`).
    #[arg(long, value_name = "FILE")]
    save: Option<PathBuf>,
    #[command(flatten)]
    threads: Threads,
    #[command(flatten)]
    reading: ReadArgs,
    /// Output format, as for `scx analyze` (default: the one the extension of -o names, `.json` or
    /// `.csv`, else `table`).
    #[arg(long, value_enum)]
    format: Option<Format>,
    #[command(flatten)]
    out: ReportOutput,
    #[command(flatten)]
    files: PatchFiles,
}

/// The states merged: the whole run, the first state's file, and the files of the states that keep no
/// per-patch sums of eq. (27).
struct Merged {
    run: SavedRun,
    first: String,
    without_sums: Vec<String>,
}

/// The scene a state names, as it was named (from the folder `scx analyze` ran in): a built-in, a file
/// found from here, or else the same relative path from the state's own folder (shards are often
/// saved beside their scene; its fingerprint is checked all the same). Not found either way: a message
/// saying what the name is and how to give the scene.
fn saved_scene(name: &str, state: &Path) -> Result<String, Failure> {
    let as_named = Path::new(name);
    if name.starts_with('@') || name == "-" || as_named.exists() {
        return Ok(name.to_string());
    }
    if as_named.is_relative() {
        if let Some(beside) = state.parent().map(|dir| dir.join(as_named)) {
            if beside.exists() {
                return Ok(beside.to_string_lossy().into_owned());
            }
        }
    }
    Err(Failure::bad_input(format!(
        "{name}: no such file: it is the scene the states were run on, named as it was from the \
         folder `scx analyze` ran in (not found from here nor beside {}); run `scx merge` from that \
         folder, or name the scene with --scene FILE",
        state.display()
    )))
}

/// Reads every state file, refusing, with the files named, states of different runs.
fn read_states(args: &MergeArgs) -> Result<Vec<StateFile>, Failure> {
    let files = args
        .states
        .iter()
        .map(|path| scene_complexity::read_state(path).map_err(persist_failure))
        .collect::<Result<Vec<_>, _>>()?;
    let first = &files[0];
    for file in &files[1..] {
        if let Some(d) = first.identity().difference(file.identity(), false) {
            // Line counts are the lines drawn; through a container, --lines counted others.
            let unit = match (d.setting.as_str(), first.identity().spec.bound) {
                ("lines", bound) if bound != LineBound::Sphere => {
                    format!(", lines drawn through the bounding {}", bound.name())
                }
                _ => String::new(),
            };
            return Err(Failure::bad_input(format!(
                "{} and {} are not parts of one run: they differ in {} ({} against {}{unit})",
                file.path(),
                first.path(),
                d.setting,
                d.theirs,
                d.ours
            )));
        }
    }
    Ok(files)
}

/// The states, checked against their scene, joined into one, refusing overlapping ones.
fn merged(files: Vec<StateFile>, scene: &Scene) -> Result<Merged, Failure> {
    let seconds = files.iter().map(StateFile::seconds).sum::<f64>();
    let mut runs = Vec::new();
    for file in files {
        let name = file.path().to_string();
        runs.push((name, file.into_run(scene).map_err(persist_failure)?));
    }
    let without_sums = runs
        .iter()
        .filter(|(_, r)| !r.state.wanted().per_patch)
        .map(|(name, _)| name.clone())
        .collect();
    let (first_name, first) = runs.remove(0);
    let mut state: RunState = first.state;
    for (name, run) in runs {
        state
            .absorb(run.state)
            .map_err(|e| Failure::bad_input(format!("{name} cannot join {first_name}: {e}")))?;
    }
    Ok(Merged {
        run: SavedRun {
            identity: first.identity,
            state,
            seconds,
        },
        first: first_name,
        without_sums,
    })
}

/// Refuses a state given twice ([`scene_complexity::files::repeated_path`]).
fn check_states_distinct(states: &[PathBuf]) -> Result<(), Failure> {
    match scene_complexity::files::repeated_path(states) {
        Some(message) => Err(Failure::bad_input(message)),
        None => Ok(()),
    }
}

/// Warns about each state that a live run still holds (its `FILE.lock` names a process that is
/// running, or one on another host): the merge reads what was saved last and may miss the batches that
/// run casts after. A warning, not a refusal: merging a checkpoint of a run still going is legitimate.
fn warn_live_states(states: &[PathBuf]) {
    let host = files::this_host();
    for path in states {
        let real = std::fs::canonicalize(path).unwrap_or_else(|_| path.clone());
        let Ok(held) = std::fs::read_to_string(files::lock_path(&real)) else {
            continue;
        };
        let mut words = held.split_whitespace();
        let (holder, pid) = (words.next().unwrap_or(""), words.next().unwrap_or(""));
        let live = holder != host || pid.parse().map_or(true, files::process_alive);
        let pid = if pid.is_empty() { "(unknown)" } else { pid };
        if live && !holder.is_empty() {
            warn(&format!(
                "{} is still being written by process {pid} on {holder}: the merge may miss its \
                 latest batches (merge again when that run has ended)",
                path.display()
            ));
        }
    }
}

/// Runs `scx merge`.
pub fn run(args: &MergeArgs) -> Result<Exit, Failure> {
    let format = report_format("merge", args.format, args.out.output.as_deref(), "")?;
    check_states_distinct(&args.states)?;
    warn_live_states(&args.states);
    let mut outputs: Vec<(&str, &Path)> = Vec::new();
    outputs.extend(args.out.output.as_deref().map(|p| ("-o", p)));
    outputs.extend(args.save.as_deref().map(|p| ("--save", p)));
    outputs.extend(args.files.outputs());
    let mut inputs: Vec<(&str, &Path)> =
        args.states.iter().map(|p| ("state", p.as_path())).collect();
    inputs.extend(args.scene.as_deref().map(|s| ("--scene", Path::new(s))));
    output::check_distinct(&outputs, &inputs, &[])?;
    check_all(args.out.output.as_deref())?;
    if let Some(path) = &args.save {
        output::check_state(path)?;
    }
    args.files.check()?;
    let _lock = output::lock_states(args.save.as_deref())?;
    let files = read_states(args)?;
    let first_identity = files[0].identity().clone();
    let name = match &args.scene {
        Some(scene) => scene.clone(),
        None => saved_scene(&first_identity.scene.name, &args.states[0])?,
    };
    let runner = Runner::with(
        &name,
        (&first_identity.scene.reading, &args.reading.policy()),
        first_identity.tracing,
        args.threads.value,
    )?;
    let Merged {
        run: SavedRun {
            identity,
            state,
            seconds,
        },
        first,
        without_sums,
    } = merged(files, &runner.scene)?;
    if let Some(missing) = state.missing_lines() {
        let message = missing.message(identity.shard.map(|s| s.count));
        if !args.partial {
            return Err(Failure::bad_input(format!(
                "{message}; merge every shard, or add --partial for a report of these lines only"
            )));
        }
        warn(&message);
    }
    args.files
        .check_saved(&first, &identity, state.wanted(), &without_sums)?;
    let cfg = RunSpec {
        per_patch: args.files.wants_per_patch(),
        ..identity.spec.clone()
    };
    // Saved after the report, so that a save that fails never costs it.
    let bytes = args
        .save
        .as_ref()
        .map(|_| scene_complexity::encode_state(&identity, &state, seconds));
    let analysis = runner
        .in_pool(None, "", || {
            finish(&runner.scene, &cfg, state, StopReason::Lines, seconds)
        })
        .map_err(Failure::of)?;
    for w in &analysis.warnings {
        warn(&w.message);
    }
    let info = runner.info();
    let text = report::render(format, &info, &analysis);
    let mut failures = Vec::new();
    failures.extend(output::emit(args.out.output.as_deref(), &text).err());
    failures.extend(
        runner
            .pool
            .install(|| args.files.write(&runner.scene, &analysis))
            .err(),
    );
    if let (Some(path), Some(bytes)) = (&args.save, &bytes) {
        match scene_complexity::save_state_bytes(path, bytes) {
            Ok(()) => output::wrote(path),
            Err(e) => failures.push(persist_failure(e)),
        }
    }
    match failures.into_iter().next() {
        Some(f) => Err(f),
        None => Ok(Exit::Ok),
    }
}
