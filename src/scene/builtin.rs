//! todo
pub const NAMES: &[&str] = &[];
pub fn load_builtin(_name: &str) -> Result<super::Scene, super::SceneError> {
    todo!()
}
