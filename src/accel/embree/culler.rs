//! Embree as a culling structure over boxes: one user primitive per box, whose callback hands
//! each candidate to the caller's `visit` (the renderer's exact f64 test of a velocity group).
//! Embree's BVH and packet traversal find the candidates far faster than the f64 box tree; the
//! boxes are widened and the f32 rays given slack, so rounding can only add candidates, never
//! lose one.

use super::exact::{self, Shape, Shapes};
use super::fault::{guarded, Callback, Fault, Injection};
use super::lane_cull::lanes_near;
use super::packet::flush_denormals;
use super::rtc::{self, field, CommittedScene, Device, Geometry, SceneBuilder, UserFunctions};
use crate::accel::BoxCuller;
use crate::geometry::{Aabb, PACKET};
use embree_sys::*;
use glam::DVec3;
use std::cell::Cell;
use std::sync::Arc;

pub struct EmbreeCuller {
    /// Where a fault in a callback is recorded (the device's).
    device: Arc<Device>,
    /// None when there are no boxes. Released before the boxes, which it points into (fields
    /// drop in order).
    rtc: Option<CommittedScene>,
    /// The boxes, relative to `center` and widened: kept for the scene's user geometry, which
    /// points into them.
    _boxes: Box<Shapes<Aabb>>,
    center: DVec3,
    /// All the (widened) boxes together, relative to `center`: rays start on it, so f32 sees
    /// only coordinates of the boxes' size however far the rays come from.
    all: Aabb,
    /// Slack for f32 rounding of rays and boxes, in world units.
    slack: f64,
}

/// The context of a culling query: Embree's first (repr(C)), then the caller's visit and the
/// rays' intervals by lane.
#[repr(C)]
struct CullContext<'a> {
    rtc: RTCIntersectContext,
    visit: &'a mut dyn FnMut(u32, usize, f64) -> f64,
    tmin: &'a [f64],
    tmax: &'a mut [f64],
    /// Embree's t is the caller's t times the length of the caller's direction, less the
    /// distance the ray's origin was moved along it.
    len: [f64; PACKET],
    shift: [f64; PACKET],
    slack: f64,
    /// What went wrong in a callback (fault.rs).
    fault: Cell<Fault>,
    /// The test hook of `EmbreeBackend::with_fault_injected` (`Device::injection`).
    inject: Option<&'a Injection>,
}

/// Offer box `prim` to every valid lane that may meet it (lane_cull.rs); a lane whose tmax
/// drops below its tmin is done. A lane's ray is the query's ray its id names (Embree may
/// split and copy the packet before it calls back: exact.rs).
///
/// # Safety
/// `context` is a `CullContext` (every query of this culler passes one); `user` the culler's
/// boxes; `ray` an N-wide SoA ray (RTCRayN layout) with `valid` of N entries.
unsafe fn offer(
    context: *mut RTCIntersectContext,
    user: *mut std::ffi::c_void,
    prim: u32,
    ray: *mut f32,
    valid: *const i32,
    n: usize,
) {
    unsafe {
        let ctx = &mut *(context as *mut CullContext);
        let (fault, inject) = (ctx.fault.clone(), ctx.inject);
        guarded(Callback::Cull, &fault, inject, || {
            let boxes = &*(user as *const Shapes<Aabb>);
            let Some(b) = boxes.0.get(prim as usize) else {
                return;
            };
            let (lo, hi) = b.bounds();
            for i in lanes_near(valid, ray, n, lo, hi) {
                let r = *(ray.add(field::ID * n + i) as *const u32) as usize;
                let (Some(&before), Some(&tmin)) = (ctx.tmax.get(r), ctx.tmin.get(r)) else {
                    fault.set(Fault::StrayRay);
                    continue;
                };
                let t = (ctx.visit)(prim, r, before);
                ctx.tmax[r] = t;
                if t < tmin {
                    *ray.add(field::TFAR * n + i) = f32::NEG_INFINITY;
                } else if t < before {
                    *ray.add(field::TFAR * n + i) =
                        (t * ctx.len[r] - ctx.shift[r] + ctx.slack) as f32;
                }
            }
        });
        ctx.fault.set(fault.get());
    }
}

unsafe extern "C" fn intersect(args: *const RTCIntersectFunctionNArguments) {
    // SAFETY: as for `offer`; Embree passes the query's context and N-wide ray.
    unsafe {
        let a = &*args;
        offer(
            a.context,
            a.geometryUserPtr,
            a.primID,
            a.rayhit as *mut f32,
            a.valid,
            a.N as usize,
        );
    }
}

unsafe extern "C" fn occluded(args: *const RTCOccludedFunctionNArguments) {
    // SAFETY: as for `intersect`.
    unsafe {
        let a = &*args;
        offer(
            a.context,
            a.geometryUserPtr,
            a.primID,
            a.ray as *mut f32,
            a.valid,
            a.N as usize,
        );
    }
}

impl EmbreeCuller {
    pub(super) fn build(device: Arc<Device>, boxes: &[Aabb]) -> crate::Result<EmbreeCuller> {
        let all = boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(b));
        let center = if all.is_empty() {
            DVec3::ZERO
        } else {
            all.centroid()
        };
        // f32 keeps ~7 digits of coordinates about the centre: a generous multiple of that.
        let extent = if all.is_empty() {
            1.0
        } else {
            (all.max - all.min).max_element().max(1e-30)
        };
        let slack = 1e-5 * (extent + (all.max - center).abs().max_element());
        let pad = DVec3::splat(slack);
        let boxes = Box::new(Shapes(
            boxes
                .iter()
                .map(|b| Aabb::new(b.min - center - pad, b.max - center + pad))
                .collect::<Vec<_>>(),
        ));
        let all = boxes.0.iter().fold(Aabb::EMPTY, |a, b| a.union(b));
        let rtc = if boxes.0.is_empty() {
            None
        } else {
            let mut builder = SceneBuilder::new(&device)?;
            let mut g = Geometry::new(&device, RTC_GEOMETRY_TYPE_USER)?;
            let ptr = &*boxes as *const Shapes<Aabb> as *mut std::ffi::c_void;
            let functions = UserFunctions {
                bounds: exact::bounds::<Aabb>,
                intersect,
                occluded,
            };
            // SAFETY: the boxes (boxed, so they never move) are kept in the culler and dropped
            // after its scene is released; the bounds callback reads them as `Shapes<Aabb>`.
            unsafe { g.set_user(boxes.0.len() as u32, ptr, functions) };
            builder.attach(g)?;
            Some(builder.commit()?)
        };
        Ok(EmbreeCuller {
            device,
            rtc,
            _boxes: boxes,
            center,
            all,
            slack,
        })
    }
}

impl BoxCuller for EmbreeCuller {
    fn traverse_packet(
        &self,
        o: DVec3,
        dirs: &[DVec3],
        tmin: &[f64],
        tmax: &mut [f64],
        visit: &mut dyn FnMut(u32, usize, f64) -> f64,
    ) {
        let Some(scene) = &self.rtc else {
            return;
        };
        flush_denormals();
        let n = dirs.len().min(PACKET).min(tmax.len());
        let mut rh = RTCRayHit16::default();
        // Lanes not traced are empty intervals as well as masked: where Embree splits a packet
        // it does not use the mask (`packet::deactivate`).
        rh.ray.tnear = [f32::INFINITY; 16];
        rh.ray.tfar = [f32::NEG_INFINITY; 16];
        rh.ray.id = std::array::from_fn(|i| i as u32);
        let mut valid = rtc::Valid([0i32; 16]);
        let o = o - self.center;
        let (mut lens, mut shifts) = ([1.0; PACKET], [0.0; PACKET]);
        for i in 0..n {
            // Unit directions, and the origin moved (in f64) to where the ray enters all the
            // boxes: f32 then rounds coordinates of the boxes' size, which the slack covers.
            let len = dirs[i].length();
            if len.is_nan() || len <= 0.0 || tmin[i] > tmax[i] {
                continue;
            }
            let d = dirs[i] / len;
            let Some((enter, _)) = self.all.clip(o, d.recip(), tmin[i] * len, tmax[i] * len) else {
                continue;
            };
            let shift = enter.max(0.0);
            let org = o + shift * d;
            (lens[i], shifts[i]) = (len, shift);
            rh.ray.org_x[i] = org.x as f32;
            rh.ray.org_y[i] = org.y as f32;
            rh.ray.org_z[i] = org.z as f32;
            rh.ray.dir_x[i] = d.x as f32;
            rh.ray.dir_y[i] = d.y as f32;
            rh.ray.dir_z[i] = d.z as f32;
            rh.ray.tnear[i] = ((tmin[i] * len - shift - self.slack).max(0.0)) as f32;
            let far = tmax[i] * len - shift + self.slack;
            rh.ray.tfar[i] = if far.is_finite() {
                far as f32
            } else {
                f32::INFINITY
            };
            rh.ray.mask[i] = u32::MAX;
            rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
            valid.0[i] = -1;
        }
        let mut ctx = CullContext {
            rtc: rtc::new_context(),
            visit,
            tmin: &tmin[..n],
            tmax: &mut tmax[..n],
            len: lens,
            shift: shifts,
            slack: self.slack,
            fault: Cell::new(Fault::None),
            inject: self.device.injection(),
        };
        ctx.rtc.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        let raw = (&mut ctx as *mut CullContext).cast::<RTCIntersectContext>();
        // SAFETY: a committed scene, a 64-byte aligned valid mask of 16, the context above
        // (which the callbacks read as a CullContext) outliving the call.
        unsafe { scene.intersect16(&valid, raw, &mut rh) };
        let fault = ctx.fault.get();
        if fault != Fault::None {
            self.device.faults.record(|| fault.message());
        }
    }
}
