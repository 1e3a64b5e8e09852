//! A pure-Rust bounding volume hierarchy in f64, built with binned SAH: the reference backend.

use super::{Accelerator, Backend, Hit, Ray};
use crate::geometry::{Aabb, Geometry};
use glam::DVec3;
use std::sync::Arc;

const BINS: usize = 16;
const MAX_LEAF: usize = 4;
const TRAVERSAL_COST: f64 = 1.0;
const INTERSECT_COST: f64 = 1.5;

/// A node: an interior node has `count == 0` and children at `first` and `first + 1`; a leaf
/// holds `indices[first .. first + count]`.
#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Aabb,
    first: u32,
    count: u32,
}

pub struct Bvh {
    geometry: Arc<Geometry>,
    nodes: Vec<Node>,
    indices: Vec<u32>,
}

pub struct BvhBackend;

impl Backend for BvhBackend {
    fn name(&self) -> &'static str {
        "bvh"
    }
    fn build(&self, geometry: Arc<Geometry>) -> Result<Box<dyn Accelerator>, String> {
        Ok(Box::new(Bvh::build(geometry)))
    }
}

struct BuildItem {
    node: usize,
    start: usize,
    end: usize,
}

impl Bvh {
    pub fn build(geometry: Arc<Geometry>) -> Bvh {
        let n = geometry.prims.len();
        let boxes: Vec<Aabb> = geometry.prims.iter().map(|p| p.bounds()).collect();
        let centroids: Vec<DVec3> = boxes.iter().map(|b| b.centroid()).collect();
        let mut indices: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n.div_ceil(MAX_LEAF).max(1));
        nodes.push(Node {
            bounds: Aabb::EMPTY,
            first: 0,
            count: 0,
        });
        let mut stack = vec![BuildItem {
            node: 0,
            start: 0,
            end: n,
        }];
        while let Some(item) = stack.pop() {
            let idx = &mut indices[item.start..item.end];
            let bounds = idx
                .iter()
                .fold(Aabb::EMPTY, |b, &i| b.union(&boxes[i as usize]));
            let cbounds = idx.iter().fold(Aabb::EMPTY, |mut b, &i| {
                b.grow(centroids[i as usize]);
                b
            });
            nodes[item.node].bounds = bounds;
            let count = idx.len();
            let split = if count <= 1 {
                None
            } else {
                find_split(idx, &boxes, &centroids, &bounds, &cbounds)
            };
            let mid = match split {
                Some(m) => Some(m),
                None if count > MAX_LEAF => Some(count / 2), // degenerate centroids: split evenly
                None => None,
            };
            match mid {
                Some(mid) => {
                    if split.is_none() {
                        let e = cbounds.extent();
                        let axis = if e.x >= e.y && e.x >= e.z {
                            0
                        } else if e.y >= e.z {
                            1
                        } else {
                            2
                        };
                        idx.select_nth_unstable_by(mid, |&a, &b| {
                            centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
                        });
                    }
                    let left = nodes.len();
                    nodes.push(Node {
                        bounds: Aabb::EMPTY,
                        first: 0,
                        count: 0,
                    });
                    nodes.push(Node {
                        bounds: Aabb::EMPTY,
                        first: 0,
                        count: 0,
                    });
                    nodes[item.node].first = left as u32;
                    nodes[item.node].count = 0;
                    stack.push(BuildItem {
                        node: left + 1,
                        start: item.start + mid,
                        end: item.end,
                    });
                    stack.push(BuildItem {
                        node: left,
                        start: item.start,
                        end: item.start + mid,
                    });
                }
                None => {
                    nodes[item.node].first = item.start as u32;
                    nodes[item.node].count = count as u32;
                }
            }
        }
        Bvh {
            geometry,
            nodes,
            indices,
        }
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Walks the tree; `visit` returns a new tmax when a leaf primitive is hit, and traversal
    /// stops early when `any` is set.
    #[inline]
    fn traverse(&self, ray: &Ray, any: bool) -> Option<Hit> {
        if self.geometry.prims.is_empty() || !ray.is_active() {
            return None;
        }
        let inv = ray.dir.recip();
        let mut tmax = ray.tmax;
        let mut best = None;
        let mut stack = [0u32; 64];
        let mut sp = 0usize;
        let root = &self.nodes[0];
        root.bounds.clip(ray.origin, inv, ray.tmin, tmax)?;
        let mut node = 0u32;
        loop {
            let n = &self.nodes[node as usize];
            if n.count > 0 {
                for &i in &self.indices[n.first as usize..(n.first + n.count) as usize] {
                    if let Some(t) = self.geometry.prims[i as usize]
                        .intersect(ray.origin, ray.dir, ray.tmin, tmax)
                    {
                        tmax = t;
                        best = Some(Hit { t, prim: i });
                        if any {
                            return best;
                        }
                    }
                }
            } else {
                let (l, r) = (n.first, n.first + 1);
                let hl = self.nodes[l as usize]
                    .bounds
                    .clip(ray.origin, inv, ray.tmin, tmax);
                let hr = self.nodes[r as usize]
                    .bounds
                    .clip(ray.origin, inv, ray.tmin, tmax);
                match (hl, hr) {
                    (Some((tl, _)), Some((tr, _))) => {
                        let (near, far) = if tl <= tr { (l, r) } else { (r, l) };
                        if sp < stack.len() {
                            stack[sp] = far;
                            sp += 1;
                        }
                        node = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node = l;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = r;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            node = stack[sp];
        }
        best
    }
}

/// Binned SAH: the split position (count of the left side, after partitioning `idx`) or None
/// when a leaf is cheaper.
fn find_split(
    idx: &mut [u32],
    boxes: &[Aabb],
    centroids: &[DVec3],
    bounds: &Aabb,
    cbounds: &Aabb,
) -> Option<usize> {
    let count = idx.len();
    let ext = cbounds.extent();
    let mut best: Option<(f64, usize, usize)> = None; // cost, axis, bin
    for axis in 0..3 {
        if ext[axis] <= 0.0 {
            continue;
        }
        let scale = BINS as f64 / ext[axis];
        let bin_of = |c: DVec3| (((c[axis] - cbounds.min[axis]) * scale) as usize).min(BINS - 1);
        let mut bin_box = [Aabb::EMPTY; BINS];
        let mut bin_n = [0usize; BINS];
        for &i in idx.iter() {
            let b = bin_of(centroids[i as usize]);
            bin_n[b] += 1;
            bin_box[b] = bin_box[b].union(&boxes[i as usize]);
        }
        let mut right_area = [0.0; BINS];
        let mut right_n = [0usize; BINS];
        let (mut acc, mut n) = (Aabb::EMPTY, 0);
        for b in (1..BINS).rev() {
            acc = acc.union(&bin_box[b]);
            n += bin_n[b];
            right_area[b] = acc.surface_area();
            right_n[b] = n;
        }
        let (mut acc, mut n) = (Aabb::EMPTY, 0);
        for b in 0..BINS - 1 {
            acc = acc.union(&bin_box[b]);
            n += bin_n[b];
            let rn = right_n[b + 1];
            if n == 0 || rn == 0 {
                continue;
            }
            let cost = n as f64 * acc.surface_area() + rn as f64 * right_area[b + 1];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    let (cost, axis, bin) = best?;
    let area = bounds.surface_area().max(f64::MIN_POSITIVE);
    let split_cost = TRAVERSAL_COST + INTERSECT_COST * cost / area;
    if count <= MAX_LEAF && split_cost >= INTERSECT_COST * count as f64 {
        return None;
    }
    let scale = BINS as f64 / ext[axis];
    let mut left = 0;
    for k in 0..count {
        let c = centroids[idx[k] as usize];
        let b = (((c[axis] - cbounds.min[axis]) * scale) as usize).min(BINS - 1);
        if b <= bin {
            idx.swap(k, left);
            left += 1;
        }
    }
    (left > 0 && left < count).then_some(left)
}

impl Accelerator for Bvh {
    fn intersect(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        for (r, h) in rays.iter().zip(hits.iter_mut()) {
            *h = self.traverse(r, false);
        }
    }

    fn occluded(&self, rays: &[Ray], out: &mut [bool]) {
        for (r, o) in rays.iter().zip(out.iter_mut()) {
            *o = self.traverse(r, true).is_some();
        }
    }

    fn geometry(&self) -> &Arc<Geometry> {
        &self.geometry
    }
}
