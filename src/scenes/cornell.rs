//! `@cornell`: the Cornell box of the Cornell University Program of Computer Graphics, with its published
//! geometry (millimetres) and single-channel materials (paper fig. 10, Tables 4 and 9).
//!
//! **Geometry.** The published vertex coordinates, unchanged: the room is 556 (x) by 548.8 (y, up) by 559.2
//! (z, depth) with a slightly skewed floor (552.8 and 549.6 wide at its front and back edges); the light is
//! the 130 x 105 rectangle x in [213, 343], z in [227, 332] in the ceiling plane y = 548.8; the short block
//! is 165 high and the tall one 330, with the published corner coordinates. Three things the published
//! quads leave to the modeller are done so that every line segment inside the room joins two visible
//! patches and neighbouring patches share their vertices (no T-junctions, even with `:N`):
//!
//! * the light is cut *out of* the ceiling (the published ceiling quad covers it): the ceiling is the four
//!   trapezoids between the ceiling's edges and the light's, so the light is coplanar with the ceiling
//!   and shares its edges;
//! * the floor is cut around the blocks' footprints (nothing sees the floor under a block, and a patch
//!   area that no line can reach would bias the area distribution of the channel): 5 convex quads and
//!   4 triangles, listed in [`FLOOR_PIECES`];
//! * the published left (red) wall is not planar (its top edge is at x = 556, its bottom edge runs from
//!   x = 552.8 to 549.6: a corner is 3.2 mm off the plane of the other three), so it is two triangles.
//!
//! `@cornell` is **closed** by a white front wall in the plane z = 0 (the published box is open towards
//! the camera): the paper's measures are those of an enclosure, whose form-factor rows sum to 1, like
//! every other built-in. `@cornell-open` is the published open box; its front side lets lines escape,
//! and `scx analyze` reports the escaping fraction.
//!
//! **Materials** (one channel each, paper eq. (2)): the published reflectances are spectra sampled every
//! 4 nm from 400 to 700 nm; a patch's reflectance is their plain mean over those 76 samples (the
//! reflectance seen under an equal-energy white light): white 0.7227, red 0.2429, green 0.1983
//! ([`WHITE`], [`RED`], [`GREEN`]). The light's emission is the mean of its published emission spectrum
//! (linear between the samples 0, 8, 15.6, 18.4 at 400, 500, 600, 700 nm): 10.933. Every radiosity
//! measure is unchanged when all emissions are scaled by one factor (B scales with E, and eqs. (30)-(32)
//! are normalised), so only the ratios matter. The published data give no reflectance for the light: we
//! give it 0.78, a white diffuser.
//!
//! **Patches.** One patch per face: 29 in the closed box (floor 9, ceiling 4, light 1, back, front and
//! right wall 1 each, left wall 2, blocks 5 each), 28 in the open one. `@cornell:N` cuts every quad into
//! an N x N grid and every triangle into N^2 triangles, so it has N^2 times as many patches.

use crate::geom::{DVec3, Point};
use crate::scene::{Material, Scene, SceneBuilder, SceneError};

/// Mean of the published spectral reflectance of the white paint (76 samples, 400-700 nm).
pub const WHITE: f64 = 0.722_671_052_631_578_8;
/// Mean of the published spectral reflectance of the red paint (left wall).
pub const RED: f64 = 0.242_947_368_421_052_66;
/// Mean of the published spectral reflectance of the green paint (right wall).
pub const GREEN: f64 = 0.198_25;
/// Mean of the published emission spectrum of the light (piecewise linear, 400-700 nm).
pub const LIGHT_EMISSION: f64 = (4.0 + 11.8 + 17.0) / 3.0;

/// The white paint as RGB: the means of the published spectrum over the longest, middle and shortest
/// third of its 76 samples (the samples at 500 and 600 nm shared 1/3 : 2/3 between neighbouring
/// thirds), so that the three means average to [`WHITE`] exactly; the blue value is moved by one ulp
/// to make that hold in f64 too. Only `scx export` and `refine` use the triples: every measure uses the
/// single values.
pub const WHITE_RGB: [f64; 3] = [0.7337631578947369, 0.7357631578947369, 0.698486842105263];
/// The red paint as RGB (see [`WHITE_RGB`]; blue moved by one ulp), averaging to [`RED`].
pub const RED_RGB: [f64; 3] = [0.5836842105263158, 0.08889473684210526, 0.05626315789473685];
/// The green paint as RGB (see [`WHITE_RGB`]), averaging to [`GREEN`].
pub const GREEN_RGB: [f64; 3] = [0.13221052631578947, 0.3466842105263158, 0.11585526315789474];
/// The light's emission as RGB: the mean of its published spectrum over 600-700, 500-600 and 400-500 nm
/// (the three terms of [`LIGHT_EMISSION`]).
pub const LIGHT_EMISSION_RGB: [f64; 3] = [17.0, 11.8, 4.0];
/// Reflectance we give the light (the published data give none).
pub const LIGHT_REFLECTANCE: f64 = 0.78;

/// Ceiling height.
const H: f64 = 548.8;

/// Floor vertices in the floor plane (x, z): the floor's corners, then the short block's footprint, then
/// the tall block's.
const FLOOR_POINTS: [[f64; 2]; 12] = [
    [552.8, 0.0],
    [0.0, 0.0],
    [0.0, 559.2],
    [549.6, 559.2],
    [130.0, 65.0],
    [82.0, 225.0],
    [240.0, 272.0],
    [290.0, 114.0],
    [423.0, 247.0],
    [265.0, 296.0],
    [314.0, 456.0],
    [472.0, 406.0],
];

/// The floor minus the blocks' footprints as convex pieces (indices into the floor's points), counter-
/// clockwise seen from above: a triangulation of the holed floor with pairs of triangles merged into
/// convex quads where they form one.
pub const FLOOR_PIECES: [&[usize]; 9] = [
    &[0, 1, 4, 7],
    &[0, 8, 11, 3],
    &[0, 7, 9, 8],
    &[2, 3, 11, 10],
    &[2, 10, 9, 5],
    &[1, 2, 5],
    &[1, 5, 4],
    &[5, 9, 6],
    &[6, 9, 7],
];

/// The short block's top (y = 165) corners in (x, z), as published.
const SHORT_BLOCK: [[f64; 2]; 4] = [[130.0, 65.0], [82.0, 225.0], [240.0, 272.0], [290.0, 114.0]];
/// The tall block's top (y = 330) corners in (x, z), as published.
const TALL_BLOCK: [[f64; 2]; 4] = [
    [423.0, 247.0],
    [265.0, 296.0],
    [314.0, 456.0],
    [472.0, 406.0],
];

/// Builds `@cornell` (`closed`) or `@cornell-open`, each face cut `n` times along each edge.
pub fn build(spec: &str, n: usize, closed: bool) -> Result<Scene, SceneError> {
    let mut b = SceneBuilder::new(spec);
    let m = Materials::add(&mut b);
    let centre = DVec3::new(278.0, H / 2.0, 279.6);
    let mut faces: Vec<(Vec<Point>, u32, &str)> = Vec::new();

    for piece in FLOOR_PIECES {
        let pts = piece
            .iter()
            .map(|&k| DVec3::new(FLOOR_POINTS[k][0], 0.0, FLOOR_POINTS[k][1]));
        faces.push((pts.collect(), m.white, "floor"));
    }
    let ceiling = |x: f64, z: f64| DVec3::new(x, H, z);
    let room = [(0.0, 0.0), (556.0, 0.0), (556.0, 559.2), (0.0, 559.2)];
    let light = [
        (213.0, 227.0),
        (343.0, 227.0),
        (343.0, 332.0),
        (213.0, 332.0),
    ];
    for k in 0..4 {
        let (a, b2) = (room[k], room[(k + 1) % 4]);
        let (c, d) = (light[(k + 1) % 4], light[k]);
        let quad = vec![
            ceiling(a.0, a.1),
            ceiling(b2.0, b2.1),
            ceiling(c.0, c.1),
            ceiling(d.0, d.1),
        ];
        faces.push((quad, m.white, "ceiling"));
    }
    faces.push((
        light.iter().map(|&(x, z)| ceiling(x, z)).collect(),
        m.light,
        "light",
    ));
    let floor_back_left = DVec3::new(549.6, 0.0, 559.2);
    let floor_front_left = DVec3::new(552.8, 0.0, 0.0);
    faces.push((
        vec![
            floor_back_left,
            DVec3::new(0.0, 0.0, 559.2),
            DVec3::new(0.0, H, 559.2),
            DVec3::new(556.0, H, 559.2),
        ],
        m.white,
        "back wall",
    ));
    faces.push((
        vec![
            DVec3::new(0.0, 0.0, 559.2),
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, H, 0.0),
            DVec3::new(0.0, H, 559.2),
        ],
        m.green,
        "right wall",
    ));
    // The published left wall is not planar: two triangles sharing the diagonal from its front bottom
    // corner to its back top corner.
    let (top_back, top_front) = (DVec3::new(556.0, H, 559.2), DVec3::new(556.0, H, 0.0));
    faces.push((
        vec![floor_front_left, floor_back_left, top_back],
        m.red,
        "left wall",
    ));
    faces.push((
        vec![floor_front_left, top_back, top_front],
        m.red,
        "left wall",
    ));
    if closed {
        faces.push((
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                floor_front_left,
                top_front,
                DVec3::new(0.0, H, 0.0),
            ],
            m.white,
            "front wall",
        ));
    }
    // Room faces look into the room; block faces look out of their block.
    for (pts, mat, name) in faces {
        add_subdivided(&mut b, &orient(pts, centre, true), n, mat, name);
    }
    for (top, height, name) in [
        (SHORT_BLOCK, 165.0, "short block"),
        (TALL_BLOCK, 330.0, "tall block"),
    ] {
        for (pts, inside) in block_faces(&top, height) {
            add_subdivided(&mut b, &orient(pts, inside, false), n, m.white, name);
        }
    }
    b.build()
}

/// The material indices of the box.
struct Materials {
    white: u32,
    red: u32,
    green: u32,
    light: u32,
}

impl Materials {
    fn add(b: &mut SceneBuilder) -> Self {
        let mut diffuse = |name: &str, reflectance: f64, rgb: [f64; 3]| {
            b.material(Material {
                reflectance_rgb: rgb,
                ..Material::grey(name, reflectance, 0.0)
            })
        };
        let (white, red, green) = (
            diffuse("white", WHITE, WHITE_RGB),
            diffuse("red", RED, RED_RGB),
            diffuse("green", GREEN, GREEN_RGB),
        );
        let light = b.material(Material {
            emission_rgb: LIGHT_EMISSION_RGB,
            ..Material::grey("light", LIGHT_REFLECTANCE, LIGHT_EMISSION)
        });
        Materials {
            white,
            red,
            green,
            light,
        }
    }
}

/// A block's top and four sides (no bottom: it stands on the floor), each with a point inside the block.
fn block_faces(top: &[[f64; 2]; 4], height: f64) -> Vec<(Vec<Point>, Point)> {
    let inside = DVec3::new(
        top.iter().map(|p| p[0]).sum::<f64>() / 4.0,
        height / 2.0,
        top.iter().map(|p| p[1]).sum::<f64>() / 4.0,
    );
    let mut faces = vec![(
        top.iter()
            .map(|p| DVec3::new(p[0], height, p[1]))
            .collect::<Vec<_>>(),
        inside,
    )];
    for k in 0..4 {
        let (a, c) = (top[k], top[(k + 1) % 4]);
        faces.push((
            vec![
                DVec3::new(a[0], 0.0, a[1]),
                DVec3::new(c[0], 0.0, c[1]),
                DVec3::new(c[0], height, c[1]),
                DVec3::new(a[0], height, a[1]),
            ],
            inside,
        ));
    }
    faces
}

/// Orders a planar convex face so that its normal points towards `reference` (`towards`) or away from it.
fn orient(mut pts: Vec<Point>, reference: Point, towards: bool) -> Vec<Point> {
    let normal = (pts[1] - pts[0]).cross(pts[2] - pts[0]);
    let facing = normal.dot(reference - pts[0]) > 0.0;
    if facing != towards {
        pts.reverse();
    }
    pts
}

/// The point `k / n` of the way along the edge between `a` and `b`, computed the same way whichever
/// end the edge is walked from, so that faces sharing the edge get bit-identical vertices.
fn edge_point(a: Point, b: Point, k: usize, n: usize) -> Point {
    let (p, q, k) = if a.to_array() <= b.to_array() {
        (a, b, k)
    } else {
        (b, a, n - k)
    };
    if k == 0 {
        return p;
    }
    if k == n {
        return q;
    }
    let t = k as f64 / n as f64;
    p + t * (q - p)
}

/// Adds a triangle or a quad cut into `n` x `n` cells (a quad: a bilinear grid, planar and convex for a
/// planar convex quad; a triangle: `n^2` triangles on a barycentric grid).
fn add_subdivided(b: &mut SceneBuilder, pts: &[Point], n: usize, m: u32, name: &str) {
    match pts.len() {
        3 => add_triangle_grid(b, [pts[0], pts[1], pts[2]], n, m, name),
        4 => add_quad_grid(b, [pts[0], pts[1], pts[2], pts[3]], n, m, name),
        k => unreachable!("the Cornell box has only triangles and quads, not {k}-gons"),
    }
}

fn add_quad_grid(b: &mut SceneBuilder, q: [Point; 4], n: usize, m: u32, name: &str) {
    // Grid point (i, j): i steps along q0 -> q1, j along q0 -> q3.
    let point = |i: usize, j: usize| -> Point {
        match (i, j) {
            (_, 0) => edge_point(q[0], q[1], i, n),
            (_, j) if j == n => edge_point(q[3], q[2], i, n),
            (0, _) => edge_point(q[0], q[3], j, n),
            (i, _) if i == n => edge_point(q[1], q[2], j, n),
            _ => {
                let (left, right) = (edge_point(q[0], q[3], j, n), edge_point(q[1], q[2], j, n));
                let t = i as f64 / n as f64;
                left + t * (right - left)
            }
        }
    };
    for i in 0..n {
        for j in 0..n {
            let cell = [
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            ];
            let idx = cell.map(|p| b.vertex(p));
            b.polygon(&idx, m, format!("{name} cell ({i}, {j})"));
        }
    }
}

fn add_triangle_grid(b: &mut SceneBuilder, t: [Point; 3], n: usize, m: u32, name: &str) {
    // Grid point (i, j) = t0 + i/n (t1 - t0) + j/n (t2 - t0), for i + j <= n.
    let point = |i: usize, j: usize| -> Point {
        if j == 0 {
            edge_point(t[0], t[1], i, n)
        } else if i == 0 {
            edge_point(t[0], t[2], j, n)
        } else if i + j == n {
            edge_point(t[1], t[2], j, n)
        } else {
            let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
            t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0])
        }
    };
    for i in 0..n {
        for j in 0..n - i {
            let (p, q, r) = (point(i, j), point(i + 1, j), point(i, j + 1));
            let idx = [p, q, r].map(|x| b.vertex(x));
            b.polygon(&idx, m, format!("{name} cell ({i}, {j})"));
            if i + j + 1 < n {
                let s = b.vertex(point(i + 1, j + 1));
                b.polygon(&[idx[1], s, idx[2]], m, format!("{name} cell ({i}, {j})'"));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// The published spectra (76 samples, 400 to 700 nm every 4 nm), to check the means above.
    const WHITE_SPECTRUM: [f64; 76] = [
        0.343, 0.445, 0.551, 0.624, 0.665, 0.687, 0.708, 0.723, 0.715, 0.710, 0.745, 0.758, 0.739,
        0.767, 0.777, 0.765, 0.751, 0.745, 0.748, 0.729, 0.745, 0.757, 0.753, 0.750, 0.746, 0.747,
        0.735, 0.732, 0.739, 0.734, 0.725, 0.721, 0.733, 0.725, 0.732, 0.743, 0.744, 0.748, 0.728,
        0.716, 0.733, 0.726, 0.713, 0.740, 0.754, 0.764, 0.752, 0.736, 0.734, 0.741, 0.740, 0.732,
        0.745, 0.755, 0.751, 0.744, 0.731, 0.733, 0.744, 0.731, 0.712, 0.708, 0.729, 0.730, 0.727,
        0.707, 0.703, 0.729, 0.750, 0.760, 0.751, 0.739, 0.724, 0.730, 0.740, 0.737,
    ];
    const RED_SPECTRUM: [f64; 76] = [
        0.040, 0.046, 0.048, 0.053, 0.049, 0.050, 0.053, 0.055, 0.057, 0.056, 0.059, 0.057, 0.061,
        0.061, 0.060, 0.062, 0.062, 0.062, 0.061, 0.062, 0.060, 0.059, 0.057, 0.058, 0.058, 0.058,
        0.056, 0.055, 0.056, 0.059, 0.057, 0.055, 0.059, 0.059, 0.058, 0.059, 0.061, 0.061, 0.063,
        0.063, 0.067, 0.068, 0.072, 0.080, 0.090, 0.099, 0.124, 0.154, 0.192, 0.255, 0.287, 0.349,
        0.402, 0.443, 0.487, 0.513, 0.558, 0.584, 0.620, 0.606, 0.609, 0.651, 0.612, 0.610, 0.650,
        0.638, 0.627, 0.620, 0.630, 0.628, 0.642, 0.639, 0.657, 0.639, 0.635, 0.642,
    ];
    const GREEN_SPECTRUM: [f64; 76] = [
        0.092, 0.096, 0.098, 0.097, 0.098, 0.095, 0.095, 0.097, 0.095, 0.094, 0.097, 0.098, 0.096,
        0.101, 0.103, 0.104, 0.107, 0.109, 0.112, 0.115, 0.125, 0.140, 0.160, 0.187, 0.229, 0.285,
        0.343, 0.390, 0.435, 0.464, 0.472, 0.476, 0.481, 0.462, 0.447, 0.441, 0.426, 0.406, 0.373,
        0.347, 0.337, 0.314, 0.285, 0.277, 0.266, 0.250, 0.230, 0.207, 0.186, 0.171, 0.160, 0.148,
        0.141, 0.136, 0.130, 0.126, 0.123, 0.121, 0.122, 0.119, 0.114, 0.115, 0.117, 0.117, 0.118,
        0.120, 0.122, 0.128, 0.132, 0.139, 0.144, 0.146, 0.150, 0.152, 0.157, 0.159,
    ];

    fn mean(s: &[f64]) -> f64 {
        s.iter().sum::<f64>() / s.len() as f64
    }

    #[test]
    fn reflectances_are_the_means_of_the_published_spectra() {
        assert!((mean(&WHITE_SPECTRUM) - WHITE).abs() < 1e-12);
        assert!((mean(&RED_SPECTRUM) - RED).abs() < 1e-12);
        assert!((mean(&GREEN_SPECTRUM) - GREEN).abs() < 1e-12);
        // Trapezoid rule over the emission samples 0, 8, 15.6, 18.4 at 100 nm steps.
        let e = [0.0, 8.0, 15.6, 18.4];
        let integral: f64 = e.windows(2).map(|w| 50.0 * (w[0] + w[1])).sum();
        assert!((integral / 300.0 - LIGHT_EMISSION).abs() < 1e-12);
    }

    #[test]
    fn floor_pieces_tile_the_floor_around_the_blocks() {
        let area2 = |p: &[usize]| -> f64 {
            // Twice the signed area seen from above (+y): positive when counter-clockwise from above.
            (1..p.len() - 1)
                .map(|k| {
                    let (a, b, c) = (
                        FLOOR_POINTS[p[0]],
                        FLOOR_POINTS[p[k]],
                        FLOOR_POINTS[p[k + 1]],
                    );
                    (b[1] - a[1]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[1] - a[1])
                })
                .sum()
        };
        let shoelace = |pts: &[[f64; 2]]| -> f64 {
            let n = pts.len();
            (0..n)
                .map(|k| pts[k][0] * pts[(k + 1) % n][1] - pts[(k + 1) % n][0] * pts[k][1])
                .sum::<f64>()
                .abs()
                / 2.0
        };
        for p in FLOOR_PIECES {
            // Convex and counter-clockwise from above: every corner turns the same way.
            for k in 0..p.len() {
                let tri = [p[k], p[(k + 1) % p.len()], p[(k + 2) % p.len()]];
                assert!(area2(&tri) > 0.0, "piece {p:?} is not convex at corner {k}");
            }
        }
        let pieces: f64 = FLOOR_PIECES.iter().map(|p| area2(p) / 2.0).sum();
        let floor = shoelace(&FLOOR_POINTS[0..4]);
        let holes = shoelace(&SHORT_BLOCK) + shoelace(&TALL_BLOCK);
        assert!(
            (pieces - (floor - holes)).abs() < 1e-9,
            "{pieces} vs {}",
            floor - holes
        );
        // Edges: every inner edge is used once in each direction; the outline and the footprints once.
        let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
        for p in FLOOR_PIECES {
            for k in 0..p.len() {
                *directed.entry((p[k], p[(k + 1) % p.len()])).or_default() += 1;
            }
        }
        let boundary: Vec<(usize, usize)> = [[0, 1, 2, 3], [4, 5, 6, 7], [8, 9, 10, 11]]
            .iter()
            .flat_map(|c| (0..4).map(move |k| (c[k], c[(k + 1) % 4])))
            .collect();
        for (&(a, b), &count) in &directed {
            assert_eq!(count, 1, "edge ({a}, {b}) used twice the same way");
            let on_boundary = boundary.contains(&(a, b)) || boundary.contains(&(b, a));
            assert_eq!(
                directed.contains_key(&(b, a)),
                !on_boundary,
                "edge ({a}, {b})"
            );
        }
        for (a, b) in boundary {
            assert!(directed.contains_key(&(a, b)) || directed.contains_key(&(b, a)));
        }
    }

    /// Every edge of the closed box's triangles is shared by exactly two triangles (a watertight,
    /// conforming mesh), and every room face points into the room, every block face out of its block.
    #[test]
    fn closed_box_is_watertight_and_faces_the_right_way() {
        for n in [1, 3] {
            let s = build("@cornell", n, true).unwrap();
            assert_eq!(s.patch_count(), 29 * n * n);
            let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
            for t in &s.triangles {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    *edges.entry((a.min(b), a.max(b))).or_default() += 1;
                }
            }
            // Block edges along the floor are shared by the floor, the block side and nothing else;
            // vertical block edges by two sides. Everything is used exactly twice.
            assert!(
                edges.values().all(|&c| c == 2),
                "n = {n}: a cracked or T-junction edge"
            );
            assert!(s.warnings.is_empty(), "{:?}", s.warnings);
        }
        let open = build("@cornell-open", 1, false).unwrap();
        assert_eq!(open.patch_count(), 28);
    }

    #[test]
    fn areas_and_materials_are_the_published_ones() {
        let s = build("@cornell", 1, true).unwrap();
        let area_of = |name: &str| -> f64 {
            s.patches
                .iter()
                .filter(|p| s.materials[p.material as usize].name == name)
                .map(|p| p.area)
                .sum::<f64>()
                * s.normalization.scale.powi(2)
        };
        assert!((area_of("light") - 130.0 * 105.0).abs() < 1e-6);
        assert!((area_of("green") - 548.8 * 559.2).abs() < 1e-6);
        let light = s.materials.iter().find(|m| m.name == "light").unwrap();
        assert_eq!(light.emission, LIGHT_EMISSION);
        assert!(s.materials.iter().filter(|m| m.emission > 0.0).count() == 1);
        // The short block: its top (the shoelace area of its footprint) and four sides 165 high.
        let n = SHORT_BLOCK.len();
        let top: f64 = (0..n)
            .map(|k| {
                let (a, b) = (SHORT_BLOCK[k], SHORT_BLOCK[(k + 1) % n]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum::<f64>()
            .abs()
            / 2.0;
        let sides: f64 = (0..n)
            .map(|k| {
                let (a, b) = (SHORT_BLOCK[k], SHORT_BLOCK[(k + 1) % n]);
                165.0 * ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
            })
            .sum();
        let short: f64 = s
            .patches
            .iter()
            .enumerate()
            .filter(|(k, _)| (19..24).contains(k))
            .map(|(_, p)| p.area)
            .sum::<f64>()
            * s.normalization.scale.powi(2);
        assert!(
            (short - (top + sides)).abs() < 1e-6,
            "{short} vs {}",
            top + sides
        );
        for p in &s.patches {
            assert!(p.offset.is_finite());
        }
    }
}
