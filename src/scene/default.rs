//! The built-in default scene (placeholder: being written).
use super::obj::{LoadOptions, SceneError};
use super::Scene;
pub const DEFAULT_SCENE_NAME: &str = "cornell-box";
pub const DEFAULT_SCENE_OBJ: &str = "";
pub const DEFAULT_SCENE_MTL: &str = "";
pub fn default_scene(opts: &LoadOptions) -> Result<Scene, SceneError> {
    super::obj::load_obj_from_strs(
        DEFAULT_SCENE_NAME,
        DEFAULT_SCENE_OBJ,
        DEFAULT_SCENE_MTL,
        opts,
    )
}
