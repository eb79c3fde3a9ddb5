//! `scx export`: a scene (built-in or file) written as OBJ + MTL, PLY, STL or glTF, by the extension of
//! `-o` (the library's [`WriteFormat`] picks; this module checks the paths and writes the files).

use std::path::{Path, PathBuf};

use scene_complexity::{scene_files, Scene, WriteFormat};

use super::args::SceneArgs;
use super::exit::{Exit, Failure};
use super::input::load_scene;
use super::output::{self, check_all};

/// Arguments of `scx export`.
#[derive(clap::Args, Debug)]
pub struct ExportArgs {
    /// The scene: a file in OBJ, glTF/GLB, PLY or STL (told by its content), a built-in such as
    /// `@cube:10` (`scx scenes` lists them), or `-` for a scene on standard input.
    scene: String,
    #[command(flatten)]
    input: SceneArgs,
    /// The file to write, its format chosen by the extension: `.obj` (OBJ, its MTL library written
    /// beside it), `.ply` (binary PLY), `.stl` (binary STL), `.gltf` or `.glb` (glTF 2.0); any other
    /// extension is refused. Checked writable first.
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs `scx export`.
pub fn run(args: &ExportArgs) -> Result<Exit, Failure> {
    let format = planned_output(&args.output, &args.scene)?;
    let scene = load_scene(&args.scene, &args.input.options(), &args.input.policy())?;
    check_not_read(&args.output, format, &scene)?;
    let beside = write_scene(&scene, format, &args.output)?;
    output::note(&format!(
        "wrote {} as {}, {}{beside}",
        args.output.display(),
        format.name(),
        format.patches_written(&scene),
    ));
    Ok(Exit::Ok)
}

/// The format `-o` asks for by its extension, refused (exit 2, naming the extensions scx writes)
/// when it names none; the files it will write are checked as [`check_outputs`] does. Before any work.
pub fn planned_output(output: &Path, scene: &str) -> Result<WriteFormat, Failure> {
    let format = match WriteFormat::of_path(output) {
        Ok(format) => format,
        Err(e) => {
            // A folder is the first thing to say of a path without an extension.
            if output.is_dir() {
                check_all([output])?;
            }
            return Err(Failure::bad_input(format!("-o {}: {e}", output.display())));
        }
    };
    check_outputs(output, format.companion(output).as_deref(), scene)?;
    Ok(format)
}

/// Refuses, once `scene` is read, to write `output` (or the MTL library beside it) over a file the
/// scene read.
pub fn check_not_read(output: &Path, format: WriteFormat, scene: &Scene) -> Result<(), Failure> {
    let companion = format.companion(output);
    let mut outputs = vec![("-o", output)];
    outputs.extend(companion.as_deref().map(|m| ("its MTL library", m)));
    output::check_not_read_by(&outputs, scene)
}

/// Writes a scene in `format` at `output` (each file whole or not at all), warning first of what the
/// format cannot keep; returns ` and FILE` naming a file written beside it, or nothing.
pub fn write_scene(scene: &Scene, format: WriteFormat, output: &Path) -> Result<String, Failure> {
    for loss in format.losses(scene) {
        output::warn(&format!("{}: {loss}", output.display()));
    }
    for (path, bytes) in scene_files(scene, format, output) {
        output::write_silently(&path, &bytes)?;
    }
    Ok(format
        .companion(output)
        .map(|c| format!(" and {}", c.display()))
        .unwrap_or_default())
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
