use super::{Boost, Event};
use glam::DVec3;

/// A past-directed null ray `E(λ) = origin + λ (−1, dir)`, λ ≥ 0: λ is the lookback time in the
/// frame the ray is written in, and `dir` (unit) is the looking direction, opposite to the
/// direction the light travels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NullRay {
    /// Where the ray starts looking back from (the imaging event, for a primary ray).
    pub origin: Event,
    /// The unit looking direction.
    pub dir: DVec3,
}

impl NullRay {
    /// The ray from `origin` looking along `dir` (unit).
    pub fn new(origin: Event, dir: DVec3) -> Self {
        Self { origin, dir }
    }

    /// The event at lookback time `lambda`.
    pub fn at(&self, lambda: f64) -> Event {
        Event::new(self.origin.t - lambda, self.origin.x + lambda * self.dir)
    }

    /// This ray written in another frame: origin and direction boosted, with the lookback time
    /// rescaled so the new ray's λ is again that frame's lookback time. Returns the ray and the
    /// factor `s` with `λ_new = s λ_old`.
    pub fn boosted(&self, b: &Boost) -> (NullRay, f64) {
        let (dir, s) = b.view_dir(self.dir);
        (NullRay::new(b.event(self.origin), dir), s)
    }
}
