//! One Embree scene per rest-frame geometry, in f32 about the geometry's centre (so f32 never
//! sees large coordinates), with native primitives: triangles for boxes and meshes, sphere
//! points for spheres, round linear curves for rods.

use super::device::Device;
use crate::geometry::{Geometry as SceneGeometry, Primitive};
use embree_sys::*;
use glam::DVec3;
use std::sync::Arc;

/// An Embree geometry handle, released on drop (the scene keeps its own reference).
struct GeometryHandle(RTCGeometry);

impl Drop for GeometryHandle {
    fn drop(&mut self) {
        unsafe { rtcReleaseGeometry(self.0) };
    }
}

/// Which scene primitive an Embree (geomID, primID) is: `prims[primID / per]`.
pub struct PrimMap {
    pub prims: Vec<u32>,
    pub per: u32,
}

pub struct Scene {
    pub(super) raw: RTCScene,
    /// Indexed by geomID.
    pub maps: Vec<PrimMap>,
    /// Embree coordinates are rest-frame coordinates minus this.
    pub center: DVec3,
    _device: Arc<Device>,
}

unsafe impl Send for Scene {}
unsafe impl Sync for Scene {}

impl Drop for Scene {
    fn drop(&mut self) {
        unsafe { rtcReleaseScene(self.raw) };
    }
}

const BOX_TRIANGLES: [[u32; 3]; 12] = [
    [0, 2, 1],
    [1, 2, 3], // x = min
    [4, 5, 6],
    [5, 7, 6], // x = max
    [0, 1, 4],
    [1, 5, 4], // y = min
    [2, 6, 3],
    [3, 6, 7], // y = max
    [0, 4, 2],
    [2, 4, 6], // z = min
    [1, 3, 5],
    [3, 7, 5], // z = max
];

fn f3(p: DVec3) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

impl Scene {
    pub fn build(device: Arc<Device>, geo: &SceneGeometry) -> Result<Scene, String> {
        let center = geo.bounds().centroid();
        let center = if center.is_finite() {
            center
        } else {
            DVec3::ZERO
        };
        let raw = unsafe { rtcNewScene(device.raw) };
        if raw.is_null() {
            device.check("creating a scene")?;
            return Err("Embree could not create a scene".into());
        }
        let mut scene = Scene {
            raw,
            maps: Vec::new(),
            center,
            _device: device.clone(),
        };
        unsafe {
            rtcSetSceneBuildQuality(raw, RTC_BUILD_QUALITY_HIGH);
            rtcSetSceneFlags(raw, RTC_SCENE_FLAG_ROBUST);
        }
        let (mut tris, mut tri_map): (Vec<[[f32; 3]; 3]>, Vec<u32>) = (Vec::new(), Vec::new());
        let (mut boxes, mut box_map): (Vec<(DVec3, DVec3)>, Vec<u32>) = (Vec::new(), Vec::new());
        let (mut spheres, mut sphere_map): (Vec<[f32; 4]>, Vec<u32>) = (Vec::new(), Vec::new());
        let (mut rods, mut rod_map): (Vec<[[f32; 4]; 2]>, Vec<u32>) = (Vec::new(), Vec::new());
        for (i, p) in geo.prims.iter().enumerate() {
            let i = i as u32;
            match *p {
                Primitive::Sphere { center: c, radius } => {
                    let q = f3(c - center);
                    spheres.push([q[0], q[1], q[2], radius as f32]);
                    sphere_map.push(i);
                }
                Primitive::Capsule { a, b, radius } => {
                    let (qa, qb) = (f3(a - center), f3(b - center));
                    let r = radius as f32;
                    rods.push([[qa[0], qa[1], qa[2], r], [qb[0], qb[1], qb[2], r]]);
                    rod_map.push(i);
                }
                Primitive::Cuboid { min, max } => {
                    boxes.push((min - center, max - center));
                    box_map.push(i);
                }
                Primitive::Triangle { v } => {
                    tris.push(v.map(|x| f3(x - center)));
                    tri_map.push(i);
                }
            }
        }
        if !boxes.is_empty() {
            let g = scene.new_geometry(&device, RTC_GEOMETRY_TYPE_TRIANGLE)?;
            let verts = scene.buffer::<[f32; 3]>(
                &g,
                RTC_BUFFER_TYPE_VERTEX,
                RTC_FORMAT_FLOAT3,
                boxes.len() * 8,
            )?;
            for (k, (lo, hi)) in boxes.iter().enumerate() {
                for c in 0..8 {
                    let p = DVec3::new(
                        if c & 4 != 0 { hi.x } else { lo.x },
                        if c & 2 != 0 { hi.y } else { lo.y },
                        if c & 1 != 0 { hi.z } else { lo.z },
                    );
                    verts[k * 8 + c] = f3(p);
                }
            }
            let idx = scene.buffer::<[u32; 3]>(
                &g,
                RTC_BUFFER_TYPE_INDEX,
                RTC_FORMAT_UINT3,
                boxes.len() * 12,
            )?;
            for k in 0..boxes.len() {
                for (t, tri) in BOX_TRIANGLES.iter().enumerate() {
                    idx[k * 12 + t] = tri.map(|c| (k * 8) as u32 + c);
                }
            }
            scene.attach(&device, g, box_map, 12)?;
        }
        if !tris.is_empty() {
            let g = scene.new_geometry(&device, RTC_GEOMETRY_TYPE_TRIANGLE)?;
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
            scene.attach(&device, g, tri_map, 1)?;
        }
        if !spheres.is_empty() {
            let g = scene.new_geometry(&device, RTC_GEOMETRY_TYPE_SPHERE_POINT)?;
            let verts = scene.buffer::<[f32; 4]>(
                &g,
                RTC_BUFFER_TYPE_VERTEX,
                RTC_FORMAT_FLOAT4,
                spheres.len(),
            )?;
            verts.copy_from_slice(&spheres);
            scene.attach(&device, g, sphere_map, 1)?;
        }
        if !rods.is_empty() {
            let g = scene.new_geometry(&device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE)?;
            let verts = scene.buffer::<[[f32; 4]; 2]>(
                &g,
                RTC_BUFFER_TYPE_VERTEX,
                RTC_FORMAT_FLOAT4,
                rods.len() * 2,
            )?;
            verts.copy_from_slice(&rods);
            // One segment per rod, with vertices of its own: no neighbours, round caps at both ends.
            let idx =
                scene.buffer::<u32>(&g, RTC_BUFFER_TYPE_INDEX, RTC_FORMAT_UINT, rods.len())?;
            for (k, slot) in idx.iter_mut().enumerate() {
                *slot = 2 * k as u32;
            }
            scene.attach(&device, g, rod_map, 1)?;
        }
        unsafe { rtcCommitScene(raw) };
        device.check("committing a scene")?;
        Ok(scene)
    }

    fn new_geometry(
        &self,
        device: &Device,
        kind: RTCGeometryType,
    ) -> Result<GeometryHandle, String> {
        let g = unsafe { rtcNewGeometry(device.raw, kind) };
        if g.is_null() {
            device.check("creating a geometry")?;
            return Err("Embree could not create a geometry".into());
        }
        Ok(GeometryHandle(g))
    }

    /// A new buffer of `count` items of T on the geometry, as a slice to fill. Buffers of
    /// `[T; 2]` items are counted in T (curve vertices).
    #[allow(clippy::mut_from_ref)]
    fn buffer<T: Copy>(
        &self,
        g: &GeometryHandle,
        kind: RTCBufferType,
        format: RTCFormat,
        count: usize,
    ) -> Result<&mut [T], String> {
        let (stride, items) = match format {
            RTC_FORMAT_FLOAT4 => (16, count),
            _ => (std::mem::size_of::<T>(), count),
        };
        let ptr = unsafe { rtcSetNewGeometryBuffer(g.0, kind, 0, format, stride, items) };
        self._device.check("allocating a buffer")?;
        if ptr.is_null() {
            return Err("Embree could not allocate a geometry buffer".into());
        }
        let n = items * stride / std::mem::size_of::<T>();
        // SAFETY: Embree allocated items * stride bytes, aligned for f32/u32, owned by the
        // geometry, which outlives this slice (it is filled before the geometry is committed).
        Ok(unsafe { std::slice::from_raw_parts_mut(ptr as *mut T, n) })
    }

    fn attach(
        &mut self,
        device: &Device,
        g: GeometryHandle,
        prims: Vec<u32>,
        per: u32,
    ) -> Result<(), String> {
        unsafe { rtcCommitGeometry(g.0) };
        device.check("committing a geometry")?;
        let id = unsafe { rtcAttachGeometry(self.raw, g.0) } as usize;
        device.check("attaching a geometry")?;
        if self.maps.len() <= id {
            self.maps.resize_with(id + 1, || PrimMap {
                prims: Vec::new(),
                per: 1,
            });
        }
        self.maps[id] = PrimMap { prims, per };
        Ok(())
    }

    /// The scene primitive an Embree hit names.
    pub fn prim(&self, geom: u32, prim: u32) -> Option<u32> {
        let m = self.maps.get(geom as usize)?;
        m.prims.get((prim / m.per) as usize).copied()
    }
}
