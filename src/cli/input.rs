//! Reading a scene: a built-in (`@cube:10`), a file, or `-` for standard input.

use std::io::Read;
use std::path::Path;

use scene_complexity::{load_obj_text, load_with, Scene, SceneOptions};

use super::exit::{Exit, Failure};
use super::output::warn;

/// Loads the scene a command names, read as `options` ask, printing its loading warnings; bad input is
/// exit code 2.
pub fn load_scene(spec: &str, options: &SceneOptions) -> Result<Scene, Failure> {
    let scene = if spec == "-" {
        from_stdin(options)?
    } else {
        load_with(spec, options).map_err(|e| Failure::bad_input(e.to_string()))?
    };
    for w in &scene.warnings {
        warn(w);
    }
    Ok(scene)
}

/// An OBJ scene from standard input; an `mtllib` is looked for in the current folder.
fn from_stdin(options: &SceneOptions) -> Result<Scene, Failure> {
    let mut text = String::new();
    std::io::stdin()
        .read_to_string(&mut text)
        .map_err(|e| Failure {
            code: Exit::Io,
            message: format!("cannot read the scene from standard input: {e}"),
        })?;
    let materials = |mtl: &Path| {
        let text = std::fs::read_to_string(mtl).map_err(|e| e.to_string())?;
        Ok((mtl.display().to_string(), text))
    };
    load_obj_text("<stdin>", &text, &materials, options)
        .map_err(|e| Failure::bad_input(e.to_string()))
}
