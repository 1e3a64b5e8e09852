//! The f64 BVH over one placement of a shared mesh (`Implicit::Instance`): one tree over the
//! mesh's triangles in its own coordinates, shared by every placement (`MeshTrees`), walked
//! with the ray moved into the placement's frame; its leaves test the placed triangle on the
//! caller's own ray, as the tree over a placed copy tests the same triangle, so both find the
//! same hits.

use super::{Hit, Ray};
use crate::geometry::{Aabb, BoxTree, IndexedMesh, MeshInstance};
use glam::DVec3;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// The trees over shared meshes, one per mesh, by the mesh's address: kept by the backend, so
/// that every velocity group placing a mesh walks the one tree. Each entry holds its mesh, so
/// no other mesh can take its address while it is kept.
#[derive(Default)]
pub(crate) struct MeshTrees(Mutex<HashMap<usize, MeshTree>>);

/// A shared mesh and the tree over its triangles.
type MeshTree = (Arc<IndexedMesh>, Arc<BoxTree>);

impl MeshTrees {
    /// The tree over `mesh`'s triangles in its own coordinates, built on first use. Its boxes
    /// are padded by far more than the rounding of a ray moved into a placement's frame, so
    /// the walk there never misses a triangle the placed ray meets.
    fn of(&self, mesh: &Arc<IndexedMesh>) -> Arc<BoxTree> {
        let mut trees = self.0.lock().unwrap_or_else(|e| e.into_inner());
        trees
            .entry(Arc::as_ptr(mesh) as usize)
            .or_insert_with(|| {
                let b = mesh.bounds();
                let pad = DVec3::splat(1e-7 * b.diagonal() + 1e-9 * b.max_abs());
                let boxes: Vec<Aabb> = (0..mesh.len())
                    .map(|i| {
                        let t = mesh.triangle(i).bounds();
                        Aabb::new(t.min - pad, t.max + pad)
                    })
                    .collect();
                (mesh.clone(), Arc::new(BoxTree::build(&boxes)))
            })
            .1
            .clone()
    }
}

pub(super) struct InstanceTree {
    /// The geometry's number of the placement's first triangle.
    first: u32,
    instance: Arc<MeshInstance>,
    tree: Arc<BoxTree>,
}

impl InstanceTree {
    pub fn build(first: u32, instance: &Arc<MeshInstance>, trees: &MeshTrees) -> InstanceTree {
        InstanceTree {
            first,
            instance: instance.clone(),
            tree: trees.of(&instance.mesh),
        }
    }

    /// The closest hit on the ray before `tmax` (`any`: the first found).
    pub fn traverse(&self, ray: &Ray, tmax: f64, any: bool) -> Option<Hit> {
        let inst = &self.instance;
        let (enter, _) = inst
            .bounds()
            .clip(ray.origin, ray.dir.recip(), ray.tmin, tmax)?;
        // The ray moved into the placement's frame from where it enters the placed box, so
        // that the move rounds coordinates of the mesh's size, not of the ray's origin.
        let t0 = enter.max(ray.tmin);
        let x = &inst.place;
        let (o, d) = (
            x.local_point(ray.origin + t0 * ray.dir),
            x.local_dir(ray.dir),
        );
        let mut best: Option<Hit> = None;
        // The walk's interval is the local one (t less t0) and a little wider; the leaves test
        // against the exact best so far.
        let margin = |t: f64| 1e-9 * t.abs().max(1.0);
        let widen = |t: f64| t + margin(t);
        let from = ray.tmin - t0;
        self.tree.traverse(
            o,
            d,
            from - margin(from),
            widen(tmax - t0),
            |item, t_end| {
                let limit = best.map_or(tmax, |h| h.t);
                match inst
                    .triangle(u64::from(item))
                    .intersect(ray.origin, ray.dir, ray.tmin, limit)
                {
                    Some(t) => {
                        best = Some(Hit {
                            t,
                            prim: self.first + item,
                        });
                        if any {
                            f64::NEG_INFINITY
                        } else {
                            widen(t - t0)
                        }
                    }
                    None => t_end,
                }
            },
        );
        best
    }
}
