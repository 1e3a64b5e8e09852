//! Culling for shadow rays among many groups.
//!
//! A shadow ray toward a light at rest (world frame) at L ends at its emission event (t_e, L):
//! read forward, its spatial track is light going out from L, on the future light cone of
//! (t_e, L). A group can meet the ray only where that cone meets the group's worldtube: at the
//! points x with x − v|x − L| ∈ B(t_e), B(t) the group's world-frame box at time t, moving at v.
//! Time reversed, that is the apparent shape of docs/physics.md §2.1 seen from L by a body moving at
//! −v, so [`apparent_box_along`] bounds it; and for emission times in a slice [t_a, t_b] the points
//! obey x − v|x − L| ∈ B(t_a) ∪ … ∪ B(t_b), inside the box around B(t_a) and B(t_b). So a static
//! culling structure per slice of emission times holds every group's reachable shape, and a shadow
//! ray tests only the slice of its own emission time, with plain slab tests along its track (the
//! kinetic trees cut a ray into pieces by time and test moving bounds in each).
//!
//! Slices are made on first use, so only the emission times a frame's shadow rays have cost
//! anything. A run of consecutive slices holds only the groups the imaging event's causal past
//! can reach (every shading point lies in it, so a ray that left L at t_e stays in the ellipsoid
//! |x − L| + |x − E| ≤ t_E − t_e), and shares one structure built at its middle slice, refitted
//! to each other slice's boxes where the structure can be (the f64 box tree), else built anew.
//! Read backwards, a slice's rays all start at L: the renderer's structure is a light buffer
//! around L (geometry/light_buffer.rs), and a tile's shadow rays of one slice go in together.

use super::apparent_tree::apparent_box_along;
use super::group_tree::world_box;
use crate::accel::{BoxCuller, CullerFactory};
use crate::geometry::{Aabb, PACKET};
use crate::spacetime::{Event, NullRay, Velocity};
use glam::DVec3;
use std::sync::{Arc, OnceLock};

/// Consecutive slices that share one tree shape.
const SLICES_PER_SHAPE: usize = 8;

pub struct LightTree {
    light: DVec3,
    /// The imaging event: every shading point lies in its causal past.
    event: Event,
    t_first: f64,
    width: f64,
    groups: Arc<[(Aabb, Velocity)]>,
    cullers: CullerFactory,
    motions: OnceLock<Vec<Motion>>,
    shapes: Vec<OnceLock<crate::Result<Shape>>>,
    slices: Vec<OnceLock<crate::Result<Box<dyn BoxCuller>>>>,
}

/// A run of slices' tree (at its middle slice), over the groups (`members`) the run's rays can
/// reach: the other slices refit it where the backend's structure can be refitted.
struct Shape {
    members: Vec<u32>,
    tree: Box<dyn BoxCuller>,
}

/// A group's motion, worked out once for the many slices: its world-frame box at time 0, and
/// its velocity as direction, β, γ and β·direction.
struct Motion {
    at_zero: Aabb,
    u: DVec3,
    beta: f64,
    gamma: f64,
    velocity: DVec3,
}

impl Motion {
    fn new(rest: &Aabb, v: &Velocity) -> Motion {
        Motion {
            at_zero: world_box(rest, v, 0.0),
            u: v.direction(),
            beta: v.beta(),
            gamma: v.gamma(),
            velocity: v.beta_vec(),
        }
    }

    /// The box holding every point where the group can meet light that left `light` at a
    /// time in [t_a, t_b].
    fn reach_box(&self, light: DVec3, t_a: f64, t_b: f64) -> Aabb {
        let (a, b) = (self.velocity * t_a, self.velocity * t_b);
        let swept = Aabb::new(self.at_zero.min + a.min(b), self.at_zero.max + a.max(b));
        if self.beta == 0.0 {
            return swept;
        }
        apparent_box_along(&swept, -self.u, self.beta, self.gamma, light)
    }
}

/// The box holding every point where a group (rest-frame bounds `rest`, velocity `v`) can meet
/// light that left `light` at a time in [t_a, t_b] (what the tests check the light tree by).
#[cfg(test)]
pub(crate) fn reach_box(rest: &Aabb, v: &Velocity, light: DVec3, t_a: f64, t_b: f64) -> Aabb {
    Motion::new(rest, v).reach_box(light, t_a, t_b)
}

/// From this many groups on, a slice's boxes are worked out on every thread.
const PIECES_FROM: usize = 1024;

/// `piece` of the runs of 0..n, joined in order: for long runs on every thread, one run each.
///
/// Plain scoped threads, not rayon's: this runs inside a slice's first use (a `OnceLock`),
/// where the other workers wait for it (so their cores are free) and where a rayon worker,
/// waiting on its own jobs, could take up a tile that waits on this very slice.
fn in_pieces<T: Send>(n: usize, piece: impl Fn(std::ops::Range<usize>) -> Vec<T> + Sync) -> Vec<T> {
    let threads = rayon::current_num_threads().min(n / PIECES_FROM).max(1);
    if threads == 1 {
        return piece(0..n);
    }
    let run = |i: usize| i * n / threads..(i + 1) * n / threads;
    let piece = &piece;
    std::thread::scope(|scope| {
        let others: Vec<_> = (1..threads)
            .map(|i| scope.spawn(move || piece(run(i))))
            .collect();
        let mut all = piece(run(0));
        for other in others {
            all.extend(
                other
                    .join()
                    .unwrap_or_else(|p| std::panic::resume_unwind(p)),
            );
        }
        all
    })
}

impl LightTree {
    /// For the light at rest at `light`: `count` slices of emission times covering
    /// [t_first, t_last].
    pub fn new(
        groups: Arc<[(Aabb, Velocity)]>,
        cullers: CullerFactory,
        light: DVec3,
        event: Event,
        t_first: f64,
        t_last: f64,
        count: usize,
    ) -> LightTree {
        let count = count.max(1);
        LightTree {
            light,
            event,
            t_first,
            width: (t_last - t_first) / count as f64,
            groups,
            cullers,
            motions: OnceLock::new(),
            shapes: (0..count.div_ceil(SLICES_PER_SHAPE))
                .map(|_| OnceLock::new())
                .collect(),
            slices: (0..count).map(|_| OnceLock::new()).collect(),
        }
    }

    /// Rounding slack: in emission times, and in how far outside the imaging event's causal past
    /// a shading point may lie (a shadow ray starts a hair off its surface).
    fn slack(&self) -> f64 {
        1e-6 * (1.0
            + self.event.t.abs()
            + self.event.x.abs().max_element()
            + (self.event.t - self.t_first).abs()
            + (self.light - self.event.x).length())
    }

    /// Group g's reach box for emission times in [t_a, t_b], a little wider for rounding in the
    /// emission times the rays are given.
    fn reach(&self, t_a: f64, t_b: f64) -> impl Fn(u32) -> Aabb + '_ {
        let pad = self.slack();
        let motions = self.motions.get_or_init(|| {
            in_pieces(self.groups.len(), |run| {
                run.map(|g| Motion::new(&self.groups[g].0, &self.groups[g].1))
                    .collect()
            })
        });
        // Also padded in space: packets walk the rays backwards from the light, which the
        // rays reach only to within rounding.
        move |g| {
            let b = motions[g as usize].reach_box(self.light, t_a - pad, t_b + pad);
            Aabb::new(b.min - DVec3::splat(pad), b.max + DVec3::splat(pad))
        }
    }

    /// The reach boxes of `members` for emission times in `(t_a, t_b)`, in their order.
    fn boxes(&self, members: &[u32], (t_a, t_b): (f64, f64)) -> Vec<Aabb> {
        let reach = self.reach(t_a, t_b);
        in_pieces(members.len(), |run| {
            run.map(|i| reach(members[i])).collect()
        })
    }

    /// Slice k's emission times.
    fn span(&self, k: usize) -> (f64, f64) {
        let t_a = self.t_first + k as f64 * self.width;
        (t_a, t_a + self.width)
    }

    /// The box around everything a shadow ray that left the light at t_e or later can pass:
    /// its points x (at time t) lie in the imaging event's causal past, and t = t_e + |x − L|,
    /// so |x − L| + |x − E| ≤ t_E − t_e: an ellipsoid with foci L and E. None when empty.
    fn causal_box(&self, t_e: f64) -> Option<Aabb> {
        let sum = self.event.t - t_e + 2.0 * self.slack();
        let axis = self.event.x - self.light;
        let focal = axis.length();
        if sum < focal {
            return None;
        }
        let (a, c) = (0.5 * sum, 0.5 * focal);
        // a ≥ c: (a − c)(a + c) keeps b² exact where the ellipsoid is thin (a ≈ c).
        let b2 = ((a - c) * (a + c)).max(0.0);
        let f = if focal > 0.0 {
            axis / focal
        } else {
            DVec3::ZERO
        };
        let half = (a * a * f * f + b2 * (DVec3::ONE - f * f)).map(f64::sqrt);
        let centre = 0.5 * (self.light + self.event.x);
        Some(Aabb::new(centre - half, centre + half))
    }

    /// Slice k's culling structure and the groups its items are: the build of its run of
    /// slices (at the run's middle slice, over the groups the run's rays can reach), refitted to
    /// slice k's boxes where the backend's structure allows, else built anew.
    fn slice(&self, k: usize) -> crate::Result<(&dyn BoxCuller, &[u32])> {
        let s = k / SLICES_PER_SHAPE;
        let first = s * SLICES_PER_SHAPE;
        let last = (first + SLICES_PER_SHAPE).min(self.slices.len()) - 1;
        let middle = (first + SLICES_PER_SHAPE / 2).min(last);
        let shape = self.shapes[s]
            .get_or_init(|| {
                let members: Vec<u32> = match self.causal_box(self.span(first).0) {
                    Some(region) => {
                        let whole = self.reach(self.span(first).0, self.span(last).1);
                        in_pieces(self.groups.len(), |run| {
                            run.map(|g| g as u32)
                                .filter(|&g| whole(g).overlaps(&region))
                                .collect()
                        })
                    }
                    None => Vec::new(),
                };
                let boxes = self.boxes(&members, self.span(middle));
                Ok(Shape {
                    tree: (self.cullers)(&boxes)?,
                    members,
                })
            })
            .as_ref()
            .map_err(|e| e.clone())?;
        if k == middle {
            return Ok((shape.tree.as_ref(), &shape.members));
        }
        let tree = self.slices[k]
            .get_or_init(|| {
                let boxes = self.boxes(&shape.members, self.span(k));
                match shape.tree.refitted(&mut |i: u32| boxes[i as usize]) {
                    Some(t) => Ok(t),
                    None => (self.cullers)(&boxes),
                }
            })
            .as_ref()
            .map_err(|e| e.clone())?;
        Ok((tree.as_ref(), &shape.members))
    }

    /// The slice a shadow ray left the light in and its lookback to the light (= distance, the
    /// light being at rest), if this tree serves the ray: it heads for this light, does not
    /// pass it before tmax, left it within the slices, and starts in the imaging event's causal
    /// past (as every shading point does).
    fn serves(&self, ray: &NullRay, tmax: f64) -> Option<(usize, f64)> {
        let reach = (self.light - ray.origin.x).length();
        let end = ray.at(reach);
        let miss = (end.x - self.light).length();
        let scale = reach + self.light.abs().max_element() + 1.0;
        if !(miss <= 1e-9 * scale && tmax <= reach) {
            return None;
        }
        let k = ((end.t - self.t_first) / self.width).floor();
        if !(k >= 0.0 && k < self.slices.len() as f64) {
            return None;
        }
        let o = ray.origin;
        if (o.x - self.event.x).length() > self.event.t - o.t + self.slack() {
            return None;
        }
        Some((k as usize, reach))
    }

    /// Offer `blocks(group)` the groups a shadow ray may meet in lookback (tmin, tmax), until
    /// one blocks it: Some(whether one did), or None, having offered nothing, when this tree
    /// does not serve the ray (or its slice could not be built).
    pub fn occluded(
        &self,
        ray: &NullRay,
        tmin: f64,
        tmax: f64,
        mut blocks: impl FnMut(u32) -> bool,
    ) -> Option<bool> {
        let (k, reach) = self.serves(ray, tmax)?;
        let (tree, members) = self.slice(k).ok()?;
        // Read backwards from the light: lookback λ is s = reach − λ.
        let mut far = [reach - tmin];
        let mut found = false;
        tree.traverse_packet(
            self.light,
            &[-ray.dir],
            &[reach - tmax],
            &mut far,
            &mut |i, _, s| {
                if blocks(members[i as usize]) {
                    found = true;
                    f64::NEG_INFINITY
                } else {
                    s
                }
            },
        );
        Some(found)
    }

    /// Many shadow rays toward this light (lookback from 0 to `tmax[i]`), in packets: the
    /// rays of one slice, read backwards, all start at the light. For each ray this tree
    /// serves, `served[i]` is set, and `blocked[i]` too when `test(group, i)` holds for a group
    /// the ray may meet; the others are left alone. `order`: a buffer for the rays by slice.
    pub fn occluded_many(
        &self,
        rays: &[NullRay],
        tmax: &[f64],
        (served, order): (&mut [bool], &mut Vec<(usize, usize, f64)>),
        blocked: &mut [bool],
        mut test: impl FnMut(u32, usize) -> bool,
    ) {
        order.clear();
        // Room for every ray at once, so the buffer grows only with the batch.
        order.reserve(rays.len());
        order.extend(
            rays.iter()
                .zip(tmax)
                .enumerate()
                .filter_map(|(i, (r, &t))| self.serves(r, t).map(|(k, reach)| (k, i, reach))),
        );
        order.sort_unstable_by_key(|&(k, i, _)| (k, i));
        for run in order.chunk_by(|a, b| a.0 == b.0) {
            // A slice that could not be built serves none of its rays.
            let Ok((tree, members)) = self.slice(run[0].0) else {
                continue;
            };
            for chunk in run.chunks(PACKET) {
                let m = chunk.len();
                let (mut dirs, mut near, mut far) =
                    ([DVec3::ZERO; PACKET], [0.0; PACKET], [0.0; PACKET]);
                for (j, &(_, i, reach)) in chunk.iter().enumerate() {
                    // Lookback λ in (0, tmax) is s = reach − λ from the light.
                    served[i] = true;
                    dirs[j] = -rays[i].dir;
                    near[j] = reach - tmax[i];
                    far[j] = reach;
                }
                tree.traverse_packet(
                    self.light,
                    &dirs[..m],
                    &near[..m],
                    &mut far[..m],
                    &mut |g: u32, j: usize, t: f64| {
                        let i: usize = chunk[j].1;
                        if test(members[g as usize], i) {
                            blocked[i] = true;
                            f64::NEG_INFINITY
                        } else {
                            t
                        }
                    },
                );
            }
        }
    }
}
