//! The scene: its description (camera, image, materials, lights, velocity groups), the TOML
//! loader with errors that name file, line and key, `--set` overrides, and procedural objects.

mod camera_keys;
mod colour;
pub(crate) mod doc;
mod envelope;
mod gltf_file;
mod gltf_object;
mod inputs;
mod lights;
mod load;
mod many_groups;
mod mesh_file;
mod model;
mod node;
mod objects;
// Only the bench and the tests load the paper's scenes by name.
#[cfg(any(test, feature = "cli"))]
pub(crate) mod paper;
mod pass_set;
mod procedural;
mod reader;
mod segments;
mod set_forms;
mod settings;
mod shared_meshes;
mod speed;
mod spin_keys;
pub mod stars;
mod surfaces;
mod texture;
mod timing;
pub(crate) mod toml_runs;
pub(crate) mod toml_tree;
mod transform;
mod worldline;

pub use crate::error::SceneError;
pub(crate) use load::load_file_as;
pub use load::{load_file, load_str, FrameSize};
pub(crate) use model::MAX_FRAME_PIXELS;
pub use model::{
    Accelerated, Camera, Clock, Film, Fog, FrameSpacing, Group, ImageSettings, Integrator, Light,
    Material, Medium, ObjectInfo, Projection, RenderSettings, Scene,
};
pub use pass_set::{Pass, PassSet};
pub(crate) use set_forms::superseded;
pub use texture::{ImageTexture, Sample as TextureSample, Sky, Texture};
pub use timing::Timing;
pub use worldline::Worldline;
