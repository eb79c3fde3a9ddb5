//! Building a [`Scene`] from polygons: validation, triangulation, patch planes, normalisation.
//!
//! Polygons come as files give them: a polygon planar within the tolerance is one patch (cut into
//! triangles by a fan when convex, by ear clipping when not); a non-planar one is split into planar
//! triangles, each its own patch, with one warning per scene (or refused in strict mode). Objects chosen
//! by the options have their normals flipped or are made two-sided: two patches back to back, one per
//! side, each with the face's area and material.

use std::collections::HashMap;

use super::{Material, Normalization, Patch, Scene, SceneError, SceneWarning, SceneWarningKind};
use crate::geom::polygon::{planar_pieces, planarity_deviation, triangulate};
use crate::geom::{centroid, newell, triangle_area, Point, Vector};

/// A triangle whose area, relative to the squared bounding radius, is below this is degenerate.
const DEGENERATE_AREA: f64 = 1e-14;
/// By default a polygon whose corners leave its plane by more than this fraction of its own size is not
/// planar: far above the rounding of coordinates written with 6 or more digits, far below a bend anyone
/// would model on purpose.
pub const DEFAULT_PLANARITY: f64 = 1e-4;
/// How many split polygons the warning names.
const SPLIT_EXAMPLES: usize = 3;

/// What to do with polygons whose corners leave their plane.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Planarity {
    /// Corners at most this fraction of the polygon's size off its best-fit plane count as planar.
    pub tolerance: f64,
    /// Refuse a non-planar polygon (an error naming it) instead of splitting it into planar triangles.
    pub strict: bool,
}

impl Default for Planarity {
    fn default() -> Self {
        Planarity {
            tolerance: DEFAULT_PLANARITY,
            strict: false,
        }
    }
}

/// Some of a scene's objects, by name.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ObjectSet {
    /// None of them.
    #[default]
    None,
    /// Every object.
    All,
    /// The objects with these names (each must exist).
    Named(Vec<String>),
}

/// How a scene is built from its file: the planarity rule and the objects to flip or make two-sided.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SceneOptions {
    /// What to do with non-planar polygons.
    pub planarity: Planarity,
    /// Objects whose polygons face the other way (their corners reversed).
    pub flip_normals: ObjectSet,
    /// Objects whose polygons are surfaces on both sides (a second, reversed patch back to back).
    pub two_sided: ObjectSet,
}

/// Which sides of a polygon are surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sides {
    /// The front side only (the side its normal points to): the other side is the inside of a solid or
    /// the outside of an enclosure.
    Front,
    /// Both sides: two patches back to back (a thin panel, a leaf, glTF's `doubleSided`).
    Both,
}

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
    /// Every polygon's corners, one after the other ([`Polygon::corners`]): one list rather than one per
    /// polygon, as a scene of millions of triangles would spend more on the lists' own keeping than on
    /// their corners.
    corners: Vec<u32>,
    /// Every polygon's origin text, one after the other ([`Polygon::origin`]), for the same reason.
    origins: String,
    materials: Vec<Material>,
    objects: Vec<String>,
    current_object: Option<u32>,
    warnings: Vec<SceneWarning>,
    /// Faces that went round their corners more than once (`f 1 2 3 1 2 3`), read once round: how many,
    /// and the first's origin and number of rounds.
    wound_again: (usize, Option<(String, usize)>),
}

#[derive(Clone, Copy, Debug)]
struct Polygon {
    /// Where its corners start in the builder's `corners`.
    start: usize,
    /// How many corners it has.
    len: usize,
    material: u32,
    object: u32,
    sides: Sides,
    /// Where its origin text starts in the builder's `origins`, and its length: where it came from, for
    /// messages (`face 12`, `line 40`).
    origin_start: usize,
    origin_len: usize,
    /// Whether it is the back side of a two-sided polygon (the reverse of the one before it).
    back: bool,
}

impl Polygon {
    fn corners<'a>(&self, corners: &'a [u32]) -> &'a [u32] {
        &corners[self.start..self.start + self.len]
    }

    /// Where it came from, for messages (the back side of a two-sided polygon says so).
    fn origin<'a>(&self, origins: &'a str) -> Origin<'a> {
        Origin {
            text: &origins[self.origin_start..self.origin_start + self.origin_len],
            back: self.back,
        }
    }
}

/// A polygon's origin as messages show it.
struct Origin<'a> {
    text: &'a str,
    back: bool,
}

impl std::fmt::Display for Origin<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.text)?;
        if self.back {
            f.write_str(" (back side)")?;
        }
        Ok(())
    }
}

/// The polygons split because they were not planar, for the one warning about them.
#[derive(Debug, Default)]
struct Splits {
    count: usize,
    pieces: usize,
    /// The pieces of the back sides of split two-sided polygons: patches too, but not more polygons.
    back_pieces: usize,
    worst: f64,
    examples: Vec<String>,
    /// The objects of the split polygons.
    objects: std::collections::BTreeSet<u32>,
}

impl SceneBuilder {
    /// An empty scene called `name`.
    pub fn new(name: impl Into<String>) -> Self {
        SceneBuilder {
            name: name.into(),
            vertices: Vec::new(),
            weld: HashMap::new(),
            polygons: Vec::new(),
            corners: Vec::new(),
            origins: String::new(),
            materials: Vec::new(),
            objects: Vec::new(),
            current_object: None,
            warnings: Vec::new(),
            wound_again: (0, None),
        }
    }

    /// Makes `name` the object of the polygons added from now on (a new object, or an earlier one of the
    /// same name) and returns its index. Polygons added before any object is named belong to an object
    /// named after the scene.
    pub fn object(&mut self, name: &str) -> u32 {
        let k = match self.objects.iter().position(|o| o == name) {
            Some(k) => k as u32,
            None => {
                self.objects.push(name.to_string());
                (self.objects.len() - 1) as u32
            }
        };
        self.current_object = Some(k);
        k
    }

    fn current_object(&mut self) -> u32 {
        match self.current_object {
            Some(k) => k,
            None => {
                let name = self.name.clone();
                self.object(&name)
            }
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

    /// Adds a polygon (counter-clockwise seen from its front side), one-sided, to the current object: one
    /// patch when planar, planar triangles when not ([`Planarity`]).
    pub fn polygon(&mut self, vertices: &[u32], material: u32, origin: impl Into<String>) {
        self.polygon_sided(vertices, material, origin, Sides::Front);
    }

    /// Adds a polygon with the given sides to the current object (see [`SceneBuilder::polygon`]).
    pub fn polygon_sided(
        &mut self,
        vertices: &[u32],
        material: u32,
        origin: impl Into<String>,
        sides: Sides,
    ) {
        let object = self.current_object();
        let origin = origin.into();
        let once = once_round(vertices);
        if once.len() < vertices.len() {
            self.wound_again.0 += 1;
            let rounds = vertices.len() / once.len();
            self.wound_again
                .1
                .get_or_insert_with(|| (origin.clone(), rounds));
        }
        let vertices = once;
        self.polygons.push(Polygon {
            start: self.corners.len(),
            len: vertices.len(),
            material,
            object,
            sides,
            origin_start: self.origins.len(),
            origin_len: origin.len(),
            back: false,
        });
        self.corners.extend_from_slice(vertices);
        self.origins.push_str(&origin);
    }

    /// The warning for faces that went round their corners more than once, if any did.
    fn wound_again_warning(&mut self) {
        let (count, Some((first, rounds))) = std::mem::take(&mut self.wound_again) else {
            return;
        };
        let message = format!(
            "{}: {count} face(s) list their corners more than once round (first: {first}, {rounds} \
             times), read once round: each round again would lay the face on itself and count its area \
             again",
            self.name
        );
        self.warnings.push(
            SceneWarning::new(SceneWarningKind::DuplicateFaces, message)
                .with_numbers(&[("faces", count as f64)]),
        );
    }

    /// Records a non-fatal problem to report with the scene.
    pub fn warn(&mut self, kind: SceneWarningKind, message: impl Into<String>) {
        self.warnings.push(SceneWarning::new(kind, message));
    }

    /// Records a non-fatal problem, with its objects and counts.
    pub fn warn_with(&mut self, warning: SceneWarning) {
        self.warnings.push(warning);
    }

    /// Validates the geometry, triangulates the polygons and scales the scene to its unit bounding sphere,
    /// with the default options.
    pub fn build(self) -> Result<Scene, SceneError> {
        self.build_with(&SceneOptions::default())
    }

    /// [`SceneBuilder::build`] with options: the planarity rule, and objects to flip or make two-sided
    /// (an object name that does not exist is an error listing the scene's objects).
    pub fn build_with(mut self, options: &SceneOptions) -> Result<Scene, SceneError> {
        if self.materials.is_empty() {
            self.materials.push(Material::default());
        }
        self.wound_again_warning();
        if self.objects.is_empty() {
            let name = self.name.clone();
            self.object(&name);
        }
        // The weld table is done with once every vertex is in; a large scene needs its memory for what
        // follows.
        self.weld = HashMap::new();
        self.check_finite()?;
        let flip = self.chosen_objects(&options.flip_normals, "--flip-normals")?;
        let two_sided = self.chosen_objects(&options.two_sided, "--two-sided")?;
        self.polygons = sided_polygons(
            std::mem::take(&mut self.polygons),
            &mut self.corners,
            &flip,
            &two_sided,
        );
        let normalization = self.normalization()?;
        let traced: Vec<Point> = self
            .vertices
            .iter()
            .map(|p| to_tracing_space(*p, &normalization))
            .collect();

        // Vertices that round to the same f32 point are one vertex for the tracers: weld them, so that
        // triangles meeting there share the index (the hit rules merge a crossing of a shared vertex).
        let remap = weld_f32(&traced, &self.polygons, &mut self.corners);
        drop_duplicates(
            &self.name,
            &mut self.polygons,
            &self.corners,
            &self.origins,
            &mut self.warnings,
        );
        let vertices: Vec<Point> = remap.iter().map(|&v| self.vertices[v as usize]).collect();
        self.vertices = Vec::new();
        let traced_all = traced;
        let traced: Vec<Point> = remap.iter().map(|&v| traced_all[v as usize]).collect();
        drop(traced_all);
        drop(remap);

        let mut scene = Scene {
            name: self.name.clone(),
            positions: traced.iter().map(|p| p.as_vec3().to_array()).collect(),
            vertices,
            triangles: Vec::new(),
            triangle_patch: Vec::new(),
            corners: Vec::new(),
            patches: Vec::new(),
            materials: std::mem::take(&mut self.materials),
            objects: std::mem::take(&mut self.objects),
            normalization,
            area_scene_units: 0.0,
            warnings: std::mem::take(&mut self.warnings),
            files_read: Vec::new(),
        };
        let mut dropped_triangles = 0usize;
        // How many polygons were dropped, and the first of them.
        let mut dropped_polygons = (0usize, None::<String>);
        let mut splits = Splits::default();
        for poly in &self.polygons {
            let origin = poly.origin(&self.origins);
            let poly_corners = poly.corners(&self.corners);
            if poly.len < 3 {
                return Err(self.geometry_error(format!(
                    "{origin}: a face needs at least 3 vertices, it has {}",
                    poly.len
                )));
            }
            if poly.material as usize >= scene.materials.len() {
                return Err(self.geometry_error(format!(
                    "{origin}: material index {} out of range",
                    poly.material
                )));
            }
            let pts: Vec<Point> = poly_corners.iter().map(|&v| traced[v as usize]).collect();
            // Zero-area triangles of this polygon: counted in the scene's only when the polygon keeps
            // others (a polygon of nothing but zero-area triangles is a dropped face).
            let mut dropped_here = 0usize;
            let deviation = planarity_deviation(&pts);
            let created = if deviation > options.planarity.tolerance {
                if options.planarity.strict {
                    return Err(self.geometry_error(format!(
                        "{origin}: non-planar polygon with {} vertices: a vertex is {deviation:.3e} of \
                         the face's size off its plane (tolerance {:e}); triangulate it, or leave \
                         --strict-planarity out to have it split into planar triangles",
                        pts.len(),
                        options.planarity.tolerance
                    )));
                }
                let pieces = planar_pieces(&pts)
                    .map_err(|e| self.geometry_error(format!("{origin}: {e}")))?;
                splits.add(poly, &origin, deviation, pieces.len());
                let mut any = false;
                for piece in pieces {
                    let corners = piece.map(|k| poly_corners[k]);
                    any |= add_patch(
                        &mut scene,
                        &traced,
                        poly,
                        &corners,
                        &[[0, 1, 2]],
                        &mut dropped_here,
                    );
                }
                any
            } else {
                let triangles =
                    triangulate(&pts).map_err(|e| self.geometry_error(format!("{origin}: {e}")))?;
                add_patch(
                    &mut scene,
                    &traced,
                    poly,
                    poly_corners,
                    &triangles,
                    &mut dropped_here,
                )
            };
            if created {
                dropped_triangles += dropped_here;
            } else {
                // The face's triangles go with it: one warning about the face, not a second about them.
                dropped_polygons.0 += 1;
                dropped_polygons.1.get_or_insert_with(|| origin.to_string());
            }
        }
        // Patches address their corners and triangles with 32-bit offsets.
        if scene.corners.len() > u32::MAX as usize || scene.triangles.len() > u32::MAX as usize {
            return Err(self.geometry_error(format!(
                "{} polygon corners and {} triangles: more than the {} scx can address",
                scene.corners.len(),
                scene.triangles.len(),
                u32::MAX
            )));
        }
        // The polygons are patches now. Their vectors grew by doubling: a large scene keeps them for
        // the whole run, so they give back what they overshot, after the polygons made room.
        drop(traced);
        self.polygons = Vec::new();
        self.corners = Vec::new();
        self.origins = String::new();
        scene.triangles.shrink_to_fit();
        scene.triangle_patch.shrink_to_fit();
        scene.patches.shrink_to_fit();
        scene.corners.shrink_to_fit();
        if let Some(w) = splits.warning(&self.name, options.planarity.tolerance, &scene.objects) {
            scene.warnings.push(w);
        }
        if dropped_triangles > 0 {
            let w = SceneWarning::new(
                SceneWarningKind::ZeroAreaTriangles,
                format!(
                    "{}: dropped {dropped_triangles} zero-area triangle(s)",
                    self.name
                ),
            );
            scene
                .warnings
                .push(w.with_numbers(&[("triangles", dropped_triangles as f64)]));
        }
        if let (count, Some(first)) = dropped_polygons {
            let w = SceneWarning::new(
                SceneWarningKind::ZeroAreaFaces,
                format!(
                    "{}: dropped {count} zero-area face(s), first: {first}",
                    self.name,
                ),
            );
            scene
                .warnings
                .push(w.with_numbers(&[("faces", count as f64)]));
        }
        if scene.patches.is_empty() {
            return Err(self.geometry_error("the scene has no faces of non-zero area".into()));
        }
        self.check_used_materials(&scene)?;
        Ok(scene)
    }

    /// Every channel of a used material physical (reflectance in [0, 1], emission finite and >= 0).
    fn check_used_materials(&self, scene: &Scene) -> Result<(), SceneError> {
        let mut used = vec![false; scene.materials.len()];
        for p in &scene.patches {
            used[p.material as usize] = true;
        }
        for (m, _) in scene.materials.iter().zip(&used).filter(|(_, &u)| u) {
            if let Some(problem) = m.unphysical_channel() {
                return Err(self.geometry_error(format!("material `{}`: {problem}", m.name)));
            }
        }
        Ok(())
    }

    /// Which objects a set names (one flag per object); an unknown name is an error listing the objects.
    fn chosen_objects(&self, set: &ObjectSet, option: &str) -> Result<Vec<bool>, SceneError> {
        let n = self.objects.len();
        match set {
            ObjectSet::None => Ok(vec![false; n]),
            ObjectSet::All => Ok(vec![true; n]),
            ObjectSet::Named(names) => {
                let mut chosen = vec![false; n];
                for name in names {
                    let Some(k) = self.objects.iter().position(|o| o == name) else {
                        return Err(self.geometry_error(format!(
                            "{option}: no object named `{name}`; the scene's objects are {}",
                            list_names(&self.objects)
                        )));
                    };
                    chosen[k] = true;
                }
                Ok(chosen)
            }
        }
    }

    fn geometry_error(&self, message: String) -> SceneError {
        SceneError::Geometry {
            scene: self.name.clone(),
            message,
        }
    }

    /// Every corner of every polygon at a finite point. Readers that know the file's own numbering of
    /// vertices check theirs as they read; this names the corner within its polygon, since the
    /// builder's vertex numbers (welded) are not the file's.
    fn check_finite(&self) -> Result<(), SceneError> {
        for poly in &self.polygons {
            let corners = poly.corners(&self.corners);
            for (k, &v) in corners.iter().enumerate() {
                let origin = poly.origin(&self.origins);
                let p = self.vertices.get(v as usize).ok_or_else(|| {
                    self.geometry_error(format!("{origin}: vertex index {v} out of range"))
                })?;
                if !p.is_finite() {
                    return Err(self.geometry_error(format!(
                        "{origin}: corner {} of {} has a non-finite coordinate ({}, {}, {})",
                        k + 1,
                        corners.len(),
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
        // The used vertices, each as often as a corner names it (twice over them, rather than a list of
        // them all: a large scene needs the memory).
        let used = || {
            self.polygons.iter().flat_map(|p| {
                p.corners(&self.corners)
                    .iter()
                    .map(|&v| self.vertices[v as usize])
            })
        };
        if used().next().is_none() {
            return Err(self.geometry_error("the scene is empty: no faces".into()));
        }
        let mut lo = Point::INFINITY;
        let mut hi = Point::NEG_INFINITY;
        for p in used() {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        // Halves first: the centre of a box from -1e308 to 1e308 stays finite.
        let center = 0.5 * lo + 0.5 * hi;
        let radius = used()
            .map(|p| length_without_overflow(p - center))
            .fold(0.0f64, f64::max);
        if radius == 0.0 {
            return Err(
                self.geometry_error("the scene has no extent: every vertex is one point".into())
            );
        }
        if !(MIN_RADIUS..=MAX_RADIUS).contains(&radius) {
            let size = if radius > MAX_RADIUS {
                "large"
            } else {
                "small"
            };
            // Each coordinate is finite (checked before), but areas, the square of the size, and the sums
            // over them must stay well inside f64's range.
            return Err(self.geometry_error(format!(
                "the scene is too {size} to measure: its bounding box runs from ({:e}, {:e}, {:e}) to \
                 ({:e}, {:e}, {:e}), a bounding sphere of radius {radius:e}; scx measures scenes of radius \
                 {MIN_RADIUS:e} to {MAX_RADIUS:e} in their own units, so that areas stay well inside the \
                 range of 64-bit numbers (rescale it)",
                lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
            )));
        }
        Ok(Normalization {
            center,
            scale: radius,
        })
    }
}

/// The smallest bounding radius of a scene scx measures, in its own units: areas, and the squares of
/// the coordinates' products that compute them, stay far from where 64-bit numbers lose digits.
pub const MIN_RADIUS: f64 = 1e-50;
/// The largest bounding radius of a scene scx measures: areas and the squares behind them stay far from
/// overflow (a radius of 1e78 made the area infinite).
pub const MAX_RADIUS: f64 = 1e50;

/// The length of `v`, scaled by its largest component where its square would overflow or underflow (in
/// range, the plain length: the scenes scx measures keep their numbers bit for bit).
fn length_without_overflow(v: Vector) -> f64 {
    let plain = v.length();
    if plain.is_finite() && plain > 1e-150 {
        return plain;
    }
    let largest = v.x.abs().max(v.y.abs()).max(v.z.abs());
    if largest == 0.0 || !largest.is_finite() {
        return largest;
    }
    largest * (v / largest).length()
}

/// Renumbers vertices so that those with equal f32 tracing positions become one, rewriting the polygons;
/// returns, for each new vertex, the old vertex it stands for (unused vertices are dropped).
fn weld_f32(traced: &[Point], polygons: &[Polygon], corners: &mut [u32]) -> Vec<u32> {
    let mut by_position: HashMap<[u32; 3], u32> = HashMap::new();
    let mut new_of_old: Vec<Option<u32>> = vec![None; traced.len()];
    let mut old_of_new: Vec<u32> = Vec::new();
    for poly in polygons {
        for v in corners[poly.start..poly.start + poly.len].iter_mut() {
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

/// A polygon's corners once round: the shortest prefix (of 3 corners or more) that the whole list
/// repeats (`1 2 3 1 2 3` is `1 2 3` twice), or all of them.
fn once_round(vertices: &[u32]) -> &[u32] {
    let n = vertices.len();
    (3..n)
        .filter(|p| n % p == 0)
        .find(|&p| (p..n).all(|i| vertices[i] == vertices[i - p]))
        .map_or(vertices, |p| &vertices[..p])
}

/// Drops, with a warning, faces with the same corners in the same cyclic order as an earlier face: they
/// coincide with it and face the same way, so they could never be seen (of overlapping faces the first
/// in the scene is the one seen, see `sample::order`). The same corners in the opposite order are the
/// two sides of a thin panel, which stay.
fn drop_duplicates(
    name: &str,
    polygons: &mut Vec<Polygon>,
    corners: &[u32],
    origins: &str,
    warnings: &mut Vec<SceneWarning>,
) {
    // Each polygon's corners from its lowest, all in one list (keys of their own would cost a large
    // scene more than their corners).
    let mut rotated: Vec<u32> = Vec::with_capacity(polygons.iter().map(|p| p.len).sum());
    for poly in polygons.iter() {
        let v = poly.corners(corners);
        if let Some(lowest) = (0..v.len()).min_by_key(|&i| v[i]) {
            rotated.extend((0..v.len()).map(|i| v[(lowest + i) % v.len()]));
        }
    }
    let mut seen: HashMap<&[u32], usize> = HashMap::with_capacity(polygons.len());
    let mut duplicates = Vec::new();
    let mut at = 0;
    for (k, poly) in polygons.iter().enumerate() {
        if poly.len == 0 {
            continue;
        }
        let key = &rotated[at..at + poly.len];
        at += poly.len;
        if let Some(&first) = seen.get(key) {
            duplicates.push((first, k));
        } else {
            seen.insert(key, k);
        }
    }
    drop(seen);
    let Some(&(first, again)) = duplicates.first() else {
        return;
    };
    let message = format!(
        "{name}: dropped {} face(s) repeating an earlier face (same corners, facing the same way: never \
         seen), first: {} repeats {}",
        duplicates.len(),
        polygons[again].origin(origins),
        polygons[first].origin(origins)
    );
    warnings.push(
        SceneWarning::new(SceneWarningKind::DuplicateFaces, message)
            .with_numbers(&[("faces", duplicates.len() as f64)]),
    );
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

/// The polygons with flipped objects' corners reversed, and each two-sided polygon followed by its
/// reverse (the back side as a patch of its own).
fn sided_polygons(
    polygons: Vec<Polygon>,
    corners: &mut Vec<u32>,
    flip: &[bool],
    two_sided: &[bool],
) -> Vec<Polygon> {
    let backs = polygons
        .iter()
        .filter(|p| p.sides == Sides::Both || two_sided[p.object as usize])
        .count();
    if backs == 0 && !flip.contains(&true) {
        return polygons;
    }
    let mut out = Vec::with_capacity(polygons.len() + backs);
    for poly in polygons {
        let range = poly.start..poly.start + poly.len;
        if flip[poly.object as usize] {
            reverse_corners(&mut corners[range.clone()]);
        }
        let both = poly.sides == Sides::Both || two_sided[poly.object as usize];
        let back = both.then(|| {
            let start = corners.len();
            corners.extend_from_within(range);
            reverse_corners(&mut corners[start..]);
            Polygon {
                start,
                back: true,
                ..poly
            }
        });
        out.push(poly);
        out.extend(back);
    }
    out
}

/// Reverses a polygon's orientation keeping its first corner first (so its fan starts there too).
fn reverse_corners(v: &mut [u32]) {
    if v.len() > 1 {
        v[1..].reverse();
    }
}

/// Adds the triangles `tris` (indices into `corners`) of polygon `poly` as one patch whose outline is
/// `corners`; drops zero-area triangles (counted) and returns whether any triangle was left.
fn add_patch(
    scene: &mut Scene,
    traced: &[Point],
    poly: &Polygon,
    corners: &[u32],
    tris: &[[usize; 3]],
    dropped_triangles: &mut usize,
) -> bool {
    let pts: Vec<Point> = corners.iter().map(|&v| traced[v as usize]).collect();
    let (normal, _) = newell(&pts);
    let first = scene.triangles.len() as u32;
    let patch_index = scene.patches.len() as u32;
    let mut patch_area = 0.0;
    for t in tris {
        let tri = t.map(|k| corners[k]);
        let a = triangle_area(
            traced[tri[0] as usize],
            traced[tri[1] as usize],
            traced[tri[2] as usize],
        );
        if a <= DEGENERATE_AREA {
            *dropped_triangles += 1;
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
        return false;
    }
    scene.patches.push(Patch {
        area: patch_area,
        normal,
        offset: normal.dot(centroid(&pts)),
        material: poly.material,
        object: poly.object,
        first_triangle: first,
        triangle_count: count,
        first_corner: scene.corners.len() as u32,
        corner_count: corners.len() as u32,
    });
    scene.corners.extend_from_slice(corners);
    true
}

impl Splits {
    fn add(&mut self, poly: &Polygon, origin: &Origin<'_>, deviation: f64, pieces: usize) {
        if poly.back {
            self.back_pieces += pieces;
            return;
        }
        self.objects.insert(poly.object);
        self.count += 1;
        self.pieces += pieces;
        self.worst = self.worst.max(deviation);
        if self.examples.len() < SPLIT_EXAMPLES {
            self.examples.push(origin.to_string());
        }
    }

    /// The one warning about the split polygons (`None` when none was split).
    fn warning(&self, scene: &str, tolerance: f64, objects: &[String]) -> Option<SceneWarning> {
        if self.count == 0 {
            return None;
        }
        let more = self.count - self.examples.len();
        let rest = if more > 0 {
            format!(", and {more} more")
        } else {
            String::new()
        };
        let backs = if self.back_pieces > 0 {
            format!(
                " (and their back sides, two-sided: {} more)",
                self.back_pieces
            )
        } else {
            String::new()
        };
        let message = format!(
            "{scene}: split {} non-planar polygon(s) into {} planar triangles{backs}, each a patch \
             (worst: a vertex {:.3e} of the face's size off its plane; tolerance {tolerance:e}): {}{rest}",
            self.count,
            self.pieces,
            self.worst,
            self.examples.join("; ")
        );
        let names = self.objects.iter().map(|&o| objects[o as usize].clone());
        Some(
            SceneWarning::new(SceneWarningKind::NonPlanarSplit, message)
                .about(names.collect())
                .with_numbers(&[
                    ("polygons", self.count as f64),
                    ("triangles", self.pieces as f64),
                    ("worst_deviation", self.worst),
                ]),
        )
    }
}

/// Names for a message: `a`, `b`, `c` (the first 10, then how many more).
pub(crate) fn list_names(names: &[String]) -> String {
    let shown: Vec<String> = names.iter().take(10).map(|n| format!("`{n}`")).collect();
    let more = names.len().saturating_sub(10);
    if more > 0 {
        format!("{} and {more} more", shown.join(", "))
    } else {
        shown.join(", ")
    }
}
