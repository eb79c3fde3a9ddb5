//! `scx export`: a scene (built-in or file) written as OBJ + MTL, or as glTF 2.0.

use std::path::{Path, PathBuf};

use scene_complexity::{gltf_bytes, obj_text, Scene};

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
        check_outputs(&args.output, None, &args.scene)?;
    } else {
        check_outputs(&args.output, Some(&mtl), &args.scene)?;
    }
    let scene = load_scene(&args.scene, &args.input.options(), &args.input.policy())?;
    if gltf {
        let binary = args
            .output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
        output::write_silently(&args.output, &gltf_bytes(&scene, binary))?;
    } else {
        write_obj_files(&scene, &args.output, &mtl)?;
    }
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

/// Checks, before any work, the files a scene is written to: the OBJ (or glTF) `output` and the MTL
/// library `mtl` beside an OBJ must be two files, neither of them the scene `scene` read, each writable.
pub fn check_outputs(output: &Path, mtl: Option<&Path>, scene: &str) -> Result<(), Failure> {
    if mtl.is_some()
        && output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mtl"))
    {
        return Err(Failure::bad_input(format!(
            "-o {}: the OBJ and its MTL library would be one file; name the OBJ .obj",
            output.display()
        )));
    }
    let mut outputs = vec![("-o", output)];
    outputs.extend(mtl.map(|m| ("its MTL library", m)));
    output::check_distinct(&outputs, &[("scene", Path::new(scene))], &[])?;
    check_all(outputs.iter().map(|(_, p)| *p))
}

/// Writes a scene as OBJ to `path` and its MTL library to `mtl`, each whole or not at all.
pub fn write_obj_files(scene: &Scene, path: &Path, mtl: &Path) -> Result<(), Failure> {
    let mtl_name = mtl
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene.mtl".into());
    let (obj, library) = obj_text(scene, &mtl_name);
    output::write_silently(mtl, library.as_bytes())?;
    output::write_silently(path, obj.as_bytes())
}
