//! Hyperbolic motion: constant proper acceleration `a` along a fixed direction of the frame the
//! motion starts at rest in (docs/physics.md §12.7). In that frame S', from the start event, the
//! point is at `(sinh θ / a, (cosh θ − 1)/a · â)` at rapidity θ = a τ (τ its proper time): the
//! hyperbola whose asymptotes, the horizon, lie 1/a behind it. A body whose points hold their
//! distances in the frame moving with it (Born-rigid) is the same figure scaled about the
//! horizon: a point ξ ahead along â keeps `ρ = 1/a + ξ` from it at every θ.

use super::{Boost, Event, Velocity};
use glam::DVec3;

/// A reference point's hyperbolic motion from a start event at a start velocity.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Hyperbola {
    /// Where it starts (world frame).
    pub start: Event,
    /// The velocity at the start (world frame): S' moves at it.
    pub v0: Velocity,
    /// The proper acceleration, a > 0.
    pub a: f64,
    /// The unit direction of the acceleration, in S'.
    pub axis: DVec3,
}

/// 2 sinh²(θ/2) = cosh θ − 1, exact for small θ.
pub fn cosh_m1(theta: f64) -> f64 {
    let s = (0.5 * theta).sinh();
    2.0 * s * s
}

impl Hyperbola {
    /// From the start event and velocity and the proper acceleration vector (in S'); None if
    /// that vector is zero or not finite.
    pub fn new(start: Event, v0: Velocity, acceleration: DVec3) -> Option<Hyperbola> {
        let a = acceleration.length();
        (a > 0.0 && a.is_finite()).then(|| Hyperbola {
            start,
            v0,
            a,
            axis: acceleration / a,
        })
    }

    /// The boost into S'.
    pub fn to_start_frame(&self) -> Boost {
        Boost::to_rest(&self.v0)
    }

    /// The event at rapidity θ, relative to the start, in S'.
    pub fn in_start_frame(&self, theta: f64) -> Event {
        Event::new(theta.sinh() / self.a, cosh_m1(theta) / self.a * self.axis)
    }

    /// The event at rapidity θ (world frame).
    pub fn event(&self, theta: f64) -> Event {
        self.start + Boost::from_rest(&self.v0).event(self.in_start_frame(theta))
    }

    /// The velocity at rapidity θ (world frame): its 4-velocity `(cosh θ, sinh θ â)` in S',
    /// boosted out; the rapidity from γβ, exact near the speed of light.
    pub fn velocity(&self, theta: f64) -> Velocity {
        let u =
            Boost::from_rest(&self.v0).event(Event::new(theta.cosh(), theta.sinh() * self.axis));
        let gb = u.x.length();
        if gb == 0.0 {
            return Velocity::ZERO;
        }
        Velocity::from_rapidity(u.x, gb.asinh()).unwrap_or(Velocity::ZERO)
    }

    /// The turn of the axes (from the plain boost's to its velocity) that the motion to
    /// rapidity θ brings: the Thomas-Wigner rotation of v₀ and the velocity tanh θ â added in
    /// S' (docs/physics.md §1.4, §12.7); the identity along v₀.
    pub fn wigner(&self, theta: f64) -> glam::DMat3 {
        match Velocity::from_rapidity(self.axis, theta) {
            Ok(u) => super::wigner_rotation(&self.v0, &u),
            Err(_) => glam::DMat3::IDENTITY,
        }
    }

    /// The rapidity at which its world time is `t`: with b = β₀·â and k = a (t − t₀)/γ₀,
    /// `sinh θ + b (cosh θ − 1) = k`, a quadratic in e^θ; e^θ − 1 is formed without
    /// cancellation, so tiny accelerations keep their digits.
    pub fn theta_at(&self, t: f64) -> f64 {
        let (beta, c) = (self.v0.beta(), self.v0.direction().dot(self.axis));
        // 1 ± b from 1 − β where b is near ∓1 (a speed near c along ∓â), exact there.
        let om = self.v0.one_minus_beta();
        let one_plus_b = if c < 0.0 {
            om + beta * (1.0 + c)
        } else {
            1.0 + beta * c
        };
        let one_minus_b = if c > 0.0 {
            om + beta * (1.0 - c)
        } else {
            1.0 - beta * c
        };
        let b = beta * c;
        let k = self.a * (t - self.start.t) / self.v0.gamma();
        let big_b = b + k;
        let s = (big_b * big_b + one_minus_b * one_plus_b).sqrt();
        // e^θ = u, the root of (1 + b)u² − 2Bu − (1 − b) = 0 that is positive, in the form
        // that subtracts nothing; and u − 1 = k(1 + u)/(S + 1) (as S² − 1 = k(2b + k)).
        let u = if big_b >= 0.0 {
            (s + big_b) / one_plus_b
        } else {
            one_minus_b / (s - big_b)
        };
        (k * (1.0 + u) / (s + 1.0)).ln_1p()
    }

    /// The world time at rapidity θ.
    pub fn time(&self, theta: f64) -> f64 {
        self.event(theta).t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Vec<Hyperbola> {
        let v = |b: DVec3| Velocity::from_beta_vec(b).unwrap();
        vec![
            Hyperbola::new(Event::ORIGIN, Velocity::ZERO, DVec3::new(0.5, 0.0, 0.0)).unwrap(),
            Hyperbola::new(
                Event::new(2.0, DVec3::new(1.0, 2.0, 3.0)),
                v(DVec3::new(0.6, 0.0, 0.0)),
                DVec3::new(-2.0, 0.0, 0.0),
            )
            .unwrap(),
            Hyperbola::new(
                Event::new(-1.0, DVec3::ZERO),
                v(DVec3::new(0.3, -0.7, 0.2)),
                DVec3::new(0.1, 0.4, -0.3),
            )
            .unwrap(),
            Hyperbola::new(Event::ORIGIN, v(DVec3::new(0.0, 0.9, 0.0)), DVec3::X * 1e-9).unwrap(),
        ]
    }

    /// Its 4-velocity is the derivative of its events, unit, and its proper time is θ/a.
    #[test]
    fn moves_at_its_velocity_with_proper_acceleration_a() {
        for h in sample() {
            for theta in [-0.7, 0.0, 0.3, 1.5, 3.0] {
                let dtheta = 1e-6;
                let (e0, e1) = (h.event(theta - dtheta), h.event(theta + dtheta));
                let d = e1 - e0;
                let v = h.velocity(theta);
                let beta = d.x / d.t;
                assert!((beta - v.beta_vec()).length() < 1e-7, "{h:?} θ {theta}");
                // dτ = dθ / a: the interval over 2 dθ.
                let tau = d.interval().sqrt();
                assert!((tau * h.a / (2.0 * dtheta) - 1.0).abs() < 1e-6, "{h:?}");
                // The acceleration in the comoving frame is a: the change of rapidity.
                let v2 = h.velocity(theta + 1e-3);
                let rel =
                    Boost::to_rest(&v).event(Event::new(v2.gamma(), v2.beta_vec() * v2.gamma()));
                let drap = rel.x.length().asinh();
                assert!((drap / 1e-3 - 1.0).abs() < 1e-6, "{h:?} θ {theta}: {drap}");
            }
        }
    }

    #[test]
    fn theta_at_inverts_time() {
        // Braking from a speed near c along −â as well: 1 + b is 1 − β there.
        let braking = Hyperbola::new(
            Event::ORIGIN,
            Velocity::from_one_minus_beta(DVec3::X, 1e-12).unwrap(),
            DVec3::new(-0.3, 0.0, 0.0),
        )
        .unwrap();
        for h in sample().into_iter().chain([braking]) {
            for theta in [-2.0, -0.3, -1e-7, 0.0, 1e-8, 0.25, 1.0, 4.0] {
                let t = h.time(theta);
                let back = h.theta_at(t);
                assert!(
                    (back - theta).abs() <= 1e-12 * theta.abs().max(1e-300) + 1e-15,
                    "{h:?}: θ {theta} → t {t} → {back}"
                );
            }
        }
        // A tiny acceleration keeps the uniform motion's times to the digits it has.
        let h = sample()[3];
        let t = 10.0;
        let theta = h.theta_at(t);
        let g = h.v0.gamma();
        assert!((theta - h.a * t / g).abs() < 1e-12 * h.a * t, "{theta}");
    }
}
