//! The scene as the tracer sees it: per velocity group its boost, rest-frame bounds and
//! accelerator; the per-group boost of world-frame null rays and the merge of hits by lookback.
//!
//! What a scene doesn't need is skipped (each switchable, for the benchmarks): groups that
//! share a velocity are merged into one rest-frame scene; a ray is tested against a group's
//! bounds before the group's accelerator, and only from where it enters them; with many groups a
//! kinetic tree over the groups (group_tree.rs) finds the few a ray can meet, so a ray that misses
//! every group costs a handful of box tests.

use super::group_tree::GroupTree;
use crate::accel::{Accelerator, Backend, Hit, Ray};
use crate::geometry::{Aabb, Geometry, Part};
use crate::scene::Scene;
use crate::spacetime::{Boost, NullRay, Velocity};
use glam::DVec3;
use std::sync::Arc;

/// From this many groups on, rays find their groups through the group tree.
pub const GROUP_TREE_MIN: usize = 8;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldOptions {
    /// Merge groups with the same velocity into one rest-frame scene.
    pub merge_equal_velocities: bool,
    /// Test rays against each group's rest-frame bounds first (and rebase them there).
    pub bounds_cull: bool,
    /// Use the kinetic group tree when there are many groups.
    pub group_tree: bool,
}

impl Default for WorldOptions {
    fn default() -> Self {
        Self {
            merge_equal_velocities: true,
            bounds_cull: true,
            group_tree: true,
        }
    }
}

pub struct GroupRt {
    pub velocity: Velocity,
    pub boost: Boost,
    pub unboost: Boost,
    pub bounds: Aabb,
    pub geometry: Arc<Geometry>,
    pub accel: Box<dyn Accelerator>,
    /// Offset for spawning secondary rays off surfaces, in rest-frame length.
    pub epsilon: f64,
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
    pub groups: Vec<GroupRt>,
    pub options: WorldOptions,
    tree: Option<GroupTree>,
}

/// A ray boosted into a group's rest frame and rebased to the near side of the group's bounds.
struct RestRay {
    ray: Ray,
    shift: f64,
    s: f64,
}

/// Concatenate geometries that share one rest frame.
fn merge(geos: &[&Arc<Geometry>]) -> Arc<Geometry> {
    if geos.len() == 1 {
        return geos[0].clone();
    }
    let mut g = Geometry::default();
    for src in geos {
        let off = g.prims.len() as u32;
        g.prims.extend_from_slice(&src.prims);
        g.parts.extend(src.parts.iter().map(|p| Part {
            start: p.start + off,
            end: p.end + off,
            ..p.clone()
        }));
    }
    Arc::new(g)
}

impl World {
    pub fn build(scene: &Scene, backend: &dyn Backend) -> Result<World, String> {
        Self::build_with(scene, backend, WorldOptions::default())
    }

    pub fn build_with(
        scene: &Scene,
        backend: &dyn Backend,
        options: WorldOptions,
    ) -> Result<World, String> {
        // Which scene groups share a rest frame.
        let mut sets: Vec<(Velocity, Vec<usize>)> = Vec::new();
        for (i, g) in scene.groups.iter().enumerate() {
            if g.geometry.is_empty() {
                continue;
            }
            match sets
                .iter_mut()
                .find(|(v, _)| options.merge_equal_velocities && v.same_as(&g.velocity))
            {
                Some((_, members)) => members.push(i),
                None => sets.push((g.velocity, vec![i])),
            }
        }
        let mut groups = Vec::with_capacity(sets.len());
        for (velocity, members) in sets {
            let geos: Vec<&Arc<Geometry>> =
                members.iter().map(|&i| &scene.groups[i].geometry).collect();
            let geometry = merge(&geos);
            let bounds = geometry.bounds();
            let names: Vec<&str> = members
                .iter()
                .map(|&i| scene.groups[i].name.as_str())
                .collect();
            let accel = backend.build(geometry.clone()).map_err(|e| {
                format!(
                    "building the {} backend for group `{}`: {e}",
                    backend.name(),
                    names.join("`, `")
                )
            })?;
            groups.push(GroupRt {
                velocity,
                boost: Boost::to_rest(&velocity),
                unboost: Boost::from_rest(&velocity),
                bounds,
                geometry,
                accel,
                epsilon: 1e-7 * bounds.diagonal().max(1e-3) + 1e-12 * bounds.max_abs(),
            });
        }
        let tree = (options.group_tree && groups.len() >= GROUP_TREE_MIN).then(|| {
            let items: Vec<(Aabb, Velocity)> =
                groups.iter().map(|g| (g.bounds, g.velocity)).collect();
            GroupTree::build(&items, scene.camera.time)
        });
        Ok(World {
            groups,
            options,
            tree,
        })
    }

    pub fn uses_group_tree(&self) -> bool {
        self.tree.is_some()
    }

    /// Boost into group g's rest frame; None when the ray misses the group's bounds in
    /// (tmin, tmax). The origin moves along the ray to where it enters the bounds, so the
    /// backend never sees large coordinates (DESIGN.md).
    fn rest_ray(&self, g: &GroupRt, ray: &NullRay, tmin: f64, tmax: f64) -> Option<RestRay> {
        let origin = g.boost.event(ray.origin).x;
        let (dir, s) = g.boost.null_dir(ray.dir);
        let shift = if self.options.bounds_cull {
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
            },
            shift,
            s,
        })
    }

    fn surface_hit(gi: usize, rr: &RestRay, h: Hit) -> SurfaceHit {
        SurfaceHit {
            group: gi,
            prim: h.prim,
            lambda: rr.shift + h.t,
            point: rr.ray.origin + h.t * rr.ray.dir,
            dir: rr.ray.dir,
            s: rr.s,
        }
    }

    /// The visible hit on each ray: the one with the smallest world-frame lookback time (the
    /// latest emission event) over all groups, in `(tmin, tmax)` of lookback. With few groups
    /// the rays go to each group's backend together (packets); with many, one by one through
    /// the group tree.
    pub fn closest_hits(&self, rays: &[NullRay], tmin: f64, out: &mut [Option<SurfaceHit>]) {
        if self.tree.is_some() {
            for (r, o) in rays.iter().zip(out.iter_mut()) {
                *o = self.closest_hit(r, tmin);
            }
            return;
        }
        let n = rays.len();
        let mut best = vec![f64::INFINITY; n];
        let mut batch = Vec::with_capacity(n);
        let mut meta = Vec::with_capacity(n);
        let mut hits: Vec<Option<Hit>> = vec![None; n];
        out.iter_mut().for_each(|o| *o = None);
        for (gi, g) in self.groups.iter().enumerate() {
            batch.clear();
            meta.clear();
            for (i, r) in rays.iter().enumerate() {
                if let Some(rr) = self.rest_ray(g, r, tmin, best[i]) {
                    batch.push(rr.ray);
                    meta.push((i, rr));
                }
            }
            if batch.is_empty() {
                continue;
            }
            g.accel.intersect(&batch, &mut hits[..batch.len()]);
            for (k, h) in hits[..batch.len()].iter().enumerate() {
                if let Some(h) = h {
                    let (i, ref rr) = meta[k];
                    let hit = Self::surface_hit(gi, rr, *h);
                    if hit.lambda < best[i] {
                        best[i] = hit.lambda;
                        out[i] = Some(hit);
                    }
                }
            }
        }
    }

    /// The visible hit on one ray (secondary rays, and every ray when there are many groups).
    pub fn closest_hit(&self, ray: &NullRay, tmin: f64) -> Option<SurfaceHit> {
        let mut best: Option<SurfaceHit> = None;
        let mut hit = [None];
        let mut visit = |gi: usize, tmax: f64| -> f64 {
            let g = &self.groups[gi];
            if let Some(rr) = self.rest_ray(g, ray, tmin, tmax) {
                g.accel.intersect(std::slice::from_ref(&rr.ray), &mut hit);
                if let Some(h) = hit[0] {
                    let sh = Self::surface_hit(gi, &rr, h);
                    if sh.lambda < tmax {
                        best = Some(sh);
                        return sh.lambda;
                    }
                }
            }
            tmax
        };
        match &self.tree {
            Some(tree) => {
                tree.traverse(ray, tmin, f64::INFINITY, |g, tmax| visit(g as usize, tmax))
            }
            None => {
                let mut tmax = f64::INFINITY;
                for gi in 0..self.groups.len() {
                    tmax = visit(gi, tmax);
                }
            }
        }
        best
    }

    /// Whether anything lies on the ray between lookback `tmin` and `tmax`.
    pub fn occluded(&self, ray: &NullRay, tmin: f64, tmax: f64) -> bool {
        let mut o = [false];
        let mut test = |gi: usize| -> bool {
            let g = &self.groups[gi];
            match self.rest_ray(g, ray, tmin, tmax) {
                Some(rr) => {
                    g.accel.occluded(std::slice::from_ref(&rr.ray), &mut o);
                    o[0]
                }
                None => false,
            }
        };
        match &self.tree {
            Some(tree) => {
                let mut found = false;
                tree.traverse(ray, tmin, tmax, |g, t| {
                    if test(g as usize) {
                        found = true;
                        f64::NEG_INFINITY
                    } else {
                        t
                    }
                });
                found
            }
            None => (0..self.groups.len()).any(test),
        }
    }
}
