//! A group of the world as rays meet it: its boost, bounds, window of emission events and
//! how it is intersected (through its accelerator, primitive by primitive, in Rindler
//! coordinates for an accelerated segment, or by sphere tracing for a turning body).

use super::moving_bounds::MovingBounds;
use super::{accelerated, turning, SurfaceHit, TurningPart};
use crate::accel::{Accelerator, Hit, Ray};
use crate::geometry::{Aabb, Geometry, Part, Primitive};
use crate::spacetime::{Boost, Event, Velocity, Window};
use glam::DVec3;
use std::sync::Arc;

/// A group of the world: its rest frame as seen from the imaging event.
pub struct WorldGroup {
    /// The imaging event's position in this group's rest frame.
    pub event_rest: DVec3,
    pub velocity: Velocity,
    /// Into the group's rest frame (its inverse leads out).
    pub boost: Boost,
    pub bounds: Aabb,
    /// The bounds in the axes of the plain boost to its velocity (`bounds` unless its axes are
    /// turned, `scene::Group::turn`): for the tests before the boost.
    pub plain_bounds: Aabb,
    pub geometry: Arc<Geometry>,
    /// None for groups intersected directly; shared by every frame of a film.
    pub accel: Option<Arc<dyn Accelerator>>,
    /// Offset for spawning secondary rays off surfaces, in rest-frame length.
    pub epsilon: f64,
    /// The bounds as they move through the world frame: a test before the boost.
    pub(super) moving: MovingBounds,
    /// The emission events it is seen at (a worldline's segment); None: all.
    pub window: Option<Box<Window>>,
    /// The window's two world times where both its ends are of world time (between uniform
    /// segments), for lookbacks without a boost (`World::in_window`).
    pub(super) world_window: Option<(f64, f64)>,
    /// Whether anything in it spins.
    pub spins: bool,
    /// Its hyperbolic motion, for a segment of constant proper acceleration (its rays start
    /// on the segment's start hyperplane, `World::rest_ray`).
    pub accelerated: Option<crate::scene::Accelerated>,
    /// Its spinning bodies whose shape turns (not of revolution), if any: the group is then
    /// intersected directly, its rays starting on its hyperplane of time `turn_time`.
    pub turning: Option<Arc<[TurningPart]>>,
    /// The group's time of the imaging event, where a turning group's rays are made to start
    /// (near the events they meet, so that their lookbacks stay small).
    pub turn_time: f64,
    /// Its primitives, where it has no accelerator (world/direct.rs), and whether their tests
    /// run in vector registers (`WorldOptions::simd`).
    pub direct: Option<Arc<super::direct::DirectPrims>>,
    pub simd: bool,
}

impl WorldGroup {
    /// The group's time at which its rays are made to start (`World::rest_ray`), where its
    /// intersection needs the time along them: an accelerated segment's start, or 0 for
    /// turning bodies.
    pub(super) fn time_origin(&self) -> Option<f64> {
        match (&self.accelerated, &self.turning) {
            (Some(acc), _) => Some(acc.start.t),
            (None, Some(_)) => Some(self.turn_time),
            (None, None) => None,
        }
    }

    /// Whether the group is seen at emission event `e` (always, but for a worldline's
    /// segment); `World::rest_ray` keeps rays to the same events.
    pub fn shows_at(&self, e: Event) -> bool {
        self.window.as_ref().is_none_or(|w| w.contains(e))
    }

    /// The closest hit of each ray in this group (None for inactive rays): through the
    /// accelerator, or the primitives one by one for a group without one.
    pub(super) fn intersect(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        self.intersect_as(rays, hits, false);
    }

    /// [`WorldGroup::intersect`] of rays that are `scattered` (sharing neither origin nor
    /// direction: `Accelerator::intersect_scattered`) or not.
    pub(super) fn intersect_as(&self, rays: &[Ray], hits: &mut [Option<Hit>], scattered: bool) {
        if let Some(parts) = &self.turning {
            for (r, h) in rays.iter().zip(hits.iter_mut()) {
                *h = turning::intersect(&self.geometry, parts, r, self.turn_time);
            }
            return;
        }
        if let Some(acc) = &self.accelerated {
            for (r, h) in rays.iter().zip(hits.iter_mut()) {
                *h = accelerated::intersect(acc, &self.geometry, r);
            }
            return;
        }
        if let Some(accel) = &self.accel {
            // Rays from anywhere go one by one: a packet of them costs an accelerator the
            // union of their traversals (the paper's lattice on Embree: 1.25x the time).
            if scattered {
                for (r, h) in rays.iter().zip(hits.iter_mut()) {
                    accel.intersect(std::slice::from_ref(r), std::slice::from_mut(h));
                }
                return;
            }
            return accel.intersect(rays, hits);
        }
        if let Some(d) = &self.direct {
            return super::direct::intersect(&d.prims, rays, hits, self.simd);
        }
        for (r, h) in rays.iter().zip(hits.iter_mut()) {
            *h = None;
            if !r.is_active() {
                continue;
            }
            for i in 0..self.geometry.len() {
                let tmax = h.map_or(r.tmax, |b| b.t);
                let p = self.geometry.prim(i);
                if let Some(t) = p.intersect(r.origin, r.dir, r.tmin, tmax) {
                    *h = Some(Hit { t, prim: i });
                }
            }
        }
    }

    /// Whether anything of this group lies on each ray (false for inactive rays).
    pub(super) fn occluded(&self, rays: &[Ray], out: &mut [bool]) {
        self.occluded_as(rays, out, false);
    }

    /// [`WorldGroup::occluded`] of rays that are `scattered` or not (as
    /// [`WorldGroup::intersect_as`]).
    pub(super) fn occluded_as(&self, rays: &[Ray], out: &mut [bool], scattered: bool) {
        if let Some(parts) = &self.turning {
            for (r, o) in rays.iter().zip(out.iter_mut()) {
                *o = turning::occluded(&self.geometry, parts, r, self.turn_time);
            }
            return;
        }
        if let Some(acc) = &self.accelerated {
            for (r, o) in rays.iter().zip(out.iter_mut()) {
                *o = accelerated::occluded(acc, &self.geometry, r);
            }
            return;
        }
        if let Some(accel) = &self.accel {
            if scattered {
                for (r, o) in rays.iter().zip(out.iter_mut()) {
                    accel.occluded(std::slice::from_ref(r), std::slice::from_mut(o));
                }
                return;
            }
            return accel.occluded(rays, out);
        }
        if let Some(d) = &self.direct {
            return super::direct::occluded(&d.prims, rays, out, self.simd);
        }
        for (r, o) in rays.iter().zip(out.iter_mut()) {
            *o = r.is_active()
                && (0..self.geometry.len()).any(|i| {
                    let p = self.geometry.prim(i);
                    p.intersect(r.origin, r.dir, r.tmin, r.tmax).is_some()
                });
        }
    }

    /// The part primitive `prim` belongs to (without a search in a small group).
    #[inline]
    pub fn part_of(&self, prim: u32) -> &Part {
        match &self.direct {
            Some(d) => &self.geometry.parts[d.parts[prim as usize] as usize],
            None => self.geometry.part_of(prim),
        }
    }

    /// `f` of primitive `prim`, by reference where it is held (a copy of a primitive read
    /// back field by field stalls on the copy's wide stores), else made.
    #[inline]
    pub fn with_prim<R>(&self, prim: u32, f: impl FnOnce(&Primitive) -> R) -> R {
        match &self.direct {
            Some(d) => f(&d.prims[prim as usize]),
            None => match self.geometry.prims.get(prim as usize) {
                Some(p) => f(p),
                None => f(&self.geometry.prim(prim)),
            },
        }
    }

    pub(super) fn intersect1(&self, r: &Ray) -> Option<Hit> {
        let mut h = [None];
        self.intersect(std::slice::from_ref(r), &mut h);
        h[0]
    }

    pub(super) fn occluded1(&self, r: &Ray) -> bool {
        let mut o = [false];
        self.occluded(std::slice::from_ref(r), &mut o);
        o[0]
    }
}

/// The outward normal (rest frame) at a hit seen at world event `event`: a turning body's is
/// its shape's at time 0 at the point turned back, turned as the body is.
pub(crate) fn surface_normal(g: &WorldGroup, hit: &SurfaceHit, event: Event) -> DVec3 {
    let prim = g.geometry.prim(hit.prim);
    surface_normal_of(g, &prim, g.geometry.part_of(hit.prim), hit, event)
}

/// [`surface_normal`] of the hit's primitive `prim`, of part `part`, made by the caller.
#[inline]
pub(crate) fn surface_normal_of(
    g: &WorldGroup,
    prim: &Primitive,
    part: &Part,
    hit: &SurfaceHit,
    event: Event,
) -> DVec3 {
    match &part.spin {
        Some(sp) if sp.turning => {
            let t = g.boost.event(event).t;
            sp.turned_dir(prim.normal(sp.unturned(hit.point, t)), t)
        }
        _ => prim.normal(hit.point),
    }
}
