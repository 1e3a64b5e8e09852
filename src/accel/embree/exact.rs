//! Spheres, rods (capsules) and boxes as Embree user geometry (also the boxes of culler.rs): Embree's BVH over their bounds
//! finds the candidates, and the exact f64 tests of the f64 BVH decide the hit, on the caller's
//! f64 ray (passed in the intersect context) rather than Embree's f32 copy, so these hits need
//! no refinement. A packet's lanes that may meet the primitive (`lane_cull`) are tested together,
//! four per AVX2 vector where the shape allows (`lane_hits`). Not Embree's own round curves and
//! sphere points: they are built for hair and particles (oriented boxes, swept spheres) and are
//! its slow path on a lattice of rods and spheres. Not boxes as twelve f32 triangles refined in
//! f64: one exact slab test costs less.

use super::fault::{self, Callback, Fault, Injection};
use super::lane_cull::lanes_near;
pub use super::lane_hits::Round;
use super::lane_hits::{round_hits, Answers, LaneRays, MAX};
use super::scale;
use crate::accel::Ray;
use crate::geometry::{capsule_hit, cuboid_hit, Aabb};
use embree_sys::*;
use glam::DVec3;
use std::cell::Cell;
use std::sync::OnceLock;

/// A primitive Embree traces as user geometry, relative to the Embree scene's centre.
pub trait Shape: Copy {
    /// Its first hit by `o + t d` with `tmin < t < tmax`.
    fn hit(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<f64>;
    /// Its bounds (min, max).
    fn bounds(&self) -> (DVec3, DVec3);
    /// Whether `hits` decides any ray (else the callbacks skip gathering the lanes for it).
    const SEVERAL: bool = false;
    /// Its hits on several rays at once (`lane_hits`); by default none decided.
    #[inline]
    fn hits(&self, _rays: &LaneRays, out: &mut Answers) {
        out.fill(f64::NAN)
    }
}

impl Shape for Round {
    #[inline]
    fn hit(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<f64> {
        capsule_hit(self.a, self.b, self.radius, o, d, tmin, tmax)
    }
    fn bounds(&self) -> (DVec3, DVec3) {
        let r = DVec3::splat(self.radius);
        (self.a.min(self.b) - r, self.a.max(self.b) + r)
    }
    const SEVERAL: bool = true;
    #[inline]
    fn hits(&self, rays: &LaneRays, out: &mut Answers) {
        round_hits(self, rays, out)
    }
}

/// An axis-aligned box.
impl Shape for Aabb {
    #[inline]
    fn hit(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<f64> {
        cuboid_hit(self.min, self.max, o, d, tmin, tmax)
    }
    fn bounds(&self) -> (DVec3, DVec3) {
        (self.min, self.max)
    }
}

/// The primitives of one Embree user geometry; Embree holds a pointer to it, so it lives in a
/// Box that the scene owns and drops after releasing the Embree scene.
pub struct Shapes<S>(pub Vec<S>);

/// The intersect context handed to Embree: Embree's own first (Embree passes a pointer to it to
/// the callbacks), then the caller's f64 rays by lane and the exact hit found so far in each.
#[repr(C)]
pub(super) struct ExactContext<'a> {
    rtc: RTCIntersectContext,
    /// The caller's rays (rest frame, unnormalised direction), by lane; empty for bare rays,
    /// which are tested in Embree's f32 copy.
    rays: &'a [Ray],
    /// Embree coordinates are the caller's minus this.
    center: DVec3,
    /// Embree's t = t · scale(len) + offset, by ray (the caller's ray was pulled back, moved
    /// up to the scene from afar, and normalised where its length is far from 1: `scale`,
    /// `Ray::len`, `EmbreeRay::offset`).
    offset: &'a [Cell<f64>],
    /// The exact t of the closest user-geometry hit so far in each lane (starts at tmax).
    best: &'a [Cell<f64>],
    /// What went wrong in a callback of this query, for the query to record (`Fault`).
    fault: Cell<Fault>,
    /// The test hook of `EmbreeBackend::with_fault_injected` (`Device::injection`).
    inject: Option<&'a Injection>,
}

/// Run a callback's body for this query (`fault::guarded`).
#[inline(always)]
pub(super) fn guarded(callback: Callback, ctx: &ExactContext, body: impl FnOnce()) {
    fault::guarded(callback, &ctx.fault, ctx.inject, body)
}

/// Per-lane storage of an `ExactContext` for up to N rays.
pub(super) struct Lanes<const N: usize> {
    pub best: [Cell<f64>; N],
    /// Each ray's Embree t = t · scale + offset (`EmbreeRay::offset`); the pullback until the
    /// query sets it.
    pub offset: [Cell<f64>; N],
}

impl<const N: usize> Lanes<N> {
    pub fn new(rays: &[Ray], pullback: f64) -> Self {
        Lanes {
            best: std::array::from_fn(|i| Cell::new(rays.get(i).map_or(f64::INFINITY, |r| r.tmax))),
            offset: std::array::from_fn(|_| Cell::new(pullback)),
        }
    }
}

/// Embree's intersect context as `rtcInitIntersectContext` makes it, coherent or not: made
/// once and copied. Made per packet, the C function's 4-byte stores were read back 8 bytes at a
/// time as the struct was moved (a store-forwarding stall per packet).
fn initial_context(coherent: bool) -> RTCIntersectContext {
    static MADE: OnceLock<[RTCIntersectContext; 2]> = OnceLock::new();
    let [incoherent, coherent_one] = *MADE.get_or_init(|| {
        let rtc = super::rtc::new_context();
        let mut c = rtc;
        c.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        [rtc, c]
    });
    if coherent {
        coherent_one
    } else {
        incoherent
    }
}

impl<'a> ExactContext<'a> {
    pub fn new<const N: usize>(
        coherent: bool,
        rays: &'a [Ray],
        lanes: &'a Lanes<N>,
        center: DVec3,
        inject: Option<&'a Injection>,
    ) -> Self {
        ExactContext {
            rtc: initial_context(coherent),
            rays: &rays[..rays.len().min(N)],
            center,
            offset: &lanes.offset,
            best: &lanes.best,
            fault: Cell::new(Fault::None),
            inject,
        }
    }

    /// What went wrong in this query's callbacks, if anything.
    pub fn fault(&self) -> Fault {
        self.fault.get()
    }

    /// The pointer Embree is given, and hands back to the callbacks: taken from the whole
    /// struct (repr(C), Embree's part first), so it may be read as the whole struct there.
    pub fn raw(&mut self) -> *mut RTCIntersectContext {
        (self as *mut Self).cast()
    }

    /// Whether the rays are bare: Embree's own f32 rays, tested as they are.
    pub fn is_bare(&self) -> bool {
        self.rays.is_empty()
    }

    /// The exact t of the user-geometry hit of the query's ray `i` (valid when Embree reports
    /// one there).
    pub fn exact_t(&self, i: usize) -> f64 {
        self.best.get(i).map_or(f64::INFINITY, Cell::get)
    }
}

/// Field k of lane i of an N-wide SoA ray (`RTCRayN` / `RTCRayHitN`: 12 ray fields, then the
/// hit's Ng_x, Ng_y, Ng_z, u, v, primID, geomID, instID, each N floats wide).
use super::rtc::field::{DIR, ID, ORG, TFAR, TNEAR};
pub(super) const NG: usize = 12;
pub(super) const U: usize = 15;
pub(super) const PRIM_ID: usize = 17;
pub(super) const GEOM_ID: usize = 18;
pub(super) const INST_ID: usize = 19;

/// Primitive `prim` of the shapes (None past their end, which Embree never asks for).
///
/// # Safety
/// `user` is the pointer registered for a live `Shapes<S>`.
unsafe fn shape<'r, S: Shape>(user: *mut std::ffi::c_void, prim: u32) -> Option<&'r S> {
    unsafe {
        let all: &'r Shapes<S> = &*(user as *const Shapes<S>);
        all.0.get(prim as usize)
    }
}

/// Which of the query's rays lane i of an N-wide SoA ray is: the index the query put in the
/// ray's id. Embree carries the id through whatever it does to a packet before it calls back
/// (a packet of a width the CPU does not trace natively is split and copied, and streams are
/// reordered), so the lane's position says nothing.
///
/// # Safety
/// `base` points to an N-wide SoA ray with lane `i < n`.
#[inline(always)]
unsafe fn caller(base: *const f32, n: usize, i: usize) -> usize {
    unsafe { *(base.add(ID * n + i) as *const u32) as usize }
}

/// Embree's f32 ray in lane i as f64: origin, direction, tnear, tfar.
///
/// # Safety
/// `base` points to an N-wide SoA ray with lane `i < n`.
unsafe fn read(base: *const f32, n: usize, i: usize) -> (DVec3, DVec3, f64, f64) {
    let f = |k: usize| unsafe { *base.add(k * n + i) } as f64;
    (
        DVec3::new(f(ORG), f(ORG + 1), f(ORG + 2)),
        DVec3::new(f(DIR), f(DIR + 1), f(DIR + 2)),
        f(TNEAR),
        f(TFAR),
    )
}

/// Panic-free: no indexing, float arithmetic only.
pub(super) unsafe extern "C" fn bounds<S: Shape>(args: *const RTCBoundsFunctionArguments) {
    // SAFETY: Embree passes the user pointer we registered (a live `Shapes<S>`) and a prim
    // index below the primitive count we set.
    unsafe {
        let args = &*args;
        *args.bounds_o = match shape::<S>(args.geometryUserPtr, args.primID) {
            Some(s) => {
                let (lo, hi) = s.bounds();
                outward(lo, hi)
            }
            // Never asked for; a box of everything loses nothing.
            None => everything(),
        };
    }
}

/// The f32 box of all space.
pub(super) fn everything() -> RTCBounds {
    outward(DVec3::splat(-1e30), DVec3::splat(1e30))
}

/// The f32 box holding the f64 box (lo, hi): rounded outward.
pub(super) fn outward(lo: DVec3, hi: DVec3) -> RTCBounds {
    // Padded by 16 f32 ulps of the box's largest coordinate, not one: Embree's packet
    // traversal without FMA (SSE, AVX) rounds its slab tests coarser than its single rays and
    // lost rays grazing an edge. The exact test decides every hit, so a wider box only costs
    // a callback now and then.
    let pad = 16.0 * f64::from(f32::EPSILON) * lo.abs().max(hi.abs()).max_element();
    let down = |x: f64| ((x - pad) as f32).next_down();
    let up = |x: f64| ((x + pad) as f32).next_up();
    RTCBounds {
        lower_x: down(lo.x),
        lower_y: down(lo.y),
        lower_z: down(lo.z),
        align0: 0.0,
        upper_x: up(hi.x),
        upper_y: up(hi.y),
        upper_z: up(hi.z),
        align1: 0.0,
    }
}

/// The hits of the primitive on the lanes of an N-wide SoA ray that may meet it (`valid`, then
/// the lane cull), by lane: Embree's t, if closer than both the lane's exact best (recorded in
/// the context, in the caller's units) and Embree's tfar.
///
/// # Safety
/// `ctx` is an `ExactContext` (every query of this backend passes one); `base` points to an
/// N-wide SoA ray and `valid` to its N entries.
#[inline(always)]
pub(super) unsafe fn lane_hits<S: Shape>(
    ctx: &ExactContext,
    prim: &S,
    valid: *const i32,
    base: *const f32,
    n: usize,
    found: impl FnMut(usize, f32),
) {
    unsafe { lane_hits_within(ctx, prim, prim.bounds(), valid, base, n, found) }
}

/// `lane_hits` with the lanes culled by `cull` (min, max), a box in the coordinates of
/// Embree's rays (an instance's own), holding the primitive moved there.
///
/// # Safety
/// As for `lane_hits`.
#[inline(always)]
pub(super) unsafe fn lane_hits_within<S: Shape>(
    ctx: &ExactContext,
    prim: &S,
    (lo, hi): (DVec3, DVec3),
    valid: *const i32,
    base: *const f32,
    n: usize,
    mut found: impl FnMut(usize, f32),
) {
    let near = unsafe { lanes_near(valid, base, n, lo, hi) };
    if n == 1 || !S::SEVERAL {
        // Embree's single-ray traversal, or a shape tested one ray at a time: nothing to share.
        for i in near {
            if let Some(t) = unsafe { lane_hit(ctx, prim, base, n, i) } {
                found(i, t);
            }
        }
        return;
    }
    // The lanes through the primitive's several-ray test, then what it left undecided through
    // the scalar one.
    let mut rays = LaneRays::new();
    rays.gather(near.filter_map(|i| {
        let (_, o, d, tmin, tmax) = unsafe { lane_ray(ctx, base, n, i) }?;
        Some((i, o, d, tmin, tmax))
    }));
    let mut answers = [0.0; MAX];
    prim.hits(&rays, &mut answers);
    for (j, &answer) in answers.iter().enumerate().take(rays.len()) {
        let (i, o, d, tmin, tmax) = rays.get(j);
        let t = if answer.is_nan() {
            prim.hit(o, d, tmin, tmax)
        } else {
            (answer < f64::INFINITY).then_some(answer)
        };
        let r = unsafe { ray_of(ctx, base, n, i) };
        if let Some(te) = t.and_then(|t| unsafe { embree_t(ctx, base, n, i, r, t, tmin, tmax) }) {
            found(i, te);
        }
    }
}

/// Embree's t for an exact hit t of lane i, the query's ray r, if it is closer than Embree's
/// tfar (for the caller's rays, also recorded as the ray's exact best); bare rays' hits
/// clamped to (tnear, tfar).
///
/// # Safety
/// As for `lane_hits`, lane `i < n`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
unsafe fn embree_t(
    ctx: &ExactContext,
    base: *const f32,
    n: usize,
    i: usize,
    r: usize,
    t: f64,
    tmin: f64,
    tmax: f64,
) -> Option<f32> {
    if ctx.rays.is_empty() {
        return Some((t as f32).clamp(tmin as f32, tmax as f32));
    }
    let (ray, best, offset) = (ctx.rays.get(r)?, ctx.best.get(r)?, ctx.offset.get(r)?);
    let te = (t * scale(ray.len) + offset.get()) as f32;
    // Embree's tfar may have been lowered by one of its own primitives.
    let tfar = unsafe { *base.add(TFAR * n + i) };
    (te <= tfar).then(|| {
        best.set(t);
        te
    })
}

/// The hit of lane i on the primitive, tested alone (see `lane_hits`).
///
/// # Safety
/// As for `lane_hits`, lane `i < n`.
#[inline(always)]
unsafe fn lane_hit<S: Shape>(
    ctx: &ExactContext,
    prim: &S,
    base: *const f32,
    n: usize,
    i: usize,
) -> Option<f32> {
    let (r, o, d, tmin, tmax) = unsafe { lane_ray(ctx, base, n, i) }?;
    let t = prim.hit(o, d, tmin, tmax)?;
    unsafe { embree_t(ctx, base, n, i, r, t, tmin, tmax) }
}

/// Which of the query's rays lane i is (`caller`); for bare rays, which have none, the lane.
///
/// # Safety
/// As for `lane_hits`, lane `i < n`.
#[inline(always)]
unsafe fn ray_of(ctx: &ExactContext, base: *const f32, n: usize, i: usize) -> usize {
    if ctx.rays.is_empty() {
        i
    } else {
        unsafe { caller(base, n, i) }
    }
}

/// Lane i's ray to test, relative to the Embree scene's centre: which of the query's rays it
/// is, and that f64 ray, with its exact best as its end; for bare rays Embree's f32 one
/// (origin, direction, tmin, tmax). None, with the fault recorded, if the lane's id names no
/// ray of the query.
///
/// # Safety
/// As for `lane_hits`, lane `i < n`.
#[inline(always)]
unsafe fn lane_ray(
    ctx: &ExactContext,
    base: *const f32,
    n: usize,
    i: usize,
) -> Option<(usize, DVec3, DVec3, f64, f64)> {
    if ctx.rays.is_empty() {
        let (o, d, tmin, tmax) = unsafe { read(base, n, i) };
        return Some((i, o, d, tmin, tmax));
    }
    let r = unsafe { caller(base, n, i) };
    match (ctx.rays.get(r), ctx.best.get(r)) {
        (Some(ray), Some(best)) => {
            Some((r, ray.origin - ctx.center, ray.dir, ray.tmin, best.get()))
        }
        _ => {
            ctx.fault.set(Fault::StrayRay);
            None
        }
    }
}

pub(super) unsafe extern "C" fn intersect<S: Shape>(args: *const RTCIntersectFunctionNArguments) {
    // SAFETY: as for `bounds`; `rayhit` is an N-wide RTCRayHitN, `valid` has N entries and
    // `context` is the ExactContext the query was started with.
    unsafe {
        let args = &*args;
        let ctx = &*(args.context as *const ExactContext);
        guarded(Callback::Intersect, ctx, || {
            let Some(prim) = shape::<S>(args.geometryUserPtr, args.primID) else {
                return;
            };
            let n = args.N as usize;
            let base = args.rayhit as *mut f32;
            let inst = (*args.context).instID[0];
            lane_hits(ctx, prim, args.valid, base, n, |i, t| {
                report_hit(base, n, i, t, args.primID, args.geomID, inst)
            });
        });
    }
}

/// Write a hit into lane i of an N-wide SoA ray hit.
///
/// # Safety
/// `base` points to an N-wide `RTCRayHitN`, lane `i < n`.
#[inline(always)]
pub(super) unsafe fn report_hit(
    base: *mut f32,
    n: usize,
    i: usize,
    t: f32,
    prim: u32,
    geom: u32,
    inst: u32,
) {
    unsafe {
        let slot = |k: usize| base.add(k * n + i);
        *slot(TFAR) = t;
        *slot(NG) = 0.0;
        *slot(NG + 1) = 0.0;
        *slot(NG + 2) = 1.0;
        *slot(U) = 0.0;
        *slot(U + 1) = 0.0;
        *(slot(PRIM_ID) as *mut u32) = prim;
        *(slot(GEOM_ID) as *mut u32) = geom;
        *(slot(INST_ID) as *mut u32) = inst;
    }
}

pub(super) unsafe extern "C" fn occluded<S: Shape>(args: *const RTCOccludedFunctionNArguments) {
    // SAFETY: as for `intersect`, with an N-wide RTCRayN.
    unsafe {
        let args = &*args;
        let ctx = &*(args.context as *const ExactContext);
        guarded(Callback::Occluded, ctx, || {
            let Some(prim) = shape::<S>(args.geometryUserPtr, args.primID) else {
                return;
            };
            let n = args.N as usize;
            let base = args.ray as *mut f32;
            lane_hits(ctx, prim, args.valid, base, n, |i, _| {
                *base.add(TFAR * n + i) = f32::NEG_INFINITY;
            });
        });
    }
}
