//! Embree's path for fans of primary rays (`Accelerator::intersect_fan`): a packet's rays made,
//! boosted and written into Embree's f32 packet four lanes per AVX2 vector, from the camera,
//! the boost and the lanes' image points, then traced as `intersect16` (or, where the CPU has
//! no native 16-wide packets, as `intersect8` on each half) traces them.
//!
//! Made one by one, a primary ray runs a chain of square roots and divisions (the camera's
//! unit direction, the boost, the packet's unit direction) and goes through three layouts (the
//! world-frame ray, the rest-frame ray, Embree's lane): most of the layer's own cost per ray,
//! set beside bare Embree's (the bench's `embree no-fused` row). Here the same arithmetic
//! (`Pinhole::look`, `Boost::null_dir_lanes`, `lane_geometry`, each written once for one lane or
//! four) runs on columns, so every lane's values are the scalar path's to the bit and images do
//! not depend on which path made them (src/tests/fused_primary.rs); the columns (`FanHits`) are
//! what the renderer reads the rays and hits from (`render::PrimaryHits`).

use super::exact::Lanes;
use super::f64x4::F4;
use super::packet::{deactivate_from, flush_denormals, Query, Reused, Valid};
use super::{lane_geometry, scale, EmbreeAccel, MAX_UNNORMALISED};
use crate::accel::{Fan, FanHits, Ray, NO_HIT};
use crate::geometry::Real;
use crate::geometry::PACKET;
use embree_sys::*;
use glam::DVec3;

impl EmbreeAccel {
    /// Whether this accelerator traces fans: 16- or 8-wide packets, on a CPU with AVX2.
    pub(super) fn serves_fans(&self) -> bool {
        matches!(self.width, 8 | 16) && std::arch::is_x86_feature_detected!("avx2")
    }

    /// A fan's rays and hits; false for a fan of one ray, which (as `intersect` sends a single
    /// ray) goes through Embree's single-ray traversal the caller's way.
    pub(super) fn fan(&self, fan: &Fan, out: &mut FanHits) -> bool {
        if !self.serves_fans() || fan.n < 2 {
            return false;
        }
        flush_denormals();
        // SAFETY: the CPU has AVX2 (checked just now).
        unsafe {
            if self.width == 16 {
                self.fan16(fan, out, 0);
            } else {
                self.fan8(fan, out, 0);
                if fan.n > 8 {
                    self.fan8(fan, out, 8);
                }
            }
        }
        true
    }
}

/// The kernel for one N-wide packet of a fan's lanes `first..first + N`, in this thread's
/// packet `rh` (`Reused`: it writes the fields a query writes).
macro_rules! fan_packet {
    ($name:ident, $n:literal, $RayHitN:ident, $isect_q:ident) => {
        impl EmbreeAccel {
            #[target_feature(enable = "avx2")]
            unsafe fn $name(&self, fan: &Fan, out: &mut FanHits, first: usize) {
                $RayHitN::with(|rh| {
                    const N: usize = $n;
                    const { assert!(N % 4 == 0 && N <= PACKET) };
                    let n = fan.n.saturating_sub(first).min(N);
                    // Every lane's s lies within [1/stretch, stretch] but for rounding, which
                    // the margin below 16 covers: then `scale` is 1 in every lane.
                    let raw = fan.to_rest.max_stretch() <= MAX_UNNORMALISED - 1.0;
                    let splat = F4::splat;
                    let o = fan.origin - self.scene.center;
                    let (o, pullback) =
                        ([splat(o.x), splat(o.y), splat(o.z)], splat(self.pullback));
                    for c in (0..N).step_by(4) {
                        // Lanes c.. of the packet are lanes at.. of the fan.
                        let at = first + c;
                        let four = |x: &[f64; PACKET]| {
                            // SAFETY: this function runs with AVX2.
                            unsafe { F4::load(x[at..at + 4].try_into().expect("four lanes")) }
                        };
                        let look = fan.camera.look(four(&fan.u), four(&fan.v));
                        // As `World::rest_ray` boosts a primary ray, and `embree_ray` puts it in a
                        // lane.
                        let (dir, s) = if fan.to_rest.is_identity() {
                            (look, splat(1.0))
                        } else {
                            fan.to_rest.null_dir_lanes(look)
                        };
                        // |dir| is s (`Ray::len`); Embree traces dir as it is where `scale` says
                        // so: in every lane when the boost stretches no more than `raw` allows.
                        let (org, du, tnear) = if raw {
                            lane_geometry(o, dir, splat(1.0), splat(0.0), pullback)
                        } else {
                            lane_geometry(o, dir, scale(s), splat(0.0), pullback)
                        };
                        let f32s = |x: F4, col: &mut [f32; N]| {
                            x.store_f32((&mut col[c..c + 4]).try_into().expect("four lanes"))
                        };
                        f32s(org[0], &mut rh.ray.org_x);
                        f32s(org[1], &mut rh.ray.org_y);
                        f32s(org[2], &mut rh.ray.org_z);
                        f32s(du[0], &mut rh.ray.dir_x);
                        f32s(du[1], &mut rh.ray.dir_y);
                        f32s(du[2], &mut rh.ray.dir_z);
                        f32s(tnear, &mut rh.ray.tnear);
                        let f64s = |x: F4, col: &mut [f64; PACKET]| {
                            col[at..at + 4].copy_from_slice(&x.store())
                        };
                        for k in 0..3 {
                            f64s(look[k], &mut out.look[k]);
                            f64s(dir[k], &mut out.dir[k]);
                        }
                        f64s(s, &mut out.s);
                    }
                    // The rest-frame rays as `World::rest_ray` makes them (shifted by 0 along
                    // themselves), for the exact tests in the callbacks and the hits' read-back.
                    let rays: [Ray; N] = std::array::from_fn(|i| {
                        let d = &out.dir;
                        let dir = DVec3::new(d[0][first + i], d[1][first + i], d[2][first + i]);
                        Ray {
                            origin: fan.origin + 0.0 * dir,
                            dir,
                            tmin: 0.0,
                            tmax: f64::INFINITY,
                            len: out.s[first + i],
                        }
                    });
                    let lanes = Lanes::<N>::new(&rays[..n], self.pullback);
                    let mut valid = Valid([0i32; N]);
                    for i in 0..n {
                        rh.ray.tfar[i] = f32::INFINITY;
                        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
                        valid.0[i] = -1;
                    }
                    deactivate_from(&mut rh.ray, n);
                    let mut ctx = self.context(Query::Intersect, &rays[..n], &lanes);
                    // SAFETY: an N-wide packet with its valid mask (64-byte aligned), the scene and
                    // the context its user geometry expects.
                    unsafe { self.scene.rtc.$isect_q(&valid, ctx.raw(), rh) };
                    self.settle(&ctx);
                    if let Some(runs) = self.scene.exact_runs {
                        // Every hit exact, so as `to_hit` reads it (the callbacks record only
                        // a t in the rays' lookback (0, ∞)), but with no lookup and no branch on
                        // whether a lane hit: lanes hit or miss about at random, so the general
                        // read-back below mispredicts often.
                        for i in 0..n {
                            let t = ctx.exact_t(i);
                            let prim = runs.hit(rh.hit.geomID[i], rh.hit.primID[i]);
                            debug_assert!(prim.is_none() || (t > 0.0 && t < f64::INFINITY));
                            out.t[first + i] = t;
                            out.prim[first + i] = prim.unwrap_or(NO_HIT);
                        }
                        return;
                    }
                    // Every lane's primitive fetched first, then refined (`EmbreeAccel::fetch`).
                    let mut fetched = [None; N];
                    for (i, f) in fetched.iter_mut().enumerate().take(n) {
                        if rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID {
                            let (geom, prim) = (rh.hit.geomID[i], rh.hit.primID[i]);
                            *f = self.fetch(geom, prim, rh.hit.instID[0][i]);
                        }
                    }
                    for (i, ray) in rays.iter().enumerate().take(n) {
                        let hit = fetched[i].and_then(|f| {
                            self.refine(ray, rh.ray.tfar[i], f, ctx.exact_t(i), self.pullback)
                        });
                        // Written field by field: an Option copied whole went through the stack
                        // with loads that straddled its stores (a store-forwarding stall per lane).
                        out.prim[first + i] = NO_HIT;
                        if let Some(h) = hit {
                            out.t[first + i] = h.t;
                            out.prim[first + i] = h.prim;
                        }
                    }
                })
            }
        }
    };
}

fan_packet!(fan16, 16, RTCRayHit16, intersect16);
fan_packet!(fan8, 8, RTCRayHit8, intersect8);

#[cfg(test)]
mod tests {
    use super::super::scale;
    use super::MAX_UNNORMALISED;
    use crate::rng::Rng;
    use crate::spacetime::{Boost, Velocity};

    /// The fans trace every lane's direction as it is where the boost stretches by at most
    /// `MAX_UNNORMALISED − 1`, which is right only if `scale` then says 1 for every ray the boost
    /// makes (so that a fan's Embree rays are `embree_ray`'s to the bit); beyond, `scale` must
    /// say so for some directions, or the margin would be wasted.
    #[test]
    fn within_the_stretch_every_direction_goes_in_as_it_is() {
        let mut rng = Rng(0x5eed_f00d_1234_5678);
        let limit = MAX_UNNORMALISED - 1.0;
        // e^φ = limit at β = (limit² − 1) / (limit² + 1).
        let edge = (limit * limit - 1.0) / (limit * limit + 1.0);
        for case in 0..2_000 {
            let beta = if case % 2 == 0 {
                rng.range(0.0, edge)
            } else {
                edge * (1.0 - 1e-15 * rng.range(0.0, 1.0))
            };
            let v = Velocity::from_beta(rng.unit(), beta).expect("below c");
            let boost = Boost::to_rest(&v);
            assert!(boost.max_stretch() <= limit * (1.0 + 1e-14), "{beta}");
            for _ in 0..50 {
                let (_, s) = boost.null_dir(rng.unit());
                assert_eq!(scale(s), 1.0, "β = {beta}: s = {s}");
            }
        }
        let fast = Boost::to_rest(&Velocity::from_beta(glam::DVec3::X, 0.999).expect("below c"));
        assert!(fast.max_stretch() > limit);
        let unit = (0..1000)
            .filter(|_| scale(fast.null_dir(rng.unit()).1) == 1.0)
            .count();
        assert!(unit < 1000, "at 0.999c some directions are normalised");
    }
}
