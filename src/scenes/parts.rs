//! The parts the built-in rooms are made of: the grey material of every built-in without light,
//! axis-aligned rectangles cut into patches ([`Rect`]), boxes of six of them, and lattices of boxes.

use crate::geom::shapes::{box_faces, Facing, Rect};
use crate::geom::{DVec3, Point};
use crate::scene::{Material, SceneBuilder};

/// Adds the grey `wall` material of the built-ins without light (R = 0.5, no emission).
pub(crate) fn grey_wall(b: &mut SceneBuilder) -> u32 {
    b.material(Material::grey("wall", 0.5, 0.0))
}

/// Adds a rectangle cut into `grid.0 x grid.1` equal patches.
pub(crate) fn add_rect(b: &mut SceneBuilder, r: &Rect, grid: (usize, usize), m: u32, name: &str) {
    for cell in r.grid(grid) {
        let idx = cell.corners.map(|p| b.vertex(p));
        b.polygon(
            &idx,
            m,
            format!("{name} axis {} patch ({}, {})", r.axis, cell.i, cell.j),
        );
    }
}

/// Adds an axis-aligned box, each face cut into `grid` x `grid` patches.
pub(crate) fn add_box(
    b: &mut SceneBuilder,
    lo: Point,
    hi: Point,
    facing: Facing,
    grid: usize,
    m: u32,
    name: &str,
) {
    for face in box_faces(lo, hi, facing) {
        add_rect(b, &face, (grid, grid), m, name);
    }
}

/// The lower corners of a c x c x c lattice of cubes from `origin`, `pitch` apart.
pub(crate) fn lattice(origin: Point, c: usize, pitch: f64) -> Vec<Point> {
    let mut v = Vec::with_capacity(c * c * c);
    for k in 0..c {
        for j in 0..c {
            for i in 0..c {
                let step = DVec3::new(i as f64, j as f64, k as f64);
                v.push(origin + step * pitch);
            }
        }
    }
    v
}
