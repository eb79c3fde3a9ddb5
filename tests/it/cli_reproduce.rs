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
