//! Helpers shared by the integration tests.
#![allow(dead_code)]

use glam::DVec3;

/// A small deterministic generator for property tests (splitmix64).
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn f(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.f()
    }
    pub fn unit(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }
}

pub fn assert_close(a: f64, b: f64, tol: f64, what: &str) {
    assert!(
        (a - b).abs() <= tol,
        "{what}: got {a}, expected {b} (tolerance {tol})"
    );
}

pub fn assert_rel(a: f64, b: f64, rel: f64, what: &str) {
    assert!(
        ((a - b) / b).abs() <= rel,
        "{what}: got {a}, expected {b} (relative tolerance {rel})"
    );
}

/// The physics cases of PHYSICS.md (a copy of shared/physics/cases.json).
pub fn cases() -> serde_json::Value {
    serde_json::from_str(include_str!("../data/cases.json")).expect("cases.json parses")
}
pub mod conformance;

use rest_embree::render::Frame;
use rest_embree::scene::Scene;

pub fn scene(toml: &str) -> Scene {
    rest_embree::scene::load_str("test.toml", toml, &[]).unwrap_or_else(|e| panic!("scene: {e}"))
}

pub fn render_with(scene: &Scene, backend: &str) -> Frame {
    let b = rest_embree::accel::backend_by_name(backend).unwrap();
    let (frame, stats) = rest_embree::render::render(scene, b.as_ref()).unwrap();
    assert_eq!(stats.nonfinite_pixels, 0, "no NaN or infinite pixel");
    frame
}

/// The backends of this build (every render test runs on each).
pub fn backends() -> Vec<&'static str> {
    rest_embree::accel::backend_names()
}

/// The vertical field of view, in degrees, that gives focal length `f` pixels at `height`.
pub fn fov_for_focal(f: f64, height: u32) -> f64 {
    2.0 * (0.5 * height as f64 / f).atan().to_degrees()
}
