//! The pure-Rust BVH with its nodes in f32 (about the geometry's centre, rounded outward and
//! padded) and the same exact f64 primitive tests at its leaves: the benchmark's f32-against-f64
//! BVH. The f32 traversal only decides which leaves to open, and it errs on the side of opening
//! them, so its hits are the f64 BVH's; what it changes is the memory a node takes (32 bytes
//! instead of 56) and the width of its arithmetic.

use super::bvh::{nearest_first, Bvh, NodeSet};
use super::{Accelerator, Backend, Hit, Ray};
use crate::geometry::{Aabb, Geometry, TreeNode};
use glam::DVec3;
use std::sync::Arc;

#[derive(Clone, Copy)]
struct Node32 {
    min: [f32; 3],
    first: u32,
    max: [f32; 3],
    count: u32,
}

/// A tree's nodes in f32, relative to `center`.
pub struct Nodes32 {
    nodes: Vec<Node32>,
    center: DVec3,
}

pub struct Bvh32Backend;

impl Backend for Bvh32Backend {
    fn name(&self) -> &'static str {
        "bvh-f32"
    }
    fn build(&self, geometry: Arc<Geometry>) -> crate::Result<Box<dyn Accelerator>> {
        Ok(Box::new(Bvh::<Nodes32>::build(geometry)))
    }
}

/// The slab test of `Aabb::clip` in f32: plain comparisons, so a NaN (0 · inf on a slab
/// boundary) never replaces the interval's ends. Returns the entry parameter.
#[inline]
fn clip32(n: &Node32, o: [f32; 3], inv: [f32; 3], tmin: f32, tmax: f32) -> Option<f32> {
    let (mut t0, mut t1) = (tmin, tmax);
    for k in 0..3 {
        let a = (n.min[k] - o[k]) * inv[k];
        let b = (n.max[k] - o[k]) * inv[k];
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        if lo > t0 {
            t0 = lo;
        }
        if hi < t1 {
            t1 = hi;
        }
    }
    (t0 <= t1).then_some(t0)
}

impl NodeSet for Nodes32 {
    /// The f64 tree's nodes over geometry with these bounds, in f32.
    fn from_tree(nodes: Vec<TreeNode>, all: &Aabb) -> Nodes32 {
        let center = if all.is_empty() {
            DVec3::ZERO
        } else {
            all.centroid()
        };
        // f32 keeps ~7 digits about the centre; rays reach the tree from at most a few extents
        // away (the renderer moves far rays to the bounds), so this pad covers their rounding.
        let pad = if all.is_empty() {
            0.0
        } else {
            1e-5 * (all.max - all.min).max_element()
        };
        let nodes = nodes
            .iter()
            .map(|n| {
                let (lo, hi) = (n.bounds.min - center, n.bounds.max - center);
                Node32 {
                    min: [lo.x, lo.y, lo.z].map(|v| ((v - pad) as f32).next_down()),
                    first: n.first,
                    max: [hi.x, hi.y, hi.z].map(|v| ((v + pad) as f32).next_up()),
                    count: n.count,
                }
            })
            .collect();
        Nodes32 { nodes, center }
    }

    /// As the f64 BVH's walk, with the node tests in f32 (limits widened by rounding).
    fn traverse(&self, indices: &[u32], geometry: &Geometry, ray: &Ray, any: bool) -> Option<Hit> {
        let o = ray.origin - self.center;
        let o32 = [o.x as f32, o.y as f32, o.z as f32];
        let inv = [
            1.0 / ray.dir.x as f32,
            1.0 / ray.dir.y as f32,
            1.0 / ray.dir.z as f32,
        ];
        let tmin32 = (ray.tmin as f32).next_down();
        let hi32 = |t: f64| {
            if t.is_finite() {
                ((t + 1e-6 * t.abs()) as f32).next_up()
            } else {
                f32::INFINITY
            }
        };
        nearest_first(
            &self.nodes,
            |n| (n.first, n.count),
            |n, tmax| clip32(n, o32, inv, tmin32, hi32(tmax)).map(f64::from),
            indices,
            geometry,
            ray,
            any,
        )
    }
}
