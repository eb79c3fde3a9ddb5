//! `scx export`: a scene (built-in or file) written as OBJ + MTL.

use std::path::PathBuf;

use scene_complexity::scene::obj;

use super::input::load_scene;
use super::output::{self, check_all};
use super::{Exit, Failure};

/// Arguments of `scx export`.
#[derive(clap::Args, Debug)]
pub struct ExportArgs {
    /// A scene file, a built-in scene such as `@cube:10`, or `-` for an OBJ on standard input.
    scene: String,
    /// The OBJ file to write; the MTL library goes beside it (both checked writable first).
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs `scx export`.
pub fn run(args: &ExportArgs) -> Result<Exit, Failure> {
    let mtl = args.output.with_extension("mtl");
    check_all([args.output.as_path(), mtl.as_path()])?;
    let scene = load_scene(&args.scene)?;
    obj::write(&scene, &args.output).map_err(|e| Failure {
        code: Exit::Io,
        message: e.to_string(),
    })?;
    output::note(&format!(
        "wrote {} ({} patches) and {}",
        args.output.display(),
        scene.patch_count(),
        mtl.display()
    ));
    Ok(Exit::Ok)
}
