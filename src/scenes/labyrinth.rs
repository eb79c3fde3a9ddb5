//! `@labyrinth[:N]`: the labyrinth of the paper's figure 9 (Table 8), lit so that the radiosity is 1
//! everywhere.
//!
//! Table 8 shows that when `R_i + E_i = 1` on every patch, the radiosity is `B = 1` everywhere (in a
//! closed scene every form-factor row sums to 1, so `B = 1` solves `B = E + R F B`, eq. 2) and the
//! radiosity measures (eqs. 33-35) equal the visibility measures (eqs. 19, 17, 20). The paper gives no
//! geometry. Ours, in units of one maze cell:
//!
//! * a perfect maze (exactly one path between any two cells) of N x N cells (default 11), drawn by a
//!   depth-first search with a fixed seed, on a grid of (2N + 1) x (2N + 1) unit squares: cells and the
//!   openings between them are corridors, everything else (the border included) is a wall block 1 high;
//! * the maze stands in a hall that closes the scene: a ceiling at height 2 and, above the border blocks,
//!   four walls from height 1 to 2;
//! * every face is cut into unit squares, one patch each: the floor of each corridor square, the top of
//!   each block, each block side that faces a corridor (4 N^2 of them in a perfect maze), the ceiling's
//!   (2N + 1)^2 squares and the hall walls' 4 (2N + 1). With N = 11: 529 + 484 + 529 + 92 = 1634 equal
//!   patches, so H_p = log2 1634 = 10.674. (Table 8's 10.6883 is log2 1650 to five digits: the paper's
//!   labyrinth may have had 1650 equal patches; no perfect maze of this kind has exactly that many.)
//!
//! Nothing is hidden: no face lies under a block or behind another, so every segment joins two visible
//! patches. Materials, all with `R + E = 1`: floor R 0.8 E 0.2, blocks 0.6 / 0.4, ceiling 0.3 / 0.7,
//! hall walls 0.5 / 0.5. So the materials differ while the radiosity does not.

use rand::RngCore;
use rand_pcg::Pcg64;

use super::parts::add_rect;
use crate::geom::shapes::Rect;
use crate::scene::{Material, Scene, SceneBuilder, SceneError};

/// Default cells per side.
pub const DEFAULT_CELLS: usize = 11;
/// Height of the wall blocks, in cells.
pub const BLOCK_HEIGHT: f64 = 1.0;
/// Height of the hall's ceiling, in cells.
pub const HALL_HEIGHT: f64 = 2.0;
/// Seed of the maze.
pub const SEED: u64 = 9;

/// The corridor squares of a perfect maze of `n` x `n` cells on a `(2n + 1)^2` grid, indexed
/// `[x][z]`: `true` for a corridor, `false` for a wall block.
pub fn maze(n: usize) -> Vec<Vec<bool>> {
    let g = 2 * n + 1;
    let mut open = vec![vec![false; g]; g];
    let mut rng = Pcg64::new(u128::from(SEED), n as u128);
    let mut visited = vec![vec![false; n]; n];
    let mut stack = vec![(0usize, 0usize)];
    visited[0][0] = true;
    open[1][1] = true;
    // Depth-first search: from the newest cell, go to a random unvisited neighbour, opening the square
    // between them; back up when there is none.
    while let Some(&(i, j)) = stack.last() {
        let next: Vec<(usize, usize)> = neighbours(i, j, n)
            .into_iter()
            .filter(|&(a, b)| !visited[a][b])
            .collect();
        if next.is_empty() {
            stack.pop();
            continue;
        }
        let (a, b) = next[(rng.next_u64() % next.len() as u64) as usize];
        visited[a][b] = true;
        open[2 * a + 1][2 * b + 1] = true;
        open[i + a + 1][j + b + 1] = true;
        stack.push((a, b));
    }
    open
}

fn neighbours(i: usize, j: usize, n: usize) -> Vec<(usize, usize)> {
    let mut v = Vec::with_capacity(4);
    if i > 0 {
        v.push((i - 1, j));
    }
    if i + 1 < n {
        v.push((i + 1, j));
    }
    if j > 0 {
        v.push((i, j - 1));
    }
    if j + 1 < n {
        v.push((i, j + 1));
    }
    v
}

/// The number of patches of `@labyrinth:n`: `2 (2n + 1)^2 + 4 n^2 + 4 (2n + 1)`, all unit squares.
pub fn patch_count(n: usize) -> usize {
    let g = 2 * n + 1;
    2 * g * g + 4 * n * n + 4 * g
}

/// `@labyrinth:n` (see the module documentation).
pub fn build(spec: &str, n: usize) -> Result<Scene, SceneError> {
    let open = maze(n);
    let g = open.len();
    let gf = g as f64;
    let mut b = SceneBuilder::new(spec);
    let mut material = |name: &str, r: f64| b.material(Material::grey(name, r, 1.0 - r));
    let (floor, block, ceiling, hall) = (
        material("floor", 0.8),
        material("block", 0.6),
        material("ceiling", 0.3),
        material("hall", 0.5),
    );
    let unit = |axis: usize, level: f64, lo: [f64; 2], positive: bool| Rect {
        axis,
        level,
        lo,
        hi: [lo[0] + 1.0, lo[1] + 1.0],
        positive,
    };
    for x in 0..g {
        for z in 0..g {
            let (xf, zf) = (x as f64, z as f64);
            // Axis y spans (z, x).
            if open[x][z] {
                add_rect(
                    &mut b,
                    &unit(1, 0.0, [zf, xf], true),
                    (1, 1),
                    floor,
                    "floor",
                );
                continue;
            }
            add_rect(
                &mut b,
                &unit(1, BLOCK_HEIGHT, [zf, xf], true),
                (1, 1),
                block,
                "block top",
            );
            let is_open = |dx: isize, dz: isize| {
                let (a, c) = (x as isize + dx, z as isize + dz);
                (0..g as isize).contains(&a)
                    && (0..g as isize).contains(&c)
                    && open[a as usize][c as usize]
            };
            // Axis x spans (y, z); axis z spans (x, y).
            let sides = [
                (is_open(-1, 0), unit(0, xf, [0.0, zf], false)),
                (is_open(1, 0), unit(0, xf + 1.0, [0.0, zf], true)),
                (is_open(0, -1), unit(2, zf, [xf, 0.0], false)),
                (is_open(0, 1), unit(2, zf + 1.0, [xf, 0.0], true)),
            ];
            for (_, r) in sides.iter().filter(|(o, _)| *o) {
                add_rect(&mut b, r, (1, 1), block, "block side");
            }
        }
    }
    let lid = Rect {
        axis: 1,
        level: HALL_HEIGHT,
        lo: [0.0, 0.0],
        hi: [gf, gf],
        positive: false,
    };
    add_rect(&mut b, &lid, (g, g), ceiling, "ceiling");
    let (y0, y1) = (BLOCK_HEIGHT, HALL_HEIGHT);
    for (axis, level, positive) in [
        (0, 0.0, true),
        (0, gf, false),
        (2, 0.0, true),
        (2, gf, false),
    ] {
        // Axis x spans (y, z): one row of g squares; axis z spans (x, y): one column.
        let (lo, hi, grid) = if axis == 0 {
            ([y0, 0.0], [y1, gf], (1, g))
        } else {
            ([0.0, y0], [gf, y1], (g, 1))
        };
        let r = Rect {
            axis,
            level,
            lo,
            hi,
            positive,
        };
        add_rect(&mut b, &r, grid, hall, "hall wall");
    }
    b.build()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A perfect maze: every cell reachable, and as many openings as a spanning tree has edges.
    #[test]
    fn the_maze_is_perfect() {
        for n in [1, 2, 5, 11] {
            let open = maze(n);
            let g = 2 * n + 1;
            let corridors = open.iter().flatten().filter(|&&o| o).count();
            assert_eq!(corridors, 2 * n * n - 1, "n = {n}");
            // Flood fill from the first cell reaches every corridor square.
            let mut seen = vec![vec![false; g]; g];
            let mut todo = vec![(1usize, 1usize)];
            seen[1][1] = true;
            let mut reached = 0;
            while let Some((x, z)) = todo.pop() {
                reached += 1;
                for (a, c) in [(x - 1, z), (x + 1, z), (x, z - 1), (x, z + 1)] {
                    if open[a][c] && !seen[a][c] {
                        seen[a][c] = true;
                        todo.push((a, c));
                    }
                }
            }
            assert_eq!(reached, corridors, "n = {n}");
            // The border is all wall.
            assert!(
                (0..g).all(|k| !open[0][k] && !open[g - 1][k] && !open[k][0] && !open[k][g - 1])
            );
        }
    }
}
