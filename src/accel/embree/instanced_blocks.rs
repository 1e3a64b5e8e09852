//! An object held as itself (`ImplicitRun`: a lattice, a bar array) as Embree instances: one
//! Embree scene of a block's members (user geometry in the block's own coordinates: a
//! lattice's spheres and rods as rounds, bars as boxes) placed at every block's first node by a
//! translation. Embree's f32 traversal only finds candidates; the callbacks make the object's
//! own primitive from its member and node and test it in f64 on the caller's ray, as the
//! listed object's user geometry does (exact.rs), so hits keep their exact lookback times, and
//! a block's members the object does not have (past its far faces) are skipped.

use super::exact::{
    everything, guarded, lane_hits_within, outward, report_hit, ExactContext, Round, Shape,
};
use super::fault::Callback;
use super::rtc::f3;
use super::rtc::field::TFAR;
use super::rtc::{CommittedScene, Device, Geometry, SceneBuilder, UserFunctions};
use crate::geometry::{Aabb, Blocks, Implicit, ImplicitRun, Member, Primitive};
use embree_sys::*;
use glam::DVec3;
use std::sync::Arc;

/// A user-geometry shape made from a primitive moved by `-shift`.
trait FromPrimitive: Shape {
    fn from_primitive(p: Primitive, shift: DVec3) -> Self;
}

impl FromPrimitive for Round {
    #[inline]
    fn from_primitive(p: Primitive, shift: DVec3) -> Round {
        match p {
            Primitive::Sphere { center, radius } => Round {
                a: center - shift,
                b: center - shift,
                radius,
            },
            Primitive::Capsule { a, b, radius } => Round {
                a: a - shift,
                b: b - shift,
                radius,
            },
            _ => unreachable!("a lattice makes spheres and rods"),
        }
    }
}

impl FromPrimitive for Aabb {
    #[inline]
    fn from_primitive(p: Primitive, shift: DVec3) -> Aabb {
        match p {
            Primitive::Cuboid { min, max } => Aabb::new(min - shift, max - shift),
            _ => unreachable!("a bar array makes boxes"),
        }
    }
}

/// One kind of a block's members (a lattice's spheres, its rods; the bars), as its user
/// geometry's callbacks read them.
struct BlockShapes {
    shape: Implicit,
    blocks: Blocks,
    /// The members, by primID, with their padded local boxes.
    members: Vec<(Member, (DVec3, DVec3))>,
    /// Each instance's block: its first node and its translation as Embree has it, by
    /// instance (geomID minus `first_instance`).
    instances: Arc<Vec<([u32; 3], [f32; 3])>>,
    /// The geomID of block 0's instance; block b's is this plus b.
    first_instance: u32,
    /// The geomID written in hits, whose map gives the object's first number.
    slot: u32,
    /// Embree coordinates are the object's minus this.
    center: DVec3,
}

impl BlockShapes {
    /// Member `p` of instance `inst`, if the object has it: its node and member (which
    /// `member_id` numbers, for a hit), the shape to test (relative to the Embree scene's
    /// centre; for bare rays in the instance's own coordinates, where Embree's rays are) and the
    /// local box to cull lanes with.
    #[inline]
    fn prim<S: FromPrimitive>(&self, inst: u32, p: u32, bare: bool) -> Option<Candidate<S>> {
        let (first, translation) = *self
            .instances
            .get(inst.wrapping_sub(self.first_instance) as usize)?;
        let (m, cull) = *self.members.get(p as usize)?;
        let n = self.blocks.place(self.shape.grid(), first, m)?;
        let shift = if bare {
            self.center + DVec3::from_array(translation.map(f64::from))
        } else {
            self.center
        };
        let s = S::from_primitive(self.shape.member_prim(n, m), shift);
        Some(Candidate {
            node: n,
            member: m,
            shape: s,
            cull,
        })
    }
}

/// A member a callback tests: where it is, its shape, and the local box that culls lanes.
struct Candidate<S> {
    node: [u32; 3],
    member: Member,
    shape: S,
    cull: (DVec3, DVec3),
}

/// An object's block scene and what its callbacks read: released in that order.
pub struct BlockScene {
    _scene: CommittedScene,
    /// Never grown or moved out of: Embree holds pointers into it.
    _shapes: Box<[BlockShapes]>,
}

/// Build `run`'s block scene and attach one instance of it per block to `builder`, as geomIDs
/// `first_instance ..`; hits are reported with geomID `slot` and primID the object's number.
pub(crate) fn attach(
    device: &Arc<Device>,
    builder: &mut SceneBuilder,
    run: &ImplicitRun,
    center: DVec3,
    slot: u32,
    first_instance: u32,
) -> crate::Result<BlockScene> {
    let shape = &run.shape;
    if matches!(shape, Implicit::Mesh(_) | Implicit::Instance(_)) {
        return Err(crate::Error::backend(
            "a mesh is a triangle geometry of its own, not instanced blocks",
        ));
    }
    let blocks = Blocks::of(shape.grid());
    let bounds = shape.bounds();
    let span = Aabb::new(bounds.min - center, bounds.max - center).max_abs();
    // What local boxes are padded by: the f32 rounding of the instances' translations and of
    // the nodes, so that a box holds its primitive seen from any instance.
    let pad = DVec3::splat(span * f64::from(f32::EPSILON) + shape.local_slack());
    let instances: Arc<Vec<([u32; 3], [f32; 3])>> = Arc::new(
        (0..blocks.count())
            .map(|b| {
                let first = blocks.first_of(blocks.block(b));
                (first, f3(shape.node(first) - center))
            })
            .collect(),
    );
    let shapes: Box<[BlockShapes]> = shape
        .members(&blocks)
        .into_iter()
        .map(|members| BlockShapes {
            shape: shape.clone(),
            blocks,
            members: members
                .into_iter()
                .map(|m| {
                    let b = shape.local_box(m);
                    (m, (b.min - pad, b.max + pad))
                })
                .collect(),
            instances: instances.clone(),
            first_instance,
            slot,
            center,
        })
        .collect();
    let functions = || match shape {
        Implicit::Lattice(_) => UserFunctions {
            bounds: block_bounds,
            intersect: block_intersect::<Round>,
            occluded: block_occluded::<Round>,
        },
        // (Refused above.)
        Implicit::Bars(_) | Implicit::Mesh(_) | Implicit::Instance(_) => UserFunctions {
            bounds: block_bounds,
            intersect: block_intersect::<Aabb>,
            occluded: block_occluded::<Aabb>,
        },
    };
    let mut block = SceneBuilder::new(device)?;
    for s in shapes.iter() {
        let count = s.members.len() as u32;
        let mut g = Geometry::new(device, RTC_GEOMETRY_TYPE_USER)?;
        let ptr = s as *const BlockShapes as *mut std::ffi::c_void;
        // SAFETY: the shapes are boxed in the `BlockScene` returned, which releases the block
        // scene before them; the callbacks read the pointer as `BlockShapes`, and make the
        // shape kind the object makes (`functions`).
        unsafe { g.set_user(count, ptr, functions()) };
        block.attach(g)?;
    }
    let scene = block.commit()?;
    for (b, &(_, translation)) in instances.iter().enumerate() {
        let mut g = Geometry::new(device, RTC_GEOMETRY_TYPE_INSTANCE)?;
        g.set_instance(&scene, translation);
        builder.attach_as(g, first_instance + b as u32)?;
    }
    Ok(BlockScene {
        _scene: scene,
        _shapes: shapes,
    })
}

/// # Safety
/// `user` is the pointer registered for a live `BlockShapes`.
unsafe fn shapes<'r>(user: *mut std::ffi::c_void) -> &'r BlockShapes {
    unsafe { &*(user as *const BlockShapes) }
}

/// Panic-free: no indexing, float arithmetic only.
unsafe extern "C" fn block_bounds(args: *const RTCBoundsFunctionArguments) {
    // SAFETY: Embree passes the user pointer we registered and a prim below the count we set.
    unsafe {
        let args = &*args;
        let member = shapes(args.geometryUserPtr)
            .members
            .get(args.primID as usize);
        *args.bounds_o = match member {
            Some(&(_, (lo, hi))) => outward(lo, hi),
            // Never asked for; a box of everything loses nothing.
            None => everything(),
        };
    }
}

unsafe extern "C" fn block_intersect<S: FromPrimitive>(
    args: *const RTCIntersectFunctionNArguments,
) {
    // SAFETY: as for `block_bounds`; `rayhit` is an N-wide RTCRayHitN, `valid` has N entries
    // and `context` is the ExactContext the query was started with, inside an instance.
    unsafe {
        let args = &*args;
        let ctx = &*(args.context as *const ExactContext);
        guarded(Callback::BlockIntersect, ctx, || {
            let s = shapes(args.geometryUserPtr);
            let inst = (*args.context).instID[0];
            let Some(c) = s.prim::<S>(inst, args.primID, ctx.is_bare()) else {
                return;
            };
            // Numbered only if some lane hits (most calls find none).
            let mut id = None;
            let n = args.N as usize;
            let base = args.rayhit as *mut f32;
            lane_hits_within(ctx, &c.shape, c.cull, args.valid, base, n, |i, t| {
                let id = *id.get_or_insert_with(|| s.shape.member_id(c.node, c.member));
                report_hit(base, n, i, t, id as u32, s.slot, inst);
            });
        });
    }
}

unsafe extern "C" fn block_occluded<S: FromPrimitive>(args: *const RTCOccludedFunctionNArguments) {
    // SAFETY: as for `block_intersect`, with an N-wide RTCRayN.
    unsafe {
        let args = &*args;
        let ctx = &*(args.context as *const ExactContext);
        guarded(Callback::BlockOccluded, ctx, || {
            let s = shapes(args.geometryUserPtr);
            let inst = (*args.context).instID[0];
            let Some(c) = s.prim::<S>(inst, args.primID, ctx.is_bare()) else {
                return;
            };
            let n = args.N as usize;
            let base = args.ray as *mut f32;
            lane_hits_within(ctx, &c.shape, c.cull, args.valid, base, n, |i, _| {
                *base.add(TFAR * n + i) = f32::NEG_INFINITY;
            });
        });
    }
}
