//! Writing files so that none is ever partial and nothing that is not ours is replaced: a file goes to a
//! temporary beside it, synced, then renamed over it; a device or FIFO is written into as a stream; a
//! symbolic link to a regular file is written through (its target replaced, the link kept); a
//! directory is refused. Temporaries are named `.NAME.PID@HOST.scx-tmp` (with the target's extension
//! after it when a writer needs one), so that those of a process gone on this host are recognised and
//! cleaned at the next write beside them. A lock file beside a state (`FILE.lock`, holding host and
//! pid) keeps two live runs from writing one state.
//!
//! Every function here is std only; the CLI and [`super::persist`] share them.

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// The first path named twice in `paths`, by the same name or by two names of one file (`./s.scx`, a
/// link), as a message naming it: a state given twice to a merge would otherwise show up as an overlap
/// of the file with itself.
pub fn repeated_path(paths: &[PathBuf]) -> Option<String> {
    let real = |p: &PathBuf| std::fs::canonicalize(p).unwrap_or_else(|_| p.clone());
    paths.iter().enumerate().find_map(|(k, path)| {
        let first = paths[..k].iter().find(|q| real(q) == real(path))?;
        let also = if first == path {
            String::new()
        } else {
            format!(" (as {} and {})", first.display(), path.display())
        };
        Some(format!(
            "{} is given twice{also}: name each state once",
            path.display()
        ))
    })
}

/// Where the bytes meant for a path go.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Destination {
    /// A regular file (new or existing) at this path, the path as given or the target of the symbolic
    /// link given: replaced atomically.
    File(PathBuf),
    /// A device, a FIFO, or a file behind `/dev/stdout`-like links (`/dev/...`, `/proc/...`): written
    /// into as a stream, never renamed over.
    Stream(PathBuf),
}

/// Why a path cannot take an output.
#[derive(Debug, thiserror::Error)]
pub enum DestinationError {
    /// It is a directory.
    #[error("it is a directory")]
    Directory,
    /// A symbolic link whose target does not exist.
    #[error("it is a symbolic link to a missing file")]
    DanglingLink,
    /// The system refused to say what it is.
    #[error("{0}")]
    Io(#[from] std::io::Error),
}

/// What writing to `path` will do (see [`Destination`]).
pub fn destination(path: &Path) -> Result<Destination, DestinationError> {
    let link = match std::fs::symlink_metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Ok(Destination::File(path.to_path_buf()))
        }
        Err(e) => return Err(e.into()),
    };
    let meta = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(DestinationError::DanglingLink)
        }
        Err(e) => return Err(e.into()),
    };
    if meta.is_dir() {
        return Err(DestinationError::Directory);
    }
    if !meta.is_file() {
        return Ok(Destination::Stream(path.to_path_buf()));
    }
    if !link.file_type().is_symlink() {
        return Ok(Destination::File(path.to_path_buf()));
    }
    // `/dev/stdout` and `/proc/self/fd/1` lead to whatever the shell opened: write into it.
    let system = path.is_absolute() && (path.starts_with("/dev") || path.starts_with("/proc"));
    if system {
        return Ok(Destination::Stream(path.to_path_buf()));
    }
    Ok(Destination::File(std::fs::canonicalize(path)?))
}

/// This machine's name, as temporaries and locks record it.
pub fn this_host() -> String {
    ["/proc/sys/kernel/hostname", "/etc/hostname"]
        .iter()
        .find_map(|p| std::fs::read_to_string(p).ok())
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .or_else(|| std::env::var("HOSTNAME").ok().filter(|s| !s.is_empty()))
        .unwrap_or_else(|| "localhost".into())
}

/// Whether process `pid` of this host is running. Where the system cannot tell (no `/proc`), every
/// process counts as running, so nothing of a live process is ever taken.
pub fn process_alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    if cfg!(target_os = "linux") && Path::new("/proc/self").exists() {
        return Path::new(&format!("/proc/{pid}")).exists();
    }
    true
}

/// The folder of `path` (`.` for a bare name).
pub fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

fn name_of(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into())
}

const TEMPORARY: &str = ".scx-tmp";

/// The temporary that a write of `path` by this process uses, ending with `.EXT` when `extension` is
/// given (for writers that choose their format by it).
pub fn temporary_for(path: &Path, extension: Option<&str>) -> PathBuf {
    let ext = extension.map(|e| format!(".{e}")).unwrap_or_default();
    folder_of(path).join(format!(
        ".{}.{}@{}{TEMPORARY}{ext}",
        name_of(path),
        std::process::id(),
        this_host()
    ))
}

/// The process and host of a temporary of `path`, when `file` (a name in its folder) is one. The
/// temporaries of scx before this naming (`.NAME.PID.tmp`) are recognised too, as of this host.
fn temporary_owner(path: &Path, file: &str) -> Option<(u32, String)> {
    let prefix = format!(".{}.", name_of(path));
    let rest = file.strip_prefix(&prefix)?;
    if let Some(k) = rest.find(TEMPORARY) {
        let (pid, host) = rest[..k].split_once('@')?;
        return Some((pid.parse().ok()?, host.to_string()));
    }
    let pid = rest.strip_suffix(".tmp")?;
    Some((pid.parse().ok()?, this_host()))
}

/// Removes the temporaries of `path` left by processes of this host that are gone (killed while
/// writing), except those that `keep` says hold finished work.
pub fn clean_stale_temporaries(path: &Path, keep: &dyn Fn(&Path) -> bool) {
    let folder = folder_of(path);
    let Ok(entries) = std::fs::read_dir(&folder) else {
        return;
    };
    let host = this_host();
    for entry in entries.flatten() {
        let file = entry.file_name().to_string_lossy().into_owned();
        let Some((pid, owner)) = temporary_owner(path, &file) else {
            continue;
        };
        let temporary = folder.join(&file);
        let regular = entry.file_type().is_ok_and(|t| t.is_file());
        if owner == host && regular && !process_alive(pid) && !keep(&temporary) {
            let _ = std::fs::remove_file(&temporary);
        }
    }
}

/// Checks, before any work, that `destination` can be written as [`write()`] will: a stream opened for
/// writing (a FIFO is not opened, which would wait for its reader); a file's folder takes a new file and
/// a rename, and an existing file is writable.
pub fn check(destination: &Destination) -> std::io::Result<()> {
    match destination {
        Destination::Stream(path) => {
            let fifo = {
                #[cfg(unix)]
                {
                    use std::os::unix::fs::FileTypeExt;
                    std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo())
                }
                #[cfg(not(unix))]
                {
                    false
                }
            };
            if !fifo {
                OpenOptions::new().append(true).open(path)?;
            }
            Ok(())
        }
        Destination::File(path) => {
            if path.exists() {
                OpenOptions::new().append(true).open(path)?;
            }
            let probe = temporary_for(path, None);
            let moved = temporary_for(path, Some("probe"));
            File::create(&probe)?;
            let renamed = std::fs::rename(&probe, &moved);
            let _ = std::fs::remove_file(&probe);
            let _ = std::fs::remove_file(&moved);
            renamed
        }
    }
}

/// A write that failed: the system's reason, and the temporary kept when it holds the whole output
/// (the rename failed).
#[derive(Debug)]
pub struct WriteError {
    /// Why.
    pub source: std::io::Error,
    /// The complete temporary left in place.
    pub kept: Option<PathBuf>,
}

impl From<std::io::Error> for WriteError {
    fn from(source: std::io::Error) -> Self {
        WriteError { source, kept: None }
    }
}

/// Writes what `fill` produces to `destination`: into a stream as it comes, or to a temporary beside a
/// file, synced and renamed over it (the file keeps its permissions). On failure the temporary is
/// removed, unless only the rename failed (then it is whole, and [`WriteError::kept`] names it).
/// `keep` spares the stale temporaries cleaned first that hold finished work.
pub fn write(
    destination: &Destination,
    keep: &dyn Fn(&Path) -> bool,
    fill: &mut dyn FnMut(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), WriteError> {
    match destination {
        Destination::Stream(path) => {
            let file = OpenOptions::new().append(true).open(path)?;
            let mut out = BufWriter::new(file);
            fill(&mut out)?;
            out.flush()?;
            Ok(())
        }
        Destination::File(path) => write_file_via(path, None, keep, &mut |temporary| {
            let mut out = BufWriter::new(File::create(temporary)?);
            fill(&mut out)?;
            out.flush()?;
            Ok(())
        }),
    }
}

/// Writes the file `path` atomically through a writer that takes a path (`make` writes the temporary
/// it is given, whose name ends with `.EXT` when `extension` is given), then syncs it and renames it
/// over `path` (see [`write()`]).
pub fn write_file_via(
    path: &Path,
    extension: Option<&str>,
    keep: &dyn Fn(&Path) -> bool,
    make: &mut dyn FnMut(&Path) -> std::io::Result<()>,
) -> Result<(), WriteError> {
    clean_stale_temporaries(path, keep);
    let temporary = temporary_for(path, extension);
    let written = make(&temporary).and_then(|()| {
        let file = OpenOptions::new().read(true).write(true).open(&temporary)?;
        if let Ok(old) = std::fs::metadata(path) {
            let _ = file.set_permissions(old.permissions());
        }
        file.sync_all()
    });
    if let Err(e) = written {
        let _ = std::fs::remove_file(&temporary);
        return Err(e.into());
    }
    if let Err(e) = std::fs::rename(&temporary, path) {
        return Err(WriteError {
            source: e,
            kept: Some(temporary),
        });
    }
    // The rename itself is durable once the folder is synced (where the system allows it).
    if let Ok(d) = File::open(folder_of(path)) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// A lock on a state file (`FILE.lock` beside it, holding `host pid`), released when dropped.
#[derive(Debug)]
pub struct Lock {
    path: PathBuf,
    mine: String,
}

/// Why a lock was not taken.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// A running process holds it.
    #[error("{state} is in use by process {pid} on {host} (its lock {lock}); wait for that run to end, or remove the lock if it is not running")]
    Held {
        /// The state file.
        state: String,
        /// The lock file.
        lock: String,
        /// The holder's host.
        host: String,
        /// The holder's process.
        pid: String,
    },
    /// The lock file could not be made or read.
    #[error("cannot lock {state} with {lock}: {source}")]
    Io {
        /// The state file.
        state: String,
        /// The lock file.
        lock: String,
        /// The system's reason.
        source: std::io::Error,
    },
}

/// The lock file of a state.
pub fn lock_path(state: &Path) -> PathBuf {
    let mut name = state.as_os_str().to_owned();
    name.push(".lock");
    PathBuf::from(name)
}

/// Takes the lock of the state `state`: refused while a live process holds it (another host's always
/// counts as live); one left by a process of this host that is gone is taken over.
pub fn lock(state: &Path) -> Result<Lock, LockError> {
    let path = lock_path(state);
    let host = this_host();
    let mine = format!("{host} {}\n", std::process::id());
    let io = |source| LockError::Io {
        state: state.display().to_string(),
        lock: path.display().to_string(),
        source,
    };
    for _ in 0..2 {
        match OpenOptions::new().write(true).create_new(true).open(&path) {
            Ok(mut f) => {
                f.write_all(mine.as_bytes()).map_err(io)?;
                return Ok(Lock { path, mine });
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let held = std::fs::read_to_string(&path).unwrap_or_default();
                let mut words = held.split_whitespace();
                let (holder, pid) = (words.next().unwrap_or(""), words.next().unwrap_or(""));
                let gone = holder == host && pid.parse().is_ok_and(|p| !process_alive(p));
                if !gone {
                    return Err(LockError::Held {
                        state: state.display().to_string(),
                        lock: path.display().to_string(),
                        host: if holder.is_empty() {
                            "an unknown host".into()
                        } else {
                            holder.into()
                        },
                        pid: if pid.is_empty() {
                            "unknown".into()
                        } else {
                            pid.into()
                        },
                    });
                }
                // Stale: its process is gone. Removed only if it still holds what was read (another
                // run may have taken it over meanwhile).
                if std::fs::read_to_string(&path).is_ok_and(|now| now == held) {
                    std::fs::remove_file(&path).map_err(io)?;
                }
            }
            Err(e) => return Err(io(e)),
        }
    }
    Err(io(std::io::Error::other(
        "another process took it meanwhile",
    )))
}

impl Drop for Lock {
    fn drop(&mut self) {
        if std::fs::read_to_string(&self.path).is_ok_and(|s| s == self.mine) {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporaries_are_recognised_with_their_owner() {
        let path = Path::new("dir/s.scx");
        let t = temporary_for(path, None);
        let name = t.file_name().unwrap().to_str().unwrap();
        assert_eq!(
            temporary_owner(path, name),
            Some((std::process::id(), this_host()))
        );
        let t = temporary_for(path, Some("png"));
        let name = t.file_name().unwrap().to_str().unwrap();
        assert!(name.ends_with(".png"));
        assert_eq!(temporary_owner(path, name).unwrap().0, std::process::id());
        assert_eq!(temporary_owner(path, ".s.scx.77.tmp").unwrap().0, 77);
        assert_eq!(temporary_owner(path, ".t.scx.77.tmp"), None);
        assert_eq!(temporary_owner(path, "s.scx"), None);
    }

    /// When only the rename fails (here: the target is a folder that is not empty), the temporary holds
    /// the whole output and is kept, named in the error; when the writing fails, nothing is left.
    #[test]
    fn a_failed_rename_keeps_the_whole_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("s.scx");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("inside"), b"x").unwrap();
        let err = write_file_via(&target, None, &|_| false, &mut |t| {
            std::fs::write(t, b"whole")
        })
        .unwrap_err();
        let kept = err.kept.expect("the temporary is kept");
        assert_eq!(std::fs::read(&kept).unwrap(), b"whole");
        assert_eq!(kept.parent(), Some(dir.path()));

        let other = dir.path().join("t.scx");
        let err = write_file_via(&other, None, &|_| false, &mut |t| {
            std::fs::write(t, b"half")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert!(err.kept.is_none());
        let left: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left.len(), 2, "only s.scx and the kept temporary: {left:?}");
        assert!(!other.exists());
    }
}
