//! How far each entropy estimator's I_s is from the exact I_s of `@cube:N` (closed-form form factors),
//! at several line counts: the measurement behind the default bias correction.
//!
//! `cargo bench --bench bias -- [N,N,...] [LINES,LINES,...] [SEEDS]`, default `30` and `1e6,1e7,1e8`, 1 seed.

#[path = "../tests/it/support.rs"]
mod support;

use scene_complexity::internals::analysis::analyze;
use scene_complexity::internals::measure::bias::corrected;
use scene_complexity::internals::measure::estimators::EntropyEstimator;
use scene_complexity::internals::run::Measures;
use scene_complexity::internals::run::{RunControl, RunSpec};
use scene_complexity::internals::scenes;
use scene_complexity::internals::trace::{make_tracer, Backend, Query};

fn list(arg: Option<&String>, default: &str) -> Vec<f64> {
    arg.map_or(default, |s| s.as_str())
        .split(',')
        .map(|x| x.parse().expect("a number"))
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let sizes = list(args.first(), "30");
    let line_counts = list(args.get(1), "1e6,1e7,1e8");
    let seeds = list(args.get(2), "1")[0] as u64;
    print!("{:>4} {:>10} {:>9} {:>8}", "N", "lines", "exact", "seconds");
    for e in EntropyEstimator::ALL {
        print!(" {:>16}", e.name());
    }
    println!("   (I_s and its relative error)");
    for &n in &sizes {
        let (_, exact) = support::cube_exact_measures(n as usize);
        let scene = scenes::load(&format!("@cube:{}", n as usize)).unwrap();
        let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
        let tracer = make_tracer(Backend::default_available(), &scene, Query::Single).unwrap();
        for &lines in &line_counts {
            for seed in 1..=seeds {
                let cfg = RunSpec {
                    measures: Measures {
                        discrete: true,
                        continuous: false,
                        radiosity: false,
                    },
                    ..RunSpec::new(lines as u64, seed)
                };
                let a = analyze(&scene, tracer.as_ref(), &cfg, &RunControl::default()).unwrap();
                let counts = a.tally.counts.as_ref().unwrap();
                print!(
                    "{:>4} {:>10.0e} {:>9.5} {:>8.2}",
                    n, lines, exact, a.seconds
                );
                for e in EntropyEstimator::ALL {
                    let v = corrected(&areas, counts, &a.tally.escapes_by_patch.dense(), e)
                        .mutual_information;
                    print!(" {:>8.4} {:>+6.1}%", v, 100.0 * (v - exact) / exact);
                }
                println!();
            }
        }
    }
}
