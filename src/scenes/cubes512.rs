//! `@cubes512`: a room full of occluders, for benchmarks and for measures of a scene where most lines
//! cross several surfaces.
//!
//! The room is the unit cube enclosure (one patch per wall, normals inwards). It is cut into an 8 x 8 x 8
//! grid of cells of side 1/8; each cell holds one axis-aligned cube of side 1/16 (one patch per face,
//! normals outwards) at a uniformly random position inside the cell, at least 1/128 from the cell's
//! walls. So the cubes never overlap or touch each other or the room (gaps of at least 1/64 between
//! neighbours and 1/128 to the walls), and every line crossing the room meets a handful of them.
//! The positions come from PCG-64 with a fixed seed: the scene is the same on every machine and version.
//!
//! 6 + 512 * 6 = 3078 patches (more than the 2048 patches whose counts are dense, so its pair counts
//! use the sparse layout), 6156 triangles.

use rand_pcg::Pcg64;

use super::parts::grey_wall;
use crate::geom::{uniform01, DVec3, Point};
use crate::scene::{Scene, SceneBuilder, SceneError};

/// Cells along each axis.
pub const CELLS: usize = 8;
/// Side of a small cube, room units.
pub const CUBE_SIDE: f64 = 1.0 / 16.0;
/// Least distance from a small cube to the walls of its cell.
pub const CELL_GAP: f64 = 1.0 / 128.0;
/// The seed of the cube positions.
pub const SEED: u64 = 512;

/// The corner of a box (bits: x = 1, y = 2, z = 4).
fn corner(lo: Point, hi: Point, bits: usize) -> Point {
    DVec3::from_array([0, 1, 2].map(|a| if bits & (1 << a) == 0 { lo[a] } else { hi[a] }))
}

/// The faces of this scene's boxes as corner-bit quads, counter-clockwise seen from outside. Their
/// first corners differ from [`crate::geom::shapes::box_faces`]'s, and so do the diagonals their
/// triangles share: the scene keeps the faces it was first published with, so that its numbers stay.
const BOX_FACES: [[usize; 4]; 6] = [
    [0, 4, 6, 2], // x = lo
    [1, 3, 7, 5], // x = hi
    [0, 1, 5, 4], // y = lo
    [2, 6, 7, 3], // y = hi
    [0, 2, 3, 1], // z = lo
    [4, 5, 7, 6], // z = hi
];

/// Adds a box as six patches, facing out (`inward == false`) or in.
fn add_box(b: &mut SceneBuilder, lo: Point, hi: Point, inward: bool, m: u32, name: &str) {
    for (f, quad) in BOX_FACES.iter().enumerate() {
        let mut idx: Vec<u32> = quad.iter().map(|&c| b.vertex(corner(lo, hi, c))).collect();
        if inward {
            idx.reverse();
        }
        b.polygon(&idx, m, format!("{name} face {f}"));
    }
}

/// The lower corners of the 512 small cubes, cell by cell (x fastest, then y, then z).
pub fn cube_corners() -> Vec<Point> {
    let mut rng = Pcg64::new(u128::from(SEED), 0xc1u128);
    let cell = 1.0 / CELLS as f64;
    let slack = cell - CUBE_SIDE - 2.0 * CELL_GAP;
    let mut corners = Vec::with_capacity(CELLS.pow(3));
    for k in 0..CELLS {
        for j in 0..CELLS {
            for i in 0..CELLS {
                let cell_lo = [i, j, k].map(|c| c as f64 * cell);
                corners.push(DVec3::from_array(
                    cell_lo.map(|c| c + CELL_GAP + slack * uniform01(&mut rng)),
                ));
            }
        }
    }
    corners
}

/// `@cubes512`: the unit room holding 512 small cubes (see the module documentation). It takes no
/// parameter (`param` must be `None`).
pub fn cubes512(spec: &str, param: Option<&str>) -> Result<Scene, SceneError> {
    if let Some(p) = param {
        return Err(SceneError::Builtin(format!(
            "{spec}: @cubes512 takes no parameter, not `{p}`"
        )));
    }
    let mut b = SceneBuilder::new(spec);
    let m = grey_wall(&mut b);
    add_box(&mut b, DVec3::ZERO, DVec3::ONE, true, m, "room");
    for (n, lo) in cube_corners().into_iter().enumerate() {
        let hi = lo + CUBE_SIDE;
        add_box(&mut b, lo, hi, false, m, &format!("cube {n}"));
    }
    b.build()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cubes_stay_inside_their_cells_with_gaps() {
        let cell = 1.0 / CELLS as f64;
        for (n, lo) in cube_corners().iter().enumerate() {
            let idx = [n % CELLS, (n / CELLS) % CELLS, n / (CELLS * CELLS)];
            for a in 0..3 {
                let cell_lo = idx[a] as f64 * cell;
                assert!(lo[a] >= cell_lo + CELL_GAP - 1e-15, "cube {n}");
                assert!(
                    lo[a] + CUBE_SIDE <= cell_lo + cell - CELL_GAP + 1e-15,
                    "cube {n}"
                );
            }
        }
    }

    #[test]
    fn counts_and_facing() {
        let s = cubes512("@cubes512", None).unwrap();
        let e = cubes512("@cubes512:3", Some("3")).unwrap_err().to_string();
        assert!(
            e.starts_with("@cubes512:3") && e.contains("no parameter"),
            "{e}"
        );
        assert_eq!(s.patch_count(), 6 + 512 * 6);
        assert_eq!(s.triangles.len(), 2 * s.patch_count());
        // Area: room 6, each small cube 6 / 256, in room units squared.
        let expected = 6.0 + 512.0 * 6.0 * CUBE_SIDE * CUBE_SIDE;
        assert!((s.total_area_scene_units() - expected).abs() < 1e-9);
        // The room faces inwards (the room's centre in front of each wall), the cubes outwards (each
        // cube's centre behind its faces).
        let corners = cube_corners();
        for (k, p) in s.patches.iter().enumerate() {
            let centre = if k < 6 {
                DVec3::splat(0.5)
            } else {
                corners[(k - 6) / 6] + CUBE_SIDE / 2.0
            };
            let v = s.vertices[s.triangles[p.first_triangle as usize][0] as usize];
            let side = p.normal.dot(centre - v);
            assert_eq!(side > 0.0, k < 6, "patch {k}");
        }
    }
}
