//! Reading a scene's files as untrusted input.
//!
//! A scene file may name other files: a glTF its buffers (URIs), an OBJ its material libraries
//! (`mtllib`). Whoever wrote the scene chose those names, so by default they are read only inside the
//! scene's folder: the name as written, relative to that folder, with no absolute path, no `..` that
//! leaves the folder and no link that points out of it. Every file read, the scene's own included, must
//! be a regular file (a FIFO would block forever, a device such as `/dev/zero` never ends) of at most
//! [`ReadPolicy::max_bytes`], and each file is read once however often the scene names it.
//!
//! [`ReadPolicy`] holds these limits. It is kept apart from [`super::SceneOptions`] on purpose: the
//! options say how a scene is built and are saved with a run, the policy says what a reading may touch
//! and belongs to the one reading.

use std::cell::RefCell;
use std::collections::HashMap;
use std::fs::File;
use std::io::Read;
use std::path::{Component, Path, PathBuf};
use std::rc::Rc;

/// The largest file scx reads by default (256 MiB): a scene of some millions of triangles. Memory grows
/// with the file (a scene takes some hundred bytes per patch), so the limit bounds it too.
pub const DEFAULT_MAX_BYTES: u64 = 256 << 20;

/// Where the files a scene refers to may be.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Reach {
    /// Only inside the scene's folder (or below it): the default.
    #[default]
    SceneFolder,
    /// Anywhere the user running scx may read: absolute paths, `..`, `file:` URIs, links out of the
    /// folder.
    Anywhere,
}

/// What reading one scene may do: where its references may point, and how large a file it may read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ReadPolicy {
    /// Where the files a scene names (glTF buffers, MTL libraries) may be.
    pub reach: Reach,
    /// The largest file read, in bytes: the scene file (or standard input), each buffer and library.
    pub max_bytes: u64,
}

impl Default for ReadPolicy {
    /// Confined to the scene's folder, files of at most [`DEFAULT_MAX_BYTES`].
    fn default() -> Self {
        ReadPolicy {
            reach: Reach::SceneFolder,
            max_bytes: DEFAULT_MAX_BYTES,
        }
    }
}

/// A size for messages: `256 MiB`, `1.5 GiB`, `300 bytes`.
pub fn size_text(bytes: u64) -> String {
    const UNITS: [(&str, u64); 4] = [
        ("TiB", 1 << 40),
        ("GiB", 1 << 30),
        ("MiB", 1 << 20),
        ("KiB", 1 << 10),
    ];
    for (unit, size) in UNITS {
        if bytes >= size {
            let value = bytes as f64 / size as f64;
            return if bytes % size == 0 {
                format!("{} {unit}", bytes / size)
            } else {
                format!("{value:.1} {unit}")
            };
        }
    }
    format!("{bytes} bytes")
}

/// Reads the scene file itself: it must exist, be a regular file and hold at most `max_bytes`. The
/// error's message follows the file's name.
pub(crate) fn read_scene_file(path: &Path, max_bytes: u64) -> Result<Vec<u8>, SceneFileError> {
    let meta = std::fs::metadata(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => SceneFileError::Missing,
        _ => SceneFileError::Unreadable(ReadError::Io(e)),
    })?;
    if meta.is_dir() {
        return Err(SceneFileError::Directory);
    }
    Ok(read_regular(path, &meta, max_bytes)?)
}

/// Why the scene file itself could not be read.
#[derive(Debug, thiserror::Error)]
pub(crate) enum SceneFileError {
    /// Nothing is there.
    #[error("no such file")]
    Missing,
    /// A directory is there.
    #[error("is a directory, not a scene file")]
    Directory,
    /// It is there but could not be read.
    #[error(transparent)]
    Unreadable(#[from] ReadError),
}

/// Why a file could not be read.
#[derive(Debug, thiserror::Error)]
pub(crate) enum ReadError {
    /// Not a regular file: a FIFO, a device, a socket or a directory (described).
    #[error("it is {0}, not a regular file: scx reads regular files only")]
    NotRegular(&'static str),
    /// Larger than the limit.
    #[error(
        "the file is {} ({size} bytes), more than the {} scx reads (--max-file-size raises the limit)",
        size_text(*.size),
        size_text(*.max)
    )]
    TooLarge {
        /// Its size, in bytes.
        size: u64,
        /// The limit, in bytes.
        max: u64,
    },
    /// The system refused or failed.
    #[error("cannot read the file: {0}")]
    Io(#[source] std::io::Error),
}

/// What kind of file metadata describes, for a message (`a FIFO (named pipe)`).
pub(crate) fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    let ft = meta.file_type();
    if ft.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if ft.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if ft.is_char_device() || ft.is_block_device() {
            return "a device";
        }
        if ft.is_socket() {
            return "a socket";
        }
    }
    "not a regular file"
}

/// Reads a file whose metadata (following links) is `meta`: only a regular file of at most `max_bytes`.
/// It is opened without blocking (a FIFO put in its place after the check cannot hang the reader), its
/// kind checked again on the open file, and at most `max_bytes + 1` bytes are read whatever its size
/// says.
fn read_regular(
    path: &Path,
    meta: &std::fs::Metadata,
    max_bytes: u64,
) -> Result<Vec<u8>, ReadError> {
    if !meta.is_file() {
        return Err(ReadError::NotRegular(kind_of(meta)));
    }
    if meta.len() > max_bytes {
        return Err(ReadError::TooLarge {
            size: meta.len(),
            max: max_bytes,
        });
    }
    let file = open_nonblocking(path).map_err(ReadError::Io)?;
    let opened = file.metadata().map_err(ReadError::Io)?;
    if !opened.is_file() {
        return Err(ReadError::NotRegular(kind_of(&opened)));
    }
    let mut bytes = Vec::with_capacity(opened.len().min(max_bytes) as usize);
    file.take(max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(ReadError::Io)?;
    if bytes.len() as u64 > max_bytes {
        return Err(ReadError::TooLarge {
            size: bytes.len() as u64,
            max: max_bytes,
        });
    }
    Ok(bytes)
}

/// Opens a file for reading; on Unix without blocking, so that opening a FIFO returns at once.
pub(crate) fn open_nonblocking(path: &Path) -> std::io::Result<File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    options.open(path)
}

/// Why a reference was not read.
#[derive(Debug, thiserror::Error)]
pub(crate) enum RefError {
    /// The policy keeps it out: how it leaves the scene's folder.
    #[error(transparent)]
    Outside(#[from] Escape),
    /// Nothing is there.
    #[error("{0}")]
    Missing(#[source] std::io::Error),
    /// It is there but could not be read.
    #[error("{0}")]
    Unreadable(#[source] ReadError),
}

/// How a name a scene gives leaves the scene's folder, which the policy keeps it in. The message says
/// so and how to lift the limit.
#[derive(Debug, thiserror::Error)]
pub(crate) enum Escape {
    /// An absolute path: the name as written.
    #[error("`{}` is an absolute path, {OUTSIDE}", .0.display())]
    Absolute(PathBuf),
    /// A `..` climbing above the folder: the name as written.
    #[error("`{}` climbs out with `..`, {OUTSIDE}", .0.display())]
    ClimbsOut(PathBuf),
    /// A link out of the folder: where it leads (canonical).
    #[error("it leads to `{}` through a link, {OUTSIDE}", .0.display())]
    Link(PathBuf),
}

/// The end of every [`Escape`] message.
const OUTSIDE: &str =
    "outside the scene's folder: scx reads the files a scene names only inside its \
                       folder (--read-anywhere lifts this)";

/// A file a scene names, read.
pub(crate) struct Fetched {
    /// The path for messages: the folder joined with the name as written.
    pub shown: PathBuf,
    /// Its bytes (shared by every reference to the same file).
    pub bytes: Rc<Vec<u8>>,
    /// Whether this is the first time the scene named it (a library read again adds nothing).
    pub first: bool,
}

/// The folder a scene's references are resolved in, the policy for reading them, and the files read so
/// far (each is read once, by its canonical path).
pub(crate) struct Folder {
    dir: PathBuf,
    policy: ReadPolicy,
    read: RefCell<HashMap<PathBuf, Rc<Vec<u8>>>>,
}

impl Folder {
    /// The folder `dir` (empty: the current folder) read under `policy`.
    pub fn new(dir: &Path, policy: ReadPolicy) -> Self {
        Folder {
            dir: dir.to_path_buf(),
            policy,
            read: RefCell::default(),
        }
    }

    /// The folder of the file at `path`.
    pub fn of_file(path: &Path, policy: ReadPolicy) -> Self {
        Folder::new(path.parent().unwrap_or(Path::new("")), policy)
    }

    /// The files read through this folder so far (canonical paths, sorted): what a scene named and scx
    /// read, which nothing the same run writes may replace.
    pub fn files_read(&self) -> Vec<PathBuf> {
        let mut files: Vec<PathBuf> = self.read.borrow().keys().cloned().collect();
        files.sort();
        files
    }

    /// The policy this folder is read under.
    pub fn policy(&self) -> ReadPolicy {
        self.policy
    }

    /// The path for messages of a name as written: the folder joined with it.
    pub fn shown(&self, written: &Path) -> PathBuf {
        self.dir.join(written)
    }

    /// Reads the file named `written` (a path relative to the folder), as the policy allows.
    pub fn fetch(&self, written: &Path) -> Result<Fetched, RefError> {
        let shown = self.shown(written);
        let canonical = self.resolve(written)?;
        if let Some(bytes) = self.read.borrow().get(&canonical) {
            return Ok(Fetched {
                shown,
                bytes: Rc::clone(bytes),
                first: false,
            });
        }
        let meta = std::fs::metadata(&canonical).map_err(RefError::Missing)?;
        let bytes = Rc::new(
            read_regular(&canonical, &meta, self.policy.max_bytes).map_err(RefError::Unreadable)?,
        );
        self.read.borrow_mut().insert(canonical, Rc::clone(&bytes));
        Ok(Fetched {
            shown,
            bytes,
            first: true,
        })
    }

    /// The canonical path of a name as written, checked against the policy: inside the folder unless
    /// the policy reaches anywhere.
    fn resolve(&self, written: &Path) -> Result<PathBuf, RefError> {
        if self.policy.reach == Reach::SceneFolder {
            stays_inside(written)?;
        }
        let joined = self.dir.join(written);
        let canonical = joined.canonicalize().map_err(RefError::Missing)?;
        if self.policy.reach == Reach::SceneFolder {
            let dir = if self.dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                &self.dir
            };
            let folder = dir.canonicalize().map_err(RefError::Missing)?;
            if !canonical.starts_with(&folder) {
                return Err(Escape::Link(canonical).into());
            }
        }
        Ok(canonical)
    }
}

/// Whether a relative path, as written, stays inside the folder it is relative to: not absolute, and no
/// `..` climbing above its start. `Err` says how it leaves.
fn stays_inside(written: &Path) -> Result<(), Escape> {
    let mut depth = 0usize;
    for c in written.components() {
        match c {
            Component::Prefix(_) | Component::RootDir => {
                return Err(Escape::Absolute(written.to_path_buf()))
            }
            Component::CurDir => {}
            Component::ParentDir => {
                depth = depth
                    .checked_sub(1)
                    .ok_or_else(|| Escape::ClimbsOut(written.to_path_buf()))?;
            }
            Component::Normal(_) => depth += 1,
        }
    }
    Ok(())
}

/// The base name of a path as some other program wrote it: the part after the last `/` or `\` (a
/// Windows path read on Unix is one name with backslashes). `None` when that is the whole path.
pub(crate) fn base_name(written: &str) -> Option<&str> {
    let name = written.rsplit(['/', '\\']).next()?;
    (name != written && !name.is_empty() && name != "..").then_some(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_stay_inside_their_folder_or_are_refused() {
        for ok in ["a.bin", "sub/a.bin", "sub/../a.bin", "./a.bin"] {
            assert!(stays_inside(Path::new(ok)).is_ok(), "{ok}");
        }
        for bad in ["/etc/passwd", "../a.bin", "sub/../../a.bin", "./.."] {
            assert!(stays_inside(Path::new(bad)).is_err(), "{bad}");
        }
        assert_eq!(base_name("/etc/passwd"), Some("passwd"));
        assert_eq!(base_name("C:\\scenes\\room.mtl"), Some("room.mtl"));
        assert_eq!(base_name("room.mtl"), None);
        assert_eq!(base_name("dir/"), None);
    }

    #[test]
    fn sizes_read_as_people_write_them() {
        assert_eq!(size_text(DEFAULT_MAX_BYTES), "256 MiB");
        assert_eq!(size_text(3 << 29), "1.5 GiB");
        assert_eq!(size_text(300), "300 bytes");
    }

    #[test]
    fn only_regular_files_within_the_limit_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("a.bin");
        std::fs::write(&file, [1u8; 100]).unwrap();
        assert_eq!(read_scene_file(&file, 100).unwrap().len(), 100);
        assert!(read_scene_file(&file, 99)
            .unwrap_err()
            .to_string()
            .contains("more than the 99 bytes"));
        assert!(read_scene_file(dir.path(), 100)
            .unwrap_err()
            .to_string()
            .contains("directory"));
        #[cfg(target_os = "linux")]
        assert!(read_scene_file(Path::new("/dev/zero"), 100)
            .unwrap_err()
            .to_string()
            .contains("a device"));
    }
}
