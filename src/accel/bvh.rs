//! A pure-Rust bounding volume hierarchy in f64, built with binned SAH: the reference backend.
//! Its nodes over the held primitives are a [`NodeSet`]: f64 here, f32 in bvh32.rs (the
//! benchmark's f32-against-f64 BVH).

use super::instance_tree::{InstanceTree, MeshTrees};
use super::instanced_tree::InstancedTree;
use super::mesh_tree::MeshTree;
use super::{Accelerator, Backend, Hit, Ray};
use crate::geometry::{Aabb, BoxTree, Geometry, TreeNode};
use std::sync::Arc;

pub struct Bvh<N = Nodes64> {
    geometry: Arc<Geometry>,
    /// Over the primitives held one by one.
    nodes: N,
    indices: Vec<u32>,
    /// The objects held as themselves: lattices and bar arrays each in two levels, meshes
    /// each in a tree over its triangles, placements of a shared mesh each over its mesh's.
    instanced: Vec<Held>,
    /// A tree over the held objects' boxes, where there are many (a mesh placed a thousand
    /// times): a ray then visits the objects whose boxes it meets, nearer first.
    held_tree: Option<BoxTree>,
}

/// Held objects past this many are found through a tree over their boxes.
const HELD_TREE_OVER: usize = 8;

/// An object held as itself, as the BVH walks it.
enum Held {
    Blocks(InstancedTree),
    Mesh(MeshTree),
    Instance(InstanceTree),
}

impl Held {
    fn build(run: &crate::geometry::ImplicitRun, trees: &MeshTrees) -> Held {
        use crate::geometry::Implicit;
        match &run.shape {
            Implicit::Mesh(m) => Held::Mesh(MeshTree::build(run.first, m)),
            Implicit::Instance(m) => Held::Instance(InstanceTree::build(run.first, m, trees)),
            _ => Held::Blocks(InstancedTree::build(run)),
        }
    }

    fn traverse(&self, ray: &Ray, tmax: f64, any: bool) -> Option<Hit> {
        match self {
            Held::Blocks(t) => t.traverse(ray, tmax, any),
            Held::Mesh(t) => t.traverse(ray, tmax, any),
            Held::Instance(t) => t.traverse(ray, tmax, any),
        }
    }
}

/// How a BVH's nodes over its held primitives are kept and walked.
pub(super) trait NodeSet: Send + Sync + Sized + 'static {
    /// The nodes of the f64 tree `nodes` over geometry with bounds `all`.
    fn from_tree(nodes: Vec<TreeNode>, all: &Aabb) -> Self;
    /// The nearest hit (or any, for occlusion) among the held primitives.
    fn traverse(&self, indices: &[u32], geometry: &Geometry, ray: &Ray, any: bool) -> Option<Hit>;
}

/// The tree's nodes in f64, as built.
pub struct Nodes64(Vec<TreeNode>);

impl NodeSet for Nodes64 {
    fn from_tree(nodes: Vec<TreeNode>, _: &Aabb) -> Self {
        Nodes64(nodes)
    }

    fn traverse(&self, indices: &[u32], geometry: &Geometry, ray: &Ray, any: bool) -> Option<Hit> {
        let inv = ray.dir.recip();
        nearest_first(
            &self.0,
            |n| (n.first, n.count),
            |n, tmax| n.bounds.clip(ray.origin, inv, ray.tmin, tmax).map(|x| x.0),
            indices,
            geometry,
            ray,
            any,
        )
    }
}

/// The f64 BVH backend; it keeps the trees over shared meshes for every group it builds.
#[derive(Default)]
pub struct BvhBackend {
    trees: MeshTrees,
}

impl Backend for BvhBackend {
    fn name(&self) -> &'static str {
        "bvh"
    }
    fn build(&self, geometry: Arc<Geometry>) -> crate::Result<Box<dyn Accelerator>> {
        Ok(Box::new(Bvh::<Nodes64>::build_with(geometry, &self.trees)))
    }
}

impl<N: NodeSet> Bvh<N> {
    pub fn build(geometry: Arc<Geometry>) -> Bvh<N> {
        Self::build_with(geometry, &MeshTrees::default())
    }

    /// The BVH over `geometry`, its shared meshes' trees taken from `trees` (built there when
    /// new).
    pub(super) fn build_with(geometry: Arc<Geometry>, trees: &MeshTrees) -> Bvh<N> {
        let boxes: Vec<Aabb> = geometry.prims.iter().map(|p| p.bounds()).collect();
        let BoxTree { nodes, indices } = BoxTree::build(&boxes);
        let instanced: Vec<Held> = geometry
            .implicit
            .iter()
            .map(|r| Held::build(r, trees))
            .collect();
        let held_tree = (instanced.len() > HELD_TREE_OVER).then(|| {
            // Padded: the objects' own walks decide, the boxes only pass rays on to them.
            let boxes: Vec<Aabb> = geometry
                .implicit
                .iter()
                .map(|r| {
                    let b = r.shape.bounds();
                    let pad = glam::DVec3::splat(1e-9 * (b.diagonal() + b.max_abs()));
                    Aabb::new(b.min - pad, b.max + pad)
                })
                .collect();
            BoxTree::build(&boxes)
        });
        Bvh {
            nodes: N::from_tree(nodes, &geometry.bounds()),
            geometry,
            indices,
            instanced,
            held_tree,
        }
    }

    fn traverse(&self, ray: &Ray, any: bool) -> Option<Hit> {
        let mut best = self.traverse_held(ray, any);
        if any && best.is_some() {
            return best;
        }
        if let Some(tree) = &self.held_tree {
            let tmax = best.map_or(ray.tmax, |h| h.t);
            tree.traverse(
                ray.origin,
                ray.dir,
                ray.tmin,
                tmax,
                |item, t_end| match self.instanced[item as usize].traverse(ray, t_end, any) {
                    Some(h) => {
                        best = Some(h);
                        if any {
                            f64::NEG_INFINITY
                        } else {
                            h.t
                        }
                    }
                    None => t_end,
                },
            );
            return best;
        }
        for l in &self.instanced {
            if any && best.is_some() {
                break;
            }
            let tmax = best.map_or(ray.tmax, |h| h.t);
            best = l.traverse(ray, tmax, any).or(best);
        }
        best
    }

    fn traverse_held(&self, ray: &Ray, any: bool) -> Option<Hit> {
        self.nodes.traverse(&self.indices, &self.geometry, ray, any)
    }
}

/// The BVH walk for one ray, nearer child first, over nodes of any precision: `link(node)` is
/// its (first, count) (interior when count is 0, children at first and first + 1) and
/// `enter(node, tmax)` where the ray enters its box before tmax (None: it does not); leaves run
/// the exact f64 primitive tests. `any`: stop at the first hit (occlusion).
pub(super) fn nearest_first<N>(
    nodes: &[N],
    link: impl Fn(&N) -> (u32, u32),
    enter: impl Fn(&N, f64) -> Option<f64>,
    indices: &[u32],
    geometry: &Geometry,
    ray: &Ray,
    any: bool,
) -> Option<Hit> {
    if geometry.prims.is_empty() || !ray.is_active() {
        return None;
    }
    let mut tmax = ray.tmax;
    let mut best = None;
    let mut stack = [0u32; 64];
    let mut sp = 0usize;
    enter(&nodes[0], tmax)?;
    let mut node = 0u32;
    loop {
        let (first, count) = link(&nodes[node as usize]);
        if count > 0 {
            for &i in &indices[first as usize..(first + count) as usize] {
                if let Some(t) =
                    geometry.prims[i as usize].intersect(ray.origin, ray.dir, ray.tmin, tmax)
                {
                    tmax = t;
                    best = Some(Hit { t, prim: i });
                    if any {
                        return best;
                    }
                }
            }
        } else {
            let (l, r) = (first, first + 1);
            match (
                enter(&nodes[l as usize], tmax),
                enter(&nodes[r as usize], tmax),
            ) {
                (Some(tl), Some(tr)) => {
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

impl<N: NodeSet> Accelerator for Bvh<N> {
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
