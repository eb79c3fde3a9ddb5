//! The scenes of the calibration suite: built-ins whose exact values are known (`@cube:N`, the regular
//! solids) and four made here, whose exact values are known too:
//!
//! * `two-squares:parallel[:N[:D]]`: two unit squares facing each other at distance D (default 1), each
//!   cut into N x N patches: an open scene (lines escape between them);
//! * `two-squares:perpendicular[:N]`: two unit squares at a right angle sharing an edge, facing each
//!   other (the floor and a wall of a corner): open;
//! * `flipped-cube[:N]`: `@cube:N` with the face x = 0 facing out: from inside its back is seen, which
//!   absorbs what reaches it (no pair), and its front sees out of the scene;
//! * `lit-cube[:N]`: `@cube:N` with the face x = 0 emitting E = 1, every face reflecting R = 1/2: the
//!   radiosity measures of sec. 4.

use crate::scene::{Material, Scene, SceneBuilder, SceneError};
/// The regular solids of [`CalibrationScene::Solid`], re-exported so that a caller can name them (the
/// built-in scenes' module is not part of the public API).
pub use crate::scenes::solids::Solid;

/// The cube face that `flipped-cube` turns round and `lit-cube` lights: x = 0, the first N^2 patches of
/// `@cube:N`.
pub const FLIPPED_FACE: usize = 0;

/// A scene of the suite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CalibrationScene {
    /// `@cube:N`.
    Cube(usize),
    /// `@tetrahedron:k`, `@octahedron:k`, `@icosahedron:k`, `@dodecahedron:k`.
    Solid(Solid, usize),
    /// `two-squares:parallel:N:D`.
    ParallelSquares {
        /// Patches per side of each square.
        patches: usize,
        /// The distance between the squares (their side is 1).
        distance: f64,
    },
    /// `two-squares:perpendicular:N`.
    PerpendicularSquares {
        /// Patches per side of each square.
        patches: usize,
    },
    /// `flipped-cube:N`.
    FlippedCube(usize),
    /// `lit-cube:N`.
    LitCube(usize),
}

const SOLIDS: [(&str, Solid); 4] = [
    ("tetrahedron", Solid::Tetrahedron),
    ("octahedron", Solid::Octahedron),
    ("icosahedron", Solid::Icosahedron),
    ("dodecahedron", Solid::Dodecahedron),
];

/// The scene names `parse` reads, for messages.
pub const USAGE: &str = "@cube[:N], @tetrahedron[:k], @octahedron[:k], @icosahedron[:k], \
                         @dodecahedron[:k], two-squares:parallel[:N[:D]], two-squares:perpendicular[:N], \
                         flipped-cube[:N], lit-cube[:N]";

impl CalibrationScene {
    /// Reads a scene name (see [`USAGE`]).
    pub fn parse(spec: &str) -> Result<CalibrationScene, SceneError> {
        let parts: Vec<&str> = spec.trim().split(':').collect();
        let bad = || {
            SceneError::Builtin(format!(
                "`{spec}`: not a calibration scene; the scenes with exact values are {USAGE}"
            ))
        };
        let count = |i: usize| -> Result<usize, SceneError> {
            match parts.get(i) {
                None => Ok(1),
                Some(p) => p.parse::<usize>().ok().filter(|&n| n >= 1).ok_or_else(bad),
            }
        };
        if parts.len() > 4 {
            return Err(bad());
        }
        let scene = match parts[0] {
            "@cube" if parts.len() <= 2 => CalibrationScene::Cube(count(1)?),
            "flipped-cube" if parts.len() <= 2 => CalibrationScene::FlippedCube(count(1)?),
            "lit-cube" if parts.len() <= 2 => CalibrationScene::LitCube(count(1)?),
            "two-squares" => match parts.get(1).copied() {
                Some("parallel") => CalibrationScene::ParallelSquares {
                    patches: count(2)?,
                    distance: match parts.get(3) {
                        None => 1.0,
                        Some(d) => d
                            .parse::<f64>()
                            .ok()
                            .filter(|d| d.is_finite() && *d > 0.0)
                            .ok_or_else(bad)?,
                    },
                },
                Some("perpendicular") if parts.len() <= 3 => {
                    CalibrationScene::PerpendicularSquares { patches: count(2)? }
                }
                _ => return Err(bad()),
            },
            name if parts.len() <= 2 => {
                let solid = SOLIDS
                    .iter()
                    .find(|(n, _)| name.strip_prefix('@') == Some(*n))
                    .ok_or_else(bad)?;
                CalibrationScene::Solid(solid.1, count(1)?)
            }
            _ => return Err(bad()),
        };
        Ok(scene)
    }

    /// The scene's name (the form [`CalibrationScene::parse`] reads).
    pub fn name(&self) -> String {
        match *self {
            CalibrationScene::Cube(n) => format!("@cube:{n}"),
            CalibrationScene::Solid(which, k) => {
                let name = SOLIDS.iter().find(|s| s.1 == which).map_or("?", |s| s.0);
                format!("@{name}:{k}")
            }
            CalibrationScene::ParallelSquares { patches, distance } => {
                if distance == 1.0 {
                    format!("two-squares:parallel:{patches}")
                } else {
                    format!("two-squares:parallel:{patches}:{distance}")
                }
            }
            CalibrationScene::PerpendicularSquares { patches } => {
                format!("two-squares:perpendicular:{patches}")
            }
            CalibrationScene::FlippedCube(n) => format!("flipped-cube:{n}"),
            CalibrationScene::LitCube(n) => format!("lit-cube:{n}"),
        }
    }

    /// Whether every segment leaving a front side reaches another (rows of F sum to 1).
    pub fn is_closed(&self) -> bool {
        matches!(
            self,
            CalibrationScene::Cube(_) | CalibrationScene::Solid(..) | CalibrationScene::LitCube(_)
        )
    }

    /// Builds the scene.
    pub fn build(&self) -> Result<Scene, SceneError> {
        match *self {
            CalibrationScene::Cube(_) | CalibrationScene::Solid(..) => {
                crate::scenes::load(&self.name())
            }
            CalibrationScene::ParallelSquares { patches, distance } => {
                two_squares(&self.name(), patches, Some(distance))
            }
            CalibrationScene::PerpendicularSquares { patches } => {
                two_squares(&self.name(), patches, None)
            }
            CalibrationScene::FlippedCube(n) => flipped_cube(&self.name(), n),
            CalibrationScene::LitCube(n) => lit_cube(&self.name(), n),
        }
    }
}

/// Two unit squares cut into `n x n` patches: the floor `z = 0` facing up, and either a ceiling at
/// `z = distance` facing down, or (`None`) the wall `x = 0` facing +x.
fn two_squares(name: &str, n: usize, distance: Option<f64>) -> Result<Scene, SceneError> {
    let mut b = SceneBuilder::new(name);
    let m = b.material(Material::grey("wall", 0.5, 0.0));
    let step = 1.0 / n as f64;
    for i in 0..n {
        for j in 0..n {
            let (u0, u1, v0, v1) = (
                i as f64 * step,
                (i + 1) as f64 * step,
                j as f64 * step,
                (j + 1) as f64 * step,
            );
            // Counter-clockwise seen from the front side.
            let floor = [[u0, v0, 0.0], [u1, v0, 0.0], [u1, v1, 0.0], [u0, v1, 0.0]];
            let other = match distance {
                Some(c) => [[u0, v0, c], [u0, v1, c], [u1, v1, c], [u1, v0, c]],
                None => [[0.0, u0, v0], [0.0, u1, v0], [0.0, u1, v1], [0.0, u0, v1]],
            };
            for (quad, which) in [(floor, "floor"), (other, "other")] {
                let ids: Vec<u32> = quad.iter().map(|&p| b.vertex(p)).collect();
                b.polygon(&ids, m, format!("{which} patch ({i}, {j})"));
            }
        }
    }
    b.build()
}

/// `@cube:n` with the face x = 0 turned round (its polygons reversed).
fn flipped_cube(name: &str, n: usize) -> Result<Scene, SceneError> {
    let cube = crate::scenes::load(&format!("@cube:{n}"))?;
    let mut b = SceneBuilder::new(name);
    for m in &cube.materials {
        b.material(m.clone());
    }
    let ids: Vec<u32> = cube.vertices.iter().map(|&v| b.vertex(v)).collect();
    for (k, p) in cube.patches.iter().enumerate() {
        let mut corners: Vec<u32> = cube.polygon(p).iter().map(|&v| ids[v as usize]).collect();
        if on_flipped_face(k, n) {
            corners.reverse();
        }
        b.polygon(&corners, p.material, format!("patch {k}"));
    }
    b.build()
}

/// Whether patch `k` of `@cube:n` is on the face [`FLIPPED_FACE`].
pub fn on_flipped_face(k: usize, n: usize) -> bool {
    k / (n * n) == FLIPPED_FACE
}

/// `@cube:n` with the face x = 0 emitting 1; every face reflects 1/2.
fn lit_cube(name: &str, n: usize) -> Result<Scene, SceneError> {
    let mut scene = crate::scenes::load(&format!("@cube:{n}"))?;
    scene.name = name.to_string();
    scene.materials = vec![
        Material::grey("wall", 0.5, 0.0),
        Material::grey("light", 0.5, 1.0),
    ];
    for (k, p) in scene.patches.iter_mut().enumerate() {
        p.material = u32::from(on_flipped_face(k, n));
    }
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_read_back() {
        for spec in [
            "@cube:4",
            "@tetrahedron:2",
            "@dodecahedron:1",
            "two-squares:parallel:3",
            "two-squares:parallel:1:0.5",
            "two-squares:perpendicular:2",
            "flipped-cube:1",
            "lit-cube:3",
        ] {
            let scene = CalibrationScene::parse(spec).unwrap();
            assert_eq!(scene.name(), spec);
        }
        assert_eq!(
            CalibrationScene::parse("@cube").unwrap(),
            CalibrationScene::Cube(1)
        );
        for bad in ["@sphere:2", "cube", "@cube:0", "two-squares", "lit-cube:x"] {
            assert!(CalibrationScene::parse(bad).is_err(), "{bad}");
        }
    }

    /// The made scenes have the patches, areas and sides they should.
    #[test]
    fn made_scenes_are_what_they_say() {
        let parallel = CalibrationScene::parse("two-squares:parallel:2")
            .unwrap()
            .build()
            .unwrap();
        assert_eq!(parallel.patch_count(), 8);
        assert!((parallel.total_area_scene_units() - 2.0).abs() < 1e-12);
        let flipped = CalibrationScene::FlippedCube(2).build().unwrap();
        let cube = CalibrationScene::Cube(2).build().unwrap();
        for (k, (a, b)) in flipped.patches.iter().zip(&cube.patches).enumerate() {
            let expected = if on_flipped_face(k, 2) { -1.0 } else { 1.0 };
            assert!(
                (a.normal.dot(b.normal) - expected).abs() < 1e-12,
                "patch {k}"
            );
        }
        let lit = CalibrationScene::LitCube(2).build().unwrap();
        let emitting = lit
            .patches
            .iter()
            .filter(|p| lit.materials[p.material as usize].emission > 0.0)
            .count();
        assert_eq!(emitting, 4);
    }
}
