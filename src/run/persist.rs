//! Saved run states (`scx analyze --save/--checkpoint`, `scx merge`, `--resume`): everything needed to
//! report a run or to continue it, in a versioned, checksummed file.
//!
//! Layout: the 8 bytes `SCXSTATE`, the format version (u32, little-endian), the payload's length (u64)
//! and its CRC-32 (u32), then the payload: one CBOR (RFC 8949) document, so that integers are stored as
//! integers in their shortest form and the file can be read from other languages (Python's `cbor2`).
//! The payload holds the run's identity ([`RunIdentity`]: scene fingerprint, scx version, seed, line
//! source, tracer, groups, estimator, ...), its batch plan, the batches done, and each group's tally: its
//! counters, and its escapes and pair counts as sparse lists whose sorted keys are stored as differences
//! (mostly one or two bytes each); and, when the run was asked for per-patch results (`--patches`), its
//! per-patch sums of eq. (27) ([`PatchKernelSums`]), without which a resumed or merged run could not
//! share I_s^c out among the patches, and with `--enclose` the sums of each patch's escapes, without
//! which the enclosed scene's I_s^c could not be. States written before those sums were kept load as
//! states without them (an enclosed one without the escapes' sums as one without any per-patch sums).
//!
//! Files are written atomically (a temporary file beside the target, synced, then renamed over it), so a
//! run killed while saving leaves the previous state intact ([`super::files`]). A state goes only to a
//! regular file (or through a symbolic link to one): never into a device or FIFO, never renamed over
//! one.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::cast::Shard;
use super::consistency;
use super::files::{self, Destination, DestinationError};
use super::plan::BatchPlan;
use super::spec::{RunSpec, SpecDifference};
use super::state::RunState;
use crate::sample::counts::{pair_key, split_key, PairCounts};
use crate::sample::exact::ExactSum;
use crate::sample::kernel_sums::PatchKernelSums;
use crate::sample::patch_counts::PatchCounts;
use crate::sample::tally::{Counters, ObjectSides, Tally, Wanted};
use crate::scene::read as scene_read;
use crate::scene::{Scene, SceneOptions};
use crate::trace::{Backend, Query};

/// The format version this scx writes and reads. Format 1 (before the run's spec was stored typed) is
/// refused with a message saying so.
pub const FORMAT_VERSION: u32 = 2;

const MAGIC: &[u8; 8] = b"SCXSTATE";
const HEADER: usize = 8 + 4 + 8 + 4;

/// The scene a saved run is of: as named, as read, and its fingerprint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneRef {
    /// The scene as named on the command line (a file path or a built-in).
    pub name: String,
    /// How the scene file was read (planarity, flipped and two-sided objects), so that a resume or a
    /// merge reads it the same way.
    pub reading: SceneOptions,
    /// [`crate::scene::Scene::fingerprint`] of the loaded scene.
    pub fingerprint: String,
    /// Its patches.
    pub patches: u64,
}

impl SceneRef {
    /// The scene `scene`, named `name` and read with `reading`.
    pub fn of(name: &str, reading: &SceneOptions, scene: &Scene) -> Self {
        SceneRef {
            name: name.into(),
            reading: reading.clone(),
            fingerprint: scene.fingerprint(),
            patches: scene.patch_count() as u64,
        }
    }
}

/// How a run's lines were traced. Not part of what the run is ([`RunSpec`]): both tracers give the same
/// hits by design, so parts of one run may be traced by either.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Tracing {
    /// The backend.
    pub backend: Backend,
    /// Its ray query.
    pub query: Query,
}

/// What a saved state is of: the scx that wrote it, the scene, the run's spec, its shard, and how its
/// lines were traced. Two states can be merged, or one resumed, only when these agree
/// ([`RunIdentity::difference`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunIdentity {
    /// The scx version that wrote the state.
    pub scx_version: String,
    /// The scene.
    pub scene: SceneRef,
    /// What the run is.
    pub spec: RunSpec,
    /// The shard, when the run was one.
    pub shard: Option<Shard>,
    /// How its lines were traced.
    pub tracing: Tracing,
}

impl RunIdentity {
    /// The identity of a run of `spec` on `scene`, traced with `tracing`, as shard `shard` when it is
    /// one, written by this scx.
    pub fn new(scene: SceneRef, spec: RunSpec, shard: Option<Shard>, tracing: Tracing) -> Self {
        RunIdentity {
            scx_version: env!("CARGO_PKG_VERSION").into(),
            scene,
            spec,
            shard,
            tracing,
        }
    }

    /// Whether this scx may continue the run: only the version that started it may, since another
    /// version's lines or estimates may differ, and a run continued by it would mix the two without a
    /// word (its results then those of neither). The problem in words otherwise.
    pub fn continuable_here(&self) -> Result<(), String> {
        let here = env!("CARGO_PKG_VERSION");
        if self.scx_version == here {
            return Ok(());
        }
        // A forged state's version may be any text: a bounded, printable excerpt.
        let theirs: String = self
            .scx_version
            .chars()
            .take(40)
            .map(|c| if c.is_control() { '?' } else { c })
            .collect();
        Err(format!(
            "the run was started by scx {theirs}, and this is scx {here}, whose lines or estimates \
             may differ: continue it with scx {theirs}, or start it again (`scx merge` still reports \
             it)"
        ))
    }

    /// The first setting in which two runs differ that must agree for them to be parts of one run:
    /// the scx version, the scene, the spec ([`RunSpec::difference`]; the line counts only unless
    /// `lines_may_differ`) and the shard count.
    pub fn difference(
        &self,
        other: &RunIdentity,
        lines_may_differ: bool,
    ) -> Option<SpecDifference> {
        let differ = |setting: &str, ours: String, theirs: String| {
            (ours != theirs).then(|| SpecDifference {
                setting: setting.into(),
                ours,
                theirs,
            })
        };
        // Only the count must agree: each part is another shard of it.
        let shards = |s: &RunIdentity| {
            s.shard
                .map_or("not sharded".into(), |s| format!("{} shards", s.count))
        };
        // Enough of the fingerprint to tell scenes apart, by chars: a forged state's may be any text.
        let scene = |s: &RunIdentity| {
            let print: String = s.scene.fingerprint.chars().take(12).collect();
            format!("{} (fingerprint {print})", s.scene.name)
        };
        differ(
            "scx version",
            self.scx_version.clone(),
            other.scx_version.clone(),
        )
        .or_else(|| {
            (self.scene.fingerprint != other.scene.fingerprint).then(|| SpecDifference {
                setting: "scene fingerprint".into(),
                ours: scene(self),
                theirs: scene(other),
            })
        })
        .or_else(|| {
            differ(
                "patches",
                self.scene.patches.to_string(),
                other.scene.patches.to_string(),
            )
        })
        .or_else(|| self.spec.difference(&other.spec, lines_may_differ))
        .or_else(|| differ("shard count", shards(self), shards(other)))
    }
}

/// A saved run: what it is, and how far it got.
#[derive(Clone, Debug)]
pub struct SavedRun {
    /// The run's identity.
    pub identity: RunIdentity,
    /// Its state.
    pub state: RunState,
    /// Seconds spent on it so far (summed over resumes and, once merged, over shards).
    pub seconds: f64,
}

/// Why a state file could not be saved or loaded.
#[derive(Debug, thiserror::Error)]
pub enum PersistError {
    /// The file system refused.
    #[error("cannot {doing} {path}: {source}")]
    Io {
        /// What was being done (`read`, `write`).
        doing: &'static str,
        /// The file.
        path: String,
        /// The system's reason.
        source: std::io::Error,
    },
    /// The whole state was written to a temporary beside the file, but it could not be renamed into
    /// place: the temporary is kept.
    #[error("cannot write {path}: {source}; the state is kept whole in {kept}")]
    Kept {
        /// The file.
        path: String,
        /// The temporary holding the state.
        kept: String,
        /// The system's reason.
        source: std::io::Error,
    },
    /// The path cannot take a state: a directory, a device, a FIFO.
    #[error("cannot save a run state to {path}: {problem}")]
    NotAFile {
        /// The file.
        path: String,
        /// What it is.
        problem: String,
    },
    /// The file is not a state file, or is damaged.
    #[error("{path}: {problem}")]
    Bad {
        /// The file.
        path: String,
        /// What is wrong with it.
        problem: String,
    },
}

impl PersistError {
    /// Whether the file's contents are at fault (not the file system).
    pub fn is_bad_input(&self) -> bool {
        matches!(
            self,
            PersistError::Bad { .. } | PersistError::NotAFile { .. }
        )
    }
}

#[derive(Serialize, Deserialize)]
struct Wire {
    identity: RunIdentity,
    plan_lines: u64,
    batch_size: u64,
    discrete: bool,
    continuous: bool,
    /// Whether the tallies hold the per-patch sums of eq. (27) (absent from the states of scx before
    /// they were kept: those have none).
    #[serde(default)]
    per_patch: bool,
    /// Whether the per-patch sums hold the escapes' terms too (`--enclose`; absent, and then false,
    /// from the states of scx before they were kept and from the states of runs not enclosed, which
    /// are written as before).
    #[serde(default, skip_serializing_if = "is_false")]
    per_patch_environment: bool,
    done: Vec<[u64; 2]>,
    groups: Vec<Option<TallyWire>>,
    tail: Option<(u64, TallyWire)>,
    seconds: f64,
}

#[derive(Serialize, Deserialize)]
struct TallyWire {
    counters: Counters,
    /// Non-zero escapes per patch.
    escapes: Sparse,
    /// Non-zero segments to back sides per front patch.
    absorbed: Sparse,
    /// Pair counts by pair key.
    counts: Option<Sparse>,
    /// Per object: back sides met from open space, back sides leaving to it, front sides escaping,
    /// back sides seen from front sides.
    #[serde(default)]
    orientation: Vec<[u64; 4]>,
    /// Per patch, the sum of eq. (27)'s log kernel over its pair ends and how many ends, when the run
    /// gathers them ([`Wanted::per_patch`]). The sums are stored as their fixed-point integers, so a
    /// state read back, resumed or merged adds up to the same bits as the run cast at once.
    #[serde(default)]
    kernel_by_patch: Option<KernelWire>,
}

/// [`PatchKernelSums`] as stored: one entry per patch in each list. Dense, not sparse: in any run
/// long enough to be worth a per-patch table every patch of a group has pair ends, and a patch without
/// any costs two bytes. The escapes' lists are absent when not gathered.
#[derive(Serialize, Deserialize)]
struct KernelWire {
    log2_kernel: Vec<ExactSum>,
    ends: Vec<u64>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    environment_log2_kernel: Vec<ExactSum>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    environment_ends: Vec<u64>,
}

fn is_false(b: &bool) -> bool {
    !*b
}

/// Sorted `(key, value)` entries as key differences and values.
#[derive(Serialize, Deserialize)]
struct Sparse {
    key_steps: Vec<u64>,
    values: Vec<u64>,
}

impl Sparse {
    /// The non-zero entries of counts per patch.
    fn of_counts(per_patch: &PatchCounts) -> Self {
        let mut entries = Vec::new();
        per_patch.for_each_counted(|i, e| entries.push((u64::from(i), e)));
        Sparse::of(entries)
    }

    fn of(entries: impl IntoIterator<Item = (u64, u64)>) -> Self {
        let (mut key_steps, mut values, mut last) = (Vec::new(), Vec::new(), 0u64);
        for (k, v) in entries {
            key_steps.push(k - last);
            values.push(v);
            last = k;
        }
        Sparse { key_steps, values }
    }

    /// The entries, or none when the keys are not strictly increasing (a key stored twice would be
    /// counted twice: a forged or damaged state).
    fn entries(&self) -> Option<Vec<(u64, u64)>> {
        if self.key_steps.len() != self.values.len() {
            return None;
        }
        let mut key = 0u64;
        self.key_steps
            .iter()
            .zip(&self.values)
            .enumerate()
            .map(|(k, (&step, &v))| {
                if k > 0 && step == 0 {
                    return None;
                }
                key = key.checked_add(step)?;
                Some((key, v))
            })
            .collect()
    }
}

fn tally_wire(t: &Tally) -> TallyWire {
    TallyWire {
        counters: t.counters,
        escapes: Sparse::of_counts(&t.escapes_by_patch),
        absorbed: Sparse::of_counts(&t.absorbed_by_patch),
        counts: t.counts.as_ref().map(|c| {
            let mut entries = Vec::with_capacity(c.distinct_pairs());
            c.for_each(|i, j, n| entries.push((pair_key(i, j), n)));
            Sparse::of(entries)
        }),
        orientation: t
            .orientation
            .iter()
            .map(|o| [o.back_from_open, o.back_to_open, o.front_open, o.back_seen])
            .collect(),
        kernel_by_patch: t.kernel_by_patch.as_ref().map(|k| KernelWire {
            log2_kernel: k.log2_kernel.clone(),
            ends: k.ends.clone(),
            environment_log2_kernel: k.environment_log2_kernel.clone(),
            environment_ends: k.environment_ends.clone(),
        }),
    }
}

/// Counts per patch from sparse entries (sorted, distinct), each within the scene's patches.
fn per_patch(entries: &[(u64, u64)], patches: usize, what: &str) -> Result<PatchCounts, String> {
    if let Some(&(i, _)) = entries.iter().find(|&&(i, _)| i >= patches as u64) {
        return Err(format!(
            "{what} of patch {i}, beyond the scene's {patches} patches"
        ));
    }
    // Below the patch count, which fits a u32 (a scene's patches are numbered by u32).
    let entries = entries.iter().map(|&(i, e)| (i as u32, e));
    Ok(PatchCounts::of_entries(patches, entries))
}

/// The sorted, unique entries of a sparse list, refused by name when they are not.
fn entries_of(sparse: &Sparse, what: &str) -> Result<Vec<(u64, u64)>, String> {
    sparse
        .entries()
        .ok_or_else(|| format!("its {what} are not a sorted list of distinct keys"))
}

/// The sum of the values of some entries, which must equal a counter of the same tally.
fn check_sum(entries: &[(u64, u64)], counter: u64, what: &str) -> Result<(), String> {
    let sum = entries.iter().map(|&(_, v)| u128::from(v)).sum::<u128>();
    if sum != u128::from(counter) {
        return Err(format!(
            "its {what} add up to {sum}, its counter says {counter}"
        ));
    }
    Ok(())
}

/// A group's (or the partial last batch's) tally from its stored form, checked against the scene and
/// against `lines`, the lines its batches hold.
fn tally_of(w: &TallyWire, scene: &SceneSize, wanted: Wanted, lines: u64) -> Result<Tally, String> {
    let patches = scene.patches;
    consistency::check_counters(&w.counters, lines, scene.triangles)?;
    let escapes = entries_of(&w.escapes, "escapes")?;
    let absorbed = entries_of(&w.absorbed, "absorbed segments")?;
    let escapes_by_patch = if wanted.discrete {
        check_sum(&escapes, w.counters.escapes, "escapes per patch")?;
        per_patch(&escapes, patches, "escapes")?
    } else if escapes.is_empty() {
        PatchCounts::default()
    } else {
        return Err("it lists escapes per patch for a run that keeps none".into());
    };
    let absorbed_by_patch = if absorbed.is_empty() {
        PatchCounts::default()
    } else {
        check_sum(
            &absorbed,
            w.counters.absorbed,
            "absorbed segments per patch",
        )?;
        per_patch(&absorbed, patches, "absorbed segments")?
    };
    if wanted.discrete && absorbed.is_empty() && w.counters.absorbed > 0 {
        return Err(format!(
            "it counts {} absorbed segments and lists none per patch",
            w.counters.absorbed
        ));
    }
    let counts = match (&w.counts, wanted.discrete) {
        (Some(c), true) => {
            let entries = entries_of(c, "pair counts")?;
            if let Some(&(k, _)) = entries.iter().find(|&&(k, _)| {
                let (i, j) = split_key(k);
                (j as usize) >= patches || i > j
            }) {
                let (i, j) = split_key(k);
                return Err(format!(
                    "a pair count of patches {i} and {j}, not a pair of the scene's {patches} patches"
                ));
            }
            check_sum(&entries, w.counters.pairs, "pair counts")?;
            Some(PairCounts::from_entries(patches, entries))
        }
        (None, false) => None,
        (None, true) => return Err("a group without the pair counts its run keeps".into()),
        (Some(_), false) => return Err("pair counts in a run that keeps none".into()),
    };
    if !w.orientation.is_empty() && w.orientation.len() != scene.objects {
        return Err(format!(
            "side counts for {} objects, the scene has {}",
            w.orientation.len(),
            scene.objects
        ));
    }
    let orientation = w
        .orientation
        .iter()
        .map(
            |&[back_from_open, back_to_open, front_open, back_seen]| ObjectSides {
                back_from_open,
                back_to_open,
                front_open,
                back_seen,
            },
        )
        .collect();
    // Sums for a run that gathers none, or none for one that does, would make the state's groups
    // disagree on what they hold.
    let kernel_by_patch = match (&w.kernel_by_patch, wanted.per_patch) {
        (Some(k), true) => {
            if k.log2_kernel.len() != patches || k.ends.len() != patches {
                return Err(format!(
                    "per-patch sums of eq. (27) for {} patches, the scene has {patches}",
                    k.log2_kernel.len().max(k.ends.len())
                ));
            }
            let ends = k.ends.iter().map(|&e| u128::from(e)).sum::<u128>();
            if ends > 2 * u128::from(w.counters.pairs) {
                return Err(format!(
                    "per-patch sums of eq. (27) over {ends} pair ends, more than its {} pairs have",
                    w.counters.pairs
                ));
            }
            consistency::check_kernel_sums(&k.log2_kernel, &k.ends, "per-patch sums of eq. (27)")?;
            let sums = PatchKernelSums {
                log2_kernel: k.log2_kernel.clone(),
                ends: k.ends.clone(),
                environment_log2_kernel: k.environment_log2_kernel.clone(),
                environment_ends: k.environment_ends.clone(),
            };
            check_environment_sums(&sums, w, &escapes_by_patch.dense(), wanted)?;
            Some(sums)
        }
        (None, false) => None,
        (None, true) => {
            return Err("a group without the per-patch sums of eq. (27) its run keeps".into())
        }
        (Some(_), false) => {
            return Err("per-patch sums of eq. (27) in a run that keeps none".into())
        }
    };
    Ok(Tally {
        counters: w.counters,
        orientation,
        escapes_by_patch,
        absorbed_by_patch,
        counts,
        kernel_by_patch,
    })
}

/// The escapes' per-patch sums of a tally ([`PatchKernelSums::environment_log2_kernel`]): present, one
/// entry per patch, exactly when the run gathers them; no patch with more of them than its escapes; and
/// as many in all as the escapes that entered the environment's sum of eq. (27) (every segment to the
/// environment that is no miss).
fn check_environment_sums(
    k: &PatchKernelSums,
    w: &TallyWire,
    escapes_by_patch: &[u64],
    wanted: Wanted,
) -> Result<(), String> {
    let listed = !k.environment_log2_kernel.is_empty() || !k.environment_ends.is_empty();
    if !wanted.environment {
        return match listed {
            true => Err("per-patch sums of escapes in a run that keeps none".into()),
            false => Ok(()),
        };
    }
    let patches = escapes_by_patch.len();
    if k.environment_log2_kernel.len() != patches || k.environment_ends.len() != patches {
        return Err(format!(
            "per-patch sums of escapes for {} patches, the scene has {patches}",
            k.environment_log2_kernel
                .len()
                .max(k.environment_ends.len())
        ));
    }
    if let Some(i) = (0..patches).find(|&i| k.environment_ends[i] > escapes_by_patch[i]) {
        return Err(format!(
            "per-patch sums of escapes over {} escapes of patch {i}, which has {}",
            k.environment_ends[i], escapes_by_patch[i]
        ));
    }
    let ends = k
        .environment_ends
        .iter()
        .map(|&e| u128::from(e))
        .sum::<u128>();
    let c = &w.counters;
    if ends + u128::from(c.misses) != u128::from(c.env_pairs) {
        return Err(format!(
            "per-patch sums of escapes over {ends} escapes, where {} segments to the environment \
             and {} misses leave {} escapes",
            c.env_pairs,
            c.misses,
            i128::from(c.env_pairs) - i128::from(c.misses)
        ));
    }
    consistency::check_kernel_sums(
        &k.environment_log2_kernel,
        &k.environment_ends,
        "per-patch sums of escapes",
    )
}

/// What a state is checked against in its scene.
struct SceneSize {
    patches: usize,
    triangles: u64,
    objects: usize,
}

impl SceneSize {
    fn of(scene: &Scene) -> Self {
        SceneSize {
            patches: scene.patch_count(),
            triangles: scene.triangles.len() as u64,
            objects: scene.objects.len(),
        }
    }
}

/// The bytes of the state file of a run that took `seconds` so far.
pub fn encode(identity: &RunIdentity, state: &RunState, seconds: f64) -> Vec<u8> {
    let parts = state.parts();
    let wire = Wire {
        identity: identity.clone(),
        plan_lines: parts.plan.lines,
        batch_size: parts.plan.batch_size,
        discrete: parts.wanted.discrete,
        continuous: parts.wanted.continuous,
        per_patch: parts.wanted.per_patch,
        per_patch_environment: parts.wanted.environment,
        done: parts
            .done
            .ranges()
            .iter()
            .map(|r| [r.start, r.end])
            .collect(),
        groups: parts
            .groups
            .iter()
            .map(|g| g.as_ref().map(tally_wire))
            .collect(),
        tail: parts.tail.map(|(b, t)| (*b, tally_wire(t))),
        seconds,
    };
    let mut payload = Vec::new();
    ciborium::into_writer(&wire, &mut payload).expect("writing CBOR to memory");
    let mut out = Vec::with_capacity(HEADER + payload.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    out.extend_from_slice(&payload);
    out
}

/// A state file read and checked for form (its header, length, checksum and encoding) but not yet for
/// meaning: what it is of ([`StateFile::identity`]) can be looked at before the scene it names is loaded,
/// and its tallies are built only against that scene ([`StateFile::into_run`]), so that a state cannot
/// make scx allocate for more patches than the scene has.
pub struct StateFile {
    path: String,
    wire: Wire,
}

impl std::fmt::Debug for StateFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StateFile")
            .field("path", &self.path)
            .field("identity", &self.wire.identity)
            .finish_non_exhaustive()
    }
}

impl StateFile {
    /// What the saved run is of.
    pub fn identity(&self) -> &RunIdentity {
        &self.wire.identity
    }

    /// The file, as named when it was read.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// Seconds spent on the run so far.
    pub fn seconds(&self) -> f64 {
        self.wire.seconds
    }

    /// The saved run, once the state is found to be of `scene` (its fingerprint) and consistent with it
    /// and with itself: keys sorted and unique, patch indices within the scene's, each group holding the
    /// lines of its batches, counts adding up to their counters ([`PersistError::Bad`] naming the first
    /// problem otherwise).
    pub fn into_run(self, scene: &Scene) -> Result<SavedRun, PersistError> {
        let saved = &self.wire.identity.scene.fingerprint;
        let fingerprint = scene.fingerprint();
        if saved != &fingerprint {
            let problem = format!(
                "the state is of another scene than {} (fingerprint {} against {})",
                scene.name,
                saved.get(..12).unwrap_or(saved),
                &fingerprint[..12]
            );
            return Err(PersistError::Bad {
                path: self.path,
                problem,
            });
        }
        self.into_run_of_any_scene(scene)
    }

    /// [`StateFile::into_run`] without the fingerprint check: the state checked against `scene`'s size
    /// only (for fuzzing the checks with states whose scene is not at hand).
    #[doc(hidden)]
    pub fn into_run_of_any_scene(self, scene: &Scene) -> Result<SavedRun, PersistError> {
        let StateFile { path, wire } = self;
        state_of(wire, &SceneSize::of(scene)).map_err(|problem| PersistError::Bad {
            path,
            problem: format!("inconsistent contents: {problem}"),
        })
    }
}

/// A state file from its bytes, checked for form; `path` names it in messages.
pub fn decode(path: &str, bytes: &[u8]) -> Result<StateFile, PersistError> {
    let bad = |problem: String| PersistError::Bad {
        path: path.to_string(),
        problem,
    };
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        return Err(bad(
            "not an scx run state (it does not start with SCXSTATE)".into(),
        ));
    }
    if bytes.len() < HEADER {
        return Err(bad(format!(
            "truncated: {} bytes, shorter than a run state's {HEADER}-byte header",
            bytes.len()
        )));
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if version != FORMAT_VERSION {
        let hint = if version < FORMAT_VERSION {
            ": it was written by an earlier scx; finish the run with that scx, or start it again"
        } else {
            ": it was written by a later scx"
        };
        return Err(bad(format!(
            "written in run-state format {version}; this scx reads format {FORMAT_VERSION}{hint}"
        )));
    }
    let length = u64::from_le_bytes(bytes[12..20].try_into().expect("8 bytes"));
    let crc = u32::from_le_bytes(bytes[20..24].try_into().expect("4 bytes"));
    let payload = &bytes[HEADER..];
    if payload.len() as u64 != length {
        return Err(bad(format!(
            "truncated or extended: the header announces {length} bytes of state, the file holds {}",
            payload.len()
        )));
    }
    if crc32fast::hash(payload) != crc {
        return Err(bad(
            "corrupted: its checksum does not match its contents (a damaged or edited file)".into(),
        ));
    }
    let wire: Wire = ciborium::from_reader(payload).map_err(|e| {
        bad(format!(
            "cannot be read as a run state: {}",
            cbor_problem(&e)
        ))
    })?;
    Ok(StateFile {
        path: path.to_string(),
        wire,
    })
}

/// Why a state's CBOR did not decode, in words: ciborium's own text is its debug form
/// (`Syntax(141)`). Offsets are counted in the file, header included.
fn cbor_problem(e: &ciborium::de::Error<std::io::Error>) -> String {
    use ciborium::de::Error;
    let in_file = |at: usize| at + HEADER;
    match e {
        Error::Syntax(at) => format!(
            "its contents are not well-formed CBOR (a malformed item at byte {})",
            in_file(*at)
        ),
        Error::Semantic(Some(at), what) => format!(
            "its contents are not those of a run state: {what} (in the item at byte {})",
            in_file(*at)
        ),
        Error::Semantic(None, what) => {
            format!("its contents are not those of a run state: {what}")
        }
        Error::Io(_) => "its contents end in the middle of an item".into(),
        Error::RecursionLimitExceeded => "its contents nest deeper than any run state does".into(),
    }
}

/// The run a decoded state holds, checked for meaning against the scene's size.
fn state_of(w: Wire, scene: &SceneSize) -> Result<SavedRun, String> {
    let spec = &w.identity.spec;
    let plan = BatchPlan {
        lines: w.plan_lines,
        batch_size: w.batch_size,
    };
    if plan != spec.plan() {
        return Err(format!(
            "its plan of {} lines in batches of {} is not that of its run of {} lines",
            plan.lines, plan.batch_size, spec.lines
        ));
    }
    if w.groups.len() != spec.group_count() {
        return Err(format!(
            "{} groups, where its run has {}",
            w.groups.len(),
            spec.group_count()
        ));
    }
    // The per-patch sums need the pair keys (the discrete counts) to be gathered at all.
    if w.per_patch && !w.discrete {
        return Err("per-patch sums without the pair counts they need".into());
    }
    if w.identity.scene.patches != scene.patches as u64 {
        return Err(format!(
            "it says its scene has {} patches, the scene has {}",
            w.identity.scene.patches, scene.patches
        ));
    }
    if w.per_patch_environment && !(w.per_patch && spec.enclose) {
        return Err(
            "per-patch sums of escapes in a run without per-patch sums or --enclose".into(),
        );
    }
    let wanted = Wanted {
        discrete: w.discrete,
        continuous: w.continuous,
        per_patch: w.per_patch,
        environment: w.per_patch_environment,
    };
    // An enclosed run's state written before the escapes' sums were kept: its per-patch sums cannot
    // give the enclosed scene's per-patch I_s^c, so it is read as a state without any.
    let lacks_environment = spec.enclose && w.per_patch && !w.per_patch_environment;
    let done = consistency::done_batches(&w.done, plan)?;
    let lines = consistency::group_lines(plan, &done, w.groups.len());
    let groups = w
        .groups
        .iter()
        .zip(&lines)
        .enumerate()
        .map(|(g, (t, &lines))| match t {
            Some(t) => tally_of(t, scene, wanted, lines)
                .map(Some)
                .map_err(|e| format!("group {g}: {e}")),
            None if lines == 0 => Ok(None),
            None => Err(format!(
                "group {g} is empty, though its batches hold {lines} lines"
            )),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let partial = consistency::partial_batch(plan).filter(|&b| done.contains(b));
    let tail = match (&w.tail, partial) {
        (Some((b, t)), Some(last)) if *b == last => {
            let lines = plan.batch_len(last) as u64;
            let tally =
                tally_of(t, scene, wanted, lines).map_err(|e| format!("last batch: {e}"))?;
            Some((*b, tally))
        }
        (None, None) => None,
        (Some((b, _)), _) => {
            return Err(format!(
                "a partial last batch {b} that is not its run's, or not done"
            ))
        }
        (None, Some(b)) => return Err(format!("its partial last batch {b} is done but not kept")),
    };
    let mut state = RunState::from_parts(plan, wanted, groups, done, tail);
    if lacks_environment {
        state.drop_per_patch();
    }
    Ok(SavedRun {
        identity: w.identity,
        state,
        seconds: w.seconds,
    })
}

/// Writes the state file of a run that took `seconds` so far, atomically: a temporary file beside
/// `path`, synced, renamed over it.
pub fn save(
    path: &Path,
    identity: &RunIdentity,
    state: &RunState,
    seconds: f64,
) -> Result<(), PersistError> {
    save_bytes(path, &encode(identity, state, seconds))
}

/// Where a state for `path` is written: a regular file (the path, or the target of the symbolic link
/// it is); anything else is refused with a sentence.
pub fn state_destination(path: &Path) -> Result<std::path::PathBuf, PersistError> {
    let refuse = |problem: String| PersistError::NotAFile {
        path: path.display().to_string(),
        problem,
    };
    match files::destination(path) {
        Ok(Destination::File(real)) => Ok(real),
        Ok(Destination::Stream(_)) => Err(refuse(
            "it is not a regular file (a device, a FIFO or a standard stream); a state is written \
             whole and renamed into place, so name a file"
                .into(),
        )),
        Err(DestinationError::Io(source)) => Err(PersistError::Io {
            doing: "write",
            path: path.display().to_string(),
            source,
        }),
        Err(e) => Err(refuse(e.to_string())),
    }
}

/// Checks, before any work, that a state can be saved to `path` (see [`state_destination`]; its folder
/// takes a new file and a rename).
pub fn check_save(path: &Path) -> Result<(), PersistError> {
    let real = state_destination(path)?;
    files::check(&Destination::File(real)).map_err(|source| PersistError::Io {
        doing: "write",
        path: path.display().to_string(),
        source,
    })
}

/// Writes the bytes of a state file ([`encode`]) to `path`, atomically. A failed write removes its
/// temporary, unless only the rename failed: then the temporary holds the whole state and the error
/// names it ([`PersistError::Kept`]). Temporaries of this file left by processes of this host that are
/// gone are removed first, unless they hold a whole state.
pub fn save_bytes(path: &Path, bytes: &[u8]) -> Result<(), PersistError> {
    let real = state_destination(path)?;
    let shown = path.display().to_string();
    files::write_file_via(&real, None, &is_whole_state, &mut |t| {
        std::fs::write(t, bytes)
    })
    .map_err(|e| match e.kept {
        Some(kept) => PersistError::Kept {
            path: shown.clone(),
            kept: kept.display().to_string(),
            source: e.source,
        },
        None => PersistError::Io {
            doing: "write",
            path: shown.clone(),
            source: e.source,
        },
    })
}

/// Whether the file at `path` is a whole state file: its header, its length and its checksum agree.
fn is_whole_state(path: &Path) -> bool {
    let Ok(bytes) = std::fs::read(path) else {
        return false;
    };
    bytes.len() >= HEADER
        && &bytes[..8] == MAGIC
        && u64::from_le_bytes(bytes[12..20].try_into().expect("8 bytes"))
            == (bytes.len() - HEADER) as u64
        && u32::from_le_bytes(bytes[20..24].try_into().expect("4 bytes"))
            == crc32fast::hash(&bytes[HEADER..])
}

/// Reads a state file and checks its form ([`decode`]). Only a regular file is read: a directory, a
/// device or a FIFO named as a state is refused (opened without blocking, so that a FIFO put there after
/// the check cannot hang the reader), and no more bytes are read than its size said.
pub fn read(path: &Path) -> Result<StateFile, PersistError> {
    let shown = path.display().to_string();
    let io = |source| PersistError::Io {
        doing: "read",
        path: shown.clone(),
        source,
    };
    let not_a_file = |meta: &std::fs::Metadata| PersistError::Bad {
        path: shown.clone(),
        problem: format!(
            "not a regular file ({}): a run state is a file",
            scene_read::kind_of(meta)
        ),
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(not_a_file(&meta));
    }
    let file = scene_read::open_nonblocking(path).map_err(io)?;
    let opened = file.metadata().map_err(io)?;
    if !opened.is_file() {
        return Err(not_a_file(&opened));
    }
    let mut bytes = Vec::new();
    bytes
        .try_reserve_exact(opened.len() as usize)
        .map_err(|_| io(std::io::Error::from(std::io::ErrorKind::OutOfMemory)))?;
    // A file growing meanwhile is cut at the size read above, and then refused as truncated.
    std::io::Read::read_to_end(&mut std::io::Read::take(file, opened.len()), &mut bytes)
        .map_err(io)?;
    decode(&shown, &bytes)
}

/// Reads a state file of `scene` ([`read`], then [`StateFile::into_run`]).
pub fn load(path: &Path, scene: &Scene) -> Result<SavedRun, PersistError> {
    read(path)?.into_run(scene)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::control::RunControl;
    use crate::run::{cast, start, CastHooks, CastOptions};
    use crate::sample::lines::Sampler;
    use crate::trace::{make_tracer, Backend, Query};

    /// A state saved and read back reports the same numbers, bit for bit; a truncated file, a flipped
    /// byte and a stranger are refused with a sentence.
    #[test]
    fn states_round_trip_and_damage_is_caught() {
        for spec in ["@cube:2", "@cubes512"] {
            let scene = crate::scenes::load(spec).unwrap();
            let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
            let cfg = RunSpec::new(20_000, 3);
            let mut state = start(&scene, &cfg).unwrap();
            cast(
                &scene,
                tracer.as_ref(),
                &cfg,
                &mut state,
                CastOptions::default(),
                &RunControl::default(),
                CastHooks {
                    target: None,
                    after_round: &mut |_| {},
                },
            )
            .unwrap();
            let identity = RunIdentity::new(
                SceneRef::of(spec, &SceneOptions::default(), &scene),
                cfg.clone(),
                None,
                Tracing {
                    backend: Backend::Rust,
                    query: Query::Single,
                },
            );
            let bytes = encode(&identity, &state, 1.5);
            let back = decode("s.scx", &bytes).unwrap().into_run(&scene).unwrap();
            assert_eq!(back.identity, identity);
            assert_eq!(back.seconds, 1.5);
            let (a, b) = (state.finish(&scene), back.state.finish(&scene));
            assert_eq!(a.total.counters, b.total.counters, "{spec}");
            assert_eq!(a.total.escapes_by_patch, b.total.escapes_by_patch);
            let entries = |t: &Tally| {
                let mut v = Vec::new();
                t.counts
                    .as_ref()
                    .unwrap()
                    .for_each(|i, j, c| v.push((i, j, c)));
                v
            };
            assert_eq!(entries(&a.total), entries(&b.total), "{spec}");
            assert_eq!(a.groups.len(), b.groups.len());

            let message = |bytes: &[u8]| decode("s.scx", bytes).unwrap_err().to_string();
            assert!(message(&bytes[..bytes.len() - 7]).contains("truncated"));
            let mut flipped = bytes.clone();
            flipped[bytes.len() / 2] ^= 0x10;
            assert!(message(&flipped).contains("checksum"));
            assert!(message(b"v 0 0 0\nf 1 2 3\n").contains("not an scx run state"));
            // A state cut inside its header is a truncated state, not a stranger.
            for cut in [8, 16, HEADER - 1] {
                let m = message(&bytes[..cut]);
                assert!(m.contains("truncated") && m.contains("header"), "{m}");
            }
            assert!(message(&bytes[..5]).contains("not an scx run state"));
        }
    }

    /// A key stored twice (a step of 0 after the first entry) is refused: it would be counted twice.
    #[test]
    fn repeated_keys_are_refused() {
        let ok = Sparse {
            key_steps: vec![0, 1, 2],
            values: vec![5, 6, 7],
        };
        assert_eq!(ok.entries(), Some(vec![(0, 5), (1, 6), (3, 7)]));
        let repeated = Sparse {
            key_steps: vec![3, 0],
            values: vec![5, 6],
        };
        assert_eq!(repeated.entries(), None);
    }

    /// A run of `cfg` on `@cube:3`, cast at once, its scene and state.
    fn cube_run(cfg: &RunSpec) -> (Scene, RunState) {
        run_of("@cube:3", cfg)
    }

    /// A run of `cfg` on the built-in scene `spec`, cast at once, its scene and state.
    fn run_of(spec: &str, cfg: &RunSpec) -> (Scene, RunState) {
        let scene = crate::scenes::load(spec).unwrap();
        let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
        let mut state = start(&scene, cfg).unwrap();
        cast(
            &scene,
            tracer.as_ref(),
            cfg,
            &mut state,
            CastOptions::default(),
            &RunControl::default(),
            CastHooks {
                target: None,
                after_round: &mut |_| {},
            },
        )
        .unwrap();
        (scene, state)
    }

    /// A payload whose checksum matches but whose CBOR is malformed, cut short or of another shape is
    /// refused in words, with the byte in the file (it said `cannot be read as a run state
    /// (Syntax(0))`, ciborium's debug text).
    #[test]
    fn malformed_contents_are_described_in_words() {
        let message = |payload: &[u8]| match decode("s.scx", &framed(payload)) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("read"),
        };
        // 0x1c: a reserved additional-information value, malformed in CBOR.
        assert_eq!(
            message(&[0x1c]),
            format!(
                "s.scx: cannot be read as a run state: its contents are not well-formed CBOR (a \
                 malformed item at byte {HEADER})"
            )
        );
        // A map announcing one entry and ending.
        assert_eq!(
            message(&[0xa1]),
            "s.scx: cannot be read as a run state: its contents end in the middle of an item"
        );
        let e = message(&[0x01]);
        assert!(
            e.starts_with(
                "s.scx: cannot be read as a run state: its contents are not those of a run state: "
            ) && !e.contains("Semantic("),
            "{e}"
        );
    }

    /// The bytes of a state file around a CBOR payload (what `encode` adds).
    fn framed(payload: &[u8]) -> Vec<u8> {
        let mut out = MAGIC.to_vec();
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&crc32fast::hash(payload).to_le_bytes());
        out.extend_from_slice(payload);
        out
    }

    /// The per-patch sums of eq. (27) of a run asked for per-patch results survive a save, to the last
    /// bit, in every group and the partial last batch; a run not asked for them saves none.
    #[test]
    fn per_patch_sums_round_trip() {
        // 70 000 lines: batches of 1024 and a partial last one, kept apart in the state.
        for per_patch in [true, false] {
            let cfg = RunSpec {
                per_patch,
                ..RunSpec::new(70_000, 5)
            };
            let (scene, state) = cube_run(&cfg);
            assert!(state.parts().tail.is_some(), "the run has a partial batch");
            let identity = RunIdentity::new(
                SceneRef::of("@cube:3", &SceneOptions::default(), &scene),
                cfg.clone(),
                None,
                Tracing {
                    backend: Backend::Rust,
                    query: Query::Single,
                },
            );
            let back = decode("s.scx", &encode(&identity, &state, 0.5))
                .unwrap()
                .into_run(&scene)
                .unwrap()
                .state;
            assert_eq!(back.wanted(), state.wanted());
            assert_eq!(back.wanted().per_patch, per_patch);
            let sums = |s: &RunState| -> Vec<Option<PatchKernelSums>> {
                let parts = s.parts();
                let tail = parts.tail.map(|(_, t)| t);
                parts
                    .groups
                    .iter()
                    .flatten()
                    .chain(tail)
                    .map(|t| t.kernel_by_patch.clone())
                    .collect()
            };
            let (ours, theirs) = (sums(&state), sums(&back));
            assert_eq!(ours, theirs);
            assert!(ours.iter().all(|k| k.is_some() == per_patch));
            let (a, b) = (state.finish(&scene), back.finish(&scene));
            assert_eq!(a.total.kernel_by_patch, b.total.kernel_by_patch);
        }
    }

    /// A state written before the per-patch sums were kept (no `per_patch` and no `kernel_by_patch`
    /// fields) still loads, as a state without them; one that claims the sums but lacks them in a group
    /// is refused.
    #[test]
    fn states_without_the_per_patch_fields_load() {
        let cfg = RunSpec {
            per_patch: true,
            ..RunSpec::new(20_010, 2)
        };
        let (scene, state) = cube_run(&cfg);
        assert!(state.parts().tail.is_some(), "the run has a partial batch");
        let identity = RunIdentity::new(
            SceneRef::of("@cube:3", &SceneOptions::default(), &scene),
            cfg.clone(),
            None,
            Tracing {
                backend: Backend::Rust,
                query: Query::Single,
            },
        );
        let bytes = encode(&identity, &state, 1.0);
        let mut doc: ciborium::Value = ciborium::from_reader(&bytes[HEADER..]).unwrap();
        let strip = |doc: &mut ciborium::Value, per_patch_flag: bool| {
            let map = doc.as_map_mut().unwrap();
            if per_patch_flag {
                map.retain(|(k, _)| k.as_text() != Some("per_patch"));
            }
            // The groups' tallies, and the partial last batch's (`[batch, tally]`).
            for (k, v) in map.iter_mut() {
                let tallies = match k.as_text() {
                    Some("groups") => v.as_array_mut().unwrap(),
                    Some("tail") => match v.as_array_mut() {
                        Some(pair) => &mut pair[1..],
                        None => continue,
                    },
                    _ => continue,
                };
                for t in tallies.iter_mut().filter_map(|t| t.as_map_mut()) {
                    t.retain(|(k, _)| k.as_text() != Some("kernel_by_patch"));
                }
            }
        };
        // Only the groups' sums removed: the state says it has them and does not.
        let mut damaged = doc.clone();
        strip(&mut damaged, false);
        let mut payload = Vec::new();
        ciborium::into_writer(&damaged, &mut payload).unwrap();
        let message = decode("d.scx", &framed(&payload))
            .unwrap()
            .into_run(&scene)
            .unwrap_err()
            .to_string();
        assert!(message.contains("inconsistent"), "{message}");
        // Both removed: a state of an older scx.
        strip(&mut doc, true);
        let mut payload = Vec::new();
        ciborium::into_writer(&doc, &mut payload).unwrap();
        let old = decode("old.scx", &framed(&payload))
            .unwrap()
            .into_run(&scene)
            .unwrap();
        assert!(!old.state.wanted().per_patch);
        let (a, b) = (state.finish(&scene), old.state.finish(&scene));
        assert_eq!(a.total.counters, b.total.counters);
        assert!(b.total.kernel_by_patch.is_none());
    }

    /// A state written before the sampler was part of a run's spec (no `sampler` field) loads as a run of
    /// independent lines; a state with its field names the sampler it was drawn with.
    #[test]
    fn states_without_a_sampler_load_as_independent_lines() {
        let cfg = RunSpec::new(20_000, 2);
        let (scene, state) = cube_run(&cfg);
        let tracing = Tracing {
            backend: Backend::Rust,
            query: Query::Single,
        };
        let scene_ref = SceneRef::of("@cube:3", &SceneOptions::default(), &scene);
        let identity = RunIdentity::new(scene_ref.clone(), cfg.clone(), None, tracing);
        let bytes = encode(&identity, &state, 1.0);
        let mut doc: ciborium::Value = ciborium::from_reader(&bytes[HEADER..]).unwrap();
        let spec = doc
            .as_map_mut()
            .unwrap()
            .iter_mut()
            .find(|(k, _)| k.as_text() == Some("identity"))
            .and_then(|(_, v)| v.as_map_mut())
            .and_then(|m| m.iter_mut().find(|(k, _)| k.as_text() == Some("spec")))
            .and_then(|(_, v)| v.as_map_mut())
            .unwrap();
        let before = spec.len();
        spec.retain(|(k, _)| k.as_text() != Some("sampler"));
        assert_eq!(spec.len(), before - 1, "the spec had its sampler");
        let mut payload = Vec::new();
        ciborium::into_writer(&doc, &mut payload).unwrap();
        let old = decode("old.scx", &framed(&payload)).unwrap();
        assert_eq!(old.identity().spec.sampler, Sampler::Independent);
        assert_eq!(old.identity().spec, cfg);
        let sobol = RunSpec {
            sampler: Sampler::Sobol,
            ..cfg
        };
        let identity = RunIdentity::new(scene_ref, sobol.clone(), None, tracing);
        let read = decode("s.scx", &encode(&identity, &state, 1.0)).unwrap();
        assert_eq!(read.identity().spec, sobol);
    }

    /// The state of an enclosed run of the open `@cornell-open:2` with per-patch sums, its scene, its
    /// identity and its CBOR document.
    fn enclosed_state() -> (Scene, RunState, RunIdentity, ciborium::Value) {
        let cfg = RunSpec {
            per_patch: true,
            enclose: true,
            ..RunSpec::new(30_000, 4)
        };
        let (scene, state) = run_of("@cornell-open:2", &cfg);
        let identity = RunIdentity::new(
            SceneRef::of("@cornell-open:2", &SceneOptions::default(), &scene),
            cfg,
            None,
            Tracing {
                backend: Backend::Rust,
                query: Query::Single,
            },
        );
        let bytes = encode(&identity, &state, 1.0);
        let doc = ciborium::from_reader(&bytes[HEADER..]).unwrap();
        (scene, state, identity, doc)
    }

    /// The tallies of a state's CBOR document (the groups' and the partial last batch's), as maps.
    fn wire_tallies(
        doc: &mut ciborium::Value,
    ) -> Vec<&mut Vec<(ciborium::Value, ciborium::Value)>> {
        let mut out = Vec::new();
        for (k, v) in doc.as_map_mut().unwrap().iter_mut() {
            let tallies = match k.as_text() {
                Some("groups") => v.as_array_mut().unwrap(),
                Some("tail") => match v.as_array_mut() {
                    Some(pair) => &mut pair[1..],
                    None => continue,
                },
                _ => continue,
            };
            out.extend(tallies.iter_mut().filter_map(|t| t.as_map_mut()));
        }
        out
    }

    /// A tally's stored per-patch sums (`kernel_by_patch`), as a map.
    fn kernel_map(
        tally: &mut [(ciborium::Value, ciborium::Value)],
    ) -> &mut Vec<(ciborium::Value, ciborium::Value)> {
        let (_, v) = tally
            .iter_mut()
            .find(|(k, _)| k.as_text() == Some("kernel_by_patch"))
            .unwrap();
        v.as_map_mut().unwrap()
    }

    fn decode_doc(doc: &ciborium::Value, scene: &Scene) -> Result<SavedRun, PersistError> {
        let mut payload = Vec::new();
        ciborium::into_writer(doc, &mut payload).unwrap();
        decode("e.scx", &framed(&payload))?.into_run(scene)
    }

    /// The escapes' per-patch sums of an enclosed run (`--enclose`) survive a save to the last bit; a
    /// run not enclosed writes none, nor the flag saying it has them (its state is written as before).
    #[test]
    fn enclosed_per_patch_sums_round_trip() {
        let (scene, state, identity, doc) = enclosed_state();
        assert!(state.wanted().environment);
        let back = decode("e.scx", &encode(&identity, &state, 1.0))
            .unwrap()
            .into_run(&scene)
            .unwrap()
            .state;
        assert_eq!(back.wanted(), state.wanted());
        let (a, b) = (state.finish(&scene), back.finish(&scene));
        let k = a.total.kernel_by_patch.as_ref().unwrap();
        assert!(k.has_environment() && k.environment_ends.iter().sum::<u64>() > 0);
        assert_eq!(a.total.kernel_by_patch, b.total.kernel_by_patch);
        let keys = |doc: &ciborium::Value| -> Vec<String> {
            let map = doc.as_map().unwrap();
            map.iter()
                .filter_map(|(k, _)| k.as_text().map(String::from))
                .collect()
        };
        assert!(keys(&doc).contains(&"per_patch_environment".to_string()));

        let cfg = RunSpec {
            per_patch: true,
            ..RunSpec::new(30_000, 4)
        };
        let (plain_scene, plain) = run_of("@cornell-open:2", &cfg);
        assert!(!plain.wanted().environment);
        let identity = RunIdentity {
            spec: cfg,
            ..identity
        };
        let bytes = encode(&identity, &plain, 1.0);
        let mut doc: ciborium::Value = ciborium::from_reader(&bytes[HEADER..]).unwrap();
        assert!(!keys(&doc).contains(&"per_patch_environment".to_string()));
        for t in wire_tallies(&mut doc) {
            let stored: Vec<String> = kernel_map(t)
                .iter()
                .filter_map(|(k, _)| k.as_text().map(String::from))
                .collect();
            assert_eq!(stored, ["log2_kernel", "ends"]);
        }
        let back = decode_doc(&doc, &plain_scene).unwrap();
        assert_eq!(back.state.wanted(), plain.wanted());
    }

    /// An enclosed run's state written before the escapes' sums were kept (no flag, no lists) loads as a
    /// state without per-patch sums; escapes' sums that their counters cannot give, or that a run
    /// without them holds, are refused.
    #[test]
    fn enclosed_states_without_or_with_wrong_escape_sums() {
        let (scene, state, _, doc) = enclosed_state();
        let strip_lists = |doc: &mut ciborium::Value| {
            for t in wire_tallies(doc) {
                kernel_map(t)
                    .retain(|(k, _)| !k.as_text().is_some_and(|k| k.starts_with("environment_")));
            }
        };
        let mut old = doc.clone();
        old.as_map_mut()
            .unwrap()
            .retain(|(k, _)| k.as_text() != Some("per_patch_environment"));
        strip_lists(&mut old);
        let read = decode_doc(&old, &scene).unwrap();
        assert!(!read.state.wanted().per_patch && !read.state.wanted().environment);
        let (a, b) = (state.finish(&scene), read.state.finish(&scene));
        assert_eq!(a.total.counters, b.total.counters);
        assert!(b.total.kernel_by_patch.is_none());

        // The flag without the lists, and the lists without the flag.
        let mut no_lists = doc.clone();
        strip_lists(&mut no_lists);
        let message = decode_doc(&no_lists, &scene).unwrap_err().to_string();
        assert!(
            message.contains("sums of escapes for 0 patches"),
            "{message}"
        );
        let mut no_flag = doc.clone();
        no_flag
            .as_map_mut()
            .unwrap()
            .retain(|(k, _)| k.as_text() != Some("per_patch_environment"));
        let message = decode_doc(&no_flag, &scene).unwrap_err().to_string();
        assert!(
            message.contains("escapes in a run that keeps none"),
            "{message}"
        );

        // One more escape summed for a patch than the run's counters give.
        let mut forged = doc.clone();
        let tally = wire_tallies(&mut forged).into_iter().next().unwrap();
        let ends = kernel_map(tally)
            .iter_mut()
            .find(|(k, _)| k.as_text() == Some("environment_ends"))
            .unwrap();
        let first = &mut ends.1.as_array_mut().unwrap()[0];
        let n = u64::try_from(first.as_integer().unwrap()).unwrap();
        *first = ciborium::Value::Integer((n + 1).into());
        let message = decode_doc(&forged, &scene).unwrap_err().to_string();
        assert!(
            message.contains("inconsistent") && message.contains("escapes"),
            "{message}"
        );
    }
}
