//! Tests of the renderer's internals: the group and light trees, the culls, the fans of primary
//! rays, batched shadow rays. The integration tests in tests/ use the public API alone; these
//! reach what the crate keeps to itself.

#[path = "../../tests/common/basics.rs"]
mod common;

mod allocations;
mod backend_names;
mod every_isa;
// It counts the bench's primary hits (src/bench/primary.rs).
#[cfg(feature = "cli")]
mod fused_primary;
mod instanced_lattice;
mod light_buffer;
mod many_groups;
mod mesh_instances;
mod progressive;
mod screen_cull;
mod shadow_batches;
mod slow_light;
mod strips;
mod toml_tree;

/// How many pixels of two frames of one size differ, in any pass.
fn differing_pixels(a: &crate::render::Frame, b: &crate::render::Frame) -> usize {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| p != q)
        .count()
}
