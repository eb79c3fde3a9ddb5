//! The data of a glTF read as untrusted input: its buffers, its accessors and its node tree.
//!
//! The `gltf` crate checks that a document's objects refer to each other by valid indices, but not that
//! an accessor's bytes lie inside its buffer, that a stride fits its elements, or that the nodes form
//! trees: its reader then panics, silently reads nothing, or (for a node cycle) walks forever. Here
//! every byte range is computed with checked arithmetic and compared with the bytes there are, the
//! component types are the ones scx reads, and the node hierarchy is walked once with each node reached
//! at most once. Accessors are read from the document's JSON, not through the crate's reader, so that no
//! malformed value reaches code that would panic on it.

use std::path::Path;
use std::rc::Rc;

use ::gltf::json;
use base64::Engine as _;
use json::accessor::{ComponentType, Type};
use json::validation::Checked;

use super::read::{Folder, Reach, RefError};

/// A buffer's bytes, shared by the buffers that name the same file or chunk.
pub(super) type Buffer = Rc<Vec<u8>>;

/// The bytes of every buffer: the binary chunk of a .glb, a base64 data URI, or a file in the glTF's
/// folder (read as the folder's policy allows).
pub(super) fn buffers(gltf: &::gltf::Gltf, folder: &Folder) -> Result<Vec<Buffer>, String> {
    let blob = gltf.blob.clone().map(Rc::new);
    gltf.buffers()
        .map(|buffer| {
            let data = buffer_data(&buffer, blob.as_ref(), folder)?;
            if data.len() < buffer.length() {
                return Err(format!(
                    "buffer {} has {} bytes, the file says {}",
                    buffer.index(),
                    data.len(),
                    buffer.length()
                ));
            }
            Ok(data)
        })
        .collect()
}

/// One buffer's bytes.
fn buffer_data(
    buffer: &::gltf::Buffer,
    blob: Option<&Buffer>,
    folder: &Folder,
) -> Result<Buffer, String> {
    let k = buffer.index();
    match buffer.source() {
        ::gltf::buffer::Source::Bin => blob
            .cloned()
            .ok_or_else(|| format!("buffer {k} is the binary chunk, which is missing")),
        ::gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
            let (_, payload) = uri
                .split_once(";base64,")
                .ok_or_else(|| format!("buffer {k}: a data URI that is not base64"))?;
            base64::engine::general_purpose::STANDARD
                .decode(payload)
                .map(Rc::new)
                .map_err(|e| format!("buffer {k}: bad base64 in its data URI: {e}"))
        }
        ::gltf::buffer::Source::Uri(uri) => {
            let path = uri_path(uri, folder).map_err(|e| format!("buffer {k}: {e}"))?;
            let fetched = folder.fetch(Path::new(&path)).map_err(|e| match e {
                RefError::Missing(io) => format!(
                    "buffer {k}: cannot read `{}`: {io}",
                    folder.shown(Path::new(&path)).display()
                ),
                outside @ RefError::Outside(_) => format!("buffer {k}: {outside}"),
                other => format!("buffer {k}: `{uri}`: {other}"),
            })?;
            Ok(fetched.bytes)
        }
    }
}

/// The file path of a buffer URI that is not a data URI: a relative reference, percent-decoded. A URI
/// with a scheme is refused (scx fetches nothing from a network), except `file:` when the policy reaches
/// anywhere.
fn uri_path(uri: &str, folder: &Folder) -> Result<String, String> {
    match scheme(uri) {
        None => Ok(percent_decode(uri)),
        Some(s) if s.eq_ignore_ascii_case("file") => {
            if folder.policy().reach != Reach::Anywhere {
                return Err(format!(
                    "`{uri}` is a `file:` URI, an absolute path outside the scene's folder: scx reads \
                     the files a scene names only inside its folder (--read-anywhere lifts this)"
                ));
            }
            let rest = &uri[s.len() + 1..];
            let path = rest
                .strip_prefix("//localhost")
                .or_else(|| rest.strip_prefix("//"))
                .unwrap_or(rest);
            Ok(percent_decode(path))
        }
        Some(s) => Err(format!(
            "`{uri}` is a `{s}:` URI: scx reads buffers from data URIs and from files beside the \
             glTF, never from a network"
        )),
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

    /// Spends `bytes`, or says that the meshes hold too much.
    fn spend(&mut self, bytes: u64) -> Result<(), String> {
        self.left = self.left.checked_sub(bytes).ok_or_else(|| {
            format!(
                "the meshes its nodes place hold more than {} of vertices and indices (a mesh counts once \
                 for each node that places it): more than a file within the read limit could hold \
                 (--max-file-size raises the limit)",
                super::read::size_text(self.max)
            )
        })?;
        Ok(())
    }
}

/// The accessors, buffer views and buffers one reads from.
pub(super) struct Data<'a> {
    /// The document's JSON.
    pub root: &'a json::Root,
    /// Every buffer's bytes, by index.
    pub buffers: &'a [Buffer],
}

impl Data<'_> {
    /// The vertex positions of accessor `k`: FLOAT VEC3.
    pub fn positions(&self, k: usize, budget: &mut Budget) -> Result<Vec<[f32; 3]>, String> {
        let accessor = self.accessor(k)?;
        let what = format!("its POSITION accessor {k}");
        let component = component_type(accessor, &what)?;
        if component != ComponentType::F32 || accessor.type_ != Checked::Valid(Type::Vec3) {
            return Err(format!(
                "{what} holds {} {}: scx reads positions as FLOAT VEC3",
                component_name(component),
                type_name(&accessor.type_)
            ));
        }
        let bytes = self.packed(accessor, 12, &what, budget)?;
        Ok(bytes
            .chunks_exact(12)
            .map(|c| std::array::from_fn(|a| f32::from_le_bytes(word(&c[4 * a..]))))
            .collect())
    }

    /// The vertex indices of accessor `k`: unsigned bytes, shorts or ints, SCALAR.
    pub fn indices(&self, k: usize, budget: &mut Budget) -> Result<Vec<u32>, String> {
        let accessor = self.accessor(k)?;
        let what = format!("its indices accessor {k}");
        let component = component_type(accessor, &what)?;
        let size = match component {
            ComponentType::U8 => 1,
            ComponentType::U16 => 2,
            ComponentType::U32 => 4,
            _ => {
                return Err(format!(
                    "{what} holds {}: indices are UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT",
                    component_name(component)
                ))
            }
        };
        if accessor.type_ != Checked::Valid(Type::Scalar) {
            return Err(format!(
                "{what} is {}: indices are SCALAR",
                type_name(&accessor.type_)
            ));
        }
        let bytes = self.packed(accessor, size, &what, budget)?;
        Ok(bytes.chunks_exact(size).map(unsigned).collect())
    }

    fn accessor(&self, k: usize) -> Result<&json::Accessor, String> {
        self.root
            .accessors
            .get(k)
            .ok_or_else(|| format!("accessor {k} does not exist"))
    }

    /// An accessor's elements, `size` bytes each, packed one after the other: from its buffer view, or
    /// zeros under its sparse values.
    fn packed(
        &self,
        accessor: &json::Accessor,
        size: usize,
        what: &str,
        budget: &mut Budget,
    ) -> Result<Vec<u8>, String> {
        let count = usize::try_from(accessor.count.0).unwrap_or(usize::MAX);
        if count == 0 {
            return Err(format!("{what} has no elements (count 0)"));
        }
        let total = count
            .checked_mul(size)
            .ok_or_else(|| format!("{what}: its count {count} is beyond any buffer"))?;
        let offset = accessor.byte_offset.map_or(0, |o| o.0);
        let mut out = match accessor.buffer_view {
            Some(view) => {
                let (bytes, stride) = self.range(view.value(), offset, count, size, what)?;
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
            None => {
                return Err(format!(
                    "{what} has no buffer view and no sparse values: it holds no data"
                ))
            }
        };
        if let Some(sparse) = &accessor.sparse {
            self.apply_sparse(&mut out, sparse, count, size, what)?;
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
        what: &str,
    ) -> Result<(&[u8], usize), String> {
        let v = self
            .root
            .buffer_views
            .get(view)
            .ok_or_else(|| format!("{what}: buffer view {view} does not exist"))?;
        // No stride (or 0, which the gltf crate reads the same way): tightly packed.
        let stride = match v.byte_stride {
            Some(s) if s.0 > 0 => s.0,
            _ => size,
        };
        if stride < size {
            return Err(format!(
                "{what}: its buffer view {view} has a byte stride of {stride}, less than its {size}-byte \
                 elements"
            ));
        }
        let b = v.buffer.value();
        let data = self
            .buffers
            .get(b)
            .ok_or_else(|| format!("{what}: buffer {b} does not exist"))?;
        let start = v.byte_offset.map_or(0, |o| o.0);
        let length = v.byte_length.0;
        let end = start
            .checked_add(length)
            .filter(|&e| e <= data.len() as u64);
        let Some(end) = end else {
            return Err(format!(
                "{what}: its buffer view {view} (bytes {start} to {}) does not fit in buffer {b} of {} \
                 bytes",
                start.saturating_add(length),
                data.len()
            ));
        };
        let needed = (count as u64 - 1)
            .checked_mul(stride as u64)
            .and_then(|n| n.checked_add(size as u64))
            .and_then(|n| n.checked_add(offset))
            .filter(|&n| n <= length);
        let Some(needed) = needed else {
            return Err(format!(
                "{what}: its {count} elements of {size} bytes (stride {stride}) from byte {offset} do not \
                 fit in its buffer view {view} of {length} bytes"
            ));
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
        what: &str,
    ) -> Result<(), String> {
        let n = usize::try_from(sparse.count.0).unwrap_or(usize::MAX);
        if n == 0 {
            return Ok(());
        }
        if n > count {
            return Err(format!("{what}: {n} sparse values for {count} elements"));
        }
        let index_size = match sparse.indices.component_type {
            Checked::Valid(json::accessor::IndexComponentType(ComponentType::U8)) => 1,
            Checked::Valid(json::accessor::IndexComponentType(ComponentType::U16)) => 2,
            Checked::Valid(json::accessor::IndexComponentType(ComponentType::U32)) => 4,
            _ => {
                return Err(format!(
                "{what}: its sparse indices are not UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT"
            ))
            }
        };
        let sparse_what = format!("{what} (sparse)");
        let (indices, index_stride) = self.range(
            sparse.indices.buffer_view.value(),
            sparse.indices.byte_offset.0,
            n,
            index_size,
            &sparse_what,
        )?;
        let (values, value_stride) = self.range(
            sparse.values.buffer_view.value(),
            sparse.values.byte_offset.0,
            n,
            size,
            &sparse_what,
        )?;
        let mut previous = None;
        for k in 0..n {
            let at = index_stride * k;
            let i = unsigned(&indices[at..at + index_size]) as usize;
            if i >= count || previous.is_some_and(|p| p >= i) {
                return Err(format!(
                    "{what}: sparse index {i} (number {k}) is not below {count} and above the one before"
                ));
            }
            previous = Some(i);
            let v = value_stride * k;
            out[i * size..(i + 1) * size].copy_from_slice(&values[v..v + size]);
        }
        Ok(())
    }
}

/// An accessor's component type, or an error for an invalid one.
fn component_type(accessor: &json::Accessor, what: &str) -> Result<ComponentType, String> {
    match accessor.component_type {
        Checked::Valid(json::accessor::GenericComponentType(c)) => Ok(c),
        Checked::Invalid => Err(format!("{what} has an invalid component type")),
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
) -> Result<Vec<(usize, Option<usize>)>, String> {
    let mut reached: Vec<Option<Option<usize>>> = vec![None; root.nodes.len()];
    let mut order: Vec<(usize, Option<usize>)> = Vec::new();
    let mut stack: Vec<(usize, Option<usize>)> = roots.iter().rev().map(|&r| (r, None)).collect();
    while let Some((node, parent_at)) = stack.pop() {
        let parent = parent_at.map(|p| order[p].0);
        let slot = reached
            .get_mut(node)
            .ok_or_else(|| format!("node {node} does not exist"))?;
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

/// Why a node was reached a second time: first from `first` (its parent then, `None` for a root), now
/// from the node at `parent_at` in `order`.
fn reached_twice(
    node: usize,
    first: Option<usize>,
    parent_at: Option<usize>,
    order: &[(usize, Option<usize>)],
) -> String {
    const TREES: &str = "glTF nodes form trees: each node has at most one parent";
    let Some(at) = parent_at else {
        return match first {
            None => format!("its scene lists node {node} twice among its root nodes"),
            Some(p) => format!("node {node} is a root node of its scene and a child of node {p}"),
        };
    };
    let mut chain = vec![order[at].0];
    let mut up = order[at].1;
    while let Some(p) = up {
        chain.push(order[p].0);
        up = order[p].1;
    }
    if let Some(k) = chain.iter().position(|&n| n == node) {
        let cycle: Vec<String> = chain[..=k]
            .iter()
            .rev()
            .chain(std::iter::once(&node))
            .map(|n| n.to_string())
            .collect();
        return format!(
            "node {node} is its own ancestor (nodes {}): the node hierarchy has a cycle",
            cycle.join(" -> ")
        );
    }
    match first {
        Some(p) if p == order[at].0 => {
            format!("node {node} is listed twice among the children of node {p}; {TREES}")
        }
        Some(p) => format!(
            "node {node} is a child of node {p} and of node {}; {TREES}",
            order[at].0
        ),
        None => format!(
            "node {node} is a root node of its scene and a child of node {}",
            order[at].0
        ),
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
