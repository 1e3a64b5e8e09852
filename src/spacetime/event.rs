use glam::DVec3;
use std::ops::{Add, Sub};

/// A spacetime event `(t, x)` in some inertial frame (c = 1).
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize)]
pub struct Event {
    /// Time.
    pub t: f64,
    /// Position.
    pub x: DVec3,
}

impl Event {
    /// The event (0, 0).
    pub const ORIGIN: Event = Event {
        t: 0.0,
        x: DVec3::ZERO,
    };

    /// The event at time `t`, position `x`.
    pub fn new(t: f64, x: DVec3) -> Self {
        Self { t, x }
    }

    /// The Minkowski interval `t² − |x|²` (signature + − − −).
    pub fn interval(&self) -> f64 {
        self.t * self.t - self.x.length_squared()
    }
}

impl Add for Event {
    type Output = Event;
    fn add(self, o: Event) -> Event {
        Event::new(self.t + o.t, self.x + o.x)
    }
}

impl Sub for Event {
    type Output = Event;
    fn sub(self, o: Event) -> Event {
        Event::new(self.t - o.t, self.x - o.x)
    }
}
