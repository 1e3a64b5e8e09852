//! The part of a world that does not depend on the camera: the scene's groups merged by
//! velocity, each with its rest-frame geometry and accelerator. Built once, it serves every
//! frame of a film (`World::aim`).

use super::WorldOptions;
use crate::accel::{Accelerator, Backend};
use crate::geometry::{Aabb, Geometry, ImplicitRun};
use crate::scene::Scene;
use crate::spacetime::{Boost, Velocity, Window};
use std::sync::Arc;

/// A group of the world as it is in its rest frame, whatever the camera: its merged geometry
/// and accelerator.
pub(super) struct RestGroup {
    pub velocity: Velocity,
    pub boost: Boost,
    pub bounds: Aabb,
    /// The bounds in the axes of the plain boost to `velocity` (`bounds` but for a group
    /// whose axes are turned, `Group::turn`).
    pub plain_bounds: Aabb,
    pub geometry: Arc<Geometry>,
    pub accel: Option<Arc<dyn Accelerator>>,
    pub epsilon: f64,
    /// The emission events it is seen at (a worldline's segment).
    pub window: Option<Box<Window>>,
    /// Whether anything in it spins (its hits then move into their points' frames).
    pub spins: bool,
    /// Its hyperbolic motion, for a segment of constant proper acceleration.
    pub accelerated: Option<crate::scene::Accelerated>,
    /// Its turning bodies, if any (world/turning/).
    pub turning: Option<Arc<[super::TurningPart]>>,
    /// Its primitives, where it has no accelerator and is intersected one primitive at a time
    /// against lanes of rays (world/direct.rs).
    pub direct: Option<Arc<super::direct::DirectPrims>>,
}

/// The world's groups, built once: the part of a world that a film's frames share (the
/// accelerators are most of a world's build).
pub struct RestGroups {
    pub(super) groups: Vec<RestGroup>,
    pub(super) options: WorldOptions,
    /// How many bodies the groups are: those seen at all times (as merged) and the worldlines
    /// (a worldline's segments are groups of one name, each seen in its window).
    pub(super) bodies: usize,
}

impl RestGroups {
    /// Merge the scene's groups of one velocity and build each one's accelerator.
    pub fn build(
        scene: &Scene,
        backend: &dyn Backend,
        options: WorldOptions,
    ) -> crate::Result<RestGroups> {
        // Which scene groups share a rest frame and the times they are seen at, in file order.
        // An accelerated segment is never merged (its key holds its index).
        type Key = ([u64; 4], Option<[u64; 10]>, Option<usize>);
        type Set = (
            Velocity,
            Option<Box<Window>>,
            smallvec::SmallVec<[usize; 1]>,
        );
        let mut sets: Vec<Set> = Vec::with_capacity(scene.groups.len());
        // Sized for every group at once: 100,000 groups otherwise pay for the map's regrowth.
        let mut index: hashbrown::HashMap<Key, usize> =
            hashbrown::HashMap::with_capacity(scene.groups.len());
        for (i, g) in scene.groups.iter().enumerate() {
            if g.geometry.is_empty() {
                continue;
            }
            let v = g.velocity;
            let key = (
                v.identity_key(),
                g.window.as_ref().map(|w| w.key()),
                (g.accelerated.is_some() || g.geometry.turns() || g.turn.is_some()).then_some(i),
            );
            match index.get(&key).filter(|_| options.merge_equal_velocities) {
                Some(&k) => sets[k].2.push(i),
                None => {
                    index.insert(key, sets.len());
                    sets.push((v, g.window.clone(), smallvec::smallvec![i]));
                }
            }
        }
        let mut groups = Vec::with_capacity(sets.len());
        for (velocity, window, members) in sets {
            let geos: Vec<&Arc<Geometry>> =
                members.iter().map(|&i| &scene.groups[i].geometry).collect();
            let mut geometry = merge(&geos);
            let small = |r: &ImplicitRun| r.shape.len() <= options.instance_over;
            if geometry.implicit.iter().any(small) {
                // Small lattices and bar arrays as lists of primitives, as every backend traces
                // best; large ones stay themselves, to be instanced.
                geometry = Arc::new(geometry.listing(options.instance_over));
            }
            let (accelerated, turn) = (
                scene.groups[members[0]].accelerated,
                scene.groups[members[0]].turn,
            );
            let own = geometry.bounds();
            let turning: Option<Arc<[super::TurningPart]>> = geometry
                .turns()
                .then(|| super::turning::turning_parts(&geometry).into());
            let bounds = match &accelerated {
                Some(acc) => super::accelerated::swept_bounds(acc, geometry.bounds()),
                None if turning.is_some() => geometry.swept_bounds(),
                None => geometry.bounds(),
            };
            let names: Vec<&str> = members
                .iter()
                .map(|&i| scene.groups[i].name.as_str())
                .collect();
            let direct = accelerated.is_some() || turning.is_some();
            let accel = if geometry.len() as usize <= options.direct_max || direct {
                None
            } else {
                Some(Arc::from(backend.build(geometry.clone()).map_err(|e| {
                    crate::Error::backend(format!(
                        "building the {} backend for group `{}`: {e}",
                        backend.name(),
                        names.join("`, `")
                    ))
                })?))
            };
            let spins = geometry.spins();
            let prims = (accel.is_none() && !direct)
                .then(|| Arc::new(super::direct::DirectPrims::of(&geometry)));
            groups.push(RestGroup {
                velocity,
                boost: scene.groups[members[0]].to_rest(),
                bounds,
                plain_bounds: turn.map_or(bounds, |r| bounds.turned(r.transpose())),
                geometry,
                accel,
                // Relative to the group's size and place alone, so that a scene scaled as a
                // whole renders the same (tests/suite/envelope.rs); an accelerated body's own, not the
                // box it sweeps.
                epsilon: 1e-7 * own.diagonal() + 1e-12 * bounds.max_abs(),
                window,
                spins,
                accelerated,
                turning,
                direct: prims,
            });
        }
        let worldlines = scene
            .groups
            .iter()
            .filter(|g| g.window.is_some() && !g.geometry.is_empty())
            .map(|g| g.name.as_str())
            .collect::<std::collections::HashSet<_>>()
            .len();
        let bodies = groups.iter().filter(|g| g.window.is_none()).count() + worldlines;
        Ok(RestGroups {
            groups,
            options,
            bodies,
        })
    }
}

/// Concatenate geometries that share one rest frame.
fn merge(geos: &[&Arc<Geometry>]) -> Arc<Geometry> {
    if geos.len() == 1 {
        return geos[0].clone();
    }
    let mut g = Geometry::default();
    for src in geos {
        g.append(src);
    }
    Arc::new(g)
}
