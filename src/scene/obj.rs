//! OBJ + MTL loading through tobj (placeholder: being written).
use super::Scene;
use std::path::Path;

#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    pub emit: Vec<(String, [f64; 3])>,
}

#[derive(Debug, thiserror::Error)]
#[error("{path}: {message}")]
pub struct SceneError {
    pub path: String,
    pub message: String,
}

pub fn load_obj(path: &Path, _opts: &LoadOptions) -> Result<Scene, SceneError> {
    Err(SceneError {
        path: path.display().to_string(),
        message: "not yet implemented".into(),
    })
}

pub fn load_obj_from_strs(
    name: &str,
    _obj: &str,
    _mtl: &str,
    _opts: &LoadOptions,
) -> Result<Scene, SceneError> {
    Err(SceneError {
        path: name.into(),
        message: "not yet implemented".into(),
    })
}
