//! The Intel Embree backend: one Embree scene per rest-frame geometry; batches of rays go to
//! Embree as 16-wide packets (8-wide where the CPU has no native 16-wide support), 64-byte
//! aligned, with the coherent flag and a valid mask; single rays and occlusion queries as well.
//!
//! Precision (docs/physics.md §7.1): the renderer hands over f64 rays (rebased to the near side of the
//! group's bounds when they come from afar); here they are made relative to the scene's centre,
//! given a unit direction, and only then cast to f32. Spheres, rods and boxes are user geometry
//! tested in f64 on the caller's f64 ray (exact.rs); a triangle hit's t is converted back and
//! refined in f64 on the triangle Embree found. Either way the lookback times that decide the
//! merge between groups are as exact as the f64 BVH's. culler.rs makes Embree the culling
//! structure over many groups.

mod bare;
mod culler;
mod exact;
#[cfg(target_arch = "x86_64")]
mod f64x4;
#[cfg(target_arch = "x86_64")]
mod fan_kernel;
mod fault;
mod instanced_blocks;
mod isa;
mod lane_cull;
mod lane_hits;
mod packet;
mod rtc;
mod scene;

pub use bare::BareRay;
pub use fault::Callback;
pub use isa::Isa;
pub(crate) use isa::ENV as ISA_ENV;

use super::{Accelerator, Backend, BoxCuller, CullerFactory, Fan, FanHits, Faults, Hit, Ray};
use crate::geometry::{Aabb, Geometry, Primitive, Real};
use rtc::Device;
use std::sync::{Arc, OnceLock};

pub struct EmbreeBackend {
    device: OnceLock<crate::Result<Arc<Device>>>,
    /// Packet width for batches: None, the widest Embree traces natively here (16, 8 or 4);
    /// 1 sends single rays.
    packet_width: Option<usize>,
    /// The instruction set Embree is to run; None, Embree's choice (the CPU's best).
    isa: Option<Isa>,
    /// What went wrong in a callback while tracing.
    faults: Arc<Faults>,
    /// The Embree scenes of meshes several objects place, made on this backend's device and
    /// shared by every group's scene that instances them.
    mesh_scenes: Arc<scene::MeshScenes>,
    /// From how many triangles a group's scene (or a shared mesh's) is built compact.
    compact_from: u64,
    /// A test hook: a user-geometry callback panics (`REST_EMBREE_FAULT=callback`), to prove
    /// that the panic is caught at the FFI boundary and the render fails with an error.
    inject_fault: Option<Option<Callback>>,
}

/// From how many triangles a scene is built compact (`SceneBuilder::compact`): Embree's
/// structure in about half the memory, for a slower traversal. From a million triangles on,
/// the structure is most of the process's memory (docs/bench/terrain.md has the peak of a
/// 10M-triangle mesh); below, speed matters more.
pub const COMPACT_FROM_TRIANGLES: u64 = 1 << 20;

/// The environment variable of the fault-injection test hook (`EmbreeBackend::configured_by_env`).
pub(crate) const FAULT_ENV: &str = "REST_EMBREE_FAULT";

impl EmbreeBackend {
    pub fn new() -> Self {
        Self {
            device: OnceLock::new(),
            packet_width: None,
            isa: None,
            faults: Arc::default(),
            inject_fault: None,
            mesh_scenes: Arc::default(),
            compact_from: COMPACT_FROM_TRIANGLES,
        }
    }

    /// A backend that always uses this packet width (16, 8, 4, or 1 for single rays: any
    /// other width is taken as 1).
    pub fn with_packet_width(width: usize) -> Self {
        Self {
            packet_width: Some(if matches!(width, 4 | 8 | 16) {
                width
            } else {
                1
            }),
            ..Self::new()
        }
    }

    /// The same backend running Embree's code path for `isa` (checked: the CPU has it).
    pub fn on_isa(self, isa: Isa) -> crate::Result<Self> {
        Ok(Self {
            isa: Some(isa.checked()?),
            // A device already made runs another (and its scenes go with it).
            device: OnceLock::new(),
            mesh_scenes: Arc::default(),
            ..self
        })
    }

    /// The same backend building compact every scene of `triangles` or more (a test of the
    /// compact scenes on small meshes; the default is [`COMPACT_FROM_TRIANGLES`]).
    #[cfg(test)]
    pub fn compact_from(self, triangles: u64) -> Self {
        Self {
            compact_from: triangles,
            // Shared meshes' scenes are kept as built.
            mesh_scenes: Arc::default(),
            ..self
        }
    }

    /// Whether each shared mesh's scene this backend holds was built compact.
    #[cfg(test)]
    pub fn shared_scenes_compact(&self) -> Vec<bool> {
        self.mesh_scenes.compact()
    }

    /// The same backend with a panic in the first user-geometry callback that runs (a test of
    /// the FFI boundary).
    pub fn with_fault_injected(self) -> Self {
        self.with_fault_injected_in(None)
    }

    /// The same backend with a panic in the first run of `callback` (None: of any).
    pub fn with_fault_injected_in(self, callback: Option<Callback>) -> Self {
        Self {
            inject_fault: Some(callback),
            device: OnceLock::new(),
            mesh_scenes: Arc::default(),
            ..self
        }
    }

    /// The backend as the environment asks: `REST_EMBREE_ISA` (isa.rs) and the test hook
    /// `REST_EMBREE_FAULT=callback`.
    pub fn configured_by_env(self) -> crate::Result<Self> {
        let backend = match Isa::from_env()? {
            Some(isa) => self.on_isa(isa)?,
            None => self,
        };
        match std::env::var(FAULT_ENV).ok().as_deref() {
            None | Some("") => Ok(backend),
            Some("callback") => Ok(backend.with_fault_injected()),
            Some(other) => Err(crate::Error::flag(
                FAULT_ENV,
                format!("{other:?} is not a fault this test hook knows (choose: callback)"),
            )),
        }
    }

    /// The accelerator over `geometry`, as this backend's `build` makes it (concrete, for
    /// callers that trace it more ways than the trait's).
    pub fn accelerator(&self, geometry: Arc<Geometry>) -> crate::Result<EmbreeAccel> {
        let device = self.device()?;
        let width = self.packet_width.unwrap_or(device.native_width());
        let scene = scene::EmbreeScene::build(
            device.clone(),
            &geometry,
            &self.mesh_scenes,
            self.compact_from,
        )?;
        let bounds = geometry.bounds();
        let diag = bounds.diagonal();
        Ok(EmbreeAccel {
            scene,
            geometry,
            width,
            // How far a ray's origin is pulled back before the f32 cast, so geometry flush with
            // the bounds (where the renderer put the origin) is not lost to f32 rounding.
            pullback: 1e-4 * diag.max(1e-6),
            bounds,
            diag,
            device,
        })
    }

    /// The Embree device, made on first use: the instruction set it runs and its native
    /// packet widths (`rest-embree backends` prints them).
    pub fn device(&self) -> crate::Result<Arc<Device>> {
        // Embree's build threads follow the render's (--threads sets rayon's global pool).
        self.device
            .get_or_init(|| {
                let threads = rayon::current_num_threads();
                let device = Device::new(threads, self.isa, self.faults.clone())?;
                if let Some(callback) = self.inject_fault {
                    device.inject_fault.arm(callback);
                }
                Ok(Arc::new(device))
            })
            .clone()
    }

    /// The packet width this backend traces batches with (`device` for the native ones).
    pub fn packet_width(&self) -> crate::Result<usize> {
        Ok(match self.packet_width {
            Some(w) => w,
            None => self.device()?.native_width(),
        })
    }

    /// What `rest-embree backends` says of it: Embree's version, the instruction set it runs
    /// (of those the CPU has), the packet widths it traces natively and the one this backend
    /// traces with.
    pub fn describe(&self) -> crate::Result<String> {
        let device = self.device()?;
        let widths: Vec<String> = [4, 8, 16]
            .iter()
            .zip(device.native)
            .filter(|(_, native)| *native)
            .map(|(w, _)| w.to_string())
            .collect();
        let on_cpu: Vec<&str> = Isa::on_cpu().into_iter().map(Isa::name).collect();
        let how = match self.isa {
            Some(_) => format!("as {} asks", isa::ENV),
            None => "the CPU's best".to_string(),
        };
        let width = match self.packet_width()? {
            1 => "single rays".to_string(),
            w => format!("packets of {w}"),
        };
        Ok(format!(
            "Intel Embree {}, instruction set {} ({how}; this CPU has {}), native packets of {}; traces {width}",
            device.version(),
            device.isa.name(),
            on_cpu.join(", "),
            if widths.is_empty() { "none".to_string() } else { widths.join(", ") },
        ))
    }
}

impl Default for EmbreeBackend {
    fn default() -> Self {
        Self::new()
    }
}

impl Backend for EmbreeBackend {
    fn name(&self) -> &'static str {
        "embree"
    }

    fn cullers(&self) -> CullerFactory {
        let device = self.device();
        Arc::new(move |boxes: &[Aabb]| {
            let device = device.clone()?;
            Ok(Box::new(culler::EmbreeCuller::build(device, boxes)?) as Box<dyn BoxCuller>)
        })
    }

    fn build(&self, geometry: Arc<Geometry>) -> crate::Result<Box<dyn Accelerator>> {
        Ok(Box::new(self.accelerator(geometry)?))
    }

    fn faults(&self) -> Option<Arc<Faults>> {
        Some(self.faults.clone())
    }
}

pub struct EmbreeAccel {
    scene: scene::EmbreeScene,
    geometry: Arc<Geometry>,
    width: usize,
    pullback: f64,
    /// The geometry's bounds (`Geometry::bounds` walks the primitives: made once), and their
    /// diagonal.
    bounds: Aabb,
    diag: f64,
    /// Where faults in callbacks are recorded (and whether to inject one).
    device: Arc<Device>,
}

/// A ray as Embree sees it: f32, relative to the scene centre, unit direction.
#[derive(Clone, Copy, Default)]
struct EmbreeRay {
    org: [f32; 3],
    dir: [f32; 3],
    tnear: f32,
    tfar: f32,
    active: bool,
    /// Embree's t = t · scale + offset for this ray: the pullback, less how far (in Embree's
    /// units) the origin was moved up to the scene's bounds (`embree_ray`).
    offset: f64,
}

/// Directions this long, within a factor of the unit, Embree traces as they are (`scale`).
const MAX_UNNORMALISED: f64 = 16.0;

/// What Embree traces a direction of length `len` (`Ray::len`) divided by: 1 where `len`
/// lies within [1/16, 16], so the direction goes in as it is, with no division (a boost's
/// null directions are so long up to 0.99c, as a camera's unit ones are); else `len`, the
/// unit direction, since far from 1 an unnormalised one would pull the origin back by that
/// much more or less, out where f32 is coarser or into the rounding. Embree's t is then
/// t · scale + pullback. Written once for one ray or four (`Real`), so that the fans' lanes
/// follow the rule of rays made one by one to the bit.
#[inline(always)]
fn scale<R: Real>(len: R) -> R {
    let near = R::both(
        len.ge(R::splat(1.0 / MAX_UNNORMALISED)),
        len.le(R::splat(MAX_UNNORMALISED)),
    );
    R::select(near, R::splat(1.0), len)
}

/// A ray as it goes into Embree's f32 packet, before the cast, written once for one ray or
/// several (`Real`) so that a fan's rays are `embree_ray`'s to the bit: from the origin `o`
/// (relative to the scene's centre) and direction `d` traced divided by `scale` (`scale`), the
/// origin pulled back by `pullback` along that, the direction Embree traces and tnear for the
/// caller's `tmin`. Embree's t is t · scale + pullback; for a scale of 1 the division is by 1,
/// exact, and a caller that knows it passes the constant, which the compiler folds away.
#[inline(always)]
fn lane_geometry<R: Real>(
    o: [R; 3],
    d: [R; 3],
    scale: R,
    tmin: R,
    pullback: R,
) -> ([R; 3], [R; 3], R) {
    // One division, not three: the f32 cast rounds far more than this.
    let inv = R::splat(1.0) / scale;
    let du = [d[0] * inv, d[1] * inv, d[2] * inv];
    let org = [
        o[0] - pullback * du[0],
        o[1] - pullback * du[1],
        o[2] - pullback * du[2],
    ];
    let tnear = (tmin * scale + pullback).max(R::splat(0.0));
    (org, du, tnear)
}

impl EmbreeAccel {
    /// Whether its scene was built compact (`EmbreeBackend::compact_from`).
    #[cfg(test)]
    pub fn is_compact(&self) -> bool {
        self.scene.rtc.is_compact()
    }

    #[inline(always)]
    fn embree_ray(&self, r: &Ray) -> EmbreeRay {
        if !r.is_active() {
            return EmbreeRay::default();
        }
        let (d, k) = (r.dir, scale(r.len));
        // A ray from far off is moved, in f64, up to where it enters the scene's bounds: f32
        // then rounds coordinates of the scene's size, not of its distance. Embree's code paths
        // without FMA (SSE, AVX) lose packet rays that graze a box from 10⁵ away otherwise,
        // which single rays and AVX2's find. Near rays are traced as they are.
        let far = self.bounds.clip(r.origin, d.recip(), r.tmin, r.tmax);
        let shift = match far {
            Some((enter, _)) if enter * r.len > 4.0 * self.diag => enter,
            _ => 0.0,
        };
        let offset = self.pullback - shift * k;
        let o = r.origin + shift * d - self.scene.center;
        let (o, du, tnear) = lane_geometry(
            [o.x, o.y, o.z],
            [d.x, d.y, d.z],
            k,
            r.tmin - shift,
            self.pullback,
        );
        let tfar = r.tmax * k + offset;
        EmbreeRay {
            org: o.map(|x| x as f32),
            dir: du.map(|x| x as f32),
            tnear: tnear as f32,
            tfar: if tfar.is_finite() {
                (tfar as f32).max(tnear as f32)
            } else {
                f32::INFINITY
            },
            active: true,
            offset,
        }
    }

    /// Embree's hit back in the caller's units: exact already for user geometry (`exact_t`,
    /// from the context), else refined in f64 on the primitive that was hit (Embree's t is
    /// t · `scale(r.len)` + `offset`, `EmbreeRay::offset`).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn to_hit(
        &self,
        r: &Ray,
        t_embree: f32,
        geom: u32,
        prim: u32,
        inst: u32,
        exact_t: f64,
        offset: f64,
    ) -> Option<Hit> {
        let hit = self.fetch(geom, prim, inst)?;
        self.refine(r, t_embree, hit, exact_t, offset)
    }

    /// What Embree's hit (geometry, primitive, instance) is among the group's primitives: its
    /// number, and the primitive where its t is to be refined (None where the hit is exact).
    /// Fetching it is the read-back's one trip to memory the BVH's leaf did not make (a big
    /// mesh's indices and vertices): a packet's lanes fetch first, all of them, then refine,
    /// so that their fetches overlap.
    #[inline(always)]
    fn fetch(&self, geom: u32, prim: u32, inst: u32) -> Option<(u32, Option<Primitive>)> {
        let (prim, exact) = self.scene.prim(geom, prim, inst)?;
        Some((prim, (!exact).then(|| self.geometry.prim(prim))))
    }

    /// The hit `fetch` found, in the caller's units (see `to_hit`).
    #[inline(always)]
    fn refine(
        &self,
        r: &Ray,
        t_embree: f32,
        (prim, p): (u32, Option<Primitive>),
        exact_t: f64,
        offset: f64,
    ) -> Option<Hit> {
        let Some(p) = p else {
            return (exact_t > r.tmin && exact_t < r.tmax).then_some(Hit { t: exact_t, prim });
        };
        let k = scale(r.len);
        let t = (t_embree as f64 - offset) / k;
        let slack = 1e-4 * t.abs().max(self.pullback / k) + 4.0 * self.pullback / k;
        let (lo, hi) = ((t - slack).max(r.tmin), (t + slack).min(r.tmax));
        // Where Embree's f32 test met the triangle and the f64 one finds the ray just outside
        // it (a ray at an edge the triangle shares), the ray meets the neighbour where it
        // crosses this plane: that crossing in f64, not Embree's t.
        let refined = p
            .intersect(r.origin, r.dir, lo, hi)
            .or_else(|| p.plane_crossing(r.origin, r.dir, lo, hi));
        let t = refined.unwrap_or(t);
        (t > r.tmin && t < r.tmax).then_some(Hit { t, prim })
    }
}

impl Accelerator for EmbreeAccel {
    fn intersect(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        packet::flush_denormals();
        if rays.len() == 1 || self.width == 1 {
            for (r, h) in rays.iter().zip(hits.iter_mut()) {
                *h = self.intersect1(r);
            }
            return;
        }
        for (rs, hs) in rays.chunks(self.width).zip(hits.chunks_mut(self.width)) {
            match self.width {
                16 => self.intersect16(rs, hs),
                8 => self.intersect8(rs, hs),
                _ => self.intersect4(rs, hs),
            }
        }
    }

    fn occluded(&self, rays: &[Ray], out: &mut [bool]) {
        packet::flush_denormals();
        if rays.len() == 1 || self.width == 1 {
            for (r, o) in rays.iter().zip(out.iter_mut()) {
                *o = self.occluded1(r);
            }
            return;
        }
        for (rs, os) in rays.chunks(self.width).zip(out.chunks_mut(self.width)) {
            match self.width {
                16 => self.occluded16(rs, os),
                8 => self.occluded8(rs, os),
                _ => self.occluded4(rs, os),
            }
        }
    }

    fn serves_fans(&self) -> bool {
        #[cfg(target_arch = "x86_64")]
        return EmbreeAccel::serves_fans(self);
        #[cfg(not(target_arch = "x86_64"))]
        false
    }

    fn intersect_fan(&self, fan: &Fan, out: &mut FanHits) -> bool {
        #[cfg(target_arch = "x86_64")]
        return self.fan(fan, out);
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = (fan, out);
            false
        }
    }

    fn geometry(&self) -> &Arc<Geometry> {
        &self.geometry
    }
}
