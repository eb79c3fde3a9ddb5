//! `@fig5:S` and `@fig6:S`: the cube lattices of the paper's figures 5 and 6 (Tables 6 and 7), 64
//! cubes on a 4 x 4 x 4 lattice in the unit cube enclosure, from clustered to spread to the walls.
//!
//! The paper gives each scene's description and patch counts but not its coordinates; the choices below
//! match every number the paper does give (Tables 1, 3, 6 and 7) and are documented where made. Every
//! room is the unit cube (normals inwards), every small cube is axis-aligned (normals outwards), and
//! nothing touches: every line segment in the room joins two visible patches. Material: the grey `wall`
//! of the other built-ins (R = 0.5, no light).
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

use super::parts::{add_box, grey_wall, lattice};
use crate::geom::shapes::Facing;
use crate::geom::{DVec3, Point};
use crate::scene::{Scene, SceneBuilder, SceneError};

/// Side of a Fig. 5/6 cube, room units.
pub const FIG5_SIDE: f64 = 1.0 / 8.0;
/// Gap between neighbouring Fig. 5/6 cubes at stage `a`.
pub const FIG5_GAP_CLUSTERED: f64 = FIG5_SIDE / 10.0;
/// Gap between the outer Fig. 5/6 cubes and the walls at stage `f`.
pub const FIG5_GAP_WALLS: f64 = FIG5_SIDE / 8.0;

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
    let m = grey_wall(&mut b);
    add_box(
        &mut b,
        DVec3::ZERO,
        DVec3::ONE,
        Facing::In,
        wall_grid,
        m,
        "room",
    );
    for (k, lo) in fig56_corners(t).into_iter().enumerate() {
        let hi = lo + FIG5_SIDE;
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
pub fn fig56_corners(t: f64) -> Vec<Point> {
    let pitch = fig56_pitch(t);
    let first = 0.5 - 1.5 * pitch - FIG5_SIDE / 2.0;
    lattice(DVec3::splat(first), 4, pitch)
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
