//! rest-embree: a special-relativistic ray tracer after Hsiung & Dunn's REST-frame algorithm.
//!
//! Module map: [`spacetime`] (f64 kinematics) → [`scene`] (file format, validation, procedural
//! objects) → [`geometry`] + [`accel`] (static rest-frame intersection, backends by name) →
//! [`render`] (past light-cone rays, per-group boost and merge, Whitted shading) → [`output`]
//! (EXR, PNG). [`cli`] is the command line.

pub mod accel;
pub mod bench;
pub mod cli;
pub mod compare;
mod error;
pub mod geometry;
pub mod output;
pub mod render;
pub mod rng;
pub mod scene;
pub mod spacetime;
pub mod spectrum;

pub use error::{Cause, Error, Result};
