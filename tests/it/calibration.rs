//! The calibration suite's `small` level (`scx calibrate --suite small`, docs/calibration.md), run once
//! and shared by the tests below, against exact values: closed-form form factors and quadrature, each
//! checked here against the tests' own closed forms (`support.rs`, written independently of the
//! library's) before the runs are judged by them.
//!
//! The seeds are fixed, so the numbers are the same on every machine; the bounds leave 4 binomial
//! standard errors below 95% (3.8 points with 200 runs), so that they fail on a change of estimator or
//! standard error that loses coverage, not on the luck of the seeds.

use std::sync::OnceLock;

use scene_complexity::calibrate::kernel::Precision;
use scene_complexity::calibrate::scenes::Solid;
use scene_complexity::calibrate::truth::{convex_pair_sums, cube_pair_sums};
use scene_complexity::calibrate::{
    run_cells, suite, truth, Basis, CalibrationScene, CellReport, SuiteLevel, Summary,
};
use scene_complexity::{Backend, Measure};

use crate::support::{cube_exact_measures, ff_parallel_rectangles, ff_perpendicular_rectangles};

/// The small suite's reports, run once for every test of this module (about 25 s on two idle cores).
fn small() -> &'static [CellReport] {
    static REPORTS: OnceLock<Vec<CellReport>> = OnceLock::new();
    REPORTS.get_or_init(|| {
        run_cells(&suite(SuiteLevel::Small), Backend::Rust, &mut |_| {})
            .expect("the small suite runs")
    })
}

/// The small suite's cell of `scene`, with or without a precision target.
fn cell(scene: &str, target: bool) -> &'static CellReport {
    small()
        .iter()
        .find(|r| r.cell.scene.name() == scene && r.cell.target.is_some() == target)
        .unwrap_or_else(|| panic!("the small suite has no cell of {scene} (target: {target})"))
}

fn summary(report: &CellReport, measure: Measure, basis: Basis) -> &Summary {
    report
        .summary(measure, basis)
        .unwrap_or_else(|| panic!("{measure:?} ({basis:?}) was not summarised"))
}

/// The lowest coverage of a 95% interval over `runs` runs that is not a loss of coverage: 4 binomial
/// standard errors below 95%.
fn floor(runs: usize) -> f64 {
    0.95 - 4.0 * (0.95 * 0.05 / runs as f64).sqrt()
}

/// The basis the program reads a scene on: the closed one, or per area (it counts the segments lost to
/// escapes and back sides in every row and in eq. (27)'s denominator).
fn programs_basis(report: &CellReport) -> Basis {
    if report.cell.scene.is_closed() {
        Basis::Closed
    } else {
        Basis::PerArea
    }
}

/// The exact H_s and I_s of `@cube:N` equal the tests' own closed-form ones; I_s^c of the unit cube by
/// the triangle quadrature over `@cube:1` equals the hand reduction over squares, and is the paper's
/// 1.6093 (Table 4, 10^6 lines) within its Monte Carlo error.
#[test]
fn exact_values_agree_with_independent_closed_forms_and_quadrature() {
    for n in [1, 4, 7] {
        let t = truth(&CalibrationScene::Cube(n)).unwrap();
        let (h_s, i_s) = cube_exact_measures(n);
        let closed = |m| t.value(m, Basis::Closed).unwrap();
        assert!((closed(Measure::Entropy) - h_s).abs() < 1e-12, "N = {n}");
        assert!(
            (closed(Measure::MutualInformation) - i_s).abs() < 1e-12,
            "N = {n}"
        );
    }
    let faces = CalibrationScene::Cube(1).build().unwrap();
    let by_triangles = convex_pair_sums(&faces, Precision::FINE)
        .unwrap()
        .per_area();
    let by_squares = cube_pair_sums().per_area();
    assert!(
        (by_triangles - by_squares).abs() < 1e-12,
        "{by_triangles} vs {by_squares}"
    );
    assert!((by_squares - 1.6093).abs() < 2e-3, "{by_squares}");
    // The tetrahedron's faces see each other equally (F = 1/3), by quadrature.
    let t = truth(&CalibrationScene::Solid(Solid::Tetrahedron, 1)).unwrap();
    let log3 = 3f64.log2();
    assert!((t.value(Measure::Entropy, Basis::Closed).unwrap() - log3).abs() < 1e-12);
}

/// The open and flipped scenes' exact values per area, from the tests' own closed-form form factors:
/// two facing squares (F = F_par both ways, rows summing to F), and the cube whose face x = 0 is turned
/// round (the other faces' rows lose their entry to it, its own row is empty).
#[test]
fn exact_values_of_the_open_scenes_follow_their_form_factors() {
    let h = |x: f64| -x * x.log2();
    let f = ff_parallel_rectangles(1.0, 1.0, 1.0);
    let squares = truth(&CalibrationScene::ParallelSquares {
        patches: 1,
        distance: 1.0,
    })
    .unwrap();
    let per_area = |m| squares.value(m, Basis::PerArea).unwrap();
    assert!((per_area(Measure::Entropy) - h(f)).abs() < 1e-12);
    assert!((per_area(Measure::MutualInformation) - f * (2.0 * f).log2()).abs() < 1e-12);
    assert!((per_area(Measure::MsePerLine) - (2.0 - 2.0 * f * f)).abs() < 1e-12);
    let (fp, fq) = (f, ff_perpendicular_rectangles(1.0, 1.0, 1.0));
    let flipped = truth(&CalibrationScene::FlippedCube(1)).unwrap();
    let expected = (4.0 * h(fq) + 4.0 * (3.0 * h(fq) + h(fp))) / 6.0;
    let got = flipped.value(Measure::Entropy, Basis::PerArea).unwrap();
    assert!((got - expected).abs() < 1e-12, "{got} vs {expected}");
}

/// I_s^c, a mean of independent terms, covers its exact value at the stated rate in every cell of fixed
/// lines (Student's t for 15 degrees of freedom), with mean z near 0 and sd z near 1.07 (t's).
#[test]
fn continuous_mutual_information_covers_its_exact_value() {
    for report in small().iter().filter(|r| r.cell.target.is_none()) {
        let s = summary(
            report,
            Measure::ContinuousMutualInformation,
            programs_basis(report),
        );
        assert!(s.coverage().unwrap() >= floor(s.runs), "{s:?}");
        assert!(s.mean_z.abs() < 0.3, "{s:?}");
        assert!((0.85..1.3).contains(&s.sd_z), "{s:?}");
    }
}

/// On `@cube:4` at 1e5 lines (about 150 segments per row of 96 patches) the plug-in H_s and I_s are off
/// by several standard errors and never `ok`, E(MSE) by about one; the bias-corrected readings cover and
/// are `ok`.
#[test]
fn the_corrected_readings_of_an_undersampled_mesh_cover_and_the_plug_in_ones_do_not() {
    let report = cell("@cube:4", false);
    for measure in [
        Measure::EntropyCorrected,
        Measure::MutualInformationCorrected,
        Measure::AccuracyCorrected,
        Measure::MsePerLineCorrected,
    ] {
        let s = summary(report, measure, Basis::Closed);
        assert!(s.coverage().unwrap() >= floor(s.runs), "{s:?}");
        assert_eq!(s.ok, s.runs, "{s:?}");
    }
    // E(MSE)'s plug-in reads low (it sums the rows' plug-in F^2, biased up) and says so; its unbiased
    // estimate sits on the exact value.
    let plug_in = summary(report, Measure::MsePerLine, Basis::Closed);
    assert!(plug_in.mean_z < -0.8, "{plug_in:?}");
    assert!(plug_in.ok * 10 <= plug_in.runs, "{plug_in:?}");
    let corrected = summary(report, Measure::MsePerLineCorrected, Basis::Closed);
    assert!(corrected.mean_z.abs() < 0.3, "{corrected:?}");
    for measure in [Measure::MutualInformation, Measure::Accuracy] {
        let s = summary(report, measure, Basis::Closed);
        assert!(s.mean_z > 3.0, "{s:?}");
        assert_eq!(s.ok, 0, "{s:?}");
    }
}

/// The promise of the verdict: in the cells of fixed lines, the `ok` readings of every measure (with at
/// least 20 of them) cover at the stated rate, on the footing the program reads the scene on.
#[test]
fn ok_readings_cover_at_the_stated_rate() {
    for report in small().iter().filter(|r| r.cell.target.is_none()) {
        let basis = programs_basis(report);
        for s in report.summaries.iter().filter(|s| s.basis == basis) {
            if s.ok >= 20 {
                assert!(s.ok_coverage().unwrap() >= floor(s.ok), "{s:?}");
            }
        }
    }
}

/// Open scenes and a face seen from behind are read per area (eqs. 3, 17, 21, 25 as written: the lost
/// segments count in every row and in eq. (27)'s denominator): every measure covers its per-area exact
/// value, and the other footing, the channel of the visible pairs, is many standard errors away.
#[test]
fn open_scenes_and_a_flipped_face_are_read_per_area() {
    for scene in [
        "two-squares:parallel:1",
        "two-squares:perpendicular:1",
        "flipped-cube:1",
    ] {
        let report = cell(scene, false);
        for measure in [
            Measure::EntropyCorrected,
            Measure::MutualInformationCorrected,
            Measure::ContinuousMutualInformation,
            Measure::MsePerLine,
        ] {
            let s = summary(report, measure, Basis::PerArea);
            assert!(s.coverage().unwrap() >= floor(s.runs), "{scene}: {s:?}");
            // No bias beyond a small share of the error bar, allowing for the mean's own noise over
            // the seeds: the corrected I_s per area reads a true mean z of -0.18 to -0.27 here (1000
            // seeds, through the sphere or the box), so 200 seeds read -0.42 in one draw of them.
            let noise = 3.0 * s.sd_z / (s.runs as f64).sqrt();
            assert!(s.mean_z.abs() < 0.3 + noise, "{scene}: {s:?}");
        }
        for measure in [
            Measure::MutualInformationCorrected,
            Measure::ContinuousMutualInformation,
        ] {
            let s = summary(report, measure, Basis::PerVisiblePair);
            assert!(s.mean_z.abs() > 10.0, "{scene}: {s:?}");
        }
    }
}

/// The radiosity measures of the lit cube against the system solved on exact form factors.
#[test]
fn the_lit_cubes_radiosity_measures_cover() {
    let report = cell("lit-cube:1", false);
    for measure in [
        Measure::RadiosityPositionalEntropy,
        Measure::RadiosityEntropyCorrected,
        Measure::RadiosityMutualInformationCorrected,
    ] {
        let s = summary(report, measure, Basis::Closed);
        assert!(s.coverage().unwrap() >= floor(s.runs), "{measure:?}: {s:?}");
        assert!(s.mean_z.abs() < 0.3, "{measure:?}: {s:?}");
    }
}

/// Precision targets, on I_s^c alone and on the corrected I_s: every run meets its target before its cap,
/// and the runs that meet it cover.
///
/// Known shortfall: a run stops when its *estimated* standard error is below the target, so the runs
/// that stop are more often those whose error is estimated low (and, for the skewed terms of eq. 27,
/// whose value is low with it). On I_s^c alone (target 0.005) the met runs cover 87-89% with sd z 1.2-1.3,
/// against 92-96% at fixed lines, with the checks at geometric line counts as with those at every
/// round. Hence 0.8 here rather than the binomial floor; tighten it when the stopping rule allows for
/// its own choice.
#[test]
fn precision_targets_are_met_and_the_runs_that_meet_them_cover() {
    for report in small().iter().filter(|r| r.cell.target.is_some()) {
        let target = report.cell.target.unwrap();
        let s = summary(report, target.measure, Basis::Closed);
        let (met, met_covered) = s
            .met
            .expect("the watched measure counts the runs that met it");
        assert_eq!(met, s.runs, "every run meets its target: {s:?}");
        assert!(met_covered as f64 / met as f64 >= 0.8, "{s:?}");
        assert!(
            report.runs.iter().all(|r| r.lines < report.cell.lines),
            "the target stops the runs before the cap: {s:?}"
        );
        assert!(
            s.mean_stderr <= target.stderr,
            "the runs reach the standard error asked for: {s:?}"
        );
    }
}

/// `scx calibrate --groups G` runs what `scx analyze --groups G` runs: each seed's I_s^c is analyze's,
/// to the bit, the readings name the groups, and the table names the degrees of freedom they give.
#[cfg(feature = "cli")]
#[test]
fn calibration_runs_take_the_groups_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let readings = dir.path().join("r.csv");
    let common = [
        "--lines",
        "2e4",
        "--sampler",
        "sobol",
        "--measures",
        "continuous",
    ];
    let out = crate::support::scx(
        &[
            &["calibrate", "--scene", "@octahedron", "--seeds", "2"][..],
            &common[..],
            &["--groups", "4", "--readings", readings.to_str().unwrap()][..],
        ]
        .concat(),
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("| 2 (3 dof) | I_s^c |"), "{stdout}");
    let rows = std::fs::read_to_string(&readings).unwrap();
    for seed in ["1", "2"] {
        let row: Vec<&str> = rows
            .lines()
            .map(|l| l.split(',').collect::<Vec<_>>())
            .find(|r| r[2] == seed && r[6] == "continuous_mutual_information")
            .unwrap_or_else(|| panic!("seed {seed}: {rows}"));
        assert_eq!(row[4], "4", "groups of seed {seed}: {row:?}");
        let analyze = crate::support::scx(
            &[
                &["analyze", "@octahedron", "--seed", seed, "--groups", "4"][..],
                &common[..],
                &["--format", "csv"][..],
            ]
            .concat(),
        );
        let report = String::from_utf8_lossy(&analyze.stdout);
        let value: f64 = report
            .lines()
            .find(|l| l.contains(",continuous_mutual_information,"))
            .and_then(|l| l.split(',').nth(10))
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("{report}"));
        let reading: f64 = row[7].parse().unwrap();
        assert_eq!(
            reading.to_bits(),
            value.to_bits(),
            "seed {seed}: {row:?} against {report}"
        );
    }
}

/// `scx calibrate` prints the table with its multipliers and writes the CSV files; a scene without exact
/// values is bad input (exit code 2).
#[cfg(feature = "cli")]
#[test]
fn the_command_prints_the_table_and_writes_csv() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, readings) = (dir.path().join("t.csv"), dir.path().join("r.csv"));
    let out = crate::support::scx(&[
        "calibrate",
        "--scene",
        "@tetrahedron:1,two-squares:perpendicular",
        "--lines",
        "2e4",
        "--seeds",
        "3",
        "--threads",
        "2",
        "--csv",
        csv.to_str().unwrap(),
        "--readings",
        readings.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("2.131 for the default 16") && stdout.contains("normal 1.96"),
        "{stdout}"
    );
    assert!(
        stdout.contains("| `@tetrahedron:1` | 2e4 | 3 | I_s^c | 2.619458 |"),
        "{stdout}"
    );
    assert!(stdout.contains("I_s^c (per visible pair)"), "{stdout}");
    let table = std::fs::read_to_string(&csv).unwrap();
    assert!(table.starts_with("scene,lines,"), "{table}");
    assert!(table.contains("@tetrahedron:1,20000,,,3,"), "{table}");
    let rows = std::fs::read_to_string(&readings).unwrap();
    // 3 seeds of each scene, one row per reading.
    assert_eq!(
        rows.lines()
            .filter(|l| l.contains(",continuous_mutual_information,"))
            .count(),
        6
    );
    let bad = crate::support::scx(&["calibrate", "--scene", "@sphere:2"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("exact values"));
    // Parameters the scene cannot take are bad input before the table starts (they were an internal
    // error, exit 101, and an error after the table's header).
    for (scene, says) in [
        ("@cube:3000", "from 1 to 2000"),
        ("two-squares:parallel:2:1e9", "no faces of non-zero area"),
        // Scenes whose exact values are beyond reach (6 n^4 form factors: @cube:200 would take
        // hours; its rows alone were 77 GB), refused before the table, not after its first cells.
        ("@cube:200", "up to N = 100"),
        ("flipped-cube:30", "5400 patches"),
        ("lit-cube:30", "at most 2000"),
    ] {
        let bad = crate::support::scx(&["calibrate", "--scene", scene, "--seeds", "2"]);
        let stderr = String::from_utf8_lossy(&bad.stderr);
        assert_eq!(bad.status.code(), Some(2), "{scene}: {stderr}");
        assert!(
            stderr.contains(says) && !stderr.contains("internal error"),
            "{stderr}"
        );
        assert!(bad.stdout.is_empty(), "{scene}");
    }
    // Options of `--scene`'s cells are refused without it (the suite's cells went on unchanged).
    for option in [
        ["--lines", "1e3"],
        ["--seeds", "5"],
        ["--first-seed", "7"],
        ["--measures", "continuous"],
    ] {
        let args = [&["calibrate", "--list"][..], &option[..]].concat();
        let bad = crate::support::scx(&args);
        let stderr = String::from_utf8_lossy(&bad.stderr);
        assert_eq!(bad.status.code(), Some(2), "{option:?}: {stderr}");
        assert!(stderr.contains("--scene"), "{stderr}");
    }
}

/// A cell's runs are `scx analyze`'s: its lines are the sphere's, `auto` draws them through the box of
/// a cube (the fewest worth as many) for the Sobol' sampler and for independent lines, and a cell that
/// asks for the sphere draws through the sphere.
#[test]
fn a_cells_runs_draw_their_lines_as_scx_analyze_does() {
    use scene_complexity::calibrate::driver::run_spec;
    use scene_complexity::calibrate::suite::Cell;
    use scene_complexity::{lines_to_draw, LineBound, LinesThrough, Sampler};
    let scene = CalibrationScene::parse("@cube:4").unwrap();
    let built = scene_complexity::internals::scenes::load("@cube:4").unwrap();
    let cell = Cell::new(scene, 100_000, 3);
    for spec in [
        run_spec(&cell.with_sampler(Sampler::Sobol), 1, &built),
        run_spec(&cell, 1, &built),
    ] {
        assert_eq!(spec.bound, LineBound::Box);
        assert_eq!(spec.lines, lines_to_draw(&built, LineBound::Box, 100_000));
        assert!((63_000..64_500).contains(&spec.lines), "{}", spec.lines);
    }
    let sphere = cell
        .with_sampler(Sampler::Sobol)
        .with_bound(LinesThrough::Bound(LineBound::Sphere));
    for spec in [
        run_spec(&sphere, 1, &built),
        run_spec(&sphere.with_sampler(Sampler::Independent), 1, &built),
    ] {
        assert_eq!((spec.bound, spec.lines), (LineBound::Sphere, 100_000));
    }
}
