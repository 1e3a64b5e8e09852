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
/// that every velocity group placing a mesh walks the one tree. An entry lives while its mesh
/// does: a dead mesh's entry is dropped before any lookup, so no other mesh found at its
/// address is taken for it.
#[derive(Default)]
pub(crate) struct MeshTrees(Mutex<HashMap<usize, MeshTree>>);

/// A shared mesh (while it lives) and the tree over its triangles.
type MeshTree = (std::sync::Weak<IndexedMesh>, Arc<BoxTree>);

impl MeshTrees {
    /// The tree over `mesh`'s triangles in its own coordinates, built on first use. Its boxes
    /// are padded by far more than the rounding of a ray moved into a placement's frame, so
    /// the walk there never misses a triangle the placed ray meets.
    fn of(&self, mesh: &Arc<IndexedMesh>) -> Arc<BoxTree> {
        let mut trees = self.0.lock().unwrap_or_else(|e| e.into_inner());
        // Meshes no longer held anywhere (a scene the viewer read again, say) leave with their
        // trees.
        trees.retain(|_, (m, _)| m.strong_count() > 0);
        let key = Arc::as_ptr(mesh) as usize;
        if let Some((m, tree)) = trees.get(&key) {
            // Alive, at this address, it is this mesh.
            if m.upgrade().is_some_and(|m| Arc::ptr_eq(&m, mesh)) {
                return tree.clone();
            }
        }
        let b = mesh.bounds();
        let pad = DVec3::splat(1e-7 * b.diagonal() + 1e-9 * b.max_abs());
        let boxes: Vec<Aabb> = (0..mesh.len())
            .map(|i| {
                let t = mesh.triangle(i).bounds();
                Aabb::new(t.min - pad, t.max + pad)
            })
            .collect();
        let tree = Arc::new(BoxTree::build(&boxes));
        trees.insert(key, (Arc::downgrade(mesh), tree.clone()));
        tree
    }

    /// How many meshes it keeps trees for.
    #[cfg(test)]
    fn len(&self) -> usize {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).len()
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

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(n: usize) -> Arc<IndexedMesh> {
        let positions = (0..n + 2)
            .map(|i| DVec3::new(i as f64, (i % 2) as f64, 0.0))
            .collect();
        let triangles = (0..n as u32).map(|i| [i, i + 1, i + 2]).collect();
        Arc::new(IndexedMesh::new(positions, triangles))
    }

    /// A tree is kept while its mesh lives, shared by every lookup of it, and dropped with it.
    #[test]
    fn trees_live_as_long_as_their_meshes() {
        let trees = MeshTrees::default();
        let a = mesh(5);
        let t = trees.of(&a);
        assert!(Arc::ptr_eq(&t, &trees.of(&a)));
        assert_eq!(t.indices.len(), 5);
        drop(a);
        let b = mesh(7);
        assert_eq!(trees.of(&b).indices.len(), 7);
        assert_eq!(trees.len(), 1, "the dead mesh's tree is dropped");
    }
}
