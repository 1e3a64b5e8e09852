//! Ray packets and single rays through Embree's C API.

use super::exact::{ExactContext, Lanes};
use super::{BareRay, EmbreeAccel, EmbreeRay};
use crate::accel::{Hit, Ray};
use embree_sys::*;
use std::cell::{Cell, RefCell};

thread_local! {
    static FTZ_SET: Cell<bool> = const { Cell::new(false) };
}

/// Flush-to-zero and denormals-are-zero on this thread (Embree's recommendation), once.
pub(super) fn flush_denormals() {
    FTZ_SET.with(|done| {
        if !done.get() {
            #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
            #[allow(deprecated)]
            unsafe {
                #[cfg(target_arch = "x86")]
                use std::arch::x86::{_mm_getcsr, _mm_setcsr};
                #[cfg(target_arch = "x86_64")]
                use std::arch::x86_64::{_mm_getcsr, _mm_setcsr};
                _mm_setcsr(_mm_getcsr() | 0x8040);
            }
            done.set(true);
        }
    });
}

/// A thread's Embree packet of each kind, kept and reused: made per packet, a 16-wide
/// `RTCRayHit16` is 1.28 kB zeroed before its rays are written over half of it. The fields
/// every query here gives the same value (a ray's time 0, mask all ones, flags and id 0; a
/// hit's instID none) are set when the packet is made, and nothing changes them but a hit's
/// instID, which the instanced blocks' callbacks write (instanced_blocks.rs) and nothing reads:
/// the hits' read-back goes by geomID and primID alone; each query writes the rest that Embree reads
/// in the lanes it marks valid: a ray's origin, tnear, direction and tfar (`Lane::set`, or the
/// fans' kernel) and a hit's geomID. The rest of a hit Embree writes where it
/// reports one. Embree's callbacks start no query, so a packet is never in use twice on one
/// thread.
pub(super) trait Reused: Sized {
    /// `f` on this thread's packet of this kind.
    fn with<R>(f: impl FnOnce(&mut Self) -> R) -> R;
}

macro_rules! reused {
    ($T:ident, $made:expr) => {
        impl Reused for $T {
            #[inline(always)]
            fn with<R>(f: impl FnOnce(&mut Self) -> R) -> R {
                thread_local! {
                    static PACKET: RefCell<$T> = RefCell::new($made);
                }
                PACKET.with_borrow_mut(f)
            }
        }
    };
}

macro_rules! packet_fns {
    ($n:literal, $isect:ident, $occl:ident, $bare:ident, $RayHitN:ident, $RayN:ident, $HitN:ident, $isect_q:ident, $occl_q:ident) => {
        impl EmbreeAccel {
            /// Bare Embree (the benchmark's baseline): prepared rays in one packet, nothing
            /// else; returns how many hit.
            pub(super) fn $bare(&self, rays: &[BareRay], ctx: *mut RTCIntersectContext) -> usize {
                $RayHitN::with(|rh| {
                    let mut valid = Valid([0i32; $n]);
                    for (i, r) in rays.iter().enumerate() {
                        fill_lane(&mut rh.ray, i, &r.lane(), &mut valid.0);
                        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
                    }
                    unsafe { self.scene.rtc.$isect_q(&valid, ctx, rh) };
                    (0..rays.len())
                        .filter(|&i| rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID)
                        .count()
                })
            }

            pub(super) fn $isect(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
                $RayHitN::with(|rh| {
                    let mut valid = Valid([0i32; $n]);
                    let lanes = Lanes::<$n>::new(rays);
                    for (i, r) in rays.iter().enumerate() {
                        let e = self.embree_ray(r);
                        fill_lane(&mut rh.ray, i, &e, &mut valid.0);
                        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
                    }
                    let mut ctx = self.context(true, rays, &lanes);
                    unsafe { self.scene.rtc.$isect_q(&valid, ctx.raw(), rh) };
                    if let Some(runs) = self.scene.exact_runs {
                        // As the fans read hits back (`ExactRuns`): every hit exact, within the
                        // ray's (tmin, tmax), its primitive with no lookup.
                        for (i, r) in rays.iter().enumerate() {
                            let t = ctx.exact_t(i);
                            let prim = runs.hit(rh.hit.geomID[i], rh.hit.primID[i]);
                            let hit = valid.0[i] != 0 && prim.is_some();
                            debug_assert!(!hit || (t > r.tmin && t < r.tmax));
                            // The hit made whether or not it is kept, so nothing branches
                            // (lanes hit or miss about at random).
                            let h = Hit {
                                t,
                                prim: prim.unwrap_or_default(),
                            };
                            hits[i] = hit.then_some(h);
                        }
                        return;
                    }
                    for (i, r) in rays.iter().enumerate() {
                        hits[i] = if valid.0[i] != 0 && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID
                        {
                            self.to_hit(
                                r,
                                rh.ray.tfar[i],
                                rh.hit.geomID[i],
                                rh.hit.primID[i],
                                ctx.exact_t(i),
                            )
                        } else {
                            None
                        };
                    }
                })
            }

            pub(super) fn $occl(&self, rays: &[Ray], out: &mut [bool]) {
                $RayN::with(|ray| {
                    let mut valid = Valid([0i32; $n]);
                    let lanes = Lanes::<$n>::new(rays);
                    for (i, r) in rays.iter().enumerate() {
                        let e = self.embree_ray(r);
                        fill_lane(ray, i, &e, &mut valid.0);
                    }
                    let mut ctx = self.context(true, rays, &lanes);
                    unsafe { self.scene.rtc.$occl_q(&valid, ctx.raw(), ray) };
                    for i in 0..rays.len() {
                        out[i] = valid.0[i] != 0 && ray.tfar[i] == f32::NEG_INFINITY;
                    }
                })
            }
        }

        // The fields every query gives the same value (`Reused`).
        reused!(
            $RayN,
            $RayN {
                mask: [u32::MAX; $n],
                ..Default::default()
            }
        );
        reused!(
            $RayHitN,
            $RayHitN {
                ray: $RayN {
                    mask: [u32::MAX; $n],
                    ..Default::default()
                },
                hit: $HitN {
                    instID: [[RTC_INVALID_GEOMETRY_ID; $n]],
                    ..Default::default()
                },
            }
        );

        impl Lane for $RayN {
            fn set(&mut self, i: usize, e: &EmbreeRay) {
                self.org_x[i] = e.org[0];
                self.org_y[i] = e.org[1];
                self.org_z[i] = e.org[2];
                self.dir_x[i] = e.dir[0];
                self.dir_y[i] = e.dir[1];
                self.dir_z[i] = e.dir[2];
                self.tnear[i] = e.tnear;
                self.tfar[i] = e.tfar;
            }
        }
    };
}

/// The valid mask of a packet: Embree reads it with aligned vector loads, so it needs the
/// packet's alignment (64 bytes covers 8- and 16-wide).
pub(super) use super::rtc::Valid;

pub(super) trait Lane {
    fn set(&mut self, i: usize, e: &EmbreeRay);
}

/// Put a ray in lane i; inactive rays (masked by the caller, e.g. missing the group's bounds)
/// stay out of the valid mask.
pub(super) fn fill_lane<R: Lane>(ray: &mut R, i: usize, e: &EmbreeRay, valid: &mut [i32]) {
    if e.active {
        ray.set(i, e);
        valid[i] = -1;
    }
}

packet_fns!(
    16,
    intersect16,
    occluded16,
    bare16,
    RTCRayHit16,
    RTCRay16,
    RTCHit16,
    intersect16,
    occluded16
);
packet_fns!(8, intersect8, occluded8, bare8, RTCRayHit8, RTCRay8, RTCHit8, intersect8, occluded8);

pub(super) fn single(e: &EmbreeRay) -> RTCRay {
    RTCRay {
        org_x: e.org[0],
        org_y: e.org[1],
        org_z: e.org[2],
        tnear: e.tnear,
        dir_x: e.dir[0],
        dir_y: e.dir[1],
        dir_z: e.dir[2],
        time: 0.0,
        tfar: e.tfar,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

impl EmbreeAccel {
    /// The context for a query of these rays (lanes in order), as user geometry needs it.
    pub(super) fn context<'a, const N: usize>(
        &self,
        coherent: bool,
        rays: &'a [Ray],
        lanes: &'a Lanes<N>,
    ) -> ExactContext<'a> {
        // Embree 3.13's coherent packet traversal can fail to return from an occlusion query
        // into instances once a coherent closest-hit query has run on the thread (found on
        // the instanced lattice: the call spun in Embree's traversal); scenes with instances
        // trace their packets as incoherent.
        let coherent = coherent && self.scene.coherent_packets;
        ExactContext::new(coherent, rays, lanes, self.scene.center, self.pullback)
    }

    pub(super) fn intersect1(&self, r: &Ray) -> Option<Hit> {
        let e = self.embree_ray(r);
        if !e.active {
            return None;
        }
        let mut rh = RTCRayHit {
            ray: single(&e),
            hit: RTCHit {
                geomID: RTC_INVALID_GEOMETRY_ID,
                ..Default::default()
            },
        };
        let rays = std::slice::from_ref(r);
        let lanes = Lanes::<1>::new(rays);
        let mut ctx = self.context(false, rays, &lanes);
        unsafe { self.scene.rtc.intersect1(ctx.raw(), &mut rh) };
        if rh.hit.geomID == RTC_INVALID_GEOMETRY_ID {
            return None;
        }
        self.to_hit(r, rh.ray.tfar, rh.hit.geomID, rh.hit.primID, ctx.exact_t(0))
    }

    pub(super) fn occluded1(&self, r: &Ray) -> bool {
        let e = self.embree_ray(r);
        if !e.active {
            return false;
        }
        let mut ray = single(&e);
        let rays = std::slice::from_ref(r);
        let lanes = Lanes::<1>::new(rays);
        let mut ctx = self.context(false, rays, &lanes);
        unsafe { self.scene.rtc.occluded1(ctx.raw(), &mut ray) };
        ray.tfar == f32::NEG_INFINITY
    }
}
