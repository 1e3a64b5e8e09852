//! The apparent (retarded) position of a uniformly moving point (docs/physics.md §2.1), in the
//! sign-split form that never subtracts nearly equal numbers.

use super::Velocity;
use glam::DVec3;

/// How long ago (camera time) a point moving at `v`, whose lab-simultaneous offset from the
/// camera at camera time 0 is `r0`, sent the light the camera receives at time 0: Δ with
/// |r0 − βΔ| = Δ.
pub fn retarded_delay(r0: DVec3, v: &Velocity) -> f64 {
    if v.is_zero() {
        return r0.length();
    }
    let b = v.beta_vec();
    let br = b.dot(r0);
    let g = v.gamma();
    // sqrt((β·r0)² + r0²/γ²): both terms ≥ 0, where r0² − |β × r0|² would cancel near β → 1.
    let root = (br * br + r0.length_squared() / (g * g)).sqrt();
    if br <= 0.0 {
        // γ² = cosh²φ, no cancellation: root and −β·r0 are both ≥ 0.
        g * g * (root - br)
    } else {
        r0.length_squared() / (br + root)
    }
}

/// Where the point appears: its position when it sent the light, r0 − βΔ.
pub fn retarded_position(r0: DVec3, v: &Velocity) -> DVec3 {
    r0 - v.beta_vec() * retarded_delay(r0, v)
}
