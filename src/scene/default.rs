//! The built-in default scene: the Cornell box with two white blocks, from the published
//! measurements of the Cornell Program of Computer Graphics, in metres, open side facing +z.
//!
//! The geometry and materials live in `scenes/cornell-box.obj` and `scenes/cornell-box.mtl`
//! (commented there with the source of every number) and are embedded into the binary, so the
//! program runs without any file. The scene goes through the same loader as any OBJ.

use super::obj::{LoadOptions, SceneError};
use super::Scene;

/// The name the built-in scene carries in messages and reports.
pub const DEFAULT_SCENE_NAME: &str = "cornell-box";

/// The OBJ text of the built-in scene: 23 quads (floor, 8 ceiling quads around the light,
/// back wall, red left wall, green right wall, the light, two blocks of 5 faces).
pub const DEFAULT_SCENE_OBJ: &str = include_str!("../../scenes/cornell-box.obj");

/// The MTL text of the built-in scene: materials `white`, `red`, `green` and `light`
/// (the only emitter, `Ke 17 12 4` W/sr/m²).
pub const DEFAULT_SCENE_MTL: &str = include_str!("../../scenes/cornell-box.mtl");

/// Load the built-in Cornell box. `opts.emit` applies as for any OBJ (e.g. to relight it).
pub fn default_scene(opts: &LoadOptions) -> Result<Scene, SceneError> {
    super::obj::load_obj_from_strs(
        DEFAULT_SCENE_NAME,
        DEFAULT_SCENE_OBJ,
        DEFAULT_SCENE_MTL,
        opts,
    )
}
