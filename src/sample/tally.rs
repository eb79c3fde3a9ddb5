//! Accumulation: what a set of global lines found, as integers (counts) and f64 sums.
//!
//! [`tally_lines`] turns one batch of traced lines into a [`BatchTally`]: its [`Counters`], the keys of
//! its visible pairs and the patches its escapes left. Batches are added up into a [`Tally`] in batch
//! order, so that even the f64 sums are bit-identical whatever the number of threads that traced them.
//! The hot loop knows nothing of I/O, threads or scheduling (that is the run engine's, `run`).

use rayon::prelude::*;

use super::counts::{count_by_group, pair_key, PairCounts};
use super::environment;
use super::exact::ExactSum;
use super::kernel::Log2Sum;
use super::kernel_sums::PatchKernelSums;
use super::pairs::{PatchPlanes, Segment};
use super::patch_counts::PatchCounts;
use crate::scene::Scene;
use crate::trace::{Line, LineHits};

/// Which estimates a run must gather; leaving one out skips its work (paper sec. 3.1 and 3.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Wanted {
    /// Pair counts N_ij for the discrete measures (H_s, I_s, ...).
    pub discrete: bool,
    /// The per-pair sum of eq. (27) for the continuous mutual information.
    pub continuous: bool,
    /// Eq. (27)'s terms summed per patch ([`PatchKernelSums`]) for the per-patch results; needs
    /// `discrete` (the pair keys say which patches a term belongs to).
    pub per_patch: bool,
    /// With `per_patch`, the terms of each patch's escapes summed too
    /// ([`PatchKernelSums::environment_log2_kernel`]), for the per-patch results of an enclosed scene
    /// (`--enclose`, [`super::environment`]).
    pub environment: bool,
}

impl Wanted {
    /// Empty per-patch sums for `patches` patches, when they are wanted.
    fn kernel_sums(self, patches: usize) -> Option<PatchKernelSums> {
        match (self.per_patch, self.environment) {
            (false, _) => None,
            (true, false) => Some(PatchKernelSums::new(patches)),
            (true, true) => Some(PatchKernelSums::with_environment(patches)),
        }
    }
}

/// Which cosine eq. (27)'s sum takes at the far end of each line's last pair.
///
/// Uniformly distributed lines run either way with equal density, and reversing a line makes its first
/// pair its last and the near end of that pair the far one: so over all lines the cosine at the near
/// end of a line's first pair has the same distribution as the cosine at the far end of its last, and
/// either may stand in eq. (27)'s sum for the latter without bias (pairs whose kernel is degenerate,
/// [`super::kernel::kernel_without_pi`], keep their own, at either end, so that the exchange stays
/// symmetric). Which one is better is a question of variance, measured in docs/sampling.md.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LastCosine {
    /// Every pair's own two cosines: the plain estimator.
    #[default]
    Own,
    /// The cosine at the near end of the line's first pair. For lines drawn from a container's faces
    /// with Sobol' points: where the scene's surfaces lie in the container's faces (rooms, solids) that
    /// cosine is a smooth function of the sequence's coordinates, which the sequence integrates far
    /// better than the exit's (the octahedron's I_s^c: 1.5x smaller spread at 10^6 lines and more;
    /// independent lines: 1.1x larger, so they keep their own).
    FirstEntry,
}

/// The counters and sums of a set of lines: every number a run adds up but the pair counts and the
/// escapes per patch.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Counters {
    /// Lines traced.
    pub lines: u64,
    /// Canonical hits (crossings) found.
    pub hits: u64,
    /// Visible pairs (each counted once, though it enters N_ij and N_ji).
    pub pairs: u64,
    /// Segments from a front side out of the scene.
    pub escapes: u64,
    /// Segments that join no two front sides.
    pub unpaired: u64,
    /// Of them, the segments from a front side to a back side: what leaves that front side there
    /// arrives at no front side, and is absorbed (it counts in the row, like an escape).
    #[serde(default)]
    pub absorbed: u64,
    /// Pairs whose two points coincide in f64 (touching surfaces): left out of eq. (27).
    pub degenerate_pairs: u64,
    /// Crossings of two coplanar overlapping surfaces facing the same way (only the first is seen there).
    pub coincident_crossings: u64,
    /// Lines that hit nothing (for `--enclose`: a chord of the environment sphere).
    pub misses: u64,
    /// Sum over pairs of log2(A_T cos cos / (pi d^2)), eq. (27), exact in any order of addition.
    pub cmi_sum: ExactSum,
    /// Pairs that entered `cmi_sum`.
    pub cmi_pairs: u64,
    /// Over the segments joining a surface, or the sphere itself, to the environment sphere (escapes and
    /// misses): the sum of log2(cos cos / d^2), for eq. (27) with `--enclose` ([`super::environment`]).
    pub env_log2_sum: ExactSum,
    /// How many segments entered `env_log2_sum`.
    pub env_pairs: u64,
    /// Pairs whose two points are [`SHORT_CHORD`] apart (tracing units): how densely lines cross the
    /// scene's corners close to an edge, from which the shorter chords f32 tracing loses are estimated
    /// (the reliability of I_s^c). Absent from states saved before it existed, which read as none.
    #[serde(default)]
    pub short_chords: u64,
}

/// The chord lengths counted in [`Counters::short_chords`], tracing units (the bounding sphere's radius
/// being 1): short enough that only lines crossing a corner near its edge have them, long enough that f32
/// tracing finds every one of them.
pub const SHORT_CHORD: std::ops::Range<f64> = 1e-5..1e-4;

impl Counters {
    /// Adds another set of lines' counters into these (in any order: every sum is exact).
    pub fn add(&mut self, other: &Counters) {
        self.lines += other.lines;
        self.hits += other.hits;
        self.pairs += other.pairs;
        self.escapes += other.escapes;
        self.unpaired += other.unpaired;
        self.absorbed += other.absorbed;
        self.degenerate_pairs += other.degenerate_pairs;
        self.coincident_crossings += other.coincident_crossings;
        self.misses += other.misses;
        self.cmi_sum.add(other.cmi_sum);
        self.cmi_pairs += other.cmi_pairs;
        self.env_log2_sum.add(other.env_log2_sum);
        self.env_pairs += other.env_pairs;
        self.short_chords += other.short_chords;
    }
}

/// How lines met one object's two sides where a consistently oriented scene shows only front sides
/// ([`super::pairs`]): the evidence for normals facing the wrong way and for one-sided surfaces seen
/// from behind. Only the ends of a line and its unpaired segments are looked at.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ObjectSides {
    /// Lines whose first crossing is a back side of the object: they arrive at it from open space.
    pub back_from_open: u64,
    /// Lines whose last crossing is a back side of the object: they leave it into open space.
    pub back_to_open: u64,
    /// Segments between a front side of the object and open space (escapes, at either end).
    pub front_open: u64,
    /// Segments between a front side (of any object) and a back side of this object: lost pairs if the
    /// object is meant to be seen from there.
    pub back_seen: u64,
}

/// One piece of orientation evidence of a batch: which object, and which of its [`ObjectSides`]
/// counters. A batch of a scene of many objects keeps a list of them ([`BatchSides::Events`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SideEvent {
    /// The object.
    pub object: u32,
    /// Which counter: 0 `back_from_open`, 1 `back_to_open`, 2 `front_open`, 3 `back_seen`.
    pub kind: u8,
}

/// A batch's orientation evidence ([`ObjectSides`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BatchSides {
    /// Counted per object, for scenes of at most [`DENSE_SIDE_OBJECTS`] objects: a room seen from inside
    /// gives two pieces of evidence per line, and as a list they took three times the memory of the
    /// batch's pair keys, all of it fresh pages to fault in as the rounds grow.
    Dense(Vec<ObjectSides>),
    /// Event by event, for scenes of more objects (a table per batch would outweigh its lines).
    Events(Vec<SideEvent>),
}

/// Scenes with at most this many objects count their batches' orientation evidence in a table.
pub const DENSE_SIDE_OBJECTS: usize = 256;

impl Default for BatchSides {
    fn default() -> Self {
        BatchSides::Events(Vec::new())
    }
}

impl BatchSides {
    /// No evidence yet, for a scene of `objects` objects.
    pub fn for_objects(objects: usize) -> Self {
        if objects <= DENSE_SIDE_OBJECTS {
            BatchSides::Dense(vec![ObjectSides::default(); objects])
        } else {
            BatchSides::Events(Vec::new())
        }
    }

    /// Counts one piece of evidence.
    fn count(&mut self, object: u32, kind: u8) {
        match self {
            BatchSides::Dense(table) => {
                let o = object as usize;
                if o >= table.len() {
                    table.resize(o + 1, ObjectSides::default());
                }
                table[o].count(kind);
            }
            BatchSides::Events(events) => events.push(SideEvent { object, kind }),
        }
    }

    /// Adds this evidence into per-object counters (integers: in any order).
    fn add_to(&self, into: &mut Vec<ObjectSides>) {
        match self {
            BatchSides::Dense(table) => add_sides(into, table),
            BatchSides::Events(events) => {
                for e in events {
                    let o = e.object as usize;
                    if o >= into.len() {
                        into.resize(o + 1, ObjectSides::default());
                    }
                    into[o].count(e.kind);
                }
            }
        }
    }
}

impl ObjectSides {
    /// Counts one event.
    fn count(&mut self, kind: u8) {
        match kind {
            0 => self.back_from_open += 1,
            1 => self.back_to_open += 1,
            2 => self.front_open += 1,
            _ => self.back_seen += 1,
        }
    }

    fn add(&mut self, other: &ObjectSides) {
        self.back_from_open += other.back_from_open;
        self.back_to_open += other.back_to_open;
        self.front_open += other.front_open;
        self.back_seen += other.back_seen;
    }
}

/// Adds per-object sides element by element (an empty side takes the other's length).
fn add_sides(into: &mut Vec<ObjectSides>, other: &[ObjectSides]) {
    if into.len() < other.len() {
        into.resize(other.len(), ObjectSides::default());
    }
    for (a, b) in into.iter_mut().zip(other) {
        a.add(b);
    }
}

/// What a set of lines found.
#[derive(Clone, Debug)]
pub struct Tally {
    /// The counters and sums.
    pub counters: Counters,
    /// Per object of the scene ([`crate::scene::Scene::objects`]): how its sides were met.
    pub orientation: Vec<ObjectSides>,
    /// Escapes per patch (none kept unless the discrete measures are wanted).
    pub escapes_by_patch: PatchCounts,
    /// Segments from each patch's front side to a back side (absorbed), when the discrete measures are
    /// wanted; none kept as long as there are none (most scenes have none).
    pub absorbed_by_patch: PatchCounts,
    /// Pair counts (only when the discrete measures are wanted).
    pub counts: Option<PairCounts>,
    /// Eq. (27)'s terms summed per patch (only when [`Wanted::per_patch`]).
    pub kernel_by_patch: Option<PatchKernelSums>,
}

impl Tally {
    /// An empty tally for a scene.
    pub fn empty(scene: &Scene, wanted: Wanted) -> Self {
        Tally {
            counters: Counters::default(),
            orientation: vec![ObjectSides::default(); scene.objects.len()],
            escapes_by_patch: if wanted.discrete {
                PatchCounts::zeros(scene.patch_count())
            } else {
                PatchCounts::default()
            },
            absorbed_by_patch: PatchCounts::default(),
            counts: wanted
                .discrete
                .then(|| PairCounts::new(scene.patch_count())),
            kernel_by_patch: wanted.kernel_sums(scene.patch_count()),
        }
    }

    /// A copy of everything but the pair counts.
    pub fn without_counts(&self) -> Tally {
        Tally {
            counters: self.counters,
            orientation: self.orientation.clone(),
            escapes_by_patch: self.escapes_by_patch.clone(),
            absorbed_by_patch: self.absorbed_by_patch.clone(),
            counts: None,
            kernel_by_patch: self.kernel_by_patch.clone(),
        }
    }

    /// Adds another tally of the same scene into this one.
    pub fn merge(&mut self, other: &Tally) {
        self.counters.add(&other.counters);
        add_sides(&mut self.orientation, &other.orientation);
        self.escapes_by_patch.add(&other.escapes_by_patch);
        self.absorbed_by_patch.add(&other.absorbed_by_patch);
        if let (Some(a), Some(b)) = (&mut self.counts, &other.counts) {
            a.merge(b);
        }
        // Sums of only some of the lines would be silently wrong: both or none.
        match (&mut self.kernel_by_patch, &other.kernel_by_patch) {
            (Some(a), Some(b)) => a.merge(b),
            _ => self.kernel_by_patch = None,
        }
    }

    /// The pair counts and escapes of this tally without those of `part`, a tally of some of its lines
    /// (a leave-one-group-out replicate of the delete-a-group jackknife). The counters are left as they
    /// are: only the form factors are meant to be read from the result.
    pub fn without_part(&self, part: &Tally) -> Tally {
        Tally {
            counters: self.counters,
            orientation: self.orientation.clone(),
            escapes_by_patch: self.escapes_by_patch.minus(&part.escapes_by_patch),
            absorbed_by_patch: self.absorbed_by_patch.minus(&part.absorbed_by_patch),
            counts: match (&self.counts, &part.counts) {
                (Some(t), Some(p)) => Some(t.without(p)),
                _ => None,
            },
            kernel_by_patch: None,
        }
    }

    /// Adds up batches in their order (so the f64 sums are the same whatever the threads) and counts
    /// their pairs.
    pub fn from_batches(scene: &Scene, wanted: Wanted, batches: Vec<BatchTally>) -> Tally {
        let (mut tally, keys) = Tally::sum_batches(scene, wanted, batches);
        if wanted.discrete {
            tally.counts = Some(PairCounts::from_batches(scene.patch_count(), keys));
        }
        tally
    }

    /// The tallies of groups of batches (`None` for a group without batches). Small scenes count each
    /// group on its own; the pair keys of large ones are counted in one sort of every group's keys
    /// ([`count_by_group`]), which frees them as it deals them.
    pub fn of_groups(
        scene: &Scene,
        wanted: Wanted,
        groups: Vec<Vec<BatchTally>>,
    ) -> Vec<Option<Tally>> {
        let patches = scene.patch_count();
        if !wanted.discrete || !PairCounts::counted_by_sorting(patches) {
            return groups
                .into_par_iter()
                .map(|piece| (!piece.is_empty()).then(|| Tally::from_batches(scene, wanted, piece)))
                .collect();
        }
        // The counters (and per-patch sums) first, then the keys are counted.
        type GroupKeys = Vec<(usize, Vec<u64>)>;
        let (sums, keyed): (Vec<Option<Tally>>, Vec<GroupKeys>) = groups
            .into_par_iter()
            .enumerate()
            .map(|(g, piece)| {
                if piece.is_empty() {
                    return (None, Vec::new());
                }
                let (tally, keys) = Tally::sum_batches(scene, wanted, piece);
                (Some(tally), keys.into_iter().map(|k| (g, k)).collect())
            })
            .unzip();
        // Moved, not cloned (`concat` would copy every batch's keys).
        let count = sums.len();
        let keyed: GroupKeys = keyed.into_iter().flatten().collect();
        let counted = count_by_group(patches, count, keyed);
        sums.into_iter()
            .zip(counted)
            .map(|(tally, counts)| {
                tally.map(|mut tally| {
                    tally.counts = Some(counts);
                    tally
                })
            })
            .collect()
    }

    /// Everything but the pair counts, added up in batch order; and the batches' pair keys, for the
    /// caller to count.
    fn sum_batches(
        scene: &Scene,
        wanted: Wanted,
        batches: Vec<BatchTally>,
    ) -> (Tally, Vec<Vec<u64>>) {
        let mut tally = Tally {
            counters: Counters::default(),
            orientation: vec![ObjectSides::default(); scene.objects.len()],
            escapes_by_patch: PatchCounts::default(),
            absorbed_by_patch: PatchCounts::default(),
            counts: None,
            kernel_by_patch: wanted.kernel_sums(scene.patch_count()),
        };
        let mut batch_keys = Vec::with_capacity(batches.len());
        let (mut escapes, mut absorbed) = (Vec::new(), Vec::new());
        for b in batches {
            tally.counters.add(&b.counters);
            b.sides.add_to(&mut tally.orientation);
            if let Some(k) = &mut tally.kernel_by_patch {
                k.add_pairs(&b.pair_keys, &b.pair_terms);
                k.add_escapes(&b.escape_patches, &b.escape_terms);
            }
            escapes.extend_from_slice(&b.escape_patches);
            absorbed.extend_from_slice(&b.absorbed_patches);
            batch_keys.push(b.pair_keys);
        }
        let n = scene.patch_count();
        if wanted.discrete {
            tally.escapes_by_patch = PatchCounts::of_patches(n, escapes);
        }
        if !absorbed.is_empty() {
            tally.absorbed_by_patch = PatchCounts::of_patches(n, absorbed);
        }
        (tally, batch_keys)
    }

    /// Per patch, the segments leaving its front side that arrive at no front side: its escapes and the
    /// segments absorbed at back sides. They count in the patch's row `N_i` beside its pairs, so that
    /// `F_ij = N_ij / N_i` is the geometric form factor whatever else the row loses.
    pub fn lost_by_patch(&self) -> std::borrow::Cow<'_, [u64]> {
        if self.absorbed_by_patch.is_empty() {
            return self.escapes_by_patch.dense();
        }
        let mut lost = self.escapes_by_patch.clone();
        lost.add(&self.absorbed_by_patch);
        std::borrow::Cow::Owned(lost.dense().into_owned())
    }

    /// The environment patch's area in tracing space ([`environment::area`]).
    pub fn environment_area(&self, scene: &Scene) -> f64 {
        let c = &self.counters;
        environment::area(scene.bounding_radius(), c.lines, c.escapes, c.misses)
    }

    /// The tally of the enclosed scene, whose patch `n_p` is the environment, and the patch areas with the
    /// environment's last ([`super::environment`]). Needs the discrete counts for the pair counts
    /// (without them only eq. (27) is enclosed), and the environment's per-patch sums of eq. (27)
    /// ([`Wanted::environment`]) for the enclosed per-patch sums (without them there are none).
    pub fn enclosed(&self, scene: &Scene) -> (Tally, Vec<f64>) {
        let n = scene.patch_count();
        let mut areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
        let a_scene: f64 = areas.iter().sum();
        let a_env = self.environment_area(scene);
        areas.push(a_env);

        let c = &self.counters;
        // The counts are rebuilt, not cloned: a large scene's are most of the tally.
        let mut t = Tally {
            counts: self.enclosed_counts(n),
            ..self.without_counts()
        };
        t.escapes_by_patch = if self.counts.is_some() {
            PatchCounts::zeros(n + 1)
        } else {
            PatchCounts::default()
        };
        if !t.absorbed_by_patch.is_empty() {
            let mut absorbed = Vec::new();
            self.absorbed_by_patch
                .for_each_counted(|i, k| absorbed.push((i, k)));
            t.absorbed_by_patch = PatchCounts::of_entries(n + 1, absorbed);
        }
        t.counters.pairs += c.escapes + c.misses;
        t.counters.escapes = 0;
        t.kernel_by_patch = self
            .kernel_by_patch
            .as_ref()
            .and_then(|k| k.enclosed(c.misses, scene.bounding_radius()));

        // Eq. (27) with A_T' = A_T + A_env: take the scene's log2(A_T / pi) back out of each term.
        let log2_over_pi = |a: f64| (a / std::f64::consts::PI).log2();
        let raw = c.cmi_sum.value() - c.cmi_pairs as f64 * log2_over_pi(a_scene);
        t.counters.cmi_pairs = c.cmi_pairs + c.env_pairs;
        t.counters.cmi_sum = ExactSum::of(
            raw + c.env_log2_sum.value()
                + t.counters.cmi_pairs as f64 * log2_over_pi(a_scene + a_env),
        );
        (t, areas)
    }

    /// The pair counts of the enclosed scene of `n` patches (the tally's scene), whose patch `n` is the
    /// environment ([`Tally::enclosed`]): each patch's escapes are its pairs with the environment, each
    /// line that met nothing a pair of the environment with itself. `None` without pair counts.
    pub fn enclosed_counts(&self, n: usize) -> Option<PairCounts> {
        let counts = self.counts.as_ref()?;
        let env = n as u32;
        let mut entries: Vec<(u64, u64)> = Vec::with_capacity(counts.distinct_pairs() + n + 1);
        // In pair-key order (the smaller patch first, then the larger), so that the counts are built
        // without sorting: (i, env) follows every pair (i, j) of the scene.
        let mut next_row = 0u32;
        let escapes = self.escapes_by_patch.dense();
        let mut escapes_up_to = |row: u32, entries: &mut Vec<(u64, u64)>| {
            for i in next_row..row {
                let e = escapes.get(i as usize).copied().unwrap_or(0);
                if e > 0 {
                    entries.push((pair_key(i, env), e));
                }
            }
            next_row = next_row.max(row);
        };
        counts.for_each(|i, j, k| {
            escapes_up_to(i, &mut entries);
            entries.push((pair_key(i, j), k));
        });
        escapes_up_to(env, &mut entries);
        if self.counters.misses > 0 {
            entries.push((pair_key(env, env), self.counters.misses));
        }
        debug_assert!(entries.windows(2).all(|w| w[0].0 < w[1].0));
        Some(PairCounts::from_entries(n + 1, entries))
    }

    /// Per patch of the enclosed scene of `n` patches, the segments leaving its front side that arrive
    /// at no front side: only those absorbed at back sides (the escapes are pairs with the environment,
    /// which loses nothing); empty when there are none.
    pub fn enclosed_lost(&self, n: usize) -> Vec<u64> {
        let mut lost = self.absorbed_by_patch.dense().into_owned();
        if !lost.is_empty() {
            lost.resize(n + 1, 0);
        }
        lost
    }
}

/// One batch's findings, before its pair keys become counts.
#[derive(Debug, Default)]
pub struct BatchTally {
    /// Its counters and sums.
    pub counters: Counters,
    /// The key of every visible pair ([`pair_key`]), when the discrete measures are wanted.
    pub pair_keys: Vec<u64>,
    /// The patch of every escape, when the discrete measures are wanted.
    pub escape_patches: Vec<u32>,
    /// The front patch of every segment to a back side, when the discrete measures are wanted.
    pub absorbed_patches: Vec<u32>,
    /// How the batch's lines met the objects' sides.
    pub sides: BatchSides,
    /// Beside each pair key, its log kernel ([`PatchKernelSums::pair_term`]), when
    /// [`Wanted::per_patch`].
    pub pair_terms: Vec<f64>,
    /// Beside each escape patch, the log kernel of its segment to the environment sphere, when
    /// [`Wanted::environment`].
    pub escape_terms: Vec<f64>,
}

/// Pairs the canonical hits of a batch of lines and tallies the segments (paper sec. 3.2.2): the hot
/// loop of every analysis. A run tallies many batches with one [`LineTally`] instead.
pub fn tally_lines(scene: &Scene, lines: &[Line], hits: &LineHits, wanted: Wanted) -> BatchTally {
    LineTally::new(scene, wanted).batch(lines, hits)
}

/// The tally of batches of lines through one scene ([`tally_lines`]), with what depends only on the
/// scene computed once: the eq. (27) offset log2(A_T / pi) is a sum over every patch, which would cost
/// a pass over the whole patch list per batch.
#[derive(Clone, Debug)]
pub struct LineTally<'a> {
    scene: &'a Scene,
    wanted: Wanted,
    last_cosine: LastCosine,
    log2_area_over_pi: f64,
    planes: PatchPlanes,
    objects: PatchObjects,
}

/// The object of each patch, for the orientation evidence: a room seen from inside gives two pieces of it
/// per line (it enters and leaves through back sides), and reading them from the 80-byte patch records
/// missed the cache on every line of a large mesh. A dense table of 4 bytes a patch stays in cache, and a
/// scene of one object needs none.
#[derive(Clone, Debug)]
enum PatchObjects {
    /// Every patch belongs to object 0.
    One,
    /// `objects[patch]`.
    Table(Vec<u32>),
}

impl PatchObjects {
    fn of(scene: &Scene) -> Self {
        if scene.patches.iter().all(|p| p.object == 0) {
            PatchObjects::One
        } else {
            PatchObjects::Table(scene.patches.iter().map(|p| p.object).collect())
        }
    }

    fn object(&self, patch: u32) -> u32 {
        match self {
            PatchObjects::One => 0,
            PatchObjects::Table(objects) => objects[patch as usize],
        }
    }
}

impl<'a> LineTally<'a> {
    /// Prepares the tally of lines through `scene`, gathering what `wanted` says.
    pub fn new(scene: &'a Scene, wanted: Wanted) -> Self {
        LineTally {
            scene,
            wanted,
            last_cosine: LastCosine::Own,
            log2_area_over_pi: (scene.total_area() / std::f64::consts::PI).log2(),
            planes: PatchPlanes::of(scene),
            objects: PatchObjects::of(scene),
        }
    }

    /// The same tally with eq. (27)'s sum taking `last` at the far end of each line's last pair.
    pub fn with_last_cosine(self, last: LastCosine) -> Self {
        LineTally {
            last_cosine: last,
            ..self
        }
    }

    /// Pairs the canonical hits of one batch of lines and tallies the segments.
    pub fn batch(&self, lines: &[Line], hits: &LineHits) -> BatchTally {
        tally_batch(self, lines, hits)
    }
}

fn tally_batch(prepared: &LineTally, lines: &[Line], hits: &LineHits) -> BatchTally {
    let (scene, wanted) = (prepared.scene, prepared.wanted);
    let count = lines.len();
    // About one pair per line in most scenes: one allocation instead of a dozen doublings.
    let mut keys = Vec::with_capacity(if wanted.discrete { count } else { 0 });
    let mut log2_sum = Log2Sum::default();
    let mut env_sum = Log2Sum::default();
    let mut t = BatchTally {
        counters: Counters {
            lines: count as u64,
            hits: hits.hits.len() as u64,
            ..Counters::default()
        },
        sides: BatchSides::for_objects(scene.objects.len()),
        ..BatchTally::default()
    };
    let objects = &prepared.objects;
    let (miss_cos, miss_chord) = environment::miss(scene.bounding_radius());
    let c = &mut t.counters;
    let exchange = wanted.continuous && prepared.last_cosine == LastCosine::FirstEntry;
    let mut records = Vec::new();
    prepared.planes.records_of(&hits.hits, &mut records);
    for (k, line) in lines.iter().enumerate() {
        let line_hits = hits.of_line(k);
        let line_records = if records.is_empty() {
            &[][..]
        } else {
            &records[hits.start[k] as usize..hits.start[k + 1] as usize]
        };
        if line_hits.is_empty() {
            c.misses += 1;
            env_sum.add(miss_cos, miss_chord);
            continue;
        }
        // For `LastCosine::FirstEntry`: the line's last pair so far, and its first pair's near cosine
        // and whether its kernel is usable.
        let (mut last, mut first) = (None, None);
        let sides = &mut t.sides;
        let pair_terms = &mut t.pair_terms;
        let escape_terms = &mut t.escape_terms;
        let ends = prepared.planes.segments_and_ends_of_records(
            scene,
            line,
            line_hits,
            line_records,
            |s| match s {
                Segment::Pair {
                    from,
                    to,
                    distance,
                    cos_from,
                    cos_to,
                } => {
                    c.pairs += 1;
                    c.short_chords += u64::from(SHORT_CHORD.contains(&distance));
                    if wanted.discrete {
                        keys.push(pair_key(from, to));
                    }
                    if wanted.per_patch {
                        pair_terms.push(PatchKernelSums::pair_term(cos_from * cos_to, distance));
                    }
                    if wanted.continuous {
                        if exchange {
                            // Held back until the line's last pair is known.
                            if let Some(held) = last.replace((cos_from, cos_to, distance)) {
                                c.degenerate_pairs +=
                                    u64::from(!log2_sum.add(held.0 * held.1, held.2));
                            }
                            if first.is_none() {
                                first = Some((cos_from, usable(cos_from * cos_to, distance)));
                            }
                        } else if !log2_sum.add(cos_from * cos_to, distance) {
                            c.degenerate_pairs += 1;
                        }
                    }
                }
                Segment::Escape { patch, at_start } => {
                    c.escapes += 1;
                    if wanted.discrete {
                        t.escape_patches.push(patch);
                    }
                    sides.count(objects.object(patch), 2);
                    let (cos_product, distance) = environment::escape(scene, line, patch, at_start);
                    env_sum.add(cos_product, distance);
                    if wanted.environment {
                        escape_terms.push(PatchKernelSums::pair_term(cos_product, distance));
                    }
                }
                Segment::BackSeen { patch, front } => {
                    c.unpaired += 1;
                    c.absorbed += 1;
                    if wanted.discrete {
                        t.absorbed_patches.push(front);
                    }
                    sides.count(objects.object(patch), 3);
                }
                Segment::Unpaired => c.unpaired += 1,
            },
        );
        if let (Some(held), Some(first)) = (last, first) {
            c.degenerate_pairs += u64::from(!add_last_pair(&mut log2_sum, held, first));
        }
        if let Some(p) = ends.back_first {
            t.sides.count(objects.object(p), 0);
        }
        if let Some(p) = ends.back_last {
            t.sides.count(objects.object(p), 1);
        }
        c.coincident_crossings += ends.overlaps;
    }
    let (cmi_sum, cmi_pairs) = log2_sum.finish(prepared.log2_area_over_pi);
    let (env_sum, env_pairs) = env_sum.finish(0.0);
    (c.cmi_sum, c.cmi_pairs) = (ExactSum::of(cmi_sum), cmi_pairs);
    (c.env_log2_sum, c.env_pairs) = (ExactSum::of(env_sum), env_pairs);
    t.pair_keys = keys;
    t
}

/// Whether a pair's kernel (cosine product, distance) is usable in eq. (27)'s sum, not degenerate.
fn usable(cos_product: f64, distance: f64) -> bool {
    super::kernel::kernel_without_pi(cos_product, distance).is_some()
}

/// Adds a line's last pair `(cos_from, cos_to, distance)` to eq. (27)'s sum with the near cosine of the
/// line's first pair in place of its own far one ([`LastCosine::FirstEntry`]); `first` is that cosine
/// and whether the first pair's kernel is usable. With its own cosine when either pair is degenerate, so
/// that the exchange is made on a set of lines that reversal maps onto itself. Returns false, adding
/// nothing, for a degenerate last pair (counted as such whatever the estimator).
fn add_last_pair(
    sum: &mut Log2Sum,
    (cos_from, cos_to, distance): (f64, f64, f64),
    (first_cos, first_usable): (f64, bool),
) -> bool {
    let exchanged = cos_from * first_cos;
    if first_usable && usable(cos_from * cos_to, distance) && usable(exchanged, distance) {
        sum.add(exchanged, distance)
    } else {
        sum.add(cos_from * cos_to, distance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first pair's near cosine in place of the last pair's far one changes eq. (27)'s sum by
    /// nothing on average over uniformly distributed lines, whatever the scene: in a room with blocks
    /// (lines of up to 6 pairs) the batches' mean change is within 4.5 of its standard errors of 0,
    /// though single batches change; and every count, degenerate pairs included, is the same.
    #[test]
    fn the_first_entry_stands_for_the_last_exit_without_bias() {
        use crate::trace::Tracer;
        let scene = crate::scenes::load("@cornell").unwrap();
        let tracer = crate::trace::rust::BvhTracer::new(&scene).unwrap();
        let wanted = Wanted {
            discrete: false,
            continuous: true,
            per_patch: false,
            environment: false,
        };
        let own = LineTally::new(&scene, wanted);
        let exchanged = LineTally::new(&scene, wanted).with_last_cosine(LastCosine::FirstEntry);
        let (mut changes, mut several, mut paired) = (Vec::new(), 0, 0);
        for batch in 0..64 {
            let mut lines = Vec::new();
            super::super::lines::batch_lines(3, batch, 4096, scene.bounding_radius(), &mut lines);
            let mut hits = LineHits::default();
            tracer.all_hits(&lines, &mut Vec::new(), &mut hits).unwrap();
            let (a, b) = (own.batch(&lines, &hits), exchanged.batch(&lines, &hits));
            let (a, b) = (a.counters, b.counters);
            assert_eq!(
                (a.pairs, a.cmi_pairs, a.degenerate_pairs),
                (b.pairs, b.cmi_pairs, b.degenerate_pairs)
            );
            assert_eq!(a.env_log2_sum, b.env_log2_sum);
            changes.push((b.cmi_sum.value() - a.cmi_sum.value()) / a.cmi_pairs as f64);
            for k in 0..lines.len() {
                let crossings = hits.of_line(k).len();
                paired += usize::from(crossings >= 2);
                several += usize::from(crossings >= 4);
            }
        }
        // Lines of several pairs are common: the exchange is not only a convex solid's.
        assert!(several * 10 > paired, "{several} of {paired}");
        let n = changes.len() as f64;
        let mean = changes.iter().sum::<f64>() / n;
        let sd = (changes.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        assert!(sd > 1e-4, "the exchange changed nothing: {sd}");
        assert!(
            mean.abs() < 4.5 * sd / n.sqrt(),
            "mean change {mean}, sd {sd}"
        );
    }

    /// On a line of one pair the exchange makes its term log2(A_T cos_near^2 / (pi d^2)).
    #[test]
    fn a_single_pair_takes_its_near_cosine_twice() {
        let mut a = Log2Sum::default();
        assert!(add_last_pair(&mut a, (0.5, 0.25, 2.0), (0.5, true)));
        let mut b = Log2Sum::default();
        assert!(b.add(0.25, 2.0));
        assert_eq!(a.finish(0.0), b.finish(0.0));
        // A degenerate first pair leaves the last its own cosine; a degenerate last is not added.
        let mut c = Log2Sum::default();
        assert!(add_last_pair(&mut c, (0.5, 0.25, 2.0), (0.9, false)));
        assert_eq!(c.finish(0.0), (-5.0, 1));
        let mut d = Log2Sum::default();
        assert!(!add_last_pair(&mut d, (0.5, 0.25, 0.0), (0.5, true)));
        assert_eq!(d.finish(0.0).1, 0);
    }

    /// The per-object table and the event list count the same evidence: every event lands in its own
    /// object's counter, whichever form a batch keeps, and objects beyond the table's length extend it.
    #[test]
    fn side_tables_and_event_lists_count_the_same() {
        assert!(matches!(
            BatchSides::for_objects(DENSE_SIDE_OBJECTS),
            BatchSides::Dense(_)
        ));
        assert!(matches!(
            BatchSides::for_objects(DENSE_SIDE_OBJECTS + 1),
            BatchSides::Events(_)
        ));
        let events: Vec<(u32, u8)> = (0..1000u32)
            .map(|k| ((k * 7) % 13, (k % 4) as u8))
            .collect();
        let mut expected = vec![ObjectSides::default(); 13];
        for &(o, kind) in &events {
            let s = &mut expected[o as usize];
            match kind {
                0 => s.back_from_open += 1,
                1 => s.back_to_open += 1,
                2 => s.front_open += 1,
                _ => s.back_seen += 1,
            }
        }
        for mut sides in [
            BatchSides::for_objects(13),
            BatchSides::for_objects(2),
            BatchSides::Events(Vec::new()),
        ] {
            for &(o, kind) in &events {
                sides.count(o, kind);
            }
            let mut into = Vec::new();
            sides.add_to(&mut into);
            assert_eq!(into, expected, "{sides:?}");
        }
    }
}
