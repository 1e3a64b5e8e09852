//! A pure-Rust bounding volume hierarchy in f64, built with binned SAH: the reference backend.

use super::{Accelerator, Backend, Hit, Ray};
use crate::geometry::{Aabb, BoxTree, Geometry, TreeNode};
use std::sync::Arc;

pub struct Bvh {
    geometry: Arc<Geometry>,
    nodes: Vec<TreeNode>,
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

impl Bvh {
    pub fn build(geometry: Arc<Geometry>) -> Bvh {
        let boxes: Vec<Aabb> = geometry.prims.iter().map(|p| p.bounds()).collect();
        let BoxTree { nodes, indices } = BoxTree::build(&boxes);
        Bvh {
            geometry,
            nodes,
            indices,
        }
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

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}
