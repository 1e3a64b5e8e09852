#![warn(missing_docs)]
// Without the command line (feature `cli`), the entry points only it calls so far are unused.
#![cfg_attr(not(feature = "cli"), allow(dead_code, unused_imports))]
//! rest-embree: a special-relativistic ray tracer after Hsiung & Dunn's REST-frame algorithm.
//!
//! As a library: load a scene ([`scene::load_file`], [`scene::load_str`]), change it in code if
//! need be, [`render()`] it on a backend ([`accel::backend_by_name`]) and write the frame
//! ([`output::write`]); `examples/render_from_code.rs` does exactly that.
//!
//! Module map: [`spacetime`] (f64 kinematics) → [`scene`] (file format, validation) →
//! [`geometry`] + [`accel`] (static rest-frame intersection; the [`accel::Backend`] trait is
//! where a new acceleration structure plugs in) → [`mod@render`] (past light-cone rays,
//! per-group boost and merge, shading) → [`output`] (EXR, PNG). [`spectrum`] is light as
//! spectra; [`compare`] tells how two frames differ. The command line and the bench are the
//! binary's, not the library's (`src/cli/`, `src/bench/`, reached through [`run_command_line`]).
//! The renderer's internals are private to the crate, and tested inside it (src/tests/);
//! docs/architecture.md walks through them.

pub mod accel;
#[cfg(feature = "cli")]
mod bench;
#[cfg(feature = "cli")]
mod cli;
pub mod compare;
mod error;
mod exr_read;
pub mod geometry;
pub mod memory;
pub mod output;
pub mod render;
pub mod rng;
pub mod scene;
pub mod spacetime;
pub mod spectrum;
mod text;
#[cfg(feature = "cli")]
mod view;

pub use error::{Cause, Error, Result};

/// The `rest-embree` command: parse the process's arguments and run it (what `src/main.rs`
/// calls; not part of the library's API).
#[doc(hidden)]
#[cfg(feature = "cli")]
pub fn run_command_line() -> std::process::ExitCode {
    cli::main()
}
pub use render::{render, RenderOptions};

/// Serve the viewer (`rest-embree view`, docs/viewer.md) on the scene `scene` (its text `text`
/// when given, else the file), with `--set` `overrides`, on 127.0.0.1:`port` (0: a free one),
/// until [`stop_viewer`]; its URL with the token is sent on `tell_url` once it listens. What the
/// Python package's `view` runs on a thread of its own.
#[doc(hidden)]
#[cfg(feature = "cli")]
pub fn serve_viewer(
    scene: std::path::PathBuf,
    text: Option<String>,
    overrides: Vec<(String, String)>,
    port: u16,
    backend: &str,
    tell_url: std::sync::mpsc::Sender<String>,
) -> Result<()> {
    view::run(&view::Config {
        scene,
        text,
        overrides,
        tell_url: Some(tell_url),
        bind: std::net::IpAddr::V4(std::net::Ipv4Addr::LOCALHOST),
        port,
        backend: backend.to_string(),
        out: std::path::PathBuf::from("."),
        allow_hosts: Vec::new(),
        open_browser: false,
    })
}

/// Stop the viewer [`serve_viewer`] runs; false if none runs.
#[doc(hidden)]
#[cfg(feature = "cli")]
pub fn stop_viewer() -> bool {
    view::interrupt()
}

// The helpers shared with tests/ name the crate `rest_embree`, as the integration tests do.
#[cfg(test)]
extern crate self as rest_embree;
#[cfg(test)]
mod tests;
