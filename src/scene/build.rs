//! Building a [`Scene`] from polygons: validation, triangulation, patch planes, normalisation.

use std::collections::HashMap;

use super::{Material, Normalization, Patch, Scene, SceneError};
use crate::geom::{centroid, newell, triangle_area, Normal, Point};

/// A triangle whose area, relative to the squared bounding radius, is below this is degenerate.
const DEGENERATE_AREA: f64 = 1e-14;
/// A polygon whose vertices leave its plane by more than this fraction of its own size is not planar.
const PLANARITY_TOLERANCE: f64 = 1e-4;

/// Collects polygons (each one patch) and turns them into a [`Scene`].
///
/// Vertices at exactly the same position are welded, so triangles that meet along an edge share vertex
/// indices whatever the file did; the tracers rely on that to count a crossing of a shared edge once.
#[derive(Debug)]
pub struct SceneBuilder {
    name: String,
    vertices: Vec<Point>,
    weld: HashMap<[u64; 3], u32>,
    polygons: Vec<Polygon>,
    materials: Vec<Material>,
    warnings: Vec<String>,
}

#[derive(Debug)]
struct Polygon {
    vertices: Vec<u32>,
    material: u32,
    /// Where it came from, for messages (`face 12`, `line 40`).
    origin: String,
}

impl SceneBuilder {
    /// An empty scene called `name`.
    pub fn new(name: impl Into<String>) -> Self {
        SceneBuilder {
            name: name.into(),
            vertices: Vec::new(),
            weld: HashMap::new(),
            polygons: Vec::new(),
            materials: Vec::new(),
            warnings: Vec::new(),
        }
    }

    /// Adds a vertex (welded with an identical earlier one) and returns its index.
    pub fn vertex(&mut self, p: impl Into<Point>) -> u32 {
        let p = p.into();
        // -0.0 and 0.0 are the same point.
        let key = p.to_array().map(|c| (c + 0.0).to_bits());
        if let Some(&i) = self.weld.get(&key) {
            return i;
        }
        let i = self.vertices.len() as u32;
        self.vertices.push(p);
        self.weld.insert(key, i);
        i
    }

    /// Adds a material and returns its index.
    pub fn material(&mut self, m: Material) -> u32 {
        self.materials.push(m);
        (self.materials.len() - 1) as u32
    }

    /// Adds a planar convex polygon (counter-clockwise seen from its front side) as one patch.
    pub fn polygon(&mut self, vertices: &[u32], material: u32, origin: impl Into<String>) {
        self.polygons.push(Polygon {
            vertices: vertices.to_vec(),
            material,
            origin: origin.into(),
        });
    }

    /// Records a non-fatal problem to report with the scene.
    pub fn warn(&mut self, message: impl Into<String>) {
        self.warnings.push(message.into());
    }

    /// Validates the geometry, triangulates the polygons and scales the scene to its unit bounding sphere.
    pub fn build(mut self) -> Result<Scene, SceneError> {
        if self.materials.is_empty() {
            self.materials.push(Material::default());
        }
        self.check_finite()?;
        let normalization = self.normalization()?;
        let traced: Vec<Point> = self
            .vertices
            .iter()
            .map(|p| to_tracing_space(*p, &normalization))
            .collect();

        // Vertices that round to the same f32 point are one vertex for the tracers: weld them, so that
        // triangles meeting there share the index (the hit rules merge a crossing of a shared vertex).
        let remap = weld_f32(&traced, &mut self.polygons);
        drop_duplicates(&self.name, &mut self.polygons, &mut self.warnings);
        let vertices: Vec<Point> = remap.iter().map(|&v| self.vertices[v as usize]).collect();
        let traced: Vec<Point> = remap.iter().map(|&v| traced[v as usize]).collect();

        let mut scene = Scene {
            name: self.name.clone(),
            positions: traced.iter().map(|p| p.as_vec3().to_array()).collect(),
            vertices,
            triangles: Vec::new(),
            triangle_patch: Vec::new(),
            patches: Vec::new(),
            materials: std::mem::take(&mut self.materials),
            normalization,
            area_scene_units: 0.0,
            warnings: std::mem::take(&mut self.warnings),
        };
        let mut dropped_triangles = 0usize;
        let mut dropped_polygons = Vec::new();
        for poly in &self.polygons {
            if poly.vertices.len() < 3 {
                return Err(self.geometry_error(format!(
                    "{}: a face needs at least 3 vertices, it has {}",
                    poly.origin,
                    poly.vertices.len()
                )));
            }
            if poly.material as usize >= scene.materials.len() {
                return Err(self.geometry_error(format!(
                    "{}: material index {} out of range",
                    poly.origin, poly.material
                )));
            }
            let pts: Vec<Point> = poly.vertices.iter().map(|&v| traced[v as usize]).collect();
            let (normal, area) = newell(&pts);
            check_planar(&pts, normal, area)
                .map_err(|m| self.geometry_error(format!("{}: {m}", poly.origin)))?;
            let first = scene.triangles.len() as u32;
            let patch_index = scene.patches.len() as u32;
            let mut patch_area = 0.0;
            for k in 1..poly.vertices.len() - 1 {
                let tri = [poly.vertices[0], poly.vertices[k], poly.vertices[k + 1]];
                let a = triangle_area(
                    traced[tri[0] as usize],
                    traced[tri[1] as usize],
                    traced[tri[2] as usize],
                );
                if a <= DEGENERATE_AREA {
                    dropped_triangles += 1;
                    continue;
                }
                patch_area += a;
                scene.area_scene_units += triangle_area(
                    scene.vertices[tri[0] as usize],
                    scene.vertices[tri[1] as usize],
                    scene.vertices[tri[2] as usize],
                );
                scene.triangles.push(tri);
                scene.triangle_patch.push(patch_index);
            }
            let count = scene.triangles.len() as u32 - first;
            if count == 0 {
                dropped_polygons.push(poly.origin.clone());
                continue;
            }
            let centroid = centroid(&pts);
            scene.patches.push(Patch {
                area: patch_area,
                normal,
                offset: normal.dot(centroid),
                material: poly.material,
                first_triangle: first,
                triangle_count: count,
                polygon: poly.vertices.clone(),
            });
        }
        if dropped_triangles > 0 {
            scene.warnings.push(format!(
                "{}: dropped {dropped_triangles} zero-area triangle(s)",
                self.name
            ));
        }
        if !dropped_polygons.is_empty() {
            scene.warnings.push(format!(
                "{}: dropped {} zero-area face(s), first: {}",
                self.name,
                dropped_polygons.len(),
                dropped_polygons[0]
            ));
        }
        if scene.patches.is_empty() {
            return Err(self.geometry_error("the scene has no faces of non-zero area".into()));
        }
        Ok(scene)
    }

    fn geometry_error(&self, message: String) -> SceneError {
        SceneError::Geometry {
            scene: self.name.clone(),
            message,
        }
    }

    fn check_finite(&self) -> Result<(), SceneError> {
        for poly in &self.polygons {
            for &v in &poly.vertices {
                let p = self.vertices.get(v as usize).ok_or_else(|| {
                    self.geometry_error(format!("{}: vertex index {v} out of range", poly.origin))
                })?;
                if !p.is_finite() {
                    return Err(self.geometry_error(format!(
                        "{}: vertex {} has a non-finite coordinate ({}, {}, {})",
                        poly.origin,
                        v + 1,
                        p.x,
                        p.y,
                        p.z
                    )));
                }
            }
        }
        Ok(())
    }

    /// Centre of the bounding box of the used vertices, and the largest distance from it.
    fn normalization(&self) -> Result<Normalization, SceneError> {
        let used: Vec<Point> = self
            .polygons
            .iter()
            .flat_map(|p| p.vertices.iter().map(|&v| self.vertices[v as usize]))
            .collect();
        if used.is_empty() {
            return Err(self.geometry_error("the scene is empty: no faces".into()));
        }
        let mut lo = Point::INFINITY;
        let mut hi = Point::NEG_INFINITY;
        for p in &used {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let center = 0.5 * (lo + hi);
        let radius = used
            .iter()
            .map(|&p| (p - center).length())
            .fold(0.0f64, f64::max);
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(self.geometry_error(format!(
                "the scene has no extent (bounding radius {radius})"
            )));
        }
        Ok(Normalization {
            center,
            scale: radius,
        })
    }
}

/// Renumbers vertices so that those with equal f32 tracing positions become one, rewriting the polygons;
/// returns, for each new vertex, the old vertex it stands for (unused vertices are dropped).
fn weld_f32(traced: &[Point], polygons: &mut [Polygon]) -> Vec<u32> {
    let mut by_position: HashMap<[u32; 3], u32> = HashMap::new();
    let mut new_of_old: Vec<Option<u32>> = vec![None; traced.len()];
    let mut old_of_new: Vec<u32> = Vec::new();
    for poly in polygons.iter_mut() {
        for v in poly.vertices.iter_mut() {
            let old = *v as usize;
            let new = *new_of_old[old].get_or_insert_with(|| {
                let key = traced[old].to_array().map(|c| ((c as f32) + 0.0).to_bits());
                *by_position.entry(key).or_insert_with(|| {
                    old_of_new.push(old as u32);
                    (old_of_new.len() - 1) as u32
                })
            });
            *v = new;
        }
    }
    old_of_new
}

/// Drops, with a warning, faces with the same corners in the same cyclic order as an earlier face: they
/// coincide with it and face the same way, so they could never be seen (of overlapping faces the first
/// in the scene is the one seen, see `sample::order`). The same corners in the opposite order are the
/// two sides of a thin panel, which stay.
fn drop_duplicates(name: &str, polygons: &mut Vec<Polygon>, warnings: &mut Vec<String>) {
    let mut seen: HashMap<Vec<u32>, usize> = HashMap::new();
    let mut duplicates = Vec::new();
    for (k, poly) in polygons.iter().enumerate() {
        let v = &poly.vertices;
        let Some(lowest) = (0..v.len()).min_by_key(|&i| v[i]) else {
            continue;
        };
        let key: Vec<u32> = (0..v.len()).map(|i| v[(lowest + i) % v.len()]).collect();
        if let Some(&first) = seen.get(&key) {
            duplicates.push((first, k));
        } else {
            seen.insert(key, k);
        }
    }
    let Some(&(first, again)) = duplicates.first() else {
        return;
    };
    warnings.push(format!(
        "{name}: dropped {} face(s) repeating an earlier face (same corners, facing the same way: never \
         seen), first: {} repeats {}",
        duplicates.len(),
        polygons[again].origin,
        polygons[first].origin
    ));
    let drop: std::collections::HashSet<usize> = duplicates.iter().map(|&(_, k)| k).collect();
    let mut k = 0;
    polygons.retain(|_| {
        k += 1;
        !drop.contains(&(k - 1))
    });
}

fn to_tracing_space(p: Point, n: &Normalization) -> Point {
    (p - n.center) / n.scale
}

fn check_planar(pts: &[Point], normal: Normal, area: f64) -> Result<(), String> {
    if pts.len() <= 3 || area <= 0.0 {
        return Ok(());
    }
    let c = centroid(pts);
    let size = pts.iter().map(|&p| (p - c).length()).fold(0.0, f64::max);
    let off = pts
        .iter()
        .map(|&p| normal.dot(p - c).abs())
        .fold(0.0, f64::max);
    if off > PLANARITY_TOLERANCE * size {
        return Err(format!(
            "non-planar polygon with {} vertices: a vertex is {:.3e} of the face's size off its plane \
             (tolerance {PLANARITY_TOLERANCE:e}); triangulate it",
            pts.len(),
            off / size
        ));
    }
    Ok(())
}
