//! The Embree backend (Embree 3 or 4, chosen at build time).
//!
//! Every intersection along a line comes from *one* traversal: the C shim (`ffi/scx_embree.c`) gives
//! Embree the triangles as a user geometry whose intersect callback sees each candidate, records it and
//! reports no hit, so Embree carries on to the next candidate instead of stopping at the nearest.
//!
//! Embree proposes, our watertight test decides. Embree's candidates are the triangles whose *boxes* a
//! line crosses, each box grown by the pure-Rust tracer's [`margin`](crate::trace::rust::bvh::margin) on
//! every side (1/65536 of the scene's size), exactly the boxes that tracer proposes from. A box holds every
//! point within the margin of its triangle, in every direction, far beyond the rounding of the watertight
//! test and of Embree's box tests, so the candidates are a superset of the true hits for every line, at any
//! angle to the triangle. The shim decides each candidate, and computes its distance, with the watertight
//! test of Woop, Benthin and Wald on the original triangle, in the same operations as
//! [`crate::trace::rust::watertight`]: the hits are bit-identical to the pure-Rust tracers', at edges and
//! vertices too, and for lines grazing a triangle at any angle. A crossing of a shared edge or vertex is
//! reported by one triangle, as for a line beside it ([`HitRules`] merges what rounding leaves).
//!
//! Embree's own triangle tests are not used, even on inflated triangles: its robust test can reject every
//! triangle around a vertex a line passes within rounding distance of (measured on `@cube:N`: 1-2% of
//! such lines lost a crossing), and a triangle inflated within its plane has no margin across the plane.
//! A line at a small angle `a` to the plane sees every error across it (the f32 rounding of the inflated
//! corners, which tilts the plane, and the rounding of both tests) magnified by `1 / sin a` within the
//! plane, past any in-plane margin near an edge: with inflated triangles, Embree lost a crossing on
//! 2602 of 61,440 lines grazing `@sphere:2` at vertices and edges (sines 1e-3 and 4e-3), and on 0.3-2 per
//! thousand lines aimed at vertices and edges of `@cornell` or `@sphere:5` in random directions, while
//! uniformly distributed lines practically never showed it. Boxes cost candidates (2.6 instead of 1.3 per
//! line on `@cube:30`, 7.2 instead of 2.0 on `@sphere:5`) and some speed (docs/design.md, "Two tracers, one
//! answer").
//!
//! For all hits the candidates are decided after the traversal of a batch, in one pass, not in the
//! callback: there Embree waited, candidate after candidate, for the test and for the cache miss on the
//! original triangle, while a pass over the batch overlaps them (docs/design.md, "Exact hits only where they
//! matter"). First-hit queries decide in the callback, because reporting a hit narrows Embree's search.
//!
//! Lines are traced one by one (`rtcIntersect1`, [`Query::Single`]) or in packets of 4, 8 or 16 adjacent
//! lines (`rtcIntersectN`, [`Query::Packet`]), at the widths the machine traces natively; both give the
//! same hits.
//!
//! All `unsafe` of the crate lives in this module: calls into the shim, each with its reason.

mod ffi;

use std::cell::RefCell;
use std::ffi::{c_char, c_int, CStr};
use std::fmt;
use std::mem::{align_of, size_of};
use std::ptr::{self, NonNull};
use std::sync::Arc;

use super::{Hit, HitRules, Line, Query, RawHit, TraceError, Tracer};
use crate::scene::Scene;

/// The name reported by [`Tracer::name`] and in errors.
const BACKEND: &str = "embree";

/// The shim's "no triangle" / "no line" marker (all ones).
const NONE: u32 = u32::MAX;

/// The packet widths Embree has kernels for.
const PACKET_WIDTHS: [usize; 3] = [4, 8, 16];

fn backend_error(message: impl Into<String>) -> TraceError {
    TraceError::Backend {
        backend: BACKEND,
        message: message.into(),
    }
}

/// What a status code means, for messages: the shim's own codes, else Embree's `RTCError`.
fn status_name(code: c_int) -> &'static str {
    match code {
        ffi::SCX_ERR_INVALID => "invalid argument",
        ffi::SCX_ERR_HIT_BUFFER => "hit buffer overflow",
        ffi::SCX_ERR_RAY_ID => "unexpected ray id",
        _ => match code as ffi::RTCError {
            ffi::RTC_ERROR_UNKNOWN => "unknown error",
            ffi::RTC_ERROR_INVALID_ARGUMENT => "invalid argument",
            ffi::RTC_ERROR_INVALID_OPERATION => "invalid operation",
            ffi::RTC_ERROR_OUT_OF_MEMORY => "out of memory",
            ffi::RTC_ERROR_UNSUPPORTED_CPU => "unsupported CPU",
            ffi::RTC_ERROR_CANCELLED => "cancelled",
            _ => "error",
        },
    }
}

/// Turns a shim status into a result, with the message the shim recorded on this thread.
fn check(code: c_int) -> Result<(), TraceError> {
    if code == ffi::SCX_OK {
        return Ok(());
    }
    let mut buf = [0u8; 512];
    // SAFETY: `buf` is writable for `buf.len()` bytes; the shim writes at most that many, NUL included.
    unsafe { ffi::scx_take_error(buf.as_mut_ptr().cast::<c_char>(), buf.len()) };
    let message = CStr::from_bytes_until_nul(&buf)
        .map(|m| m.to_string_lossy().into_owned())
        .unwrap_or_default();
    Err(backend_error(format!(
        "{} (code {code}): {message}",
        status_name(code)
    )))
}

/// An Embree device. Shared through an `Arc` by the tracer and its scene, so whichever is dropped last
/// releases it.
struct Device {
    raw: NonNull<ffi::scx_device>,
}

// SAFETY: an Embree device is a reference-counted, internally synchronised object (Embree's API may be
// called from any thread), and the shim's wrapper is immutable after creation: it can move between and be
// shared by threads.
unsafe impl Send for Device {}
// SAFETY: see `Send`; `&Device` only reads immutable properties.
unsafe impl Sync for Device {}

impl Device {
    fn new() -> Result<Self, TraceError> {
        let mut raw = ptr::null_mut();
        // SAFETY: a null config asks for Embree's defaults; `raw` is a valid place for the result.
        check(unsafe { ffi::scx_device_new(ptr::null(), &mut raw) })?;
        NonNull::new(raw)
            .map(|raw| Device { raw })
            .ok_or_else(|| backend_error("scx_device_new returned no device"))
    }

    fn native_widths(&self) -> Vec<usize> {
        // SAFETY: `self.raw` is a live device (released only in Drop).
        let bits = unsafe { ffi::scx_device_packet_widths(self.raw.as_ptr()) } as usize;
        PACKET_WIDTHS
            .into_iter()
            .filter(|w| bits & w != 0)
            .collect()
    }

    fn version(&self) -> String {
        let (mut major, mut minor, mut patch) = (0, 0, 0);
        // SAFETY: `self.raw` is a live device; the three out-pointers are valid places for ints.
        unsafe { ffi::scx_device_version(self.raw.as_ptr(), &mut major, &mut minor, &mut patch) };
        format!("{major}.{minor}.{patch}")
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: `self.raw` came from `scx_device_new` and is released exactly once, here. Scenes made from
        // the device hold an `Arc<Device>`, so none is still in use.
        unsafe { ffi::scx_device_release(self.raw.as_ptr()) };
    }
}

/// A committed Embree scene with the scene's triangles as geometry 0 (primID = triangle index).
struct CommittedScene {
    raw: NonNull<ffi::scx_scene>,
    /// Keeps the device alive for as long as the scene.
    _device: Arc<Device>,
}

// SAFETY: after commit an Embree scene is immutable, and Embree documents queries on a committed scene as
// safe from any number of threads at once; release is reference counted. The shim's per-query state lives
// on the calling thread's stack and in the caller's own hit buffer.
unsafe impl Send for CommittedScene {}
// SAFETY: see `Send`: `&CommittedScene` only runs queries.
unsafe impl Sync for CommittedScene {}

impl CommittedScene {
    fn new(device: &Arc<Device>, scene: &Scene) -> Result<Self, TraceError> {
        let too_big =
            |what: &str| backend_error(format!("{}: too many {what} for Embree", scene.name));
        let n_vertices = u32::try_from(scene.positions.len()).map_err(|_| too_big("vertices"))?;
        let n_triangles = u32::try_from(scene.triangles.len()).map_err(|_| too_big("triangles"))?;
        let mut raw = ptr::null_mut();
        // SAFETY: `[f32; 3]` and `[u32; 3]` are laid out as 3 contiguous elements, so the two pointers cover
        // `3 * n_vertices` floats and `3 * n_triangles` indices; the shim copies them (no pointer is kept)
        // and checks every index against `n_vertices` before Embree reads any. `raw` is a valid out-pointer.
        let code = unsafe {
            ffi::scx_scene_new(
                device.raw.as_ptr(),
                scene.positions.as_ptr().cast::<f32>(),
                n_vertices,
                scene.triangles.as_ptr().cast::<u32>(),
                n_triangles,
                &mut raw,
            )
        };
        check(code)
            .map_err(|e| backend_error(format!("{}: building the scene: {e}", scene.name)))?;
        let raw =
            NonNull::new(raw).ok_or_else(|| backend_error("scx_scene_new returned no scene"))?;
        Ok(CommittedScene {
            raw,
            _device: Arc::clone(device),
        })
    }
}

impl Drop for CommittedScene {
    fn drop(&mut self) {
        // SAFETY: `self.raw` came from `scx_scene_new` and is released exactly once, here; `&self` queries
        // cannot outlive `self`.
        unsafe { ffi::scx_scene_release(self.raw.as_ptr()) };
    }
}

/// The shim's growable hit array, freed on drop (also when a query fails half way).
#[derive(Default)]
struct HitBuffer(ffi::scx_hits);

impl HitBuffer {
    fn as_slice(&self) -> &[ffi::scx_hit] {
        if self.0.data.is_null() {
            return &[];
        }
        // SAFETY: the shim keeps `data` pointing at `cap >= len` records of which the first `len` are
        // written, and it only changes them during a query, which needs `&mut self`.
        unsafe { std::slice::from_raw_parts(self.0.data, self.0.len) }
    }
}

impl Drop for HitBuffer {
    fn drop(&mut self) {
        // SAFETY: the buffer was zeroed at creation and since then only managed by the shim, whose
        // `scx_hits_free` frees exactly what its `realloc` allocated.
        unsafe { ffi::scx_hits_free(&mut self.0) };
    }
}

/// Checks that Embree can trace `lines`: finite numbers, `t_max >= 0`, and fewer lines than the shim's
/// padding id. The shim reads them in place: [`Line`] is `#[repr(C)]` with the fields of `scx_line`
/// (sizes compared in [`layout_checks`]).
fn check_lines(lines: &[Line]) -> Result<(), TraceError> {
    if lines.len() >= NONE as usize {
        return Err(backend_error(format!(
            "{} lines in one batch; at most {} fit",
            lines.len(),
            NONE - 1
        )));
    }
    for (k, l) in lines.iter().enumerate() {
        let finite = l.origin.iter().chain(&l.dir).all(|c| c.is_finite()) && l.t_max.is_finite();
        if !finite || l.t_max < 0.0 {
            return Err(backend_error(format!(
                "line {k} cannot be traced: {l:?} (needs finite values and t_max >= 0)"
            )));
        }
    }
    Ok(())
}

/// `lines` as the shim's `scx_line` array (the same layout; see [`check_lines`]).
fn shim_lines(lines: &[Line]) -> *const ffi::scx_line {
    lines.as_ptr().cast()
}

/// A thread's query buffers, kept from batch to batch: a batch of 4096 lines needs ~150 KB of lines
/// prepared for the watertight test and ~100 KB of hits, and allocating them afresh for every batch made
/// the allocator map and the system clear fresh pages each time (perf: 4-5% of an analysis of `@cube:30`
/// went to clearing pages for them).
#[derive(Default)]
struct Scratch {
    /// Room for the shim's prepared lines: only its capacity is used. The shim writes them and reads
    /// them back; Rust never reads them, so they are neither initialised nor counted in the length
    /// (clearing ~150 KB per batch, and copying the lines into the shim's layout, were 3-5% of an Embree
    /// all-hits trace).
    sheared: Vec<ffi::scx_sheared>,
    hits: HitBuffer,
}

impl Scratch {
    /// Prepares the buffers for `lines`: the lines checked, room for as many prepared lines, and an empty
    /// hit buffer.
    fn prepare(&mut self, lines: &[Line]) -> Result<(), TraceError> {
        check_lines(lines)?;
        self.sheared.clear();
        self.sheared.reserve(lines.len());
        self.hits.0.len = 0;
        self.hits.0.overflow = 0;
        Ok(())
    }

    /// Where the shim writes the prepared lines: room for as many as [`Scratch::prepare`] was given.
    fn sheared_room(&mut self) -> *mut ffi::scx_sheared {
        self.sheared
            .spare_capacity_mut()
            .as_mut_ptr()
            .cast::<ffi::scx_sheared>()
    }
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// Runs `f` with this thread's buffers (or fresh ones, should a query ever run inside another).
fn with_scratch<R>(f: impl FnOnce(&mut Scratch) -> R) -> R {
    SCRATCH.with(|s| match s.try_borrow_mut() {
        Ok(mut s) => f(&mut s),
        Err(_) => f(&mut Scratch::default()),
    })
}

/// One shared struct's size (or alignment, or a constant) as the C shim's compiler and as the Rust
/// bindings see it; see [`layout_checks`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LayoutCheck {
    /// What is measured (`"RTCRayHit16"`, `"align RTCRayHit8"`, `"RTC_VERSION"`).
    pub name: &'static str,
    /// The value in C (`sizeof`, `_Alignof`, or the constant).
    pub c: usize,
    /// The value in Rust (`size_of`, `align_of` of the bindgen type, or bindgen's constant).
    pub rust: usize,
}

impl LayoutCheck {
    fn new(name: &'static str, c: usize, rust: usize) -> Self {
        LayoutCheck { name, c, rust }
    }
}

fn shim_layout() -> ffi::scx_layout {
    let mut layout = ffi::scx_layout::default();
    // SAFETY: `layout` is a valid, writable `scx_layout`, the only thing the shim writes.
    unsafe { ffi::scx_get_layout(&mut layout) };
    layout
}

/// The sizes of every struct Rust shares with the shim or Embree, from both sides. They must agree:
/// Embree writes whole structs, so a smaller Rust struct would be overrun. [`EmbreeTracer::new`] refuses
/// to run when they differ.
pub fn layout_checks() -> Vec<LayoutCheck> {
    let c = shim_layout();
    let mut checks = vec![
        LayoutCheck::new("RTCRay", c.ray, size_of::<ffi::RTCRay>()),
        LayoutCheck::new("RTCHit", c.hit, size_of::<ffi::RTCHit>()),
        LayoutCheck::new("RTCRayHit", c.rayhit, size_of::<ffi::RTCRayHit>()),
        LayoutCheck::new("RTCRayHit4", c.rayhit4, size_of::<ffi::RTCRayHit4>()),
        LayoutCheck::new("RTCRayHit8", c.rayhit8, size_of::<ffi::RTCRayHit8>()),
        LayoutCheck::new("RTCRayHit16", c.rayhit16, size_of::<ffi::RTCRayHit16>()),
        LayoutCheck::new(
            "align RTCRayHit4",
            c.align_rayhit4,
            align_of::<ffi::RTCRayHit4>(),
        ),
        LayoutCheck::new(
            "align RTCRayHit8",
            c.align_rayhit8,
            align_of::<ffi::RTCRayHit8>(),
        ),
        LayoutCheck::new(
            "align RTCRayHit16",
            c.align_rayhit16,
            align_of::<ffi::RTCRayHit16>(),
        ),
        LayoutCheck::new("scx_line", c.line, size_of::<ffi::scx_line>()),
        LayoutCheck::new("scx_line as Line", c.line, size_of::<Line>()),
        LayoutCheck::new("scx_hit", c.hit_record, size_of::<ffi::scx_hit>()),
        LayoutCheck::new("scx_hit as RawHit", c.hit_record, size_of::<RawHit>()),
        LayoutCheck::new("scx_hits", c.hits, size_of::<ffi::scx_hits>()),
        LayoutCheck::new(
            "scx_first_hit",
            c.first_hit,
            size_of::<ffi::scx_first_hit>(),
        ),
        LayoutCheck::new("scx_query", c.query, size_of::<ffi::scx_query>()),
        LayoutCheck::new("scx_layout", c.layout, size_of::<ffi::scx_layout>()),
        LayoutCheck::new("RTC_VERSION", c.version as usize, ffi::RTC_VERSION as usize),
    ];
    #[cfg(embree_v3)]
    checks.push(LayoutCheck::new(
        "RTCIntersectContext",
        c.context,
        size_of::<ffi::RTCIntersectContext>(),
    ));
    #[cfg(embree_v4)]
    checks.extend([
        LayoutCheck::new(
            "RTCRayQueryContext",
            c.context,
            size_of::<ffi::RTCRayQueryContext>(),
        ),
        LayoutCheck::new(
            "RTCIntersectArguments",
            c.arguments,
            size_of::<ffi::RTCIntersectArguments>(),
        ),
    ]);
    checks
}

/// `RTC_VERSION` of the Embree headers the shim was compiled against (e.g. 31305 for 3.13.5).
pub fn header_version() -> u32 {
    shim_layout().version as u32
}

fn check_layout() -> Result<(), TraceError> {
    let bad: Vec<String> = layout_checks()
        .into_iter()
        .filter(|l| l.c != l.rust)
        .map(|l| format!("{}: C {} vs Rust {}", l.name, l.c, l.rust))
        .collect();
    if bad.is_empty() {
        Ok(())
    } else {
        Err(backend_error(format!(
            "the bindings do not match the compiled shim ({}); rebuild from clean",
            bad.join(", ")
        )))
    }
}

/// Tracing with Embree: all hits (the [`Tracer`] trait) and first hits, one line or one packet per query.
///
/// Queries take `&self` and may run on many threads at once; each call has its own hit buffer.
pub struct EmbreeTracer {
    scene: CommittedScene,
    device: Arc<Device>,
    query: Query,
    /// 1 for single lines, else the packet width.
    width: u32,
    rules: HitRules,
}

impl EmbreeTracer {
    /// Uploads `scene`'s triangles to a new Embree device and commits them (robust mode), to be traced
    /// with `query`.
    ///
    /// Errors: [`TraceError::Unsupported`] when `query` asks for packets of a width that this machine
    /// does not trace natively (the message names the native widths); [`TraceError::Backend`] when
    /// Embree fails or the scene cannot be uploaded.
    pub fn new(scene: &Scene, query: Query) -> Result<Self, TraceError> {
        check_layout()?;
        let device = Arc::new(Device::new()?);
        let width = query_width(&device, query)?;
        let committed = CommittedScene::new(&device, scene)?;
        Ok(EmbreeTracer {
            scene: committed,
            device,
            query,
            width,
            rules: HitRules::new(scene),
        })
    }

    /// The packet widths (among 4, 8, 16) that this machine and Embree build trace natively.
    pub fn native_packet_widths(&self) -> Vec<usize> {
        self.device.native_widths()
    }

    /// The running Embree library's version, e.g. `"3.13.5"`.
    pub fn version(&self) -> String {
        self.device.version()
    }

    /// The query kind this tracer uses.
    pub fn query(&self) -> Query {
        self.query
    }

    /// The nearest hit of each line (`None` for a miss), one entry per line; replaces `out`'s contents.
    pub fn first_hits(&self, lines: &[Line], out: &mut Vec<Option<Hit>>) -> Result<(), TraceError> {
        let mut first = vec![ffi::scx_first_hit::default(); lines.len()];
        with_scratch(|scratch| {
            scratch.prepare(lines)?;
            let sheared = scratch.sheared_room();
            // SAFETY: the scene is live and committed; `lines` (read in place: `Line` has the layout of
            // `scx_line`, checked in `new`) and `first` hold `lines.len()` elements (checked to fit in
            // u32), `sheared` has room for as many plain-data records, which the shim writes before it
            // reads them; the width was checked against the device in `new` (and the shim checks it
            // again).
            let code = unsafe {
                ffi::scx_first_hits(
                    self.scene.raw.as_ptr(),
                    shim_lines(lines),
                    lines.len() as u32,
                    self.width,
                    sheared,
                    first.as_mut_ptr(),
                )
            };
            check(code)
        })?;
        out.clear();
        out.extend(first.iter().map(|f| {
            (f.prim != NONE).then_some(Hit {
                t: f.t,
                triangle: f.prim,
            })
        }));
        Ok(())
    }
}

/// The shim's width for a query, or why this machine cannot run it.
fn query_width(device: &Device, query: Query) -> Result<u32, TraceError> {
    let width = match query {
        Query::Single => return Ok(1),
        Query::Packet(width) => width,
    };
    let native = device.native_widths();
    if native.contains(&width) {
        return Ok(width as u32);
    }
    let list = if native.is_empty() {
        "none".to_string()
    } else {
        native
            .iter()
            .map(|w| w.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    Err(TraceError::Unsupported(format!(
        "embree: packets of {width} lines are not native here (Embree {}; native packet widths: {list}); \
         use one of those or single lines",
        device.version()
    )))
}

impl Tracer for EmbreeTracer {
    fn name(&self) -> &'static str {
        BACKEND
    }

    fn rules(&self) -> &HitRules {
        &self.rules
    }

    fn first_hits(&self, lines: &[Line], out: &mut Vec<Option<Hit>>) -> Result<(), TraceError> {
        EmbreeTracer::first_hits(self, lines, out)
    }

    fn raw_hits(&self, lines: &[Line], out: &mut Vec<RawHit>) -> Result<(), TraceError> {
        with_scratch(|scratch| {
            scratch.prepare(lines)?;
            let sheared = scratch.sheared_room();
            // SAFETY: the scene is live and committed; `lines` (read in place: `Line` has the layout of
            // `scx_line`, checked in `new`) holds `lines.len()` elements (checked to fit in u32 below
            // the padding id), `sheared` has room for as many plain-data records, which the shim writes
            // before it reads them; `scratch.hits` is this thread's buffer, emptied above and grown by
            // the shim with realloc; the width was checked against the device in `new` (and the shim
            // checks it again).
            let code = unsafe {
                ffi::scx_all_hits(
                    self.scene.raw.as_ptr(),
                    shim_lines(lines),
                    lines.len() as u32,
                    self.width,
                    sheared,
                    &mut scratch.hits.0,
                )
            };
            check(code)?;
            out.clear();
            out.extend(scratch.hits.as_slice().iter().map(|h| RawHit {
                t: h.t,
                triangle: h.prim,
                line: h.line,
            }));
            Ok(())
        })
    }
}

impl fmt::Debug for EmbreeTracer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("EmbreeTracer")
            .field("version", &self.version())
            .field("query", &self.query)
            .field("native_packet_widths", &self.native_packet_widths())
            .finish_non_exhaustive()
    }
}
