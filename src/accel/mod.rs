//! Static-frame ray intersection behind one trait, with backends chosen by name.
//!
//! The renderer boosts every ray into a group's rest frame before it gets here, so a backend
//! only ever sees static geometry and static rays `o + t d`. `d` is unnormalised: its length is
//! the boost's lookback factor, so `t` is already the world-frame lookback time and hits of all
//! groups compare directly (docs/physics.md §7.1).
//!
//! A backend also builds the culling structures over many velocity groups (`BoxCuller`): boxes
//! in the world frame that rays from one origin traverse, the renderer testing each candidate
//! group exactly.

mod bvh;
mod bvh32;
#[cfg(feature = "embree")]
mod embree;
mod fan;
mod instance_tree;
mod instanced_tree;
mod mesh_tree;

pub(crate) use bvh::BvhBackend;
pub(crate) use bvh32::Bvh32Backend;
#[cfg(feature = "embree")]
pub(crate) use embree::{BareRay, EmbreeAccel, EmbreeBackend};
#[cfg(all(feature = "embree", test))]
pub(crate) use embree::{Callback, Isa};
pub(crate) use fan::NO_HIT;
pub use fan::{Fan, FanHits};

use crate::geometry::{Aabb, BoxTree, Geometry, LightBuffer};
use glam::DVec3;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// What went wrong inside a backend where no error could be returned: Embree calls back into
/// the renderer from C, where a panic must not unwind and a query has no result to fail with.
/// The backend records each fault here; a world notes how many there were when it was made
/// and its render fails if there are more (`World::check`), rather than write a picture that
/// may be wrong. A backend that recorded one stays usable: later worlds start from there.
#[derive(Debug, Default)]
pub struct Faults {
    count: AtomicU64,
    /// The latest fault's message.
    latest: Mutex<Option<String>>,
}

impl Faults {
    /// Record a fault.
    pub fn record(&self, what: impl FnOnce() -> String) {
        if let Ok(mut latest) = self.latest.lock() {
            *latest = Some(what());
        }
        self.count.fetch_add(1, Ordering::AcqRel);
    }

    /// How many faults were recorded so far.
    pub fn count(&self) -> u64 {
        self.count.load(Ordering::Acquire)
    }

    /// An error if a fault was recorded since there were `seen`.
    pub fn check_since(&self, seen: u64) -> crate::Result<()> {
        let now = self.count();
        if now <= seen {
            return Ok(());
        }
        let what = self
            .latest
            .lock()
            .ok()
            .and_then(|f| f.clone())
            .unwrap_or_else(|| "a fault".to_string());
        Err(crate::Error::backend(if now - seen > 1 {
            format!("{what} ({} faults in all)", now - seen)
        } else {
            what
        }))
    }

    /// An error if any fault was recorded.
    pub fn check(&self) -> crate::Result<()> {
        self.check_since(0)
    }
}

/// A static ray `origin + t dir`, searched for `tmin < t < tmax`. A ray with `tmin > tmax` is
/// inactive (masked) and must be skipped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts.
    pub origin: DVec3,
    /// Its direction, unnormalised (its length is the lookback factor).
    pub dir: DVec3,
    /// The search interval's open lower end.
    pub tmin: f64,
    /// The search interval's open upper end.
    pub tmax: f64,
    /// |dir|, for backends that trace along the unit direction (Embree): where the ray comes
    /// from a boost it is the lookback factor the boost found with the direction (the spatial
    /// part of a null vector is as long as its time part), which spares a square root per ray.
    pub len: f64,
}

impl Ray {
    /// The ray `origin + t dir` for `tmin < t < tmax`, its length taken from `dir`.
    pub fn new(origin: DVec3, dir: DVec3, tmin: f64, tmax: f64) -> Self {
        Ray {
            origin,
            dir,
            tmin,
            tmax,
            len: dir.length(),
        }
    }

    /// Whether the ray is to be traced (`tmin ≤ tmax`, not masked).
    pub fn is_active(&self) -> bool {
        self.tmin <= self.tmax
    }
}

/// The closest hit of a ray: its parameter and the primitive's index in the group geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// The ray parameter of the hit: the world-frame lookback time.
    pub t: f64,
    /// The index of the primitive hit in its group's [`Geometry::prims`].
    pub prim: u32,
}

/// Intersection of batches of rays with one group's static geometry.
pub trait Accelerator: Send + Sync {
    /// For each active ray, the closest hit with `tmin < t < tmax`, else None.
    fn intersect(&self, rays: &[Ray], hits: &mut [Option<Hit>]);
    /// For each active ray, whether anything lies at `tmin < t < tmax` (inactive: false).
    fn occluded(&self, rays: &[Ray], out: &mut [bool]);
    /// Whether `intersect_fan` serves fans of primary rays (here, on this CPU).
    fn serves_fans(&self) -> bool {
        false
    }
    /// The rays of a fan of primary rays and their closest hits for lookback in (0, ∞), made
    /// and traced by a path of the backend's own, the same rays as the renderer's to the bit;
    /// false, with nothing written, where the backend has none (`serves_fans`).
    fn intersect_fan(&self, _fan: &Fan, _out: &mut FanHits) -> bool {
        false
    }
    /// The geometry this accelerator was built over.
    fn geometry(&self) -> &Arc<Geometry>;
}

/// An accelerator shared (a world and a measurement of the same structure, say).
impl<A: Accelerator + ?Sized> Accelerator for Arc<A> {
    fn intersect(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        (**self).intersect(rays, hits)
    }
    fn occluded(&self, rays: &[Ray], out: &mut [bool]) {
        (**self).occluded(rays, out)
    }
    fn serves_fans(&self) -> bool {
        (**self).serves_fans()
    }
    fn intersect_fan(&self, fan: &Fan, out: &mut FanHits) -> bool {
        (**self).intersect_fan(fan, out)
    }
    fn geometry(&self) -> &Arc<Geometry> {
        (**self).geometry()
    }
}

/// Builds accelerators; one per kind of backend.
pub trait Backend: Send + Sync {
    /// The name `--backend` selects it by.
    fn name(&self) -> &'static str;
    /// An accelerator over one group's rest-frame geometry.
    fn build(&self, geometry: Arc<Geometry>) -> crate::Result<Box<dyn Accelerator>>;
    /// What builds culling structures over boxes (the trees over many velocity groups), also
    /// later, on first use; by default the f64 box tree.
    fn cullers(&self) -> CullerFactory {
        Arc::new(|boxes| Ok(Box::new(BoxTree::build(boxes)) as Box<dyn BoxCuller>))
    }
    /// Where the backend records what went wrong while tracing (`Faults`), if it can fail
    /// there; the render checks it.
    fn faults(&self) -> Option<Arc<Faults>> {
        None
    }
}

/// Builds a [`BoxCuller`] over boxes.
pub type CullerFactory = Arc<dyn Fn(&[Aabb]) -> crate::Result<Box<dyn BoxCuller>> + Send + Sync>;

/// A culling structure over boxes, one per item, that packets of rays from one origin `o`
/// traverse (directions `dirs`, each searched in `(tmin[i], tmax[i])`): `visit(item, ray, tmax)`
/// tests an item exactly and returns the ray's new tmax; one below the ray's tmin ends the ray.
/// Every item whose box a ray meets before its tmax is visited (rounding may add others).
pub trait BoxCuller: Send + Sync {
    /// Traverse the packet, visiting every item a ray meets as described above.
    fn traverse_packet(
        &self,
        o: DVec3,
        dirs: &[DVec3],
        tmin: &[f64],
        tmax: &mut [f64],
        visit: &mut dyn FnMut(u32, usize, f64) -> f64,
    );

    /// The same structure over other boxes of the same items (`box_of(item)`), if it can be
    /// refitted far more cheaply than built; None: build anew.
    fn refitted(&self, _box_of: &mut dyn FnMut(u32) -> Aabb) -> Option<Box<dyn BoxCuller>> {
        None
    }
}

impl BoxCuller for BoxTree {
    fn traverse_packet(
        &self,
        o: DVec3,
        dirs: &[DVec3],
        tmin: &[f64],
        tmax: &mut [f64],
        visit: &mut dyn FnMut(u32, usize, f64) -> f64,
    ) {
        BoxTree::traverse_packet(self, o, dirs, tmin, tmax, visit)
    }

    fn refitted(&self, box_of: &mut dyn FnMut(u32) -> Aabb) -> Option<Box<dyn BoxCuller>> {
        Some(Box::new(self.refit_with(box_of)))
    }
}

impl BoxCuller for LightBuffer {
    fn traverse_packet(
        &self,
        o: DVec3,
        dirs: &[DVec3],
        tmin: &[f64],
        tmax: &mut [f64],
        visit: &mut dyn FnMut(u32, usize, f64) -> f64,
    ) {
        self.traverse(o, dirs, tmin, tmax, visit)
    }
}

/// Light buffers around `origin` as culling structures (for rays from it, as shadow rays read
/// backwards from a light are), on every backend.
pub(crate) fn light_buffers(origin: DVec3) -> CullerFactory {
    Arc::new(move |boxes| Ok(Box::new(LightBuffer::build(origin, boxes)) as Box<dyn BoxCuller>))
}

/// The names `--backend` accepts in this build, default first.
pub fn backend_names() -> Vec<&'static str> {
    if cfg!(feature = "embree") {
        vec!["embree", "bvh"]
    } else {
        vec!["bvh"]
    }
}

/// Every name `--backend` accepts in this build: the backends (`backend_names`), then the
/// variants kept for comparisons.
pub(crate) fn all_backend_names() -> Vec<&'static str> {
    let mut names = backend_names();
    #[cfg(feature = "embree")]
    names.extend(EMBREE_WIDTHS);
    names.push("bvh-f32");
    names
}

/// What `rest-embree backends` prints: every name `--backend` takes and what it is; for
/// Embree, what this CPU and `REST_EMBREE_ISA` make of it (an error if that names an
/// instruction set Embree or the CPU does not have).
pub(crate) fn backend_report() -> crate::Result<Vec<String>> {
    let mut lines = Vec::new();
    #[cfg(feature = "embree")]
    {
        let embree = embree_summary()?.unwrap_or_default();
        lines.push(format!("embree (default): {embree}"));
    }
    let default = if cfg!(feature = "embree") {
        ""
    } else {
        " (default)"
    };
    lines.push(format!(
        "bvh{default}: the f64 BVH in pure Rust, the reference every backend is compared with"
    ));
    #[cfg(feature = "embree")]
    lines.push(format!(
        "{}: Embree with a fixed packet width (single: one ray at a time), for comparisons",
        EMBREE_WIDTHS.join(", ")
    ));
    lines.push("bvh-f32: the f64 BVH's tree with f32 nodes, for comparisons".to_string());
    #[cfg(feature = "embree")]
    lines.push(format!(
        "Embree's instruction set: {}={} (one this CPU has; unset: the CPU's best)",
        embree::ISA_ENV,
        embree::Isa::ALL.map(embree::Isa::name).join("|")
    ));
    Ok(lines)
}

/// What Embree runs here (version, instruction set, packet widths), as `backends` says it;
/// None in a build without Embree. For the bench's record of the machine.
pub(crate) fn embree_summary() -> crate::Result<Option<String>> {
    #[cfg(feature = "embree")]
    return EmbreeBackend::new()
        .configured_by_env()?
        .describe()
        .map(Some);
    #[cfg(not(feature = "embree"))]
    Ok(None)
}

/// The backend `render` uses when none is named: Embree where built, else the f64 BVH.
pub fn default_backend_name() -> &'static str {
    backend_names()[0]
}

/// The Embree backend of that name: `embree` traces packets as wide as Embree traces natively
/// on this CPU (16, 8 or 4); `embree-16`, `embree-8`, `embree-4` and `embree-single` fix the
/// width, for comparisons.
#[cfg(feature = "embree")]
pub(crate) fn embree_backend(name: &str) -> Option<EmbreeBackend> {
    match name {
        "embree" => Some(EmbreeBackend::new()),
        "embree-16" => Some(EmbreeBackend::with_packet_width(16)),
        "embree-8" => Some(EmbreeBackend::with_packet_width(8)),
        "embree-4" => Some(EmbreeBackend::with_packet_width(4)),
        "embree-single" => Some(EmbreeBackend::with_packet_width(1)),
        _ => None,
    }
}

/// The Embree backends of fixed packet width, for comparisons (`--backend` takes them too).
#[cfg(feature = "embree")]
pub(crate) const EMBREE_WIDTHS: [&str; 4] = ["embree-16", "embree-8", "embree-4", "embree-single"];

/// What asking a build without Embree for an Embree backend says: how to get one. Built in
/// every build, so the tests of the build with Embree check the message too.
#[cfg_attr(all(feature = "embree", not(test)), expect(dead_code))]
pub(crate) fn embree_not_in_this_build() -> crate::Error {
    crate::Error::backend(
        "backend 'embree' is not in this build: rebuild with `--features embree` (needs libembree-dev and libclang-dev)",
    )
}

/// The backend of that name, or an error that lists the choices.
pub fn backend_by_name(name: &str) -> crate::Result<Box<dyn Backend>> {
    match name {
        "bvh" => Ok(Box::new(BvhBackend::default())),
        // The f64 BVH's tree with f32 nodes, for comparisons.
        "bvh-f32" => Ok(Box::new(Bvh32Backend)),
        // The instruction set and test hook the environment asks for (`EmbreeBackend::configured_by_env`).
        #[cfg(feature = "embree")]
        "embree" | "embree-16" | "embree-8" | "embree-4" | "embree-single" => {
            match embree_backend(name) {
                Some(b) => Ok(Box::new(b.configured_by_env()?)),
                None => Err(crate::Error::backend(format!("unknown backend '{name}'"))),
            }
        }
        #[cfg(not(feature = "embree"))]
        "embree" | "embree-16" | "embree-8" | "embree-4" | "embree-single" => {
            Err(embree_not_in_this_build())
        }
        other => Err(crate::Error::backend(format!(
            "unknown backend '{other}' (choose one of: {})",
            all_backend_names().join(", ")
        ))),
    }
}
