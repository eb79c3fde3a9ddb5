//! `scx export`: a scene (built-in or file) written as OBJ + MTL, or as glTF 2.0.

use std::path::PathBuf;

use scene_complexity::{write_gltf, write_obj};

use super::args::SceneArgs;
use super::exit::{Exit, Failure};
use super::input::load_scene;
use super::output::{self, check_all};

/// Arguments of `scx export`.
#[derive(clap::Args, Debug)]
pub struct ExportArgs {
    /// A scene file (OBJ, glTF, PLY, STL), a built-in scene such as `@cube:10`, or `-` for an OBJ on standard input.
    scene: String,
    #[command(flatten)]
    input: SceneArgs,
    /// The file to write: `.gltf` or `.glb` writes glTF 2.0, anything else OBJ with its MTL library
    /// beside it (checked writable first).
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs `scx export`.
pub fn run(args: &ExportArgs) -> Result<Exit, Failure> {
    let gltf = is_gltf(&args.output);
    let mtl = args.output.with_extension("mtl");
    if gltf {
        check_all([args.output.as_path()])?;
    } else {
        check_all([args.output.as_path(), mtl.as_path()])?;
    }
    let scene = load_scene(&args.scene, &args.input.options())?;
    let written = if gltf {
        write_gltf(&scene, &args.output)
    } else {
        write_obj(&scene, &args.output)
    };
    written.map_err(|e| Failure {
        code: Exit::Io,
        message: e.to_string(),
    })?;
    let beside = if gltf {
        String::new()
    } else {
        format!(" and {}", mtl.display())
    };
    output::note(&format!(
        "wrote {} ({} patches){beside}",
        args.output.display(),
        scene.patch_count(),
    ));
    Ok(Exit::Ok)
}

/// Whether `path` asks for glTF (`.gltf` text or `.glb` binary) rather than OBJ.
fn is_gltf(path: &std::path::Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}
