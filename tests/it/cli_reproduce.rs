//! `scx reproduce` and the paper's scenes on the command line: the tables print beside the paper's
//! values; bad tables, line plans and scene parameters are clear errors with exit code 2.

use crate::support;

use support::scx;

#[test]
fn a_table_prints_beside_the_papers_values_with_lines_and_seconds() {
    let out = scx(&[
        "reproduce",
        "--table",
        "4",
        "--lines",
        "x0.02",
        "--tracer",
        "rust",
        "--threads",
        "2",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("### Table 4"), "{stdout}");
    // The paper's values, as printed in its Table 4.
    for v in ["0.5428", "0.8254", "1.2583", "1.6093", "2.6227", "2.800"] {
        assert!(stdout.contains(v), "paper value {v} missing:\n{stdout}");
    }
    // 2% of the paper's 10^6 lines per scene, and every finding checked.
    assert!(stdout.contains("| 2e4 |"), "{stdout}");
    assert!(stdout.contains("**holds**"), "{stdout}");
    assert!(stdout.contains("Total:"), "{stdout}");
    assert!(!stdout.contains("### Table 5"), "only the table asked for");
}

#[test]
fn bad_requests_are_errors_with_exit_code_2() {
    for args in [
        &["reproduce", "--table", "10"][..],
        &["reproduce", "--table", "0"],
        &["reproduce", "--lines", "x0"],
        &["reproduce", "--lines", "lots"],
        &["reproduce", "--lines", "1.5"],
        &["analyze", "@fig2:d"],
        &["analyze", "@fig2"],
        &["analyze", "@fig4:g"],
        &["analyze", "@fig5:1.5"],
        &["analyze", "@fig6:z"],
        &["analyze", "@labyrinth:0"],
    ] {
        let out = scx(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}

#[test]
fn scenes_lists_the_papers_scenes_with_their_parameters() {
    let out = scx(&["scenes"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    for usage in [
        "@fig2:a|b|c",
        "@fig4:a..f",
        "@fig5:a..f|T",
        "@fig6:a..f|T",
        "@labyrinth[:N]",
    ] {
        assert!(stdout.contains(usage), "{usage} missing:\n{stdout}");
    }
}

/// A table that asks twice for one run says it repeated it, not that it shared it with an earlier
/// table (Table 1 alone did); a later table that reuses an earlier one's runs casts no line for them.
#[test]
fn runs_cast_once_are_told_apart_by_where_they_came_from() {
    let out = scx(&[
        "reproduce",
        "--table",
        "1,2,3",
        "--lines",
        "1e4",
        "--tracer",
        "rust",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let casts: Vec<&str> = stdout
        .lines()
        .filter(|l| l.contains("lines cast for this table"))
        .collect();
    assert_eq!(casts.len(), 3, "{stdout}");
    assert!(
        casts[0].contains("repeated within it") && !casts[0].contains("earlier table"),
        "{}",
        casts[0]
    );
    assert!(
        casts[2].starts_with("0 lines cast") && casts[2].contains("shared with an earlier table"),
        "{}",
        casts[2]
    );
    // A table asked for twice takes its runs from its first time.
    let out = scx(&[
        "reproduce",
        "--table",
        "1,1",
        "--lines",
        "1e4",
        "--tracer",
        "rust",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let second = stdout
        .lines()
        .filter(|l| l.contains("lines cast for this table"))
        .nth(1)
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(
        second.starts_with("0 lines cast") && !second.contains("repeated within it"),
        "{second}"
    );
}

/// `reproduce` marks `!` the readings `scx analyze` flags, with a note in its words, and no other; a
/// finding judged on flagged readings says so and names them. Fig. 2a at 10^5 lines: the plug-in I_s is
/// far above I_s^c (Proposition 2 says I_s <= I_s^c), the corrected I_s below it. Checked against
/// `analyze --format json` of the same run (scene, lines, seed 1): its numbers and its flags.
#[test]
fn flagged_readings_are_marked_and_findings_resting_on_them_say_so() {
    let md = support::text_of(scx(&[
        "reproduce",
        "--table",
        "1,3",
        "--lines",
        "1e5",
        "--tracer",
        "rust",
        "--threads",
        "1",
        "--quiet",
    ]));
    let doc = support::analyze_json(&["@fig2:a", "--lines", "1e5", "--threads", "1"]);
    let v = &doc["visibility"];
    let isc = &v["continuous_mutual_information"];
    let (c, cse) = (
        isc["value"].as_f64().unwrap(),
        isc["stderr"].as_f64().unwrap(),
    );
    // Table 3's row: lines, seconds, I_s, I_s corr., paper, I_s^c, paper.
    let row: Vec<&str> = md
        .lines()
        .find(|l| l.starts_with("| 1e5 |"))
        .unwrap_or_else(|| panic!("no Table 3 row:\n{md}"))
        .split(" | ")
        .collect();
    let mut marks = 0;
    for (reading, cell) in [
        (&v["mutual_information"], row[2]),
        (&v["mutual_information"]["corrected"], row[3]),
        (isc, row[5]),
    ] {
        let (value, se) = (
            reading["value"].as_f64().unwrap(),
            reading["stderr"].as_f64().unwrap(),
        );
        let text = format!("{value:.3} ± {se:.4}");
        assert!(cell.starts_with(&text), "{cell} is not {text}");
        let flags = reading["reliability"]["flags"].as_array().unwrap();
        assert_eq!(cell.ends_with(" !"), !flags.is_empty(), "{cell}: {flags:?}");
        for f in flags {
            let note = format!("! @fig2:a 1e5: {}  ", f.as_str().unwrap());
            assert!(md.lines().any(|l| l == note), "{note} missing:\n{md}");
            marks += 1;
        }
    }
    // The numbers alone: the plug-in I_s breaks Proposition 2, the corrected one does not.
    let is = v["mutual_information"]["value"].as_f64().unwrap();
    let is_se = v["mutual_information"]["stderr"].as_f64().unwrap();
    assert!(
        is - c > 2.0 * (is_se * is_se + cse * cse).sqrt(),
        "{is} vs {c}"
    );
    assert!(
        v["mutual_information"]["corrected"]["value"]
            .as_f64()
            .unwrap()
            < c
    );
    assert!(row[2].ends_with(" !") && !row[3].ends_with(" !") && !row[5].ends_with(" !"));
    assert_eq!(marks, 1, "one broken bound: {md}");
    // Table 1's first finding rests on fig. 2a's plug-in I_s; Table 3's first on I_s^c alone.
    let finding = |claim: &str| {
        md.lines()
            .find(|l| l.starts_with(&format!("- *{claim}")))
            .unwrap_or_else(|| panic!("{claim}: no finding\n{md}"))
            .to_string()
    };
    let clustered = finding("clustered configurations");
    assert!(
        clustered.contains("on flagged readings**")
            && clustered.contains("(flagged: @fig2:a 1e5: I_s. "),
        "{clustered}"
    );
    let cheap = finding("I_s^c is cheap");
    assert!(
        cheap.contains("**holds**") && !cheap.contains("flagged"),
        "{cheap}"
    );
}
