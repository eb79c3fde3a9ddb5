//! Tracing backends: every intersection along a batch of global lines.
//!
//! A backend (`embree`, or the pure-Rust BVH) only reports *raw* hits: `(line, t, triangle)` in any
//! order. Every backend decides a hit with the same watertight test, exact on edges and vertices, so a
//! crossing of a shared edge or vertex is reported once, by the triangle a line beside it would cross,
//! and the raw reports of a line through a closed mesh are even in number. [`HitRules::canonicalize`]
//! turns them into the canonical form that every consumer relies on, identically for every backend:
//!
//! * hits of a line are sorted by `(t, triangle)`;
//! * exact repeats of `(t, triangle)` are removed;
//! * hits within a few f32 ulps of each other whose triangles share a vertex and face the line the same
//!   way (a line grazing a surface within f32 rounding, which can fold the f32 mesh there) are one
//!   crossing, kept once (the first in sort order). Hits at the same place that face the line
//!   differently are a graze (the line touches a ridge and leaves) and are all kept.

#[cfg(feature = "embree")]
#[allow(unsafe_code)]
pub mod embree;
mod rules;
pub mod rust;

pub use rules::HitRules;

use std::fmt;

/// A line in tracing space (the scene scaled to its unit bounding sphere), traced in f32.
///
/// The segment `origin + t * dir`, `t` in `[0, t_max]`, covers the whole bounding sphere; `dir` is unit.
/// `#[repr(C)]`: the Embree shim reads lines in place, as its `scx_line` (the same fields in the same
/// order; the sizes are compared when an Embree tracer is made).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Line {
    /// A point on the line outside the scene: on (or just beyond) the bounding sphere or the bounding
    /// box the run draws its lines through.
    pub origin: [f32; 3],
    /// Unit direction.
    pub dir: [f32; 3],
    /// The far end of the traced segment.
    pub t_max: f32,
}

/// One intersection of a line with a triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance from the line's origin, in tracing units.
    pub t: f32,
    /// Index of the triangle in [`crate::scene::Scene::triangles`].
    pub triangle: u32,
}

/// A raw hit as a backend reports it: which line, where, which triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct RawHit {
    /// Distance from the line's origin.
    pub t: f32,
    /// Triangle index.
    pub triangle: u32,
    /// Index of the line within the batch passed to the backend.
    pub line: u32,
}

/// The hits of a batch of lines in compressed rows: the hits of line `k` are
/// `hits[start[k] as usize..start[k + 1] as usize]`.
#[derive(Clone, Debug, Default)]
pub struct LineHits {
    /// All hits, grouped by line.
    pub hits: Vec<Hit>,
    /// Row offsets, one more than the number of lines.
    pub start: Vec<u32>,
}

impl LineHits {
    /// The number of lines held.
    pub fn lines(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// The hits of line `k`.
    pub fn of_line(&self, k: usize) -> &[Hit] {
        &self.hits[self.start[k] as usize..self.start[k + 1] as usize]
    }

    /// Groups raw hits by line (a stable counting sort), replacing the current contents.
    pub fn fill_from_raw(&mut self, n_lines: usize, raw: &[RawHit]) {
        self.start.clear();
        self.start.resize(n_lines + 1, 0);
        for r in raw {
            self.start[r.line as usize + 1] += 1;
        }
        for k in 0..n_lines {
            self.start[k + 1] += self.start[k];
        }
        let mut next: Vec<u32> = self.start[..n_lines].to_vec();
        self.hits.clear();
        self.hits.resize(
            raw.len(),
            Hit {
                t: 0.0,
                triangle: 0,
            },
        );
        for r in raw {
            let slot = &mut next[r.line as usize];
            self.hits[*slot as usize] = Hit {
                t: r.t,
                triangle: r.triangle,
            };
            *slot += 1;
        }
    }
}

/// Which kind of Embree query drives a batch of lines (saved as its name, `single`, `packet8`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(into = "String", try_from = "String")]
pub enum Query {
    /// One line per query (`rtcIntersect1`).
    Single,
    /// Packets of 4, 8 or 16 lines per query (`rtcIntersect4/8/16`).
    Packet(usize),
}

impl Query {
    /// Parses a query as [`Query`]'s `Display` writes it (`single`, `packet4`, `packet8`, `packet16`).
    pub fn parse(s: &str) -> Result<Query, QueryError> {
        match s {
            "single" => Ok(Query::Single),
            "packet4" => Ok(Query::Packet(4)),
            "packet8" => Ok(Query::Packet(8)),
            "packet16" => Ok(Query::Packet(16)),
            _ => Err(QueryError(s.into())),
        }
    }
}

impl From<Query> for String {
    fn from(q: Query) -> String {
        q.to_string()
    }
}

impl TryFrom<String> for Query {
    type Error = QueryError;

    fn try_from(s: String) -> Result<Query, QueryError> {
        Query::parse(&s)
    }
}

/// A ray query's name that is not one ([`Query::parse`]).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("`{0}`: expected single, packet4, packet8 or packet16")]
pub struct QueryError(pub String);

impl fmt::Display for Query {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Query::Single => write!(f, "single"),
            Query::Packet(w) => write!(f, "packet{w}"),
        }
    }
}

/// Errors a tracing backend can report.
#[derive(Debug, thiserror::Error)]
pub enum TraceError {
    /// The backend library reported an error (Embree's device error callback, or a failed call).
    #[error("{backend}: {message}")]
    Backend {
        /// Which backend.
        backend: &'static str,
        /// What it said.
        message: String,
    },
    /// The requested query is not available on this machine or build.
    #[error("{0}")]
    Unsupported(String),
}

/// A tracing backend: all intersections along a batch of lines.
///
/// Implementations must be usable from several threads at once (`&self` queries on a committed scene).
pub trait Tracer: Send + Sync {
    /// A short name for reports (`"embree"`, `"rust"`).
    fn name(&self) -> &'static str;

    /// The canonicalisation rules for this backend's scene.
    fn rules(&self) -> &HitRules;

    /// Every intersection of every line with the scene's triangles, in any order; replaces `out`'s contents.
    fn raw_hits(&self, lines: &[Line], out: &mut Vec<RawHit>) -> Result<(), TraceError>;

    /// Every intersection along each line, sorted by `(t, triangle)`, one hit per crossing
    /// (see the module documentation).
    fn all_hits(
        &self,
        lines: &[Line],
        scratch: &mut Vec<RawHit>,
        out: &mut LineHits,
    ) -> Result<(), TraceError> {
        self.raw_hits(lines, scratch)?;
        out.fill_from_raw(lines.len(), scratch);
        self.rules().canonicalize(lines, out);
        Ok(())
    }

    /// The nearest hit of each line (`None` for a miss): the least `t`, ties to the lower triangle index,
    /// i.e. the first hit of the canonical list; replaces `out`'s contents.
    ///
    /// This default finds all hits; backends override it with a query that stops early.
    fn first_hits(&self, lines: &[Line], out: &mut Vec<Option<Hit>>) -> Result<(), TraceError> {
        let mut scratch = Vec::new();
        let mut hits = LineHits::default();
        self.all_hits(lines, &mut scratch, &mut hits)?;
        out.clear();
        out.extend((0..lines.len()).map(|k| hits.of_line(k).first().copied()));
        Ok(())
    }
}

/// The tracing backends a user can choose.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Backend {
    /// Embree (needs the `embree` feature).
    Embree,
    /// The pure-Rust tracer.
    Rust,
}

impl Backend {
    /// The name on the command line and in reports (`embree`, `rust`).
    pub fn name(self) -> &'static str {
        match self {
            Backend::Embree => "embree",
            Backend::Rust => "rust",
        }
    }

    /// The backend used when none is named: the pure-Rust tracer, in every build. Its hits are
    /// Embree's to the bit (`scx crosscheck`) and it is the faster of the two end to end on every scene
    /// size measured (docs/performance.md, "The two tracers: throughput and packets"); Embree stays one flag away.
    pub fn default_available() -> Self {
        Backend::Rust
    }
}

/// Builds the tracer for `scene` with the chosen backend and query kind.
pub fn make_tracer(
    backend: Backend,
    scene: &crate::scene::Scene,
    query: Query,
) -> Result<Box<dyn Tracer>, TraceError> {
    match backend {
        #[cfg(feature = "embree")]
        Backend::Embree => Ok(Box::new(embree::EmbreeTracer::new(scene, query)?)),
        #[cfg(not(feature = "embree"))]
        Backend::Embree => {
            let _ = query;
            Err(TraceError::Unsupported(
                "this scx was built without Embree (cargo feature `embree`); use --tracer rust"
                    .into(),
            ))
        }
        Backend::Rust => match query {
            Query::Single => Ok(Box::new(rust::BvhTracer::new(scene)?)),
            Query::Packet(_) => Err(TraceError::Unsupported(
                "the pure-Rust tracer traces single lines only".into(),
            )),
        },
    }
}
