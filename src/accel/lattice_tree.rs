//! The f64 BVH's two levels for a lattice held as itself (`LatticeRun`): a tree over its
//! blocks' boxes, and one tree over a block's primitives in the block's own coordinates, which
//! every block shares (the ray moved by the block's corner walks it). The leaves test the
//! lattice's own primitive, made from its number, on the caller's ray: the same test, on the
//! same primitive and ray, as the listed lattice's BVH makes, so the hits are the same to the
//! bit wherever both trees reach the primitive (the local boxes are padded so that they do).

use super::{Hit, Ray};
use crate::geometry::{Aabb, Blocks, BoxTree, LatticeRun};

pub(super) struct LatticeTree {
    run: LatticeRun,
    blocks: Blocks,
    /// Over the blocks, by number, in the lattice's coordinates.
    top: BoxTree,
    /// Over one block's primitives in its local coordinates; items index `codes`.
    bottom: BoxTree,
    /// A block's primitives: below `blocks.nodes()` the sphere at that local node, else the
    /// rod numbered `code - nodes` (`Blocks::rod`).
    codes: Vec<u32>,
}

impl LatticeTree {
    pub fn build(run: &LatticeRun) -> LatticeTree {
        let l = &run.lattice;
        let blocks = Blocks::of(l);
        let boxes: Vec<Aabb> = (0..blocks.count())
            .map(|b| blocks.bounds(l, blocks.block(b)))
            .collect();
        let nodes = blocks.nodes();
        let spheres = (l.sphere_count() > 0).then_some(0..nodes);
        let rods = (l.rod_count() > 0).then_some(nodes..4 * nodes);
        let codes: Vec<u32> = spheres.into_iter().chain(rods).flatten().collect();
        let pad = glam::DVec3::splat(blocks.local_slack(l));
        let local: Vec<Aabb> = codes
            .iter()
            .map(|&c| {
                let b = if c < nodes {
                    blocks.local_sphere(l, c)
                } else {
                    blocks.local_rod(l, c - nodes)
                };
                Aabb::new(b.min - pad, b.max + pad)
            })
            .collect();
        LatticeTree {
            run: run.clone(),
            blocks,
            top: BoxTree::build(&boxes),
            bottom: BoxTree::build(&local),
            codes,
        }
    }

    /// The closest hit on the ray before `tmax` (`any`: the first found).
    pub fn traverse(&self, ray: &Ray, tmax: f64, any: bool) -> Option<Hit> {
        let (l, blocks) = (&self.run.lattice, &self.blocks);
        let nodes = blocks.nodes();
        let mut best = None;
        self.top
            .traverse(ray.origin, ray.dir, ray.tmin, tmax, |b, tmax| {
                let b = blocks.block(b as u64);
                let o = ray.origin - blocks.corner(l, b);
                let mut tmax = tmax;
                self.bottom
                    .traverse(o, ray.dir, ray.tmin, tmax, |item, t_end| {
                        let code = self.codes[item as usize];
                        let id = if code < nodes {
                            blocks.sphere(l, b, code)
                        } else {
                            blocks.rod(l, b, code - nodes)
                        };
                        let hit = id.and_then(|id| {
                            let t = l.prim(id).intersect(ray.origin, ray.dir, ray.tmin, t_end)?;
                            Some(Hit {
                                t,
                                prim: self.run.first + id as u32,
                            })
                        });
                        match hit {
                            Some(h) => {
                                best = Some(h);
                                tmax = h.t;
                                if any {
                                    f64::NEG_INFINITY
                                } else {
                                    h.t
                                }
                            }
                            None => t_end,
                        }
                    });
                if any && best.is_some() {
                    f64::NEG_INFINITY
                } else {
                    tmax
                }
            });
        best
    }
}
