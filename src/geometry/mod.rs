//! Rest-frame geometry in f64: bounding boxes, primitives and their exact ray intersections.
//!
//! Rays here are static rays `o + t d` with an unnormalised `d`: the renderer passes the boosted
//! null direction whose length is the Doppler-like factor, so `t` is the world-frame lookback time.

mod aabb;
mod bars;
mod box_tree;
pub(crate) mod digest;
mod group_geometry;
mod implicit;
mod indexed_mesh;
mod lattice;
mod light_buffer;
mod mesh_instance;
mod primitive;
mod real;

pub use aabb::Aabb;
pub use bars::BarArray;
pub(crate) use box_tree::{walk, BoxTree, TreeNode, PACKET};
pub use group_geometry::{Corners, Geometry, ImplicitRun, Part, Placement, Spin};
pub(crate) use implicit::INSTANCE_OVER;
pub use implicit::{Blocks, Implicit, Member};
pub use indexed_mesh::IndexedMesh;
pub use lattice::Lattice;
pub(crate) use light_buffer::LightBuffer;
pub use mesh_instance::{Affine, MeshInstance};
pub(crate) use primitive::ball_crossings;
pub use primitive::Primitive;
#[cfg(feature = "embree")]
pub(crate) use primitive::{capsule_hit, cuboid_hit, cylinder_crossings, AxisRod};
pub(crate) use real::Real;
