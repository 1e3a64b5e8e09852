//! The scene as the tracer sees it: per velocity group its boost, rest-frame bounds and
//! accelerator; the per-group boost of world-frame null rays and the merge of hits by lookback.

use crate::accel::{Accelerator, Backend, Hit, Ray};
use crate::geometry::Aabb;
use crate::scene::Scene;
use crate::spacetime::{Boost, NullRay};
use glam::DVec3;

pub struct GroupRt {
    pub boost: Boost,
    pub unboost: Boost,
    pub bounds: Aabb,
    pub accel: Box<dyn Accelerator>,
    /// Offset for spawning secondary rays off surfaces, in rest-frame length.
    pub epsilon: f64,
}

/// A primary or secondary hit: which group and primitive, the world-frame lookback λ, and the
/// rest-frame point and (unnormalised) ray direction, whose length `s` is the lookback factor.
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
}

/// A ray boosted into a group's rest frame and rebased to the near side of the group's bounds.
struct RestRay {
    ray: Ray,
    shift: f64,
    s: f64,
}

impl World {
    pub fn build(scene: &Scene, backend: &dyn Backend) -> Result<World, String> {
        let mut groups = Vec::new();
        for g in &scene.groups {
            let bounds = g.geometry.bounds();
            let accel = backend.build(g.geometry.clone()).map_err(|e| {
                format!(
                    "building the {} backend for group `{}`: {e}",
                    backend.name(),
                    g.name
                )
            })?;
            let epsilon = 1e-7 * bounds.diagonal().max(1e-3) + 1e-12 * bounds.max_abs();
            groups.push(GroupRt {
                boost: Boost::to_rest(&g.velocity),
                unboost: Boost::from_rest(&g.velocity),
                bounds,
                accel,
                epsilon,
            });
        }
        Ok(World { groups })
    }

    /// Boost into group g's rest frame; None when the ray misses the group's bounds in
    /// (tmin, tmax). The origin moves along the ray to where it enters the bounds, so the
    /// backend never sees large coordinates (DESIGN.md).
    fn rest_ray(&self, g: &GroupRt, ray: &NullRay, tmin: f64, tmax: f64) -> Option<RestRay> {
        if g.bounds.is_empty() {
            return None;
        }
        let origin = g.boost.event(ray.origin).x;
        let (dir, s) = g.boost.null_dir(ray.dir);
        let (t0, _) = g.bounds.clip(origin, dir.recip(), tmin, tmax)?;
        let shift = t0;
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

    /// The visible hit on each ray: the one with the smallest world-frame lookback time (the
    /// latest emission event) over all groups, in `(tmin, tmax)` of lookback.
    pub fn closest_hits(&self, rays: &[NullRay], tmin: f64, out: &mut [Option<SurfaceHit>]) {
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
                    meta.push((i, rr.shift, rr.s));
                }
            }
            if batch.is_empty() {
                continue;
            }
            g.accel.intersect(&batch, &mut hits[..batch.len()]);
            for (k, h) in hits[..batch.len()].iter().enumerate() {
                if let Some(h) = h {
                    let (i, shift, s) = meta[k];
                    let lambda = shift + h.t;
                    if lambda < best[i] {
                        best[i] = lambda;
                        let r = &batch[k];
                        out[i] = Some(SurfaceHit {
                            group: gi,
                            prim: h.prim,
                            lambda,
                            point: r.origin + h.t * r.dir,
                            dir: r.dir,
                            s,
                        });
                    }
                }
            }
        }
    }

    /// The visible hit on one ray (secondary rays), without the batch's bookkeeping.
    pub fn closest_hit(&self, ray: &NullRay, tmin: f64) -> Option<SurfaceHit> {
        let mut best: Option<SurfaceHit> = None;
        let mut hit = [None];
        for (gi, g) in self.groups.iter().enumerate() {
            let tmax = best.map_or(f64::INFINITY, |b| b.lambda);
            let Some(rr) = self.rest_ray(g, ray, tmin, tmax) else {
                continue;
            };
            g.accel.intersect(std::slice::from_ref(&rr.ray), &mut hit);
            if let Some(h) = hit[0] {
                let lambda = rr.shift + h.t;
                if lambda < tmax {
                    best = Some(SurfaceHit {
                        group: gi,
                        prim: h.prim,
                        lambda,
                        point: rr.ray.origin + h.t * rr.ray.dir,
                        dir: rr.ray.dir,
                        s: rr.s,
                    });
                }
            }
        }
        best
    }

    /// Whether anything lies on the ray between lookback `tmin` and `tmax`.
    pub fn occluded(&self, ray: &NullRay, tmin: f64, tmax: f64) -> bool {
        let mut o = [false];
        self.groups
            .iter()
            .any(|g| match self.rest_ray(g, ray, tmin, tmax) {
                Some(rr) => {
                    g.accel.occluded(std::slice::from_ref(&rr.ray), &mut o);
                    o[0]
                }
                None => false,
            })
    }
}
