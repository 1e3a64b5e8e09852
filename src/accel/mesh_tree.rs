//! The f64 BVH over a mesh held as itself (`Implicit::Mesh`): a tree over its triangles'
//! boxes, whose leaves make each triangle from its indices and test it exactly as the listed
//! mesh's tree tests the same triangle, so both find the same hits to the bit.

use super::{Hit, Ray};
use crate::geometry::{BoxTree, IndexedMesh};
use std::sync::Arc;

pub(super) struct MeshTree {
    /// The geometry's number of the mesh's first triangle.
    first: u32,
    mesh: Arc<IndexedMesh>,
    tree: BoxTree,
}

impl MeshTree {
    pub fn build(first: u32, mesh: &Arc<IndexedMesh>) -> MeshTree {
        MeshTree {
            first,
            mesh: mesh.clone(),
            tree: BoxTree::build_from(mesh.len() as usize, |i| mesh.triangle(i as u64).bounds()),
        }
    }

    /// The closest hit on the ray before `tmax` (`any`: the first found).
    pub fn traverse(&self, ray: &Ray, tmax: f64, any: bool) -> Option<Hit> {
        let mut best = None;
        self.tree
            .traverse(ray.origin, ray.dir, ray.tmin, tmax, |item, t_end| {
                let tri = self.mesh.triangle(u64::from(item));
                match tri.intersect(ray.origin, ray.dir, ray.tmin, t_end) {
                    Some(t) => {
                        best = Some(Hit {
                            t,
                            prim: self.first + item,
                        });
                        if any {
                            f64::NEG_INFINITY
                        } else {
                            t
                        }
                    }
                    None => t_end,
                }
            });
        best
    }
}
