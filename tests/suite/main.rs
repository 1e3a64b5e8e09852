//! Every integration test, one module per concern, in one binary: one link of the library
//! instead of one per file (the build's largest cost in `make test`, and most of target/).
//! Run one concern with `cargo test --release --test suite NAME::`, one test with its whole
//! path. The tests use the library's public API and the binary (`CARGO_BIN_EXE_rest-embree`)
//! only; helpers they share are in tests/common.

#[macro_use]
#[path = "../common/mod.rs"]
mod common;

mod acceleration;
mod backend_agreement;
mod backend_conformance;
mod billion_lattice;
mod calibration;
mod cli;
mod cli_messages;
mod compositing;
mod embree_cli;
mod envelope;
mod extreme;
mod farm;
mod film;
mod fuzz;
mod gltf;
mod house;
mod media;
mod meshes;
mod orthographic;
mod path;
mod physics_render;
mod primitives;
mod radar;
mod relativity;
mod scenes_load;
mod set_keys;
mod shading;
mod shutter;
mod sky;
mod spacetime;
mod spectral;
mod spin;
mod stress;
mod textures;
mod turning;
mod view;
mod wigner_rotation;
mod worldline;
