//! Which format a scene file is in, from its content (the extension only breaks a tie), and loading it.

use std::io::Read;
use std::path::Path;

use super::read::{self, Folder, ReadPolicy};
use super::stl::is_binary_stl;
use super::{gltf, obj, ply, stl, Scene, SceneError, SceneOptions};

/// The scene file formats scx reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ (+ MTL), text.
    Obj,
    /// glTF 2.0 as JSON (`.gltf`), with its buffers in files beside it or in data URIs.
    Gltf,
    /// glTF 2.0 binary (`.glb`).
    Glb,
    /// PLY (Stanford polygon file), ASCII or binary.
    Ply,
    /// STL, ASCII.
    StlAscii,
    /// STL, binary.
    StlBinary,
}

impl Format {
    /// Whether files of this format are text (PLY may be either; its header is text).
    pub fn is_text(self) -> bool {
        matches!(self, Format::Obj | Format::Gltf | Format::StlAscii)
    }

    /// A name for messages.
    pub fn name(self) -> &'static str {
        match self {
            Format::Obj => "OBJ",
            Format::Gltf => "glTF (JSON)",
            Format::Glb => "glTF (binary .glb)",
            Format::Ply => "PLY",
            Format::StlAscii => "STL (ASCII)",
            Format::StlBinary => "STL (binary)",
        }
    }
}

/// The format of a file's bytes: magic numbers first (`glTF` for .glb, `ply` for PLY), then the text
/// forms (glTF JSON has an `"asset"`, ASCII STL starts `solid` and has a `facet`, OBJ has statements such
/// as `v` and `f`), then binary STL, whose size is exactly 84 + 50 bytes per triangle. `None` when nothing
/// fits.
pub fn detect(bytes: &[u8]) -> Option<Format> {
    if bytes.starts_with(b"glTF") {
        return Some(Format::Glb);
    }
    if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n") {
        return Some(Format::Ply);
    }
    let head = &bytes[..bytes.len().min(4096)];
    let text = std::str::from_utf8(head)
        .or_else(|e| std::str::from_utf8(&head[..e.valid_up_to()]))
        .unwrap_or("");
    let trimmed = text.trim_start_matches('\u{feff}').trim_start();
    if trimmed.starts_with('{') && text.contains("\"asset\"") {
        return Some(Format::Gltf);
    }
    if super::stl::looks_like_ascii_stl(bytes) {
        return Some(Format::StlAscii);
    }
    if is_binary_stl(bytes) {
        return Some(Format::StlBinary);
    }
    if looks_like_obj(text.trim_start_matches('\u{feff}')) {
        return Some(Format::Obj);
    }
    None
}

/// Text with OBJ statements (`v`, `f`, `o`, `usemtl`, ...) among its first ones; other statements
/// (extensions such as `vw`, comments) may be mixed in. Text without any statement is an OBJ with no
/// faces, which the OBJ reader then names as such.
fn looks_like_obj(text: &str) -> bool {
    const KEYWORDS: &[&str] = &[
        "v", "vt", "vn", "vp", "f", "l", "p", "o", "g", "s", "usemtl", "mtllib",
    ];
    if text.contains('\0') {
        return false;
    }
    let mut statements = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .peekable();
    if statements.peek().is_none() {
        return true;
    }
    statements
        .take(50)
        .any(|l| KEYWORDS.contains(&l.split_whitespace().next().unwrap_or("")))
}

/// Loads a scene file in any format scx reads, found from its content ([`detect`]), under the default
/// [`ReadPolicy`].
pub fn load_file(path: &Path, options: &SceneOptions) -> Result<Scene, SceneError> {
    load_file_with_policy(path, options, &ReadPolicy::default())
}

/// [`load_file`] under a reading policy: the file and those it names are regular files within the size
/// limit, and what it names is read inside its folder unless the policy reaches further.
pub fn load_file_with_policy(
    path: &Path,
    options: &SceneOptions,
    policy: &ReadPolicy,
) -> Result<Scene, SceneError> {
    let shown = path.display().to_string();
    let bytes = read::read_scene_file(path, policy.max_bytes)
        .map_err(|e| SceneError::in_file(&shown, e.to_string()))?;
    load_detected(
        &shown,
        bytes,
        path,
        &Folder::of_file(path, *policy),
        options,
    )
}

/// Loads a scene from bytes in any format scx reads ([`detect`]), called `shown` in messages and object
/// names; the files it names are read in `folder` under `policy`.
pub fn load_bytes(
    shown: &str,
    bytes: Vec<u8>,
    folder: &Path,
    options: &SceneOptions,
    policy: &ReadPolicy,
) -> Result<Scene, SceneError> {
    let folder = Folder::new(folder, *policy);
    load_detected(shown, bytes, Path::new(shown), &folder, options)
}

/// [`load_bytes`] for a stream such as standard input: read up to the policy's size limit, and no
/// further than its first bytes allow (a stream that starts in no format scx reads is refused after
/// its first 64 KiB, not read to the limit).
pub fn load_stream(
    shown: &str,
    stream: impl Read,
    folder: &Path,
    options: &SceneOptions,
    policy: &ReadPolicy,
) -> Result<Scene, SceneError> {
    let bytes = read_stream(stream, Path::new(shown), policy.max_bytes)
        .map_err(|e| SceneError::in_file(shown, e.to_string()))?;
    load_bytes(shown, bytes, folder, options, policy)
}

/// Loads bytes as the given format (no detection), as [`load_bytes`] does: for readers of one format
/// (the fuzz targets).
pub fn load_as(
    format: Format,
    shown: &str,
    bytes: &[u8],
    folder: &Path,
    options: &SceneOptions,
    policy: &ReadPolicy,
) -> Result<Scene, SceneError> {
    let folder = Folder::new(folder, *policy);
    load_format(format, shown, bytes, Path::new(shown), &folder, options)
}

/// Loads bytes in the format [`detect`] finds; `path` names single-object scenes (PLY, STL).
fn load_detected(
    shown: &str,
    bytes: Vec<u8>,
    path: &Path,
    folder: &Folder,
    options: &SceneOptions,
) -> Result<Scene, SceneError> {
    let file_error = |problem: FormatProblem| SceneError::in_file(shown, problem.to_string());
    let format = detect(&bytes).ok_or_else(|| file_error(unknown_format(path, &bytes)))?;
    if format == Format::Obj {
        let text = obj::text_of(&bytes).map_err(|e| e.in_file(shown))?;
        return obj::load_obj_text(shown, &text, folder, options);
    }
    // A single-object file is read whole before its scene is built: the file's bytes can go first, as a
    // large scene needs the memory to build.
    let builder = match format {
        Format::Ply => ply::read_bytes(shown, &bytes, path)?,
        Format::StlAscii | Format::StlBinary => stl::read_bytes(shown, &bytes, path)?,
        _ => return load_format(format, shown, &bytes, path, folder, options),
    };
    drop(bytes);
    builder.build_with(options)
}

/// Loads bytes as `format`.
fn load_format(
    format: Format,
    shown: &str,
    bytes: &[u8],
    path: &Path,
    folder: &Folder,
    options: &SceneOptions,
) -> Result<Scene, SceneError> {
    match format {
        Format::Obj => {
            let text = obj::text_of(bytes).map_err(|e| e.in_file(shown))?;
            obj::load_obj_text(shown, &text, folder, options)
        }
        Format::Gltf | Format::Glb => gltf::load_bytes(shown, bytes, folder, options),
        Format::Ply => ply::load_bytes(shown, bytes, path, options),
        Format::StlAscii | Format::StlBinary => stl::load_bytes(shown, bytes, path, options),
    }
}

/// How much of a stream is read before deciding whether it can be a scene at all.
const STREAM_HEAD: u64 = 64 << 10;

/// Reads a stream up to `max_bytes`. After its first [`STREAM_HEAD`] bytes, a stream in no format scx
/// reads is refused at once, and a binary STL (the one format told by its size) is read only up to the
/// size its header gives.
fn read_stream(stream: impl Read, path: &Path, max_bytes: u64) -> Result<Vec<u8>, StreamProblem> {
    let mut stream = stream;
    let mut bytes = Vec::new();
    (&mut stream)
        .take(STREAM_HEAD.min(max_bytes + 1))
        .read_to_end(&mut bytes)
        .map_err(StreamProblem::Unreadable)?;
    if (bytes.len() as u64) < STREAM_HEAD {
        return within(bytes, max_bytes);
    }
    let limit = match detect(&bytes) {
        Some(format) if format.is_text() => {
            text_head(&bytes, format)?;
            max_bytes
        }
        Some(_) => max_bytes,
        None => match stl_size(&bytes) {
            Some(size) if size <= max_bytes => size,
            _ => return Err(unknown_format(path, &bytes).into()),
        },
    };
    stream
        .take((limit + 1).saturating_sub(bytes.len() as u64))
        .read_to_end(&mut bytes)
        .map_err(StreamProblem::Unreadable)?;
    within(bytes, max_bytes)
}

/// Why a stream (standard input) was not read as a scene.
#[derive(Debug, thiserror::Error)]
pub(crate) enum StreamProblem {
    /// Reading it failed.
    #[error("cannot read it: {0}")]
    Unreadable(#[source] std::io::Error),
    /// It holds more than the limit, in bytes.
    #[error(
        "it holds more than the {} scx reads (--max-file-size raises the limit)",
        read::size_text(*.0)
    )]
    TooLarge(u64),
    /// What it holds is no scene scx reads.
    #[error(transparent)]
    Format(#[from] FormatProblem),
}

/// Why bytes are no scene scx reads: in no format it knows, or not text where text is needed. The
/// message names what the bytes look like.
#[derive(Debug, thiserror::Error)]
pub(crate) enum FormatProblem {
    /// No bytes at all.
    #[error("the file is empty")]
    Empty,
    /// A file named `.stl` whose size is not the one its binary STL header gives.
    #[error("{}", stl::wrong_size_text(*.count, *.expected, *.size))]
    StlSize {
        /// The triangle count in the header.
        count: u64,
        /// The size that count gives: 84 bytes and 50 per triangle.
        expected: u64,
        /// The size the file has.
        size: u64,
    },
    /// Binary bytes (not UTF-8) of no binary format scx reads: the extension, if any, and the first
    /// bytes.
    #[error(
        "not a text file and in no binary format scx reads{}: it starts `{}`; scx reads OBJ, glTF \
         (.gltf, .glb), PLY and STL",
        Extension(.extension),
        Start(.start)
    )]
    Binary {
        /// The file's extension, if it has one.
        extension: Option<String>,
        /// Its first bytes (up to 8).
        start: Vec<u8>,
    },
    /// Text (or bytes that pass for it) in no format scx reads: the extension, if any, and the first
    /// bytes.
    #[error(
        "unknown scene format{}: it starts `{}`; scx reads OBJ, glTF (.gltf, .glb), PLY and STL",
        Extension(.extension),
        Start(.start)
    )]
    Unknown {
        /// The file's extension, if it has one.
        extension: Option<String>,
        /// Its first bytes (up to 8).
        start: Vec<u8>,
    },
    /// Text that is not UTF-8: the offset of the first invalid byte.
    #[error("not a text file (invalid UTF-8 at byte {at})")]
    InvalidUtf8 {
        /// The offset of the first invalid byte.
        at: usize,
    },
    /// OBJ text with bytes that are not text outside its names and comments.
    #[error("line {line}: {0}", line = .0.line)]
    NotText(super::obj_check::NotText),
    /// Text with a NUL byte: its offset.
    #[error("not a text file (a NUL byte at byte {at})")]
    Nul {
        /// The offset of the NUL byte.
        at: usize,
    },
}

/// A file's extension in a message: ` (extension `.obj`)`, or nothing.
struct Extension<'a>(&'a Option<String>);

impl std::fmt::Display for Extension<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            Some(e) => write!(f, " (extension `.{e}`)"),
            None => Ok(()),
        }
    }
}

/// A file's first bytes in a message: printable ASCII as it is, other bytes as `\xNN`.
struct Start<'a>(&'a [u8]);

impl std::fmt::Display for Start<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for &b in self.0 {
            if b.is_ascii_graphic() || b == b' ' {
                write!(f, "{}", b as char)?;
            } else {
                write!(f, "\\x{b:02x}")?;
            }
        }
        Ok(())
    }
}

/// The first bytes of a stream in a text format must be text: valid UTF-8 (but for a character cut at
/// the end) without NUL bytes. Anything else is refused before more is read (random bytes whose start
/// is not even UTF-8 would otherwise be read to the size limit as an OBJ).
///
/// An OBJ may hold names and comments in another encoding ([`obj::text_of`]): its whole lines in the
/// head are checked as the OBJ reader checks them.
fn text_head(head: &[u8], format: Format) -> Result<(), FormatProblem> {
    if format == Format::Obj {
        let lines = head.iter().rposition(|&b| b == b'\n').map_or(0, |k| k + 1);
        obj::text_of(&head[..lines]).map_err(FormatProblem::NotText)?;
        return match head.iter().position(|&b| b == 0) {
            Some(at) => Err(FormatProblem::Nul { at }),
            None => Ok(()),
        };
    }
    let valid = match std::str::from_utf8(head) {
        Ok(_) => head.len(),
        Err(e) if e.error_len().is_none() => e.valid_up_to(),
        Err(e) => {
            return Err(FormatProblem::InvalidUtf8 {
                at: e.valid_up_to(),
            })
        }
    };
    match head[..valid].iter().position(|&b| b == 0) {
        Some(at) => Err(FormatProblem::Nul { at }),
        None => Ok(()),
    }
}

/// Bytes read from a stream, refused when over the size limit.
fn within(bytes: Vec<u8>, max_bytes: u64) -> Result<Vec<u8>, StreamProblem> {
    if bytes.len() as u64 > max_bytes {
        return Err(StreamProblem::TooLarge(max_bytes));
    }
    Ok(bytes)
}

/// The size a binary STL with this header has: 84 bytes and 50 per triangle its count gives.
fn stl_size(bytes: &[u8]) -> Option<u64> {
    let count = bytes.get(80..84)?;
    Some(84 + 50 * u64::from(u32::from_le_bytes(count.try_into().ok()?)))
}

/// Why a file is in no format scx reads, naming what it looks like.
fn unknown_format(path: &Path, bytes: &[u8]) -> FormatProblem {
    let extension = path.extension().map(|e| e.to_string_lossy().into_owned());
    let start = bytes[..bytes.len().min(8)].to_vec();
    if bytes.is_empty() {
        return FormatProblem::Empty;
    }
    let stl = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("stl"));
    if stl && bytes.len() >= 84 {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        return FormatProblem::StlSize {
            count,
            expected: 84 + 50 * count,
            size: bytes.len() as u64,
        };
    }
    if std::str::from_utf8(&bytes[..bytes.len().min(4096)]).is_err() && !is_binary_stl(bytes) {
        return FormatProblem::Binary { extension, start };
    }
    FormatProblem::Unknown { extension, start }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_are_told_by_their_content() {
        assert_eq!(detect(b"glTF\x02\0\0\0"), Some(Format::Glb));
        assert_eq!(detect(b"ply\nformat ascii 1.0\n"), Some(Format::Ply));
        assert_eq!(
            detect(b"{\"asset\": {\"version\": \"2.0\"}}"),
            Some(Format::Gltf)
        );
        assert_eq!(
            detect(b"solid x\n facet normal 0 0 1\n"),
            Some(Format::StlAscii)
        );
        let mut binary = vec![0u8; 84 + 50];
        binary[80] = 1;
        assert_eq!(detect(&binary), Some(Format::StlBinary));
        // A binary STL whose header starts `solid` (some exporters do) is still binary.
        binary[..5].copy_from_slice(b"solid");
        assert_eq!(detect(&binary), Some(Format::StlBinary));
        assert_eq!(detect(b"# cube\nv 0 0 0\nf 1 2 3\n"), Some(Format::Obj));
        assert_eq!(detect(b""), Some(Format::Obj));
        assert_eq!(detect(b"hello world\n"), None);
        assert_eq!(detect(&[0x7f, 0x45, 0x4c, 0x46, 0xff, 0x00]), None);
    }
}
