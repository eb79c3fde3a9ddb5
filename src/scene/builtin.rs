//! Built-in scenes, named `@name` or `@name:param`.
//!
//! * `@cube:N`: the interior of the unit cube (area 6), each face cut into N x N square patches, normals
//!   pointing inwards. `@cube` is `@cube:1`.

use super::{Material, Scene, SceneBuilder, SceneError};

/// A built-in scene's name, parameter and description, for `scx scenes`.
#[derive(Clone, Copy, Debug)]
pub struct BuiltinInfo {
    /// How to name it (`@cube:N`).
    pub usage: &'static str,
    /// What it is.
    pub description: &'static str,
}

/// Every built-in scene.
pub const BUILTINS: &[BuiltinInfo] = &[BuiltinInfo {
    usage: "@cube[:N]",
    description: "unit cube enclosure, inward normals, each face cut into N x N square patches (N >= 1, default 1)",
}];

/// Builds a built-in scene from its name (`@cube:10`).
pub fn build(spec: &str) -> Result<Scene, SceneError> {
    let body = spec.strip_prefix('@').unwrap_or(spec);
    let (name, param) = match body.split_once(':') {
        Some((n, p)) => (n, Some(p)),
        None => (body, None),
    };
    match name {
        "cube" => cube(spec, parse_count(spec, param, 1, 2000)?),
        _ => Err(SceneError::Builtin(format!(
            "{spec}: unknown built-in scene; `scx scenes` lists them ({})",
            BUILTINS
                .iter()
                .map(|b| b.usage)
                .collect::<Vec<_>>()
                .join(", ")
        ))),
    }
}

/// Parses an optional whole-number parameter within `[1, max]`.
fn parse_count(
    spec: &str,
    param: Option<&str>,
    default: usize,
    max: usize,
) -> Result<usize, SceneError> {
    let Some(p) = param else {
        return Ok(default);
    };
    match p.parse::<usize>() {
        Ok(n) if (1..=max).contains(&n) => Ok(n),
        _ => Err(SceneError::Builtin(format!(
            "{spec}: the parameter must be a whole number from 1 to {max}, not `{p}`"
        ))),
    }
}

/// The six faces of the unit cube as (corner, u axis, v axis), with `u x v` pointing inwards.
const CUBE_FACES: [([f64; 3], [f64; 3], [f64; 3]); 6] = [
    ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]), // x = 0, normal +x
    ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]), // x = 1, normal -x
    ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]), // y = 0, normal +y
    ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]), // y = 1, normal -y
    ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), // z = 0, normal +z
    ([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]), // z = 1, normal -z
];

/// `@cube:N`: the unit cube enclosure, N x N patches per face, inward normals.
///
/// Patches are numbered face by face in the order of [`CUBE_FACES`], and within a face by `(i, j)` with
/// `patch = face * N^2 + i * N + j`, `i` along u and `j` along v.
pub fn cube(spec: &str, n: usize) -> Result<Scene, SceneError> {
    let mut b = SceneBuilder::new(spec);
    let m = b.material(Material {
        name: "wall".into(),
        emission: 0.0,
        reflectance: 0.5,
    });
    for (face, (o, u, v)) in CUBE_FACES.iter().enumerate() {
        for i in 0..n {
            for j in 0..n {
                let corner = |di: usize, dj: usize| {
                    let s = (i + di) as f64 / n as f64;
                    let t = (j + dj) as f64 / n as f64;
                    [0, 1, 2].map(|a| o[a] + s * u[a] + t * v[a])
                };
                let quad = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                let idx = quad.map(|p| b.vertex(p));
                b.polygon(&idx, m, format!("cube face {face} patch ({i}, {j})"));
            }
        }
    }
    b.build()
}
