//! The nine tables: which scenes, which columns, and which of the paper's claims to check.

use crate::scenes;
use std::time::Instant;

use super::{est, lines_text, published, Finding, ReproduceError, Run, Session, TableReport, Want};
use crate::measure::radiosity::SolveOptions;
use crate::measure::Estimate;
use crate::measure::{ByMeasure, Measure};
use crate::refine::{refine, RefineConfig, Strategy};
use crate::scene::Scene;
use crate::trace::{make_tracer, Query};

/// Regenerates table `t` (1..=9); its lines and seconds are filled in by the caller.
pub(super) fn table(s: &mut Session, t: u8) -> Result<TableReport, ReproduceError> {
    match t {
        1 => table1(s),
        2 => table2(s),
        3 => table3(s),
        4 => table4(s),
        5 => table5(s),
        6 => table67(s, 6),
        7 => table67(s, 7),
        8 => table8(s),
        9 => table9(s),
        _ => Err(ReproduceError::NoSuchTable(t)),
    }
}

fn report(number: u8, title: &str, header: &[&str]) -> TableReport {
    TableReport {
        number,
        title: title.into(),
        header: header.iter().map(|h| h.to_string()).collect(),
        rows: Vec::new(),
        notes: Vec::new(),
        findings: Vec::new(),
        lines: 0,
        reused: 0,
        repeated: 0,
        seconds: 0.0,
    }
}

/// A claim checked on readings none of which is flagged (those that may be use [`finding_on`]).
fn finding(claim: &str, holds: bool, detail: String) -> Finding {
    Finding {
        claim: claim.into(),
        holds,
        detail,
        flagged: Vec::new(),
    }
}

/// A claim checked on the readings `measures` of `runs`: the finding names those that break a bound of
/// the theory, so that its verdict does not pass for more than they are worth.
fn finding_on(
    claim: &str,
    holds: bool,
    detail: String,
    runs: &[&Run],
    measures: &[Measure],
) -> Finding {
    Finding {
        flagged: flagged_among(runs, measures),
        ..finding(claim, holds, detail)
    }
}

/// The readings `measures` of `runs` that break a bound of the theory, one entry per run
/// (`@fig2:a 1e5: I_s, I_s corrected`).
fn flagged_among(runs: &[&Run], measures: &[Measure]) -> Vec<String> {
    let mut out = Vec::new();
    for r in runs {
        let symbols: Vec<&str> = measures
            .iter()
            .filter(|&&m| !r.flags(m).is_empty())
            .map(|m| m.info().symbol)
            .collect();
        let entry = format!("{}: {}", r.label(), symbols.join(", "));
        if !symbols.is_empty() && !out.contains(&entry) {
            out.push(entry);
        }
    }
    out
}

/// A table's reading cells, each marked `!` when the reading breaks a bound of the theory, and the
/// notes under the table that say which bound, in `scx analyze`'s words after the run's name.
#[derive(Default)]
struct Marks {
    notes: Vec<String>,
}

impl Marks {
    /// The cell of reading `m` of run `r`, with `digits` decimals ([`est`]), marked.
    fn cell(&mut self, r: &Run, m: Measure, digits: usize) -> String {
        self.cell_of(r, m, r.v.of(m), digits)
    }

    /// The cell of `e`, a number derived from reading `m` of run `r` (E(MSE) area-weighted), marked as
    /// that reading is: it breaks what the reading breaks.
    fn cell_of(&mut self, r: &Run, m: Measure, e: Option<Estimate>, digits: usize) -> String {
        let flags = r.flags(m);
        for f in flags {
            let note = format!("! {}: {f}", r.label());
            if !self.notes.contains(&note) {
                self.notes.push(note);
            }
        }
        let mark = if flags.is_empty() { "" } else { " !" };
        format!("{}{mark}", est(e, digits))
    }
}

/// Picks one measure of a run.
type Pick = fn(&ByMeasure<Estimate>) -> Option<Estimate>;

/// A fig. 2 run of Table 1: placement, the paper's line count, the paper's E(MSE), the run.
type Fig2Run = (char, u64, f64, Run);

/// The value of an estimate (NaN when missing, which fails every comparison).
fn val(e: Option<Estimate>) -> f64 {
    e.map_or(f64::NAN, |e| e.value)
}

/// The standard error of an estimate (0 when missing).
fn se(e: Option<Estimate>) -> f64 {
    e.and_then(|e| e.stderr).unwrap_or(0.0)
}

/// An estimate scaled by a constant factor.
fn scaled(e: Option<Estimate>, k: f64) -> Option<Estimate> {
    e.map(|e| Estimate {
        value: e.value * k,
        stderr: e.stderr.map(|s| s * k),
    })
}

fn secs(r: &Run) -> String {
    format!("{:.2}", r.seconds)
}

/// Whether `xs` strictly decreases.
fn decreasing(xs: &[f64]) -> bool {
    xs.windows(2).all(|w| w[0] > w[1])
}

/// Whether `x` and `y` rank their elements alike.
fn same_order(x: &[f64], y: &[f64]) -> bool {
    (0..x.len()).all(|i| (0..x.len()).all(|j| (x[i] > x[j]) == (y[i] > y[j])))
}

/// Numbers joined by `/` with 3 decimals.
fn slash(xs: &[f64]) -> String {
    xs.iter()
        .map(|x| format!("{x:.3}"))
        .collect::<Vec<_>>()
        .join("/")
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}

/// Whether two estimates agree within 3 combined standard errors.
fn agree(a: Option<Estimate>, b: Option<Estimate>) -> bool {
    (val(a) - val(b)).abs() <= 3.0 * (se(a).powi(2) + se(b).powi(2)).sqrt()
}

/// Distinct values in first-seen order.
fn distinct<T: PartialEq + Copy>(xs: impl IntoIterator<Item = T>) -> Vec<T> {
    let mut v = Vec::new();
    for x in xs {
        if !v.contains(&x) {
            v.push(x);
        }
    }
    v
}

/// A note when some runs cast fewer lines than the paper's.
fn capped_note(s: &Session, paper_counts: &[u64]) -> Option<String> {
    let capped: Vec<String> = distinct(paper_counts.iter().copied())
        .into_iter()
        .filter(|&p| s.lines(p) != p)
        .map(|p| format!("{} -> {}", lines_text(p), lines_text(s.lines(p))))
        .collect();
    (!capped.is_empty()).then(|| {
        format!(
            "Lines: the paper's counts changed by `--lines` (paper -> ours): {}.",
            capped.join(", ")
        )
    })
}

fn table1(s: &mut Session) -> Result<TableReport, ReproduceError> {
    let mut t = report(
        1,
        "fig. 2, 512 cubes: random (a) and clustered (b, c) placements (`@fig2:a|b|c`)",
        &[
            "scene",
            "lines",
            "s",
            "H_s",
            "H_s corr.",
            "H_s paper",
            "I_s",
            "I_s corr.",
            "I_s paper",
            "E(MSE) eq. 22",
            "E(MSE) area-weighted",
            "E(MSE) paper",
        ],
    );
    let mut marks = Marks::default();
    let mut runs = Vec::new();
    for &(p, lines, hs, is, mse) in &published::TABLE1 {
        let r = s.run(&format!("@fig2:{p}"), lines, Want::Visibility)?;
        let v = &r.v;
        t.rows.push(vec![
            format!("Fig.2{p}"),
            lines_text(r.lines),
            secs(&r),
            marks.cell(&r, Measure::Entropy, 3),
            marks.cell(&r, Measure::EntropyCorrected, 3),
            hs.into(),
            marks.cell(&r, Measure::MutualInformation, 3),
            marks.cell(&r, Measure::MutualInformationCorrected, 3),
            is.into(),
            marks.cell(&r, Measure::MsePerLine, 1),
            marks.cell_of(
                &r,
                Measure::MsePerLine,
                scaled(v.of(Measure::MsePerLine), r.area_weight),
                1,
            ),
            mse.into(),
        ]);
        runs.push((p, lines, mse.parse::<f64>().unwrap_or(f64::NAN), r));
    }
    t.notes.append(&mut marks.notes);
    let hp = runs[0].3.v.of(Measure::PositionalEntropy);
    t.notes.push(format!(
        "H_p (eq. 19, exact from the areas) = {} for all three (paper: {}).",
        est(hp, 4),
        published::TABLE1_HP
    ));
    let ratios: Vec<String> = runs
        .iter()
        .map(|(p, l, m, r)| {
            let ours = val(scaled(r.v.of(Measure::MsePerLine), r.area_weight));
            format!("{p} {}: {:.3}", lines_text(*l), m / ours)
        })
        .collect();
    t.notes.push(format!(
        "E(MSE) eq. 22 is n_p - sum F_ij^2 (the MSE of the form factors times the lines); area-weighted is \
         sum_i (A_i/A_T) sum_j Var(F_ij) times the lines = (2 pi R^2 / A_T)(n_p - sum F_ij^2), R the radius \
         of the sphere the lines cross. Paper / area-weighted: {}.",
        ratios.join(", ")
    ));
    t.notes.extend(capped_note(s, &[1_000_000, 10_000_000]));
    t.findings = table1_findings(s, &runs);
    Ok(t)
}

/// Table 1's claims: clustering lowers H_s and raises I_s; E(MSE) follows H_s; more lines raise H_s.
fn table1_findings(s: &Session, runs: &[Fig2Run]) -> Vec<Finding> {
    let counts = distinct(runs.iter().map(|x| x.1));
    let at = |p: char, l: u64| &runs.iter().find(|x| x.0 == p && x.1 == l).expect("ran").3;
    let (mut plug, mut corr, mut mse_order) = (true, true, true);
    let mut detail = Vec::new();
    for &l in &counts {
        let [a, b, c] = ['a', 'b', 'c'].map(|p| &at(p, l).v);
        let h = |f: Pick| [f(a), f(b), f(c)].map(val);
        let (hs, is) = (
            h(|v| v.of(Measure::Entropy)),
            h(|v| v.of(Measure::MutualInformation)),
        );
        let (hc, ic) = (
            h(|v| v.of(Measure::EntropyCorrected)),
            h(|v| v.of(Measure::MutualInformationCorrected)),
        );
        let clustered_lower =
            |x: [f64; 3], y: [f64; 3]| x[1] < x[0] && x[2] < x[0] && y[1] > y[0] && y[2] > y[0];
        plug &= clustered_lower(hs, is);
        corr &= clustered_lower(hc, ic);
        let mse = h(|v| v.of(Measure::MsePerLine));
        mse_order &= same_order(&hs, &mse);
        detail.push(format!(
            "{}: H_s a/b/c {} (corrected {}), I_s {} ({}), E(MSE) {}",
            lines_text(s.lines(l)),
            slash(&hs),
            slash(&hc),
            slash(&is),
            slash(&ic),
            mse.map(|m| format!("{m:.0}")).join("/")
        ));
    }
    let all: Vec<&Run> = runs.iter().map(|x| &x.3).collect();
    let mut findings = vec![
        finding_on(
            "clustered configurations (b, c) have lower H_s and higher I_s than the random one (a)",
            plug && corr,
            format!(
                "plug-in: {}, corrected: {}; {}",
                yes(plug),
                yes(corr),
                detail.join("; ")
            ),
            &all,
            &[
                Measure::Entropy,
                Measure::EntropyCorrected,
                Measure::MutualInformation,
                Measure::MutualInformationCorrected,
            ],
        ),
        finding_on(
            "the larger the entropy, the larger the E(MSE)",
            mse_order,
            "see the E(MSE) above".into(),
            &all,
            &[Measure::Entropy, Measure::MsePerLine],
        ),
    ];
    // Only meaningful when the two line counts still differ after `--lines`.
    if counts.len() > 1 && s.lines(counts[0]) != s.lines(counts[1]) {
        let more = ['a', 'b', 'c'].iter().all(|&p| {
            let (lo, hi) = (&at(p, counts[0]).v, &at(p, counts[1]).v);
            val(hi.of(Measure::Entropy)) > val(lo.of(Measure::Entropy))
                && val(hi.of(Measure::MutualInformation)) < val(lo.of(Measure::MutualInformation))
        });
        findings.push(finding_on(
            "more lines increase the (plug-in) H_s and decrease I_s",
            more,
            "each scene, 10x the lines".into(),
            &all,
            &[Measure::Entropy, Measure::MutualInformation],
        ));
    }
    findings
}

fn table2(s: &mut Session) -> Result<TableReport, ReproduceError> {
    let mut t = report(
        2,
        "fig. 3, empty cube with N x N patches per face (`@cube:10|20|30`)",
        &[
            "scene",
            "lines",
            "s",
            "H_s",
            "H_s corr.",
            "H_s paper",
            "I_s",
            "I_s corr.",
            "I_s paper",
            "I_s^c",
            "I_s^c paper",
        ],
    );
    let mut marks = Marks::default();
    let mut runs = Vec::new();
    for &(n, lines, hs, is, isc) in &published::TABLE2 {
        let r = s.run(&format!("@cube:{n}"), lines, Want::Visibility)?;
        let fig = ["3a", "3b", "3c"][n / 10 - 1];
        t.rows.push(vec![
            format!("Fig.{fig} ({n}x{n})"),
            lines_text(r.lines),
            secs(&r),
            marks.cell(&r, Measure::Entropy, 3),
            marks.cell(&r, Measure::EntropyCorrected, 3),
            hs.into(),
            marks.cell(&r, Measure::MutualInformation, 3),
            marks.cell(&r, Measure::MutualInformationCorrected, 3),
            is.into(),
            marks.cell(&r, Measure::ContinuousMutualInformation, 3),
            isc.into(),
        ]);
        runs.push((n, lines, r));
    }
    t.notes.append(&mut marks.notes);
    t.notes
        .extend(capped_note(s, &published::TABLE2.map(|r| r.1)));
    t.findings = table2_findings(s, &runs);
    Ok(t)
}

/// Table 2's claims: I_s^c ignores the mesh and bounds I_s; more lines raise H_s and lower I_s.
fn table2_findings(s: &Session, runs: &[(usize, u64, Run)]) -> Vec<Finding> {
    let mut findings = Vec::new();
    let all: Vec<&Run> = runs.iter().map(|x| &x.2).collect();
    let counts = distinct(runs.iter().map(|x| x.1));
    let at = |n: usize, l: u64| &runs.iter().find(|x| x.0 == n && x.1 == l).expect("ran").2.v;
    let same_isc = counts.iter().all(|&l| {
        let c = [10, 20, 30].map(|n| at(n, l).of(Measure::ContinuousMutualInformation));
        agree(c[0], c[1]) && agree(c[1], c[2]) && agree(c[0], c[2])
    });
    findings.push(finding_on(
        "I_s^c does not depend on the discretisation (the three meshes agree at every line count)",
        same_isc,
        "within 3 combined standard errors".into(),
        &all,
        &[Measure::ContinuousMutualInformation],
    ));
    let last = *counts.last().expect("three counts");
    let bound: Vec<String> = [10, 20, 30]
        .iter()
        .map(|&n| {
            let v = at(n, last);
            format!(
                "{n}x{n}: I_s {:.3} (corrected {:.3}) vs I_s^c {:.3}",
                val(v.of(Measure::MutualInformation)),
                val(v.of(Measure::MutualInformationCorrected)),
                val(v.of(Measure::ContinuousMutualInformation))
            )
        })
        .collect();
    let below = |f: Pick| {
        [10, 20, 30].iter().all(|&n| {
            val(f(at(n, last))) < val(at(n, last).of(Measure::ContinuousMutualInformation))
        })
    };
    let (plug, corr) = (
        below(|v| v.of(Measure::MutualInformation)),
        below(|v| v.of(Measure::MutualInformationCorrected)),
    );
    let at_last: Vec<&Run> = runs.iter().filter(|x| x.1 == last).map(|x| &x.2).collect();
    findings.push(finding_on(
        "I_s^c is an upper bound of I_s (Proposition 2), checked at the most lines",
        corr,
        format!(
            "corrected: {}, plug-in: {} (the plug-in I_s is biased upwards); {}",
            yes(corr),
            yes(plug),
            bound.join(", ")
        ),
        &at_last,
        &[
            Measure::MutualInformationCorrected,
            Measure::ContinuousMutualInformation,
        ],
    ));
    // Only meaningful when the line counts still differ after `--lines`.
    if distinct(counts.iter().map(|&l| s.lines(l))).len() == counts.len() {
        let more = [10, 20, 30].iter().all(|&n| {
            let h: Vec<f64> = counts
                .iter()
                .map(|&l| val(at(n, l).of(Measure::Entropy)))
                .collect();
            let i: Vec<f64> = counts
                .iter()
                .map(|&l| val(at(n, l).of(Measure::MutualInformation)))
                .collect();
            decreasing(&i) && h.windows(2).all(|w| w[0] < w[1])
        });
        findings.push(finding_on(
            "more lines increase the (plug-in) H_s and decrease I_s",
            more,
            "each mesh, over its three line counts".into(),
            &all,
            &[Measure::Entropy, Measure::MutualInformation],
        ));
    }
    findings
}

fn table3(s: &mut Session) -> Result<TableReport, ReproduceError> {
    let mut t = report(
        3,
        "fig. 2a, random placement of 512 cubes (`@fig2:a`): I_s needs many lines, I_s^c few",
        &[
            "lines",
            "s",
            "I_s",
            "I_s corr.",
            "I_s paper",
            "I_s^c",
            "I_s^c paper",
        ],
    );
    let mut marks = Marks::default();
    let mut runs = Vec::new();
    for &(lines, is, isc) in &published::TABLE3 {
        let r = s.run("@fig2:a", lines, Want::Visibility)?;
        t.rows.push(vec![
            lines_text(r.lines),
            secs(&r),
            marks.cell(&r, Measure::MutualInformation, 3),
            marks.cell(&r, Measure::MutualInformationCorrected, 3),
            is.into(),
            marks.cell(&r, Measure::ContinuousMutualInformation, 3),
            isc.into(),
        ]);
        runs.push(r);
    }
    t.notes.append(&mut marks.notes);
    t.notes
        .extend(capped_note(s, &published::TABLE3.map(|r| r.0)));
    let last = runs
        .last()
        .expect("four runs")
        .v
        .of(Measure::ContinuousMutualInformation);
    let cheap = runs
        .iter()
        .all(|r| agree(r.v.of(Measure::ContinuousMutualInformation), last));
    let all: Vec<&Run> = runs.iter().collect();
    t.findings.push(finding_on(
        "I_s^c is cheap: every line count gives it within 3 standard errors of the largest run",
        cheap,
        format!(
            "I_s^c {}",
            slash(
                &runs
                    .iter()
                    .map(|r| val(r.v.of(Measure::ContinuousMutualInformation)))
                    .collect::<Vec<_>>()
            )
        ),
        &all,
        &[Measure::ContinuousMutualInformation],
    ));
    let is: Vec<f64> = runs
        .iter()
        .map(|r| val(r.v.of(Measure::MutualInformation)))
        .collect();
    if distinct(runs.iter().map(|r| r.lines)).len() == runs.len() {
        t.findings.push(finding_on(
            "I_s is expensive: the plug-in I_s keeps falling as lines are added",
            decreasing(&is),
            format!("I_s {}", slash(&is)),
            &all,
            &[Measure::MutualInformation],
        ));
    }
    Ok(t)
}

/// Table 4's scenes: the paper's name and ours.
const TABLE4_SCENES: [&str; 7] = [
    "@sphere:5",
    "@icosahedron",
    "@dodecahedron",
    "@octahedron",
    "@cube",
    "@tetrahedron",
    "@cornell",
];

fn table4(s: &mut Session) -> Result<TableReport, ReproduceError> {
    let mut t = report(
        4,
        "continuous mutual information of the regular solids, a sphere and the Cornell box",
        &["scene", "scx scene", "lines", "s", "I_s^c", "I_s^c paper"],
    );
    let mut marks = Marks::default();
    let mut runs = Vec::new();
    let mut isc = Vec::new();
    for (&(name, value), spec) in published::TABLE4.iter().zip(TABLE4_SCENES) {
        let r = s.run(spec, published::TABLE45_LINES, Want::Continuous)?;
        let c = r.v.of(Measure::ContinuousMutualInformation);
        t.rows.push(vec![
            name.into(),
            format!("`{spec}`"),
            lines_text(r.lines),
            secs(&r),
            marks.cell(&r, Measure::ContinuousMutualInformation, 4),
            value.into(),
        ]);
        isc.push(c);
        runs.push(r);
    }
    t.notes.append(&mut marks.notes);
    t.notes.push(
        "The sphere is the icosphere `@sphere:5` (20480 triangles), whose I_s^c tends to the sphere's 0 as it \
         is subdivided; `@cornell` is the closed box (see `scx scenes`)."
            .into(),
    );
    t.notes.extend(capped_note(s, &[published::TABLE45_LINES]));
    let solids: Vec<f64> = isc[..6].iter().map(|&e| val(e)).collect();
    let ranked = solids.windows(2).all(|w| w[0] < w[1]);
    let isc_only = [Measure::ContinuousMutualInformation];
    let solid_runs: Vec<&Run> = runs[..6].iter().collect();
    t.findings.push(finding_on(
        "I_s^c ranks sphere < icosahedron < dodecahedron < octahedron < cube < tetrahedron",
        ranked,
        format!("I_s^c {}", slash(&solids)),
        &solid_runs,
        &isc_only,
    ));
    t.findings.push(finding_on(
        "the Cornell box is clearly more complex than the empty cube",
        val(isc[6]) > val(isc[4]),
        format!("{:.3} vs {:.3}", val(isc[6]), val(isc[4])),
        &[&runs[6], &runs[4]],
        &isc_only,
    ));
    Ok(t)
}

fn table5(s: &mut Session) -> Result<TableReport, ReproduceError> {
    let mut t = report(
        5,
        "fig. 4, tables with four chairs in a room (`@fig4:a..f`)",
        &["scene", "lines", "s", "I_s^c", "I_s^c paper"],
    );
    let mut marks = Marks::default();
    let mut runs = Vec::new();
    let mut isc = Vec::new();
    for &(p, value) in &published::TABLE5 {
        let r = s.run(
            &format!("@fig4:{p}"),
            published::TABLE45_LINES,
            Want::Continuous,
        )?;
        let c = r.v.of(Measure::ContinuousMutualInformation);
        t.rows.push(vec![
            format!("4{p}"),
            lines_text(r.lines),
            secs(&r),
            marks.cell(&r, Measure::ContinuousMutualInformation, 3),
            value.into(),
        ]);
        isc.push(c);
        runs.push(r);
    }
    t.notes.append(&mut marks.notes);
    t.notes.push(
        "a: one group in the middle; b: 2 x 2 in the middle; c: 4 x 4 in the middle; d: 4 x 4 spread \
         evenly; e: four 2 x 2 blocks in the corners; f: 16 along the walls (our layouts, `scx scenes`)."
            .into(),
    );
    t.notes.extend(capped_note(s, &[published::TABLE45_LINES]));
    let v: Vec<f64> = isc.iter().map(|&e| val(e)).collect();
    let isc_only = [Measure::ContinuousMutualInformation];
    t.findings.push(finding_on(
        "introducing objects increases the complexity (a < b < c)",
        v[0] < v[1] && v[1] < v[2],
        format!("I_s^c a/b/c {}", slash(&v[..3])),
        &runs[..3].iter().collect::<Vec<_>>(),
        &isc_only,
    ));
    let spread = |x: &[f64]| {
        x.iter().cloned().fold(f64::MIN, f64::max) - x.iter().cloned().fold(f64::MAX, f64::min)
    };
    let paper_v: Vec<f64> = published::TABLE5
        .iter()
        .map(|r| r.1.parse().unwrap_or(f64::NAN))
        .collect();
    t.findings.push(finding_on(
        "objects near the walls increase the complexity (e and f, near the walls, above c, in the middle)",
        v[4] > v[2] && v[5] > v[2],
        format!(
            "c {} e {} f {}; c..f span {:.3} (paper {:.3})",
            est(isc[2], 3),
            est(isc[4], 3),
            est(isc[5], 3),
            spread(&v[2..]),
            spread(&paper_v[2..])
        ),
        &[&runs[2], &runs[4], &runs[5]],
        &isc_only,
    ));
    Ok(t)
}

fn table67(s: &mut Session, number: u8) -> Result<TableReport, ReproduceError> {
    let (fig, data, what) = if number == 6 {
        (
            "5",
            &published::TABLE6,
            "cubes finer: faces 2 x 2, walls 8 x 8",
        )
    } else {
        (
            "6",
            &published::TABLE7,
            "walls finer: faces 1 x 1, walls 16 x 16",
        )
    };
    let mut t = report(
        number,
        &format!(
            "fig. {fig}, 64 cubes from the centre (a) to the walls (f), {what} (`@fig{fig}:a..f`)"
        ),
        &[
            "scene",
            "lines",
            "s",
            "I_s",
            "I_s corr.",
            "I_s paper",
            "I_s^c",
            "I_s^c paper",
            "I_s/I_s^c",
            "corr.",
            "paper",
        ],
    );
    let mut marks = Marks::default();
    let mut runs = Vec::new();
    for (k, &(is, isc, acc)) in data.iter().enumerate() {
        let stage = "abcdef".as_bytes()[k] as char;
        let r = s.run(
            &format!("@fig{fig}:{stage}"),
            published::TABLE67_LINES,
            Want::Visibility,
        )?;
        t.rows.push(vec![
            format!("Fig.{fig}{stage}"),
            lines_text(r.lines),
            secs(&r),
            marks.cell(&r, Measure::MutualInformation, 3),
            marks.cell(&r, Measure::MutualInformationCorrected, 3),
            is.into(),
            marks.cell(&r, Measure::ContinuousMutualInformation, 3),
            isc.into(),
            marks.cell(&r, Measure::Accuracy, 3),
            marks.cell(&r, Measure::AccuracyCorrected, 3),
            acc.into(),
        ]);
        runs.push(r);
    }
    t.notes.append(&mut marks.notes);
    t.notes.extend(capped_note(s, &[published::TABLE67_LINES]));
    let isc: Vec<f64> = runs
        .iter()
        .map(|r| val(r.v.of(Measure::ContinuousMutualInformation)))
        .collect();
    let extremes_complex = isc[1..5].iter().all(|&m| m < isc[0] && m < isc[5]);
    let all: Vec<&Run> = runs.iter().collect();
    t.findings.push(finding_on(
        "the extreme stages (a, f) are the most complex (highest I_s^c)",
        extremes_complex,
        format!("I_s^c a..f {}", slash(&isc)),
        &all,
        &[Measure::ContinuousMutualInformation],
    ));
    let middle_best = |acc: &[f64]| {
        let worst_middle = acc[1..5].iter().cloned().fold(f64::INFINITY, f64::min);
        worst_middle > acc[0] && worst_middle > acc[5]
    };
    let acc: Vec<f64> = runs
        .iter()
        .map(|r| val(r.v.of(Measure::Accuracy)))
        .collect();
    let acc_c: Vec<f64> = runs
        .iter()
        .map(|r| val(r.v.of(Measure::AccuracyCorrected)))
        .collect();
    let (plug, corr) = (middle_best(&acc), middle_best(&acc_c));
    t.findings.push(finding_on(
        "the middle stages (b-e) have the highest accuracy I_s/I_s^c and the extreme ones (a, f) the lowest",
        plug && corr,
        format!(
            "plug-in: {} ({}), corrected: {} ({})",
            yes(plug),
            slash(&acc),
            yes(corr),
            slash(&acc_c)
        ),
        &all,
        &[Measure::Accuracy, Measure::AccuracyCorrected],
    ));
    if number == 7 {
        t.findings.push(compare_meshes(s, &runs)?);
    }
    Ok(t)
}

/// Fig. 5a against 6a and 6f against 5f: the finer cubes win when the cubes are close together, the finer
/// walls when the cubes are near the walls.
fn compare_meshes(s: &mut Session, fig6: &[Run]) -> Result<Finding, ReproduceError> {
    let a5 = s.run("@fig5:a", published::TABLE67_LINES, Want::Visibility)?;
    let f5 = s.run("@fig5:f", published::TABLE67_LINES, Want::Visibility)?;
    let wins = |f: Pick| val(f(&a5.v)) > val(f(&fig6[0].v)) && val(f(&fig6[5].v)) > val(f(&f5.v));
    let (plug, corr) = (
        wins(|v| v.of(Measure::Accuracy)),
        wins(|v| v.of(Measure::AccuracyCorrected)),
    );
    Ok(finding_on(
        "5a (cubes finer) is more accurate than 6a, and 6f (walls finer) more accurate than 5f",
        plug && corr,
        format!(
            "plug-in: {}, corrected: {}; accuracy 5a {:.3} 6a {:.3}, 5f {:.3} 6f {:.3}",
            yes(plug),
            yes(corr),
            val(a5.v.of(Measure::Accuracy)),
            val(fig6[0].v.of(Measure::Accuracy)),
            val(f5.v.of(Measure::Accuracy)),
            val(fig6[5].v.of(Measure::Accuracy))
        ),
        &[&a5, &fig6[0], &f5, &fig6[5]],
        &[Measure::Accuracy, Measure::AccuracyCorrected],
    ))
}

fn table8(s: &mut Session) -> Result<TableReport, ReproduceError> {
    let mut t = report(
        8,
        "fig. 9, the labyrinth with R_i + E_i = 1 on every patch (`@labyrinth`)",
        &[
            "",
            "lines",
            "s",
            "H_p",
            "H_p paper",
            "H_s",
            "H_s corr.",
            "H_s paper",
            "I_s",
            "I_s corr.",
            "I_s paper",
        ],
    );
    let mut marks = Marks::default();
    let r = s.run("@labyrinth", super::UNSTATED_LINES, Want::Radiosity)?;
    let v = &r.v;
    let (ph, ps, pi) = published::TABLE8_VISIBILITY;
    t.rows.push(vec![
        "Visibility".into(),
        lines_text(r.lines),
        secs(&r),
        marks.cell(&r, Measure::PositionalEntropy, 4),
        ph.into(),
        marks.cell(&r, Measure::Entropy, 5),
        marks.cell(&r, Measure::EntropyCorrected, 5),
        ps.into(),
        marks.cell(&r, Measure::MutualInformation, 5),
        marks.cell(&r, Measure::MutualInformationCorrected, 5),
        pi.into(),
    ]);
    let Some(rad) = &r.radiosity else {
        t.notes.append(&mut marks.notes);
        t.notes
            .push("The radiosity measures could not be computed.".into());
        return Ok(t);
    };
    let (qh, qs, qi) = published::TABLE8_RADIOSITY;
    t.rows.push(vec![
        "Radiosity".into(),
        lines_text(r.lines),
        "(same run)".into(),
        marks.cell(&r, Measure::RadiosityPositionalEntropy, 4),
        qh.into(),
        marks.cell(&r, Measure::RadiosityEntropy, 5),
        marks.cell(&r, Measure::RadiosityEntropyCorrected, 5),
        qs.into(),
        marks.cell(&r, Measure::RadiosityMutualInformation, 5),
        marks.cell(&r, Measure::RadiosityMutualInformationCorrected, 5),
        qi.into(),
    ]);
    t.notes.append(&mut marks.notes);
    t.notes.push(format!(
        "The paper does not give its line count; ours is {}. Our labyrinth has {} equal patches (H_p = \
         log2 {}); the paper's 10.6883 is log2 1650.",
        lines_text(r.lines),
        r.patches,
        r.patches
    ));
    let pairs = [
        (
            v.of(Measure::PositionalEntropy),
            rad.of(Measure::RadiosityPositionalEntropy),
        ),
        (v.of(Measure::Entropy), rad.of(Measure::RadiosityEntropy)),
        (
            v.of(Measure::EntropyCorrected),
            rad.of(Measure::RadiosityEntropyCorrected),
        ),
        (
            v.of(Measure::MutualInformation),
            rad.of(Measure::RadiosityMutualInformation),
        ),
        (
            v.of(Measure::MutualInformationCorrected),
            rad.of(Measure::RadiosityMutualInformationCorrected),
        ),
    ];
    let gap = pairs
        .iter()
        .map(|(a, b)| (val(*a) - val(*b)).abs())
        .fold(0.0, f64::max);
    // The identity is exact when every form-factor row sums to 1; a segment escaping through a grazing
    // hit (a line exactly through an edge) leaves its row short and B a hair below 1. The paper's own
    // two rows differ by up to 0.004.
    t.findings.push(finding_on(
        "with constant radiosity (R_i + E_i = 1) the radiosity measures equal the visibility measures",
        gap <= 1e-4,
        format!(
            "largest difference {gap:.1e} bits; {} of {} segments escaped through grazing hits",
            r.escapes,
            r.escapes + r.pairs
        ),
        &[&r],
        &[
            Measure::PositionalEntropy,
            Measure::Entropy,
            Measure::EntropyCorrected,
            Measure::MutualInformation,
            Measure::MutualInformationCorrected,
            Measure::RadiosityPositionalEntropy,
            Measure::RadiosityEntropy,
            Measure::RadiosityEntropyCorrected,
            Measure::RadiosityMutualInformation,
            Measure::RadiosityMutualInformationCorrected,
        ],
    ));
    Ok(t)
}

fn table9(s: &mut Session) -> Result<TableReport, ReproduceError> {
    let mut t = report(
        9,
        "fig. 10, radiosity measures of Cornell box meshes made by `scx refine` (`@cornell`)",
        &[
            "fig.",
            "mesh",
            "patches",
            "paper",
            "refine lines",
            "refine s",
            "lines",
            "s",
            "H_p",
            "H_p paper",
            "H_s",
            "H_s corr.",
            "H_s paper",
            "I_s",
            "I_s corr.",
            "I_s paper",
        ],
    );
    let base = scenes::load("@cornell")?;
    let mut marks = Marks::default();
    let mut runs = Vec::new();
    let mut mi = Vec::new();
    for &(fig, mesh, patches, lines, hp, hs, is) in &published::TABLE9 {
        let strategy = match mesh {
            "uniform" => Strategy::Uniform,
            "power" => Strategy::Power,
            _ => Strategy::Smoothness,
        };
        let (refined, refine_lines, refine_s) = refine_cornell(s, &base, strategy, patches)?;
        let r = s.run_scene(&refined, s.lines(lines), Want::Radiosity)?;
        let Some(rad) = r.radiosity.clone() else {
            continue;
        };
        t.rows.push(vec![
            fig.to_string(),
            mesh.into(),
            r.patches.to_string(),
            patches.to_string(),
            lines_text(refine_lines),
            format!("{refine_s:.2}"),
            lines_text(r.lines),
            secs(&r),
            marks.cell(&r, Measure::RadiosityPositionalEntropy, 2),
            hp.into(),
            marks.cell(&r, Measure::RadiosityEntropy, 2),
            marks.cell(&r, Measure::RadiosityEntropyCorrected, 2),
            hs.into(),
            marks.cell(&r, Measure::RadiosityMutualInformation, 3),
            marks.cell(&r, Measure::RadiosityMutualInformationCorrected, 3),
            is.into(),
        ]);
        mi.push((
            mesh,
            val(rad.of(Measure::RadiosityMutualInformation)),
            val(rad.of(Measure::RadiosityMutualInformationCorrected)),
        ));
        runs.push(r);
    }
    t.notes.append(&mut marks.notes);
    t.notes.push(format!(
        "Meshes: `scx refine @cornell --strategy uniform|power|smoothness --patches N` (rounds of {} lines, \
         growth 1.5) to the paper's patch counts; measures: `scx analyze` with the lines in the table.",
        lines_text(s.lines(super::REFINE_LINES))
    ));
    t.notes.extend(capped_note(s, &[16_500_000, 41_200_000]));
    if mi.len() == 6 {
        let all: Vec<&Run> = runs.iter().collect();
        let flagged = flagged_among(
            &all,
            &[
                Measure::RadiosityMutualInformation,
                Measure::RadiosityMutualInformationCorrected,
            ],
        );
        t.findings
            .extend(table9_findings(&mi).into_iter().map(|f| Finding {
                flagged: flagged.clone(),
                ..f
            }));
    }
    Ok(t)
}

/// Refines `@cornell` with `strategy` to `patches` patches: the mesh, the lines cast and the seconds.
fn refine_cornell(
    s: &mut Session,
    base: &Scene,
    strategy: Strategy,
    patches: usize,
) -> Result<(Scene, u64, f64), ReproduceError> {
    let start = Instant::now();
    let backend = s.cfg.backend;
    let cfg = RefineConfig {
        strategy,
        target_patches: patches,
        lines_per_round: s.lines(super::REFINE_LINES),
        seed: s.cfg.seed,
        growth: 1.5,
        solve: SolveOptions::default(),
    };
    let tracer_for = |sc: &Scene| make_tracer(backend, sc, Query::Single);
    let refined = refine(
        base,
        &tracer_for,
        &cfg,
        &crate::run::RunControl::default(),
        &mut |_| {},
    )?;
    let lines: u64 = refined.rounds.iter().map(|r| r.lines).sum();
    let seconds = start.elapsed().as_secs_f64();
    s.lines_cast += lines;
    (s.log)(&format!(
        "@cornell refined ({strategy}) to {} patches: {} lines, {seconds:.1} s",
        refined.scene.patch_count(),
        lines_text(lines)
    ));
    Ok((refined.scene, lines, seconds))
}

/// Table 9's claims from `(mesh, I_s, corrected I_s)` in the paper's row order (3 coarse, 3 fine).
fn table9_findings(mi: &[(&str, f64, f64)]) -> Vec<Finding> {
    let finer = |k: usize| -> (bool, bool) { (mi[k + 3].1 > mi[k].1, mi[k + 3].2 > mi[k].2) };
    let (plug, corr) = (0..3).fold((true, true), |acc, k| {
        let f = finer(k);
        (acc.0 && f.0, acc.1 && f.1)
    });
    let list = |r: std::ops::Range<usize>, c: fn(&(&str, f64, f64)) -> f64| {
        mi[r]
            .iter()
            .map(|m| format!("{} {:.3}", m.0, c(m)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let uniform_worst = |c: fn(&(&str, f64, f64)) -> f64| {
        [0, 3]
            .iter()
            .all(|&k| c(&mi[k]) < c(&mi[k + 1]) && c(&mi[k]) < c(&mi[k + 2]))
    };
    let (uw_plug, uw_corr) = (uniform_worst(|m| m.1), uniform_worst(|m| m.2));
    vec![
        finding(
            "a finer mesh is a better mesh: I_s grows from ~460 to ~1150 patches for every strategy",
            plug && corr,
            format!("plug-in: {}, corrected: {}", yes(plug), yes(corr)),
        ),
        finding(
            "among equally fine meshes the uniform one has the lowest I_s",
            uw_plug && uw_corr,
            format!(
                "plug-in: {} ({}; {}), corrected: {} ({}; {})",
                yes(uw_plug),
                list(0..3, |m| m.1),
                list(3..6, |m| m.1),
                yes(uw_corr),
                list(0..3, |m| m.2),
                list(3..6, |m| m.2)
            ),
        ),
    ]
}
