//! The data of a glTF read as untrusted input: its buffers, its accessors and its node tree.
//!
//! The `gltf` crate checks that a document's objects refer to each other by valid indices, but not that
//! an accessor's bytes lie inside its buffer, that a stride fits its elements, or that the nodes form
//! trees: its reader then panics, silently reads nothing, or (for a node cycle) walks forever. Here
//! every byte range is computed with checked arithmetic and compared with the bytes there are, the
//! component types are the ones scx reads, and the node hierarchy is walked once with each node reached
//! at most once. Accessors are read from the document's JSON, not through the crate's reader, so that no
//! malformed value reaches code that would panic on it.

use std::path::{Path, PathBuf};
use std::rc::Rc;

use ::gltf::json;
use base64::Engine as _;
use json::accessor::{ComponentType, Type};
use json::validation::Checked;

use super::read::{Escape, Folder, Reach, ReadError, RefError};

/// A buffer's bytes, shared by the buffers that name the same file or chunk.
pub(super) type Buffer = Rc<Vec<u8>>;

/// A buffer's bytes and its `byteLength`, which may be less than the bytes (a .glb's binary chunk is
/// padded; a file may hold more): the buffer is its first `byteLength` bytes.
pub(super) struct BufferBytes {
    bytes: Buffer,
    length: usize,
}

impl BufferBytes {
    /// The buffer's bytes, as many as its `byteLength` gives.
    fn declared(&self) -> &[u8] {
        &self.bytes[..self.length]
    }
}

/// The bytes of every buffer: the binary chunk of a .glb, a base64 data URI, or a file in the glTF's
/// folder (read as the folder's policy allows).
pub(super) fn buffers(
    gltf: &::gltf::Gltf,
    folder: &Folder,
) -> Result<Vec<BufferBytes>, BufferProblem> {
    let blob = gltf.blob.clone().map(Rc::new);
    gltf.buffers()
        .map(|buffer| {
            let data = buffer_data(&buffer, blob.as_ref(), folder)?;
            if data.len() < buffer.length() {
                return Err(BufferProblem::TooShort {
                    buffer: buffer.index(),
                    has: data.len(),
                    declared: buffer.length(),
                });
            }
            Ok(BufferBytes {
                bytes: data,
                length: buffer.length(),
            })
        })
        .collect()
}

/// Why a buffer's bytes were not read: the buffer's index and what went wrong.
#[derive(Debug, thiserror::Error)]
pub(super) enum BufferProblem {
    /// Fewer bytes than the document says the buffer has.
    #[error("buffer {buffer} has {has} bytes, the file says {declared}")]
    TooShort {
        /// The buffer's index.
        buffer: usize,
        /// The bytes it has.
        has: usize,
        /// The bytes the document gives it.
        declared: usize,
    },
    /// The buffer is the binary chunk of a .glb, which the file lacks.
    #[error("buffer {0} is the binary chunk, which is missing")]
    NoBinaryChunk(usize),
    /// A data URI that is not base64.
    #[error("buffer {0}: a data URI that is not base64")]
    NotBase64(usize),
    /// A base64 data URI that does not decode.
    #[error("buffer {buffer}: bad base64 in its data URI: {error}")]
    BadBase64 {
        /// The buffer's index.
        buffer: usize,
        /// Why it does not decode.
        #[source]
        error: base64::DecodeError,
    },
    /// A `file:` URI, under a policy that keeps references in the scene's folder.
    #[error(
        "buffer {buffer}: `{uri}` is a `file:` URI, an absolute path outside the scene's folder: scx \
         reads the files a scene names only inside its folder (--read-anywhere lifts this)"
    )]
    FileUri {
        /// The buffer's index.
        buffer: usize,
        /// The URI.
        uri: String,
    },
    /// A URI with another scheme (`http:`, ...): scx fetches nothing from a network.
    #[error(
        "buffer {buffer}: `{uri}` is a `{scheme}:` URI: scx reads buffers from data URIs and from files \
         beside the glTF, never from a network"
    )]
    Scheme {
        /// The buffer's index.
        buffer: usize,
        /// The URI.
        uri: String,
        /// Its scheme.
        scheme: String,
    },
    /// No file where the URI points (or it cannot be resolved).
    #[error("buffer {buffer}: {}", missing_text(.uri, .path, .error))]
    Missing {
        /// The buffer's index.
        buffer: usize,
        /// The URI, as the glTF writes it.
        uri: String,
        /// The file's path for messages (the folder joined with the URI's path).
        path: PathBuf,
        /// Why.
        #[source]
        error: std::io::Error,
    },
    /// The reading policy keeps the file out of reach.
    #[error("buffer {buffer}: {escape}")]
    Outside {
        /// The buffer's index.
        buffer: usize,
        /// How its path leaves the scene's folder.
        #[source]
        escape: Escape,
    },
    /// The file is there but was not read (not a regular file, too large, a failure to read).
    #[error("buffer {buffer}: `{uri}`: {error}")]
    Unreadable {
        /// The buffer's index.
        buffer: usize,
        /// The URI.
        uri: String,
        /// Why.
        #[source]
        error: ReadError,
    },
}

/// Why a buffer's file was not read: the file as the glTF names it and as scx looked for it, and that
/// it is not there (or the system's reason, without Rust's `(os error N)`).
fn missing_text(uri: &str, path: &Path, error: &std::io::Error) -> String {
    let file = format!("the file `{uri}` (resolved as `{}`)", path.display());
    if error.kind() == std::io::ErrorKind::NotFound {
        return format!("{file} was not found");
    }
    let reason = error.to_string();
    let reason = reason
        .find(" (os error")
        .map_or(reason.as_str(), |k| &reason[..k]);
    format!("{file} cannot be reached: {reason}")
}

/// One buffer's bytes.
fn buffer_data(
    buffer: &::gltf::Buffer,
    blob: Option<&Buffer>,
    folder: &Folder,
) -> Result<Buffer, BufferProblem> {
    let k = buffer.index();
    match buffer.source() {
        ::gltf::buffer::Source::Bin => blob.cloned().ok_or(BufferProblem::NoBinaryChunk(k)),
        ::gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
            let (_, payload) = uri
                .split_once(";base64,")
                .ok_or(BufferProblem::NotBase64(k))?;
            base64::engine::general_purpose::STANDARD
                .decode(payload)
                .map(Rc::new)
                .map_err(|error| BufferProblem::BadBase64 { buffer: k, error })
        }
        ::gltf::buffer::Source::Uri(uri) => {
            let path = uri_path(k, uri, folder)?;
            let fetched = folder.fetch(Path::new(&path)).map_err(|e| match e {
                RefError::Missing(error) => BufferProblem::Missing {
                    buffer: k,
                    uri: uri.to_string(),
                    path: folder.shown(Path::new(&path)),
                    error,
                },
                RefError::Outside(escape) => BufferProblem::Outside { buffer: k, escape },
                RefError::Unreadable(error) => BufferProblem::Unreadable {
                    buffer: k,
                    uri: uri.to_string(),
                    error,
                },
            })?;
            Ok(fetched.bytes)
        }
    }
}

/// The file path of buffer `k`'s URI that is not a data URI: a relative reference, percent-decoded. A
/// URI with a scheme is refused (scx fetches nothing from a network), except `file:` when the policy
/// reaches anywhere.
fn uri_path(k: usize, uri: &str, folder: &Folder) -> Result<String, BufferProblem> {
    match scheme(uri) {
        None => Ok(percent_decode(uri)),
        Some(s) if s.eq_ignore_ascii_case("file") => {
            if folder.policy().reach != Reach::Anywhere {
                return Err(BufferProblem::FileUri {
                    buffer: k,
                    uri: uri.to_string(),
                });
            }
            let rest = &uri[s.len() + 1..];
            let path = rest
                .strip_prefix("//localhost")
                .or_else(|| rest.strip_prefix("//"))
                .unwrap_or(rest);
            Ok(percent_decode(path))
        }
        Some(s) => Err(BufferProblem::Scheme {
            buffer: k,
            uri: uri.to_string(),
            scheme: s.to_string(),
        }),
    }
}

/// The scheme of a URI (`http` in `http://...`), as RFC 3986 spells one: a letter, then letters,
/// digits, `+`, `-` or `.`, then `:`. A one-letter "scheme" is taken for a drive letter (`C:`), so
/// not a scheme.
fn scheme(uri: &str) -> Option<&str> {
    let (head, _) = uri.split_once(':')?;
    let mut chars = head.chars();
    let starts = chars.next().is_some_and(|c| c.is_ascii_alphabetic());
    let rest = chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'));
    (starts && rest && head.len() > 1).then_some(head)
}

/// A URI path with its `%XX` escapes decoded (glTF URIs are percent-encoded).
fn percent_decode(uri: &str) -> String {
    percent_encoding::percent_decode_str(uri)
        .decode_utf8_lossy()
        .into_owned()
}

/// How many bytes of vertices and indices the meshes of a glTF's nodes may add up to: a mesh placed by
/// many nodes is read once per node, so a small file could otherwise ask for any amount of memory.
pub(super) struct Budget {
    left: u64,
    max: u64,
}

impl Budget {
    /// A budget of `max` bytes.
    pub fn new(max: u64) -> Self {
        Budget { left: max, max }
    }

    /// The budget in all, in bytes.
    pub fn max(&self) -> u64 {
        self.max
    }

    /// Spends `bytes`, or says that the meshes hold too much.
    fn spend(&mut self, bytes: u64) -> Result<(), AccessorProblem> {
        self.left = self
            .left
            .checked_sub(bytes)
            .ok_or(AccessorProblem::OverBudget { max: self.max })?;
        Ok(())
    }
}

/// The accessors, buffer views and buffers one reads from.
pub(super) struct Data<'a> {
    /// The document's JSON.
    pub root: &'a json::Root,
    /// Every buffer's bytes, by index.
    pub buffers: &'a [BufferBytes],
}

/// An accessor as messages name it: what a primitive reads from it, its index, and whether the
/// message is about its sparse values.
#[derive(Clone, Copy, Debug)]
pub(super) struct Role {
    /// What the primitive reads from it.
    reads: Reads,
    /// The accessor's index.
    index: usize,
    /// Whether the message is about its sparse indices or values.
    sparse: bool,
}

/// What a primitive reads from an accessor.
#[derive(Clone, Copy, Debug)]
enum Reads {
    /// Its vertex positions.
    Positions,
    /// Its vertex indices.
    Indices,
}

impl std::fmt::Display for Role {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let attribute = match self.reads {
            Reads::Positions => "POSITION",
            Reads::Indices => "indices",
        };
        write!(f, "its {attribute} accessor {}", self.index)?;
        if self.sparse {
            f.write_str(" (sparse)")?;
        }
        Ok(())
    }
}

/// Why an accessor's data was not read: most name the accessor by its [`Role`], and give the numbers
/// that do not fit.
#[derive(Debug, thiserror::Error)]
pub(super) enum AccessorProblem {
    /// The accessor does not exist: its index.
    #[error("accessor {0} does not exist")]
    Missing(usize),
    /// The component type is not one glTF defines.
    #[error("{0} has an invalid component type")]
    InvalidComponent(Role),
    /// Positions that are not FLOAT VEC3: what they are.
    #[error(
        "{role} holds {} {}: scx reads positions as FLOAT VEC3",
        component_name(*.component),
        type_name(.type_)
    )]
    NotFloatVec3 {
        /// The accessor.
        role: Role,
        /// Its component type.
        component: ComponentType,
        /// Its type.
        type_: Checked<Type>,
    },
    /// Indices of a component type that is not unsigned: that type.
    #[error(
        "{role} holds {}: indices are UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT",
        component_name(*.component)
    )]
    IndexComponent {
        /// The accessor.
        role: Role,
        /// Its component type.
        component: ComponentType,
    },
    /// Indices that are not SCALAR: their type.
    #[error("{role} is {}: indices are SCALAR", type_name(.type_))]
    IndexType {
        /// The accessor.
        role: Role,
        /// Its type.
        type_: Checked<Type>,
    },
    /// An accessor of no elements.
    #[error("{0} has no elements (count 0)")]
    Empty(Role),
    /// A count whose bytes overflow the address space.
    #[error("{role}: its count {count} is beyond any buffer")]
    CountTooLarge {
        /// The accessor.
        role: Role,
        /// Its count.
        count: usize,
    },
    /// An accessor without data: no buffer view and no sparse values.
    #[error("{0} has no buffer view and no sparse values: it holds no data")]
    NoData(Role),
    /// A buffer view that does not exist: its index.
    #[error("{role}: buffer view {view} does not exist")]
    NoView {
        /// The accessor.
        role: Role,
        /// The buffer view's index.
        view: usize,
    },
    /// A byte stride shorter than the elements.
    #[error(
        "{role}: its buffer view {view} has a byte stride of {stride}, less than its {size}-byte \
         elements"
    )]
    Stride {
        /// The accessor.
        role: Role,
        /// The buffer view's index.
        view: usize,
        /// Its byte stride.
        stride: usize,
        /// The size of an element, in bytes.
        size: usize,
    },
    /// A buffer that does not exist: its index.
    #[error("{role}: buffer {buffer} does not exist")]
    NoBuffer {
        /// The accessor.
        role: Role,
        /// The buffer's index.
        buffer: usize,
    },
    /// A buffer view reaching past the end of its buffer.
    #[error(
        "{role}: its buffer view {view} (bytes {start} to {}) does not fit in buffer {buffer} of \
         {buffer_length} bytes (its byteLength)",
        .start.saturating_add(*.length)
    )]
    ViewOutside {
        /// The accessor.
        role: Role,
        /// The buffer view's index.
        view: usize,
        /// Where the view starts in its buffer.
        start: u64,
        /// The view's length in bytes.
        length: u64,
        /// The buffer's index.
        buffer: usize,
        /// The buffer's length in bytes (its byteLength).
        buffer_length: usize,
    },
    /// Elements reaching past the end of their buffer view.
    #[error(
        "{role}: its {count} elements of {size} bytes (stride {stride}) from byte {offset} do not \
         fit in its buffer view {view} of {length} bytes"
    )]
    ElementsOutside {
        /// The accessor.
        role: Role,
        /// How many elements.
        count: usize,
        /// The size of an element, in bytes.
        size: usize,
        /// The stride between elements.
        stride: usize,
        /// The offset of the first element in the view.
        offset: u64,
        /// The buffer view's index.
        view: usize,
        /// The view's length in bytes.
        length: u64,
    },
    /// More sparse values than elements.
    #[error("{role}: {values} sparse values for {count} elements")]
    SparseCount {
        /// The accessor.
        role: Role,
        /// How many sparse values.
        values: usize,
        /// How many elements.
        count: usize,
    },
    /// Sparse indices of a component type that is not unsigned.
    #[error("{0}: its sparse indices are not UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT")]
    SparseIndexComponent(Role),
    /// A sparse index out of range or not above the one before.
    #[error(
        "{role}: sparse index {index} (number {number}) is not below {count} and above the one before"
    )]
    SparseOrder {
        /// The accessor.
        role: Role,
        /// The sparse index.
        index: usize,
        /// Its place among the sparse indices.
        number: usize,
        /// How many elements.
        count: usize,
    },
    /// The meshes the nodes place hold more bytes than the limit: the limit.
    #[error(
        "the meshes its nodes place hold more than {} of vertices and indices (a mesh counts once for \
         each node that places it): more than a file within the read limit could hold \
         (--max-file-size raises the limit)",
        super::read::size_text(*.max)
    )]
    OverBudget {
        /// The limit, in bytes.
        max: u64,
    },
}

impl Data<'_> {
    /// The vertex positions of accessor `k`: FLOAT VEC3.
    pub fn positions(
        &self,
        k: usize,
        budget: &mut Budget,
    ) -> Result<Vec<[f32; 3]>, AccessorProblem> {
        let accessor = self.accessor(k)?;
        let role = Role {
            reads: Reads::Positions,
            index: k,
            sparse: false,
        };
        let component = component_type(accessor, role)?;
        if component != ComponentType::F32 || accessor.type_ != Checked::Valid(Type::Vec3) {
            return Err(AccessorProblem::NotFloatVec3 {
                role,
                component,
                type_: accessor.type_,
            });
        }
        let bytes = self.packed(accessor, 12, role, budget)?;
        Ok(bytes
            .chunks_exact(12)
            .map(|c| std::array::from_fn(|a| f32::from_le_bytes(word(&c[4 * a..]))))
            .collect())
    }

    /// The vertex indices of accessor `k`: unsigned bytes, shorts or ints, SCALAR.
    pub fn indices(&self, k: usize, budget: &mut Budget) -> Result<Vec<u32>, AccessorProblem> {
        let accessor = self.accessor(k)?;
        let role = Role {
            reads: Reads::Indices,
            index: k,
            sparse: false,
        };
        let component = component_type(accessor, role)?;
        let size = match component {
            ComponentType::U8 => 1,
            ComponentType::U16 => 2,
            ComponentType::U32 => 4,
            _ => return Err(AccessorProblem::IndexComponent { role, component }),
        };
        if accessor.type_ != Checked::Valid(Type::Scalar) {
            return Err(AccessorProblem::IndexType {
                role,
                type_: accessor.type_,
            });
        }
        let bytes = self.packed(accessor, size, role, budget)?;
        Ok(bytes.chunks_exact(size).map(unsigned).collect())
    }

    fn accessor(&self, k: usize) -> Result<&json::Accessor, AccessorProblem> {
        self.root
            .accessors
            .get(k)
            .ok_or(AccessorProblem::Missing(k))
    }

    /// An accessor's elements, `size` bytes each, packed one after the other: from its buffer view, or
    /// zeros under its sparse values.
    fn packed(
        &self,
        accessor: &json::Accessor,
        size: usize,
        role: Role,
        budget: &mut Budget,
    ) -> Result<Vec<u8>, AccessorProblem> {
        let count = usize::try_from(accessor.count.0).unwrap_or(usize::MAX);
        if count == 0 {
            return Err(AccessorProblem::Empty(role));
        }
        let total = count
            .checked_mul(size)
            .ok_or(AccessorProblem::CountTooLarge { role, count })?;
        let offset = accessor.byte_offset.map_or(0, |o| o.0);
        let mut out = match accessor.buffer_view {
            Some(view) => {
                let (bytes, stride) = self.range(view.value(), offset, count, size, role)?;
                budget.spend(total as u64)?;
                let mut out = Vec::with_capacity(total);
                for k in 0..count {
                    out.extend_from_slice(&bytes[k * stride..k * stride + size]);
                }
                out
            }
            None if accessor.sparse.is_some() => {
                budget.spend(total as u64)?;
                vec![0; total]
            }
            None => return Err(AccessorProblem::NoData(role)),
        };
        if let Some(sparse) = &accessor.sparse {
            self.apply_sparse(&mut out, sparse, count, size, role)?;
        }
        Ok(out)
    }

    /// The bytes of `count` elements of `size` bytes at `offset` in buffer view `view`, and the stride
    /// between them; an error unless every one lies inside the view and the view inside its buffer.
    fn range(
        &self,
        view: usize,
        offset: u64,
        count: usize,
        size: usize,
        role: Role,
    ) -> Result<(&[u8], usize), AccessorProblem> {
        let v = self
            .root
            .buffer_views
            .get(view)
            .ok_or(AccessorProblem::NoView { role, view })?;
        // No stride (or 0, which the gltf crate reads the same way): tightly packed.
        let stride = match v.byte_stride {
            Some(s) if s.0 > 0 => s.0,
            _ => size,
        };
        if stride < size {
            return Err(AccessorProblem::Stride {
                role,
                view,
                stride,
                size,
            });
        }
        let b = v.buffer.value();
        // A view must fit in the buffer as its byteLength gives it, whatever bytes follow in the
        // file or data URI.
        let data = self
            .buffers
            .get(b)
            .ok_or(AccessorProblem::NoBuffer { role, buffer: b })?
            .declared();
        let start = v.byte_offset.map_or(0, |o| o.0);
        let length = v.byte_length.0;
        let end = start
            .checked_add(length)
            .filter(|&e| e <= data.len() as u64);
        let Some(end) = end else {
            return Err(AccessorProblem::ViewOutside {
                role,
                view,
                start,
                length,
                buffer: b,
                buffer_length: data.len(),
            });
        };
        let needed = (count as u64 - 1)
            .checked_mul(stride as u64)
            .and_then(|n| n.checked_add(size as u64))
            .and_then(|n| n.checked_add(offset))
            .filter(|&n| n <= length);
        let Some(needed) = needed else {
            return Err(AccessorProblem::ElementsOutside {
                role,
                count,
                size,
                stride,
                offset,
                view,
                length,
            });
        };
        let from = (start + offset) as usize;
        let to = (start + needed) as usize;
        debug_assert!(to as u64 <= end);
        Ok((&data[from..to], stride))
    }

    /// Puts a sparse accessor's values in place: its indices must rise and stay below the count.
    fn apply_sparse(
        &self,
        out: &mut [u8],
        sparse: &json::accessor::sparse::Sparse,
        count: usize,
        size: usize,
        role: Role,
    ) -> Result<(), AccessorProblem> {
        let n = usize::try_from(sparse.count.0).unwrap_or(usize::MAX);
        if n == 0 {
            return Ok(());
        }
        if n > count {
            return Err(AccessorProblem::SparseCount {
                role,
                values: n,
                count,
            });
        }
        let index_size = match sparse.indices.component_type {
            Checked::Valid(json::accessor::IndexComponentType(ComponentType::U8)) => 1,
            Checked::Valid(json::accessor::IndexComponentType(ComponentType::U16)) => 2,
            Checked::Valid(json::accessor::IndexComponentType(ComponentType::U32)) => 4,
            _ => return Err(AccessorProblem::SparseIndexComponent(role)),
        };
        let sparse_role = Role {
            sparse: true,
            ..role
        };
        let (indices, index_stride) = self.range(
            sparse.indices.buffer_view.value(),
            sparse.indices.byte_offset.0,
            n,
            index_size,
            sparse_role,
        )?;
        let (values, value_stride) = self.range(
            sparse.values.buffer_view.value(),
            sparse.values.byte_offset.0,
            n,
            size,
            sparse_role,
        )?;
        let mut previous = None;
        for k in 0..n {
            let at = index_stride * k;
            let i = unsigned(&indices[at..at + index_size]) as usize;
            if i >= count || previous.is_some_and(|p| p >= i) {
                return Err(AccessorProblem::SparseOrder {
                    role,
                    index: i,
                    number: k,
                    count,
                });
            }
            previous = Some(i);
            let v = value_stride * k;
            out[i * size..(i + 1) * size].copy_from_slice(&values[v..v + size]);
        }
        Ok(())
    }
}

/// An accessor's component type, or an error for an invalid one.
fn component_type(accessor: &json::Accessor, role: Role) -> Result<ComponentType, AccessorProblem> {
    match accessor.component_type {
        Checked::Valid(json::accessor::GenericComponentType(c)) => Ok(c),
        Checked::Invalid => Err(AccessorProblem::InvalidComponent(role)),
    }
}

fn component_name(c: ComponentType) -> &'static str {
    match c {
        ComponentType::I8 => "BYTE",
        ComponentType::U8 => "UNSIGNED_BYTE",
        ComponentType::I16 => "SHORT",
        ComponentType::U16 => "UNSIGNED_SHORT",
        ComponentType::U32 => "UNSIGNED_INT",
        ComponentType::F32 => "FLOAT",
    }
}

fn type_name(t: &Checked<Type>) -> &'static str {
    match t {
        Checked::Valid(Type::Scalar) => "SCALAR",
        Checked::Valid(Type::Vec2) => "VEC2",
        Checked::Valid(Type::Vec3) => "VEC3",
        Checked::Valid(Type::Vec4) => "VEC4",
        Checked::Valid(Type::Mat2) => "MAT2",
        Checked::Valid(Type::Mat3) => "MAT3",
        Checked::Valid(Type::Mat4) => "MAT4",
        Checked::Invalid => "an invalid type",
    }
}

/// The first four bytes of a slice (it has them: callers slice whole elements).
fn word(bytes: &[u8]) -> [u8; 4] {
    [bytes[0], bytes[1], bytes[2], bytes[3]]
}

/// A little-endian unsigned integer of 1, 2 or 4 bytes.
fn unsigned(bytes: &[u8]) -> u32 {
    bytes
        .iter()
        .rev()
        .fold(0u32, |acc, &b| (acc << 8) | u32::from(b))
}

/// The nodes under `roots`, depth first in document order (the order objects come in), each with the
/// place of its parent in the list. Each node may be reached once: a node reached again (a child of
/// two nodes, its own ancestor, a root listed twice or also a child) is an error, so the walk ends
/// after at most as many steps as the file has nodes.
pub(super) fn node_tree(
    root: &json::Root,
    roots: &[usize],
) -> Result<Vec<(usize, Option<usize>)>, NodeProblem> {
    let mut reached: Vec<Option<Option<usize>>> = vec![None; root.nodes.len()];
    let mut order: Vec<(usize, Option<usize>)> = Vec::new();
    let mut stack: Vec<(usize, Option<usize>)> = roots.iter().rev().map(|&r| (r, None)).collect();
    while let Some((node, parent_at)) = stack.pop() {
        let parent = parent_at.map(|p| order[p].0);
        let slot = reached.get_mut(node).ok_or(NodeProblem::Missing(node))?;
        if let Some(first) = *slot {
            return Err(reached_twice(node, first, parent_at, &order));
        }
        *slot = Some(parent);
        order.push((node, parent_at));
        let at = order.len() - 1;
        let children = root.nodes[node].children.as_deref().unwrap_or(&[]);
        stack.extend(children.iter().rev().map(|c| (c.value(), Some(at))));
    }
    Ok(order)
}

/// The nodes that are no node's child: the roots of a file without scenes.
pub(super) fn parentless_nodes(root: &json::Root) -> Vec<usize> {
    let mut child = vec![false; root.nodes.len()];
    for node in &root.nodes {
        for c in node.children.iter().flatten() {
            if let Some(flag) = child.get_mut(c.value()) {
                *flag = true;
            }
        }
    }
    (0..root.nodes.len()).filter(|&k| !child[k]).collect()
}

/// Why the nodes under a scene's roots are no forest: a node that does not exist, or one reached twice.
#[derive(Debug, thiserror::Error)]
pub(super) enum NodeProblem {
    /// A node index past the nodes.
    #[error("node {0} does not exist")]
    Missing(usize),
    /// A root node listed twice.
    #[error("its scene lists node {0} twice among its root nodes")]
    RootTwice(usize),
    /// A root node that is also a child.
    #[error("node {node} is a root node of its scene and a child of node {parent}")]
    RootAndChild {
        /// The node.
        node: usize,
        /// Its parent.
        parent: usize,
    },
    /// A node that is its own ancestor: the cycle, from the node down to the node again.
    #[error(
        "node {node} is its own ancestor (nodes {}): the node hierarchy has a cycle",
        Chain(.cycle)
    )]
    Cycle {
        /// The node.
        node: usize,
        /// The nodes of the cycle, from the node down to itself again.
        cycle: Vec<usize>,
    },
    /// A node listed twice among one node's children.
    #[error("node {node} is listed twice among the children of node {parent}; {TREES}")]
    ChildTwice {
        /// The node.
        node: usize,
        /// Its parent.
        parent: usize,
    },
    /// A node with two parents.
    #[error("node {node} is a child of node {first} and of node {second}; {TREES}")]
    TwoParents {
        /// The node.
        node: usize,
        /// The parent it was reached from first.
        first: usize,
        /// The other parent.
        second: usize,
    },
}

/// The rule the nodes of [`NodeProblem::ChildTwice`] and [`NodeProblem::TwoParents`] break.
const TREES: &str = "glTF nodes form trees: each node has at most one parent";

/// Node indices in a message: `1 -> 2 -> 1`.
struct Chain<'a>(&'a [usize]);

impl std::fmt::Display for Chain<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (k, node) in self.0.iter().enumerate() {
            if k > 0 {
                f.write_str(" -> ")?;
            }
            write!(f, "{node}")?;
        }
        Ok(())
    }
}

/// Why a node was reached a second time: first from `first` (its parent then, `None` for a root), now
/// from the node at `parent_at` in `order`.
fn reached_twice(
    node: usize,
    first: Option<usize>,
    parent_at: Option<usize>,
    order: &[(usize, Option<usize>)],
) -> NodeProblem {
    let Some(at) = parent_at else {
        return match first {
            None => NodeProblem::RootTwice(node),
            Some(p) => NodeProblem::RootAndChild { node, parent: p },
        };
    };
    let mut chain = vec![order[at].0];
    let mut up = order[at].1;
    while let Some(p) = up {
        chain.push(order[p].0);
        up = order[p].1;
    }
    if let Some(k) = chain.iter().position(|&n| n == node) {
        let cycle: Vec<usize> = chain[..=k]
            .iter()
            .rev()
            .chain(std::iter::once(&node))
            .copied()
            .collect();
        return NodeProblem::Cycle { node, cycle };
    }
    match first {
        Some(p) if p == order[at].0 => NodeProblem::ChildTwice { node, parent: p },
        Some(p) => NodeProblem::TwoParents {
            node,
            first: p,
            second: order[at].0,
        },
        None => NodeProblem::RootAndChild {
            node,
            parent: order[at].0,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_with_a_scheme_are_told_apart_from_paths() {
        assert_eq!(scheme("http://example.com/a.bin"), Some("http"));
        assert_eq!(scheme("file:///etc/passwd"), Some("file"));
        assert_eq!(scheme("a.bin"), None);
        assert_eq!(scheme("C:/scenes/a.bin"), None);
        assert_eq!(scheme("dir/a:b.bin"), None);
        assert_eq!(percent_decode("my%20scene.bin"), "my scene.bin");
        assert_eq!(percent_decode("100%"), "100%");
        assert_eq!(percent_decode("%2Fetc%2Fpasswd"), "/etc/passwd");
    }

    #[test]
    fn little_endian_indices_are_read() {
        assert_eq!(unsigned(&[0x01]), 1);
        assert_eq!(unsigned(&[0x01, 0x02]), 0x0201);
        assert_eq!(unsigned(&[0x01, 0x02, 0x03, 0x04]), 0x0403_0201);
    }
}
