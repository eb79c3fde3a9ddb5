//! The catalogue of built-in scenes, named `@name` or `@name:param`: the scenes of the paper's figures
//! and tables, one file per figure or family, and one registry ([`CATALOGUE`]) that both `scx scenes`
//! and name lookup use.
//!
//! Every built-in is an enclosure seen from inside (room and solid interiors face inwards, objects in a
//! room face outwards), so every line segment inside it joins two patches (`@cornell-open` excepted,
//! which lets lines out at its open front).
//!
//! * [`solids`]: `@cube:N`, `@sphere:L` and the regular solids (Tables 2 and 4);
//! * [`cornell`]: `@cornell[:N]` and `@cornell-open[:N]`, the Cornell box (Tables 4 and 9);
//! * [`cubes512`]: `@cubes512`, a room full of occluders for benchmarks;
//! * [`cube_clusters`]: `@fig2:a|b|c`, 512 cubes at random or in clusters (Tables 1 and 3);
//! * [`furniture`]: `@fig4:a..f`, tables and chairs in a room (Table 5);
//! * [`cube_lattice`]: `@fig5:S` and `@fig6:S`, 64 cubes from clustered to spread (Tables 6 and 7);
//! * [`labyrinth`]: `@labyrinth[:N]`, the maze with R + E = 1 everywhere (Table 8).
//!
//! Materials: every built-in but the Cornell box and the labyrinth has one material, `wall`, with
//! reflectance R = 0.5 and no emission (nothing emits, so these scenes have no radiosity measures).

pub mod cornell;
pub mod cube_clusters;
pub mod cube_lattice;
pub mod cubes512;
pub mod furniture;
pub mod labyrinth;
mod parts;
pub mod solids;

use cube_lattice::Fig56Mesh;
use solids::Solid;

use crate::scene::{format, ReadPolicy, Scene, SceneBuilder, SceneError, SceneOptions};

/// A built-in scene: its name, how to name it, what it is, and how to build it.
#[derive(Clone, Copy, Debug)]
pub struct Builtin {
    /// The name after `@` (`cube`).
    pub name: &'static str,
    /// How to name it (`@cube[:N]`).
    pub usage: &'static str,
    /// What it is.
    pub description: &'static str,
    /// Builds it from the whole name (for messages) and the parameter after `:`, if any.
    build: fn(&str, Option<&str>) -> Result<Scene, SceneError>,
}

/// Every built-in scene, in the order `scx scenes` lists them.
pub const CATALOGUE: &[Builtin] = &[
    Builtin {
        name: "cube",
        usage: "@cube[:N]",
        description: "unit cube enclosure, each face cut into N x N square patches (N >= 1, default 1)",
        build: |spec, p| solids::cube(spec, subdivisions(spec, p, 2000, 6)?),
    },
    Builtin {
        name: "sphere",
        usage: "@sphere[:L]",
        description: "icosphere enclosure after L subdivisions (0..=7, default 3): 20*4^L triangle patches",
        build: |spec, p| solids::sphere(spec, count(spec, p.or(Some("3")), 0, 7)?),
    },
    Builtin {
        name: "tetrahedron",
        usage: "@tetrahedron[:N]",
        description: "regular tetrahedron interior, each face cut into N^2 triangles (default 1: 4 patches)",
        build: |spec, p| solid(spec, Solid::Tetrahedron, p),
    },
    Builtin {
        name: "octahedron",
        usage: "@octahedron[:N]",
        description: "regular octahedron interior, each face cut into N^2 triangles (default 1: 8 patches)",
        build: |spec, p| solid(spec, Solid::Octahedron, p),
    },
    Builtin {
        name: "icosahedron",
        usage: "@icosahedron[:N]",
        description: "regular icosahedron interior, each face cut into N^2 triangles (default 1: 20 patches)",
        build: |spec, p| solid(spec, Solid::Icosahedron, p),
    },
    Builtin {
        name: "dodecahedron",
        usage: "@dodecahedron[:N]",
        description: "regular dodecahedron interior, one pentagon per face; N > 1 cuts each into 5 N^2 triangles",
        build: |spec, p| solid(spec, Solid::Dodecahedron, p),
    },
    Builtin {
        name: "cornell",
        usage: "@cornell[:N]",
        description: "the Cornell box (published geometry, mm), closed by a white front wall; light E = 10.93, \
                      white/red/green R = 0.723/0.243/0.198; 29 N^2 patches",
        build: |spec, p| cornell::build(spec, count(spec, p, 1, 100)?, true),
    },
    Builtin {
        name: "cornell-open",
        usage: "@cornell-open[:N]",
        description: "the Cornell box as published, open at the front (lines escape there); 28 N^2 patches",
        build: |spec, p| cornell::build(spec, count(spec, p, 1, 100)?, false),
    },
    Builtin {
        name: "cubes512",
        usage: "@cubes512",
        description: "unit cube room holding 512 small cubes (side 1/16, one per cell of an 8^3 grid, fixed random offsets)",
        build: cubes512::cubes512,
    },
    Builtin {
        name: "fig2",
        usage: "@fig2:a|b|c",
        description: "paper fig. 2: unit cube room with 512 cubes of side 1/20, walls 10 x 10 patches, cube \
                      faces 1 (3672 patches, H_p 11.5407); a: one cube at random in each cell of an 8^3 \
                      grid; b: 64 clusters of 2^3 cubes, c: 8 clusters of 4^3 (gaps 1/200) at random in \
                      their blocks",
        build: cube_clusters::fig2,
    },
    Builtin {
        name: "fig4",
        usage: "@fig4:a..f",
        description: "paper fig. 4: 10 x 10 x 3 m room; a: a 0.9 m table with four chairs in the middle; \
                      b: 2 x 2 of them; c: 4 x 4 in the middle, d: 4 x 4 spread evenly, e: four 2 x 2 \
                      blocks in the corners, f: 16 along the walls (e, f: 0.1 m from the walls)",
        build: furniture::fig4,
    },
    Builtin {
        name: "fig5",
        usage: "@fig5:a..f|T",
        description: "paper fig. 5: 64 cubes of side 1/8 on a 4^3 lattice in the unit room, from gaps of \
                      1/80 between them (a) to 1/64 from the walls (f), or at fraction T in [0, 1] of the \
                      way; cubes finer: faces 2 x 2, walls 8 x 8 (1536 + 384 patches)",
        build: |spec, p| cube_lattice::fig56(spec, p, Fig56Mesh::CubesFiner),
    },
    Builtin {
        name: "fig6",
        usage: "@fig6:a..f|T",
        description: "paper fig. 6: the scenes of @fig5 with walls finer: cube faces 1, walls 16 x 16 \
                      (384 + 1536 patches)",
        build: |spec, p| cube_lattice::fig56(spec, p, Fig56Mesh::WallsFiner),
    },
    Builtin {
        name: "labyrinth",
        usage: "@labyrinth[:N]",
        description: "paper fig. 9: perfect maze of N x N cells (default 11) with unit-high wall blocks \
                      in a hall 2 high, unit-square patches (1634 for N = 11); every material has R + E = 1, \
                      so the radiosity is 1 everywhere",
        build: |spec, p| labyrinth::build(spec, count(spec, p.or(Some("11")), 1, 100)?),
    },
];

/// Loads a scene: a built-in name starting with `@` ([`build`]) or a scene file in any format scx reads
/// ([`format::load_file`]: OBJ, glTF, PLY, STL, told apart by their content).
pub fn load(spec: &str) -> Result<Scene, SceneError> {
    load_with(spec, &SceneOptions::default())
}

/// [`load`] with options: the planarity rule, and objects to flip or make two-sided (a built-in is one
/// object, named after it).
pub fn load_with(spec: &str, options: &SceneOptions) -> Result<Scene, SceneError> {
    load_with_policy(spec, options, &ReadPolicy::default())
}

/// [`load_with`] under a reading policy for scene files (see [`ReadPolicy`]; built-ins read no file).
pub fn load_with_policy(
    spec: &str,
    options: &SceneOptions,
    policy: &ReadPolicy,
) -> Result<Scene, SceneError> {
    if spec.starts_with('@') {
        if *options == SceneOptions::default() {
            return build(spec);
        }
        return rebuild(&build(spec)?, options);
    }
    format::load_file_with_policy(std::path::Path::new(spec), options, policy)
}

/// Runs a scene reader with Rust's panic message switched off and any panic turned into an error
/// naming `spec`: a scene file is untrusted input, and a panic in a reader (or a dependency of one)
/// must reach the user as one clear message, never as a panic's text or backtrace, nor cross into a
/// host language (the Python binding). The panic hook is process-wide: call it while no other thread
/// of the program may panic (before a run starts).
pub fn read_guarded(
    spec: &str,
    read: impl FnOnce() -> Result<Scene, SceneError>,
) -> Result<Scene, SceneError> {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(read));
    std::panic::set_hook(previous);
    result.unwrap_or_else(|_| {
        Err(SceneError::Geometry {
            scene: spec.to_string(),
            message: "scx failed to read it (an internal error in a scene reader); please report \
                      the file"
                .into(),
        })
    })
}

/// A built scene built again with options: its patches as polygons (they are planar, so the planarity
/// rule changes nothing), its objects and materials.
fn rebuild(scene: &Scene, options: &SceneOptions) -> Result<Scene, SceneError> {
    let mut b = SceneBuilder::new(scene.name.clone());
    for m in &scene.materials {
        b.material(m.clone());
    }
    let ids: Vec<u32> = scene.vertices.iter().map(|&v| b.vertex(v)).collect();
    for (k, p) in scene.patches.iter().enumerate() {
        b.object(&scene.objects[p.object as usize]);
        let corners: Vec<u32> = scene.polygon(p).iter().map(|&v| ids[v as usize]).collect();
        b.polygon(&corners, p.material, format!("patch {k}"));
    }
    b.build_with(options)
}

/// Builds a built-in scene from its name (`@cube:10`).
pub fn build(spec: &str) -> Result<Scene, SceneError> {
    let body = spec.strip_prefix('@').unwrap_or(spec);
    let (name, param) = match body.split_once(':') {
        Some((n, p)) => (n, Some(p)),
        None => (body, None),
    };
    match CATALOGUE.iter().find(|b| b.name == name) {
        Some(b) => (b.build)(spec, param),
        None => Err(SceneError::Builtin(format!(
            "{spec}: unknown built-in scene; `scx scenes` lists them ({})",
            CATALOGUE
                .iter()
                .map(|b| b.usage)
                .collect::<Vec<_>>()
                .join(", ")
        ))),
    }
}

/// A regular solid with its optional subdivision parameter.
fn solid(spec: &str, which: Solid, param: Option<&str>) -> Result<Scene, SceneError> {
    // Triangles per unit of N^2: each face cut into N^2 (a dodecahedron's pentagons into 5 N^2).
    let per_square = match which {
        Solid::Tetrahedron => 4,
        Solid::Octahedron => 8,
        Solid::Icosahedron => 20,
        Solid::Dodecahedron => 60,
    };
    solids::solid(spec, which, subdivisions(spec, param, 1000, per_square)?)
}

/// The most patches a built-in scene may have: parameters are checked against it before anything is
/// built, so a large one is refused at once rather than failing to allocate (a patch takes some hundred
/// bytes, so this is some gigabytes).
pub const MAX_BUILTIN_PATCHES: usize = 1 << 22;

/// Parses the subdivision N (from 1 to `max`, absent: 1) of a scene with `per_square` N^2 patches, and
/// refuses one whose scene would have more than [`MAX_BUILTIN_PATCHES`].
fn subdivisions(
    spec: &str,
    param: Option<&str>,
    max: usize,
    per_square: usize,
) -> Result<usize, SceneError> {
    let n = count(spec, param, 1, max)?;
    let largest = (MAX_BUILTIN_PATCHES / per_square).isqrt();
    if n > largest {
        return Err(SceneError::Builtin(format!(
            "{spec}: {} patches, more than the {MAX_BUILTIN_PATCHES} a built-in scene may have: the \
             parameter can be at most {largest}",
            per_square * n * n
        )));
    }
    Ok(n)
}

/// Parses an optional whole-number parameter within `[min, max]` (absent: `min`).
fn count(spec: &str, param: Option<&str>, min: usize, max: usize) -> Result<usize, SceneError> {
    let Some(p) = param else {
        return Ok(min);
    };
    match p.parse::<usize>() {
        Ok(n) if (min..=max).contains(&n) => Ok(n),
        _ => Err(SceneError::Builtin(format!(
            "{spec}: the parameter must be a whole number from {min} to {max}, not `{p}`"
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_names_and_parameters_are_clear_errors() {
        for bad in ["@cub", "@cube:0", "@cube:x", "@sphere:9", "@tetrahedron:-1"] {
            let e = build(bad).unwrap_err().to_string();
            assert!(e.starts_with(bad), "{e}");
        }
        // Too many patches: refused before anything is allocated.
        for (bad, max) in [
            ("@cube:2000", 836),
            ("@icosahedron:1000", 457),
            ("@dodecahedron:265", 264),
        ] {
            let e = build(bad).unwrap_err().to_string();
            assert!(e.contains(&format!("at most {max}")), "{e}");
        }
    }

    /// Every entry builds with its default parameter or its first documented one.
    #[test]
    fn every_entry_builds() {
        for b in CATALOGUE {
            let spec = match b.name {
                "fig2" => "@fig2:a".to_string(),
                "fig4" | "fig5" | "fig6" => format!("@{}:a", b.name),
                name => format!("@{name}"),
            };
            let scene = build(&spec).unwrap_or_else(|e| panic!("{spec}: {e}"));
            assert!(scene.patch_count() > 0, "{spec}");
            assert!(b.usage.starts_with(&format!("@{}", b.name)), "{}", b.usage);
        }
    }
}
