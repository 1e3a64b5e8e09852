//! Ray packets and single rays through Embree's C API.

use super::exact::{ExactContext, Lanes};
use super::fault::Fault;
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
/// every query here gives the same value (a ray's time 0, mask all ones, flags 0, id its lane,
/// by which the callbacks find the query's ray; a hit's instID none) are set when the packet
/// is made, and nothing changes them but a hit's
/// instID, which Embree and the callbacks write with every hit (the instance's geomID, or none
/// at the top level) and the read-back reads only where there is a hit (a placement of a
/// shared mesh, scene.rs's `MeshInstances`); each query writes the rest that Embree reads
/// in the lanes it marks valid: a ray's origin, tnear, direction and tfar (`Lane::set`, or the
/// fans' kernel) and a hit's geomID; in the others an empty interval (`Lane::deactivate`). The rest of a hit Embree writes where it
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
                    deactivate_from(&mut rh.ray, rays.len());
                    unsafe { self.scene.rtc.$isect_q(&valid, ctx, rh) };
                    (0..rays.len())
                        .filter(|&i| rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID)
                        .count()
                })
            }

            pub(super) fn $isect(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
                $RayHitN::with(|rh| {
                    let mut valid = Valid([0i32; $n]);
                    let lanes = Lanes::<$n>::new(rays, self.pullback);
                    for (i, r) in rays.iter().enumerate() {
                        let e = self.embree_ray(r);
                        fill_lane(&mut rh.ray, i, &e, &mut valid.0);
                        lanes.offset[i].set(e.offset);
                        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
                    }
                    deactivate_from(&mut rh.ray, rays.len());
                    let mut ctx = self.context(Query::Intersect, rays, &lanes);
                    unsafe { self.scene.rtc.$isect_q(&valid, ctx.raw(), rh) };
                    self.settle(&ctx);
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
                    // Every lane's primitive fetched, then refined (`EmbreeAccel::fetch`).
                    let mut fetched = [None; $n];
                    for (i, f) in fetched.iter_mut().enumerate().take(rays.len()) {
                        if valid.0[i] != 0 && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID {
                            let (geom, prim) = (rh.hit.geomID[i], rh.hit.primID[i]);
                            *f = self.fetch(geom, prim, rh.hit.instID[0][i]);
                        }
                    }
                    for (i, r) in rays.iter().enumerate() {
                        let offset = lanes.offset[i].get();
                        hits[i] = fetched[i].and_then(|f| {
                            self.refine(r, rh.ray.tfar[i], f, ctx.exact_t(i), offset)
                        });
                    }
                })
            }

            pub(super) fn $occl(&self, rays: &[Ray], out: &mut [bool]) {
                $RayN::with(|ray| {
                    let mut valid = Valid([0i32; $n]);
                    let lanes = Lanes::<$n>::new(rays, self.pullback);
                    for (i, r) in rays.iter().enumerate() {
                        let e = self.embree_ray(r);
                        fill_lane(ray, i, &e, &mut valid.0);
                        lanes.offset[i].set(e.offset);
                    }
                    deactivate_from(ray, rays.len());
                    let mut ctx = self.context(Query::Occluded, rays, &lanes);
                    unsafe { self.scene.rtc.$occl_q(&valid, ctx.raw(), ray) };
                    self.settle(&ctx);
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
                id: std::array::from_fn(|i| i as u32),
                ..Default::default()
            }
        );
        reused!(
            $RayHitN,
            $RayHitN {
                ray: $RayN {
                    mask: [u32::MAX; $n],
                    id: std::array::from_fn(|i| i as u32),
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

            fn deactivate(&mut self, i: usize) {
                self.tnear[i] = f32::INFINITY;
                self.tfar[i] = f32::NEG_INFINITY;
            }

            fn width(&self) -> usize {
                $n
            }
        }
    };
}

/// The valid mask of a packet: Embree reads it with aligned vector loads, so it needs the
/// packet's alignment (64 bytes covers 8- and 16-wide).
pub(super) use super::rtc::Valid;

pub(super) trait Lane {
    /// Lane i traces `e`.
    fn set(&mut self, i: usize, e: &EmbreeRay);
    /// Lane i traces nothing: its interval is empty (tnear +∞, tfar −∞). The valid mask alone
    /// does not do: where Embree does not trace a packet's width natively it splits the packet
    /// and takes a lane as valid by its interval, not the mask (Embree 3's
    /// `RayStreamFilter::filterSOA`), and a reused packet's idle lanes hold old rays.
    fn deactivate(&mut self, i: usize);
    /// The packet's width.
    fn width(&self) -> usize;
}

/// Put a ray in lane i; inactive rays (masked by the caller, e.g. missing the group's bounds)
/// stay out of the valid mask and get an empty interval.
pub(super) fn fill_lane<R: Lane>(ray: &mut R, i: usize, e: &EmbreeRay, valid: &mut [i32]) {
    if e.active {
        ray.set(i, e);
        valid[i] = -1;
    } else {
        ray.deactivate(i);
    }
}

/// Lanes `first..` of the packet trace nothing (`Lane::deactivate`).
pub(super) fn deactivate_from<R: Lane>(ray: &mut R, first: usize) {
    for i in first..ray.width() {
        ray.deactivate(i);
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
packet_fns!(4, intersect4, occluded4, bare4, RTCRayHit4, RTCRay4, RTCHit4, intersect4, occluded4);

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

/// Which query a context is for, and how it is traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Query {
    /// Closest hits of a packet (coherent).
    Intersect,
    /// Occlusion of a packet (coherent, but for scenes with instances).
    Occluded,
    /// One ray, or bare rays (incoherent).
    Single,
}

impl EmbreeAccel {
    /// The context for a query of these rays (lanes in order), as user geometry needs it.
    pub(super) fn context<'a, const N: usize>(
        &'a self,
        query: Query,
        rays: &'a [Ray],
        lanes: &'a Lanes<N>,
    ) -> ExactContext<'a> {
        // Packets go to Embree's coherent traversal, but occlusion queries into instances:
        // with AVX-512, Embree 3.13.5's coherent 16-wide occlusion query into a scene of
        // instances does not return for some packets (the paper's lattice grown to 30^3 nodes
        // and instanced, rendered at 32^2: the thread spins inside rtcOccluded16, in Embree's
        // own traversal, with no callback of ours on the stack), while 8- and 4-wide ones,
        // the same query incoherent and coherent closest-hit queries into the same scene all
        // return. It is not the lane bookkeeping (16 lanes are native there: no split).
        let coherent = match query {
            Query::Intersect => true,
            Query::Occluded => self.scene.coherent_occlusion,
            Query::Single => false,
        };
        let inject = self.device.injection();
        ExactContext::new(coherent, rays, lanes, self.scene.center, inject)
    }

    /// Record what went wrong in the query's callbacks, if anything, for the render to report.
    #[inline(always)]
    pub(super) fn settle(&self, ctx: &ExactContext) {
        let fault = ctx.fault();
        if fault != Fault::None {
            self.device.faults.record(|| fault.message());
        }
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
        let lanes = Lanes::<1>::new(rays, e.offset);
        let mut ctx = self.context(Query::Single, rays, &lanes);
        unsafe { self.scene.rtc.intersect1(ctx.raw(), &mut rh) };
        self.settle(&ctx);
        if rh.hit.geomID == RTC_INVALID_GEOMETRY_ID {
            return None;
        }
        let t = ctx.exact_t(0);
        let inst = rh.hit.instID[0];
        self.to_hit(
            r,
            rh.ray.tfar,
            rh.hit.geomID,
            rh.hit.primID,
            inst,
            t,
            e.offset,
        )
    }

    pub(super) fn occluded1(&self, r: &Ray) -> bool {
        let e = self.embree_ray(r);
        if !e.active {
            return false;
        }
        let mut ray = single(&e);
        let rays = std::slice::from_ref(r);
        let lanes = Lanes::<1>::new(rays, e.offset);
        let mut ctx = self.context(Query::Single, rays, &lanes);
        unsafe { self.scene.rtc.occluded1(ctx.raw(), &mut ray) };
        self.settle(&ctx);
        ray.tfar == f32::NEG_INFINITY
    }
}
