//! A group's bounds as they move through the world frame, for a test before the boost: whether
//! a world-frame null ray can meet them at all.
//!
//! Among many groups the trees over them (apparent_tree.rs, light_tree.rs) hand a ray the
//! groups whose boxes over a window of times it meets; most of those it then misses (10,000
//! moving boxes, 256²: 4.3 groups per primary ray, 0.8 met; 7.8 per shadow ray). Each costs a
//! boost into the group's frame before its bounds reject the ray. Here the ray is tested in the
//! world frame instead: the group's rest-frame bounds, contracted along v, lie at world time t
//! within `at_ref + v (t − t_ref)` (`world_box`). The ray is at x = o + λ d at time t_o − λ, so
//! it meets that moving box at lookback λ where o − v (t_o − t_ref) + λ (d + v) lies in
//! `at_ref`: a slab test on a static box, with no boost.
//!
//! The same test widened over a chunk of rays (`may_meet_any`, by interval arithmetic over
//! their origins, directions and lookbacks) lets a packet that passes beside a group, or
//! beside where a worldline's segment is during its window, skip the group's boosts at once.

use super::group_tree::world_box;
use crate::geometry::Aabb;
use crate::spacetime::{NullRay, Velocity};
use glam::DVec3;

/// Relative slack for rounding (positions and lookback times): the test must never reject a
/// ray the exact bounds would keep, and a little more kept only costs a boost.
const SLACK: f64 = 1e-9;

/// Groups faster than 1 − β = this have no world-frame test (every ray goes on to the boost).
/// Near c a ray riding along with a group has d + v of ~1 − β, which the f64 β and d carry
/// only to ~2e-16 / (1 − β) relative, and over its long ride (a lookback of ~1/(1 − β)) that
/// moves it sideways by as much relative to its distance: below the slack only for
/// 1 − β ≳ 2e-6. (At 1 − β = 1e-12 such rays were turned away from groups they meet; the boost
/// works with the rapidity instead, docs/physics.md §8.)
const MIN_ONE_MINUS_BETA: f64 = 1e-5;

#[derive(Clone, Copy, Debug)]
pub struct MovingBounds {
    /// The world-frame box at time `t_ref` of the group's bounds; its largest |coordinate|.
    at_ref: Aabb,
    scale: f64,
    /// The group's velocity (units of c); None at rest (the world-frame test is then the
    /// bounds test itself, which the caller makes anyway) and near c (`MIN_ONE_MINUS_BETA`).
    v: Option<DVec3>,
    t_ref: f64,
}

impl MovingBounds {
    /// Rest-frame bounds `rest` moving at `v`, about world time `t_ref` (the imaging event's:
    /// the rays' events lie near it, which keeps the numbers small).
    pub fn new(rest: &Aabb, v: &Velocity, t_ref: f64) -> Self {
        let at_ref = world_box(rest, v, t_ref);
        MovingBounds {
            at_ref,
            scale: at_ref.max_abs(),
            v: (!v.is_zero() && v.one_minus_beta() >= MIN_ONE_MINUS_BETA).then(|| v.beta_vec()),
            t_ref,
        }
    }

    /// Whether the ray may meet the bounds at a lookback in [tmin, tmax]: false only where it
    /// cannot (up to rounding far below the slack).
    #[inline]
    pub fn may_meet(&self, ray: &NullRay, tmin: f64, tmax: f64) -> bool {
        let Some(v) = self.v else {
            return true;
        };
        let o = ray.origin.x - v * (ray.origin.t - self.t_ref);
        let pad = SLACK * (1.0 + self.scale + o.abs().max_element());
        let b = Aabb::new(self.at_ref.min - pad, self.at_ref.max + pad);
        let (lo, hi) = (
            tmin - SLACK * (1.0 + tmin.abs()),
            tmax + SLACK * (1.0 + tmax.abs()),
        );
        b.clip(o, (ray.dir + v).recip(), lo, hi).is_some()
    }
}

/// What a chunk of rays spans: per axis the least and greatest origin and direction, and the
/// least and greatest origin time (`MovingBounds::may_meet_any`).
#[derive(Clone, Copy, Debug)]
pub struct RaySpan {
    x: Aabb,
    d: Aabb,
    t: (f64, f64),
}

impl RaySpan {
    /// The span of `rays` (at least one).
    pub fn of(rays: &[NullRay]) -> RaySpan {
        let (mut x, mut d) = (Aabb::EMPTY, Aabb::EMPTY);
        let mut t = (f64::INFINITY, f64::NEG_INFINITY);
        for r in rays {
            x.grow(r.origin.x);
            d.grow(r.dir);
            t = (t.0.min(r.origin.t), t.1.max(r.origin.t));
        }
        RaySpan { x, d, t }
    }
}

/// λ w for a lookback λ in [0, ∞] and a component w of d + v: 0 where w is (for every λ).
#[inline]
fn reach(lambda: f64, w: f64) -> f64 {
    if w == 0.0 {
        0.0
    } else {
        lambda * w
    }
}

impl MovingBounds {
    /// Whether any ray of `span` may meet the bounds at a lookback in [lo, hi] (0 ≤ lo ≤ hi,
    /// hi perhaps ∞): false only where none can. The set `may_meet` tests ray by ray,
    /// o − v (t_o − t_ref) + λ (d + v), widened to a box by interval arithmetic over the
    /// span's origins, times and directions and the lookbacks: one test for a chunk of rays
    /// (a packet of primary rays shares its origin, and its directions lie close), which a
    /// chunk that misses the group's moving bounds takes instead of a boost per ray.
    pub fn may_meet_any(&self, span: &RaySpan, lo: f64, hi: f64) -> bool {
        let Some(v) = self.v else {
            return true;
        };
        // λ ≥ 0 below (lookbacks); anything else is kept.
        if lo.is_nan() || lo < 0.0 {
            return true;
        }
        let (ta, tb) = (span.t.0 - self.t_ref, span.t.1 - self.t_ref);
        for k in 0..3 {
            let vk = v[k];
            let (va, vb) = (vk * ta, vk * tb);
            let (vmin, vmax) = if va < vb { (va, vb) } else { (vb, va) };
            // The origins as seen against the box at t_ref: x − v (t − t_ref).
            let (xmin, xmax) = (span.x.min[k], span.x.max[k]);
            let (p, q) = (xmin - vmax, xmax - vmin);
            // λ w over λ in [lo, hi] and w in [a, b] (λ ≥ 0): least at lo a where a ≥ 0, else
            // at hi a; greatest at hi b where b ≥ 0, else at lo b. Finite, or ∞ away from
            // the box on that side only.
            let (a, b) = (span.d.min[k] + vk, span.d.max[k] + vk);
            let near = if a >= 0.0 { reach(lo, a) } else { reach(hi, a) };
            let far = if b >= 0.0 { reach(hi, b) } else { reach(lo, b) };
            // The rounding of every term, far below the slack. Where the positions' end
            // toward the box is infinite, so is its pad, and that test turns nothing away.
            let common = 1.0 + self.scale + vmin.abs().max(vmax.abs());
            let below = q + far < self.at_ref.min[k] - SLACK * (common + xmax.abs() + far.abs());
            let above = p + near > self.at_ref.max[k] + SLACK * (common + xmin.abs() + near.abs());
            if below || above {
                return false;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::spacetime::{Boost, Event};

    /// Whether the ray boosted into the group's frame meets the rest-frame bounds in
    /// [tmin, tmax] of world lookback (as `World::rest_ray` tests it).
    fn meets_in_rest_frame(rest: &Aabb, v: &Velocity, ray: &NullRay, tmin: f64, tmax: f64) -> bool {
        let boost = Boost::to_rest(v);
        let o = boost.event(ray.origin).x;
        let (d, _) = boost.null_dir(ray.dir);
        rest.clip(o, d.recip(), tmin, tmax).is_some()
    }

    /// Never rejects a ray that meets the bounds, and rejects most that do not: random boxes,
    /// velocities up to 1 − 1e-9, rays from random events toward and past the boxes, and at
    /// large times.
    #[test]
    fn keeps_every_ray_that_meets_the_bounds() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut met, mut rejected, mut missed) = (0, 0, 0);
        for case in 0..40_000 {
            let c = DVec3::new(
                rng.range(-50.0, 50.0),
                rng.range(-50.0, 50.0),
                rng.range(-50.0, 50.0),
            );
            let h = DVec3::new(
                rng.range(0.1, 3.0),
                rng.range(0.1, 3.0),
                rng.range(0.1, 3.0),
            );
            let rest = Aabb::new(c - h, c + h);
            let v = match case % 4 {
                0 => Velocity::from_beta(rng.unit(), rng.range(0.0, 0.5)),
                1 => Velocity::from_beta(rng.unit(), rng.range(0.5, 0.99)),
                2 => Velocity::from_one_minus_beta(rng.unit(), 10f64.powf(-rng.range(2.0, 12.0))),
                _ => Velocity::from_beta(rng.unit(), rng.range(0.0, 0.9)),
            }
            .expect("below c");
            let beta = v.beta();
            let t_ref = if case % 8 == 7 { 1e9 } else { 120.0 };
            let bounds = MovingBounds::new(&rest, &v, t_ref);
            // A ray from an event near t_ref, aimed at where the group is seen from it or
            // anywhere.
            let t = t_ref - rng.range(0.0, 200.0);
            let x = DVec3::new(
                rng.range(-150.0, 150.0),
                rng.range(-150.0, 150.0),
                rng.range(-150.0, 150.0),
            );
            let ray_event = Event::new(t, x);
            let rest_event = Boost::to_rest(&v).event(ray_event).x;
            let dir = if case % 2 == 0 {
                // Toward a point of the bounds, in the rest frame, brought back to the world.
                let p = c + h * DVec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                let rest_dir = (p - rest_event).normalize();
                Boost::to_rest(&v).inverse().view_dir(rest_dir).0
            } else {
                rng.unit()
            };
            let ray = NullRay::new(ray_event, dir);
            let (tmin, tmax) = if case % 3 == 0 {
                (0.0, f64::INFINITY)
            } else {
                (rng.range(0.0, 50.0), rng.range(50.0, 400.0))
            };
            let meets = meets_in_rest_frame(&rest, &v, &ray, tmin, tmax);
            let kept = bounds.may_meet(&ray, tmin, tmax);
            assert!(
                kept || !meets,
                "case {case}: a ray that meets the bounds was rejected (β = {beta})"
            );
            match (meets, kept) {
                (true, _) => met += 1,
                (false, false) => rejected += 1,
                (false, true) => missed += 1,
            }
        }
        assert!(met > 5_000, "too few rays met the bounds: {met}");
        assert!(
            rejected > 4 * missed,
            "the test should reject most misses: {rejected} rejected, {missed} kept"
        );
    }

    /// A chunk's test never turns away a chunk with a ray that meets the bounds in the
    /// lookbacks given, and turns away most chunks that miss: chunks of eight rays from one
    /// event (a packet of primary rays, directions within a small cone) or from events
    /// scattered about one, at speeds up to 1 − 1e-5, with finite and unbounded lookbacks.
    #[test]
    fn a_chunk_is_kept_if_any_ray_meets_the_bounds() {
        let mut rng = Rng(0x0dd_c0ffee);
        let (mut met, mut rejected, mut missed) = (0, 0, 0);
        for case in 0..20_000 {
            let c = DVec3::new(
                rng.range(-40.0, 40.0),
                rng.range(-40.0, 40.0),
                rng.range(-40.0, 40.0),
            );
            let h = DVec3::new(
                rng.range(0.1, 4.0),
                rng.range(0.1, 4.0),
                rng.range(0.1, 4.0),
            );
            let rest = Aabb::new(c - h, c + h);
            let v = match case % 3 {
                0 => Velocity::from_beta(rng.unit(), rng.range(0.0, 0.9)),
                1 => Velocity::from_beta(rng.unit(), rng.range(0.9, 0.999)),
                _ => Velocity::from_one_minus_beta(rng.unit(), 10f64.powf(-rng.range(3.0, 5.0))),
            }
            .expect("below c");
            // Late in a long film in one case of seven: large times, the group and the events
            // far from the origin (where it has moved to by then).
            let t_ref = if case % 7 == 6 { 1e6 } else { 30.0 };
            let bounds = MovingBounds::new(&rest, &v, t_ref);
            let centre = Event::new(
                t_ref - rng.range(0.0, 30.0),
                v.beta_vec() * t_ref
                    + DVec3::new(
                        rng.range(-80.0, 80.0),
                        rng.range(-80.0, 80.0),
                        rng.range(-80.0, 80.0),
                    ),
            );
            // The first ray toward a corner of the bounds or a point of an edge, as seen from
            // the event (it may meet them there alone), or anywhere; the others about it.
            let aim = if case % 2 == 0 {
                let mut p = DVec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                let free = (rng.f() * 3.0) as usize % 3;
                for k in 0..3 {
                    if case % 4 == 0 || k != free {
                        p[k] = p[k].signum();
                    }
                }
                let rest_event = Boost::to_rest(&v).event(centre).x;
                let rest_dir = (c + h * p - rest_event).normalize();
                Boost::to_rest(&v).inverse().view_dir(rest_dir).0
            } else {
                rng.unit()
            };
            let spread = [0.003, 0.03, 0.3][case % 3];
            let scattered = case % 8 >= 5;
            let rays: Vec<NullRay> = (0..8)
                .map(|j| {
                    if j == 0 {
                        return NullRay::new(centre, aim);
                    }
                    let origin = if scattered {
                        Event::new(centre.t - rng.range(0.0, 2.0), centre.x + 2.0 * rng.unit())
                    } else {
                        centre
                    };
                    NullRay::new(origin, (aim + spread * rng.unit()).normalize())
                })
                .collect();
            // Where the first ray crosses the bounds, in lookback.
            let crossing = {
                let boost = Boost::to_rest(&v);
                let (d, _) = boost.null_dir(rays[0].dir);
                rest.clip(boost.event(rays[0].origin).x, d.recip(), 0.0, f64::INFINITY)
            };
            let (lo, hi) = match (case % 5, crossing) {
                (0, _) => (0.0, f64::INFINITY),
                (1, _) => (rng.range(0.0, 40.0), f64::INFINITY),
                // Lookbacks that end just after the first ray enters the bounds, or begin just
                // before it leaves them: it meets them in a sliver at one end.
                (2, Some((t0, _))) => (0.0, t0 + 1e-6 * (1.0 + t0)),
                (3, Some((_, t1))) => ((t1 - 1e-6 * (1.0 + t1)).max(0.0), f64::INFINITY),
                _ => {
                    let a = rng.range(0.0, 150.0);
                    (a, a + rng.range(0.5, 60.0))
                }
            };
            let meets = rays
                .iter()
                .any(|r| meets_in_rest_frame(&rest, &v, r, lo, hi));
            let kept = bounds.may_meet_any(&RaySpan::of(&rays), lo, hi);
            assert!(
                kept || !meets,
                "case {case}: a chunk with a ray that meets the bounds was turned away"
            );
            match (meets, kept) {
                (true, _) => met += 1,
                (false, false) => rejected += 1,
                (false, true) => missed += 1,
            }
        }
        assert!(met > 2_000, "too few chunks met the bounds: {met}");
        assert!(
            rejected > 2 * missed,
            "the test should turn away most chunks that miss: {rejected} turned away, {missed} kept"
        );
    }

    /// The hardest rays near c: nearly along the group's motion (d + v small, so a ray crosses
    /// the contracted box over a lookback of ~1/(1 − β)), aimed in the rest frame at points of
    /// the bounds from up to 60 box sizes ahead in the world frame (60 γ in the rest frame),
    /// through its faces. Fails at 1 − β = 1e-12 without `MIN_ONE_MINUS_BETA` (tried).
    #[test]
    fn keeps_rays_that_ride_along_with_the_group_near_c() {
        let mut rng = Rng(0x5eed_1e55);
        let rest = Aabb::new(DVec3::new(-1.0, -1.5, -0.5), DVec3::new(1.0, 1.5, 0.5));
        for e in [1e-3, 1e-4, 2e-5, 1e-5, 1e-6, 1e-9, 1e-12] {
            let v = Velocity::from_one_minus_beta(DVec3::X, e).expect("below c");
            let boost = Boost::to_rest(&v);
            let bounds = MovingBounds::new(&rest, &v, 120.0);
            let mut met = 0;
            for case in 0..4_000 {
                // A rest-frame event ahead of the box along x (half of them as far ahead in the
                // world frame, where the box is contracted by γ), beside it in y or within its
                // section; a ray toward a point of the box (on its y face in half the cases),
                // brought back to the world.
                let far = if case % 4 < 2 { v.gamma() } else { 1.0 };
                let beside = case % 8 >= 4;
                let y = if beside {
                    rng.range(1.6, 4.0)
                } else {
                    rng.range(-1.4, 1.4)
                };
                let ahead = DVec3::new(rng.range(2.0, 60.0) * far, y, rng.range(-0.4, 0.4));
                let mut p = DVec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.5, 1.5),
                    rng.range(-0.5, 0.5),
                );
                if case % 2 == 0 {
                    p.y = 1.5;
                }
                let rest_dir = (p - ahead).normalize();
                // Its rest-frame time such that its world time is near t_ref, as a shading
                // point's would be: t = γ(τ + β x) (docs/physics.md §1.3).
                let t_world = 120.0 - rng.range(0.0, 50.0);
                let tau = t_world / v.gamma() - v.beta() * ahead.x;
                let rest_event = Event::new(tau, ahead);
                let world = boost.inverse();
                let ray = NullRay::new(world.event(rest_event), world.view_dir(rest_dir).0);
                let meets = meets_in_rest_frame(&rest, &v, &ray, 0.0, f64::INFINITY);
                met += usize::from(meets);
                assert!(
                    !meets || bounds.may_meet(&ray, 0.0, f64::INFINITY),
                    "1 − β = {e:e}, case {case}: a ray riding along was turned away"
                );
            }
            assert!(
                met > 1_000,
                "1 − β = {e:e}: too few rays met the bounds ({met})"
            );
        }
    }
}
