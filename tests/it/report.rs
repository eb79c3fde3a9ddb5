//! The reports as data (`scene_complexity::report`), which the command line writes as files and the
//! Python binding hands over as arrays: against the scene's own numbers and the invariants of F.

use scene_complexity::report::{self, Context, FormFactors, Values};
use scene_complexity::{analyze, load, make_tracer, Backend, Measure, Query, RunControl, RunSpec};
use scene_complexity::{PatchMeasure, Tracing};

fn analysed(name: &str, lines: u64) -> (scene_complexity::Scene, scene_complexity::Analysis) {
    let scene = load(name).unwrap();
    let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
    let spec = RunSpec {
        per_patch: true,
        ..RunSpec::new(lines, 3)
    };
    let a = analyze(&scene, tracer.as_ref(), &spec, &RunControl::default()).unwrap();
    (scene, a)
}

fn numbers(t: &report::Table, name: &str) -> Vec<f64> {
    match &t.column(name).unwrap().values {
        Values::Numbers(v) => v.iter().map(|x| x.unwrap()).collect(),
        other => panic!("{name} is not a number column: {other:?}"),
    }
}

/// Without a process, the document has none of its fields; with one, it has them; the rest is the same
/// document, in the same order.
#[test]
fn the_json_document_leaves_out_the_process_when_asked() {
    let (scene, a) = analysed("@cube:2", 20_000);
    let context = |process| Context {
        scene: &scene,
        tracing: Tracing {
            backend: Backend::Rust,
            query: Query::Single,
        },
        build_seconds: 0.0,
        shard: None,
        process,
    };
    let bare = report::json(&context(None), &a);
    let full = report::json(&context(Some(report::Process::current(3))), &a);
    let (bare, full) = (bare.as_object().unwrap(), full.as_object().unwrap());
    for key in ["command_line", "cpu", "threads"] {
        assert!(!bare.contains_key(key), "{key} left in");
        assert!(full.contains_key(key), "{key} missing");
    }
    assert_eq!(full["threads"], 3);
    let full_keys: Vec<&String> = full.keys().filter(|k| bare.contains_key(*k)).collect();
    assert_eq!(bare.keys().collect::<Vec<_>>(), full_keys);
    let isc = &bare["visibility"]["continuous_mutual_information"]["value"];
    let exact = a
        .estimate(Measure::ContinuousMutualInformation)
        .unwrap()
        .value;
    assert_eq!(isc.as_f64().unwrap(), exact);
}

/// The patch table's areas are the scene's, its fractions sum to 1, and its I_s^c terms sum to the
/// scene's I_s^c (eq. 27 is a sum over patches).
#[test]
fn the_patch_table_adds_up_to_the_scene() {
    let (scene, a) = analysed("@cube:3", 100_000);
    let t = report::patch_table(&scene, a.patches.as_ref().unwrap());
    assert_eq!(t.rows(), scene.patch_count());
    assert!(t.columns.iter().all(|c| c.values.len() == t.rows()));
    let fractions: f64 = numbers(&t, "area_fraction").iter().sum();
    assert!((fractions - 1.0).abs() < 1e-12);
    let areas: f64 = numbers(&t, "area").iter().sum();
    assert!(
        (areas - 6.0).abs() < 1e-9,
        "the unit cube's area is 6, got {areas}"
    );
    let column = PatchMeasure::ContinuousTerm.info().column;
    let sum: f64 = numbers(&t, column).iter().sum();
    let scene_isc = a
        .estimate(Measure::ContinuousMutualInformation)
        .unwrap()
        .value;
    assert!(
        (sum - scene_isc).abs() < 1e-9 * scene_isc,
        "{sum} against {scene_isc}"
    );
}

/// In a closed scene every row of F sums to 1 (eq. 2's rows are a distribution) and A_i F_ij = A_j F_ji
/// within a few standard errors (reciprocity).
#[test]
fn form_factors_are_a_closed_reciprocal_matrix() {
    let (scene, a) = analysed("@cube:2", 200_000);
    let f = FormFactors::of(&a, scene.patch_count()).unwrap();
    let mut rows = vec![0.0; f.patches];
    let mut dense = vec![vec![(0.0, 0.0); f.patches]; f.patches];
    for (k, &(i, j, _)) in f.entries.iter().enumerate() {
        let (v, se) = f.value(k);
        rows[i as usize] += v;
        dense[i as usize][j as usize] = (v, se);
    }
    assert!(rows.iter().all(|r| (r - 1.0).abs() < 1e-12), "{rows:?}");
    let area = |i: usize| scene.patches[i].area;
    for (i, row) in dense.iter().enumerate() {
        for (j, &(fij, sij)) in row.iter().enumerate().take(i) {
            let (fji, sji) = dense[j][i];
            let diff = area(i) * fij - area(j) * fji;
            let se = (area(i) * sij).hypot(area(j) * sji);
            assert!(
                diff.abs() <= 5.0 * se + 1e-12,
                "{i},{j}: {diff} against se {se}"
            );
        }
    }
}

/// The tables of an enclosed open scene, as the Python binding reads them: the patch table has the
/// environment's row last (its counted area, no centroid, object and material `environment`), the
/// object table the environment's object, and F is one row and column larger, every row a distribution
/// (the open Cornell box has no segments to back sides).
#[test]
fn the_tables_of_an_enclosed_scene_have_the_environment() {
    let scene = load("@cornell-open").unwrap();
    let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
    let spec = RunSpec {
        per_patch: true,
        enclose: true,
        ..RunSpec::new(100_000, 3)
    };
    let a = analyze(&scene, tracer.as_ref(), &spec, &RunControl::default()).unwrap();
    assert!(a.enclosed);
    let n = scene.patch_count();
    let t = report::patch_table(&scene, a.patches.as_ref().unwrap());
    assert_eq!(t.rows(), n + 1);
    assert!(t.columns.iter().all(|c| c.values.len() == n + 1));
    assert_eq!(
        t.row_text(n)[..3],
        [n.to_string(), "environment".into(), "environment".into()]
    );
    match &t.column("centroid_x").unwrap().values {
        Values::Numbers(v) => assert!(v[n].is_none() && v[..n].iter().all(Option::is_some)),
        other => panic!("{other:?}"),
    }
    let env_area = a.environment_area.unwrap().value;
    assert_eq!(numbers(&t, "area")[n], env_area);
    let fractions: f64 = numbers(&t, "area_fraction").iter().sum();
    assert!((fractions - 1.0).abs() < 1e-12);
    let objects = report::object_table(&a);
    assert_eq!(objects.rows(), scene.objects.len() + 1);
    assert_eq!(
        objects.row_text(scene.objects.len())[0],
        scene_complexity::ENVIRONMENT
    );

    let f = FormFactors::of(&a, n).unwrap();
    assert_eq!(f.patches, n + 1);
    let mut rows = vec![0.0; f.patches];
    for (k, &(i, _, _)) in f.entries.iter().enumerate() {
        rows[i as usize] += f.value(k).0;
    }
    assert!(rows.iter().all(|r| (r - 1.0).abs() < 1e-12), "{rows:?}");
    let to_environment: u64 = f
        .entries
        .iter()
        .filter(|e| e.1 == n as u32)
        .map(|e| e.2)
        .sum();
    assert_eq!(to_environment, a.escapes + 2 * a.tally.counters.misses);
}
