//! The thin layer over `embree-sys`: every `rtc*` call of the backend is made here, and every
//! Embree handle is owned by a type that releases it on drop.
//!
//! - [`Device`]: the Embree device, with an error callback whose messages are checked after
//!   building and committing (never per ray).
//! - [`Geometry`]: a geometry being made (triangles, user geometry or an instance).
//! - [`SceneBuilder`]: a scene being made, which geometries are attached to; committing it
//!   gives a [`CommittedScene`], the only kind that is shared between threads and traced.
//! - [`field`]: where Embree's SoA rays keep each field, for the user-geometry callbacks.

use super::fault::Injection;
use super::isa::Isa;
use crate::accel::Faults;
use crate::{Error, Result};
use embree_sys::*;
use std::ffi::{c_char, c_void, CStr, CString};
use std::sync::{Arc, Mutex};

/// Fields of Embree's SoA ray (`RTCRayN`), each `N` f32 lanes wide, by index: lane i of field
/// k is at `k · N + i` (as `RTCRay16` lays them out; checked below).
pub mod field {
    pub const ORG: usize = 0;
    pub const TNEAR: usize = 3;
    pub const DIR: usize = 4;
    pub const TFAR: usize = 8;
    /// The ray's id: the queries put each ray's lane in the caller's packet here, and Embree
    /// carries it through any split or reordering of the packet (exact.rs).
    pub const ID: usize = 10;
}

const _: () = {
    use std::mem::offset_of;
    assert!(offset_of!(RTCRay16, org_x) == field::ORG * 64);
    assert!(offset_of!(RTCRay16, tnear) == field::TNEAR * 64);
    assert!(offset_of!(RTCRay16, dir_x) == field::DIR * 64);
    assert!(offset_of!(RTCRay16, tfar) == field::TFAR * 64);
    assert!(offset_of!(RTCRay16, id) == field::ID * 64);
    assert!(offset_of!(RTCRay8, tfar) == field::TFAR * 32);
    assert!(offset_of!(RTCRay8, id) == field::ID * 32);
    assert!(offset_of!(RTCRay4, tfar) == field::TFAR * 16);
    assert!(offset_of!(RTCRay4, id) == field::ID * 16);
    assert!(offset_of!(RTCRay, tfar) == field::TFAR * 4);
    assert!(offset_of!(RTCRay, id) == field::ID * 4);
};

pub struct Device {
    raw: RTCDevice,
    errors: *mut ErrorSink,
    /// The instruction set Embree runs (`isa.rs`).
    pub isa: Isa,
    /// Whether Embree traces packets of 4, 8 and 16 rays natively here (any other width it
    /// splits and copies before it calls back into user geometry).
    pub native: [bool; 3],
    /// What went wrong in a callback while tracing (checked by the render).
    pub faults: Arc<Faults>,
    /// The test hook of `EmbreeBackend::with_fault_injected` (fault.rs).
    pub inject_fault: Injection,
}

// SAFETY: Embree devices may be used from any thread (Embree's API is thread-safe for device
// calls); the error list the callback writes is behind a mutex and freed only on drop.
unsafe impl Send for Device {}
unsafe impl Sync for Device {}

unsafe extern "C" fn on_error(user: *mut c_void, code: RTCError, msg: *const c_char) {
    // No panic may unwind into Embree: whatever fails here loses a message, nothing more.
    let _ = std::panic::catch_unwind(|| {
        let text = if msg.is_null() {
            String::new()
        } else {
            // SAFETY: Embree passes a NUL-terminated message.
            unsafe { CStr::from_ptr(msg) }
                .to_string_lossy()
                .into_owned()
        };
        // SAFETY: `user` is the device's error sink, registered in `Device::new` and
        // unregistered before it is freed.
        let sink = unsafe { &*(user as *const ErrorSink) };
        let message = format!("{code:?}: {text}");
        // Also a fault: an error inside a query leaves its rays untouched (read as misses),
        // and only the render's check of the faults would notice.
        sink.faults
            .record(|| format!("Embree reported an error: {message}"));
        if let Ok(mut l) = sink.list.lock() {
            l.push(message);
        }
    });
}

/// Where Embree's error callback writes: the messages `Device::check` reports after a build
/// or commit, and the faults the render checks.
struct ErrorSink {
    list: Mutex<Vec<String>>,
    faults: Arc<Faults>,
}

impl Device {
    /// A device; `threads` limits Embree's own build threads (0: all cores); `isa` is the
    /// instruction set to run (None: Embree's choice, the best the CPU has), which the caller
    /// has checked the CPU has (`Isa::checked`).
    pub fn new(threads: usize, isa: Option<Isa>, faults: Arc<Faults>) -> Result<Device> {
        let mut config = format!("threads={threads},verbose=0");
        if let Some(isa) = isa {
            config += &format!(",isa={}", isa.name());
        }
        let config = CString::new(config).expect("no NUL");
        // SAFETY: a NUL-terminated configuration string.
        let raw = unsafe { rtcNewDevice(config.as_ptr()) };
        if raw.is_null() {
            // SAFETY: asking for the error of no device is allowed.
            let code = unsafe { rtcGetDeviceError(std::ptr::null_mut()) };
            return Err(Error::backend(format!(
                "Embree could not create a device ({code:?})"
            )));
        }
        let errors = Box::into_raw(Box::new(ErrorSink {
            list: Mutex::new(Vec::new()),
            faults: faults.clone(),
        }));
        // SAFETY: a live device; the list outlives the registration (see Drop).
        unsafe { rtcSetDeviceErrorFunction(raw, Some(on_error), errors as *mut c_void) };
        let property = |p| {
            // SAFETY: a live device, a property Embree 3 knows.
            unsafe { rtcGetDeviceProperty(raw, p) != 0 }
        };
        let native = [
            property(RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED),
            property(RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED),
            property(RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED),
        ];
        // Left to itself Embree runs the best code path the CPU has, which its native widths
        // tell apart but for AVX from AVX2 and SSE2 from SSE4.2 (the CPU's best of each pair).
        let isa = isa.unwrap_or_else(|| {
            let best = Isa::best().unwrap_or(Isa::Sse2);
            let of_width = |w: usize| Isa::on_cpu().into_iter().rfind(|i| i.native_width() == w);
            match native {
                [_, _, true] => of_width(16),
                [_, true, false] => of_width(8),
                _ => of_width(4),
            }
            .unwrap_or(best)
        });
        Ok(Device {
            raw,
            errors,
            isa,
            native,
            faults,
            inject_fault: Injection::default(),
        })
    }

    /// Embree's version, as major.minor.patch.
    pub fn version(&self) -> String {
        // SAFETY: a live device, properties Embree 3 knows.
        let p = |k| unsafe { rtcGetDeviceProperty(self.raw, k) };
        format!(
            "{}.{}.{}",
            p(RTC_DEVICE_PROPERTY_VERSION_MAJOR),
            p(RTC_DEVICE_PROPERTY_VERSION_MINOR),
            p(RTC_DEVICE_PROPERTY_VERSION_PATCH)
        )
    }

    /// The fault-injection flag for a query's context: None unless a fault is to be injected
    /// (`EmbreeBackend::with_fault_injected`), so a query pays one test of an Option.
    #[inline(always)]
    pub fn injection(&self) -> Option<&Injection> {
        self.inject_fault.armed().then_some(&self.inject_fault)
    }

    /// The widest packet Embree traces natively here (1 if none).
    pub fn native_width(&self) -> usize {
        match self.native {
            [_, _, true] => 16,
            [_, true, false] => 8,
            [true, false, false] => 4,
            _ => 1,
        }
    }

    /// Fail with the collected messages, if Embree reported any since the last check.
    pub fn check(&self, what: &str) -> Result<()> {
        // SAFETY: the list lives as long as the device.
        let mut list = unsafe { &*self.errors }
            .list
            .lock()
            .map_err(|_| Error::backend("Embree error list poisoned"))?;
        // SAFETY: a live device.
        let code = unsafe { rtcGetDeviceError(self.raw) };
        if code != RTCError::RTC_ERROR_NONE && list.is_empty() {
            list.push(format!("{code:?}"));
        }
        if list.is_empty() {
            return Ok(());
        }
        let msg = list.join("; ");
        list.clear();
        Err(Error::backend(format!("Embree failed while {what}: {msg}")))
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: unregister the callback before freeing what it writes to; every scene and
        // geometry holds an Arc of the device, so none outlives it.
        unsafe {
            rtcSetDeviceErrorFunction(self.raw, None, std::ptr::null_mut());
            rtcReleaseDevice(self.raw);
            drop(Box::from_raw(self.errors));
        }
    }
}

/// An Embree geometry being made; released on drop (a scene it is attached to keeps its own
/// reference).
pub struct Geometry {
    raw: RTCGeometry,
    device: Arc<Device>,
}

impl Drop for Geometry {
    fn drop(&mut self) {
        // SAFETY: our reference to a live geometry.
        unsafe { rtcReleaseGeometry(self.raw) };
    }
}

/// The callbacks of a user geometry.
pub struct UserFunctions {
    pub bounds: unsafe extern "C" fn(*const RTCBoundsFunctionArguments),
    pub intersect: unsafe extern "C" fn(*const RTCIntersectFunctionNArguments),
    pub occluded: unsafe extern "C" fn(*const RTCOccludedFunctionNArguments),
}

impl Geometry {
    pub fn new(device: &Arc<Device>, kind: RTCGeometryType) -> Result<Geometry> {
        // SAFETY: a live device.
        let raw = unsafe { rtcNewGeometry(device.raw, kind) };
        if raw.is_null() {
            device.check("creating a geometry")?;
            return Err(Error::backend("Embree could not create a geometry"));
        }
        Ok(Geometry {
            raw,
            device: device.clone(),
        })
    }

    /// Make this (user) geometry `count` primitives whose callbacks read `data`.
    ///
    /// # Safety
    /// `data` must stay valid, unmoved, for as long as any scene this geometry is attached to,
    /// and be what `functions` read it as.
    pub unsafe fn set_user(&mut self, count: u32, data: *mut c_void, functions: UserFunctions) {
        // SAFETY: a live user geometry; the caller vouches for `data`.
        unsafe {
            rtcSetGeometryUserPrimitiveCount(self.raw, count);
            rtcSetGeometryUserData(self.raw, data);
            rtcSetGeometryBoundsFunction(self.raw, Some(functions.bounds), data);
            rtcSetGeometryIntersectFunction(self.raw, Some(functions.intersect));
            rtcSetGeometryOccludedFunction(self.raw, Some(functions.occluded));
        }
    }

    /// Make this (instance) geometry `scene` moved by `translation`. The instance keeps its
    /// own reference to the scene.
    pub fn set_instance(&mut self, scene: &CommittedScene, translation: [f32; 3]) {
        let [x, y, z] = translation;
        // Column-major 3x4: the identity, then the translation.
        self.set_instance_affine(
            scene,
            [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, x, y, z],
        );
    }

    /// Make this (instance) geometry `scene` placed by the affine map `xfm` (column-major 3x4:
    /// three columns of the linear map, then the translation). The instance keeps its own
    /// reference to the scene.
    pub fn set_instance_affine(&mut self, scene: &CommittedScene, xfm: [f32; 12]) {
        // SAFETY: a live instance geometry and a live committed scene; Embree copies the
        // transform.
        unsafe {
            rtcSetGeometryInstancedScene(self.raw, scene.raw);
            rtcSetGeometryTransform(
                self.raw,
                0,
                RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR,
                xfm.as_ptr() as *const c_void,
            );
        }
    }

    /// Give the geometry `items` as its buffer of `kind` (of Embree format `format`) without
    /// copying them.
    ///
    /// # Safety
    /// `items` must stay valid, unmoved and unchanged for as long as any scene this geometry
    /// is attached to lives (the caller keeps their owner beside the scene and drops it after).
    pub unsafe fn share_buffer<T: Copy>(
        &mut self,
        kind: RTCBufferType,
        format: RTCFormat,
        items: &[T],
    ) -> Result<()> {
        // SAFETY: a live geometry, slot 0; the caller vouches for the items' lifetime.
        unsafe {
            rtcSetSharedGeometryBuffer(
                self.raw,
                kind,
                0,
                format,
                items.as_ptr() as *const c_void,
                0,
                std::mem::size_of::<T>(),
                items.len(),
            )
        };
        self.device.check("sharing a buffer")
    }

    /// A new buffer of `count` items of T (of Embree format `format`), to fill before the
    /// geometry is attached.
    pub fn new_buffer<T: Copy>(
        &mut self,
        kind: RTCBufferType,
        format: RTCFormat,
        count: usize,
    ) -> Result<&mut [T]> {
        let stride = std::mem::size_of::<T>();
        // SAFETY: a live geometry, slot 0.
        let ptr = unsafe { rtcSetNewGeometryBuffer(self.raw, kind, 0, format, stride, count) };
        self.device.check("allocating a buffer")?;
        if ptr.is_null() {
            return Err(Error::backend(
                "Embree could not allocate a geometry buffer",
            ));
        }
        // SAFETY: Embree allocated count · stride bytes, aligned for f32/u32 and owned by the
        // geometry, which the returned slice borrows.
        Ok(unsafe { std::slice::from_raw_parts_mut(ptr as *mut T, count) })
    }
}

/// A scene being made; released on drop unless committed.
pub struct SceneBuilder {
    raw: RTCScene,
    device: Arc<Device>,
}

impl Drop for SceneBuilder {
    fn drop(&mut self) {
        if !self.raw.is_null() {
            // SAFETY: our reference to a live scene.
            unsafe { rtcReleaseScene(self.raw) };
        }
    }
}

impl SceneBuilder {
    /// A scene built for quality and robust traversal (rays grazing edges are not lost).
    pub fn new(device: &Arc<Device>) -> Result<SceneBuilder> {
        // SAFETY: a live device.
        let raw = unsafe { rtcNewScene(device.raw) };
        if raw.is_null() {
            device.check("creating a scene")?;
            return Err(Error::backend("Embree could not create a scene"));
        }
        // SAFETY: a live scene, not yet committed.
        unsafe {
            rtcSetSceneBuildQuality(raw, RTC_BUILD_QUALITY_HIGH);
            rtcSetSceneFlags(raw, RTC_SCENE_FLAG_ROBUST);
        }
        Ok(SceneBuilder {
            raw,
            device: device.clone(),
        })
    }

    /// Build it compact: Embree's leaves then name their triangles' vertices by index
    /// (`triangle4i`) instead of holding copies of them (`triangle4v`), in 4-wide nodes
    /// instead of 8-wide: about half the memory, for a slower traversal. Both run Embree's
    /// robust (Pluecker) test on the same f32 vertices (src/tests/compact_scenes.rs).
    pub fn compact(&mut self) {
        // SAFETY: a live scene, not yet committed.
        unsafe {
            let flags = rtcGetSceneFlags(self.raw);
            rtcSetSceneFlags(self.raw, flags | RTC_SCENE_FLAG_COMPACT);
        }
    }

    /// Commit `g` and attach it; its geomID.
    pub fn attach(&mut self, g: Geometry) -> Result<u32> {
        // SAFETY: a live geometry and scene.
        unsafe { rtcCommitGeometry(g.raw) };
        self.device.check("committing a geometry")?;
        // SAFETY: as above; the scene takes its own reference, ours goes with `g`.
        let id = unsafe { rtcAttachGeometry(self.raw, g.raw) };
        self.device.check("attaching a geometry")?;
        Ok(id)
    }

    /// Commit `g` and attach it as geomID `id` (which no geometry of the scene has).
    pub fn attach_as(&mut self, g: Geometry, id: u32) -> Result<()> {
        // SAFETY: a live geometry and scene.
        unsafe { rtcCommitGeometry(g.raw) };
        self.device.check("committing a geometry")?;
        // SAFETY: as above; the scene takes its own reference, ours goes with `g`.
        unsafe { rtcAttachGeometryByID(self.raw, g.raw, id) };
        self.device.check("attaching a geometry")
    }

    /// Build the scene's BVH; from now on it is only read.
    pub fn commit(mut self) -> Result<CommittedScene> {
        let raw = std::mem::replace(&mut self.raw, std::ptr::null_mut());
        let scene = CommittedScene {
            raw,
            _device: self.device.clone(),
        };
        // SAFETY: a live scene.
        unsafe { rtcCommitScene(raw) };
        self.device.check("committing a scene")?;
        Ok(scene)
    }
}

/// A committed scene: only traced, from any number of threads.
pub struct CommittedScene {
    raw: RTCScene,
    _device: Arc<Device>,
}

// SAFETY: a committed Embree scene may be traced from several threads at once (Embree's
// documented contract); nothing here modifies it after the commit.
unsafe impl Send for CommittedScene {}
unsafe impl Sync for CommittedScene {}

impl Drop for CommittedScene {
    fn drop(&mut self) {
        // SAFETY: our reference to a live scene.
        unsafe { rtcReleaseScene(self.raw) };
    }
}

/// A ray packet's valid mask, aligned as Embree requires of packets of up to 16.
#[repr(C, align(64))]
pub struct Valid<const N: usize>(pub [i32; N]);

macro_rules! packet_queries {
    ($isect:ident, $occl:ident, $n:literal, $rayhit:ty, $ray:ty, $rtc_isect:ident, $rtc_occl:ident) => {
        /// Closest hits of the packet's valid lanes.
        ///
        /// # Safety
        /// `context` is an intersect context whose extension, if any, is what this scene's
        /// user geometry callbacks read, valid for the call.
        #[inline(always)]
        pub unsafe fn $isect(
            &self,
            valid: &Valid<$n>,
            context: *mut RTCIntersectContext,
            rays: &mut $rayhit,
        ) {
            // SAFETY: a committed scene, an aligned mask; the caller vouches for the context.
            unsafe { $rtc_isect(valid.0.as_ptr(), self.raw, context, rays) };
        }

        /// Whether anything lies on each of the packet's valid lanes (tfar set to −∞ where so).
        ///
        /// # Safety
        /// As for the closest hits.
        #[inline(always)]
        pub unsafe fn $occl(
            &self,
            valid: &Valid<$n>,
            context: *mut RTCIntersectContext,
            rays: &mut $ray,
        ) {
            // SAFETY: as above.
            unsafe { $rtc_occl(valid.0.as_ptr(), self.raw, context, rays) };
        }
    };
}

impl CommittedScene {
    /// Whether it was built compact (`SceneBuilder::compact`).
    #[cfg(test)]
    pub fn is_compact(&self) -> bool {
        // SAFETY: a live scene.
        let flags = unsafe { rtcGetSceneFlags(self.raw) };
        flags & RTC_SCENE_FLAG_COMPACT != 0
    }

    packet_queries!(
        intersect16,
        occluded16,
        16,
        RTCRayHit16,
        RTCRay16,
        rtcIntersect16,
        rtcOccluded16
    );
    packet_queries!(
        intersect8,
        occluded8,
        8,
        RTCRayHit8,
        RTCRay8,
        rtcIntersect8,
        rtcOccluded8
    );
    packet_queries!(
        intersect4,
        occluded4,
        4,
        RTCRayHit4,
        RTCRay4,
        rtcIntersect4,
        rtcOccluded4
    );

    /// The closest hit of one ray.
    ///
    /// # Safety
    /// As for the packets.
    #[inline(always)]
    pub unsafe fn intersect1(&self, context: *mut RTCIntersectContext, ray: &mut RTCRayHit) {
        // SAFETY: a committed scene; the caller vouches for the context.
        unsafe { rtcIntersect1(self.raw, context, ray) };
    }

    /// Whether anything lies on one ray.
    ///
    /// # Safety
    /// As for the packets.
    #[inline(always)]
    pub unsafe fn occluded1(&self, context: *mut RTCIntersectContext, ray: &mut RTCRay) {
        // SAFETY: as above.
        unsafe { rtcOccluded1(self.raw, context, ray) };
    }
}

/// An intersect context as `rtcInitIntersectContext` makes it.
pub(crate) fn new_context() -> RTCIntersectContext {
    let mut rtc = RTCIntersectContext::default();
    // SAFETY: initialises the plain struct in place.
    unsafe { rtcInitIntersectContext(&mut rtc) };
    rtc
}

/// A point or vector (already rebased near the origin) in the f32 Embree stores.
pub(super) fn f3(p: glam::DVec3) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}
