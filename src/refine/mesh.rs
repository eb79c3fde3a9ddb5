//! A refinable mesh: the scene's patches as planar convex elements that can be split.
//!
//! Splitting keeps every element planar and convex:
//! * a triangle becomes 4 at its edge midpoints;
//! * a quad becomes 4 along its bimedians (the segments joining the midpoints of opposite edges; each
//!   child is the quad cut by two lines through it, so convex, and the quad's plane holds them all);
//! * a polygon with 5 or more corners becomes 2 along the shortest chord joining the midpoints of two
//!   roughly opposite edges (a chord cuts a convex polygon into two convex ones).
//!
//! A midpoint is computed once per edge, from the edge's two end vertices in a fixed order, and remembered
//! (`splits`), so neighbours that both split a shared edge share the new vertex. A neighbour that does
//! not split it keeps its whole edge: its polygon does not list the new vertex, a T-junction. That is
//! harmless for tracing (a line would have to pass within f32 rounding of the edge to slip through or hit
//! twice) and keeps each OBJ face a plain convex polygon that the loader fans into triangles without
//! slivers (listing the new vertex in the neighbour's polygon would make the fan's first triangle on
//! that edge degenerate).

use std::collections::HashMap;

use crate::geom::Point;
use crate::scene::{Material, Scene, SceneBuilder, SceneError};

/// One element (a future patch): its corners counter-clockwise seen from the front, its material and
/// the object it belongs to.
#[derive(Clone, Debug, PartialEq)]
pub struct Element {
    /// Corner vertices (indices into the mesh's vertices).
    pub corners: Vec<u32>,
    /// Material index.
    pub material: u32,
    /// Object index (into the scene's objects), kept so that the refined scene keeps its objects.
    pub object: u32,
}

/// A mesh of planar convex elements in the scene's own units.
#[derive(Clone, Debug)]
pub struct Mesh {
    vertices: Vec<Point>,
    weld: HashMap<[u64; 3], u32>,
    elements: Vec<Element>,
    /// The midpoint vertex of each split edge, keyed by its end vertices (smaller index first).
    splits: HashMap<(u32, u32), u32>,
    materials: Vec<Material>,
    objects: Vec<String>,
}

impl Mesh {
    /// The scene's patches as elements (patch `k` is element `k`).
    pub fn from_scene(scene: &Scene) -> Self {
        let mut mesh = Mesh {
            vertices: Vec::new(),
            weld: HashMap::new(),
            elements: Vec::with_capacity(scene.patch_count()),
            splits: HashMap::new(),
            materials: scene.materials.clone(),
            objects: scene.objects.clone(),
        };
        let ids: Vec<u32> = scene.vertices.iter().map(|&p| mesh.vertex(p)).collect();
        for p in &scene.patches {
            mesh.elements.push(Element {
                corners: scene.polygon(p).iter().map(|&v| ids[v as usize]).collect(),
                material: p.material,
                object: p.object,
            });
        }
        mesh
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.elements.len()
    }

    /// Whether there are no elements.
    pub fn is_empty(&self) -> bool {
        self.elements.is_empty()
    }

    /// The elements.
    pub fn elements(&self) -> &[Element] {
        &self.elements
    }

    /// A vertex's position (scene units).
    pub fn position(&self, v: u32) -> Point {
        self.vertices[v as usize]
    }

    /// The mesh as a scene called `name`, element `k` becoming patch `k`.
    pub fn to_scene(&self, name: &str) -> Result<Scene, SceneError> {
        let mut b = SceneBuilder::new(name);
        for m in &self.materials {
            b.material(m.clone());
        }
        let ids: Vec<u32> = self.vertices.iter().map(|&p| b.vertex(p)).collect();
        for (k, e) in self.elements.iter().enumerate() {
            let corners: Vec<u32> = e.corners.iter().map(|&v| ids[v as usize]).collect();
            if let Some(object) = self.objects.get(e.object as usize) {
                b.object(object);
            }
            b.polygon(&corners, e.material, format!("element {k}"));
        }
        let scene = b.build()?;
        if scene.patch_count() != self.len() {
            // Only an input with zero-area faces gets here: the builder drops them.
            return Err(SceneError::Geometry {
                scene: name.into(),
                message: format!(
                    "{} of {} elements have no area; remove the degenerate faces first",
                    self.len() - scene.patch_count(),
                    self.len()
                ),
            });
        }
        Ok(scene)
    }

    /// Splits element `e` (see the module docs): the first child takes its index, the others are appended.
    pub fn split(&mut self, e: usize) {
        let Element {
            corners,
            material,
            object,
        } = self.elements[e].clone();
        let children = match corners.len() {
            3 => self.split_triangle(&corners),
            4 => self.split_quad(&corners),
            _ => self.split_polygon(&corners),
        };
        let mut children = children.into_iter().map(|c| Element {
            corners: c,
            material,
            object,
        });
        self.elements[e] = children.next().expect("a split has children");
        self.elements.extend(children);
    }

    fn vertex(&mut self, p: Point) -> u32 {
        let key = p.to_array().map(|c| (c + 0.0).to_bits());
        if let Some(&v) = self.weld.get(&key) {
            return v;
        }
        let v = self.vertices.len() as u32;
        self.vertices.push(p);
        self.weld.insert(key, v);
        v
    }

    /// The midpoint of edge (a, b), the same vertex from either side.
    fn midpoint(&mut self, a: u32, b: u32) -> u32 {
        let key = (a.min(b), a.max(b));
        if let Some(&m) = self.splits.get(&key) {
            return m;
        }
        let (p, q) = (self.vertices[key.0 as usize], self.vertices[key.1 as usize]);
        let m = self.vertex(0.5 * (p + q));
        self.splits.insert(key, m);
        m
    }

    fn split_triangle(&mut self, c: &[u32]) -> Vec<Vec<u32>> {
        let (a, b, d) = (c[0], c[1], c[2]);
        let (ab, bd, da) = (
            self.midpoint(a, b),
            self.midpoint(b, d),
            self.midpoint(d, a),
        );
        vec![
            vec![a, ab, da],
            vec![ab, b, bd],
            vec![da, bd, d],
            vec![ab, bd, da],
        ]
    }

    fn split_quad(&mut self, c: &[u32]) -> Vec<Vec<u32>> {
        let m: Vec<u32> = (0..4)
            .map(|k| self.midpoint(c[k], c[(k + 1) % 4]))
            .collect();
        let centre = {
            let p: Vec<Point> = c.iter().map(|&v| self.vertices[v as usize]).collect();
            // The bimedians cross at the mean of the four corners.
            self.vertex(0.25 * (p[0] + p[1] + p[2] + p[3]))
        };
        vec![
            vec![c[0], m[0], centre, m[3]],
            vec![m[0], c[1], m[1], centre],
            vec![centre, m[1], c[2], m[2]],
            vec![m[3], centre, m[2], c[3]],
        ]
    }

    fn split_polygon(&mut self, c: &[u32]) -> Vec<Vec<u32>> {
        let n = c.len();
        let half = n / 2;
        let mid_point = |k: usize| {
            let (p, q) = (
                self.vertices[c[k] as usize],
                self.vertices[c[(k + 1) % n] as usize],
            );
            0.5 * (p + q)
        };
        let chord = |k: usize| (mid_point(k) - mid_point((k + half) % n)).length_squared();
        // The shortest chord cuts across the polygon's longest extent.
        let k = (0..n)
            .min_by(|&a, &b| chord(a).total_cmp(&chord(b)))
            .expect("a polygon has edges");
        let l = (k + half) % n;
        let (mk, ml) = (
            self.midpoint(c[k], c[(k + 1) % n]),
            self.midpoint(c[l], c[(l + 1) % n]),
        );
        let walk = |from: usize, to: usize| -> Vec<u32> {
            let mut v = Vec::new();
            let mut i = from;
            loop {
                v.push(c[i]);
                if i == to {
                    return v;
                }
                i = (i + 1) % n;
            }
        };
        let mut first = vec![mk];
        first.extend(walk((k + 1) % n, l));
        first.push(ml);
        let mut second = vec![ml];
        second.extend(walk((l + 1) % n, k));
        second.push(mk);
        vec![first, second]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes;

    fn total_area(s: &Scene) -> f64 {
        s.total_area_scene_units()
    }

    #[test]
    fn splits_keep_the_area_and_make_the_expected_children() {
        for (spec, grow) in [("@cube", 3), ("@tetrahedron", 3), ("@dodecahedron", 1)] {
            let s = scenes::load(spec).unwrap();
            let mut m = Mesh::from_scene(&s);
            let before = m.len();
            m.split(0);
            assert_eq!(m.len(), before + grow, "{spec}");
            let t = m.to_scene("t").unwrap();
            assert!((total_area(&t) - total_area(&s)).abs() < 1e-12 * total_area(&s));
            // The children together have the parent's area.
            let parent = s.patches[0].area;
            let children: f64 = std::iter::once(0)
                .chain(before..m.len())
                .map(|k| t.patches[k].area)
                .sum();
            assert!(
                (children - parent).abs() < 1e-12,
                "{spec}: {children} vs {parent}"
            );
            // Planar and convex: the builder accepted them; every normal equals the parent's.
            for k in std::iter::once(0).chain(before..m.len()) {
                let (a, b) = (t.patches[k].normal, s.patches[0].normal);
                assert!(
                    (0..3).all(|i| (a[i] - b[i]).abs() < 1e-12),
                    "{spec}: child {k}"
                );
            }
        }
    }

    #[test]
    fn neighbours_share_the_midpoint_of_a_shared_edge() {
        let s = scenes::load("@cube:2").unwrap();
        let mut m = Mesh::from_scene(&s);
        // Patches 0 and 1 are side by side on face x = 0 (i = 0, j = 0 and 1): they share an edge.
        m.split(0);
        let n = m.len();
        m.split(1);
        assert_eq!(m.len(), n + 3);
        // Both split the shared edge: its midpoint is one vertex, used by children of both.
        let used_by = |v: u32| {
            m.elements()
                .iter()
                .filter(|e| e.corners.contains(&v))
                .count()
        };
        let shared = m
            .splits
            .values()
            .copied()
            .filter(|&v| used_by(v) == 4)
            .count();
        assert_eq!(
            shared, 1,
            "one midpoint on the shared edge, used by 2 + 2 children"
        );
    }
}
