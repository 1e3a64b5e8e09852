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
