use super::{Event, Velocity};
use glam::DVec3;

/// A passive Lorentz boost along any direction, evaluated in light-cone coordinates along the
/// boost axis (PHYSICS.md §8.2 item 4): `u = t − x∥`, `w = t + x∥`, `u' = e^{φ} u`, `w' = e^{−φ} w`,
/// `x⊥' = x⊥`. No step subtracts nearly equal numbers, so speeds like 1 − 1e-12 stay exact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Boost {
    axis: DVec3,
    e_pos: f64,
    e_neg: f64,
    identity: bool,
}

impl Boost {
    pub const IDENTITY: Boost = Boost {
        axis: DVec3::ZERO,
        e_pos: 1.0,
        e_neg: 1.0,
        identity: true,
    };

    /// The boost from a frame into the frame that moves at `v` relative to it
    /// (`X' = Λ(β) X`, PHYSICS.md §1.3).
    pub fn to_rest(v: &Velocity) -> Boost {
        if v.is_zero() {
            return Self::IDENTITY;
        }
        let phi = v.rapidity();
        Boost {
            axis: v.direction(),
            e_pos: phi.exp(),
            e_neg: (-phi).exp(),
            identity: false,
        }
    }

    /// The boost out of the frame moving at `v` back into the frame `v` is measured in.
    pub fn from_rest(v: &Velocity) -> Boost {
        Self::to_rest(&v.reversed())
    }

    pub fn inverse(&self) -> Boost {
        if self.identity {
            return *self;
        }
        Boost {
            axis: self.axis,
            e_pos: self.e_neg,
            e_neg: self.e_pos,
            identity: false,
        }
    }

    /// Transform an event (or any 4-vector).
    pub fn event(&self, e: Event) -> Event {
        if self.identity {
            return e;
        }
        let xp = e.x.dot(self.axis);
        let u = self.e_pos * (e.t - xp);
        let w = self.e_neg * (e.t + xp);
        let xp_new = 0.5 * (w - u);
        Event::new(0.5 * (u + w), e.x + (xp_new - xp) * self.axis)
    }

    /// Transform the past-directed null vector `(−1, a)` with `a` a unit vector. Returns the
    /// spatial part `d'` (unnormalised) and `s = −t' = |d'|`, the factor by which the frame's
    /// lookback time exceeds the original one: for a boost into a frame moving at β,
    /// `s = γ(1 + β·a)` (DESIGN.md, "the one trick").
    pub fn null_dir(&self, a: DVec3) -> (DVec3, f64) {
        if self.identity {
            return (a, 1.0);
        }
        let ap = a.dot(self.axis);
        let perp = a - ap * self.axis;
        let p2 = perp.length_squared();
        // 1 ± a∥ without cancellation (|a| = 1).
        let one_plus = if ap >= 0.0 { 1.0 + ap } else { p2 / (1.0 - ap) };
        let one_minus = if ap <= 0.0 { 1.0 - ap } else { p2 / (1.0 + ap) };
        let up = self.e_pos * one_plus;
        let wp = self.e_neg * one_minus;
        let s = 0.5 * (up + wp);
        let par = 0.5 * (up - wp);
        (perp + par * self.axis, s)
    }

    /// The unit direction of a null ray after the boost, and the factor `s` of [`Boost::null_dir`].
    pub fn view_dir(&self, a: DVec3) -> (DVec3, f64) {
        if self.identity {
            return (a, 1.0);
        }
        let (d, s) = self.null_dir(a);
        (d / s, s)
    }
}
