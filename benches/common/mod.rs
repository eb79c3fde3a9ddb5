//! What the table-printing benches share: their arguments, and CPU time read from Linux's schedstat
//! (robust when the machine is shared, unlike wall-clock time).

// Each bench compiles this module on its own and uses only part of it.
#![allow(dead_code)]

/// The scenes and the line count given after `cargo bench --bench NAME --`: numbers are the line count,
/// the rest scenes (default `@cube:30 @cubes512` and `default_lines`). `cargo bench` itself passes
/// `--bench`, which is skipped.
pub fn scenes_and_lines(default_lines: f64) -> anyhow::Result<(Vec<String>, u64)> {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let (counts, mut specs): (Vec<String>, Vec<String>) =
        args.into_iter().partition(|a| a.parse::<f64>().is_ok());
    if specs.is_empty() {
        specs = vec!["@cube:30".into(), "@cubes512".into()];
    }
    let lines = counts
        .first()
        .map_or(Ok(default_lines), |c| c.parse::<f64>())? as u64;
    Ok((specs, lines))
}

/// CPU time used so far by the live threads of this process (the first field of each
/// `/proc/self/task/*/schedstat`, nanoseconds on a CPU); NaN where that is not available.
pub fn cpu_seconds() -> f64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return f64::NAN;
    };
    let ns: u64 = tasks
        .flatten()
        .map(|task| schedstat_ns(&task.path().join("schedstat")))
        .sum();
    ns as f64 * 1e-9
}

/// CPU time of the calling thread so far (`/proc/thread-self/schedstat`).
pub fn thread_cpu_seconds() -> f64 {
    schedstat_ns(std::path::Path::new("/proc/thread-self/schedstat")) as f64 * 1e-9
}

fn schedstat_ns(path: &std::path::Path) -> u64 {
    std::fs::read_to_string(path)
        .unwrap_or_default()
        .split_whitespace()
        .next()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0)
}
