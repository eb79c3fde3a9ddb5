//! Reading a scene: a built-in (`@cube:10`), a file, or `-` for standard input.

use std::path::Path;

use scene_complexity::{
    load_stream, load_with_policy, ReadPolicy, Scene, SceneError, SceneOptions,
};

use super::exit::Failure;
use super::output::warn;

/// Loads the scene a command names, read as `options` ask and touching only what `policy` lets it,
/// printing its loading warnings; bad input is exit code 2.
pub fn load_scene(
    spec: &str,
    options: &SceneOptions,
    policy: &ReadPolicy,
) -> Result<Scene, Failure> {
    let scene = quietly(spec, || {
        if spec == "-" {
            // A scene on standard input names its files relative to the current folder.
            let stdin = std::io::stdin().lock();
            load_stream("<stdin>", stdin, Path::new(""), options, policy)
        } else {
            load_with_policy(spec, options, policy)
        }
    })
    .map_err(|e| Failure::bad_input(e.to_string()))?;
    for w in &scene.warnings {
        warn(&w.message);
    }
    Ok(scene)
}

/// Runs a scene reader with Rust's panic message switched off: the readers turn a panic in a dependency
/// into an error of their own (the glTF reader) and this catches any other, so that the user sees one
/// clear message and never a panic's text or backtrace. Reading happens before any other thread of the
/// run starts, so the process-wide hook is this reading's alone while it is swapped.
fn quietly(
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
