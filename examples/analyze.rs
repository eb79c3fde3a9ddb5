//! Using scx from Rust: load a scene (an OBJ file or a built-in), cast global lines through it, and
//! print its discrete and continuous mutual information with their standard errors.
//!
//!     cargo run --release --example analyze -- scenes/cornell.obj 1e6
//!     cargo run --release --example analyze -- @cube:10

use std::error::Error;

use scene_complexity::{
    analyze, load, make_tracer, Backend, LinesThrough, Measure, Query, RunControl, RunSpec,
};

fn main() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let spec = args.next().unwrap_or_else(|| "@cube:10".into());
    let lines = match args.next() {
        Some(n) => n.parse::<f64>()? as u64,
        None => 1_000_000,
    };

    let scene = load(&spec)?;
    for warning in &scene.warnings {
        eprintln!("warning: {warning}");
    }
    // Embree when this build has it, else the pure-Rust tracer: both give the same hits.
    let tracer = make_tracer(Backend::default_available(), &scene, Query::Single)?;
    // `lines` counted through the bounding sphere, drawn where `scx analyze` draws them (the smallest
    // container: the same estimates for less time); `RunSpec::new` alone draws through the sphere.
    let run = RunSpec::new(lines, 1).through(&scene, LinesThrough::Auto);
    let analysis = analyze(&scene, tracer.as_ref(), &run, &RunControl::default())?;
    for warning in &analysis.warnings {
        eprintln!("warning: {warning}");
    }

    println!(
        "{}: {} patches, {lines} lines ({} drawn through the bounding {}), {} tracer",
        scene.name,
        scene.patch_count(),
        analysis.lines,
        analysis.spec.bound.name(),
        tracer.name()
    );
    for measure in [
        Measure::MutualInformation,
        Measure::MutualInformationCorrected,
        Measure::ContinuousMutualInformation,
    ] {
        if let Some(e) = analysis.estimate(measure) {
            let se = e.stderr.map_or("n/a".into(), |s| format!("{s:.6}"));
            let verdict = analysis.verdict(measure).map_or("", |v| v.name());
            println!(
                "{:<38} {:>10.6} ± {se} {}  {verdict}",
                measure.info().label,
                e.value,
                measure.info().unit.name()
            );
        }
    }
    Ok(())
}
