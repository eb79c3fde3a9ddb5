//! Where results go: standard output or files, every file path checked before any line is cast, and a
//! "wrote FILE" line on stderr for each file written (unless `--quiet`). Every file is written whole or
//! not at all (a temporary beside it, renamed over it), a device or FIFO is written into, a symbolic link
//! to a file is written through, a directory is refused; two outputs with one path, and an output that
//! is an input, are refused before any work.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use scene_complexity::files::{self, Destination, DestinationError};

use super::exit::{Exit, Failure};

/// `--quiet`: no progress bars, no "wrote" lines, no warnings on stderr (JSON reports keep them).
static QUIET: AtomicBool = AtomicBool::new(false);

/// Sets `--quiet` for the whole program.
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// Whether `--quiet` was given.
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// Prints a line on stderr unless `--quiet`.
pub fn note(message: &str) {
    if !quiet() {
        eprintln!("scx: {message}");
    }
}

/// Prints a warning on stderr unless `--quiet`.
pub fn warn(message: &str) {
    if !quiet() {
        eprintln!("scx: warning: {message}");
    }
}

/// An I/O failure naming the path and the OS reason, in one sentence.
pub fn io_failure(path: &Path, doing: &str, e: &std::io::Error) -> Failure {
    Failure {
        code: Exit::Io,
        message: format!("cannot {doing} {}: {}", path.display(), os_reason(e)),
    }
}

/// The OS's reason without Rust's decoration (`No such file or directory`, not `... (os error 2)`).
fn os_reason(e: &std::io::Error) -> String {
    let text = e.to_string();
    match text.find(" (os error") {
        Some(k) => text[..k].to_string(),
        None => text,
    }
}

/// What writing `path` will do, or why it cannot take an output (a directory, a dangling link).
fn destination_of(path: &Path) -> Result<Destination, Failure> {
    files::destination(path).map_err(|e| match e {
        DestinationError::Io(e) => io_failure(path, "write", &e),
        other => Failure {
            code: Exit::Io,
            message: format!("cannot write {}: {other}", path.display()),
        },
    })
}

/// Checks, before any work, that `path` can be written: a file's folder exists and takes a new file and
/// a rename (every file is written to a temporary beside it, then renamed over it), an existing file is
/// writable; a device is opened for writing; a directory is refused. Nothing is left behind.
pub fn check_writable(path: &Path) -> Result<(), Failure> {
    if is_standard_output(path) {
        return Ok(());
    }
    let destination = destination_of(path)?;
    if let Destination::File(real) = &destination {
        let dir = files::folder_of(real);
        if !dir.is_dir() {
            return Err(Failure {
                code: Exit::Io,
                message: format!(
                    "cannot write {}: the folder {} does not exist",
                    path.display(),
                    dir.display()
                ),
            });
        }
    }
    files::check(&destination).map_err(|e| io_failure(path, "write", &e))
}

/// Checks every path given (see [`check_writable`]).
pub fn check_all<'a>(paths: impl IntoIterator<Item = &'a Path>) -> Result<(), Failure> {
    paths.into_iter().try_for_each(check_writable)
}

/// Checks, before any work, that a run state can be saved to `path`: a regular file (never a device,
/// a FIFO or standard output: a state is renamed into place whole), in a folder that takes it.
pub fn check_state(path: &Path) -> Result<(), Failure> {
    if let Destination::File(real) = destination_of(path)? {
        let dir = files::folder_of(&real);
        if !dir.is_dir() {
            return Err(Failure {
                code: Exit::Io,
                message: format!(
                    "cannot write {}: the folder {} does not exist",
                    path.display(),
                    dir.display()
                ),
            });
        }
    }
    scene_complexity::check_state_save(path).map_err(persist_failure)
}

/// A state file that cannot be read or written: bad input (2) or I/O (3).
pub fn persist_failure(e: scene_complexity::PersistError) -> Failure {
    Failure {
        code: if e.is_bad_input() {
            Exit::BadInput
        } else {
            Exit::Io
        },
        message: without_os_error(&e.to_string()),
    }
}

/// A message without Rust's ` (os error N)` decoration.
fn without_os_error(text: &str) -> String {
    match text.find(" (os error ") {
        Some(k) => {
            let end = text[k..].find(')').map_or(text.len(), |e| k + e + 1);
            format!("{}{}", &text[..k], &text[end..])
        }
        None => text.to_string(),
    }
}

/// Takes the lock of every state file a run writes (`FILE.lock` beside the file itself, links
/// resolved): a second run on a live state is refused (exit 3), naming the host and process that hold
/// it.
pub fn lock_states<'a>(
    paths: impl IntoIterator<Item = &'a Path>,
) -> Result<Vec<files::Lock>, Failure> {
    let mut locks = Vec::new();
    for path in paths {
        let real = match files::destination(path) {
            Ok(Destination::File(real)) => real,
            _ => path.to_path_buf(),
        };
        let locked = files::lock(&real).map_err(|e| Failure {
            code: Exit::Io,
            message: without_os_error(&e.to_string()),
        })?;
        locks.push(locked);
    }
    Ok(locks)
}

/// The file a path names, for comparing paths: none for a device or a stream (they may take several
/// outputs), the real path of a file (links resolved; a new file's folder resolved).
fn identity(path: &Path) -> Option<PathBuf> {
    match files::destination(path).ok()? {
        Destination::Stream(_) => None,
        Destination::File(real) => std::fs::canonicalize(&real).ok().or_else(|| {
            let folder = std::fs::canonicalize(files::folder_of(&real)).ok()?;
            Some(folder.join(real.file_name()?))
        }),
    }
}

/// Refuses, before any work, two outputs that are one file and an output that is an input (a scene, a
/// state), naming both. Each entry is the option that names the file and the file; built-in scenes
/// (`@...`) and standard input (`-`) are not files. `allowed` pairs an output with the input it may be
/// (the state that `--resume` continues and saves back).
pub fn check_distinct(
    outputs: &[(&str, &Path)],
    inputs: &[(&str, &Path)],
    allowed: &[(&str, &str)],
) -> Result<(), Failure> {
    let known = |(flag, path): &(&str, &Path)| {
        let shown = path.to_string_lossy();
        (shown != "-" && !shown.starts_with('@'))
            .then(|| identity(path).map(|id| (flag.to_string(), path.to_path_buf(), id)))
            .flatten()
    };
    let outs: Vec<_> = outputs.iter().filter_map(known).collect();
    for (k, (flag, path, id)) in outs.iter().enumerate() {
        if let Some((other_flag, other, _)) = outs[..k].iter().find(|(_, _, i)| i == id) {
            return Err(Failure::bad_input(format!(
                "{other_flag} {} and {flag} {} are one file: each output needs a file of its own",
                other.display(),
                path.display()
            )));
        }
    }
    for (in_flag, input) in inputs {
        let Some(input_id) = std::fs::canonicalize(input).ok() else {
            continue;
        };
        for (flag, path, id) in &outs {
            if *id == input_id && !allowed.contains(&(flag.as_str(), *in_flag)) {
                return Err(Failure::bad_input(format!(
                    "{flag} {} is the {in_flag} {}: writing it would replace what is read; name \
                     another file",
                    path.display(),
                    input.display()
                )));
            }
        }
    }
    Ok(())
}

/// Refuses, once the scene is read and before any work on it, an output that is a file the scene named
/// and scx read (an MTL library, a glTF buffer): as much an input as the scene file, which
/// [`check_distinct`] could not know of before the scene was read.
pub fn check_not_read_by(
    outputs: &[(&str, &Path)],
    scene: &scene_complexity::Scene,
) -> Result<(), Failure> {
    for (flag, path) in outputs {
        let Some(id) = identity(path) else { continue };
        if let Some(read) = scene.files_read.iter().find(|r| **r == id) {
            return Err(Failure::bad_input(format!(
                "{flag} {} is {}, which the scene {} reads: writing it would replace what is read; \
                 name another file",
                path.display(),
                read.display(),
                scene.name
            )));
        }
    }
    Ok(())
}

/// Writes a file whole or not at all (a temporary beside it, renamed over it; into a device or FIFO as
/// a stream) from what `fill` writes, and says so.
pub fn write_with(
    path: &Path,
    mut fill: impl FnMut(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), Failure> {
    let destination = destination_of(path)?;
    files::write(&destination, &|_| false, &mut fill).map_err(|e| write_failure(path, e))?;
    wrote(path);
    Ok(())
}

/// Writes a file whole or not at all through a writer that takes a path (a plot, a picture): it writes
/// a temporary whose name ends with `.EXT`, renamed over `path` (a device or FIFO it writes itself).
/// Does not say so.
pub fn write_via(
    path: &Path,
    extension: &str,
    mut make: impl FnMut(&Path) -> Result<(), String>,
) -> Result<(), Failure> {
    let mut run = |p: &Path| make(p).map_err(std::io::Error::other);
    match destination_of(path)? {
        Destination::Stream(p) => run(&p).map_err(|e| io_failure(path, "write", &e)),
        Destination::File(real) => {
            files::write_file_via(&real, Some(extension), &|_| false, &mut run)
                .map_err(|e| write_failure(path, e))
        }
    }
}

fn write_failure(path: &Path, e: files::WriteError) -> Failure {
    let mut f = io_failure(path, "write", &e.source);
    if let Some(kept) = e.kept {
        f.message
            .push_str(&format!("; the whole file is kept in {}", kept.display()));
    }
    f
}

/// Writes a file whole or not at all, without saying so (the caller says what it wrote).
pub fn write_silently(path: &Path, contents: &[u8]) -> Result<(), Failure> {
    let destination = destination_of(path)?;
    files::write(&destination, &|_| false, &mut |w| w.write_all(contents))
        .map_err(|e| write_failure(path, e))
}

/// Writes a file and says so.
pub fn write_file(path: &Path, contents: &[u8]) -> Result<(), Failure> {
    write_with(path, |w| w.write_all(contents))
}

/// Whether a report's output path is `-`, standard output (as a scene path `-` is standard input).
pub fn is_standard_output(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// Says that a file written elsewhere (a mesh, a plot) was written.
pub fn wrote(path: &Path) {
    note(&format!("wrote {}", path.display()));
}

/// Sends a report to `output` (a file) or to standard output; a reader that went away
/// (`scx ... | head`) is not an error.
pub fn emit(output: Option<&Path>, text: &str) -> Result<(), Failure> {
    if let Some(path) = output.filter(|p| !is_standard_output(p)) {
        return write_file(path, text.as_bytes());
    }
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(Failure {
            code: Exit::Io,
            message: format!(
                "cannot write the report to standard output: {}",
                os_reason(&e)
            ),
        }),
    }
}
