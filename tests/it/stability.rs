//! Stiff and extreme geometry (issue 8): almost-touching and touching surfaces, grazing lines, lines
//! through edges and vertices of stiff scenes, tiny and huge scenes, very fine meshes with few lines,
//! coplanar overlapping faces and zero-area triangles.
//!
//! Each test states the behaviour expected of scx and checks it against a closed form or an independent
//! reference computed here (never against scx's own earlier output).

use crate::support;
use scene_complexity::internals::measure::Measure;
use scene_complexity::internals::scenes;

use std::f64::consts::{LN_2, PI};

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use scene_complexity::internals::analysis::{analyze, Analysis};
use scene_complexity::internals::measure::channel::row_totals;
use scene_complexity::internals::run::{RunControl, RunSpec};
use scene_complexity::internals::sample::pairs::{segments, Segment};
use scene_complexity::internals::scene::{Material, Scene, SceneBuilder};
use scene_complexity::internals::trace::{make_tracer, Backend, Line, LineHits, Query, Tracer};
use support::{count_entries, ff_parallel_rectangles, room_with_box_obj};

// ------------------------------------------------------------------------------------------------
// Helpers.

fn tracer(scene: &Scene) -> Box<dyn Tracer> {
    make_tracer(Backend::default_available(), scene, Query::Single).expect("tracer")
}

fn run(scene: &Scene, lines: u64, seed: u64) -> Analysis {
    analyze(
        scene,
        tracer(scene).as_ref(),
        &RunSpec::new(lines, seed),
        &RunControl::default(),
    )
    .expect("analysis runs")
}

fn trace(tracer: &dyn Tracer, lines: &[Line]) -> LineHits {
    let mut raw = Vec::new();
    let mut hits = LineHits::default();
    tracer.all_hits(lines, &mut raw, &mut hits).expect("traces");
    hits
}

/// Every reported measure is a finite number (or absent), never NaN or infinite.
fn assert_all_finite(a: &Analysis, what: &str) {
    for (name, e) in [
        ("H_p", a.estimate(Measure::PositionalEntropy)),
        ("H_s", a.estimate(Measure::Entropy)),
        ("H_s corrected", a.estimate(Measure::EntropyCorrected)),
        ("H(X,Y)", a.estimate(Measure::JointEntropy)),
        ("I_s", a.estimate(Measure::MutualInformation)),
        (
            "I_s corrected",
            a.estimate(Measure::MutualInformationCorrected),
        ),
        ("I_s^c", a.estimate(Measure::ContinuousMutualInformation)),
        ("accuracy", a.estimate(Measure::Accuracy)),
        ("mse", a.estimate(Measure::MsePerLine)),
    ] {
        if let Some(e) = e {
            assert!(e.value.is_finite(), "{what}: {name} = {}", e.value);
            if let Some(se) = e.stderr {
                assert!(se.is_finite(), "{what}: {name} stderr {se}");
            }
        }
    }
    assert!(
        a.tally.counters.cmi_sum.value().is_finite(),
        "{what}: eq. (27) sum"
    );
}

/// Sum of the pair counts between the patches of `from` and those of `to` (ordered: N_ij for i in
/// `from`, j in `to`, a self pair counting twice as in the form factors), and the row total of `from`.
fn block_counts(
    a: &Analysis,
    n: usize,
    from: &dyn Fn(usize) -> bool,
    to: &dyn Fn(usize) -> bool,
) -> (f64, f64) {
    let counts = a.tally.counts.as_ref().expect("counts");
    let rows = row_totals(n, counts, &a.tally.escapes_by_patch.dense());
    let mut block = 0.0;
    counts.for_each(|i, j, c| {
        let (i, j) = (i as usize, j as usize);
        let c = c as f64;
        if from(i) && to(j) {
            block += c;
        }
        if from(j) && to(i) {
            block += c;
        }
    });
    let total: f64 = (0..n).filter(|&i| from(i)).map(|i| rows[i]).sum();
    (block, total)
}

fn wall() -> Material {
    Material::grey("wall", 0.5, 0.0)
}

/// Adds an axis-aligned box `[lo, hi]` as six quads, normals outwards (`inward == false`) or inwards.
/// Returns the patch index of its first face; faces come in the order -x, +x, -y, +y, -z, +z.
fn add_box(b: &mut SceneBuilder, lo: [f64; 3], hi: [f64; 3], inward: bool, m: u32, name: &str) {
    let corner = |k: usize| {
        [
            if k & 1 == 0 { lo[0] } else { hi[0] },
            if k & 2 == 0 { lo[1] } else { hi[1] },
            if k & 4 == 0 { lo[2] } else { hi[2] },
        ]
    };
    let quads = crate::support::CUBE_QUADS;
    for (f, q) in quads.iter().enumerate() {
        let mut idx: Vec<u32> = q.iter().map(|&k| b.vertex(corner(k))).collect();
        if inward {
            idx.reverse();
        }
        b.polygon(&idx, m, format!("{name} face {f}"));
    }
}

/// A quad with the given corners (counter-clockwise seen from its front).
fn add_quad(b: &mut SceneBuilder, corners: [[f64; 3]; 4], m: u32, name: &str) {
    let idx: Vec<u32> = corners.iter().map(|&p| b.vertex(p)).collect();
    b.polygon(&idx, m, name.to_string());
}

/// The unit-cube room `[0, 1]^3` (inward normals), its floor cut into the square `[a, c]^2` (first
/// floor patch) and four rectangles around it, so that the square is a patch of its own.
/// Patch order: the floor square, 4 floor rectangles, then the 5 other walls.
fn room_with_floor_square(b: &mut SceneBuilder, a: f64, c: f64, m: u32) {
    let p = |x: f64, y: f64| [x, y, 0.0];
    // Floor faces up (+z): counter-clockwise seen from above.
    add_quad(b, [p(a, a), p(c, a), p(c, c), p(a, c)], m, "floor square");
    add_quad(
        b,
        [p(0.0, 0.0), p(1.0, 0.0), p(1.0, a), p(0.0, a)],
        m,
        "floor south",
    );
    add_quad(
        b,
        [p(0.0, c), p(1.0, c), p(1.0, 1.0), p(0.0, 1.0)],
        m,
        "floor north",
    );
    add_quad(b, [p(0.0, a), p(a, a), p(a, c), p(0.0, c)], m, "floor west");
    add_quad(b, [p(c, a), p(1.0, a), p(1.0, c), p(c, c)], m, "floor east");
    let room = scene_complexity::internals::scenes::solids::cube("room", 1).expect("cube");
    // The other five walls of the unit cube, inward, from the built-in cube (face 4 is the floor z = 0).
    for (k, patch) in room.patches.iter().enumerate() {
        if k == 4 {
            continue;
        }
        let idx: Vec<u32> = room
            .polygon(patch)
            .iter()
            .map(|&v| b.vertex(room.vertices[v as usize]))
            .collect();
        b.polygon(&idx, m, format!("room wall {k}"));
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

// ------------------------------------------------------------------------------------------------
// Almost-touching surfaces: two nearly concentric spheres.

/// The triangles of the icosphere `@sphere:level` (unit circumradius), counter-clockwise seen from
/// outside (outward normals).
fn icosphere(level: usize) -> Vec<[[f64; 3]; 3]> {
    let s = scenes::load(&format!("@sphere:{level}")).unwrap();
    s.patches
        .iter()
        .map(|p| {
            // The built-in faces inwards: reverse to face outwards.
            let v: Vec<[f64; 3]> = s
                .polygon(p)
                .iter()
                .map(|&k| s.vertices[k as usize].to_array())
                .collect();
            [v[2], v[1], v[0]]
        })
        .collect()
}

/// The outer icosphere (radius 1, facing inwards: patches `0..n`) and the inner one (radius `1 - gap`,
/// facing outwards: patches `n..2n`, patch `n + k` directly below patch `k`).
fn nested_spheres(tris: &[[[f64; 3]; 3]], gap: f64) -> Scene {
    let mut b = SceneBuilder::new(format!("nested spheres, gap {gap:e}"));
    let m = b.material(wall());
    for (k, t) in tris.iter().enumerate() {
        let idx = [t[2], t[1], t[0]].map(|p| b.vertex(p));
        b.polygon(&idx, m, format!("outer {k}"));
    }
    let r = 1.0 - gap;
    for (k, t) in tris.iter().enumerate() {
        let idx = t.map(|p| b.vertex(p.map(|c| c * r)));
        b.polygon(&idx, m, format!("inner {k}"));
    }
    b.build().unwrap()
}

/// A convex polyhedron given by triangles with outward normals: planes `n . x = p`.
struct Convex {
    tris: Vec<[[f64; 3]; 3]>,
    normals: Vec<[f64; 3]>,
    offsets: Vec<f64>,
    areas: Vec<f64>,
}

impl Convex {
    fn new(tris: Vec<[[f64; 3]; 3]>) -> Self {
        let mut normals = Vec::new();
        let mut offsets = Vec::new();
        let mut areas = Vec::new();
        for t in &tris {
            let c = cross(sub(t[1], t[0]), sub(t[2], t[0]));
            let l = norm(c);
            let n = c.map(|x| x / l);
            normals.push(n);
            offsets.push((dot(n, t[0]) + dot(n, t[1]) + dot(n, t[2])) / 3.0);
            areas.push(0.5 * l);
        }
        Convex {
            tris,
            normals,
            offsets,
            areas,
        }
    }

    fn area(&self) -> f64 {
        self.areas.iter().sum()
    }

    /// Where a ray from inside leaves: `(t, face)`.
    fn exit(&self, x: [f64; 3], w: [f64; 3]) -> (f64, usize) {
        let mut best = (f64::INFINITY, usize::MAX);
        for (f, (&n, &p)) in self.normals.iter().zip(&self.offsets).enumerate() {
            let c = dot(n, w);
            if c > 0.0 {
                let t = (p - dot(n, x)) / c;
                if t < best.0 {
                    best = (t, f);
                }
            }
        }
        best
    }
}

/// A uniform point on triangle `t` and a cosine-distributed direction about the unit normal `n`.
fn local_line(rng: &mut Pcg64, t: &[[f64; 3]; 3], n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let (mut u, mut v): (f64, f64) = (rng.gen(), rng.gen());
    if u + v > 1.0 {
        (u, v) = (1.0 - u, 1.0 - v);
    }
    let x = [0, 1, 2].map(|a| t[0][a] + u * (t[1][a] - t[0][a]) + v * (t[2][a] - t[0][a]));
    let helper = if n[0].abs() < 0.6 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let e1 = {
        let c = cross(n, helper);
        c.map(|x| x / norm(c))
    };
    let e2 = cross(n, e1);
    let (s, phi): (f64, f64) = (rng.gen(), 2.0 * PI * rng.gen::<f64>());
    let (r, h) = (s.sqrt(), (1.0 - s).sqrt());
    let w = [0, 1, 2].map(|a| r * phi.cos() * e1[a] + r * phi.sin() * e2[a] + h * n[a]);
    (x, w)
}

/// Independent reference for eq. (27) on two nested convex polyhedra (`inner` strictly inside `outer`),
/// by *local* lines in f64: a uniform point on the inner surface and a cosine-distributed direction give
/// the inner -> outer segments exactly (a ray leaving a convex inner body meets only the outer one).
/// The outer -> outer segments (a fraction ~ 1 - A_in/A_out of the outer's) are those of a sphere, whose
/// kernel is the constant 1 / (4 pi R^2): their term is log2(A_T / (4 pi)), to O(faceting).
///
/// Segments of each kind, counted once: A_in (inner-outer) and (A_out - A_in) / 2 (outer-outer), of
/// A_T / 2 in all. Returns the value and its Monte Carlo standard error.
fn nested_reference(inner: &Convex, outer: &Convex, samples: usize, seed: u64) -> (f64, f64) {
    let (a_in, a_out) = (inner.area(), outer.area());
    let a_t = a_in + a_out;
    let mut rng = Pcg64::seed_from_u64(seed);
    let cumulative: Vec<f64> = inner
        .areas
        .iter()
        .scan(0.0, |s, a| {
            *s += a;
            Some(*s)
        })
        .collect();
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..samples {
        let pick = rng.gen::<f64>() * a_in;
        let f = cumulative
            .partition_point(|&c| c < pick)
            .min(inner.tris.len() - 1);
        let n = inner.normals[f];
        let (x, w) = local_line(&mut rng, &inner.tris[f], n);
        let (t, g) = outer.exit(x, w);
        let term = (a_t * dot(n, w) * dot(outer.normals[g], w) / (PI * t * t)).log2();
        sum += term;
        sum2 += term * term;
    }
    let m = samples as f64;
    let mean = sum / m;
    let se = ((sum2 / m - mean * mean) / m).sqrt();
    let outer_outer = (a_t / (4.0 * PI)).log2();
    let w_io = a_in / (a_t / 2.0);
    let value = w_io * mean + (1.0 - w_io) * outer_outer;
    (value, w_io * se)
}

/// Two concentric icospheres, outer radius 1 facing in, inner radius 1 - gap facing out, for gaps of
/// 1e-3 to 1e-6 of the radius (the inner and outer f32 vertices are then ~16 ulps apart).
///
/// Expected: the scene is closed, so nothing escapes; the inner sphere sees only the outer one, so
/// F(inner -> outer) = 1 exactly (no inner-inner pair can exist); by reciprocity F(outer -> inner) =
/// A_in / A_out = (1 - gap)^2 (scaled copies); each inner face sees mostly the outer face above it,
/// losing a fraction ~ perimeter * h / (2 area) (h: the local gap) past its edges, so F -> 1 as gap -> 0.
/// I_s^c grows like -2 log2(gap) (the kernel cos cos / (pi d^2) of parallel planes at distance h averages
/// to log2(1 / (pi h^2)) - 2 log2(e)), stays finite at every gap, and equals the local-line f64
/// reference above within the statistical errors. No pair has d = 0.
#[test]
fn nearly_concentric_spheres_close_to_touching() {
    let tris = icosphere(2);
    let n = tris.len();
    let outer = Convex::new(tris.clone());
    for (k, &gap) in [1e-3, 1e-4, 1e-5, 1e-6].iter().enumerate() {
        let scene = nested_spheres(&tris, gap);
        assert_eq!(scene.patch_count(), 2 * n);
        let a = run(&scene, 200_000, 31 + k as u64);
        let what = format!("gap {gap:e}");
        assert_all_finite(&a, &what);
        assert_eq!(a.escapes, 0, "{what}: a closed scene has no escapes");
        assert_eq!(a.degenerate_pairs, 0, "{what}");

        let is_inner = |i: usize| i >= n;
        let is_outer = |i: usize| i < n;
        let (in_in, in_total) = block_counts(&a, 2 * n, &is_inner, &is_inner);
        let (in_out, _) = block_counts(&a, 2 * n, &is_inner, &is_outer);
        assert_eq!(
            in_in, 0.0,
            "{what}: the convex inner sphere cannot see itself"
        );
        assert_eq!(in_out, in_total, "{what}: F(inner -> outer) = 1");

        let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
        let ratio = areas[n..].iter().sum::<f64>() / areas[..n].iter().sum::<f64>();
        assert!(
            (ratio - (1.0 - gap).powi(2)).abs() < 1e-12,
            "{what}: area ratio {ratio}"
        );
        let (out_in, out_total) = block_counts(&a, 2 * n, &is_outer, &is_inner);
        let f = out_in / out_total;
        let sigma = (ratio * (1.0 - ratio) / out_total).sqrt();
        assert!(
            (f - ratio).abs() < 4.5 * sigma + 1.0 / out_total,
            "{what}: F(outer -> inner) = {f}, A_in / A_out = {ratio} (sigma {sigma})"
        );

        // Inner face k -> outer face k: the leak past the edges, first order in the local gap.
        let inner = Convex::new(
            tris.iter()
                .map(|t| t.map(|p| p.map(|c| c * (1.0 - gap))))
                .collect(),
        );
        let leak_expected: f64 = (0..n)
            .map(|f| {
                let t = &inner.tris[f];
                let perimeter: f64 = (0..3).map(|e| norm(sub(t[(e + 1) % 3], t[e]))).sum();
                let h = outer.offsets[f] - inner.offsets[f];
                perimeter * h / 2.0
            })
            .sum::<f64>()
            / inner.area();
        let counts = a.tally.counts.as_ref().unwrap();
        let mut matched = 0.0;
        counts.for_each(|i, j, c| {
            if j as usize == i as usize + n {
                matched += c as f64;
            }
        });
        let leak = 1.0 - matched / in_total;
        assert!(
            (leak - leak_expected).abs()
                < 0.25 * leak_expected + 5.0 * (leak_expected / in_total).sqrt(),
            "{what}: inner face -> the outer face above it leaks {leak}, expected ~{leak_expected}"
        );

        let (reference, se_ref) = nested_reference(&inner, &outer, 300_000, 77 + k as u64);
        let cmi = a.estimate(Measure::ContinuousMutualInformation).unwrap();
        let se = cmi.stderr.unwrap();
        assert!(
            (cmi.value - reference).abs() < 4.5 * (se * se + se_ref * se_ref).sqrt() + 3e-3,
            "{what}: I_s^c = {} +- {se}, local-line reference {reference} +- {se_ref}",
            cmi.value
        );
        if gap <= 1e-5 {
            // The thin-gap limit in closed form: the inner-outer pairs average log2(A_T / (pi h^2)) -
            // 2 log2(e) (h: the local gap of each inner face), up to O(h perimeter / area).
            let a_t = inner.area() + outer.area();
            let e_io: f64 = (0..n)
                .map(|f| {
                    let h = outer.offsets[f] - inner.offsets[f];
                    inner.areas[f] * ((a_t / (PI * h * h)).log2() - 2.0 / LN_2)
                })
                .sum::<f64>()
                / inner.area();
            let w_io = inner.area() / (a_t / 2.0);
            let limit = w_io * e_io + (1.0 - w_io) * (a_t / (4.0 * PI)).log2();
            assert!(
                (cmi.value - limit).abs() < 4.5 * se + 2e-3,
                "{what}: I_s^c = {} +- {se}, thin-gap limit {limit}",
                cmi.value
            );
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Almost-touching and touching surfaces: a cube just above the floor.

/// Side of the small cube, and where it stands on the floor square `[A, C]^2`.
const SIDE: f64 = 0.2;
const A: f64 = 0.4;
const C: f64 = 0.6;
/// Patches of [`cube_above_floor`]: the floor square under the cube, and the cube's bottom face.
const FLOOR_SQUARE: usize = 0;
const BOTTOM: usize = 10 + 4;

/// The unit-cube room with a cube of side 0.2 floating `gap` above the floor (0: standing on it).
fn cube_above_floor(gap: f64) -> Scene {
    let mut b = SceneBuilder::new(format!("cube {gap:e} above the floor"));
    let m = b.material(wall());
    room_with_floor_square(&mut b, A, C, m);
    add_box(&mut b, [A, A, gap], [C, C, gap + SIDE], false, m, "cube");
    b.build().unwrap()
}

/// A cube of side s = 0.2 floating at gap = 1e-3 ... 1e-6 (of the room's side) above the floor square
/// under it, and standing on it (gap 0).
///
/// Expected, gap > 0: the cube's bottom and the floor square are directly opposed parallel squares, so
/// F(bottom -> floor square) is the closed form of parallel squares at distance gap (-> 1); nothing
/// escapes, no pair has d = 0, every measure is finite. The bottom's pairs (a fraction w = 2 A_b F / A_T
/// of all pairs) average log2(A_T / (pi gap^2)) - 2 log2(e) + O(gap / s): going from gap 1e-4 to 1e-6
/// raises I_s^c by w * 2 log2(100) and changes nothing else to first order.
///
/// Expected, gap = 0: every line through the bottom square yields one pair of coincident points (the
/// bottom leaves towards the floor at d = 0), counted in `degenerate_pairs` and in the form factors
/// (F(bottom -> floor square) = 1 exactly) but left out of eq. (27); by Crofton's formula their number is
/// N A_b / (2 pi R^2). I_s^c stays finite.
#[test]
fn cube_almost_touching_and_touching_the_floor() {
    let lines = 200_000;
    let mut cmi = Vec::new();
    for gap in [1e-3, 1e-4, 1e-5, 1e-6] {
        let scene = cube_above_floor(gap);
        let n = scene.patch_count();
        assert_eq!(n, 16);
        assert!(
            (scene.patches[BOTTOM].normal[2] + 1.0).abs() < 1e-12,
            "the bottom faces down"
        );
        let a = run(&scene, lines, 5);
        let what = format!("gap {gap:e}");
        assert_all_finite(&a, &what);
        assert_eq!((a.escapes, a.degenerate_pairs), (0, 0), "{what}");
        let (to_square, total) = block_counts(&a, n, &|i| i == BOTTOM, &|j| j == FLOOR_SQUARE);
        let exact = ff_parallel_rectangles(SIDE, SIDE, gap);
        let f = to_square / total;
        let sigma = (exact * (1.0 - exact) / total).sqrt();
        assert!(
            (f - exact).abs() < 4.5 * sigma + 1.0 / total,
            "{what}: F(bottom -> floor square) = {f}, closed form {exact} (sigma {sigma})"
        );
        cmi.push((
            gap,
            exact,
            a.estimate(Measure::ContinuousMutualInformation).unwrap(),
        ));
    }
    let a_t = 6.0 + 6.0 * SIDE * SIDE;
    let (g1, f1, c1) = cmi[1];
    let (g2, f2, c2) = cmi[3];
    let w = 2.0 * SIDE * SIDE * 0.5 * (f1 + f2) / a_t;
    let expected = w * 2.0 * (g1 / g2).log2();
    let got = c2.value - c1.value;
    let se = (c1.stderr.unwrap().powi(2) + c2.stderr.unwrap().powi(2)).sqrt();
    assert!(
        (got - expected).abs() < 4.5 * se + 2e-3,
        "I_s^c(1e-6) - I_s^c(1e-4) = {got} +- {se}, thin-gap closed form {expected}"
    );

    // Touching.
    let scene = cube_above_floor(0.0);
    let a = run(&scene, lines, 5);
    assert_all_finite(&a, "touching");
    assert_eq!(a.escapes, 0, "touching");
    let (to_square, total) = block_counts(&a, 16, &|i| i == BOTTOM, &|j| j == FLOOR_SQUARE);
    assert_eq!(to_square, total, "touching: F(bottom -> floor square) = 1");
    let radius = 3f64.sqrt() / 2.0;
    let expected = lines as f64 * SIDE * SIDE / radius.powi(2) / (2.0 * PI);
    let got = a.degenerate_pairs as f64;
    assert!(
        (got - expected).abs() < 5.0 * expected.sqrt(),
        "touching: {got} pairs at d = 0, Crofton expects {expected}"
    );
    assert_eq!(
        a.tally.counters.cmi_pairs + a.degenerate_pairs,
        a.pairs,
        "d = 0 pairs are left out of eq. (27) only"
    );
}

// ------------------------------------------------------------------------------------------------
// Coincident surfaces: a two-sided panel, a decal on the floor, a duplicated face.

/// The unit-cube room cut in two by a two-sided panel at x = 0.5: two coincident quads with the same
/// vertices facing opposite ways (a thin wall modelled as two faces, common in real models).
///
/// Expected: a line crossing the panel arrives at one side's front and leaves from the other side's
/// front: two ordinary pairs and a zero-length unpaired segment between the two faces, never a pair of
/// the two sides at d = 0, whichever order f32 rounding gives the two hits. Each side sees its half-room
/// only: F(side -> the parallel wall 0.5 away) is the closed form of parallel unit squares at distance
/// 0.5, and F(one side -> the other) = 0. Nothing escapes.
#[test]
fn a_two_sided_panel_is_two_surfaces_back_to_back() {
    let mut b = SceneBuilder::new("room with a two-sided panel");
    let m = b.material(wall());
    add_box(&mut b, [0.0; 3], [1.0; 3], true, m, "room");
    let p = |y: f64, z: f64| [0.5, y, z];
    // Side A faces -x, side B faces +x (counter-clockwise seen from the front).
    add_quad(
        &mut b,
        [p(0.0, 0.0), p(0.0, 1.0), p(1.0, 1.0), p(1.0, 0.0)],
        m,
        "panel A",
    );
    add_quad(
        &mut b,
        [p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)],
        m,
        "panel B",
    );
    let scene = b.build().unwrap();
    let (side_a, side_b) = (6, 7);
    assert!(scene.patches[side_a].normal[0] < -0.99 && scene.patches[side_b].normal[0] > 0.99);
    let a = run(&scene, 200_000, 8);
    assert_all_finite(&a, "panel");
    assert_eq!(a.escapes, 0, "panel: no escapes");
    assert_eq!(
        a.degenerate_pairs, 0,
        "panel: its two sides never pair at d = 0"
    );
    let exact = ff_parallel_rectangles(1.0, 1.0, 0.5);
    for (side, wall) in [(side_a, 0), (side_b, 1)] {
        let (to_wall, total) = block_counts(&a, 8, &|i| i == side, &|j| j == wall);
        let f = to_wall / total;
        let sigma = (exact * (1.0 - exact) / total).sqrt();
        assert!(
            (f - exact).abs() < 4.5 * sigma,
            "panel side {side}: F to the wall 0.5 away = {f}, closed form {exact}"
        );
        let (through, _) =
            block_counts(&a, 8, &|i| i == side, &|j| j == 1 - wall || j == 13 - side);
        assert_eq!(through, 0.0, "panel side {side} sees through the panel");
    }
}

/// A decal: a square `[0.3, 0.7]^2` on the floor of the unit-cube room, coplanar with it and facing the
/// same way, with vertices of its own. And a duplicated face: the ceiling quad given twice.
///
/// Decided behaviour: two coplanar overlapping faces facing the same way are at the same place, so only
/// one of them can be seen there: scx gives every crossing of the overlap to the face first in the file
/// (the floor, the first ceiling), on both sides, deterministically. The decal is then never left by a
/// line: it is reported among the unsampled patches with its area fraction; the crossings of the
/// overlap are counted (`coincident_crossings`, by Crofton N A_decal / (2 pi R^2)) so the report can
/// warn. A face repeating an earlier face's corners in the same order could never be seen at all: it is
/// dropped when the scene is built, with a warning naming both. The floor's row is that of the plain
/// unit cube: F(floor -> ceiling) is the closed form of parallel unit squares.
#[test]
fn coplanar_overlapping_faces_are_seen_once_and_reported() {
    let mut b = SceneBuilder::new("room with a decal and a duplicated ceiling");
    let m = b.material(wall());
    add_box(&mut b, [0.0; 3], [1.0; 3], true, m, "room");
    let p = |x: f64, y: f64| [x, y, 0.0];
    add_quad(
        &mut b,
        [p(0.3, 0.3), p(0.7, 0.3), p(0.7, 0.7), p(0.3, 0.7)],
        m,
        "decal",
    );
    let ceiling: Vec<u32> = {
        let q = |x: f64, y: f64| [x, y, 1.0];
        [q(0.0, 0.0), q(0.0, 1.0), q(1.0, 1.0), q(1.0, 0.0)]
            .map(|v| b.vertex(v))
            .to_vec()
    };
    b.polygon(&ceiling, m, "ceiling again");
    let scene = b.build().unwrap();
    let (floor, ceiling, decal) = (4, 5, 6);
    assert_eq!(scene.patch_count(), 7, "the repeated ceiling is dropped");
    assert!(scene.patches[decal].normal[2] > 0.99);
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.message.contains("dropped 1 face(s)")
                && w.message.contains("ceiling again repeats room face 5")),
        "the repeated face is named: {:?}",
        scene.warnings
    );
    let lines = 200_000u64;
    let a = run(&scene, lines, 12);
    assert_all_finite(&a, "decal");
    assert_eq!((a.escapes, a.degenerate_pairs), (0, 0));
    let (n_unsampled, fraction) = a.unsampled.unwrap();
    assert_eq!(n_unsampled, 1, "the decal is never seen");
    let a_t: f64 = scene.patches.iter().map(|p| p.area).sum();
    let expected_fraction = scene.patches[decal].area / a_t;
    assert!(
        (fraction - expected_fraction).abs() < 1e-12,
        "{fraction} vs {expected_fraction}"
    );
    let decal_area = scene.patches[decal].area;
    let expected = lines as f64 * decal_area / (2.0 * PI);
    let got = a.tally.counters.coincident_crossings as f64;
    assert!(
        (got - expected).abs() < 5.0 * expected.sqrt(),
        "{got} crossings of the overlap, Crofton expects {expected}"
    );
    let exact = ff_parallel_rectangles(1.0, 1.0, 1.0);
    let (up, total) = block_counts(&a, 7, &|i| i == floor, &|j| j == ceiling);
    let sigma = (exact * (1.0 - exact) / total).sqrt();
    assert!(
        (up / total - exact).abs() < 4.5 * sigma,
        "F(floor -> ceiling) = {}",
        up / total
    );
}

// ------------------------------------------------------------------------------------------------
// Grazing lines.

/// Lines through the `@cube` enclosure that cross its floor at a grazing angle alpha, from 0.1 down to
/// 1e-9 radians, and one lying exactly in the floor's plane.
///
/// Expected (hand-computed in tracing space, where the floor is z = -1/sqrt(3)): a line rising through
/// the floor at P with direction (cos a, 0, sin a) meets the wall x = +1/sqrt(3) next; scx pairs the
/// floor with that wall, with cos_from = sin a, cos_to = cos a and the distance between the two planes
/// along the line, each recomputed in f64 (relative error ~1e-16 / sin a). The eq. (27) term
/// log2(cos cos / d^2) goes to -infinity only like log2(sin a): finite for every a > 0. A line in the
/// floor's plane does not hit the floor (coplanar: the watertight test reports no crossing); it meets the
/// walls x = -+1/sqrt(3) at their bottom edges and pairs them at d = 2/sqrt(3), the limit of lines just
/// above the floor. Nothing is NaN, nothing escapes.
#[test]
fn grazing_lines_give_finite_exact_pairs() {
    let scene = scenes::load("@cube").unwrap();
    let h = 1.0 / 3f64.sqrt();
    let (floor, east, west) = (4u32, 1u32, 0u32);
    for tracer in support::all_tracers(&scene) {
        for alpha in [1e-1f64, 1e-3, 1e-5, 1e-7, 1e-9, 0.0] {
            let (s, c) = alpha.sin_cos();
            let dir = [c as f32, 0.0, s as f32];
            // Cross the floor's plane at x = -0.2, y = 0.1, starting 3 units before.
            let origin = [
                (-0.2 - 3.0 * c) as f32,
                0.1,
                if alpha == 0.0 {
                    (-h) as f32
                } else {
                    (-h - 3.0 * s) as f32
                },
            ];
            let line = Line {
                origin,
                dir,
                t_max: 6.0,
            };
            let hits = trace(tracer.as_ref(), &[line]);
            let row = hits.of_line(0);
            let mut seen = Vec::new();
            segments(&scene, &line, row, |seg| seen.push(seg));
            let what = format!("{}: alpha {alpha:e}: {row:?} -> {seen:?}", tracer.name());
            // By hand, in f64, from the traced (f32) line.
            let o = origin.map(f64::from);
            let d = {
                let d = dir.map(f64::from);
                let l = norm(d);
                d.map(|x| x / l)
            };
            let t_floor = (-h - o[2]) / d[2];
            let t_east = (h - o[0]) / d[0];
            let t_west = (-h - o[0]) / d[0];
            match seen.as_slice() {
                [Segment::Pair {
                    from,
                    to,
                    distance,
                    cos_from,
                    cos_to,
                }] if alpha >= 1e-5 => {
                    assert_eq!((*from, *to), (floor, east), "{what}");
                    assert!((cos_from / d[2] - 1.0).abs() < 1e-12, "{what}");
                    assert!((cos_to / d[0] - 1.0).abs() < 1e-12, "{what}");
                    let exact = t_east - t_floor;
                    assert!(
                        (distance / exact - 1.0).abs() < 1e-9,
                        "{what}: d = {distance}, by hand {exact}"
                    );
                    let term = (cos_from * cos_to / (distance * distance)).log2();
                    assert!(term.is_finite(), "{what}");
                }
                [Segment::Pair {
                    from, to, distance, ..
                }] if alpha == 0.0 => {
                    assert_eq!((*from, *to), (west, east), "{what}");
                    assert!((distance - (t_east - t_west)).abs() < 1e-12, "{what}");
                }
                // Below f32 resolution of the floor's plane the line may cross at the floor or at the wall
                // edge: either way one finite pair, never an escape.
                [Segment::Pair {
                    distance,
                    cos_from,
                    cos_to,
                    ..
                }] => {
                    assert!(distance.is_finite() && *distance > 0.0, "{what}");
                    assert!(
                        (cos_from * cos_to / (distance * distance))
                            .log2()
                            .is_finite(),
                        "{what}"
                    );
                }
                _ => panic!("expected one pair: {what}"),
            }
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Lines through edges and vertices of stiff scenes.

/// A closed bipyramid (outward normals): apexes (0, 0, +-1), `k` equator vertices on the unit circle,
/// so each apex is shared by `k` thin triangles.
fn bipyramid(k: usize) -> Scene {
    let mut b = SceneBuilder::new(format!("bipyramid {k}"));
    let m = b.material(wall());
    let top = b.vertex([0.0, 0.0, 1.0]);
    let bottom = b.vertex([0.0, 0.0, -1.0]);
    let ring: Vec<u32> = (0..k)
        .map(|i| {
            let a = 2.0 * PI * i as f64 / k as f64;
            b.vertex([a.cos(), a.sin(), 0.0])
        })
        .collect();
    for i in 0..k {
        let (p, q) = (ring[i], ring[(i + 1) % k]);
        b.polygon(&[top, p, q], m, format!("upper {i}"));
        b.polygon(&[bottom, q, p], m, format!("lower {i}"));
    }
    b.build().unwrap()
}

/// Lines through vertices where many triangles meet, and through the vertices and edges of the nearly
/// touching spheres.
///
/// Expected: (a) a line from an apex of a bipyramid whose 256 upper triangles all own that apex, into
/// the solid, crosses its surface exactly twice (the 256 reports of the apex crossing are one crossing),
/// giving escape, unpaired (inside the solid), escape; quickly (the merging of a crossing's reports is
/// near-linear in their number). (b) Lines through vertices and points of edges of the inner sphere of
/// two spheres 1e-5 apart, nudged by up to 1e-7 (below the gap): every line crosses each closed sphere
/// an even number of times, and nothing escapes (the closed outer sphere surrounds everything). The
/// Embree backend misses a crossing on a few of these lines (see the comment at the end).
#[test]
fn lines_through_stiff_vertices_and_edges_keep_parity() {
    let k = 256;
    let scene = bipyramid(k);
    let mut rng = Pcg64::seed_from_u64(3);
    let mut lines = Vec::new();
    for _ in 0..200 {
        // Towards a point well inside, from the top apex (tracing space: the scene is already unit).
        let target = [
            rng.gen_range(-0.3..0.3),
            rng.gen_range(-0.3..0.3),
            rng.gen_range(-0.5..0.2),
        ];
        let d = sub(target, [0.0, 0.0, 1.0]);
        let d = d.map(|x| x / norm(d));
        lines.push(Line {
            origin: [0, 1, 2].map(|a| ([0.0, 0.0, 1.0][a] - 2.0 * d[a]) as f32),
            dir: d.map(|x| x as f32),
            t_max: 5.0,
        });
    }
    for tracer in support::all_tracers(&scene) {
        let hits = trace(tracer.as_ref(), &lines);
        for (i, line) in lines.iter().enumerate() {
            let row = hits.of_line(i);
            assert_eq!(row.len(), 2, "{}: {line:?}: {row:?}", tracer.name());
            let mut seen = Vec::new();
            segments(&scene, line, row, |s| seen.push(s));
            assert!(
                matches!(
                    seen.as_slice(),
                    [
                        Segment::Escape { .. },
                        Segment::Unpaired,
                        Segment::Escape { .. }
                    ]
                ),
                "{seen:?}"
            );
        }
    }

    let tris = icosphere(2);
    let scene = nested_spheres(&tris, 1e-5);
    let n = tris.len();
    let inner_vertices: Vec<[f64; 3]> = scene.patches[n..]
        .iter()
        .flat_map(|p| {
            scene
                .polygon(p)
                .iter()
                .map(|&v| scene.positions[v as usize].map(f64::from))
        })
        .collect();
    let mut lines = Vec::new();
    for i in 0..4000 {
        let v = inner_vertices[rng.gen_range(0..inner_vertices.len())];
        let w = inner_vertices[rng.gen_range(0..inner_vertices.len())];
        let f = if i % 2 == 0 {
            0.0
        } else {
            rng.gen_range(0.0..1.0)
        };
        let through = [0, 1, 2].map(|a| v[a] + f * (w[a] - v[a]) + rng.gen_range(-1e-7..1e-7));
        let d = {
            let d: [f64; 3] = [0; 3].map(|_| rng.gen_range(-1.0..1.0));
            d.map(|x| x / norm(d))
        };
        lines.push(Line {
            origin: [0, 1, 2].map(|a| (through[a] - 2.0 * d[a]) as f32),
            dir: d.map(|x| x as f32),
            t_max: 4.0,
        });
    }
    for tracer in support::all_tracers(&scene) {
        let hits = trace(tracer.as_ref(), &lines);
        let mut odd = 0;
        for (i, line) in lines.iter().enumerate() {
            let row = hits.of_line(i);
            let inner = row
                .iter()
                .filter(|h| scene.triangle_patch[h.triangle as usize] as usize >= n)
                .count();
            if inner % 2 != 0 || (row.len() - inner) % 2 != 0 {
                odd += 1;
                continue;
            }
            let mut escapes = 0;
            segments(&scene, line, row, |s| {
                escapes += matches!(s, Segment::Escape { .. }) as usize
            });
            assert_eq!(escapes, 0, "{}: {line:?}: {row:?}", tracer.name());
        }
        // Some of these lines are chords 4e-5 long, nearly tangent to the inner sphere at a vertex: they
        // graze its triangles. Embree lost 3 of their crossings while its candidates came from triangles
        // inflated within their plane; from grown boxes, as the pure-Rust tracer's, it loses none.
        assert!(
            odd == 0,
            "{}: {odd} of {} lines with odd parity",
            tracer.name(),
            lines.len()
        );
    }
}

// ------------------------------------------------------------------------------------------------
// Very small and very large scenes.

/// The room with a box (support::room_with_box_obj) written at scales 1e-6, 1e6, 2^-20 and 2^20.
///
/// Expected: every scene is first mapped to its unit bounding sphere, so the traced f32 geometry, the
/// lines, the hits and every integer count are identical at every scale; the f64 patch planes and areas
/// are computed from coordinates x s and differ from the unit scene's in the last bits (s x p rounds),
/// so the measures agree to ~1e-15 relative (checked at 1e-12). For a power-of-two scale every
/// operation of the normalisation is exact, and the results are bit-identical.
#[test]
fn tiny_and_huge_scenes_give_the_same_results() {
    let dir = tempfile::tempdir().unwrap();
    let load = |s: f64| {
        let path = dir.path().join(format!("room_{s:e}.obj"));
        std::fs::write(&path, room_with_box_obj(s)).unwrap();
        scenes::load(path.to_str().unwrap()).unwrap()
    };
    let measures = |a: &Analysis| {
        [
            a.estimate(Measure::PositionalEntropy),
            a.estimate(Measure::Entropy),
            a.estimate(Measure::EntropyCorrected),
            a.estimate(Measure::MutualInformation),
            a.estimate(Measure::ContinuousMutualInformation),
            a.estimate(Measure::MsePerLine),
        ]
        .map(|e| e.unwrap().value)
    };
    let base_scene = load(1.0);
    let base = run(&base_scene, 50_000, 4);
    let base_counts = |a: &Analysis| (a.hits, a.pairs, a.unpaired, a.escapes, count_entries(a));
    for s in [1e-6, 1e6, 2f64.powi(-20), 2f64.powi(20)] {
        let scene = load(s);
        assert_eq!(
            scene.positions, base_scene.positions,
            "scale {s:e}: f32 geometry"
        );
        let a = run(&scene, 50_000, 4);
        assert_eq!(base_counts(&a), base_counts(&base), "scale {s:e}: counts");
        let exact = s.log2().fract() == 0.0;
        for (x, y) in measures(&a).iter().zip(measures(&base)) {
            if exact {
                assert_eq!(x.to_bits(), y.to_bits(), "scale {s:e}: {x} vs {y}");
            } else {
                assert!((x - y).abs() <= 1e-12 * y.abs(), "scale {s:e}: {x} vs {y}");
            }
        }
        let ratio = scene.total_area_scene_units() / (base_scene.total_area_scene_units() * s * s);
        assert!((ratio - 1.0).abs() < 1e-12, "areas in scene units: {ratio}");
    }
}

// ------------------------------------------------------------------------------------------------
// Very fine meshes with few lines.

/// `@cube:130` (101 400 patches, 202 800 triangles) with 10^4 lines, through the binary.
///
/// Expected: each patch (area 4 / (3 N^2) in tracing space) is crossed by a line with probability
/// p = A / (2 pi) (Crofton), and each crossing leaves it once towards the inside, so it stays unsampled
/// with probability (1 - p)^lines: about 88% of the patches here. They are reported
/// (`unsampled_patches`, and their area fraction, which for equal patches is their share of the count)
/// with a warning, never silently dropped; every measure is still a finite number (the counts are
/// sparse: memory follows the distinct pairs, not n_p^2; its speed is a benchmark matter, not a test's).
#[cfg(feature = "cli")]
#[test]
fn a_very_fine_mesh_with_few_lines_reports_its_unsampled_patches() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_scx"))
        .args([
            "analyze",
            "@cube:130",
            "--lines",
            "1e4",
            "--tracer",
            "rust",
            "--format",
            "json",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let n_p = 6 * 130 * 130;
    assert_eq!(doc["patches"], n_p);
    let p = 4.0 / (3.0 * 130.0f64.powi(2)) / (2.0 * PI);
    let q = (1.0 - p).powi(10_000);
    let expected = n_p as f64 * q;
    let sd = (n_p as f64 * q * (1.0 - q)).sqrt();
    let got = doc["unsampled_patches"].as_f64().unwrap();
    assert!(
        (got - expected).abs() < 5.0 * sd,
        "{got} unsampled, expected {expected} +- {sd}"
    );
    let fraction = doc["unsampled_area_fraction"].as_f64().unwrap();
    assert!((fraction - got / n_p as f64).abs() < 1e-9, "{fraction}");
    let warnings = doc["warnings"].as_array().unwrap();
    let unsampled = warnings
        .iter()
        .find(|w| w["code"] == "unsampled-patches")
        .unwrap_or_else(|| panic!("{warnings:?}"));
    assert!(
        unsampled["message"]
            .as_str()
            .unwrap()
            .contains(&format!("{got} patch(es)")),
        "{unsampled}"
    );
    assert_eq!(unsampled["from"], "run");
    assert_eq!(unsampled["numbers"]["patches"].as_f64(), Some(got));
    assert_eq!(
        unsampled["numbers"]["area_fraction"].as_f64(),
        Some(fraction)
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("were never left by a line"), "{stderr}");
    for (k, m) in doc["visibility"].as_object().unwrap() {
        if !m.is_null() {
            assert!(m["value"].as_f64().unwrap().is_finite(), "{k}: {m}");
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Zero-area triangles.

/// An OBJ of the unit-cube room whose floor quad is given with a repeated corner (its fan has a
/// zero-area triangle), plus a face whose three corners are collinear.
///
/// Expected: the zero-area triangle and the zero-area face are dropped with warnings that say how many
/// and name the face (the face's own triangle counted in the face warning only, not again as a
/// triangle); everything else is exactly the plain room: the same patches and areas, and the
/// same hits and counts for the same lines, so F(floor -> ceiling) is the closed form of unit squares.
#[test]
fn zero_area_triangles_are_dropped_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let corners = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n";
    // Inward quads of the unit cube, corner k = x + 2y + 4z + 1.
    let faces = "f 1 3 7 5\nf 2 6 8 4\nf 1 5 6 2\nf 3 4 8 7\nf 1 2 2 4 3\nf 5 7 8 6\n";
    let plain = dir.path().join("plain.obj");
    std::fs::write(
        &plain,
        format!("{corners}{}", faces.replace("f 1 2 2 4 3", "f 1 2 4 3")),
    )
    .unwrap();
    let broken = dir.path().join("broken.obj");
    std::fs::write(&broken, format!("{corners}v 0.5 0.5 0.5\n{faces}f 1 9 8\n")).unwrap();
    let a = scenes::load(plain.to_str().unwrap()).unwrap();
    let b = scenes::load(broken.to_str().unwrap()).unwrap();
    assert!(a.warnings.is_empty(), "{:?}", a.warnings);
    let joined = b
        .warnings
        .iter()
        .map(|w| w.message.as_str())
        .collect::<Vec<_>>()
        .join("\n");
    let codes: Vec<&str> = b.warnings.iter().map(|w| w.kind.code()).collect();
    assert_eq!(codes, ["zero-area-triangles", "zero-area-faces"]);
    assert_eq!(b.warnings[0].numbers, [("triangles", 1.0)]);
    assert!(
        joined.contains("dropped 1 zero-area triangle(s)"),
        "{joined}"
    );
    assert!(
        joined.contains("dropped 1 zero-area face(s)") && joined.contains("face 7"),
        "{joined}"
    );
    assert_eq!(a.patch_count(), 6);
    assert_eq!(b.patch_count(), 6);
    for (p, q) in a.patches.iter().zip(&b.patches) {
        assert!((p.area - q.area).abs() < 1e-15);
    }
    let (ra, rb) = (run(&a, 50_000, 2), run(&b, 50_000, 2));
    assert_eq!(count_entries(&ra), count_entries(&rb));
    let exact = ff_parallel_rectangles(1.0, 1.0, 1.0);
    let (up, total) = block_counts(&rb, 6, &|i| i == 4, &|j| j == 5);
    assert!((up / total - exact).abs() < 4.5 * (exact * (1.0 - exact) / total).sqrt());
}

// ------------------------------------------------------------------------------------------------
// Open scenes and `--enclose`.

/// The unit cube without its top face, facing inwards (an open box), as OBJ text.
const OPEN_BOX: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n\
                        f 1 3 7 5\nf 2 6 8 4\nf 1 5 6 2\nf 3 4 8 7\nf 1 2 4 3\n";

/// The sampling report of an enclosed scene is that of the scene's own rows: the same segments per row
/// and coverage as the same lines without `--enclose` (an escape is a pair with the environment, one
/// outcome either way), never the environment row's millions of segments standing for the scene's.
#[test]
fn enclosing_leaves_the_sampling_of_the_scenes_rows_alone() {
    let scene = scenes::load("@cornell-open").unwrap();
    let sampling = |enclose: bool| {
        let cfg = RunSpec {
            enclose,
            ..RunSpec::new(200_000, 5)
        };
        let a = analyze(
            &scene,
            tracer(&scene).as_ref(),
            &cfg,
            &RunControl::default(),
        )
        .unwrap();
        let report = a.sampling.expect("pairs were counted");
        (
            report.sampling,
            (report.lines_for_coverage, report.from_half),
        )
    };
    let ((plain, plain_lines), (enclosed, enclosed_lines)) = (sampling(false), sampling(true));
    assert_eq!(enclosed.rows, scene.patch_count());
    assert!(
        (enclosed.segments_per_row - plain.segments_per_row).abs() < 1e-9 * plain.segments_per_row,
        "{} against {}",
        enclosed.segments_per_row,
        plain.segments_per_row
    );
    assert!((enclosed.coverage - plain.coverage).abs() < 1e-12);
    assert_eq!(enclosed_lines, plain_lines);
}

/// The environment patch closes an open scene consistently.
///
/// Expected, a cube object in open space (outward normals, side 1, bounding radius R = sqrt(3)/2): every
/// segment from the bounding sphere meets a front side or the sphere, so the environment's counted area
/// is the whole sphere, 4 pi R^2 (within its error); the convex cube sees only the environment
/// (F(face -> env) = 1) and the environment sees the cube with F = A_cube / (4 pi R^2) (reciprocity);
/// every row of the enclosed F sums to 1; H_p is that of the areas with the environment's.
///
/// Expected, the open box (unit cube without its top, inward): the floor sees out through the opening
/// with F = the closed form of parallel unit squares; the sphere's segments that meet the outside (back)
/// of the five walls join nothing, so the environment's area is 4 pi R^2 - 5; rows sum to 1.
/// A closed scene is left alone.
#[test]
fn enclose_closes_open_scenes_consistently() {
    let lines = 200_000;
    let cfg = RunSpec {
        enclose: true,
        ..RunSpec::new(lines, 19)
    };
    let r2 = 0.75;
    let sphere = 4.0 * PI * r2;

    let mut b = SceneBuilder::new("cube object");
    let m = b.material(wall());
    add_box(&mut b, [0.0; 3], [1.0; 3], false, m, "cube");
    let cube = b.build().unwrap();
    let a = analyze(&cube, tracer(&cube).as_ref(), &cfg, &RunControl::default()).unwrap();
    assert_all_finite(&a, "cube object");
    let env = a.environment_area.expect("enclosed");
    assert!(
        (env.value - sphere).abs() < 4.5 * env.stderr.unwrap() + 1e-9,
        "{env:?} vs {sphere}"
    );
    let (t, areas) = a.tally.enclosed(&cube);
    assert_eq!(areas.len(), 7);
    let n = 7;
    let counts = t.counts.as_ref().unwrap();
    let rows = row_totals(n, counts, &t.escapes_by_patch.dense());
    let mut f = vec![vec![0.0; n]; n];
    scene_complexity::internals::measure::channel::for_each_form_factor(
        counts,
        &rows,
        |i, j, v| f[i][j] = v,
    );
    for (i, row) in f.iter().enumerate() {
        assert!((row.iter().sum::<f64>() - 1.0).abs() < 1e-12, "row {i}");
    }
    for row in &f[..6] {
        assert_eq!(row[6], 1.0, "a convex object sees only the environment");
    }
    let to_cube: f64 = f[6][..6].iter().sum();
    let exact = 6.0 / sphere;
    let sigma = (exact * (1.0 - exact) / rows[6]).sqrt();
    assert!(
        (to_cube - exact).abs() < 4.5 * sigma,
        "F(env -> cube) = {to_cube}, A_cube / 4 pi R^2 = {exact}"
    );
    let hp = a.estimate(Measure::PositionalEntropy).unwrap();
    let total = 6.0 + sphere;
    let exact_hp =
        -(6.0 * (1.0 / total) * (1.0 / total).log2() + (sphere / total) * (sphere / total).log2());
    assert!(
        (hp.value - exact_hp).abs() < 4.5 * hp.stderr.unwrap() + 1e-9,
        "{hp:?} vs {exact_hp}"
    );

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("open_box.obj");
    std::fs::write(&path, OPEN_BOX).unwrap();
    let open = scenes::load(path.to_str().unwrap()).unwrap();
    let a = analyze(&open, tracer(&open).as_ref(), &cfg, &RunControl::default()).unwrap();
    assert_all_finite(&a, "open box");
    let env = a.environment_area.expect("enclosed");
    let expected = sphere - 5.0;
    assert!(
        (env.value - expected).abs() < 4.5 * env.stderr.unwrap(),
        "{env:?} vs {expected}"
    );
    let (t, _) = a.tally.enclosed(&open);
    let counts = t.counts.as_ref().unwrap();
    let rows = row_totals(6, counts, &t.escapes_by_patch.dense());
    let mut f = vec![vec![0.0; 6]; 6];
    scene_complexity::internals::measure::channel::for_each_form_factor(
        counts,
        &rows,
        |i, j, v| f[i][j] = v,
    );
    for (i, row) in f.iter().enumerate() {
        assert!((row.iter().sum::<f64>() - 1.0).abs() < 1e-12, "row {i}");
    }
    let exact = ff_parallel_rectangles(1.0, 1.0, 1.0);
    let sigma = (exact * (1.0 - exact) / rows[4]).sqrt();
    assert!(
        (f[4][5] - exact).abs() < 4.5 * sigma,
        "F(floor -> env) = {}, closed form {exact}",
        f[4][5]
    );

    let closed = scenes::load("@cube:2").unwrap();
    let a = analyze(
        &closed,
        tracer(&closed).as_ref(),
        &cfg,
        &RunControl::default(),
    )
    .unwrap();
    assert!(
        a.environment_area.is_none(),
        "nothing escapes a closed scene"
    );
}

/// The open box through the binary: the report gives the fraction of escaping segments and warns.
///
/// Expected: a line through the opening (area 1) escapes once; the inside front area is 5 and a pair has
/// two front ends, an escape one; so escapes / (pairs + escapes) = 1 / (1 + (5 - 1) / 2) = 1/3 (Crofton).
/// With `--enclose` the warning says the escapes became pairs with the environment, and the JSON gives
/// its area.
#[cfg(feature = "cli")]
#[test]
fn open_scenes_report_their_escapes_and_can_be_enclosed() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("open_box.obj");
    std::fs::write(&path, OPEN_BOX).unwrap();
    let scx = |extra: &[&str]| {
        let mut args = vec![
            "analyze",
            path.to_str().unwrap(),
            "--lines",
            "1e5",
            "--format",
            "json",
        ];
        args.extend_from_slice(extra);
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_scx"))
            .args(&args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (doc, String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (doc, stderr) = scx(&[]);
    let fraction = doc["escape_fraction"].as_f64().unwrap();
    let segments = doc["pairs"].as_f64().unwrap() + doc["escapes"].as_f64().unwrap();
    let sigma = (2.0 / 9.0 / segments).sqrt();
    assert!((fraction - 1.0 / 3.0).abs() < 4.5 * sigma, "{fraction}");
    assert!(
        stderr.contains("the scene is open") && stderr.contains("--enclose closes"),
        "{stderr}"
    );
    assert!(doc["environment_area"].is_null());
    let (doc, stderr) = scx(&["--enclose"]);
    assert!(
        stderr.contains("pairs with the environment patch"),
        "{stderr}"
    );
    let env = doc["environment_area"]["value"].as_f64().unwrap();
    assert!((env - (3.0 * PI - 5.0)).abs() < 0.1, "{env}");
}

/// Lines across the corner of an enclosure, closer to its edge than an f32 `t` resolves: inside the
/// `@octahedron`, near the edge where its faces over (x, y, +z) and (x, y, -z) meet, at distances from
/// 1e-5 down to 1e-7 (chords of 3e-7 and less, within the window where the hits' f32 order is not
/// trusted), straight up and tilted.
///
/// Expected (by hand, in f64, from the traced f32 line): the line leaves the lower face and arrives at
/// the upper one, one pair whose distance is that between the two planes along the line,
/// `|t(x + y + z = 1) - t(x + y - z = 1)|`. Such a chord has the signature of a line that only touches
/// an edge (leaving one front side and arriving at another within a few ulps); it was dropped as one,
/// which lost the largest terms of eq. 27 and read the octahedron's I_s^c 4e-5 low.
#[test]
fn chords_across_the_corner_of_an_enclosure_are_paired() {
    let scene = scenes::load("@octahedron").unwrap();
    let (lower, upper) = (1u32, 0u32);
    for tracer in support::all_tracers(&scene) {
        for delta in [1e-5f64, 1e-6, 3e-7, 1e-7] {
            for tilt in [0.0f64, 0.3] {
                let s = std::f64::consts::FRAC_1_SQRT_2;
                let d = [tilt * s, -tilt * s, 1.0];
                let l = norm(d);
                let d = d.map(|x| x / l);
                let (x, y) = (0.5 - delta * s, 0.5 - delta * s);
                let origin = [x - 2.0 * d[0], y - 2.0 * d[1], -2.0 * d[2]].map(|v| v as f32);
                let line = Line {
                    origin,
                    dir: d.map(|v| v as f32),
                    t_max: 4.0,
                };
                let hits = trace(tracer.as_ref(), &[line]);
                let row = hits.of_line(0);
                let mut seen = Vec::new();
                segments(&scene, &line, row, |seg| seen.push(seg));
                let what = format!(
                    "{}: delta {delta:e}, tilt {tilt}: {row:?} -> {seen:?}",
                    tracer.name()
                );
                let o = origin.map(f64::from);
                let d = {
                    let d = line.dir.map(f64::from);
                    let l = norm(d);
                    d.map(|x| x / l)
                };
                let t_plane = |sz: f64| (1.0 - o[0] - o[1] - sz * o[2]) / (d[0] + d[1] + sz * d[2]);
                let exact = (t_plane(1.0) - t_plane(-1.0)).abs();
                assert!(exact > 0.0 && exact < 3e-5, "{what}: chord {exact}");
                match seen.as_slice() {
                    [Segment::Pair {
                        from, to, distance, ..
                    }] => {
                        assert_eq!((*from, *to), (lower, upper), "{what}");
                        assert!(
                            (distance / exact - 1.0).abs() < 1e-6,
                            "{what}: d = {distance}, by hand {exact}"
                        );
                    }
                    _ => panic!("{what}: expected one pair"),
                }
            }
        }
    }
}

/// A precision target on I_s^c below what f32 tracing resolves in a room (lines within ~1e-7 of its
/// edges read as misses; docs/scenes.md measures the bias, 5.5e-5 bits on `@cube:1`) is not chased
/// for ever: the run stops at that floor (`stop_reason` `f32_floor`, long before its time budget), and
/// its I_s^c says why and is not `ok`; the floor it states is within a factor 2 of the measured bias.
#[test]
fn a_target_below_the_f32_floor_stops_there() {
    let out = support::scx(&[
        "analyze",
        "@cube:1",
        "--measures",
        "continuous",
        "--target-stderr",
        "1e-5",
        "--target-measure",
        "continuous_mutual_information",
        "--seconds",
        "600",
        "--format",
        "json",
    ]);
    let doc = support::json_of(&out);
    assert_eq!(doc["stop_reason"], "f32_floor", "{doc}");
    let isc = &doc["visibility"]["continuous_mutual_information"];
    assert_eq!(isc["reliability"]["verdict"], "undersampled", "{isc}");
    let flag = isc["reliability"]["flags"][0].as_str().unwrap();
    assert!(flag.contains("f32 tracing"), "{flag}");
    let floor: f64 = flag
        .split("up to ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap();
    assert!((2.75e-5..1.1e-4).contains(&floor), "{floor}");
    assert!(doc["seconds"].as_f64().unwrap() < 120.0);
}
