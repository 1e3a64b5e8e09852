//! A lattice held as itself (`LatticeRun`) as Embree instances: one Embree scene of a block's
//! spheres and rods (user geometry, in the block's own coordinates) placed at every block's
//! corner by a translation. Embree's f32 traversal only finds candidates; the callbacks make
//! the lattice's own primitive from its number and test it in f64 on the caller's ray, as the
//! listed lattice's user geometry does (exact.rs), so hits keep their exact lookback times,
//! and a block's numbers the lattice does not have (past its far faces) are skipped.

use super::exact::{
    lane_hits_within, outward, ExactContext, Round, GEOM_ID, INST_ID, NG, PRIM_ID, U,
};
use super::rtc::field::TFAR;
use super::rtc::{CommittedScene, Device, Geometry, SceneBuilder, UserFunctions};
use super::scene::f3;
use crate::geometry::{Aabb, Blocks, Lattice, LatticeRun, Member, Primitive};
use embree_sys::*;
use glam::DVec3;
use std::sync::Arc;

/// One kind of a block's primitives (its spheres, or its rods), as its user geometry's
/// callbacks read them.
struct BlockShapes {
    lattice: Lattice,
    blocks: Blocks,
    /// The primitives, by primID, with their padded local boxes.
    members: Vec<(Member, (DVec3, DVec3))>,
    /// Each instance's block: its first node and its translation as Embree has it, by
    /// instance (geomID minus `first_instance`).
    instances: Arc<Vec<([u32; 3], [f32; 3])>>,
    /// The geomID of block 0's instance; block b's is this plus b.
    first_instance: u32,
    /// The geomID written in hits, whose map gives the lattice's first number.
    slot: u32,
    /// Embree coordinates are the lattice's minus this.
    center: DVec3,
}

impl BlockShapes {
    /// Primitive `p` of instance `inst`, if the lattice has it: its number, the shape to test
    /// (relative to the Embree scene's centre; for bare rays in the instance's own
    /// coordinates, where Embree's rays are) and the local box to cull lanes with.
    #[inline]
    fn prim(&self, inst: u32, p: u32, bare: bool) -> Option<(u64, Round, (DVec3, DVec3))> {
        let (first, translation) = *self
            .instances
            .get(inst.wrapping_sub(self.first_instance) as usize)?;
        let (m, cull) = self.members[p as usize];
        let l = &self.lattice;
        let n = self.blocks.place(l, first, m)?;
        let shift = if bare {
            self.center + DVec3::from_array(translation.map(f64::from))
        } else {
            self.center
        };
        let round = match l.member_prim(n, m) {
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
        };
        Some((l.member_id(n, m), round, cull))
    }
}

/// A lattice's block scene and what its callbacks read: released in that order.
pub struct BlockScene {
    _scene: CommittedScene,
    /// Never grown or moved out of: Embree holds pointers into it.
    _shapes: Box<[BlockShapes]>,
}

/// Build `run`'s block scene and attach one instance of it per block to `builder`, as geomIDs
/// `first_instance ..`; hits are reported with geomID `slot` and primID the lattice's number.
pub fn attach(
    device: &Arc<Device>,
    builder: &mut SceneBuilder,
    run: &LatticeRun,
    center: DVec3,
    slot: u32,
    first_instance: u32,
) -> crate::Result<BlockScene> {
    let l = &run.lattice;
    let blocks = Blocks::of(l);
    let bounds = l.bounds();
    let span = Aabb::new(bounds.min - center, bounds.max - center).max_abs();
    // What local boxes are padded by: the f32 rounding of the instances' translations and of
    // the corners, so that a box holds its primitive seen from any instance.
    let pad = DVec3::splat(span * f64::from(f32::EPSILON) + blocks.local_slack(l));
    let padded = |b: Aabb| (b.min - pad, b.max + pad);
    let instances: Arc<Vec<([u32; 3], [f32; 3])>> = Arc::new(
        (0..blocks.count())
            .map(|b| {
                let b = blocks.block(b);
                (blocks.first_of(b), f3(blocks.corner(l, b) - center))
            })
            .collect(),
    );
    let nodes = blocks.nodes();
    let spheres = (l.sphere_count() > 0).then(|| {
        (0..nodes)
            .map(|p| (blocks.sphere_member(p), padded(blocks.local_sphere(l, p))))
            .collect::<Vec<_>>()
    });
    let rods = (l.rod_count() > 0).then(|| {
        (0..3 * nodes)
            .map(|p| (blocks.rod_member(p), padded(blocks.local_rod(l, p))))
            .collect::<Vec<_>>()
    });
    let shapes: Box<[BlockShapes]> = spheres
        .into_iter()
        .chain(rods)
        .map(|members| BlockShapes {
            lattice: l.clone(),
            blocks,
            members,
            instances: instances.clone(),
            first_instance,
            slot,
            center,
        })
        .collect();
    let mut block = SceneBuilder::new(device)?;
    for s in shapes.iter() {
        let count = s.members.len() as u32;
        let mut g = Geometry::new(device, RTC_GEOMETRY_TYPE_USER)?;
        let ptr = s as *const BlockShapes as *mut std::ffi::c_void;
        // SAFETY: the shapes are boxed in the `BlockScene` returned, which releases the block
        // scene before them; the callbacks read the pointer as `BlockShapes`.
        unsafe {
            g.set_user(
                count,
                ptr,
                UserFunctions {
                    bounds: block_bounds,
                    intersect: block_intersect,
                    occluded: block_occluded,
                },
            )
        };
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

unsafe extern "C" fn block_bounds(args: *const RTCBoundsFunctionArguments) {
    // SAFETY: Embree passes the user pointer we registered and a prim below the count we set.
    unsafe {
        let args = &*args;
        let (lo, hi) = shapes(args.geometryUserPtr).members[args.primID as usize].1;
        *args.bounds_o = outward(lo, hi);
    }
}

unsafe extern "C" fn block_intersect(args: *const RTCIntersectFunctionNArguments) {
    // SAFETY: as for `block_bounds`; `rayhit` is an N-wide RTCRayHitN, `valid` has N entries
    // and `context` is the ExactContext the query was started with, inside an instance.
    unsafe {
        let args = &*args;
        let s = shapes(args.geometryUserPtr);
        let ctx = &*(args.context as *const ExactContext);
        let inst = (*args.context).instID[0];
        let Some((id, round, cull)) = s.prim(inst, args.primID, ctx.is_bare()) else {
            return;
        };
        let n = args.N as usize;
        let base = args.rayhit as *mut f32;
        lane_hits_within(ctx, &round, cull, args.valid, base, n, |i, t| {
            let slot = |k: usize| base.add(k * n + i);
            *slot(TFAR) = t;
            *slot(NG) = 0.0;
            *slot(NG + 1) = 0.0;
            *slot(NG + 2) = 1.0;
            *slot(U) = 0.0;
            *slot(U + 1) = 0.0;
            *(slot(PRIM_ID) as *mut u32) = id as u32;
            *(slot(GEOM_ID) as *mut u32) = s.slot;
            *(slot(INST_ID) as *mut u32) = inst;
        });
    }
}

unsafe extern "C" fn block_occluded(args: *const RTCOccludedFunctionNArguments) {
    // SAFETY: as for `block_intersect`, with an N-wide RTCRayN.
    unsafe {
        let args = &*args;
        let s = shapes(args.geometryUserPtr);
        let ctx = &*(args.context as *const ExactContext);
        let inst = (*args.context).instID[0];
        let Some((_, round, cull)) = s.prim(inst, args.primID, ctx.is_bare()) else {
            return;
        };
        let n = args.N as usize;
        let base = args.ray as *mut f32;
        lane_hits_within(ctx, &round, cull, args.valid, base, n, |i, _| {
            *base.add(TFAR * n + i) = f32::NEG_INFINITY;
        });
    }
}
