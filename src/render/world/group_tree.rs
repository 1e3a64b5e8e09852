//! A culling structure over many velocity groups, so that a ray does not loop over all of them.
//!
//! Each node bounds its groups in the world frame by a box at a reference time T and per-axis
//! velocity bounds [v_lo, v_hi]: at time t the groups lie within
//! `[lo + min(v_lo·dt, v_hi·dt), hi + max(v_lo·dt, v_hi·dt)]`, dt = t − T. A past null ray
//! `x(λ) = x_H + λ a, t = t_H − λ` meets those bounds on an interval of λ found by two slab
//! tests, one for λ ≤ t_H − T (with directions a + v_lo, a + v_hi) and one beyond: each bound is
//! linear in λ on either side. For one group (v_lo = v_hi) this is the exact Galilean test of the
//! ray against the group's moving, Lorentz-contracted box. It holds for any past null ray —
//! primary, reflected or shadow — with no assumption about when it starts.

use crate::geometry::{walk, Aabb, BoxTree};
use crate::spacetime::{NullRay, Velocity};
use glam::DVec3;

#[derive(Clone, Copy, Debug)]
struct KineticNode {
    lo: DVec3,
    hi: DVec3,
    vlo: DVec3,
    vhi: DVec3,
    first: u32,
    count: u32,
}

pub struct GroupTree {
    nodes: Vec<KineticNode>,
    /// For a tree that serves only times within `t_ref ± half_span` (an inner slice), each
    /// node's bounds over that whole span: a static box, tested first because a ray meets a
    /// static box far more cheaply than moving bounds.
    swept: Option<Vec<Aabb>>,
    indices: Vec<u32>,
    t_ref: f64,
}

/// Kinetic trees at several reference times: a ray is cut at the midpoints between them and
/// each piece asks the tree nearest in time, so a node's bounds grow by at most v_max times
/// half the slice spacing (plus the ends, beyond which the outermost trees serve). The inner
/// trees test each node's static box over their span first (a plain slab test, a fraction of
/// the cost of the moving bounds', which it spares most nodes a ray does not meet).
pub struct SlicedGroupTree {
    slices: Vec<GroupTree>,
}

impl SlicedGroupTree {
    /// `count` reference times spread evenly over [t_first, t_last].
    pub fn build(
        groups: &[(Aabb, Velocity)],
        t_first: f64,
        t_last: f64,
        count: usize,
    ) -> SlicedGroupTree {
        let count = count.max(1);
        // One SAH build per slice: groups that are neighbours at one time drift apart at
        // another, so a shared topology (refitted) overlaps badly and rays visit most of it.
        use rayon::prelude::*;
        let slices = (0..count)
            .into_par_iter()
            .map(|k| {
                let f = if count == 1 {
                    0.5
                } else {
                    k as f64 / (count - 1) as f64
                };
                let t_ref = t_first + f * (t_last - t_first);
                // The outermost slices also serve every time beyond the window.
                let inner = k > 0 && k + 1 < count;
                let half_span = 0.5 * (t_last - t_first) / (count - 1).max(1) as f64;
                GroupTree::build_for(groups, t_ref, inner.then_some(half_span))
            })
            .collect();
        SlicedGroupTree { slices }
    }

    /// As [`GroupTree::traverse`], piece by piece along the ray (later times first); a group
    /// met in several pieces may be visited more than once.
    pub fn traverse(
        &self,
        ray: &NullRay,
        tmin: f64,
        tmax: f64,
        mut visit: impl FnMut(u32, f64) -> f64,
    ) {
        let mut tmax = tmax;
        let n = self.slices.len();
        for (k, tree) in self.slices.iter().enumerate().rev() {
            // Times closer to this slice's reference than to its neighbours' (λ = t_H − t).
            let t_hi = if k + 1 < n {
                0.5 * (tree.t_ref + self.slices[k + 1].t_ref)
            } else {
                f64::INFINITY
            };
            let t_lo = if k > 0 {
                0.5 * (tree.t_ref + self.slices[k - 1].t_ref)
            } else {
                f64::NEG_INFINITY
            };
            let lo = tmin.max(ray.origin.t - t_hi);
            let hi = tmax.min(ray.origin.t - t_lo);
            if lo > hi {
                continue;
            }
            let mut stop = false;
            tree.traverse(ray, lo, hi, |g, _| {
                // Groups are searched over the whole ray, so pass the best hit so far.
                let new = visit(g, tmax);
                stop |= new < tmin;
                tmax = tmax.min(new);
                new
            });
            if stop || tmax < tmin {
                return;
            }
        }
    }
}

/// The world-frame box at world time `t` of rest-frame bounds moving at `v` (whose rest-frame
/// origin passes the world origin at t = 0): the corners contracted along v, then carried.
pub(crate) fn world_box(rest: &Aabb, v: &Velocity, t: f64) -> Aabb {
    // Per group, not per corner: the speed is a tanh and γ a cosh of the rapidity. The
    // contraction 1/γ − 1 = −(γ − 1)/γ, exact at small speeds (docs/physics.md §8.1).
    let (dir, shift) = (v.direction(), v.beta_vec() * t);
    let shrink = -v.gamma_minus_one() / v.gamma();
    let mut b = Aabb::EMPTY;
    for p in rest.corners() {
        b.grow(p + shrink * p.dot(dir) * dir + shift);
    }
    b
}

/// Where `c + λ k ≥ 0` holds, intersected into [t0, t1].
#[inline]
fn half(c: f64, k: f64, t0: &mut f64, t1: &mut f64) {
    if k > 0.0 {
        *t0 = t0.max(-c / k);
    } else if k < 0.0 {
        *t1 = t1.min(-c / k);
    } else if c < 0.0 {
        *t1 = f64::NEG_INFINITY;
    }
}

impl GroupTree {
    /// `groups`: each group's rest-frame bounds and velocity; `t_ref`: the reference time
    /// (the view time keeps the numbers small near the imaging event).
    #[cfg(test)]
    pub fn build(groups: &[(Aabb, Velocity)], t_ref: f64) -> GroupTree {
        Self::build_for(groups, t_ref, None)
    }

    /// As [`GroupTree::build`], for a tree that will only be asked about times within
    /// `half_span` of `t_ref`, if given.
    pub fn build_for(groups: &[(Aabb, Velocity)], t_ref: f64, half_span: Option<f64>) -> GroupTree {
        let boxes: Vec<Aabb> = groups.iter().map(|(b, v)| world_box(b, v, t_ref)).collect();
        let mut tree = Self::refit(&BoxTree::build(&boxes), groups, t_ref);
        tree.swept = half_span.map(|h| {
            // A node's bounds at t_ref ± h hold it at every time between (each moves linearly).
            let pad = 1e-9 * (h + 1.0);
            tree.nodes
                .iter()
                .map(|n| {
                    let (a, b) = (n.vlo * h, n.vhi * h);
                    let lo = n.lo + a.min(-a).min(b.min(-b));
                    let hi = n.hi + a.max(-a).max(b.max(-b));
                    Aabb::new(lo - DVec3::splat(pad), hi + DVec3::splat(pad))
                })
                .collect()
        });
        tree
    }

    /// Kinetic bounds at `t_ref` over the topology of `tree`.
    fn refit(tree: &BoxTree, groups: &[(Aabb, Velocity)], t_ref: f64) -> GroupTree {
        let mut nodes: Vec<KineticNode> = tree
            .nodes
            .iter()
            .map(|n| KineticNode {
                lo: DVec3::splat(f64::INFINITY),
                hi: DVec3::splat(f64::NEG_INFINITY),
                vlo: DVec3::splat(f64::INFINITY),
                vhi: DVec3::splat(f64::NEG_INFINITY),
                first: n.first,
                count: n.count,
            })
            .collect();
        // Children come after their parents: fill bounds from the leaves up.
        for i in (0..nodes.len()).rev() {
            let n = nodes[i];
            if n.count > 0 {
                for &g in &tree.indices[n.first as usize..(n.first + n.count) as usize] {
                    let (b, v) = &groups[g as usize];
                    let w = world_box(b, v, t_ref);
                    let v = v.beta_vec();
                    let node = &mut nodes[i];
                    node.lo = node.lo.min(w.min);
                    node.hi = node.hi.max(w.max);
                    node.vlo = node.vlo.min(v);
                    node.vhi = node.vhi.max(v);
                }
            } else {
                let (l, r) = (nodes[n.first as usize], nodes[n.first as usize + 1]);
                let node = &mut nodes[i];
                node.lo = l.lo.min(r.lo);
                node.hi = l.hi.max(r.hi);
                node.vlo = l.vlo.min(r.vlo);
                node.vhi = l.vhi.max(r.vhi);
            }
        }
        GroupTree {
            nodes,
            swept: None,
            indices: tree.indices.clone(),
            t_ref,
        }
    }

    /// The first λ in (tmin, tmax) at which the ray may be inside the node's bounds.
    #[inline]
    fn entry(&self, n: &KineticNode, ray: &NullRay, tmin: f64, tmax: f64) -> Option<f64> {
        let tau = ray.origin.t - self.t_ref;
        let (x, a) = (ray.origin.x, ray.dir);
        // Segment A: λ ≤ τ (t ≥ T), lower bounds move at v_lo, upper at v_hi; segment B the
        // other way round.
        let mut best: Option<f64> = None;
        for (seg0, seg1, vl, vh) in [
            (tmin, tmax.min(tau), n.vlo, n.vhi),
            (tmin.max(tau), tmax, n.vhi, n.vlo),
        ] {
            let (mut t0, mut t1) = (seg0, seg1);
            if t0 > t1 {
                continue;
            }
            for i in 0..3 {
                half(x[i] - n.lo[i] - vl[i] * tau, a[i] + vl[i], &mut t0, &mut t1);
                half(
                    -(x[i] - n.hi[i] - vh[i] * tau),
                    -(a[i] + vh[i]),
                    &mut t0,
                    &mut t1,
                );
            }
            if t0 <= t1 {
                best = Some(best.map_or(t0, |b: f64| b.min(t0)));
            }
        }
        best
    }

    /// Visit the groups the ray may meet in (tmin, tmax), nearer subtrees first. `visit(group,
    /// tmax)` returns the new tmax (the best hit so far); a tmax below tmin stops the walk.
    pub fn traverse(
        &self,
        ray: &NullRay,
        tmin: f64,
        tmax: f64,
        visit: impl FnMut(u32, f64) -> f64,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let nodes = &self.nodes;
        let inv = ray.dir.recip();
        walk(
            &self.indices,
            |i| (nodes[i as usize].first, nodes[i as usize].count),
            |i, tmax| {
                if let Some(swept) = &self.swept {
                    swept[i as usize].clip(ray.origin.x, inv, tmin, tmax)?;
                }
                self.entry(&nodes[i as usize], ray, tmin, tmax)
            },
            tmin,
            tmax,
            visit,
        );
    }
}
