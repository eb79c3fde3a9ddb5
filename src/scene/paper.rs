//! The cube rooms of the paper's figures 2, 5 and 6: small cubes in the unit cube enclosure.
//!
//! The paper gives each scene's description and patch counts but not its coordinates; the choices below
//! match every number the paper does give (Tables 1, 3, 6 and 7) and are documented where made. Every
//! room is the unit cube (normals inwards), every small cube is axis-aligned (normals outwards), and
//! nothing touches: every line segment in the room joins two visible patches. Material: the grey `wall`
//! of the other built-ins (R = 0.5, no light).
//!
//! **Fig. 2** (`@fig2:a|b|c`, Tables 1 and 3): 512 cubes of side 1/20.
//!
//! * Discretisation: each room wall cut into 10 x 10 patches, each cube face one patch: 600 + 3072 =
//!   3672 patches of areas 1/100 and 1/400, so `H_p = 11.5407` (Table 1: 11.541), the same for the three
//!   placements. [`fig2_positional_entropy`] gives the closed form. Of the cube sides 1/8 .. 1/64, wall
//!   grids up to 40 x 40 and cube faces cut up to 4 x 4, two choices round to 11.541: this one and side
//!   1/56 with 14 x 14 walls and 4 x 4 faces. Only side 1/20 also gives Table 3's continuous mutual
//!   information (I_s^c = 5.63 against 5.632; side 1/16 gives 6.94, side 1/25 already 4.57).
//! * `a` (random): the room cut into 8 x 8 x 8 cells of side 1/8; each cube at a uniformly random
//!   position in its cell, at least 1/128 from the cell's walls (as `@cubes512`, with smaller cubes).
//! * `b`, `c` (progressively clustered): the cells grouped into blocks of 2 x 2 x 2 (`b`: 64 clusters of
//!   8 cubes) or 4 x 4 x 4 (`c`: 8 clusters of 64 cubes); a block's cubes form a lattice with gaps of
//!   1/10 of a side between neighbours ([`FIG2_CLUSTER_GAP`]), placed at a uniformly random position in
//!   the block, at least 1/128 from its walls. The paper gives no rule; of the few we tried (gaps of a
//!   fifth to a twentieth of a side, clusters centred or at random) this one brings `c` within 0.08 of
//!   Table 1's H_s and I_s and `b` within 0.25 (we read higher H_s there).
//!
//! Positions come from PCG-64 with fixed seeds: the scenes are the same on every machine and version.
//!
//! **Figs. 5 and 6** (`@fig5:S`, `@fig6:S`, Tables 6 and 7): 64 cubes of side 1/8 on a 4 x 4 x 4 lattice
//! centred in the room, at six stages `a`..`f` of the lattice pitch, linear from "grouped very closely
//! together in the center" (stage `a`: gaps of 1/10 of a side between neighbouring cubes) to "almost
//! touch the walls" (stage `f`: the outer faces 1/8 of a side from the walls). The two gaps were chosen so
//! that I_s^c at stages `a` and `f` is Table 6's (6.43 and 6.06; I_s^c depends on the geometry only,
//! not on the patches), not by the accuracies of Tables 6 and 7 (a first guess, both gaps 1/64, tied
//! the accuracies of fig. 5's stages a and e); side 1/8 (of 1/10, 1/8 and 3/20) is the closest to Table
//! 6's I_s^c at the middle stages. With side 1/8 the cubes and the walls both have area 6, so the two
//! discretisations have the same H_p. `@fig5` cuts every cube face into 2 x 2 patches and every wall into
//! 8 x 8 (1536 + 384 patches, "the discretisation of the cubes is finer"); `@fig6` cuts cube faces into 1
//! and walls into 16 x 16 (384 + 1536, "the discretisation of the walls is finer"). The stage may also be
//! a number t in [0, 1] (`@fig5:0.5`): the pitch at fraction t of the way from `a` (t = 0) to `f`
//! (t = 1); stage `a`..`f` is t = 0, 0.2, .., 1.

use rand::RngCore;
use rand_pcg::Pcg64;

use super::{Material, Scene, SceneBuilder, SceneError};

/// Side of a Fig. 2 cube, room units.
pub const FIG2_SIDE: f64 = 1.0 / 20.0;
/// Patches per side of a Fig. 2 room wall.
pub const FIG2_WALL_GRID: usize = 10;
/// Gap between neighbouring cubes of a Fig. 2 cluster.
pub const FIG2_CLUSTER_GAP: f64 = FIG2_SIDE / 10.0;
/// Least distance from a Fig. 2 cube or cluster to the walls of its cell or block.
pub const FIG2_MARGIN: f64 = 1.0 / 128.0;
/// Seed of the Fig. 2 positions (one stream per placement).
pub const FIG2_SEED: u64 = 1999;

/// Side of a Fig. 5/6 cube, room units.
pub const FIG5_SIDE: f64 = 1.0 / 8.0;
/// Gap between neighbouring Fig. 5/6 cubes at stage `a`.
pub const FIG5_GAP_CLUSTERED: f64 = FIG5_SIDE / 10.0;
/// Gap between the outer Fig. 5/6 cubes and the walls at stage `f`.
pub const FIG5_GAP_WALLS: f64 = FIG5_SIDE / 8.0;

/// The Fig. 2 placements.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fig2Placement {
    /// One cube at a random place in each of the 8^3 cells (Fig. 2a).
    Random,
    /// 64 clusters of 2 x 2 x 2 cubes (Fig. 2b).
    Clusters8,
    /// 8 clusters of 4 x 4 x 4 cubes (Fig. 2c).
    Clusters64,
}

impl Fig2Placement {
    /// Cubes along a cluster's side.
    fn cluster_side(self) -> usize {
        match self {
            Fig2Placement::Random => 1,
            Fig2Placement::Clusters8 => 2,
            Fig2Placement::Clusters64 => 4,
        }
    }

    fn from_param(spec: &str, param: Option<&str>) -> Result<Self, SceneError> {
        match param {
            Some("a") => Ok(Fig2Placement::Random),
            Some("b") => Ok(Fig2Placement::Clusters8),
            Some("c") => Ok(Fig2Placement::Clusters64),
            _ => Err(SceneError::Builtin(format!(
                "{spec}: @fig2 needs a placement: a (random), b (64 clusters of 8) or c (8 clusters of 64)"
            ))),
        }
    }
}

/// The exact positional entropy (eq. 19) of every Fig. 2 scene: 600 wall patches of area 1/100 and 3072
/// cube faces of area 1/400 (= 11.5407; Table 1 gives 11.541).
pub fn fig2_positional_entropy() -> f64 {
    let walls = 6.0 * (FIG2_WALL_GRID * FIG2_WALL_GRID) as f64;
    let wall_area = 1.0 / (FIG2_WALL_GRID * FIG2_WALL_GRID) as f64;
    let faces = 512.0 * 6.0;
    let face_area = FIG2_SIDE * FIG2_SIDE;
    let total = walls * wall_area + faces * face_area;
    let term = |count: f64, area: f64| -count * (area / total) * (area / total).log2();
    term(walls, wall_area) + term(faces, face_area)
}

/// `@fig2:a|b|c`: the room with 512 cubes of Fig. 2 (see the module documentation).
pub fn fig2(spec: &str, param: Option<&str>) -> Result<Scene, SceneError> {
    let placement = Fig2Placement::from_param(spec, param)?;
    let mut b = SceneBuilder::new(spec);
    let m = grey(&mut b);
    add_box(
        &mut b,
        [0.0; 3],
        [1.0; 3],
        Facing::In,
        FIG2_WALL_GRID,
        m,
        "room",
    );
    for (k, lo) in fig2_corners(placement).into_iter().enumerate() {
        let hi = lo.map(|c| c + FIG2_SIDE);
        add_box(&mut b, lo, hi, Facing::Out, 1, m, &format!("cube {k}"));
    }
    b.build()
}

/// The lower corners of the 512 Fig. 2 cubes, cluster by cluster.
pub fn fig2_corners(placement: Fig2Placement) -> Vec<[f64; 3]> {
    let c = placement.cluster_side();
    let blocks = 8 / c;
    let block = 1.0 / blocks as f64;
    let span = c as f64 * FIG2_SIDE + (c - 1) as f64 * FIG2_CLUSTER_GAP;
    let slack = block - span - 2.0 * FIG2_MARGIN;
    let mut rng = Pcg64::new(u128::from(FIG2_SEED), c as u128);
    let mut corners = Vec::with_capacity(512);
    for bz in 0..blocks {
        for by in 0..blocks {
            for bx in 0..blocks {
                let origin =
                    [bx, by, bz].map(|i| i as f64 * block + FIG2_MARGIN + slack * unit(&mut rng));
                corners.extend(lattice(origin, c, FIG2_SIDE + FIG2_CLUSTER_GAP));
            }
        }
    }
    corners
}

/// The lower corners of a c x c x c lattice of cubes from `origin`, `pitch` apart.
fn lattice(origin: [f64; 3], c: usize, pitch: f64) -> Vec<[f64; 3]> {
    let mut v = Vec::with_capacity(c * c * c);
    for k in 0..c {
        for j in 0..c {
            for i in 0..c {
                let step = [i, j, k];
                v.push([0, 1, 2].map(|a| origin[a] + step[a] as f64 * pitch));
            }
        }
    }
    v
}

/// The two discretisations of Figs. 5 and 6.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fig56Mesh {
    /// Fig. 5: cube faces 2 x 2, walls 8 x 8 (1536 + 384 patches).
    CubesFiner,
    /// Fig. 6: cube faces 1 x 1, walls 16 x 16 (384 + 1536 patches).
    WallsFiner,
}

impl Fig56Mesh {
    /// Patches per side of a cube face and of a wall.
    pub fn grids(self) -> (usize, usize) {
        match self {
            Fig56Mesh::CubesFiner => (2, 8),
            Fig56Mesh::WallsFiner => (1, 16),
        }
    }
}

/// The lattice pitch (distance between neighbouring cube centres) of Figs. 5/6 at fraction `t` of the
/// way from stage `a` (t = 0) to stage `f` (t = 1).
pub fn fig56_pitch(t: f64) -> f64 {
    let clustered = FIG5_SIDE + FIG5_GAP_CLUSTERED;
    let spread = (1.0 - FIG5_SIDE - 2.0 * FIG5_GAP_WALLS) / 3.0;
    clustered + t * (spread - clustered)
}

/// Reads a Fig. 5/6 stage: a letter `a`..`f` or a number in [0, 1].
fn fig56_stage(spec: &str, param: Option<&str>) -> Result<f64, SceneError> {
    let bad = || {
        SceneError::Builtin(format!(
            "{spec}: the stage must be a letter a..f or a number from 0 (a) to 1 (f)"
        ))
    };
    let p = param.ok_or_else(bad)?;
    if let Some(k) = "abcdef".find(p).filter(|_| p.len() == 1) {
        return Ok(k as f64 / 5.0);
    }
    match p.parse::<f64>() {
        Ok(t) if (0.0..=1.0).contains(&t) => Ok(t),
        _ => Err(bad()),
    }
}

/// `@fig5:S` and `@fig6:S`: 64 cubes at stage S in the unit room (see the module documentation).
pub fn fig56(spec: &str, param: Option<&str>, mesh: Fig56Mesh) -> Result<Scene, SceneError> {
    let t = fig56_stage(spec, param)?;
    let (cube_grid, wall_grid) = mesh.grids();
    let mut b = SceneBuilder::new(spec);
    let m = grey(&mut b);
    add_box(&mut b, [0.0; 3], [1.0; 3], Facing::In, wall_grid, m, "room");
    for (k, lo) in fig56_corners(t).into_iter().enumerate() {
        let hi = lo.map(|c| c + FIG5_SIDE);
        add_box(
            &mut b,
            lo,
            hi,
            Facing::Out,
            cube_grid,
            m,
            &format!("cube {k}"),
        );
    }
    b.build()
}

/// The lower corners of the 64 cubes of Figs. 5/6 at fraction `t` from stage `a` to stage `f`.
pub fn fig56_corners(t: f64) -> Vec<[f64; 3]> {
    let pitch = fig56_pitch(t);
    let first = 0.5 - 1.5 * pitch - FIG5_SIDE / 2.0;
    lattice([first; 3], 4, pitch)
}

/// The grey material of the cube rooms.
fn grey(b: &mut SceneBuilder) -> u32 {
    b.material(Material {
        name: "wall".into(),
        emission: 0.0,
        reflectance: 0.5,
    })
}

/// A uniform double in [0, 1).
fn unit(rng: &mut Pcg64) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// Which way a box's faces look.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Facing {
    /// Outwards (a solid).
    Out,
    /// Inwards (an enclosure).
    In,
}

/// Adds an axis-aligned box, each face cut into `grid` x `grid` patches.
pub(crate) fn add_box(
    b: &mut SceneBuilder,
    lo: [f64; 3],
    hi: [f64; 3],
    facing: Facing,
    grid: usize,
    m: u32,
    name: &str,
) {
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for (level, outward_positive) in [(lo[axis], false), (hi[axis], true)] {
            let rect = Rect {
                axis,
                level,
                lo: [lo[u], lo[v]],
                hi: [hi[u], hi[v]],
                positive: outward_positive == (facing == Facing::Out),
            };
            add_rect(b, &rect, (grid, grid), m, name);
        }
    }
}

/// An axis-aligned rectangle: `x[axis] = level`, spanning `lo..hi` on the next two axes in cyclic order
/// (`(axis + 1) % 3`, `(axis + 2) % 3`), its front towards `+axis` when `positive`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rect {
    pub axis: usize,
    pub level: f64,
    pub lo: [f64; 2],
    pub hi: [f64; 2],
    pub positive: bool,
}

/// Adds a rectangle cut into `grid.0 x grid.1` equal patches.
pub(crate) fn add_rect(b: &mut SceneBuilder, r: &Rect, grid: (usize, usize), m: u32, name: &str) {
    let (u, v) = ((r.axis + 1) % 3, (r.axis + 2) % 3);
    let point = |i: usize, j: usize| {
        let mut p = [0.0; 3];
        p[r.axis] = r.level;
        p[u] = r.lo[0] + (r.hi[0] - r.lo[0]) * i as f64 / grid.0 as f64;
        p[v] = r.lo[1] + (r.hi[1] - r.lo[1]) * j as f64 / grid.1 as f64;
        p
    };
    for i in 0..grid.0 {
        for j in 0..grid.1 {
            // (u, v, axis) is right-handed, so this order is counter-clockwise seen from +axis.
            let mut quad = [
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            ];
            if !r.positive {
                quad.reverse();
            }
            let idx = quad.map(|p| b.vertex(p));
            b.polygon(&idx, m, format!("{name} axis {} patch ({i}, {j})", r.axis));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stages_parse_and_bad_ones_are_errors() {
        assert_eq!(fig56_stage("@fig5:a", Some("a")).unwrap(), 0.0);
        assert_eq!(fig56_stage("@fig5:f", Some("f")).unwrap(), 1.0);
        assert!((fig56_stage("@fig5:c", Some("c")).unwrap() - 0.4).abs() < 1e-15);
        assert_eq!(fig56_stage("@fig5:0.5", Some("0.5")).unwrap(), 0.5);
        for bad in [
            None,
            Some("g"),
            Some("ab"),
            Some("1.5"),
            Some("-1"),
            Some(""),
        ] {
            assert!(fig56_stage("@fig5", bad).is_err(), "{bad:?}");
        }
        assert!(Fig2Placement::from_param("@fig2:d", Some("d")).is_err());
        assert!(Fig2Placement::from_param("@fig2", None).is_err());
    }

    #[test]
    fn stage_f_almost_touches_the_walls_and_stage_a_almost_touches_itself() {
        let f = fig56_corners(1.0);
        let lowest = f.iter().map(|c| c[0]).fold(f64::INFINITY, f64::min);
        assert!((lowest - FIG5_GAP_WALLS).abs() < 1e-12);
        let a = fig56_corners(0.0);
        assert!((a[1][0] - a[0][0] - FIG5_SIDE - FIG5_GAP_CLUSTERED).abs() < 1e-12);
    }
}
