//! The `scx` binary: JSON report fields, CSV, errors with exit code 2.

use std::process::Command;

fn scx(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_scx"))
        .args(args)
        .output()
        .expect("scx runs")
}

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
    assert_eq!(doc["schema_version"], 1);
    assert_eq!(doc["scene"], "@cube:3");
    assert_eq!(doc["patches"], 54);
    assert_eq!(doc["triangles"], 108);
    assert!((doc["area"].as_f64().unwrap() - 6.0).abs() < 1e-9);
    assert_eq!(doc["tracer"], "rust");
    assert_eq!(doc["lines"], 20000);
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
