//! A pinhole camera's past light cone: the world-frame looking direction through each image
//! point, written once for one ray or several at a time (`Real`).

use super::Boost;
use crate::geometry::Real;
use glam::DVec3;

/// What a pinhole camera's looking directions need, for one ray or several at a time: a
/// backend that makes a packet's primary rays itself (`Accelerator::intersect_fan`) runs the
/// same arithmetic, so its rays are `CameraRays::ray`'s to the bit.
#[derive(Clone, Copy, Debug)]
pub struct Pinhole {
    /// focal length · forward, right and up: the camera's axes in its rest frame, the first
    /// scaled to the focal length in pixels.
    basis: [DVec3; 3],
    /// From the camera's rest frame into the world frame.
    to_world: Boost,
}

impl Pinhole {
    /// A camera whose axes (in its rest frame) are `basis` = (focal length in pixels ·
    /// forward, right, up), and which `to_world` boosts into the world frame.
    pub fn new(basis: [DVec3; 3], to_world: Boost) -> Self {
        Pinhole { basis, to_world }
    }

    /// The world-frame unit looking direction through the image point (u, v) pixels right of
    /// and above the image centre: toward it in the camera's frame, normalised, then boosted.
    #[inline(always)]
    pub(crate) fn look<R: Real>(&self, u: R, v: R) -> [R; 3] {
        let [f, r, w] = self.basis;
        let t = [
            R::splat(f.x) + u * R::splat(r.x) + v * R::splat(w.x),
            R::splat(f.y) + u * R::splat(r.y) + v * R::splat(w.y),
            R::splat(f.z) + u * R::splat(r.z) + v * R::splat(w.z),
        ];
        let inv = R::splat(1.0) / (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
        let a = [t[0] * inv, t[1] * inv, t[2] * inv];
        if self.to_world.is_identity() {
            return a;
        }
        let (d, s) = self.to_world.null_dir_lanes(a);
        [d[0] / s, d[1] / s, d[2] / s]
    }
}
