//! Strict TOML scene loading (SPEC §3).
use std::path::Path;

use super::Scene;

/// A scene that could not be loaded: one sentence naming the file, the place and the field.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct SceneError(pub String);

pub fn load_scene_file(_path: &Path) -> Result<Scene, SceneError> {
    todo!()
}

pub fn load_scene_str(_text: &str, _name: &str) -> Result<Scene, SceneError> {
    todo!()
}
