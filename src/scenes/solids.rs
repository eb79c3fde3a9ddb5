//! The interiors of the unit cube, the regular solids and the icosphere: enclosures seen from inside
//! (normals point inwards), so every line segment inside joins two patches (paper Tables 2 and 4).
//!
//! * `@cube:N`: the interior of the unit cube (area 6), each face cut into N x N square patches.
//! * `@sphere:L`: an icosphere after L subdivisions of the icosahedron (20 * 4^L triangles, each a patch),
//!   vertices on the unit sphere.
//! * `@tetrahedron`, `@octahedron`, `@icosahedron` (`:N` cuts each triangular face into N^2 equal
//!   triangles) and `@dodecahedron` (one pentagon patch per face; `:N` cuts each pentagon into 5 triangles
//!   from its centre, then each into N^2): the interiors of the regular solids, circumradius 1.

use super::parts::grey_wall;
use crate::geom::{centroid, orthonormal_basis, unit_vector, DVec3, Point};
use crate::scene::{Scene, SceneBuilder, SceneError};

/// The six faces of the unit cube as (corner, u axis, v axis), with `u x v` pointing inwards.
const CUBE_FACES: [(DVec3, DVec3, DVec3); 6] = [
    (DVec3::ZERO, DVec3::Y, DVec3::Z), // x = 0, normal +x
    (DVec3::X, DVec3::Z, DVec3::Y),    // x = 1, normal -x
    (DVec3::ZERO, DVec3::Z, DVec3::X), // y = 0, normal +y
    (DVec3::Y, DVec3::X, DVec3::Z),    // y = 1, normal -y
    (DVec3::ZERO, DVec3::X, DVec3::Y), // z = 0, normal +z
    (DVec3::Z, DVec3::Y, DVec3::X),    // z = 1, normal -z
];

/// `@cube:N`: the unit cube enclosure, N x N patches per face, inward normals.
///
/// Patches are numbered face by face in the order x = 0, x = 1, y = 0, y = 1, z = 0, z = 1, and within a face by `(i, j)` with
/// `patch = face * N^2 + i * N + j`, `i` along u and `j` along v.
pub fn cube(spec: &str, n: usize) -> Result<Scene, SceneError> {
    let mut b = SceneBuilder::new(spec);
    let m = grey_wall(&mut b);
    for (face, (o, u, v)) in CUBE_FACES.iter().enumerate() {
        for i in 0..n {
            for j in 0..n {
                let corner = |di: usize, dj: usize| {
                    let s = (i + di) as f64 / n as f64;
                    let t = (j + dj) as f64 / n as f64;
                    *o + s * *u + t * *v
                };
                let quad = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                let idx = quad.map(|p| b.vertex(p));
                b.polygon(&idx, m, format!("cube face {face} patch ({i}, {j})"));
            }
        }
    }
    b.build()
}

/// A convex polyhedron centred at the origin: vertices and faces (vertex lists, any winding).
struct Polyhedron {
    vertices: Vec<Point>,
    faces: Vec<Vec<usize>>,
}

/// The regular solids.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solid {
    /// 4 triangles.
    Tetrahedron,
    /// 8 triangles.
    Octahedron,
    /// 20 triangles.
    Icosahedron,
    /// 12 pentagons.
    Dodecahedron,
}

/// The interior of a regular solid of circumradius 1: each face one patch (`n` = 1) or cut into
/// triangles (see the module documentation).
pub fn solid(spec: &str, which: Solid, n: usize) -> Result<Scene, SceneError> {
    let poly = match which {
        Solid::Tetrahedron => tetrahedron(),
        Solid::Octahedron => octahedron(),
        Solid::Icosahedron => icosahedron(),
        Solid::Dodecahedron => dodecahedron(),
    };
    let mut b = SceneBuilder::new(spec);
    let m = grey_wall(&mut b);
    for (f, face) in poly.faces.iter().enumerate() {
        let pts = facing_inwards(face.iter().map(|&v| poly.vertices[v]).collect());
        if n == 1 {
            let idx: Vec<u32> = pts.iter().map(|&p| b.vertex(p)).collect();
            b.polygon(&idx, m, format!("face {f}"));
        } else if pts.len() == 3 {
            split_triangle(&mut b, [pts[0], pts[1], pts[2]], n, m, &format!("face {f}"));
        } else {
            let c = centroid(&pts);
            for k in 0..pts.len() {
                let tri = [c, pts[k], pts[(k + 1) % pts.len()]];
                split_triangle(&mut b, tri, n, m, &format!("face {f} sector {k}"));
            }
        }
    }
    b.build()
}

/// Reorders a convex face so that it is counter-clockwise seen from the origin (its normal points in).
fn facing_inwards(mut pts: Vec<Point>) -> Vec<Point> {
    let c = centroid(&pts);
    let n = (pts[1] - pts[0]).cross(pts[2] - pts[0]);
    if n.dot(c) > 0.0 {
        pts.reverse();
    }
    pts
}

/// Cuts a triangle into n^2 equal triangles on a barycentric grid (same winding).
fn split_triangle(b: &mut SceneBuilder, t: [Point; 3], n: usize, m: u32, origin: &str) {
    let point = |i: usize, j: usize| {
        let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
        t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0])
    };
    for i in 0..n {
        for j in 0..n - i {
            let (p, q, r) = (
                b.vertex(point(i, j)),
                b.vertex(point(i + 1, j)),
                b.vertex(point(i, j + 1)),
            );
            b.polygon(&[p, q, r], m, format!("{origin} cell ({i}, {j})"));
            if i + j + 1 < n {
                let s = b.vertex(point(i + 1, j + 1));
                b.polygon(&[q, s, r], m, format!("{origin} cell ({i}, {j})'"));
            }
        }
    }
}

/// `@sphere:L`: icosphere enclosure, inward normals, every triangle a patch.
pub fn sphere(spec: &str, levels: usize) -> Result<Scene, SceneError> {
    let ico = icosahedron();
    let mut tris: Vec<[Point; 3]> = ico
        .faces
        .iter()
        .map(|f| {
            let p = facing_inwards(f.iter().map(|&v| unit_vector(ico.vertices[v])).collect());
            [p[0], p[1], p[2]]
        })
        .collect();
    for _ in 0..levels {
        tris = tris
            .iter()
            .flat_map(|&[a, b, c]| {
                // (x + y) is symmetric, so neighbouring triangles get the bit-identical midpoint.
                let mid = |x: Point, y: Point| unit_vector(x + y);
                let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
            })
            .collect();
    }
    let mut b = SceneBuilder::new(spec);
    let m = grey_wall(&mut b);
    for (k, t) in tris.iter().enumerate() {
        let idx = t.map(|p| b.vertex(p));
        b.polygon(&idx, m, format!("triangle {k}"));
    }
    b.build()
}

fn tetrahedron() -> Polyhedron {
    let vertices = vec![
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(-1.0, -1.0, 1.0),
    ];
    Polyhedron {
        faces: triangles_with_edge(&vertices, 8f64.sqrt()),
        vertices,
    }
}

fn octahedron() -> Polyhedron {
    let mut vertices = Vec::new();
    for a in 0..3 {
        for s in [1.0, -1.0] {
            let mut v = DVec3::ZERO;
            v[a] = s;
            vertices.push(v);
        }
    }
    Polyhedron {
        faces: triangles_with_edge(&vertices, 2f64.sqrt()),
        vertices,
    }
}

fn icosahedron() -> Polyhedron {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut vertices = Vec::new();
    for s1 in [1.0, -1.0] {
        for s2 in [phi, -phi] {
            vertices.push(DVec3::new(0.0, s1, s2));
            vertices.push(DVec3::new(s1, s2, 0.0));
            vertices.push(DVec3::new(s2, 0.0, s1));
        }
    }
    Polyhedron {
        faces: triangles_with_edge(&vertices, 2.0),
        vertices,
    }
}

/// The dodecahedron as the dual of the icosahedron: a vertex per icosahedron face (its centroid), a
/// pentagon per icosahedron vertex (the centroids of the five faces around it, in angular order).
fn dodecahedron() -> Polyhedron {
    let ico = icosahedron();
    let vertices: Vec<Point> = ico
        .faces
        .iter()
        .map(|f| centroid(&f.iter().map(|&v| ico.vertices[v]).collect::<Vec<_>>()))
        .collect();
    let faces = (0..ico.vertices.len())
        .map(|v| {
            let axis = unit_vector(ico.vertices[v]);
            let (e1, e2) = orthonormal_basis(axis);
            let mut around: Vec<usize> = (0..ico.faces.len())
                .filter(|&f| ico.faces[f].contains(&v))
                .collect();
            around.sort_by(|&a, &b| {
                let angle = |f: usize| vertices[f].dot(e2).atan2(vertices[f].dot(e1));
                angle(a).total_cmp(&angle(b))
            });
            around
        })
        .collect();
    Polyhedron { vertices, faces }
}

/// All vertex triples whose three sides have length `edge`: the faces of a deltahedron.
fn triangles_with_edge(v: &[Point], edge: f64) -> Vec<Vec<usize>> {
    let is_edge = |a: usize, b: usize| ((v[a] - v[b]).length() - edge).abs() < 1e-9 * edge;
    let mut faces = Vec::new();
    for a in 0..v.len() {
        for b in a + 1..v.len() {
            for c in b + 1..v.len() {
                if is_edge(a, b) && is_edge(b, c) && is_edge(a, c) {
                    faces.push(vec![a, b, c]);
                }
            }
        }
    }
    faces
}

#[cfg(test)]
mod tests {

    #[test]
    fn solids_have_the_right_face_counts_and_inward_normals() {
        for (spec, faces) in [
            ("@tetrahedron", 4),
            ("@octahedron", 8),
            ("@cube", 6),
            ("@icosahedron", 20),
            ("@dodecahedron", 12),
            ("@sphere:0", 20),
            ("@sphere:2", 320),
            ("@tetrahedron:3", 36),
            ("@dodecahedron:2", 240),
        ] {
            let s = crate::scenes::build(spec).unwrap();
            assert_eq!(s.patch_count(), faces, "{spec}");
            for p in &s.patches {
                // Inward: the plane offset n . x is negative for a face around the origin.
                assert!(p.offset < 0.0, "{spec}: a patch faces outwards");
            }
        }
    }
}
