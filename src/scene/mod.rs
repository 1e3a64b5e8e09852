//! The scene: its description (camera, image, materials, lights, velocity groups), the TOML
//! loader with errors that name file, line and key, `--set` overrides, and procedural objects.

mod colour;
pub(crate) mod doc;
mod envelope;
mod load;
mod mesh_file;
mod model;
mod node;
mod objects;
mod pass_set;
mod procedural;
mod reader;
mod speed;
pub mod stars;
mod surfaces;
mod texture;
pub(crate) mod toml_tree;
mod transform;

pub use crate::error::SceneError;
pub use load::{load_file, load_file_as, load_str, FrameSize};
pub use model::{
    Camera, Film, Fog, FrameSpacing, Group, ImageSettings, Integrator, Light, Material, Medium,
    ObjectInfo, Projection, RenderSettings, Scene, MAX_FRAMES, MAX_FRAME_PIXELS, MAX_RAYS,
};
pub use pass_set::{Pass, PassSet};
pub use texture::{ImageTexture, Sample as TextureSample, Sky, Texture};
