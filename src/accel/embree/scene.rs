//! One Embree scene per rest-frame geometry, in f32 about the geometry's centre (so f32 never
//! sees large coordinates): Embree's triangles for meshes, while spheres, rods and boxes are
//! user geometry running the exact f64 tests (exact.rs).

use super::device::Device;
use super::exact::{self, Round, Shape, Shapes};
use crate::geometry::{Aabb, Geometry as SceneGeometry, Primitive};
use embree_sys::*;
use glam::DVec3;
use std::sync::Arc;

/// An Embree geometry handle, released on drop (the scene keeps its own reference).
pub(super) struct GeometryHandle(pub(super) RTCGeometry);

impl Drop for GeometryHandle {
    fn drop(&mut self) {
        unsafe { rtcReleaseGeometry(self.0) };
    }
}

/// Which scene primitive an Embree (geomID, primID) is: `prims[primID]`.
pub struct PrimMap {
    pub prims: Vec<u32>,
    /// User geometry whose hits are already exact f64 (the context carries their t).
    pub exact: bool,
}

/// The scene primitives of an Embree scene whose every geometry is user geometry with exact
/// hits and holds a run of the scene's primitives (`PrimMap::prims[i] = first + i`): the
/// firsts, by geomID. A hit's primitive is then `first + primID` and its t the context's, read
/// back with no lookup and no branch on whether a lane hit (the fans in `fan.rs` and the
/// packets in `packet.rs`; the paper's lattice, the bar array and every scene of spheres and
/// rods are such).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExactRuns([u32; ExactRuns::MAX]);

impl ExactRuns {
    /// Geometries at most (a scene has one of each kind).
    const MAX: usize = 4;

    /// The runs of these maps, if they are such.
    fn of(maps: &[PrimMap]) -> Option<ExactRuns> {
        let run = |m: &PrimMap| {
            let first = *m.prims.first()?;
            let consecutive = (first..).zip(&m.prims).all(|(want, &p)| p == want);
            (m.exact && consecutive).then_some(first)
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

pub struct Scene {
    pub(super) raw: RTCScene,
    /// Indexed by geomID.
    pub maps: Vec<PrimMap>,
    /// The maps as runs, where they are runs of exact geometries.
    pub exact_runs: Option<ExactRuns>,
    /// Embree coordinates are rest-frame coordinates minus this.
    pub center: DVec3,
    /// What Embree's user geometry points into; dropped after the scene is released.
    rounds: Option<Box<Shapes<Round>>>,
    cuboids: Option<Box<Shapes<Aabb>>>,
    _device: Arc<Device>,
}

unsafe impl Send for Scene {}
unsafe impl Sync for Scene {}

impl Drop for Scene {
    fn drop(&mut self) {
        unsafe { rtcReleaseScene(self.raw) };
    }
}

/// A new Embree geometry of this kind.
pub(super) fn new_geometry(
    device: &Device,
    kind: RTCGeometryType,
) -> crate::Result<GeometryHandle> {
    let g = unsafe { rtcNewGeometry(device.raw, kind) };
    if g.is_null() {
        device.check("creating a geometry")?;
        return Err(crate::Error::backend("Embree could not create a geometry"));
    }
    Ok(GeometryHandle(g))
}

fn f3(p: DVec3) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

impl Scene {
    pub fn build(device: Arc<Device>, geo: &SceneGeometry) -> crate::Result<Scene> {
        let center = geo.bounds().centroid();
        let center = if center.is_finite() {
            center
        } else {
            DVec3::ZERO
        };
        let raw = unsafe { rtcNewScene(device.raw) };
        if raw.is_null() {
            device.check("creating a scene")?;
            return Err(crate::Error::backend("Embree could not create a scene"));
        }
        let mut scene = Scene {
            raw,
            maps: Vec::new(),
            exact_runs: None,
            center,
            rounds: None,
            cuboids: None,
            _device: device.clone(),
        };
        unsafe {
            rtcSetSceneBuildQuality(raw, RTC_BUILD_QUALITY_HIGH);
            rtcSetSceneFlags(raw, RTC_SCENE_FLAG_ROBUST);
        }
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
        if !tris.is_empty() {
            let g = new_geometry(&device, RTC_GEOMETRY_TYPE_TRIANGLE)?;
            let verts = scene.buffer::<[f32; 3]>(
                &g,
                RTC_BUFFER_TYPE_VERTEX,
                RTC_FORMAT_FLOAT3,
                tris.len() * 3,
            )?;
            for (k, t) in tris.iter().enumerate() {
                verts[k * 3..k * 3 + 3].copy_from_slice(t);
            }
            let idx = scene.buffer::<[u32; 3]>(
                &g,
                RTC_BUFFER_TYPE_INDEX,
                RTC_FORMAT_UINT3,
                tris.len(),
            )?;
            for (k, slot) in idx.iter_mut().enumerate() {
                *slot = [3 * k as u32, 3 * k as u32 + 1, 3 * k as u32 + 2];
            }
            scene.attach(&device, g, tri_map, false)?;
        }
        scene.rounds = scene.user_geometry(&device, rounds, round_map)?;
        scene.cuboids = scene.user_geometry(&device, cuboids, cuboid_map)?;
        unsafe { rtcCommitScene(raw) };
        device.check("committing a scene")?;
        scene.exact_runs = ExactRuns::of(&scene.maps);
        Ok(scene)
    }

    /// Attach `shapes` (scene primitives `map`) as one user geometry whose hits are exact; the
    /// returned box is what Embree points into.
    fn user_geometry<S: Shape>(
        &mut self,
        device: &Device,
        shapes: Vec<S>,
        map: Vec<u32>,
    ) -> crate::Result<Option<Box<Shapes<S>>>> {
        if shapes.is_empty() {
            return Ok(None);
        }
        let g = new_geometry(device, RTC_GEOMETRY_TYPE_USER)?;
        let data = Box::new(Shapes(shapes));
        let ptr = &*data as *const Shapes<S> as *mut std::ffi::c_void;
        // SAFETY: `data` outlives the Embree scene (the scene drops it after releasing the
        // scene), and the callbacks read it as `Shapes<S>`.
        unsafe {
            rtcSetGeometryUserPrimitiveCount(g.0, data.0.len() as u32);
            rtcSetGeometryUserData(g.0, ptr);
            rtcSetGeometryBoundsFunction(g.0, Some(exact::bounds::<S>), ptr);
            rtcSetGeometryIntersectFunction(g.0, Some(exact::intersect::<S>));
            rtcSetGeometryOccludedFunction(g.0, Some(exact::occluded::<S>));
        }
        self.attach(device, g, map, true)?;
        Ok(Some(data))
    }

    /// A new buffer of `count` items of T on the geometry, as a slice to fill.
    #[allow(clippy::mut_from_ref)]
    fn buffer<T: Copy>(
        &self,
        g: &GeometryHandle,
        kind: RTCBufferType,
        format: RTCFormat,
        count: usize,
    ) -> crate::Result<&mut [T]> {
        let stride = std::mem::size_of::<T>();
        let ptr = unsafe { rtcSetNewGeometryBuffer(g.0, kind, 0, format, stride, count) };
        self._device.check("allocating a buffer")?;
        if ptr.is_null() {
            return Err(crate::Error::backend(
                "Embree could not allocate a geometry buffer",
            ));
        }
        let n = count;
        // SAFETY: Embree allocated count * stride bytes, aligned for f32/u32, owned by the
        // geometry, which outlives this slice (it is filled before the geometry is committed).
        Ok(unsafe { std::slice::from_raw_parts_mut(ptr as *mut T, n) })
    }

    fn attach(
        &mut self,
        device: &Device,
        g: GeometryHandle,
        prims: Vec<u32>,
        exact: bool,
    ) -> crate::Result<()> {
        unsafe { rtcCommitGeometry(g.0) };
        device.check("committing a geometry")?;
        let id = unsafe { rtcAttachGeometry(self.raw, g.0) } as usize;
        device.check("attaching a geometry")?;
        if self.maps.len() <= id {
            self.maps.resize_with(id + 1, || PrimMap {
                prims: Vec::new(),
                exact: false,
            });
        }
        self.maps[id] = PrimMap { prims, exact };
        Ok(())
    }

    /// The scene primitive an Embree hit names, and whether its t is exact already.
    pub fn prim(&self, geom: u32, prim: u32) -> Option<(u32, bool)> {
        let m = self.maps.get(geom as usize)?;
        Some((*m.prims.get(prim as usize)?, m.exact))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(prims: &[u32], exact: bool) -> PrimMap {
        PrimMap {
            prims: prims.to_vec(),
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
