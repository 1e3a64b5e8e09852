//! The helpers the integration tests (tests/) and the tests of the crate's internals
//! (src/tests/) share; written against `rest_embree::` paths, which inside the crate name the
//! crate itself.
#![allow(dead_code)]

use rest_embree::render::Frame;
use rest_embree::scene::Scene;

/// The crate's deterministic generator (splitmix64), for property tests.
pub use rest_embree::rng::Rng;

/// |a − b| ≤ tol, or a message naming `what`.
pub fn assert_close(a: f64, b: f64, tol: f64, what: &str) {
    assert!(
        (a - b).abs() <= tol,
        "{what}: got {a}, expected {b} (tolerance {tol})"
    );
}

/// |a − b| ≤ rel·|b|, or a message naming `what`.
pub fn assert_rel(a: f64, b: f64, rel: f64, what: &str) {
    assert!(
        ((a - b) / b).abs() <= rel,
        "{what}: got {a}, expected {b} (relative tolerance {rel})"
    );
}

/// The worked cases of docs/physics.md §2-§4 (tests/data/cases.json; its "source" says where they come from).
pub fn cases() -> serde_json::Value {
    serde_json::from_str(include_str!("../data/cases.json")).expect("cases.json parses")
}

/// A scene from TOML text; panics with the error.
pub fn scene(toml: &str) -> Scene {
    rest_embree::scene::load_str("test.toml", toml, &[]).unwrap_or_else(|e| panic!("scene: {e}"))
}

/// The backends of this build (every render test runs on each).
pub fn backends() -> Vec<&'static str> {
    rest_embree::accel::backend_names()
}

/// Two renders of one picture: at most `max_id_share` of the pixels see another object, and
/// where they see the same one the colours differ by at most `max_color`.
pub fn same_picture(a: &Frame, b: &Frame, what: &str, max_id_share: f64, max_color: f32) {
    let ids = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| p.object_id != q.object_id)
        .count();
    let share = ids as f64 / a.pixels.len() as f64;
    assert!(
        share <= max_id_share,
        "{what}: {ids} pixels see another object"
    );
    let mut worst = 0.0f32;
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        if p.object_id == q.object_id {
            for k in 0..3 {
                worst = worst.max((p.color[k] - q.color[k]).abs());
            }
        }
    }
    assert!(worst <= max_color, "{what}: colour differs by {worst}");
}

/// Write a `w` x `h` 8-bit RGB PNG whose texel (x, y) is `f(x, y)` (sRGB-encoded bytes).
pub fn write_png(path: &std::path::Path, w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 3]) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut enc = png::Encoder::new(file, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc.write_header().unwrap();
    let mut data = Vec::with_capacity((3 * w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            data.extend(f(x, y));
        }
    }
    writer.write_image_data(&data).unwrap();
}

/// The first parameter in (`from`, `to`) at which `inside` holds, marched in steps of `step`
/// and refined by 60 bisections: the independent search the closed forms and marches of the
/// renderer are checked against (features thinner than a step are not seen).
pub fn first_entry(inside: impl Fn(f64) -> bool, from: f64, to: f64, step: f64) -> Option<f64> {
    let mut l = from;
    while l < to {
        if inside(l + step) {
            let (mut lo, mut hi) = (l, l + step);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if inside(mid) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            return Some(hi);
        }
        l += step;
    }
    None
}
