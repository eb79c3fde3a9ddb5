//! Meshing strategies (paper sec. 4.2, Table 9): refine a scene's patches towards about N patches.
//!
//! Starting from the scene's own patches, each round builds the current mesh as a scene, casts a moderate
//! number of global lines through it, solves the radiosity system on the estimated form factors
//! ([`crate::measure::radiosity`]), scores every patch by the chosen [`Strategy`] and splits the
//! highest-scoring patches ([`mesh`]) until the mesh has grown by a factor ([`RefineConfig::growth`]) or
//! reached the target. The rounds stop at the target (at most 2 patches over it: a split adds 3).
//!
//! * [`Strategy::Uniform`] needs no lines: it splits every patch in turn, largest first, so that patch
//!   sizes stay even (the paper's uniform quality triangulation) and the count stops at the target.
//! * [`Strategy::Power`]: largest `A_i B_i` first (the light a patch sends).
//! * [`Strategy::Smoothness`]: largest variation of received radiosity over the patch (a linear trend
//!   fitted to the radiosity arriving along the lines, [`oracle::smoothness`]).
//! * [`Strategy::Information`]: largest share of the information transfer lost by the discretisation
//!   ([`crate::measure::shares::information_loss`], the per-patch module's score).

pub mod mesh;
pub mod oracle;

use std::fmt;
use std::time::Instant;

use crate::analysis::SolveFailure;
use crate::measure::radiosity::{self, FormFactors, MaterialError, PatchMaterials, SolveOptions};
use crate::measure::shares;
use crate::run::RunControl;
use crate::scene::{Scene, SceneError};
use crate::trace::{TraceError, Tracer};
use mesh::Mesh;

/// Which patches a round splits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Strategy {
    /// All patches, largest area first.
    Uniform,
    /// Largest transported power `A_i B_i` first.
    Power,
    /// Largest variation of received radiosity `B^in` over the patch first.
    Smoothness,
    /// Largest loss of information transfer due to the discretisation first.
    Information,
}

impl fmt::Display for Strategy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Strategy::Uniform => "uniform",
            Strategy::Power => "power",
            Strategy::Smoothness => "smoothness",
            Strategy::Information => "information",
        })
    }
}

/// How to refine.
#[derive(Clone, Copy, Debug)]
pub struct RefineConfig {
    /// The strategy.
    pub strategy: Strategy,
    /// Stop at about this many patches.
    pub target_patches: usize,
    /// Global lines cast per round.
    pub lines_per_round: u64,
    /// Seed of the first round's lines (round k uses `seed + k`).
    pub seed: u64,
    /// Each round grows the mesh by at most this factor (> 1).
    pub growth: f64,
    /// The radiosity solve of each round.
    pub solve: SolveOptions,
}

/// One round's record.
#[derive(Clone, Debug, PartialEq)]
pub struct RefineRound {
    /// Patches when the round started.
    pub patches_before: usize,
    /// Patches after its splits.
    pub patches_after: usize,
    /// Lines cast (0 for uniform).
    pub lines: u64,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// The radiosity mutual information (eq. (35)) of the mesh the round measured, from its lines
    /// alone (no standard error); `None` when not measured.
    pub radiosity_mutual_information: Option<f64>,
}

/// The refined scene and how it was reached.
#[derive(Clone, Debug)]
pub struct Refinement {
    /// The refined scene (patch `k` is mesh element `k`).
    pub scene: Scene,
    /// The rounds, in order.
    pub rounds: Vec<RefineRound>,
    /// Whether a stop request ended the refinement early (the mesh is then that of the last finished
    /// round).
    pub interrupted: bool,
}

/// Why a refinement failed.
#[derive(Debug, thiserror::Error)]
pub enum RefineError {
    /// The scene or a refined mesh could not be built.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A material outside the physical range.
    #[error(transparent)]
    Material(#[from] MaterialError),
    /// A radiosity system without solution.
    #[error(transparent)]
    Solve(#[from] SolveFailure),
    /// Tracing failed.
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// A radiosity-driven strategy on a scene without light.
    #[error(
        "{scene}: the {strategy} strategy follows the light, and nothing in this scene emits (no material \
         has Ke above 0); use --strategy uniform or information"
    )]
    NeedsLight {
        /// The scene.
        scene: String,
        /// The strategy.
        strategy: Strategy,
    },
    /// Nonsense settings.
    #[error("{0}")]
    Config(String),
}

impl RefineError {
    /// Whether the user's input (scene, materials, settings) is at fault.
    pub fn is_bad_input(&self) -> bool {
        match self {
            RefineError::Scene(_)
            | RefineError::Material(_)
            | RefineError::Solve(_)
            | RefineError::NeedsLight { .. }
            | RefineError::Config(_) => true,
            RefineError::Trace(_) => false,
        }
    }
}

/// Builds a tracer for a scene (each round's mesh is a new scene).
pub type TracerFactory<'a> = dyn Fn(&Scene) -> Result<Box<dyn Tracer>, TraceError> + 'a;

/// Refines `scene` with `cfg`; `tracer_for` builds a tracer for each round's mesh, `progress` hears of
/// every finished round, and a stop requested on `control` ends the refinement after the round under
/// way (the mesh is that of the last finished round).
pub fn refine(
    scene: &Scene,
    tracer_for: &TracerFactory,
    cfg: &RefineConfig,
    control: &RunControl,
    progress: &mut dyn FnMut(&RefineRound),
) -> Result<Refinement, RefineError> {
    if !(cfg.growth > 1.0 && cfg.growth.is_finite()) {
        return Err(RefineError::Config(format!(
            "the growth per round must be above 1, not {}",
            cfg.growth
        )));
    }
    // Uniform refinement needs no light and no valid materials: it only looks at the areas.
    let lit = cfg.strategy != Strategy::Uniform && PatchMaterials::of_scene(scene)?.any_emission();
    if !lit && matches!(cfg.strategy, Strategy::Power | Strategy::Smoothness) {
        return Err(RefineError::NeedsLight {
            scene: scene.name.clone(),
            strategy: cfg.strategy,
        });
    }
    let name = format!("{} refined ({})", scene.name, cfg.strategy);
    let mut mesh = Mesh::from_scene(scene);
    let mut rounds = Vec::new();
    let mut interrupted = false;
    while mesh.len() < cfg.target_patches {
        if control.stop_requested() {
            interrupted = true;
            break;
        }
        let start = Instant::now();
        let before = mesh.len();
        let current = mesh.to_scene(&name)?;
        let (scores, lines, mi) = match cfg.strategy {
            Strategy::Uniform => (areas(&current), 0, None),
            _ => {
                let seed = cfg.seed.wrapping_add(rounds.len() as u64);
                let tracer = tracer_for(&current)?;
                let r = measure_round(&current, tracer.as_ref(), cfg, seed, lit)?;
                (r.0, cfg.lines_per_round, r.1)
            }
        };
        let goal = ((before as f64 * cfg.growth).ceil() as usize)
            .max(before + 1)
            .min(cfg.target_patches);
        split_best(&mut mesh, &scores, &areas(&current), goal);
        let round = RefineRound {
            patches_before: before,
            patches_after: mesh.len(),
            lines,
            seconds: start.elapsed().as_secs_f64(),
            radiosity_mutual_information: mi,
        };
        progress(&round);
        rounds.push(round);
    }
    Ok(Refinement {
        scene: mesh.to_scene(&name)?,
        rounds,
        interrupted,
    })
}

fn areas(scene: &Scene) -> Vec<f64> {
    scene.patches.iter().map(|p| p.area).collect()
}

/// Casts a round's lines, solves the radiosity system and scores the patches; also returns the
/// round's radiosity mutual information (eq. (35)).
fn measure_round(
    scene: &Scene,
    tracer: &dyn Tracer,
    cfg: &RefineConfig,
    seed: u64,
    lit: bool,
) -> Result<(Vec<f64>, Option<f64>), RefineError> {
    let sample = oracle::sample_pairs(scene, tracer, cfg.lines_per_round, seed)?;
    let ff: FormFactors = oracle::form_factors(scene, &sample);
    let a = areas(scene);
    let solution = if lit {
        let m = PatchMaterials::of_scene(scene)?;
        Some(
            radiosity::solve(&ff, &m, &cfg.solve).map_err(|e| SolveFailure {
                scene: scene.name.clone(),
                message: e.to_string(),
            })?,
        )
    } else {
        None
    };
    let mi = solution
        .as_ref()
        .and_then(|s| radiosity::measures(&a, &ff, s))
        .map(|v| v.mutual_information);
    let scores = match (cfg.strategy, &solution) {
        (Strategy::Power, Some(s)) => oracle::power(&a, s),
        (Strategy::Smoothness, Some(s)) => {
            let m = oracle::arrivals(scene, tracer, cfg.lines_per_round, seed, &s.radiosity)?;
            oracle::smoothness(&a, &m)
        }
        (Strategy::Information, s) => {
            shares::information_loss(&a, &sample, s.as_ref().map(|s| s.radiosity.as_slice()))
        }
        _ => a.clone(),
    };
    Ok((scores, mi))
}

/// Splits elements in decreasing score (ties: larger area first) until the mesh has `goal` elements.
fn split_best(mesh: &mut Mesh, scores: &[f64], areas: &[f64], goal: usize) {
    let mut order: Vec<usize> = (0..scores.len()).collect();
    // NaN scores (never expected) sort last rather than poisoning the order.
    let key = |k: usize| {
        if scores[k].is_nan() {
            f64::NEG_INFINITY
        } else {
            scores[k]
        }
    };
    order.sort_by(|&a, &b| {
        key(b)
            .total_cmp(&key(a))
            .then(areas[b].total_cmp(&areas[a]))
            .then(a.cmp(&b))
    });
    for k in order {
        if mesh.len() >= goal {
            break;
        }
        mesh.split(k);
    }
}
