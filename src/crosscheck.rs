//! Hit-for-hit comparison of two tracers on the same global lines, and of the measures they lead to.
//!
//! Both tracers see exactly the lines an analysis with the same seed casts ([`crate::run::LineStream`], one PCG stream
//! per batch), and their canonical hit lists ([`Tracer::all_hits`]) are compared line by line:
//!
//! * the number of hits must be equal;
//! * the k-th hits must lie on the same *patch* (two triangles of one patch are the same answer for every
//!   measure);
//! * their distances must agree within [`Tolerance`]: `ulps` f32 ulps at `max(|t|, 1)` (tracing space has
//!   the unit bounding sphere, so `t <= 2.002` and an ulp there is ~2.4e-7).
//!
//! Every line that breaks one of these is a difference. The measures are then compared by running
//! [`analyze`] with each tracer on the same seed.
//!
//! Random lines practically never meet a vertex or an edge, nor lie in a triangle's plane: [`aimed`]
//! makes lines aimed at exactly those places, of several kinds, and [`compare_aimed`] compares the two
//! tracers on them, kind by kind, by the same rules.

pub mod aimed;

use std::fmt;

use rayon::prelude::*;

use crate::analysis::{analyze, Analysis, AnalysisError};
use crate::geom::DVec3;
use crate::measure::{Estimate, Measure};
use crate::run::{
    all_batches, map_batches, BatchPlan, LineStream, LinesThrough, Measures, RunControl, RunSpec,
    TraceBuffers,
};
use crate::sample::bounds::LineBound;
use crate::scene::Scene;
use crate::trace::rust::bvh::margin;
use crate::trace::{Hit, Line, LineHits, TraceError, Tracer};
use aimed::{Aim, AimKind, AimTargets};

/// How far apart two hits' distances may be and still agree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// f32 ulps at `max(|t|, 1)`.
    pub ulps: f32,
}

impl Default for Tolerance {
    /// 4 ulps: both backends run the same watertight test, so their `t` are normally identical; this
    /// leaves room for a different but equally valid rounding without hiding a wrong triangle.
    fn default() -> Self {
        Tolerance { ulps: 4.0 }
    }
}

impl Tolerance {
    /// The largest allowed |t_a - t_b| around `t`.
    pub fn at(&self, t: f32) -> f32 {
        self.ulps * f32::EPSILON * t.abs().max(1.0)
    }
}

/// How a line's hit lists differ (the first reason found, in this order).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DifferenceKind {
    /// Different numbers of hits.
    Count,
    /// Same count, but some k-th hits lie on different patches.
    Patch,
    /// Same patches, but some k-th distances differ beyond the tolerance.
    Distance,
}

impl fmt::Display for DifferenceKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            DifferenceKind::Count => "hit count",
            DifferenceKind::Patch => "patch",
            DifferenceKind::Distance => "distance",
        })
    }
}

/// One line whose hit lists differ.
#[derive(Clone, Debug)]
pub struct LineDifference {
    /// The line's index in the run (batch order).
    pub index: u64,
    /// The line.
    pub line: Line,
    /// Why it differs.
    pub kind: DifferenceKind,
    /// The first tracer's hits.
    pub a: Vec<Hit>,
    /// The second tracer's hits.
    pub b: Vec<Hit>,
}

/// The result of comparing two tracers' hits.
#[derive(Clone, Debug)]
pub struct HitComparison {
    /// The two tracers' names.
    pub names: (&'static str, &'static str),
    /// Lines compared.
    pub lines: u64,
    /// Canonical hits of each tracer.
    pub hits: (u64, u64),
    /// Lines that differ, by kind: count, patch, distance.
    pub differing: [u64; 3],
    /// The largest |t_a - t_b| between matched hits, in ulps at `max(|t|, 1)`, over lines of equal count.
    pub max_ulps: f32,
    /// The first differing lines (at most the number asked for), in line order.
    pub examples: Vec<LineDifference>,
    /// The tolerance used.
    pub tolerance: Tolerance,
}

impl HitComparison {
    /// Lines that differ beyond the tolerance.
    pub fn differing_lines(&self) -> u64 {
        self.differing.iter().sum()
    }

    /// Whether the tracers agree on every line.
    pub fn agrees(&self) -> bool {
        self.differing_lines() == 0
    }

    fn empty(names: (&'static str, &'static str), tolerance: Tolerance) -> Self {
        HitComparison {
            names,
            lines: 0,
            hits: (0, 0),
            differing: [0; 3],
            max_ulps: 0.0,
            examples: Vec::new(),
            tolerance,
        }
    }

    /// Adds a later part of the run (keeps line order in `examples`).
    fn merge(&mut self, other: HitComparison, keep: usize) {
        self.lines += other.lines;
        self.hits.0 += other.hits.0;
        self.hits.1 += other.hits.1;
        for (a, b) in self.differing.iter_mut().zip(other.differing) {
            *a += b;
        }
        self.max_ulps = self.max_ulps.max(other.max_ulps);
        let room = keep.saturating_sub(self.examples.len());
        self.examples.extend(other.examples.into_iter().take(room));
    }
}

/// Compares two patches lists of hits of one line: `None` when they agree, else why not; also the largest
/// distance gap in ulps (0 when the counts differ).
fn compare_line(
    scene: &Scene,
    a: &[Hit],
    b: &[Hit],
    tolerance: Tolerance,
) -> (Option<DifferenceKind>, f32) {
    if a.len() != b.len() {
        return (Some(DifferenceKind::Count), 0.0);
    }
    let patch = |h: &Hit| scene.triangle_patch[h.triangle as usize];
    if a.iter().zip(b).any(|(x, y)| patch(x) != patch(y)) {
        return (Some(DifferenceKind::Patch), 0.0);
    }
    let mut worst = 0.0f32;
    let mut beyond = false;
    for (x, y) in a.iter().zip(b) {
        let gap = (x.t - y.t).abs();
        worst = worst.max(gap / Tolerance { ulps: 1.0 }.at(x.t));
        beyond |= gap > tolerance.at(x.t);
    }
    (beyond.then_some(DifferenceKind::Distance), worst)
}

/// Per-thread buffers: one tracer's hits each.
#[derive(Default)]
struct Buffers {
    a: TraceBuffers,
    b: TraceBuffers,
}

/// What to compare and how much to keep.
#[derive(Clone, Copy, Debug)]
pub struct CrossCheckConfig {
    /// Global lines.
    pub lines: u64,
    /// Seed of the line streams (the same lines as `scx analyze --seed`).
    pub seed: u64,
    /// Distance tolerance.
    pub tolerance: Tolerance,
    /// How many differing lines to keep as examples.
    pub examples: usize,
}

/// Traces the lines of `scx analyze --lines N --seed S` (`cfg.lines` counted through the bounding sphere,
/// drawn through the container `auto` chooses: [`RunSpec::through`]) with both tracers and compares
/// their canonical hits line by line, in parallel over batches (results independent of the thread
/// count).
pub fn compare_hits(
    scene: &Scene,
    a: &dyn Tracer,
    b: &dyn Tracer,
    cfg: &CrossCheckConfig,
) -> Result<HitComparison, TraceError> {
    let run = RunSpec::new(cfg.lines, cfg.seed).through(scene, LinesThrough::Auto);
    let stream = LineStream {
        bound: run.bound,
        ..LineStream::independent(run.lines, cfg.seed)
    };
    let (parts, _) = map_batches(
        &stream,
        scene,
        &all_batches(&stream),
        &|_| false,
        |buf: &mut Buffers, batch| {
            compare_batch(scene, (a, b), cfg, batch.first_line, batch.lines, buf)
        },
    )?;
    let mut total = HitComparison::empty((a.name(), b.name()), cfg.tolerance);
    for (_, p) in parts {
        total.merge(p, cfg.examples);
    }
    Ok(total)
}

/// Compares the two tracers on one batch of lines, whose first line is line `first_line` of its run.
fn compare_batch(
    scene: &Scene,
    (a, b): (&dyn Tracer, &dyn Tracer),
    cfg: &CrossCheckConfig,
    first_line: u64,
    lines: &[Line],
    buf: &mut Buffers,
) -> Result<HitComparison, TraceError> {
    buf.a.trace(a, lines)?;
    buf.b.trace(b, lines)?;
    let (hits_a, hits_b) = (&buf.a.hits, &buf.b.hits);
    let mut part = HitComparison::empty((a.name(), b.name()), cfg.tolerance);
    part.lines = lines.len() as u64;
    part.hits = (hits_a.hits.len() as u64, hits_b.hits.len() as u64);
    for (k, line) in lines.iter().enumerate() {
        let (ra, rb) = (hits_a.of_line(k), hits_b.of_line(k));
        let (kind, ulps) = compare_line(scene, ra, rb, cfg.tolerance);
        part.max_ulps = part.max_ulps.max(ulps);
        let Some(kind) = kind else { continue };
        part.differing[kind as usize] += 1;
        if part.examples.len() < cfg.examples {
            part.examples.push(LineDifference {
                index: first_line + k as u64,
                line: *line,
                kind,
                a: ra.to_vec(),
                b: rb.to_vec(),
            });
        }
    }
    Ok(part)
}

/// What to compare on aimed lines ([`aimed`]).
#[derive(Clone, Debug)]
pub struct AimedConfig {
    /// Lines of each kind.
    pub lines_per_kind: u64,
    /// The kinds to cast, in report order.
    pub kinds: Vec<AimKind>,
    /// Seed of the lines' random streams.
    pub seed: u64,
    /// Distance tolerance.
    pub tolerance: Tolerance,
    /// How many differing lines to keep as examples, per kind.
    pub examples: usize,
}

/// The two tracers on the aimed lines of one kind.
#[derive(Clone, Debug)]
pub struct KindComparison {
    /// The kind of lines.
    pub kind: AimKind,
    /// How many targets (vertices, edges, sides of triangles, faces) its lines go round; 0 when the
    /// scene has none, and the kind cast no line.
    pub targets: usize,
    /// The hit comparison; example indices count the kind's lines from 0.
    pub hits: HitComparison,
    /// What each example line was aimed at, in the order of `hits.examples`.
    pub aims: Vec<Aim>,
    /// The first tracer's hits whose point lies outside its triangle's box grown by the tracers' margin
    /// (1/65536 of the scene's size). The watertight test keeps the distance of a grazing crossing
    /// within the box, so this reads 0; it once counted hits of lines in a triangle's plane to within
    /// rounding, whose distance was rounding ([`aimed`], "What agreement means on these lines").
    pub stray_hits: u64,
}

/// A cross-check on aimed lines, kind by kind.
#[derive(Clone, Debug)]
pub struct AimedCheck {
    /// The scene's name.
    pub scene: String,
    /// Seed.
    pub seed: u64,
    /// One comparison per kind asked for, in that order.
    pub kinds: Vec<KindComparison>,
}

impl AimedCheck {
    /// Lines cast, all kinds.
    pub fn lines(&self) -> u64 {
        self.kinds.iter().map(|k| k.hits.lines).sum()
    }

    /// Lines that differ, all kinds.
    pub fn differing_lines(&self) -> u64 {
        self.kinds.iter().map(|k| k.hits.differing_lines()).sum()
    }

    /// Whether the tracers agree on every aimed line.
    pub fn passed(&self) -> bool {
        self.differing_lines() == 0
    }
}

/// Traces `cfg.lines_per_kind` aimed lines of each kind with both tracers and compares their canonical
/// hits line by line, as [`compare_hits`] does random lines: in parallel over the batches of every
/// kind, with results independent of the thread count.
pub fn compare_aimed(
    scene: &Scene,
    a: &dyn Tracer,
    b: &dyn Tracer,
    cfg: &AimedConfig,
) -> Result<AimedCheck, TraceError> {
    let targets = AimTargets::new(scene);
    let boxes = GrownBoxes::new(scene);
    let plan = BatchPlan::new(cfg.lines_per_kind);
    let per_batch = CrossCheckConfig {
        lines: cfg.lines_per_kind,
        seed: cfg.seed,
        tolerance: cfg.tolerance,
        examples: cfg.examples,
    };
    let jobs: Vec<(usize, u64)> = (0..cfg.kinds.len())
        .filter(|&k| targets.count(cfg.kinds[k]) > 0)
        .flat_map(|k| (0..plan.batches()).map(move |batch| (k, batch)))
        .collect();
    let parts: Vec<(usize, HitComparison, Vec<Aim>, u64)> = jobs
        .par_iter()
        .map_init(
            || (Vec::new(), Vec::new(), Buffers::default()),
            |(lines, aims, buf), &(k, batch)| {
                lines.clear();
                aims.clear();
                targets.draw(cfg.kinds[k], cfg.seed, &plan, batch, lines, aims);
                let first = plan.first_line(batch);
                let part = compare_batch(scene, (a, b), &per_batch, first, lines, buf)?;
                let stray = boxes.stray_hits(lines, &buf.a.hits);
                let example_aims = part
                    .examples
                    .iter()
                    .map(|d| aims[(d.index - first) as usize])
                    .collect();
                Ok((k, part, example_aims, stray))
            },
        )
        .collect::<Result<_, TraceError>>()?;
    let mut kinds: Vec<KindComparison> = cfg
        .kinds
        .iter()
        .map(|&kind| KindComparison {
            kind,
            targets: targets.count(kind),
            hits: HitComparison::empty((a.name(), b.name()), cfg.tolerance),
            aims: Vec::new(),
            stray_hits: 0,
        })
        .collect();
    for (k, part, aims, stray) in parts {
        let into = &mut kinds[k];
        into.stray_hits += stray;
        let room = cfg.examples.saturating_sub(into.aims.len());
        into.aims.extend(aims.into_iter().take(room));
        into.hits.merge(part, cfg.examples);
    }
    Ok(AimedCheck {
        scene: scene.name.clone(),
        seed: cfg.seed,
        kinds,
    })
}

/// Every triangle's box grown by the tracers' [`margin`], in f64: the boxes both tracers propose
/// candidates from.
struct GrownBoxes {
    boxes: Vec<(DVec3, DVec3)>,
}

impl GrownBoxes {
    fn new(scene: &Scene) -> Self {
        let m = DVec3::splat(f64::from(margin(scene)));
        let corner = |v: u32| DVec3::from_array(scene.positions[v as usize].map(f64::from));
        let boxes = scene
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(corner);
                (a.min(b).min(c) - m, a.max(b).max(c) + m)
            })
            .collect();
        GrownBoxes { boxes }
    }

    /// How many of `hits` (of `lines`) lie outside their triangle's grown box.
    fn stray_hits(&self, lines: &[Line], hits: &LineHits) -> u64 {
        let mut stray = 0;
        for (k, line) in lines.iter().enumerate() {
            let origin = DVec3::from_array(line.origin.map(f64::from));
            let dir = DVec3::from_array(line.dir.map(f64::from));
            for h in hits.of_line(k) {
                let p = origin + f64::from(h.t) * dir;
                let (lo, hi) = self.boxes[h.triangle as usize];
                stray += u64::from(p.cmplt(lo).any() || p.cmpgt(hi).any());
            }
        }
        stray
    }
}

/// One measure from both runs.
#[derive(Clone, Debug)]
pub struct MeasureComparison {
    /// The measure's name.
    pub name: &'static str,
    /// With the first tracer.
    pub a: Estimate,
    /// With the second tracer.
    pub b: Estimate,
}

impl MeasureComparison {
    /// |a - b| over the larger standard error (0 when equal; infinite when they differ with no error).
    pub fn gap_in_stderrs(&self) -> f64 {
        let gap = (self.a.value - self.b.value).abs();
        if gap == 0.0 {
            return 0.0;
        }
        let se = self
            .a
            .stderr
            .unwrap_or(0.0)
            .max(self.b.stderr.unwrap_or(0.0));
        gap / se
    }
}

/// Runs [`analyze`] with each tracer on the same lines and pairs up the measures both computed.
pub fn compare_measures(
    scene: &Scene,
    a: &dyn Tracer,
    b: &dyn Tracer,
    cfg: &RunSpec,
) -> Result<Vec<MeasureComparison>, AnalysisError> {
    let control = RunControl::default();
    let ra = analyze(scene, a, cfg, &control)?;
    let rb = analyze(scene, b, cfg, &control)?;
    Ok(measures(&ra)
        .into_iter()
        .zip(measures(&rb))
        .filter_map(|((name, x), (_, y))| Some(MeasureComparison { name, a: x?, b: y? }))
        .collect())
}

fn measures(r: &Analysis) -> Vec<(&'static str, Option<Estimate>)> {
    vec![
        (
            "visibility entropy H_s (eq. 17)",
            r.estimate(Measure::Entropy),
        ),
        (
            "joint entropy H(X,Y) (eq. 7)",
            r.estimate(Measure::JointEntropy),
        ),
        (
            "mutual information I_s (eq. 21)",
            r.estimate(Measure::MutualInformation),
        ),
        (
            "continuous mutual information I_s^c (eq. 27)",
            r.estimate(Measure::ContinuousMutualInformation),
        ),
        (
            "accuracy I_s / I_s^c (sec. 3.3)",
            r.estimate(Measure::Accuracy),
        ),
        (
            "form-factor E(MSE) per line (eq. 22)",
            r.estimate(Measure::MsePerLine),
        ),
    ]
}

/// A whole cross-check: hits, then measures.
#[derive(Clone, Debug)]
pub struct CrossCheck {
    /// The scene's name.
    pub scene: String,
    /// Seed.
    pub seed: u64,
    /// The lines asked for, through the bounding sphere ([`CrossCheckConfig::lines`]), and where they
    /// were drawn (the hit comparison's `lines` counts those drawn).
    pub sphere_lines: u64,
    /// Where the lines were drawn.
    pub bound: LineBound,
    /// The hit comparison.
    pub hits: HitComparison,
    /// The measure comparison.
    pub measures: Vec<MeasureComparison>,
}

/// Compares two tracers on `cfg.lines` lines: hit lists line by line, then every measure of an analysis
/// run with each (all measures, `groups` groups for the standard errors).
pub fn crosscheck(
    scene: &Scene,
    a: &dyn Tracer,
    b: &dyn Tracer,
    cfg: &CrossCheckConfig,
    groups: usize,
) -> Result<CrossCheck, AnalysisError> {
    let hits = compare_hits(scene, a, b, cfg)?;
    let analysis = RunSpec {
        groups,
        measures: Measures::VISIBILITY,
        ..RunSpec::new(cfg.lines, cfg.seed)
    }
    .through(scene, LinesThrough::Auto);
    let measures = compare_measures(scene, a, b, &analysis)?;
    Ok(CrossCheck {
        scene: scene.name.clone(),
        seed: cfg.seed,
        sphere_lines: cfg.lines,
        bound: analysis.bound,
        hits,
        measures,
    })
}

impl CrossCheck {
    /// Whether every line agrees within the tolerance (the measures then agree too, but they are only
    /// reported).
    pub fn passed(&self) -> bool {
        self.hits.agrees()
    }
}

fn fmt_hits(scene: &Scene, hits: &[Hit]) -> String {
    let items: Vec<String> = hits
        .iter()
        .map(|h| {
            format!(
                "t={:.9} tri {} patch {}",
                h.t, h.triangle, scene.triangle_patch[h.triangle as usize]
            )
        })
        .collect();
    format!("[{}]", items.join(", "))
}

/// A readable report of a cross-check; `scene` names the patches of the example hits.
pub fn report(check: &CrossCheck, scene: &Scene) -> String {
    let h = &check.hits;
    let (na, nb) = h.names;
    let mut s = String::new();
    let drawn = match check.bound {
        LineBound::Sphere => String::new(),
        bound => format!(" ({} drawn through the bounding {})", h.lines, bound.name()),
    };
    s += &format!(
        "crosscheck {} seed {}: {} lines{drawn}, {na} {} hits, {nb} {} hits\n",
        check.scene, check.seed, check.sphere_lines, h.hits.0, h.hits.1
    );
    s += &format!(
        "tolerance: same hit count, same patches, |t_a - t_b| <= {} ulps at max(t, 1)\n",
        h.tolerance.ulps
    );
    s += &format!(
        "differing lines: {} (hit count {}, patch {}, distance {}); largest distance gap {:.1} ulps\n",
        h.differing_lines(),
        h.differing[0],
        h.differing[1],
        h.differing[2],
        h.max_ulps
    );
    for d in &h.examples {
        s += &format!(
            "  line {} ({}): origin {:?} dir {:?}\n    {na}: {}\n    {nb}: {}\n",
            d.index,
            d.kind,
            d.line.origin,
            d.line.dir,
            fmt_hits(scene, &d.a),
            fmt_hits(scene, &d.b)
        );
    }
    s += &format!(
        "{:<46} {:>12} {:>12} {:>12} {:>10}\n",
        "measure", na, nb, "difference", "/ stderr"
    );
    for m in &check.measures {
        s += &format!(
            "{:<46} {:>12.6} {:>12.6} {:>12.3e} {:>10.2}\n",
            m.name,
            m.a.value,
            m.b.value,
            m.a.value - m.b.value,
            m.gap_in_stderrs()
        );
    }
    s += if check.passed() {
        "PASS: every line agrees\n"
    } else {
        "FAIL: some lines differ beyond the tolerance\n"
    };
    s
}

/// A readable report of a cross-check on aimed lines: per kind, the lines cast and the lines that
/// differ (by hit count, patch, distance), then the first `show` differing lines; `scene` names the
/// patches of their hits.
pub fn report_aimed(check: &AimedCheck, scene: &Scene, show: usize) -> String {
    let Some(first) = check.kinds.first() else {
        return format!(
            "crosscheck {}: no kind of aimed lines asked for\n",
            check.scene
        );
    };
    let (na, nb) = first.hits.names;
    let mut s = format!(
        "crosscheck {} seed {}: {} aimed lines, {} kinds\n",
        check.scene,
        check.seed,
        check.lines(),
        check.kinds.len()
    );
    s += &format!(
        "tolerance: same hit count, same patches, |t_a - t_b| <= {} ulps at max(t, 1); measures are not \
         compared (aimed lines are not uniformly distributed)\n",
        first.hits.tolerance.ulps
    );
    s += &format!(
        "{:<16} {:>8} {:>9} {:>11} {:>11} {:>9} {:>6} {:>6} {:>8} {:>9} {:>6}\n",
        "kind",
        "targets",
        "lines",
        na,
        nb,
        "differing",
        "count",
        "patch",
        "distance",
        "max ulps",
        "stray"
    );
    let mut total = HitComparison::empty((na, nb), first.hits.tolerance);
    let mut stray = 0;
    for k in &check.kinds {
        s += &kind_row(k.kind.name(), k.targets.to_string(), &k.hits, k.stray_hits);
        total.merge(k.hits.clone(), 0);
        stray += k.stray_hits;
    }
    s += &kind_row("all", String::new(), &total, stray);
    s += &format!(
        "stray: {na} hits further than the box margin from their triangle (expected 0: the distance of \
         a grazing crossing is kept within its triangle's box)\n"
    );
    let examples = check
        .kinds
        .iter()
        .flat_map(|k| k.hits.examples.iter().zip(&k.aims))
        .take(show);
    for (d, aim) in examples {
        s += &format!(
            "  {} line {} ({}): {}\n    origin {:?} dir {:?}\n    {na}: {}\n    {nb}: {}\n",
            aim.kind,
            d.index,
            d.kind,
            describe_aim(aim),
            d.line.origin,
            d.line.dir,
            fmt_hits(scene, &d.a),
            fmt_hits(scene, &d.b)
        );
    }
    s += if check.passed() {
        "PASS: every aimed line agrees\n"
    } else {
        "FAIL: some aimed lines differ beyond the tolerance\n"
    };
    s
}

/// One row of the aimed report's table.
fn kind_row(name: &str, targets: String, h: &HitComparison, stray: u64) -> String {
    format!(
        "{:<16} {:>8} {:>9} {:>11} {:>11} {:>9} {:>6} {:>6} {:>8} {:>9.1} {:>6}\n",
        name,
        targets,
        h.lines,
        h.hits.0,
        h.hits.1,
        h.differing_lines(),
        h.differing[0],
        h.differing[1],
        h.differing[2],
        h.max_ulps,
        stray
    )
}

/// Where an aimed line was aimed, in words.
fn describe_aim(aim: &Aim) -> String {
    let p = |v: DVec3| format!("({:.7}, {:.7}, {:.7})", v.x, v.y, v.z);
    let mut s = format!("through {} of triangle {}", p(aim.through), aim.triangle);
    if let Some(end) = aim.also_through {
        s += &format!(" and {}", p(end));
    }
    if let Some((normal, angle)) = aim.plane {
        s += &format!(", {angle:.1e} rad from the plane of normal {}", p(normal));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(t: f32, triangle: u32) -> Hit {
        Hit { t, triangle }
    }

    #[test]
    fn lines_are_told_apart_by_count_patch_and_distance() {
        let scene = crate::scenes::load("@cube:2").unwrap();
        let tol = Tolerance::default();
        // Triangles 0 and 1 are the two halves of patch 0; triangle 2 is patch 1.
        assert_eq!(scene.triangle_patch[..3], [0, 0, 1]);
        let a = [hit(1.0, 0), hit(1.5, 2)];
        assert_eq!(compare_line(&scene, &a, &a, tol).0, None);
        let other_half = [hit(1.0, 1), hit(1.5, 2)];
        assert_eq!(compare_line(&scene, &a, &other_half, tol).0, None);
        assert_eq!(
            compare_line(&scene, &a, &a[..1], tol).0,
            Some(DifferenceKind::Count)
        );
        let other_patch = [hit(1.0, 2), hit(1.5, 2)];
        assert_eq!(
            compare_line(&scene, &a, &other_patch, tol).0,
            Some(DifferenceKind::Patch)
        );
        // 1.5 + 4 ulps (at 1.5: ulp = 2^-23 * 1, within "4 ulps at max(t,1)" = 4 * 2^-23 * 1.5)
        let near = [hit(1.0, 0), hit(1.5 + 4.0 * f32::EPSILON, 2)];
        let (kind, ulps) = compare_line(&scene, &a, &near, tol);
        assert_eq!(kind, None);
        assert!(ulps > 2.0 && ulps <= 4.0, "{ulps}");
        let far = [hit(1.0, 0), hit(1.5 + 8.0 * f32::EPSILON, 2)];
        assert_eq!(
            compare_line(&scene, &a, &far, tol).0,
            Some(DifferenceKind::Distance)
        );
    }
}
