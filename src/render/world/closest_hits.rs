//! Closest hits: the visible hit on each ray over all groups, the one whose emission event is
//! latest (smallest lookback): in packets per group with few groups, through the group trees
//! with many, and straight through every group at once where the world is wholly at rest
//! (`direct::AtRest`).

use super::moving_bounds::RaySpan;
use super::{hit_on, ApparentTree, RestRay, SurfaceHit, World, WorldGroup, INACTIVE};
use crate::accel::{Hit, Ray};
use crate::geometry::PACKET;
use crate::spacetime::NullRay;
use glam::DVec3;

impl World {
    /// The visible hit on each ray: the one with the smallest world-frame lookback time (the
    /// latest emission event) over all groups, in `(tmin, tmax)` of lookback. With few groups
    /// the rays go to each group's backend together (packets); with many, one by one through
    /// the group tree.
    pub fn closest_hits(&self, rays: &[NullRay], tmin: f64, out: &mut [Option<SurfaceHit>]) {
        if let Some(p) = &self.primary_tree {
            if rays.iter().all(|r| p.serves(r)) {
                self.closest_hits_packets(p, rays, tmin, out);
                return;
            }
        }
        self.closest_hits_as(rays, tmin, out, false);
    }

    /// [`World::closest_hits`] of rays from anywhere (a bounce of many paths), in lookback
    /// (0, ∞): in packets where the backend's measure says they pay for rays that share
    /// neither origin nor direction, else one by one.
    pub fn closest_hits_scattered(&self, rays: &[NullRay], out: &mut [Option<SurfaceHit>]) {
        self.closest_hits_as(rays, 0.0, out, true);
    }

    fn closest_hits_as(
        &self,
        rays: &[NullRay],
        tmin: f64,
        out: &mut [Option<SurfaceHit>],
        scattered: bool,
    ) {
        if self.tree.is_some() {
            for (r, o) in rays.iter().zip(out.iter_mut()) {
                *o = self.closest_hit(r, tmin);
            }
            return;
        }
        if let Some(at_rest) = &self.at_rest {
            return at_rest.closest_hits(rays, tmin, out);
        }
        // A packet's worth of rays at a time, through every group, on the stack.
        const CHUNK: usize = PACKET;
        // Made once for every chunk: each chunk writes the lanes it reads.
        let mut batch = [INACTIVE; CHUNK];
        // Each lane's shift and lookback factor (valid where the lane is active); kept
        // apart from the rays so the rays go into the batch straight from registers.
        let mut shift = [0.0; CHUNK];
        let mut factor = [0.0; CHUNK];
        let mut hits: [Option<Hit>; CHUNK] = [None; CHUNK];
        // Each lane's lookbacks in the group's window, where it has any.
        let mut within: [Option<(f64, f64)>; CHUNK] = [None; CHUNK];
        for (rays, out) in rays.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
            let n = rays.len();
            let mut best = [f64::INFINITY; CHUNK];
            out.iter_mut().for_each(|o| *o = None);
            // What the chunk's rays span, for the groups' test in the world frame.
            let span = self.clip_rays.then(|| RaySpan::of(rays));
            // Whether a lane found a hit since the groups left were last looked at.
            let mut found = false;
            for (k, gi) in self.visiting_order().enumerate() {
                // Every lane's hit lies before any emission the groups left can show: none
                // of them can give any lane lookbacks (`in_window` gives every lane None,
                // since lo ≥ t − latest ≥ best ≥ hi), so they are passed over at once (a
                // worldline's segments, once a chunk has met the later ones).
                if std::mem::take(&mut found)
                    && self.latest.get(k).is_some_and(|&latest| {
                        rays.iter()
                            .zip(&best)
                            .all(|(r, &b)| b <= r.origin.t - latest)
                    })
                {
                    break;
                }
                let g = &self.groups[gi];
                // The lookbacks each ray may still meet the group at, and their hull.
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for (i, r) in rays.iter().enumerate() {
                    within[i] = Self::in_window(g, r, tmin, best[i]);
                    // Plain comparisons: `in_window` gives no NaN.
                    if let Some((a, b)) = within[i] {
                        if a < lo {
                            lo = a;
                        }
                        if b > hi {
                            hi = b;
                        }
                    }
                }
                if lo > hi {
                    continue;
                }
                // A chunk that cannot meet where the group moves skips its boosts (a
                // worldline's segments: most chunks meet few of their windows there). The
                // bounds move as the ray-by-ray test (`may_meet`) has them for every group.
                if let Some(span) = &span {
                    if !g.moving.may_meet_any(span, lo, hi) {
                        continue;
                    }
                }
                // Every ray keeps its lane, so a packet stays a square of neighbouring pixels;
                // a ray that misses the group's bounds is masked (inactive), not removed.
                let mut any = false;
                for (i, r) in rays.iter().enumerate() {
                    let rest = within[i].and_then(|(a, b)| self.rest_ray_within(g, r, a, b));
                    match rest {
                        Some(rr) => {
                            batch[i] = rr.ray;
                            shift[i] = rr.shift;
                            factor[i] = rr.s;
                            any = true;
                        }
                        None => batch[i] = INACTIVE,
                    }
                }
                if !any {
                    continue;
                }
                g.intersect_as(&batch[..n], &mut hits[..n], scattered);
                // A group that neither accelerates nor spins: each hit is where its rest ray
                // meets the surface (`surface_hit`, and `spun` leaves it), made here.
                let plain = g.accelerated.is_none() && !g.spins;
                for i in 0..n {
                    // Backends report no hit on inactive rays.
                    let Some(h) = hits[i] else {
                        continue;
                    };
                    let hit = if plain {
                        hit_on(gi, &batch[i], shift[i], factor[i], h)
                    } else {
                        let rr = RestRay {
                            ray: batch[i],
                            shift: shift[i],
                            s: factor[i],
                        };
                        self.spun(self.surface_hit(gi, &rr, h))
                    };
                    if hit.lambda < best[i] {
                        best[i] = hit.lambda;
                        out[i] = Some(hit);
                        found = true;
                    }
                }
            }
        }
    }

    /// Primary rays among many groups: packets through the apparent tree.
    fn closest_hits_packets(
        &self,
        tree: &ApparentTree,
        rays: &[NullRay],
        tmin: f64,
        out: &mut [Option<SurfaceHit>],
    ) {
        for (rs, os) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
            let mut dirs = [DVec3::ZERO; PACKET];
            for (d, r) in dirs.iter_mut().zip(rs) {
                *d = r.dir;
            }
            let mut tmax = [f64::INFINITY; PACKET];
            os.iter_mut().for_each(|o| *o = None);
            tree.traverse_packet(
                &dirs[..rs.len()],
                tmin,
                &mut tmax[..rs.len()],
                |gi, i, t| match self.hit_before(gi as usize, &rs[i], tmin, t) {
                    Some(sh) => {
                        os[i] = Some(sh);
                        sh.lambda
                    }
                    None => t,
                },
            );
        }
    }

    /// Group gi's hit on the ray in lookback (tmin, tmax), if it has one.
    #[inline(always)]
    fn hit_before(&self, gi: usize, ray: &NullRay, tmin: f64, tmax: f64) -> Option<SurfaceHit> {
        let g = &self.groups[gi];
        if !self.may_meet(g, ray, tmin, tmax) {
            return None;
        }
        let rr = self.rest_ray(g, ray, tmin, tmax)?;
        let sh = self.spun(self.surface_hit(gi, &rr, g.intersect1(&rr.ray)?));
        (sh.lambda < tmax).then_some(sh)
    }

    /// The first surface of group `gi` on the rest-frame ray `origin + t dir` (unit `dir`,
    /// t > 0), searched in that group alone: the primitive and t (the rest-frame distance).
    pub fn hit_in_group(&self, gi: usize, origin: DVec3, dir: DVec3) -> Option<(u32, f64)> {
        let g = &self.groups[gi];
        let (t0, _) = g.bounds.clip(origin, dir.recip(), 0.0, f64::INFINITY)?;
        // From where the ray enters the bounds, so the backend sees small coordinates.
        let start = t0.max(0.0);
        let ray = Ray::new(origin + start * dir, dir, 0.0, f64::INFINITY);
        g.intersect1(&ray).map(|h| (h.prim, start + h.t))
    }

    /// The visible hit on one ray (secondary rays, and every ray when there are many groups).
    pub fn closest_hit(&self, ray: &NullRay, tmin: f64) -> Option<SurfaceHit> {
        let mut best: Option<SurfaceHit> = None;
        let mut visit = |gi: usize, tmax: f64| -> f64 {
            match self.hit_before(gi, ray, tmin, tmax) {
                Some(sh) => {
                    best = Some(sh);
                    sh.lambda
                }
                None => tmax,
            }
        };
        match (&self.primary_tree, &self.tree) {
            (Some(p), _) if p.serves(ray) => {
                p.traverse(ray, tmin, f64::INFINITY, |g, tmax| visit(g as usize, tmax))
            }
            (_, Some(tree)) => tree
                .get()
                .traverse(ray, tmin, f64::INFINITY, |g, tmax| visit(g as usize, tmax)),
            _ => {
                let mut tmax = f64::INFINITY;
                for gi in self.visiting_order() {
                    tmax = visit(gi, tmax);
                }
            }
        }
        best
    }

    /// The order in which closest hits visit the groups without a tree (`latest_first`). On a
    /// tie of lookbacks between two groups, to rounding, the one visited first keeps the hit
    /// (a later one must come out closer in its own frame and then in lookback). `AtRest`
    /// visits its groups first to last: a world with windows is never wholly at rest.
    fn visiting_order(&self) -> impl Iterator<Item = usize> {
        let n = self.groups.len();
        let later = self.latest_first;
        (0..n).map(move |k| if later { n - 1 - k } else { k })
    }
}

/// For each place in a visiting order of `groups` (given in that order), the latest world
/// time at which the groups from there on can emit what a ray meets: the end of their windows
/// of world times, or +∞ where any has none (a group seen at all times, or a window in a
/// moving frame).
pub(super) fn latest_emissions<'a>(
    groups: impl DoubleEndedIterator<Item = &'a WorldGroup>,
) -> Box<[f64]> {
    let mut latest: Vec<f64> = groups
        .rev()
        .scan(f64::NEG_INFINITY, |later, g| {
            let to = match (g.world_window, &g.window) {
                (Some((_, to)), _) if !to.is_nan() => to,
                _ => f64::INFINITY,
            };
            *later = later.max(to);
            Some(*later)
        })
        .collect();
    latest.reverse();
    latest.into()
}
