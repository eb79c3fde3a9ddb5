//! Where results go: standard output or files, every file path checked before any line is cast, and a
//! "wrote FILE" line on stderr for each file written (unless `--quiet`).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

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

/// Checks, before any work, that `path` can be written: its folder exists and takes a new file, or the
/// file exists and can be opened for writing. Nothing is left behind.
pub fn check_writable(path: &Path) -> Result<(), Failure> {
    if path.is_dir() {
        return Err(Failure {
            code: Exit::Io,
            message: format!("cannot write {}: it is a directory", path.display()),
        });
    }
    if path.exists() {
        return std::fs::OpenOptions::new()
            .append(true)
            .open(path)
            .map(drop)
            .map_err(|e| io_failure(path, "write", &e));
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
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
    let probe = dir.join(format!(".scx-write-test-{}", std::process::id()));
    std::fs::File::create(&probe).map_err(|e| io_failure(path, "write", &e))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Checks every path given (see [`check_writable`]).
pub fn check_all<'a>(paths: impl IntoIterator<Item = &'a Path>) -> Result<(), Failure> {
    paths.into_iter().try_for_each(check_writable)
}

/// Writes a file and says so.
pub fn write_file(path: &Path, contents: &[u8]) -> Result<(), Failure> {
    std::fs::write(path, contents).map_err(|e| io_failure(path, "write", &e))?;
    note(&format!("wrote {}", path.display()));
    Ok(())
}

/// Says that a file written elsewhere (a mesh, a plot) was written.
pub fn wrote(path: &Path) {
    note(&format!("wrote {}", path.display()));
}

/// Sends a report to `output` (a file) or to standard output; a reader that went away
/// (`scx ... | head`) is not an error.
pub fn emit(output: Option<&Path>, text: &str) -> Result<(), Failure> {
    if let Some(path) = output {
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
