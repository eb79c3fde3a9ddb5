//! Reading a scene: a built-in (`@cube:10`), a file, or `-` for standard input.

use std::path::Path;

use scene_complexity::{
    load_stream, load_with_policy, read_guarded, ReadPolicy, Scene, SceneOptions,
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
    let scene = read_guarded(spec, || {
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
