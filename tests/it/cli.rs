//! The `scx` binary: JSON report fields, CSV, errors with exit code 2.

use crate::support;

use support::{json_of, scx};

use std::process::Command;

#[test]
fn json_report_parses_and_carries_the_documented_fields() {
    let out = scx(&[
        "analyze",
        "@cube:3",
        "--lines",
        "2e4",
        "--tracer",
        "rust",
        "--format",
        "json",
        "--threads",
        "2",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    assert_eq!(doc["schema_version"], 4);
    assert_eq!(
        doc["absorbed"], 0,
        "a closed, consistently oriented cube shows no back side"
    );
    assert_eq!(doc["unit"], "bit");
    assert_eq!(doc["command_line"][1], "analyze");
    assert!(doc["cpu"].as_str().is_some_and(|c| !c.is_empty()));
    assert_eq!(doc["scene"], "@cube:3");
    assert_eq!(doc["patches"], 54);
    assert_eq!(doc["triangles"], 108);
    assert!((doc["area"].as_f64().unwrap() - 6.0).abs() < 1e-9);
    assert_eq!(doc["tracer"], "rust");
    // Independent lines through the cube's box: 2/pi of the 20000 asked through the sphere.
    assert_eq!(doc["lines_through"], "box");
    assert_eq!(doc["lines"], 12733);
    assert_eq!(doc["sphere_lines"], 20000);
    assert_eq!(doc["seed"], 1);
    assert_eq!(doc["threads"], 2);
    assert!(doc["seconds"].as_f64().unwrap() > 0.0);
    assert!(doc["pairs"].as_u64().unwrap() > 10000);
    assert_eq!(doc["escapes"], 0);
    assert_eq!(doc["unpaired"], 0);
    for key in [
        "positional_entropy",
        "entropy",
        "joint_entropy",
        "mutual_information",
        "continuous_mutual_information",
        "accuracy",
        "mse_per_line",
    ] {
        let m = &doc["visibility"][key];
        assert!(m["value"].as_f64().unwrap().is_finite(), "{key}: {m}");
        assert!(m["stderr"].as_f64().unwrap() >= 0.0, "{key}: {m}");
    }
    let hp = doc["visibility"]["positional_entropy"]["value"]
        .as_f64()
        .unwrap();
    assert!((hp - 54f64.log2()).abs() < 1e-12);
}

#[test]
fn continuous_only_leaves_the_discrete_measures_out() {
    let out = scx(&[
        "analyze",
        "@cube:2",
        "--lines",
        "1e4",
        "--tracer",
        "rust",
        "--format",
        "json",
        "--measures",
        "continuous",
    ]);
    assert!(out.status.success());
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(doc["visibility"]["mutual_information"].is_null());
    assert!(doc["visibility"]["continuous_mutual_information"]["value"]
        .as_f64()
        .is_some());
    assert!(doc["distinct_pairs"].is_null(), "no count matrix was built");
}

#[test]
fn bad_input_is_one_clear_error_with_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let nan = dir.path().join("nan.obj");
    std::fs::write(&nan, "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n").unwrap();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["analyze".into(), "@nosuch".into()],
            "unknown built-in scene",
        ),
        (vec!["analyze".into(), "@cube:0".into()], "whole number"),
        (
            vec!["analyze".into(), "/no/such/file.obj".into()],
            "no such file",
        ),
        (
            vec![
                "analyze".into(),
                nan.display().to_string(),
                "--tracer".into(),
                "rust".into(),
            ],
            "non-finite",
        ),
        // A negative tolerance gets the value's own message, not the parser's "unexpected argument".
        (
            vec![
                "analyze".into(),
                "@cube".into(),
                "--planarity".into(),
                "-1".into(),
            ],
            "need a number >= 0",
        ),
    ];
    for (args, expect) in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = scx(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(expect), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let zero = scx(&["analyze", "@cube", "--lines", "0"]);
    assert_eq!(zero.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&zero.stderr).contains("whole number from 1"));
}

#[test]
fn corrected_estimates_are_reported_beside_the_plug_in() {
    let doc = json_of(&scx(&[
        "analyze", "@cube:3", "--lines", "2e4", "--format", "json",
    ]));
    for key in ["entropy", "mutual_information", "accuracy"] {
        let c = &doc["visibility"][key]["corrected"];
        assert!(
            c["value"].as_f64().unwrap().is_finite() && c["stderr"].as_f64().unwrap() > 0.0,
            "{key}: {c}"
        );
    }
    assert_eq!(doc["estimator"], "chao-wang-jost");
    assert_eq!(doc["stop_reason"], "lines");
}

/// `--errors jackknife` changes the standard errors of the count-based measures only: the values, and
/// I_s^c's error, are those of the default run; an enclosed scene falls back to batch means and says so.
#[test]
fn jackknife_errors_change_only_the_count_based_errors() {
    let run = |extra: &[&str]| {
        let mut args = vec![
            "analyze", "@cube:4", "--lines", "3e4", "--tracer", "rust", "--format", "json",
        ];
        args.extend_from_slice(extra);
        json_of(&scx(&args))
    };
    let (groups, jackknife) = (run(&[]), run(&["--errors", "jackknife"]));
    assert_eq!(groups["errors"], "groups");
    assert_eq!(jackknife["errors"], "jackknife");
    let (g, j) = (&groups["visibility"], &jackknife["visibility"]);
    for key in ["entropy", "mutual_information", "accuracy", "mse_per_line"] {
        assert_eq!(g[key]["value"], j[key]["value"], "{key}");
        let (sg, sj) = (
            g[key]["stderr"].as_f64().unwrap(),
            j[key]["stderr"].as_f64().unwrap(),
        );
        assert!(
            sj.is_finite() && sj > 0.0 && sj != sg,
            "{key}: {sg} vs {sj}"
        );
    }
    let cmi = "continuous_mutual_information";
    assert_eq!(g[cmi], j[cmi]);

    let open = |extra: &[&str]| {
        let mut args = vec![
            "analyze",
            "@cornell-open",
            "--lines",
            "2e4",
            "--tracer",
            "rust",
            "--enclose",
            "--format",
            "json",
        ];
        args.extend_from_slice(extra);
        json_of(&scx(&args))
    };
    assert_eq!(open(&["--errors", "jackknife"])["errors"], "groups");
    assert!(!scx(&["analyze", "@cube", "--errors", "bogus"])
        .status
        .success());
}

#[test]
fn budgets_stop_the_run_and_say_why() {
    let doc = json_of(&scx(&[
        "analyze",
        "@cube:2",
        "--seconds",
        "0.3",
        "--format",
        "json",
    ]));
    assert_eq!(doc["stop_reason"], "seconds");
    assert!(
        doc["lines"].as_u64().unwrap() > 0 && doc["lines"].as_u64().unwrap() % 4096 == 0,
        "whole batches"
    );

    let target = 0.004;
    let doc = json_of(&scx(&[
        "analyze",
        "@cube:2",
        "--target-stderr",
        "0.004",
        "--target-measure",
        "continuous_mutual_information",
        "--format",
        "json",
    ]));
    assert_eq!(doc["stop_reason"], "target_stderr");
    let se = doc["visibility"]["continuous_mutual_information"]["stderr"]
        .as_f64()
        .unwrap();
    assert!(se <= target, "{se}");

    let doc = json_of(&scx(&[
        "analyze",
        "@cube:2",
        "--target-stderr",
        "1e-9",
        "--lines",
        "3e5",
        "--format",
        "json",
    ]));
    assert_eq!(
        doc["stop_reason"], "lines",
        "the line cap ends a run whose target is out of reach"
    );
    assert_eq!(doc["sphere_lines"], 300_000);
}

#[test]
fn ctrl_c_stops_cleanly_with_a_report_marked_interrupted() {
    let child = Command::new(env!("CARGO_BIN_EXE_scx"))
        .args(["analyze", "@cube:20", "--lines", "1e10", "--format", "json"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1000));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    // A report of a partial run must not look like success to a script.
    assert_eq!(out.status.code(), Some(130));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    assert_eq!(doc["interrupted"], true);
    assert_eq!(doc["stop_reason"], "interrupted");
    assert!(doc["lines"].as_u64().unwrap() > 0);
    assert!(doc["visibility"]["mutual_information"]["value"]
        .as_f64()
        .unwrap()
        .is_finite());
}

#[test]
fn convergence_writes_a_table_a_csv_and_a_plot() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, svg) = (dir.path().join("c.csv"), dir.path().join("c.svg"));
    let out = scx(&[
        "convergence",
        "@cube:2",
        "--lines",
        "1e3,1e4",
        "--repeats",
        "2",
        "--csv",
        csv.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("I_s corrected") && table.contains("10000"),
        "{table}"
    );
    let rows = std::fs::read_to_string(&csv).unwrap();
    // 2 line counts x 2 repeats x 8 measures, plus the header.
    assert_eq!(rows.lines().count(), 1 + 2 * 2 * 8, "{rows}");
    let plot = std::fs::read_to_string(&svg).unwrap();
    assert!(
        plot.starts_with("<svg")
            && plot.contains("run time (s, log scale)")
            && plot.contains("error (bits, log scale)")
            && plot.contains("mutual information I_s, corrected"),
        "{plot}"
    );
}

/// The texts of an SVG's `<text>` elements anchored as `anchor` that read as numbers: the tick labels of
/// the y axis (`end`, right of the labels) or of the x axis (`middle`, with the titles, which do not
/// read as numbers).
fn svg_tick_values(svg: &str, anchor: &str) -> Vec<f64> {
    let marker = format!("text-anchor=\"{anchor}\"");
    svg.split("<text ")
        .skip(1)
        .filter(|element| element.split('>').next().unwrap_or("").contains(&marker))
        .filter_map(|element| {
            let body = element.split_once('>')?.1.split("</text>").next()?;
            body.trim().parse::<f64>().ok()
        })
        .collect()
}

/// A convergence plot of one line count has a y axis with round ticks (1, 2, 5 x 10^k), at least three,
/// the lowest below every error plotted and the highest above (the errors are the JSON report's
/// standard errors of the plotted measures), and an x axis with ticks too.
#[test]
fn a_convergence_plot_of_one_line_count_has_ticks_around_its_points() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("p.svg");
    let out = scx(&[
        "convergence",
        "@cube:4",
        "--lines",
        "1e5",
        "--threads",
        "1",
        "--format",
        "json",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    let doc = json_of(&out);
    let plot = std::fs::read_to_string(&svg).unwrap();
    let y = svg_tick_values(&plot, "end");
    assert!(y.len() >= 3, "y ticks {y:?}");
    for v in &y {
        let mantissa = v / 10f64.powf(v.log10().floor());
        assert!(
            [1.0, 2.0, 5.0].iter().any(|m| (mantissa - m).abs() < 1e-9),
            "{v} is not 1, 2 or 5 x 10^k"
        );
    }
    let (lowest, highest) = (y[0].min(y[y.len() - 1]), y[0].max(y[y.len() - 1]));
    let measures = doc["runs"][0]["measures"].as_object().unwrap();
    for key in ["I_s", "I_s_corrected", "I_s^c"] {
        let e = measures[key]["stderr"].as_f64().unwrap();
        assert!(
            lowest < e && e < highest,
            "{key}: {e} outside the ticks {y:?}"
        );
    }
    let x = svg_tick_values(&plot, "middle");
    assert!(x.len() >= 2, "x ticks {x:?}");
}

/// `convergence --format json` carries every reading's verdict, as its help says, and the verdicts are
/// the CSV's of the same runs.
#[test]
fn convergence_json_carries_the_verdicts_of_its_csv() {
    let dir = tempfile::tempdir().unwrap();
    let (json, csv) = (dir.path().join("c.json"), dir.path().join("c.csv"));
    let out = scx(&[
        "convergence",
        "@cube:3",
        "--lines",
        "1e4,1e5",
        "--format",
        "json",
        "-o",
        json.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let csv = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (lines, measure) = (col("lines"), col("measure"));
    let (plain, corrected) = (col("reliability"), col("corrected_reliability"));
    let mut checked = 0;
    for run in doc["runs"].as_array().unwrap() {
        let n = run["lines"].as_u64().unwrap().to_string();
        for (symbol, key) in [("I_s", "mutual_information"), ("H_s", "entropy")] {
            let row: Vec<&str> = csv
                .lines()
                .map(|l| l.split(',').collect::<Vec<_>>())
                .find(|r| r[lines] == n && r[measure] == key)
                .unwrap();
            let verdict = |m: &str| run["measures"][m]["reliability"]["verdict"].clone();
            assert_eq!(verdict(symbol), row[plain], "{symbol} at {n}");
            assert_eq!(
                verdict(&format!("{symbol}_corrected")),
                row[corrected],
                "{symbol} at {n}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 4);
}

/// `convergence` marks `!` each reading that breaks a bound of the theory, as `analyze` does, with a note
/// in `analyze`'s words, and marks nothing else: on `@cube:10` at 10^4 lines the rows are so undersampled
/// that I_s and the corrected I_s are far above I_s^c (Proposition 2 says I_s <= I_s^c), at 10^6 lines
/// the corrected I_s is below it. Checked against `analyze --format json` of the same runs (same lines
/// and seed): their values, which the numbers themselves show above or below I_s^c, and their flags.
#[test]
fn convergence_marks_the_readings_analyze_flags_and_no_other() {
    let table = support::text_of(scx(&[
        "convergence",
        "@cube:10",
        "--lines",
        "1e4,1e6",
        "--threads",
        "1",
        "--quiet",
    ]));
    // The table's columns, as `analyze --format json` keys the same readings.
    let columns = [
        ("mutual_information", false),
        ("mutual_information", true),
        ("entropy", false),
        ("entropy", true),
        ("continuous_mutual_information", false),
    ];
    let (mut marked, mut unmarked, mut notes) = (0, 0, 0);
    for lines in ["10000", "1000000"] {
        let doc = support::analyze_json(&["@cube:10", "--lines", lines, "--threads", "1"]);
        let v = &doc["visibility"];
        let row = table
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{lines} ")))
            .unwrap_or_else(|| panic!("no row for {lines}:\n{table}"));
        let isc = &v["continuous_mutual_information"];
        for (key, corrected) in columns {
            let reading = if corrected {
                &v[key]["corrected"]
            } else {
                &v[key]
            };
            let (value, se) = (
                reading["value"].as_f64().unwrap(),
                reading["stderr"].as_f64().unwrap(),
            );
            let cell = format!("{value:.6} +- {se:.6}");
            let at = row
                .find(&cell)
                .unwrap_or_else(|| panic!("{key} {cell} not in the {lines} row: {row}"));
            let is_marked = row[at + cell.len()..].starts_with(" !");
            let flags = reading["reliability"]["flags"].as_array().unwrap();
            assert_eq!(is_marked, !flags.is_empty(), "{key} at {lines}: {row}");
            // Proposition 2 read off the numbers alone: I_s above I_s^c by more than twice their
            // combined standard error is flagged, below it is not.
            if key == "mutual_information" {
                let (c, cse) = (
                    isc["value"].as_f64().unwrap(),
                    isc["stderr"].as_f64().unwrap(),
                );
                let above = value - c > 2.0 * (se * se + cse * cse).sqrt();
                let below = value < c;
                assert!(
                    above || below,
                    "{key} at {lines}: too close to I_s^c to test"
                );
                assert_eq!(
                    is_marked, above,
                    "{key} {value} against I_s^c {c} at {lines}"
                );
            }
            for f in flags {
                let note = format!("! {lines} lines, seed 1: {}", f.as_str().unwrap());
                assert!(table.lines().any(|l| l == note), "{note} missing:\n{table}");
                notes += 1;
            }
            if is_marked {
                marked += 1;
            } else {
                unmarked += 1;
            }
        }
    }
    // The case breaks bounds (both I_s at 10^4 lines) and keeps others; every note is one of the flags.
    assert!(marked >= 2 && unmarked >= 5, "{table}");
    assert_eq!(
        table.lines().filter(|l| l.starts_with("! ")).count(),
        notes,
        "{table}"
    );
    assert!(table.contains("\nmarked !: "), "the legend: {table}");
}

/// One flat quad sees nothing of itself: `convergence` names the undefined measures and says why (the
/// `no-pairs` warning, which knows the scene is flat), writes no plot and says so, and exits 0.
/// `convergence` passes on each run's warnings as `analyze` gives them (once each, after the run's lines
/// and seed), and says what `!` marks only when a reading is marked.
#[test]
fn convergence_warns_as_analyze_does_and_explains_only_the_marks_it_shows() {
    let warning = |out: &std::process::Output, code: &str| -> Vec<String> {
        String::from_utf8_lossy(&out.stderr)
            .lines()
            .filter(|l| l.contains(code))
            .map(str::to_string)
            .collect()
    };
    let analyze = scx(&["analyze", "@cube:10", "--lines", "2e3", "--threads", "1"]);
    let convergence = scx(&[
        "convergence",
        "@cube:10",
        "--lines",
        "2e3,1e6",
        "--threads",
        "1",
    ]);
    assert!(convergence.status.success());
    let (a, c) = (
        warning(&analyze, "fill 5 groups"),
        warning(&convergence, "fill 5 groups"),
    );
    assert_eq!((a.len(), c.len()), (1, 1), "{a:?} {c:?}");
    let message = a[0].trim_start_matches("scx: warning: ");
    assert_eq!(c[0], format!("scx: warning: 2000 lines, seed 1: {message}"));
    // At 10^6 lines no reading of @cube:10 breaks a bound: no `!` and no legend for it, but the
    // readings that are not ok are still listed.
    let table = support::text_of(scx(&[
        "convergence",
        "@cube:10",
        "--lines",
        "1e6",
        "--threads",
        "1",
        "-q",
    ]));
    assert!(
        !table.contains(" !") && !table.contains("marked !"),
        "{table}"
    );
    assert!(table.contains("\nreadings not ok"), "{table}");
}

#[test]
fn convergence_on_a_scene_with_undefined_measures_says_so_and_draws_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let quad = dir.path().join("quad.obj");
    std::fs::write(&quad, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    let svg = dir.path().join("c.svg");
    let out = scx(&[
        "convergence",
        quad.to_str().unwrap(),
        "--lines",
        "1e3,1e4",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains(
            "quad.obj: I_s, I_s corrected, H_s, H_s corrected, I_s^c undefined at every line count: \
             no line segment joined two patches"
        ) && err.contains("every patch lies in one plane"),
        "{err}"
    );
    assert!(
        err.contains("no plot written:")
            && err.contains("every measure it would show is undefined"),
        "{err}"
    );
    assert!(!svg.exists(), "no empty plot");
    let table = String::from_utf8_lossy(&out.stdout);
    let rows: Vec<&str> = table.lines().filter(|l| l.contains(" - ")).collect();
    assert_eq!(rows.len(), 2, "a row of - per line count: {table}");
}

/// With bundles the table says that the bias corrections assume independent lines (8 x 8 bundles moved
/// the corrected I_s of `@cube:30` by 7.7 standard errors over 200 seeds: docs/performance.md, Bundles);
/// without bundles, or without corrected values, it does not.
#[test]
fn bundled_runs_warn_that_the_corrections_assume_independent_lines() {
    let table = |extra: &[&str]| {
        let mut args = vec!["analyze", "@cube:3", "--lines", "2e4"];
        args.extend_from_slice(extra);
        String::from_utf8(scx(&args).stdout).unwrap()
    };
    let note = "as if the lines were independent";
    assert!(table(&["--bundle", "4"]).contains(note));
    assert!(!table(&[]).contains(note));
    assert!(!table(&["--bundle", "4", "--measures", "continuous"]).contains(note));
}

/// The default tracer is the pure-Rust one in every build (the faster end to end, with Embree's hits);
/// a packet query, which only Embree has, selects Embree.
#[test]
fn the_default_tracer_is_rust_and_packets_select_embree() {
    let tracer_of = |extra: &[&str]| {
        let mut args = vec!["analyze", "@cube:3", "--lines", "2e3", "--format", "json"];
        args.extend(extra);
        let out = support::scx(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        v["tracer"].as_str().unwrap_or_default().to_string()
    };
    assert!(tracer_of(&[]).starts_with("rust"), "{}", tracer_of(&[]));
    if cfg!(feature = "embree") {
        assert!(tracer_of(&["--query", "packet8"]).starts_with("embree"));
    }
}
