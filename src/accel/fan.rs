//! A packet of primary rays handed to a backend as what makes them rather than as rays: the
//! pinhole camera, the boost into the group's rest frame, the imaging event there and the
//! lanes' image points. A backend with a path of its own (Embree's: camera, boost and packet
//! four lanes per AVX2 vector, `embree/fan_kernel.rs`) makes, boosts and traces them at once; its rays
//! are the renderer's to the bit, because both run the same arithmetic (`Pinhole::look`,
//! `Boost::null_dir_lanes`), so images do not depend on which path served them.

use crate::geometry::PACKET;
use crate::spacetime::{Boost, Pinhole};
use glam::DVec3;

/// Up to PACKET primary rays of one tile, as one group sees them.
pub struct Fan<'a> {
    /// The camera's looking directions (world frame).
    pub camera: &'a Pinhole,
    /// From the world frame into the group's rest frame.
    pub to_rest: &'a Boost,
    /// The imaging event's position in the group's rest frame, where every ray starts.
    pub origin: DVec3,
    /// The lanes' image points, pixels right of the image centre.
    pub u: [f64; PACKET],
    /// The lanes' image points, pixels above the image centre.
    pub v: [f64; PACKET],
    /// How many lanes are in use (the first `n`).
    pub n: usize,
}

/// `FanHits::prim` of a lane without a hit.
pub(crate) const NO_HIT: u32 = u32::MAX;

/// What a fan's rays are and found, by lane, in columns: the world-frame unit looking
/// direction, the rest-frame direction (unnormalised, of length `s`, the lookback factor) and
/// the closest hit for lookback in (0, ∞): `t` and the primitive (NO_HIT for none).
pub struct FanHits {
    /// World-frame unit looking direction, by axis then lane.
    pub look: [[f64; PACKET]; 3],
    /// Rest-frame direction (unnormalised), by axis then lane.
    pub dir: [[f64; PACKET]; 3],
    /// The lookback factor, the length of `dir`.
    pub s: [f64; PACKET],
    /// Lookback time of the closest hit.
    pub t: [f64; PACKET],
    /// The primitive hit, or [`NO_HIT`].
    pub prim: [u32; PACKET],
}

impl Default for FanHits {
    fn default() -> Self {
        FanHits {
            look: [[0.0; PACKET]; 3],
            dir: [[0.0; PACKET]; 3],
            s: [0.0; PACKET],
            t: [0.0; PACKET],
            prim: [NO_HIT; PACKET],
        }
    }
}
