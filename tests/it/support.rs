//! Independent truth for the tests: closed-form form factors (textbook formulas, e.g. Howell's catalogue,
//! C-11 and C-14), brute-force helpers and small scene writers.
#![allow(dead_code)]

use std::f64::consts::PI;

use scene_complexity::internals::analysis::Analysis;
use scene_complexity::internals::scene::Scene;

use scene_complexity::internals::trace::rust::BruteForceTracer;
use scene_complexity::internals::trace::{make_tracer, Backend, Query, Tracer};

/// Form factor between two identical, directly opposed parallel rectangles `a x b` at distance `c`.
pub fn ff_parallel_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (x2, y2) = (x * x, y * y);
    2.0 / (PI * x * y)
        * (((1.0 + x2) * (1.0 + y2) / (1.0 + x2 + y2)).sqrt().ln()
            + x * (1.0 + y2).sqrt() * (x / (1.0 + y2).sqrt()).atan()
            + y * (1.0 + x2).sqrt() * (y / (1.0 + x2).sqrt()).atan()
            - x * x.atan()
            - y * y.atan())
}

/// Form factor from a rectangle `w x l` to a perpendicular rectangle `h x l` sharing the edge of length `l`.
pub fn ff_perpendicular_rectangles(w: f64, h: f64, l: f64) -> f64 {
    let (ww, hh) = (w / l, h / l);
    let (w2, h2) = (ww * ww, hh * hh);
    let s = (w2 + h2).sqrt();
    let a = (1.0 + w2) * (1.0 + h2) / (1.0 + w2 + h2);
    let b = (w2 * (1.0 + w2 + h2) / ((1.0 + w2) * (w2 + h2))).powf(w2);
    let c = (h2 * (1.0 + h2 + w2) / ((1.0 + h2) * (h2 + w2))).powf(h2);
    1.0 / (PI * ww)
        * (ww * (1.0 / ww).atan() + hh * (1.0 / hh).atan() - s * (1.0 / s).atan()
            + 0.25 * (a * b * c).ln())
}

/// Every tracer this build has, for tests that must hold for all of them: the pure-Rust BVH, the
/// brute-force reference (on scenes small enough for it) and Embree when built in.
pub fn all_tracers(scene: &Scene) -> Vec<Box<dyn Tracer>> {
    let mut v =
        vec![make_tracer(Backend::Rust, scene, Query::Single)
            .expect("the Rust tracer always builds")];
    if scene.triangles.len() <= 4000 {
        v.push(Box::new(BruteForceTracer::new(scene)));
    }
    if cfg!(feature = "embree") {
        v.push(make_tracer(Backend::Embree, scene, Query::Single).expect("Embree tracer"));
    }
    v
}

/// Writes an OBJ of a room (unit cube, inward faces as quads) holding a box, scaled by `scale`.
pub fn room_with_box_obj(scale: f64) -> String {
    let mut s = String::new();
    let mut verts = Vec::new();
    let mut faces = Vec::new();
    // Room: inward normals. Box: outward normals. Quads counter-clockwise seen from the front.
    let mut add_box = |lo: [f64; 3], hi: [f64; 3], inward: bool| {
        let base = verts.len();
        for i in 0..8 {
            verts.push([
                if i & 1 == 0 { lo[0] } else { hi[0] },
                if i & 2 == 0 { lo[1] } else { hi[1] },
                if i & 4 == 0 { lo[2] } else { hi[2] },
            ]);
        }
        for q in CUBE_QUADS {
            let mut f: Vec<usize> = q.iter().map(|&k| base + k + 1).collect();
            if inward {
                f.reverse();
            }
            faces.push(f);
        }
    };
    add_box([0.0; 3], [1.0; 3], true);
    add_box([0.3, 0.2, 0.25], [0.6, 0.5, 0.7], false);
    for v in &verts {
        s.push_str(&format!(
            "v {} {} {}\n",
            v[0] * scale,
            v[1] * scale,
            v[2] * scale
        ));
    }
    for f in &faces {
        let idx: Vec<String> = f.iter().map(|i| i.to_string()).collect();
        s.push_str(&format!("f {}\n", idx.join(" ")));
    }
    s
}

/// An axis-aligned rectangle: `coord[fixed] = level`, spanning `lo..hi` on the two other axes.
#[derive(Clone, Copy, Debug)]
pub struct AxisRect {
    pub fixed: usize,
    pub level: f64,
    pub lo: [f64; 3],
    pub hi: [f64; 3],
}

impl AxisRect {
    /// The rectangle of a patch whose polygon is axis-aligned (the patches of `@cube:N`).
    pub fn of_patch(scene: &Scene, p: usize) -> AxisRect {
        let pts: Vec<[f64; 3]> = scene
            .polygon(&scene.patches[p])
            .iter()
            .map(|&v| scene.vertices[v as usize].to_array())
            .collect();
        let lo = [0, 1, 2].map(|a| pts.iter().map(|q| q[a]).fold(f64::INFINITY, f64::min));
        let hi = [0, 1, 2].map(|a| pts.iter().map(|q| q[a]).fold(f64::NEG_INFINITY, f64::max));
        let fixed = (0..3)
            .find(|&a| hi[a] - lo[a] == 0.0)
            .expect("an axis-aligned patch");
        AxisRect {
            fixed,
            level: lo[fixed],
            lo,
            hi,
        }
    }

    fn area(&self) -> f64 {
        (0..3)
            .filter(|&a| a != self.fixed)
            .map(|a| self.hi[a] - self.lo[a])
            .product()
    }
}

/// `A_1 F_12` between two axis-aligned rectangles that see each other over no obstacle (parallel planes,
/// or perpendicular planes on the same side of each other), by the superposition of corner terms
/// (Howell's catalogue, C-16 and C-17). Zero for coplanar rectangles.
pub fn area_form_factor(r1: &AxisRect, r2: &AxisRect) -> f64 {
    if r1.fixed == r2.fixed {
        let c = (r1.level - r2.level).abs();
        if c == 0.0 {
            return 0.0;
        }
        let (u, v) = other_axes(r1.fixed);
        let g = |x: f64, y: f64| {
            let (sy, sx) = ((y * y + c * c).sqrt(), (x * x + c * c).sqrt());
            (x * sy * (x / sy).atan() + y * sx * (y / sx).atan()
                - 0.5 * c * c * (x * x + y * y + c * c).ln())
                / (2.0 * PI)
        };
        corner_sum(|i, j, k, l| {
            g(
                corner(r1, u, i) - corner(r2, u, k),
                corner(r1, v, j) - corner(r2, v, l),
            )
        })
    } else {
        // Common axis b; x: distance of r1's points from r2's plane, xi: of r2's points from r1's plane.
        let b = 3 - r1.fixed - r2.fixed;
        let g = |x: f64, y: f64, xi: f64, eta: f64| {
            let r2 = x * x + xi * xi;
            let d = y - eta;
            let t1 = if r2 > 0.0 {
                d * r2.sqrt() * (d / r2.sqrt()).atan()
            } else {
                0.0
            };
            let q = r2 + d * d;
            let t2 = if q > 0.0 {
                0.25 * (r2 - d * d) * q.ln()
            } else {
                0.0
            };
            (t1 - t2) / (2.0 * PI)
        };
        // Distances from the common line, in increasing order so the alternating sum keeps its sign.
        let dist = |r: &AxisRect, axis: usize, level: f64| {
            let (p, q) = ((r.lo[axis] - level).abs(), (r.hi[axis] - level).abs());
            [p.min(q), p.max(q)]
        };
        let (x, xi) = (dist(r1, r2.fixed, r2.level), dist(r2, r1.fixed, r1.level));
        corner_sum(|i, j, k, l| g(x[i], corner(r1, b, j), xi[k], corner(r2, b, l)))
    }
}

fn other_axes(a: usize) -> (usize, usize) {
    ((a + 1) % 3, (a + 2) % 3)
}

fn corner(r: &AxisRect, axis: usize, which: usize) -> f64 {
    if which == 0 {
        r.lo[axis]
    } else {
        r.hi[axis]
    }
}

fn corner_sum(f: impl Fn(usize, usize, usize, usize) -> f64) -> f64 {
    let mut s = 0.0;
    for i in 0..2 {
        for j in 0..2 {
            for k in 0..2 {
                for l in 0..2 {
                    let sign = if (i + j + k + l) % 2 == 0 { 1.0 } else { -1.0 };
                    s += sign * f(i, j, k, l);
                }
            }
        }
    }
    s
}

/// The exact form factors of `@cube:N` from patch `i` (one row), in the scene's patch order.
pub fn cube_form_factor_row(scene: &Scene, rects: &[AxisRect], i: usize) -> Vec<f64> {
    let a = rects[i].area();
    let _ = scene;
    rects
        .iter()
        .map(|r| area_form_factor(&rects[i], r) / a)
        .collect()
}

/// Exact H_s (eq. 17) and I_s (eq. 21) of `@cube:N`: every patch has the same area, and the cube's
/// symmetry maps every face onto face 0, so the rows of face 0's patches suffice.
pub fn cube_exact_measures(n: usize) -> (f64, f64) {
    use rayon::prelude::*;
    let scene = scene_complexity::internals::scenes::load(&format!("@cube:{n}")).unwrap();
    let rects: Vec<AxisRect> = (0..scene.patch_count())
        .map(|p| AxisRect::of_patch(&scene, p))
        .collect();
    let n_p = scene.patch_count() as f64;
    let face0: Vec<usize> = (0..scene.patch_count())
        .filter(|&p| rects[p].fixed == rects[0].fixed && rects[p].level == rects[0].level)
        .collect();
    let entropy_sum: f64 = face0
        .par_iter()
        .map(|&i| {
            cube_form_factor_row(&scene, &rects, i)
                .iter()
                .map(|&f| if f > 0.0 { -f * f.log2() } else { 0.0 })
                .sum::<f64>()
        })
        .sum();
    let h_s = entropy_sum / face0.len() as f64;
    (h_s, n_p.log2() - h_s)
}

/// Runs the `scx` binary with `args`.
#[cfg(feature = "cli")]
pub fn scx(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_scx"))
        .args(args)
        .output()
        .expect("scx runs")
}

/// The standard output of a successful `scx` run, as text.
pub fn text_of(out: std::process::Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

/// The JSON report of a successful `scx analyze ARGS --format json --tracer rust --quiet`.
#[cfg(feature = "cli")]
pub fn analyze_json(args: &[&str]) -> serde_json::Value {
    let mut all = vec!["analyze"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--format", "json", "--tracer", "rust", "--quiet"]);
    json_of(&scx(&all))
}

/// The JSON document a successful `scx ... --format json` printed.
pub fn json_of(out: &std::process::Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("valid JSON")
}

/// Every pair count of a run as `(i, j, N_ij)`, in the counts' own order: two runs that counted the same
/// give equal lists.
pub fn count_entries(a: &Analysis) -> Vec<(u32, u32, u64)> {
    let mut v = Vec::new();
    a.tally
        .counts
        .as_ref()
        .expect("the run counted pairs")
        .for_each(|i, j, c| v.push((i, j, c)));
    v
}

/// Report fields that describe the session rather than the run (timings, command line, CPU, threads,
/// shard): two reports of one run split, resumed or on other threads differ only in these.
pub const SESSION_FIELDS: [&str; 6] = [
    "seconds",
    "build_seconds",
    "command_line",
    "cpu",
    "threads",
    "shard",
];

/// A JSON report without its [`SESSION_FIELDS`].
pub fn without_session(v: &serde_json::Value) -> serde_json::Value {
    let mut v = v.clone();
    for k in SESSION_FIELDS {
        v.as_object_mut().unwrap().remove(k);
    }
    v
}

/// Crofton through the tracers: over every batch of the lines of `spec` (its plan, sampler, bound,
/// groups and seed) drawn through `scene`'s region for its bound and traced by each of `scene`'s
/// tracers, the hits of each patch per line, mean of the groups, are within 4.5 standard errors of the
/// groups of `expected(patch)`.
pub fn hits_per_patch_match(
    scene: &Scene,
    spec: &scene_complexity::internals::run::RunSpec,
    expected: impl Fn(usize) -> f64,
    label: &str,
) {
    let stream = &scene_complexity::internals::run::LineStream {
        plan: spec.plan(),
        source: spec.source,
        sampler: spec.sampler,
        bound: spec.bound,
        groups: spec.group_count() as u64,
        seed: spec.seed,
    };
    let region = &scene_complexity::internals::sample::bounds::LineRegion::of(scene, spec.bound);
    let groups = stream.groups as usize;
    for tracer in all_tracers(scene) {
        let mut per_patch = vec![vec![0.0f64; groups]; scene.patch_count()];
        let mut lines_per_group = vec![0.0f64; groups];
        let (mut lines, mut raw) = (Vec::new(), Vec::new());
        let mut hits = scene_complexity::internals::trace::LineHits::default();
        for b in 0..stream.plan.batches() {
            lines.clear();
            stream.draw(b, region, &mut lines);
            tracer.all_hits(&lines, &mut raw, &mut hits).unwrap();
            let g = (b % groups as u64) as usize;
            lines_per_group[g] += lines.len() as f64;
            for h in &hits.hits {
                per_patch[scene.triangle_patch[h.triangle as usize] as usize][g] += 1.0;
            }
        }
        for (p, counts) in per_patch.iter().enumerate() {
            let shares: Vec<f64> = counts
                .iter()
                .zip(&lines_per_group)
                .map(|(c, n)| c / n)
                .collect();
            let n = groups as f64;
            let mean = shares.iter().sum::<f64>() / n;
            let var = shares.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
            let se = (var / n).sqrt();
            let expected = expected(p);
            assert!(
                (mean - expected).abs() < 4.5 * se,
                "{label} {}: patch {p}: {mean} hits per line, Crofton {expected} (se {se})",
                tracer.name()
            );
        }
    }
}

/// The same seed gives the same values and standard errors of `measures` on 1 and 2 threads, to the bit.
pub fn same_on_one_and_two_threads(
    scene: &Scene,
    tracer: &dyn Tracer,
    spec: &scene_complexity::internals::run::RunSpec,
    measures: &[scene_complexity::internals::measure::Measure],
) {
    use scene_complexity::internals::analysis::analyze;
    use scene_complexity::internals::run::RunControl;
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| analyze(scene, tracer, spec, &RunControl::default()).unwrap())
    };
    let (one, two) = (on(1), on(2));
    for &m in measures {
        let (a, b) = (one.estimate(m).unwrap(), two.estimate(m).unwrap());
        assert_eq!(a.value.to_bits(), b.value.to_bits(), "{m:?}");
        assert_eq!(
            a.stderr.map(f64::to_bits),
            b.stderr.map(f64::to_bits),
            "{m:?}"
        );
    }
}

/// The unit cube's closed-form I_s (eq. 21 with the exact form factors of its faces: one opposite face,
/// four adjacent ones).
pub fn unit_cube_mutual_information() -> f64 {
    let f_par = ff_parallel_rectangles(1.0, 1.0, 1.0);
    let f_perp = ff_perpendicular_rectangles(1.0, 1.0, 1.0);
    f_par * (6.0 * f_par).log2() + 4.0 * f_perp * (6.0 * f_perp).log2()
}

/// A run of the unit cube reads its closed-form I_s and I_s^c (the calibration's exact value) within
/// 4.5 of its standard errors (plus 1e-6).
pub fn unit_cube_matches_closed_forms(a: &Analysis, label: &str) {
    use scene_complexity::internals::measure::Measure;
    let exact_isc = scene_complexity::calibrate::truth::cube_continuous_mutual_information();
    for (measure, exact) in [
        (Measure::MutualInformation, unit_cube_mutual_information()),
        (Measure::ContinuousMutualInformation, exact_isc),
    ] {
        let e = a.estimate(measure).unwrap();
        let se = e.stderr.unwrap();
        assert!(
            (e.value - exact).abs() < 4.5 * se + 1e-6,
            "{label}: {measure:?} = {} +- {se}, exact {exact}",
            e.value
        );
    }
}

/// Writes an OBJ of slivers: in three parallel planes 2e-3 apart (turned off the axes), strips of long
/// thin triangles (sides 1 by 1e-4 to 1e-2) and a fan of 48 narrow ones, so that a line grazing one
/// plane crosses slivers of the others close by. The tracers' distances of grazing crossings, and the
/// order of close crossings, meet their worst cases here.
pub fn slivers_obj() -> String {
    let (turn_a, turn_b) = (0.37f64, 0.61f64);
    let rotate = |p: [f64; 3]| {
        let (ca, sa, cb, sb) = (turn_a.cos(), turn_a.sin(), turn_b.cos(), turn_b.sin());
        let q = [p[0], ca * p[1] - sa * p[2], sa * p[1] + ca * p[2]];
        [cb * q[0] - sb * q[1], sb * q[0] + cb * q[1], q[2]]
    };
    let mut verts = Vec::new();
    let mut faces = Vec::new();
    for layer in 0..3 {
        let z = 2e-3 * f64::from(layer);
        let mut y = -0.5;
        for k in 0..40 {
            let h = 1e-4 * 100f64.powf(f64::from((k * 7 + layer) % 40) / 39.0);
            let base = verts.len() + 1;
            verts.push([-0.5, y, z]);
            verts.push([0.5, y, z]);
            verts.push([0.5, y + h, z]);
            verts.push([-0.5, y + h, z]);
            faces.push([base, base + 1, base + 2]);
            faces.push([base, base + 2, base + 3]);
            y += h;
        }
        let centre = verts.len() + 1;
        verts.push([0.0, 0.3, z]);
        for k in 0..=48 {
            let angle = std::f64::consts::PI * f64::from(k) / 48.0;
            verts.push([0.45 * angle.cos(), 0.3 + 0.45 * angle.sin(), z]);
        }
        for k in 0..48 {
            faces.push([centre, centre + 1 + k, centre + 2 + k]);
        }
    }
    let mut s = String::new();
    for v in verts {
        let p = rotate(v);
        s.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    }
    for f in faces {
        s.push_str(&format!("f {} {} {}\n", f[0], f[1], f[2]));
    }
    s
}

/// Lines through random points of random triangles of `scene`, at angles of 1e-2 to 1e-6 to the
/// triangle's plane, in random directions within it, from 2 before the point to 2 past it.
pub fn lines_grazing_triangles(
    scene: &Scene,
    rng: &mut rand_pcg::Pcg64,
    count: usize,
) -> Vec<scene_complexity::internals::trace::Line> {
    use rand::Rng;
    let unit = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|x| x / l)
    };
    (0..count)
        .map(|k| {
            let tri = scene.triangles[rng.gen_range(0..scene.triangles.len())];
            let [a, b, c] = tri.map(|v| scene.positions[v as usize].map(f64::from));
            let e1 = [0, 1, 2].map(|i| b[i] - a[i]);
            let e2 = [0, 1, 2].map(|i| c[i] - a[i]);
            let n = unit([
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ]);
            let u = unit(e1);
            let w = [
                n[1] * u[2] - n[2] * u[1],
                n[2] * u[0] - n[0] * u[2],
                n[0] * u[1] - n[1] * u[0],
            ];
            let (l1, l2) = loop {
                let (l1, l2): (f64, f64) = (rng.gen(), rng.gen());
                if l1 + l2 < 1.0 {
                    break (l1, l2);
                }
            };
            let p = [0, 1, 2].map(|i| a[i] + l1 * e1[i] + l2 * e2[i]);
            let sine = 10f64.powi(-2 - (k % 5) as i32) * if k % 2 == 0 { 1.0 } else { -1.0 };
            let cosine = (1.0 - sine * sine).sqrt();
            let angle: f64 = rng.gen_range(0.0..std::f64::consts::TAU);
            let d =
                [0, 1, 2].map(|i| cosine * (angle.cos() * u[i] + angle.sin() * w[i]) + sine * n[i]);
            scene_complexity::internals::trace::Line {
                origin: [0, 1, 2].map(|i| (p[i] - 2.0 * d[i]) as f32),
                dir: d.map(|x| x as f32),
                t_max: 4.0,
            }
        })
        .collect()
}

/// The faces of a box whose corner `i` has bits x = 1, y = 2, z = 4: quads counter-clockwise seen from
/// outside.
pub const CUBE_QUADS: [[usize; 4]; 6] = [
    [0, 4, 6, 2],
    [1, 3, 7, 5],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 2, 3, 1],
    [4, 5, 7, 6],
];
