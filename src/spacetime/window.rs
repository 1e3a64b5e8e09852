//! A window of emission events: the slab of spacetime between two hyperplanes of simultaneity,
//! each the events of one time in one inertial frame. A worldline's segment is seen only at
//! emission events in its window (docs/physics.md §12.4, §12.7): between two uniform segments
//! the hyperplane is one of world time; where a segment of constant proper acceleration begins
//! or ends, it is the simultaneity of the frame moving with the body there.

use super::{Boost, Event, NullRay, Velocity};

/// The events at time `time` in the frame moving at `frame` (world frame: zero velocity).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Slice {
    frame: Velocity,
    boost: Boost,
    /// The time, in `frame` (±∞: no bound).
    pub time: f64,
}

impl Slice {
    /// The events of world time `time`.
    pub fn world(time: f64) -> Slice {
        Slice::of(Velocity::ZERO, time)
    }

    /// The events of time `time` in the frame moving at `frame`.
    pub fn of(frame: Velocity, time: f64) -> Slice {
        Slice {
            frame,
            boost: Boost::to_rest(&frame),
            time,
        }
    }

    /// The frame whose simultaneity it is.
    pub fn frame(&self) -> Velocity {
        self.frame
    }

    /// An event's time in this slice's frame.
    pub fn time_of(&self, e: Event) -> f64 {
        self.boost.event(e).t
    }

    /// The lookback at which `ray` crosses it: the frame's time along the ray falls as s λ,
    /// s = γ(1 + β·a) its lookback factor (exactly `origin.t − time` in the world frame).
    fn crossing(&self, ray: &NullRay) -> f64 {
        let at = self.time_of(ray.origin) - self.time;
        if self.boost.is_identity() {
            at
        } else {
            at / self.boost.null_dir(ray.dir).1
        }
    }

    fn key(&self) -> [u64; 5] {
        let [a, b, c, d] = self.frame.identity_key();
        [a, b, c, d, self.time.to_bits()]
    }
}

/// The events between two slices: at or after `from`, at or before `to`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Window {
    /// The earliest events.
    pub from: Slice,
    /// The latest events.
    pub to: Slice,
}

impl Window {
    /// The events of world times `from..=to`.
    pub fn world(from: f64, to: f64) -> Window {
        Window {
            from: Slice::world(from),
            to: Slice::world(to),
        }
    }

    /// Whether `e` lies in it.
    pub fn contains(&self, e: Event) -> bool {
        self.from.time_of(e) >= self.from.time && self.to.time_of(e) <= self.to.time
    }

    /// Its two times, where both its slices are of world time (then a ray's crossings are
    /// `origin.t − time`, with no boost).
    pub fn world_times(&self) -> Option<(f64, f64)> {
        (self.from.boost.is_identity() && self.to.boost.is_identity())
            .then_some((self.from.time, self.to.time))
    }

    /// [`Window::lookbacks`] of a window of world times `(from, to)` (`world_times`): the
    /// same numbers, without the slices' boosts.
    #[inline(always)]
    pub fn lookbacks_in_world_times(
        (from, to): (f64, f64),
        ray: &NullRay,
        tmin: f64,
        tmax: f64,
    ) -> Option<(f64, f64)> {
        let (lo, hi) = (tmin.max(ray.origin.t - to), tmax.min(ray.origin.t - from));
        (lo < hi).then_some((lo, hi))
    }

    /// The lookbacks (lo, hi) between which `ray`'s events lie in it, within (tmin, tmax);
    /// None where none do.
    pub fn lookbacks(&self, ray: &NullRay, tmin: f64, tmax: f64) -> Option<(f64, f64)> {
        let (lo, hi) = (
            tmin.max(self.to.crossing(ray)),
            tmax.min(self.from.crossing(ray)),
        );
        (lo < hi).then_some((lo, hi))
    }

    /// The same window moved by the spacetime translation `shift`.
    pub fn translated(&self, shift: Event) -> Window {
        let moved = |s: &Slice| Slice {
            time: s.time + s.boost.event(shift).t,
            ..*s
        };
        Window {
            from: moved(&self.from),
            to: moved(&self.to),
        }
    }

    /// A key equal for windows that are exactly the same (groups with one velocity and one
    /// window share one rest-frame scene).
    pub fn key(&self) -> [u64; 10] {
        let mut k = [0; 10];
        k[..5].copy_from_slice(&self.from.key());
        k[5..].copy_from_slice(&self.to.key());
        k
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A window of world times gives the same lookbacks without its boosts, to the bit; one
    /// with either end in a moving frame has no world times.
    #[test]
    fn world_times_give_the_same_lookbacks() {
        let mut rng = crate::rng::Rng(0x71fe);
        let v = Velocity::from_beta_vec(DVec3::new(0.6, 0.3, 0.0)).unwrap();
        for (from, to) in [
            (Slice::world(-4.0), Slice::of(v, 2.5)),
            (Slice::of(v, -4.0), Slice::world(2.5)),
        ] {
            assert_eq!(Window { from, to }.world_times(), None);
        }
        for (from, to) in [
            (-40.0, -20.0),
            (f64::NEG_INFINITY, -40.0),
            (1.0, f64::INFINITY),
        ] {
            let w = Window::world(from, to);
            let times = w.world_times().expect("world times");
            for _ in 0..2000 {
                let ray = NullRay::new(
                    Event::new(
                        rng.range(-50.0, 50.0),
                        DVec3::new(rng.range(-9.0, 9.0), 0.0, 1.0),
                    ),
                    rng.unit(),
                );
                let tmin = rng.range(0.0, 5.0);
                let tmax = if rng.f() < 0.5 {
                    f64::INFINITY
                } else {
                    rng.range(5.0, 90.0)
                };
                let fast = Window::lookbacks_in_world_times(times, &ray, tmin, tmax);
                let slow = w.lookbacks(&ray, tmin, tmax);
                assert_eq!(
                    fast.map(|(a, b)| (a.to_bits(), b.to_bits())),
                    slow.map(|(a, b)| (a.to_bits(), b.to_bits()))
                );
            }
        }
    }

    /// A ray's lookbacks in a window are where its events lie in it, in any frame.
    #[test]
    fn lookbacks_bound_the_events_inside() {
        let v = Velocity::from_beta_vec(DVec3::new(0.6, 0.3, 0.0)).unwrap();
        let w = Window {
            from: Slice::world(-4.0),
            to: Slice::of(v, 2.5),
        };
        let ray = NullRay::new(
            Event::new(10.0, DVec3::new(1.0, -2.0, 0.5)),
            DVec3::new(0.6, 0.0, -0.8),
        );
        let (lo, hi) = w.lookbacks(&ray, 0.0, f64::INFINITY).unwrap();
        for (lambda, inside) in [
            (lo - 1e-6, false),
            (lo + 1e-6, true),
            (0.5 * (lo + hi), true),
            (hi - 1e-6, true),
            (hi + 1e-6, false),
        ] {
            assert_eq!(w.contains(ray.at(lambda)), inside, "λ = {lambda}");
        }
        // In the world frame, exactly origin.t − time.
        assert_eq!(hi, 14.0);
        assert!((Slice::of(v, 2.5).time_of(ray.at(lo)) - 2.5).abs() < 1e-12);
    }

    #[test]
    fn translated_windows_hold_the_translated_events() {
        let v = Velocity::from_beta_vec(DVec3::new(-0.8, 0.0, 0.1)).unwrap();
        let w = Window {
            from: Slice::of(v, -1.0),
            to: Slice::of(v, 3.0),
        };
        let shift = Event::new(7.0, DVec3::new(-3.0, 2.0, 1.0));
        let moved = w.translated(shift);
        for t in [-5.0, -1.0, 0.0, 1.0, 2.9, 4.0, 9.0] {
            let e = Event::new(t, DVec3::new(0.3 * t, 1.0, -0.2));
            assert_eq!(w.contains(e), moved.contains(e + shift), "t = {t}");
        }
    }
}
