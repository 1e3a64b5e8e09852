//! One Embree scene per rest-frame geometry, in f32 about the geometry's centre (so f32 never
//! sees large coordinates): Embree's triangles for meshes, while spheres, rods and boxes are
//! user geometry running the exact f64 tests (exact.rs), and lattices and bar arrays held as
//! themselves are instances of one block (instanced_blocks.rs).

use super::exact::{self, Round, Shape, Shapes};
use super::instanced_blocks::{self, BlockScene};
use super::rtc::{f3, CommittedScene, Device, Geometry, SceneBuilder, UserFunctions};
use crate::geometry::{
    Aabb, Blocks, Geometry as SceneGeometry, Implicit, ImplicitRun, IndexedMesh, Primitive,
};
use embree_sys::*;
use glam::DVec3;
use std::sync::Arc;

/// Which scene primitive an Embree (geomID, primID) is.
pub struct PrimMap {
    pub prims: Prims,
    /// User geometry whose hits are already exact f64 (the context carries their t).
    pub exact: bool,
}

/// The scene primitives of one geomID, by primID.
pub enum Prims {
    /// `list[primID]`.
    Listed(Vec<u32>),
    /// `first + primID`: a lattice held as itself, whose callbacks report its own numbers.
    From(u32),
}

impl PrimMap {
    /// The scene primitive `prim` names.
    fn get(&self, prim: u32) -> Option<u32> {
        match &self.prims {
            Prims::Listed(list) => list.get(prim as usize).copied(),
            Prims::From(first) => Some(first + prim),
        }
    }
}

/// The scene primitives of an Embree scene whose every geometry is user geometry with exact
/// hits and holds a run of the scene's primitives (`PrimMap::prims[i] = first + i`): the
/// firsts, by geomID. A hit's primitive is then `first + primID` and its t the context's, read
/// back with no lookup and no branch on whether a lane hit (the fans in `fan_kernel.rs` and the
/// packets in `packet.rs`; the paper's lattice, the bar array and every scene of spheres and
/// rods are such).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExactRuns([u32; ExactRuns::MAX]);

impl ExactRuns {
    /// Geometries at most (a scene has one of each kind).
    const MAX: usize = 4;

    /// The runs of these maps, if they are such.
    fn of(maps: &[PrimMap]) -> Option<ExactRuns> {
        let run = |m: &PrimMap| match &m.prims {
            Prims::Listed(list) => {
                let first = *list.first()?;
                let consecutive = (first..).zip(list).all(|(want, &p)| p == want);
                (m.exact && consecutive).then_some(first)
            }
            Prims::From(first) => m.exact.then_some(*first),
        };
        let mut firsts = [0; ExactRuns::MAX];
        if maps.is_empty() || maps.len() > ExactRuns::MAX {
            return None;
        }
        for (f, m) in firsts.iter_mut().zip(maps) {
            *f = run(m)?;
        }
        Some(ExactRuns(firsts))
    }

    /// The scene primitive Embree's (geomID, primID) names, None for no hit: worked out
    /// whether or not the lane hit, so that the callers' selects need no branch.
    #[inline(always)]
    pub fn hit(&self, geom: u32, prim: u32) -> Option<u32> {
        let p = self.0[geom as usize % ExactRuns::MAX].wrapping_add(prim);
        (geom != RTC_INVALID_GEOMETRY_ID).then_some(p)
    }
}

/// The instance geometries of shared meshes' placements: geomIDs `first_id ..`, each
/// placement's first scene primitive by geomID less `first_id`.
#[derive(Default)]
pub struct MeshInstances {
    first_id: u32,
    firsts: Vec<u32>,
}

impl MeshInstances {
    /// The scene primitive a hit on triangle `prim` of instance `inst` names, if `inst` is
    /// one of these (not a block's instance, nor none).
    #[inline(always)]
    pub fn hit(&self, inst: u32, prim: u32) -> Option<u32> {
        let k = inst.wrapping_sub(self.first_id) as usize;
        self.firsts.get(k).map(|first| first + prim)
    }

    fn is_empty(&self) -> bool {
        self.firsts.is_empty()
    }
}

/// A group's geometry as an Embree scene, and what its hits mean.
pub struct EmbreeScene {
    /// Released before the shapes below, which it points into (fields drop in order).
    pub(super) rtc: CommittedScene,
    /// Indexed by geomID.
    pub maps: Vec<PrimMap>,
    /// The maps as runs, where they are runs of exact geometries.
    pub exact_runs: Option<ExactRuns>,
    /// Embree coordinates are rest-frame coordinates minus this.
    pub center: DVec3,
    /// Whether occlusion packets may be traced with Embree's coherent flag (not into
    /// instances: `EmbreeAccel::context`).
    pub coherent_occlusion: bool,
    /// The placements of shared meshes (`Implicit::Instance`): Embree instances of one scene
    /// per mesh, whose hits name the placement by instID.
    pub mesh_instances: MeshInstances,
    /// What Embree's user geometry points into; dropped after the scene is released.
    _rounds: Option<Box<Shapes<Round>>>,
    _cuboids: Option<Box<Shapes<Aabb>>>,
    /// The implicit objects' block scenes (and what their callbacks read), likewise.
    _blocks: Vec<BlockScene>,
    /// The meshes whose index buffers Embree reads in place, likewise.
    _meshes: Vec<Arc<IndexedMesh>>,
}

impl EmbreeScene {
    /// The scene of `geo`, compact (`SceneBuilder::compact`) where it holds `compact_from`
    /// triangles or more, and the scene of each shared mesh it places likewise.
    pub fn build(
        device: Arc<Device>,
        geo: &SceneGeometry,
        scenes: &MeshScenes,
        compact_from: u64,
    ) -> crate::Result<EmbreeScene> {
        let center = geo.bounds().centroid();
        let center = if center.is_finite() {
            center
        } else {
            DVec3::ZERO
        };
        let (mut tris, mut tri_map): (Vec<[[f32; 3]; 3]>, Vec<u32>) = (Vec::new(), Vec::new());
        let (mut cuboids, mut cuboid_map): (Vec<Aabb>, Vec<u32>) = (Vec::new(), Vec::new());
        let (mut rounds, mut round_map): (Vec<Round>, Vec<u32>) = (Vec::new(), Vec::new());
        for (i, p) in geo.prims.iter().enumerate() {
            let i = i as u32;
            match *p {
                Primitive::Sphere { center: c, radius } => {
                    rounds.push(Round {
                        a: c - center,
                        b: c - center,
                        radius,
                    });
                    round_map.push(i);
                }
                Primitive::Capsule { a, b, radius } => {
                    rounds.push(Round {
                        a: a - center,
                        b: b - center,
                        radius,
                    });
                    round_map.push(i);
                }
                Primitive::Cuboid { min, max } => {
                    cuboids.push(Aabb::new(min - center, max - center));
                    cuboid_map.push(i);
                }
                Primitive::Triangle { v } => {
                    tris.push(v.map(|x| f3(x - center)));
                    tri_map.push(i);
                }
            }
        }
        // What the user geometries point into, made before the scene so that it is released
        // first should the build fail (locals drop in reverse order).
        let rounds = (!rounds.is_empty()).then(|| Box::new(Shapes(rounds)));
        let cuboids = (!cuboids.is_empty()).then(|| Box::new(Shapes(cuboids)));
        let mut builder = SceneBuilder::new(&device)?;
        let triangles = tris.len() as u64
            + geo
                .implicit
                .iter()
                .map(|r| match &r.shape {
                    Implicit::Mesh(mesh) => mesh.len(),
                    _ => 0,
                })
                .sum::<u64>();
        if triangles >= compact_from {
            builder.compact();
        }
        let mut maps = Vec::new();
        if !tris.is_empty() {
            let mut g = Geometry::new(&device, RTC_GEOMETRY_TYPE_TRIANGLE)?;
            let verts = g.new_buffer::<[f32; 3]>(
                RTC_BUFFER_TYPE_VERTEX,
                RTC_FORMAT_FLOAT3,
                tris.len() * 3,
            )?;
            for (k, t) in tris.iter().enumerate() {
                verts[k * 3..k * 3 + 3].copy_from_slice(t);
            }
            let idx =
                g.new_buffer::<[u32; 3]>(RTC_BUFFER_TYPE_INDEX, RTC_FORMAT_UINT3, tris.len())?;
            for (k, slot) in idx.iter_mut().enumerate() {
                *slot = [3 * k as u32, 3 * k as u32 + 1, 3 * k as u32 + 2];
            }
            attach(&mut builder, &mut maps, g, Prims::Listed(tri_map), false)?;
        }
        // Meshes held as themselves: Embree's triangle geometry over their shared vertices
        // (rebased, in f32), hits refined in f64 on the triangle as the listed ones are.
        for run in &geo.implicit {
            if let Implicit::Mesh(mesh) = &run.shape {
                let g = mesh_geometry(&device, mesh, center)?;
                attach(&mut builder, &mut maps, g, Prims::From(run.first), false)?;
            }
        }
        if let Some(shapes) = &rounds {
            let g = user_geometry(&device, shapes)?;
            attach(&mut builder, &mut maps, g, Prims::Listed(round_map), true)?;
        }
        if let Some(shapes) = &cuboids {
            let g = user_geometry(&device, shapes)?;
            attach(&mut builder, &mut maps, g, Prims::Listed(cuboid_map), true)?;
        }
        // Each object held as itself: a slot for its hits' geomID after the geometries above,
        // and its instances' geomIDs after every slot.
        let instanced: Vec<&ImplicitRun> = geo
            .implicit
            .iter()
            .filter(|r| !matches!(r.shape, Implicit::Mesh(_) | Implicit::Instance(_)))
            .collect();
        let mut first_instance = (maps.len() + instanced.len()) as u32;
        let mut blocks = Vec::with_capacity(instanced.len());
        for run in instanced.iter().copied() {
            let slot = maps.len() as u32;
            maps.push(PrimMap {
                prims: Prims::From(run.first),
                exact: true,
            });
            blocks.push(instanced_blocks::attach(
                &device,
                &mut builder,
                run,
                center,
                slot,
                first_instance,
            )?);
            first_instance += Blocks::of(run.shape.grid()).count() as u32;
        }
        // Placements of shared meshes: one Embree scene per mesh, an instance per placement,
        // after every other geometry.
        let mesh_instances = attach_mesh_instances(
            &device,
            &mut builder,
            geo,
            center,
            first_instance,
            scenes,
            compact_from,
        )?;
        let exact_runs = ExactRuns::of(&maps).filter(|_| mesh_instances.is_empty());
        Ok(EmbreeScene {
            rtc: builder.commit()?,
            maps,
            exact_runs,
            center,
            coherent_occlusion: blocks.is_empty() && mesh_instances.is_empty(),
            mesh_instances,
            _meshes: geo
                .implicit
                .iter()
                .filter_map(|r| match &r.shape {
                    Implicit::Mesh(m) => Some(m.clone()),
                    Implicit::Instance(m) => Some(m.mesh.clone()),
                    _ => None,
                })
                .collect(),
            _rounds: rounds,
            _cuboids: cuboids,
            _blocks: blocks,
        })
    }

    /// The scene primitive an Embree hit names (on geometry `geom` of instance `inst`, none
    /// at the top level), and whether its t is exact already.
    #[inline(always)]
    pub fn prim(&self, geom: u32, prim: u32, inst: u32) -> Option<(u32, bool)> {
        if let Some(p) = self.mesh_instances.hit(inst, prim) {
            return Some((p, false));
        }
        let m = self.maps.get(geom as usize)?;
        Some((m.get(prim)?, m.exact))
    }
}

/// A user geometry over `shapes`, whose hits are exact (exact.rs).
fn user_geometry<S: Shape>(device: &Arc<Device>, shapes: &Shapes<S>) -> crate::Result<Geometry> {
    let mut g = Geometry::new(device, RTC_GEOMETRY_TYPE_USER)?;
    let ptr = shapes as *const Shapes<S> as *mut std::ffi::c_void;
    let functions = UserFunctions {
        bounds: exact::bounds::<S>,
        intersect: exact::intersect::<S>,
        occluded: exact::occluded::<S>,
    };
    // SAFETY: `shapes` is boxed in the `EmbreeScene` the geometry's scene goes into, and dropped
    // after that scene is released; the callbacks read it as `Shapes<S>`.
    unsafe { g.set_user(shapes.0.len() as u32, ptr, functions) };
    Ok(g)
}

/// The Embree scenes of shared meshes, one per mesh (about its own centre), by the mesh's
/// address: kept by the backend, so that every velocity group placing a mesh instances the one
/// scene. An entry lives while its mesh does (the mesh's index buffer is the scene's, read in
/// place; every `EmbreeScene` instancing it holds the mesh): a dead mesh's entry is dropped
/// before any lookup, so no other mesh found at its address is taken for it.
#[derive(Default)]
pub struct MeshScenes(std::sync::Mutex<std::collections::HashMap<usize, MeshScene>>);

/// A shared mesh, its Embree scene, and the centre the scene's coordinates are taken about.
type MeshScene = (std::sync::Weak<IndexedMesh>, Arc<CommittedScene>, DVec3);

impl MeshScenes {
    /// Whether each scene held was built compact.
    #[cfg(test)]
    pub fn compact(&self) -> Vec<bool> {
        let scenes = self.0.lock().unwrap_or_else(|e| e.into_inner());
        scenes.values().map(|(_, s, _)| s.is_compact()).collect()
    }

    /// `mesh`'s scene and the centre its coordinates are taken about, built on first use.
    /// (Compact where the mesh has `compact_from` triangles or more: the backend asks the same
    /// of every scene, so a scene found here was built as asked.)
    fn of(
        &self,
        device: &Arc<Device>,
        mesh: &Arc<IndexedMesh>,
        compact_from: u64,
    ) -> crate::Result<(Arc<CommittedScene>, DVec3)> {
        let mut scenes = self.0.lock().unwrap_or_else(|e| e.into_inner());
        // Meshes no longer held anywhere (a scene the viewer read again, say) leave with their
        // scenes: nothing traces those any more, since every scene instancing one holds its mesh.
        scenes.retain(|_, (m, _, _)| m.strong_count() > 0);
        let key = Arc::as_ptr(mesh) as usize;
        if let Some((m, scene, own)) = scenes.get(&key) {
            // Alive, at this address, it is this mesh.
            if m.upgrade().is_some_and(|m| Arc::ptr_eq(&m, mesh)) {
                return Ok((scene.clone(), *own));
            }
        }
        let own = mesh.bounds().centroid();
        let own = if own.is_finite() { own } else { DVec3::ZERO };
        let mut child = SceneBuilder::new(device)?;
        if mesh.len() >= compact_from {
            child.compact();
        }
        child.attach(mesh_geometry(device, mesh, own)?)?;
        let scene = Arc::new(child.commit()?);
        scenes.insert(key, (Arc::downgrade(mesh), scene.clone(), own));
        Ok((scene, own))
    }
}

/// Each placement of a shared mesh in `geo` as an Embree instance, as geomIDs `first_id ..`:
/// the mesh once, as its own scene about its own centre, and each placement's map from it to
/// this scene's coordinates (less `center`), made in f64 and cast to f32.
fn attach_mesh_instances(
    device: &Arc<Device>,
    builder: &mut SceneBuilder,
    geo: &SceneGeometry,
    center: DVec3,
    first_id: u32,
    scenes: &MeshScenes,
    compact_from: u64,
) -> crate::Result<MeshInstances> {
    let mut out = MeshInstances {
        first_id,
        firsts: Vec::new(),
    };
    for run in &geo.implicit {
        let Implicit::Instance(inst) = &run.shape else {
            continue;
        };
        let (scene, own) = scenes.of(device, &inst.mesh, compact_from)?;
        let own = &own;
        // x in the mesh's scene is the mesh's point x + own; placed, less `center`:
        // A (x + own) + translate - center, with A the linear map times the scale.
        let x = &inst.place;
        let a = x.linear * glam::DMat3::from_diagonal(x.scale);
        let shift = a * *own + x.translate - center;
        let cols = a.to_cols_array();
        let mut xfm = [0f32; 12];
        for (slot, v) in xfm.iter_mut().zip(cols.iter().chain(&shift.to_array())) {
            *slot = *v as f32;
        }
        let mut g = Geometry::new(device, RTC_GEOMETRY_TYPE_INSTANCE)?;
        g.set_instance_affine(&scene, xfm);
        builder.attach_as(g, first_id + out.firsts.len() as u32)?;
        out.firsts.push(run.first);
    }
    Ok(out)
}

/// A mesh's triangles as Embree's triangle geometry: its vertices once (less `center`, in f32)
/// and its index buffer.
fn mesh_geometry(
    device: &Arc<Device>,
    mesh: &IndexedMesh,
    center: DVec3,
) -> crate::Result<Geometry> {
    let mut g = Geometry::new(device, RTC_GEOMETRY_TYPE_TRIANGLE)?;
    let p = mesh.positions();
    let verts = g.new_buffer::<[f32; 3]>(RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT3, p.len())?;
    for (slot, x) in verts.iter_mut().zip(p) {
        *slot = f3(x - center);
    }
    // The index buffer is the mesh's own, not a copy (12 bytes a triangle saved).
    // SAFETY: the mesh is an `Arc` the `EmbreeScene` keeps (`_meshes`) and drops after the
    // scene is released; an `IndexedMesh` never changes.
    unsafe {
        g.share_buffer(RTC_BUFFER_TYPE_INDEX, RTC_FORMAT_UINT3, mesh.triangles())?;
    }
    Ok(g)
}

/// Attach `g`, whose primitives are the scene's `prims`, recording them by geomID.
fn attach(
    builder: &mut SceneBuilder,
    maps: &mut Vec<PrimMap>,
    g: Geometry,
    prims: Prims,
    exact: bool,
) -> crate::Result<()> {
    let id = builder.attach(g)? as usize;
    if maps.len() <= id {
        maps.resize_with(id + 1, || PrimMap {
            prims: Prims::Listed(Vec::new()),
            exact: false,
        });
    }
    maps[id] = PrimMap { prims, exact };
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(prims: &[u32], exact: bool) -> PrimMap {
        PrimMap {
            prims: Prims::Listed(prims.to_vec()),
            exact,
        }
    }

    #[test]
    fn runs_of_exact_geometries_only() {
        let runs = ExactRuns::of(&[map(&[0, 1, 2], true), map(&[3, 4], true)]).unwrap();
        assert_eq!(
            (runs.hit(0, 2), runs.hit(1, 0), runs.hit(1, 1)),
            (Some(2), Some(3), Some(4))
        );
        assert_eq!(runs.hit(RTC_INVALID_GEOMETRY_ID, 0), None);
        assert_eq!(
            ExactRuns::of(&[map(&[5], true)]).unwrap().hit(0, 0),
            Some(5)
        );
        // Interleaved kinds (a sphere, a box, a sphere), a geometry refined after Embree
        // (triangles), an empty map, no geometry, more than there are kinds.
        for maps in [
            vec![map(&[0, 2], true), map(&[1], true)],
            vec![map(&[0, 1], true), map(&[2], false)],
            vec![map(&[], true)],
            vec![],
            (0..5).map(|i| map(&[i], true)).collect(),
        ] {
            assert_eq!(ExactRuns::of(&maps), None);
        }
    }
}
