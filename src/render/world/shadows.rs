//! Shadow rays: whether anything lies between a point and a light, one ray at a time or many
//! (packets per group with few groups; the light trees and the kinetic trees with many).

use super::{World, INACTIVE};
use crate::geometry::PACKET;
use crate::spacetime::NullRay;

impl World {
    /// [`World::occluded`] for many rays (lookback from 0 to `tmax[i]`) at once: with few
    /// groups they go to each group's backend together (packets), as primary rays do.
    pub fn occluded_many(&self, rays: &[NullRay], tmax: &[f64], out: &mut [bool]) {
        self.occluded_many_as(rays, tmax, out, false);
    }

    /// [`World::occluded_many`] for rays from anywhere toward anywhere (the shadow rays of a
    /// bounce of many paths): in packets traced as scattered rays.
    pub fn occluded_scattered(&self, rays: &[NullRay], tmax: &[f64], out: &mut [bool]) {
        self.occluded_many_as(rays, tmax, out, true);
    }

    fn occluded_many_as(&self, rays: &[NullRay], tmax: &[f64], out: &mut [bool], scattered: bool) {
        if self.tree.is_some() {
            for ((r, &t), o) in rays.iter().zip(tmax).zip(out.iter_mut()) {
                *o = self.occluded(r, 0.0, t);
            }
            return;
        }
        if let Some(at_rest) = &self.at_rest {
            return at_rest.occluded(rays, tmax, out);
        }
        const CHUNK: usize = PACKET;
        // Made once for every chunk: each chunk writes the lanes it reads.
        let mut batch = [INACTIVE; CHUNK];
        let mut hit = [false; CHUNK];
        for ((rays, tmax), out) in rays
            .chunks(CHUNK)
            .zip(tmax.chunks(CHUNK))
            .zip(out.chunks_mut(CHUNK))
        {
            let n = rays.len();
            out.iter_mut().for_each(|o| *o = false);
            for g in &self.groups {
                // Rays already in shadow stay out (masked) of the other groups' packets.
                let mut any = false;
                for i in 0..n {
                    batch[i] = match out[i] {
                        true => INACTIVE,
                        false => self
                            .rest_ray(g, &rays[i], 0.0, tmax[i])
                            .map_or(INACTIVE, |rr| rr.ray),
                    };
                    any |= batch[i].is_active();
                }
                if !any {
                    continue;
                }
                g.occluded_as(&batch[..n], &mut hit[..n], scattered);
                for i in 0..n {
                    out[i] |= batch[i].is_active() && hit[i];
                }
            }
        }
    }

    /// Whether group gi has anything on the ray between lookback `tmin` and `tmax`.
    fn group_blocks(&self, gi: usize, ray: &NullRay, tmin: f64, tmax: f64) -> bool {
        let g = &self.groups[gi];
        self.may_meet(g, ray, tmin, tmax)
            && self
                .rest_ray(g, ray, tmin, tmax)
                .is_some_and(|rr| g.occluded1(&rr.ray))
    }

    /// Whether the shadow ray toward scene light `light` is blocked before lookback `tmax`.
    pub fn shadowed(&self, light: usize, ray: &NullRay, tmax: f64) -> bool {
        if let Some(Some(lt)) = self.light_trees.get(light) {
            let found = lt.occluded(ray, 0.0, tmax, |gi| {
                self.group_blocks(gi as usize, ray, 0.0, tmax)
            });
            if let Some(found) = found {
                return found;
            }
        }
        self.occluded(ray, 0.0, tmax)
    }

    /// [`World::shadowed`] for many rays toward one light (lookback from 0 to `tmax[i]`): with
    /// a light tree, in packets per slice of emission times (`buffers` kept by the caller
    /// from one call to the next).
    pub fn shadowed_many(
        &self,
        light: usize,
        (rays, tmax): (&[NullRay], &[f64]),
        out: &mut [bool],
        buffers: &mut ShadowBuffers,
    ) {
        let Some(Some(lt)) = self.light_trees.get(light) else {
            return self.occluded_many(rays, tmax, out);
        };
        let ShadowBuffers { served, order } = buffers;
        served.clear();
        served.resize(rays.len(), false);
        out.iter_mut().for_each(|o| *o = false);
        lt.occluded_many(rays, tmax, (served, order), out, |gi, i| {
            self.group_blocks(gi as usize, &rays[i], 0.0, tmax[i])
        });
        for (i, o) in out.iter_mut().enumerate() {
            if !served[i] {
                *o = self.occluded(&rays[i], 0.0, tmax[i]);
            }
        }
    }

    /// Whether anything lies on the ray between lookback `tmin` and `tmax`.
    pub fn occluded(&self, ray: &NullRay, tmin: f64, tmax: f64) -> bool {
        let test = |gi: usize| self.group_blocks(gi, ray, tmin, tmax);
        match &self.tree {
            Some(tree) => {
                let mut found = false;
                tree.get().traverse(ray, tmin, tmax, |g, t| {
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

/// What [`World::shadowed_many`] works in: which rays a light tree served, and the rays by
/// slice of emission times.
#[derive(Default)]
pub(crate) struct ShadowBuffers {
    served: Vec<bool>,
    order: Vec<(usize, usize, f64)>,
}
