//! The scene as the tracer sees it: per velocity group its boost, rest-frame bounds and
//! accelerator; the per-group boost of world-frame null rays and the merge of hits by lookback.
//!
//! What a scene doesn't need is skipped (each switchable, for the benchmarks): groups that
//! share a velocity are merged into one rest-frame scene; a ray is tested against a group's
//! bounds before the group's accelerator, and only from where it enters them; groups of a few
//! primitives skip the accelerator; with many groups, trees over the groups find the few a ray
//! can meet (apparent_tree.rs for primary rays, light_tree.rs for shadow rays toward lights at
//! rest, group_tree.rs for the rest, built only when such a ray comes), so a ray that misses
//! every group costs a handful of box tests.

use apparent_tree::ApparentTree;
pub(crate) use group_tree::SlicedGroupTree;
pub(crate) use light_tree::LightTree;

mod accelerated;
mod apparent_tree;
mod group_tree;
mod light_tree;
// What the tests of the internals reach (src/tests/).
pub(crate) use accelerated::point_boost;
#[cfg(test)]
pub(crate) use {
    apparent_tree::apparent_box,
    group_tree::{world_box, GroupTree},
    light_tree::reach_box,
};
mod moving_bounds;
mod turning;
pub(crate) use turning::TurningPart;
mod rest_groups;
pub use rest_groups::RestGroups;
mod closest_hits;
mod direct;
mod primary_hits;
mod shadows;
mod world_group;
use crate::accel::{Backend, Faults, Hit, Ray};
use crate::geometry::Aabb;
use crate::scene::Scene;
use crate::spacetime::{NullRay, Velocity, Window};
use glam::DVec3;
use moving_bounds::MovingBounds;
pub use primary_hits::PrimaryHits;
pub(crate) use shadows::ShadowBuffers;
use std::sync::{Arc, OnceLock};
pub use world_group::WorldGroup;
pub(crate) use world_group::{surface_normal, surface_normal_of};

/// From this many groups on, rays find their groups through the group tree.
pub(crate) const GROUP_TREE_MIN: usize = 8;

/// Kinetic trees per world (reference times), when the group tree is in use.
const TIME_SLICES: usize = 16;

/// Slices of emission times per light tree (light_tree.rs).
const LIGHT_SLICES: usize = 128;

/// Groups with at most this many primitives are intersected in f64 directly: an acceleration
/// structure (and a call into it) costs more than the primitives themselves.
pub const DIRECT_MAX: usize = 16;

pub(crate) use crate::geometry::INSTANCE_OVER;

/// The largest distance from `p` to a corner of `b`.
fn corner_distance(b: &Aabb, p: DVec3) -> f64 {
    (b.min - p).abs().max((b.max - p).abs()).length()
}

/// What the renderer may skip or fuse. Each switch leaves the picture the same; the tests and
/// the bench turn them off to prove it and to measure what they save.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WorldOptions {
    /// Merge groups with the same velocity into one rest-frame scene.
    pub merge_equal_velocities: bool,
    /// Test rays against each group's bounds first: in the world frame, where they move, then
    /// in the rest frame (and rebase them there).
    pub bounds_cull: bool,
    /// Use the kinetic group tree when there are many groups.
    pub group_tree: bool,
    /// Groups of at most this many primitives are intersected directly in f64, without an
    /// accelerator (0: every group gets one, as tests of a backend want).
    pub direct_max: usize,
    /// Let the backend make a packet's primary rays itself where it can (`primary_hits`): the
    /// same rays and hits to the bit, made several at a time.
    pub fused_primary: bool,
    /// Lattices of more primitives than this (in one rest frame) are built from one block
    /// placed many times (instanced), not listed primitive by primitive.
    pub instance_over: u64,
    /// The path integrator shades its commonest vertices (Lambert surfaces at rest in the
    /// world frame) a bounce of a tile's paths at a time, in lanes.
    pub lanes: bool,
    /// Those lanes run in vector registers where the CPU has AVX2 or AVX-512 (else one by
    /// one); `REST_EMBREE_SIMD=off` in the environment turns it off by default.
    pub simd: bool,
}

/// `REST_EMBREE_SIMD`, if set, as `off` or `on`: another value is an error naming it (it was
/// taken as on).
pub(crate) fn simd_env_checked() -> crate::Result<()> {
    match std::env::var("REST_EMBREE_SIMD") {
        Ok(v) if v != "off" && v != "on" => Err(crate::Error::flag(
            "REST_EMBREE_SIMD",
            format!(
                "`{}` is neither `off` (the lanes one by one) nor `on` (in vector registers where the CPU has them; the default)",
                crate::text::shown(&v)
            ),
        )),
        _ => Ok(()),
    }
}

/// Whether the environment leaves SIMD on (`REST_EMBREE_SIMD=off` turns it off).
fn simd_by_default() -> bool {
    static ON: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *ON.get_or_init(|| std::env::var("REST_EMBREE_SIMD").map_or(true, |v| v != "off"))
}

impl Default for WorldOptions {
    fn default() -> Self {
        Self {
            merge_equal_velocities: true,
            bounds_cull: true,
            group_tree: true,
            direct_max: DIRECT_MAX,
            fused_primary: true,
            instance_over: INSTANCE_OVER,
            lanes: true,
            simd: simd_by_default(),
        }
    }
}

/// A primary or secondary hit: which (world) group and primitive, the world-frame lookback λ,
/// and the rest-frame point and (unnormalised) ray direction, whose length `s` is the
/// lookback factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    pub group: usize,
    pub prim: u32,
    pub lambda: f64,
    pub point: DVec3,
    pub dir: DVec3,
    pub s: f64,
}

pub struct World {
    pub groups: Vec<WorldGroup>,
    /// The imaging event (world frame), where every primary ray starts.
    event: crate::spacetime::Event,
    pub options: WorldOptions,
    /// With many groups: every ray's culling (kinetic), the primary rays' (apparent boxes) and,
    /// per scene light at rest, its shadow rays' (light_tree.rs).
    tree: Option<Kinetic>,
    primary_tree: Option<ApparentTree>,
    light_trees: Vec<Option<LightTree>>,
    /// Whether rays are clipped to a group's bounds (and moved to where they enter) before its
    /// accelerator: needed to skip groups and to keep f32 coordinates small when rays come from
    /// afar; pure cost for one group seen from close by, whose rays all start near it.
    clip_rays: bool,
    /// Where every group is small and at rest in the world frame and rays are not clipped:
    /// rays traced against all groups at once, straight from the world rays (direct.rs).
    at_rest: Option<direct::AtRest>,
    /// Whether closest hits visit the groups last to first: where a worldline's segments are
    /// groups, listed earliest first, a ray meets the latest segment's window first (the
    /// smallest lookbacks), and once it has a hit there, the earlier segments' windows lie
    /// beyond it and are passed over before any boost.
    latest_first: bool,
    /// Visiting last to first, for each place in that order: the latest world time at which
    /// the groups from there on can emit what a ray meets (`latest_emissions`). Empty when
    /// visiting first to last: no group is then passed over.
    latest: Box<[f64]>,
    /// Where the backend records what went wrong while tracing, and how many faults it had
    /// when this world was made (`check`).
    faults: Option<(Arc<Faults>, u64)>,
}

/// The kinetic trees over the groups, made on first use: only rays that neither start at the
/// imaging event nor head for a light at rest need them (reflections, refractions, shadow rays
/// toward moving lights), and a scene without such rays never pays for their builds.
struct Kinetic {
    groups: Arc<[(Aabb, Velocity)]>,
    t_first: f64,
    t_last: f64,
    trees: OnceLock<SlicedGroupTree>,
}

impl Kinetic {
    fn get(&self) -> &SlicedGroupTree {
        self.trees.get_or_init(|| {
            SlicedGroupTree::build(&self.groups, self.t_first, self.t_last, TIME_SLICES)
        })
    }
}

/// A masked lane of a batch.
const INACTIVE: Ray = Ray {
    origin: DVec3::ZERO,
    dir: DVec3::X,
    tmin: 1.0,
    tmax: 0.0,
    len: 1.0,
};

/// A ray boosted into a group's rest frame and rebased to the near side of the group's bounds.
#[derive(Clone, Copy)]
struct RestRay {
    ray: Ray,
    shift: f64,
    s: f64,
}

impl World {
    pub fn build(scene: &Scene, backend: &dyn Backend) -> crate::Result<World> {
        Self::build_with(scene, backend, WorldOptions::default())
    }

    pub fn build_with(
        scene: &Scene,
        backend: &dyn Backend,
        options: WorldOptions,
    ) -> crate::Result<World> {
        let groups = RestGroups::build(scene, backend, options)?;
        World::aim(scene, &groups, backend)
    }

    /// The world seen from `scene`'s imaging event, on groups built before (for a film, once):
    /// what depends on the event is made here, the same way for every frame as for a still.
    pub fn aim(scene: &Scene, rest: &RestGroups, backend: &dyn Backend) -> crate::Result<World> {
        let event = scene.camera.imaging_event();
        let options = rest.options;
        let groups: Vec<WorldGroup> = rest
            .groups
            .iter()
            .map(|g| WorldGroup {
                event_rest: g.boost.event(event).x,
                velocity: g.velocity,
                boost: g.boost,
                bounds: g.bounds,
                geometry: g.geometry.clone(),
                accel: g.accel.clone(),
                epsilon: g.epsilon,
                moving: MovingBounds::new(&g.plain_bounds, &g.velocity, event.t),
                plain_bounds: g.plain_bounds,
                window: g.window.clone(),
                world_window: g.window.as_ref().and_then(|w| w.world_times()),
                spins: g.spins,
                accelerated: g.accelerated,
                turning: g.turning.clone(),
                turn_time: g.boost.event(event).t,
                direct: g.direct.clone(),
                simd: options.simd,
            })
            .collect();
        // The trees cull bodies (`RestGroups::bodies`); a body's worldline segments lie where
        // it goes, and a ray meets them in turn, each only in its window, which the groups'
        // packets test before any intersection: the trees pay for many bodies, not for many
        // segments of a few (measured: a lattice on 512 segments renders faster without them).
        let (tree, primary_tree, light_trees) =
            if options.group_tree && groups.len().min(rest.bodies) >= GROUP_TREE_MIN {
                let (k, a, l) = Self::group_trees(scene, &groups, backend)?;
                (Some(k), Some(a), l)
            } else {
                (None, None, Vec::new())
            };
        // Rays start at the imaging event or on a surface: with one group, all near it unless
        // the imaging event is far (more than 4 diagonals from the bounds' centre).
        let clip_rays = options.bounds_cull
            && (groups.len() > 1
                || groups.iter().any(|g| {
                    (g.event_rest - g.bounds.centroid()).length() > 4.0 * g.bounds.diagonal()
                }));
        let at_rest = (tree.is_none() && !clip_rays)
            .then(|| {
                let groups = groups.iter().map(|g| {
                    let at_rest = g.boost.is_identity()
                        && g.window.is_none()
                        && g.time_origin().is_none()
                        && g.accel.is_none()
                        && !g.spins;
                    g.direct.clone().filter(|_| at_rest)
                });
                groups.collect::<Option<Box<[_]>>>()
            })
            .flatten()
            .map(|groups| direct::AtRest {
                groups,
                simd: options.simd,
            });
        let latest_first = groups.iter().any(|g| g.window.is_some());
        debug_assert!(
            !(latest_first && at_rest.is_some()),
            "AtRest visits first to last"
        );
        let latest = if latest_first {
            closest_hits::latest_emissions(groups.iter().rev())
        } else {
            Box::default()
        };
        Ok(World {
            latest_first,
            latest,
            event,
            groups,
            options,
            tree,
            primary_tree,
            light_trees,
            clip_rays,
            at_rest,
            faults: backend.faults().map(|f| {
                let seen = f.count();
                (f, seen)
            }),
        })
    }

    /// An error if the backend recorded a fault while tracing (Embree's callbacks cannot
    /// return one): what was rendered since may be wrong.
    pub fn check(&self) -> crate::Result<()> {
        self.faults
            .as_ref()
            .map_or(Ok(()), |(f, seen)| f.check_since(*seen))
    }

    /// The trees over many groups: kinetic (built on first use), apparent boxes for primary
    /// rays, and a light tree per light at rest for shadow rays.
    fn group_trees(
        scene: &Scene,
        groups: &[WorldGroup],
        backend: &dyn Backend,
    ) -> crate::Result<(Kinetic, ApparentTree, Vec<Option<LightTree>>)> {
        let event = scene.camera.imaging_event();
        let items: Vec<(Aabb, Velocity)> = groups
            .iter()
            .map(|g| (g.plain_bounds, g.velocity))
            .collect();
        // Kinetic trees are tight near their reference times: spread them over the window in
        // which primary rays meet the groups, twice as deep as the farthest emission seen
        // from the imaging event (secondary rays reach further back).
        let apparent: Vec<Aabb> = items
            .iter()
            .map(|(b, v)| apparent_tree::apparent_box(b, v, event))
            .collect();
        let deepest = apparent
            .iter()
            .map(|b| corner_distance(b, event.x))
            .fold(0.0, f64::max);
        let primary = ApparentTree::build(&apparent, event, &backend.cullers())?;
        let t_first = event.t - 2.0 * deepest;
        let items: Arc<[(Aabb, Velocity)]> = items.into();
        // Shadow rays of primary hits leave a light at most 2 deepest + its distance from
        // the imaging event before the imaging event (later hits fall back on the kinetic
        // trees). Their slices are light buffers on every backend: read backwards, a slice's
        // rays all leave the light, and a cell lookup finds a ray's boxes without a tree walk
        // (cheaper than a walk of f64 box trees; Embree's culler per slice would cost a full
        // build for each).
        let lights = scene
            .lights
            .iter()
            .map(|l| {
                (l.velocity.is_zero() && l.worldline.is_none()).then(|| {
                    LightTree::new(
                        items.clone(),
                        crate::accel::light_buffers(l.position),
                        l.position,
                        event,
                        t_first - (l.position - event.x).length(),
                        event.t,
                        LIGHT_SLICES,
                    )
                })
            })
            .collect();
        let kinetic = Kinetic {
            groups: items,
            t_first,
            t_last: event.t,
            trees: OnceLock::new(),
        };
        Ok((kinetic, primary, lights))
    }

    /// Whether rays go to every group at once, straight from the world rays (`at_rest`).
    #[cfg(test)]
    pub fn traces_at_rest(&self) -> bool {
        self.at_rest.is_some()
    }

    /// The same world with its groups visited first to last (the tests compare the orders).
    #[cfg(test)]
    pub fn first_to_last(mut self) -> World {
        self.latest_first = false;
        self.latest = Box::default();
        self
    }

    /// Whether closest hits visit the groups last to first.
    #[cfg(test)]
    pub fn visits_latest_first(&self) -> bool {
        self.latest_first
    }

    /// The same world with its rays traced group by group (the tests compare the two).
    #[cfg(test)]
    pub fn group_by_group(mut self) -> World {
        self.at_rest = None;
        self
    }

    /// Whether the kinetic group tree is in use (the tests check when it is).
    #[cfg(test)]
    pub fn uses_group_tree(&self) -> bool {
        self.tree.is_some()
    }

    /// Boost into group g's rest frame; None when the ray misses the group's bounds in
    /// (tmin, tmax). The origin moves along the ray to where it enters the bounds, so the
    /// backend never sees large coordinates (docs/physics.md §7.1). A group seen only in a
    /// window (a worldline's segment) is met only where the ray's emission event lies in it
    /// (docs/physics.md §12.4).
    #[inline(always)]
    fn rest_ray(&self, g: &WorldGroup, ray: &NullRay, tmin: f64, tmax: f64) -> Option<RestRay> {
        let (tmin, tmax) = Self::in_window(g, ray, tmin, tmax)?;
        self.rest_ray_within(g, ray, tmin, tmax)
    }

    /// The lookbacks in (tmin, tmax) at which the ray's events lie in group g's window (all of
    /// them for a group without one); None where none do.
    #[inline(always)]
    fn in_window(g: &WorldGroup, ray: &NullRay, tmin: f64, tmax: f64) -> Option<(f64, f64)> {
        match (g.world_window, &g.window) {
            (Some(times), _) => Window::lookbacks_in_world_times(times, ray, tmin, tmax),
            (None, None) => Some((tmin, tmax)),
            (None, Some(w)) => w.lookbacks(ray, tmin, tmax),
        }
    }

    /// [`World::rest_ray`] of lookbacks already kept to the group's window (`in_window`).
    #[inline(always)]
    fn rest_ray_within(
        &self,
        g: &WorldGroup,
        ray: &NullRay,
        tmin: f64,
        tmax: f64,
    ) -> Option<RestRay> {
        if let Some(t_ref) = g.time_origin() {
            return self.rest_ray_timed(g, t_ref, ray, tmin, tmax);
        }
        // A group at rest in the world frame sees the ray as it is. Elsewhere, every primary
        // ray starts at the imaging event: its rest-frame origin is per group.
        let (origin, (dir, s)) = if g.boost.is_identity() {
            (ray.origin.x, (ray.dir, 1.0))
        } else if ray.origin == self.event {
            (g.event_rest, g.boost.null_dir(ray.dir))
        } else {
            (g.boost.event(ray.origin).x, g.boost.null_dir(ray.dir))
        };
        let shift = if self.clip_rays {
            g.bounds.clip(origin, dir.recip(), tmin, tmax)?.0
        } else {
            0.0
        };
        Some(RestRay {
            ray: Ray {
                origin: origin + shift * dir,
                dir,
                tmin: tmin - shift,
                tmax: tmax - shift,
                // |dir| is s (`Boost::null_dir`).
                len: s,
            },
            shift,
            s,
        })
    }

    /// [`World::rest_ray`] for a group whose intersection needs the time along the ray (an
    /// accelerated segment, turning bodies): the ray moved along itself to where it crosses the
    /// group's hyperplane of time `t_ref`, after the cull by the bounds the body sweeps.
    fn rest_ray_timed(
        &self,
        g: &WorldGroup,
        t_ref: f64,
        ray: &NullRay,
        tmin: f64,
        tmax: f64,
    ) -> Option<RestRay> {
        let origin = g.boost.event(ray.origin);
        let (dir, s) = g.boost.null_dir(ray.dir);
        if self.clip_rays {
            g.bounds.clip(origin.x, dir.recip(), tmin, tmax)?;
        }
        let shift = (origin.t - t_ref) / s;
        Some(RestRay {
            ray: Ray {
                origin: origin.x + shift * dir,
                dir,
                tmin: tmin - shift,
                tmax: tmax - shift,
                len: s,
            },
            shift,
            s,
        })
    }

    fn surface_hit(&self, gi: usize, rr: &RestRay, h: Hit) -> SurfaceHit {
        if let Some(acc) = &self.groups[gi].accelerated {
            let (point, _, dir, s) = accelerated::point_frame(acc, &rr.ray, h.t);
            return SurfaceHit {
                group: gi,
                prim: h.prim,
                lambda: rr.shift + h.t,
                point,
                dir,
                s,
            };
        }
        hit_on(gi, &rr.ray, rr.shift, rr.s, h)
    }

    /// A hit on a spinning object seen in its point's own frame, which moves at the spin's
    /// velocity there through the group's frame: the ray's direction and lookback factor
    /// there (factors multiply along a chain of frames, docs/physics.md §12.6). The point
    /// stays in the group's coordinates, where the body's shape is still.
    #[inline]
    fn spun(&self, hit: SurfaceHit) -> SurfaceHit {
        if !self.groups[hit.group].spins {
            return hit;
        }
        let part = self.groups[hit.group].geometry.part_of(hit.prim);
        let Some(boost) = part.spin.and_then(|sp| sp.boost_at(hit.point)) else {
            return hit;
        };
        let (d, s) = boost.null_dir(hit.dir / hit.s);
        SurfaceHit {
            dir: d * hit.s,
            s: s * hit.s,
            ..hit
        }
    }

    /// Whether the ray may meet group g's bounds in lookback (tmin, tmax), by where they move
    /// in the world frame: before the boost `rest_ray` makes, for the groups the trees hand a
    /// ray one by one, most of which it misses (moving_bounds.rs). Part of the bounds cull
    /// (`clip_rays`). The packets of worlds without the group trees (fewer than
    /// `GROUP_TREE_MIN` groups or bodies, or the trees switched off; `closest_hits`,
    /// `occluded_many`) go without it ray by ray: each group's bounds clip
    /// their rays there (`rest_ray`), after, for closest hits, one test of the whole chunk
    /// (`MovingBounds::may_meet_any`).
    #[inline(always)]
    fn may_meet(&self, g: &WorldGroup, ray: &NullRay, tmin: f64, tmax: f64) -> bool {
        !self.clip_rays || g.moving.may_meet(ray, tmin, tmax)
    }
}

/// Hit `h` of group `gi`'s rest ray `ray` (moved `shift` along the world ray, lookback factor
/// `s`) as a surface hit, where the group's frame carries it no further (not accelerated).
#[inline]
fn hit_on(gi: usize, ray: &Ray, shift: f64, s: f64, h: Hit) -> SurfaceHit {
    SurfaceHit {
        group: gi,
        prim: h.prim,
        lambda: shift + h.t,
        point: ray.origin + h.t * ray.dir,
        dir: ray.dir,
        s,
    }
}
