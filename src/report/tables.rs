//! The per-patch and per-object tables (`--patches FILE.csv`, `--objects FILE.csv`): named columns, one
//! row per patch or object, each quantity of the per-patch catalogue followed by its standard error.

use crate::analysis::object_results::ENVIRONMENT;
use crate::analysis::{Analysis, PatchResult};
use crate::geom::{Normal, Point};
use crate::measure::catalogue::PatchMeasure;
use crate::measure::Estimate;
use crate::scene::Scene;

/// A table of named columns of equal length.
#[derive(Clone, Debug, Default)]
pub struct Table {
    /// The columns, in the order the files write them.
    pub columns: Vec<Column>,
}

/// One named column of a [`Table`].
#[derive(Clone, Debug)]
pub struct Column {
    /// Its name (the CSV header's; docs/per-patch.md lists them with their units).
    pub name: String,
    /// Its values.
    pub values: Values,
}

/// The values of a column.
#[derive(Clone, Debug)]
pub enum Values {
    /// Counts (`None`: not counted in this run).
    Integers(Vec<Option<u64>>),
    /// Numbers (`None`: not computed, or not a finite number).
    Numbers(Vec<Option<f64>>),
    /// Yes or no.
    Flags(Vec<bool>),
    /// Names, as indices into a list of distinct names (a categorical column: a patch's object and
    /// material repeat over many rows).
    Labels {
        /// The distinct names.
        names: Vec<String>,
        /// Per row, the index of its name in `names`.
        codes: Vec<u32>,
    },
}

impl Values {
    /// The number of rows.
    pub fn len(&self) -> usize {
        match self {
            Values::Integers(v) => v.len(),
            Values::Numbers(v) => v.len(),
            Values::Flags(v) => v.len(),
            Values::Labels { codes, .. } => codes.len(),
        }
    }

    /// Whether the column has no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Row `row` as the CSV files write it: numbers in Rust's shortest round-trip form (`-0` as `0`),
    /// empty when there is no value.
    pub fn text(&self, row: usize) -> String {
        match self {
            Values::Integers(v) => v[row].map(|x| x.to_string()).unwrap_or_default(),
            Values::Numbers(v) => v[row].map(|x| format!("{}", x + 0.0)).unwrap_or_default(),
            Values::Flags(v) => v[row].to_string(),
            Values::Labels { names, codes } => names[codes[row] as usize].clone(),
        }
    }
}

impl Table {
    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |c| c.values.len())
    }

    /// The column names, in order.
    pub fn header(&self) -> Vec<&str> {
        self.columns.iter().map(|c| c.name.as_str()).collect()
    }

    /// Row `row`'s cells as the CSV files write them.
    pub fn row_text(&self, row: usize) -> Vec<String> {
        self.columns.iter().map(|c| c.values.text(row)).collect()
    }

    /// The column named `name`.
    pub fn column(&self, name: &str) -> Option<&Column> {
        self.columns.iter().find(|c| c.name == name)
    }

    fn push(&mut self, name: &str, values: Values) {
        self.columns.push(Column {
            name: name.to_string(),
            values,
        });
    }

    /// Each quantity of the per-patch catalogue and its standard error, from `get` per row.
    fn push_catalogue(
        &mut self,
        rows: usize,
        get: impl Fn(usize, PatchMeasure) -> Option<Estimate>,
    ) {
        for q in PatchMeasure::ALL {
            let name = q.info().column;
            let values = (0..rows).map(|r| get(r, q).map(|e| e.value)).collect();
            let errors = (0..rows)
                .map(|r| get(r, q).and_then(|e| e.stderr))
                .collect();
            self.push(name, Values::Numbers(values));
            self.push(&format!("{name}_stderr"), Values::Numbers(errors));
        }
    }
}

/// The per-patch table (`--patches`): id (the order `scx export` writes faces), object, material,
/// area, centroid and normal in the scene's units and frame, area fraction, segments `N_i`, escapes,
/// absorbed segments, whether sampled, then each per-patch quantity (the patch's row entropy and its
/// terms of I_s (eq. 21) and I_s^c (eq. 27), the information it loses, radiosities) with its standard
/// error. The per-patch results of an enclosed scene have one row more, the environment's, last: id
/// `patches`, object and material [`ENVIRONMENT`], its counted area, no centroid nor normal.
pub fn patch_table(scene: &Scene, patches: &[PatchResult]) -> Table {
    let own = scene.patch_count().min(patches.len());
    // The environment's row, after the scene's patches.
    let n = patches.len().min(own + 1);
    let centroids: Vec<Point> = (0..own).map(|i| centroid(scene, i)).collect();
    let normals: Vec<Normal> = scene.patches[..own].iter().map(|p| p.normal).collect();
    let geometry = |f: &dyn Fn(usize) -> f64| {
        Values::Numbers((0..n).map(|i| (i < own).then(|| f(i))).collect())
    };
    let number = |f: &dyn Fn(&PatchResult) -> f64| {
        Values::Numbers(patches[..n].iter().map(|p| Some(f(p))).collect())
    };
    let count = |f: &dyn Fn(&PatchResult) -> u64| {
        Values::Integers(patches[..n].iter().map(|p| Some(f(p))).collect())
    };
    let labels = |names: Vec<String>, code: &dyn Fn(usize) -> u32| {
        let mut names = names;
        let environment = names.len() as u32;
        if n > own {
            names.push(ENVIRONMENT.to_string());
        }
        let codes = (0..n)
            .map(|i| if i < own { code(i) } else { environment })
            .collect();
        Values::Labels { names, codes }
    };
    let mut t = Table::default();
    t.push("id", Values::Integers((0..n as u64).map(Some).collect()));
    t.push(
        "object",
        labels(scene.objects.clone(), &|i| scene.patches[i].object),
    );
    t.push(
        "material",
        labels(
            scene.materials.iter().map(|m| m.name.clone()).collect(),
            &|i| scene.patches[i].material,
        ),
    );
    t.push("area", number(&|p| p.area));
    t.push("centroid_x", geometry(&|i| centroids[i].x));
    t.push("centroid_y", geometry(&|i| centroids[i].y));
    t.push("centroid_z", geometry(&|i| centroids[i].z));
    t.push("normal_x", geometry(&|i| normals[i].x));
    t.push("normal_y", geometry(&|i| normals[i].y));
    t.push("normal_z", geometry(&|i| normals[i].z));
    t.push("area_fraction", number(&|p| p.area_fraction));
    t.push("segments", count(&|p| p.segments));
    t.push("escapes", count(&|p| p.escapes));
    t.push("absorbed", count(&|p| p.absorbed));
    t.push(
        "sampled",
        Values::Flags(patches[..n].iter().map(PatchResult::sampled).collect()),
    );
    t.push_catalogue(n, |i, q| patches[i].get(q));
    t
}

/// The per-object table (`--objects`): name, patches, triangles, area, area fraction, segments,
/// escapes, escape fraction, absorbed segments, how lines met its sides, then its share of each
/// per-patch quantity with its standard error ([`crate::ObjectResult::get`]).
pub fn object_table(a: &Analysis) -> Table {
    let objects = &a.objects;
    let n = objects.len();
    let mut t = Table::default();
    t.push(
        "object",
        Values::Labels {
            names: objects.iter().map(|o| o.name.clone()).collect(),
            codes: (0..n as u32).collect(),
        },
    );
    let int = |f: &dyn Fn(usize) -> Option<u64>| Values::Integers((0..n).map(f).collect());
    let num = |f: &dyn Fn(usize) -> Option<f64>| Values::Numbers((0..n).map(f).collect());
    t.push("patches", int(&|i| Some(objects[i].patches as u64)));
    t.push("triangles", int(&|i| Some(objects[i].triangles as u64)));
    t.push("area", num(&|i| Some(objects[i].area)));
    t.push("area_fraction", num(&|i| Some(objects[i].area_fraction)));
    t.push("segments", int(&|i| objects[i].segments));
    t.push("escapes", int(&|i| objects[i].escapes));
    t.push("escape_fraction", num(&|i| objects[i].escape_fraction()));
    t.push("absorbed", int(&|i| objects[i].absorbed));
    t.push(
        "front_sides_to_open_space",
        int(&|i| Some(objects[i].sides.front_open)),
    );
    t.push(
        "back_sides_seen_from_fronts",
        int(&|i| Some(objects[i].sides.back_seen)),
    );
    t.push(
        "back_sides_from_open_space",
        int(&|i| Some(objects[i].sides.back_from_open)),
    );
    t.push(
        "back_sides_to_open_space",
        int(&|i| Some(objects[i].sides.back_to_open)),
    );
    t.push_catalogue(n, |i, q| objects[i].get(q));
    t
}

/// The area-weighted centroid of a patch's triangles, in the scene's own units and frame.
fn centroid(scene: &Scene, patch: usize) -> Point {
    let p = &scene.patches[patch];
    let first = p.first_triangle as usize;
    let (mut sum, mut weight) = (Point::ZERO, 0.0);
    for t in &scene.triangles[first..first + p.triangle_count as usize] {
        let [a, b, c] = t.map(|v| scene.vertices[v as usize]);
        let area = 0.5 * (b - a).cross(c - a).length();
        sum += area * (a + b + c) / 3.0;
        weight += area;
    }
    if weight > 0.0 {
        sum / weight
    } else {
        scene.vertices[scene.triangles[first][0] as usize]
    }
}
