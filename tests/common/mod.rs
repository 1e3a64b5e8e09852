//! Helpers shared by the integration tests.
#![allow(dead_code)]

mod basics;
pub mod cli;
#[macro_use]
pub mod conformance;
pub mod exrcheck;
pub use basics::*;

use rest_embree::render::Frame;
use rest_embree::scene::Scene;

/// Render on `backend`. Groups of a few primitives are normally intersected directly in f64,
/// whatever the backend; here only the f64 BVH keeps that path, so tests on Embree trace every
/// group through Embree.
pub fn render_with(scene: &Scene, backend: &str) -> Frame {
    use rest_embree::render::{RenderOptions, WorldOptions};
    let b = rest_embree::accel::backend_by_name(backend).unwrap();
    let world = WorldOptions {
        direct_max: if backend == "bvh" {
            WorldOptions::default().direct_max
        } else {
            0
        },
        ..Default::default()
    };
    let options = RenderOptions {
        world,
        ..Default::default()
    };
    let (frame, stats) = rest_embree::render(scene, b.as_ref(), &options).unwrap();
    assert_eq!(stats.nonfinite_pixels, 0, "no NaN or infinite pixel");
    frame
}

/// As [`render_with`], with every object of more than `instance_over` primitives held as
/// itself (0: lattices and bar arrays instanced, meshes as their shared vertices), however
/// small.
pub fn render_held(scene: &Scene, backend: &str, instance_over: u64) -> Frame {
    use rest_embree::render::{RenderOptions, WorldOptions};
    let b = rest_embree::accel::backend_by_name(backend).unwrap();
    let world = WorldOptions {
        direct_max: 0,
        instance_over,
        ..Default::default()
    };
    let options = RenderOptions {
        world,
        ..Default::default()
    };
    let (frame, stats) = rest_embree::render(scene, b.as_ref(), &options).unwrap();
    assert_eq!(stats.nonfinite_pixels, 0, "no NaN or infinite pixel");
    frame
}

/// The vertical field of view, in degrees, that gives focal length `f` pixels at `height`.
pub fn fov_for_focal(f: f64, height: u32) -> f64 {
    2.0 * (0.5 * height as f64 / f).atan().to_degrees()
}

/// Image size of the calibration renders: an odd height puts the centre row on v = 0; an even
/// width puts pixel centres on half-integer u, off the faces' edges at whole pixels.
pub const CUBE_W: u32 = 600;
pub const CUBE_H: u32 = 41;

/// The §2.4 set-up: a unit cube with its rear face at rest-frame x = `rear_x` and near face in
/// the plane y = h, moving along +x at `speed` (a TOML fragment such as `velocity = [0.5, 0, 0]`);
/// the camera at `position` at time `time`, looking along +y with f = 1000 px.
pub fn cube_scene(h: f64, speed: &str, rear_x: f64, time: f64, position: [f64; 3]) -> String {
    format!(
        r#"
[camera]
position = [{px:?}, {py:?}, {pz:?}]
direction = [0, 1, 0]
fov_y = {fov}
time = {time:?}
[image]
width = {CUBE_W}
height = {CUBE_H}
[[group]]
name = "cube"
{speed}
[[group.object]]
type = "box"
min = [{rear_x:?}, {h:?}, -0.5]
max = [{front_x:?}, {h1:?}, 0.5]
"#,
        px = position[0],
        py = position[1],
        pz = position[2],
        fov = fov_for_focal(1000.0, CUBE_H),
        front_x = rear_x + 1.0,
        h1 = h + 1.0
    )
}

/// Pixels of the centre row whose primary hit is on the cube face with this rest-frame normal.
pub fn face_width(frame: &Frame, normal: [f32; 3]) -> usize {
    let y = frame.height / 2;
    (0..frame.width)
        .filter(|&x| {
            let p = frame.get(x, y);
            p.object_id == 1
                && p.normal
                    .iter()
                    .zip(normal)
                    .all(|(a, b)| (a - b).abs() < 1e-3)
        })
        .count()
}

/// No pixel of any pass is NaN or infinite.
pub fn assert_all_finite(frame: &Frame, what: &str) {
    for p in &frame.pixels {
        let vals = [
            p.color[0],
            p.color[1],
            p.color[2],
            p.alpha,
            p.lookback,
            p.doppler,
            p.normal[0],
            p.normal[1],
            p.normal[2],
        ];
        assert!(
            vals.iter().all(|v| v.is_finite()),
            "{what}: non-finite pixel {p:?}"
        );
    }
}

/// Check a measurement against its known answer and print it as a row of docs/ACCURACY.md
/// (`scripts/accuracy-table.sh` collects these lines from a `--nocapture` run).
pub fn report(case: &str, backend: &str, expected: f64, measured: f64, tolerance: f64, unit: &str) {
    let err = (measured - expected).abs();
    // The test's thread carries its name, and the binary's name its file: the command that
    // reproduces the row.
    let test = std::thread::current().name().unwrap_or("?").to_string();
    let exe = std::env::args().next().unwrap_or_default();
    let file = std::path::Path::new(&exe)
        .file_name()
        .map(|f| {
            f.to_string_lossy()
                .split('-')
                .next()
                .unwrap_or("?")
                .to_string()
        })
        .unwrap_or_default();
    println!("ACCURACY|{case}|{backend}|{expected:.6}|{measured:.6}|{err:.2e}|{tolerance:.2e}|{unit}|{file}|{test}");
    assert!(
        err <= tolerance,
        "{case} ({backend}): measured {measured}, expected {expected}, error {err:.3e} > {tolerance:.1e} {unit}"
    );
}

/// Sub-pixel extent of a covered run on one row or column of alpha values: the left edge of the
/// first covered pixel is moved in by its uncovered share, the right edge of the last out by its
/// covered share. Returns (start, end) in frame pixels.
pub fn alpha_extent(alpha: &[f32]) -> Option<(f64, f64)> {
    let first = alpha.iter().position(|&a| a > 0.0)?;
    let last = alpha.iter().rposition(|&a| a > 0.0)?;
    Some((
        first as f64 + 1.0 - alpha[first] as f64,
        last as f64 + alpha[last] as f64,
    ))
}
