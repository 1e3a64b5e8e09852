//! The f64 BVH's two levels for a lattice held as itself (`LatticeRun`): a tree over its
//! blocks' boxes, and one tree over a block's primitives in the block's own coordinates, which
//! every block shares (the ray moved by the block's corner walks it). The leaves test the
//! lattice's own primitive, made from its number, on the caller's ray: the same test, on the
//! same primitive and ray, as the listed lattice's BVH makes, so the hits are the same to the
//! bit wherever both trees reach the primitive (the local boxes are padded so that they do).

use super::{Hit, Ray};
use crate::geometry::{Aabb, Blocks, BoxTree, LatticeRun, Member};
use glam::DVec3;

pub(super) struct LatticeTree {
    run: LatticeRun,
    blocks: Blocks,
    /// Over the blocks, by number, in the lattice's coordinates.
    top: BoxTree,
    /// Each block's first node and corner, by number.
    firsts: Vec<([u32; 3], DVec3)>,
    /// Over one block's primitives in its local coordinates; items index `members`.
    bottom: BoxTree,
    members: Vec<Member>,
}

impl LatticeTree {
    pub fn build(run: &LatticeRun) -> LatticeTree {
        let l = &run.lattice;
        let blocks = Blocks::of(l);
        let firsts: Vec<([u32; 3], DVec3)> = (0..blocks.count())
            .map(|b| {
                let b = blocks.block(b);
                (blocks.first_of(b), blocks.corner(l, b))
            })
            .collect();
        let boxes: Vec<Aabb> = (0..blocks.count())
            .map(|b| blocks.bounds(l, blocks.block(b)))
            .collect();
        let nodes = blocks.nodes();
        let spheres = (l.sphere_count() > 0).then_some(0..nodes);
        let rods = (l.rod_count() > 0).then_some(0..3 * nodes);
        let pad = DVec3::splat(blocks.local_slack(l));
        let padded = |b: Aabb| Aabb::new(b.min - pad, b.max + pad);
        let mut members = Vec::new();
        let mut local = Vec::new();
        for p in spheres.into_iter().flatten() {
            members.push(blocks.sphere_member(p));
            local.push(padded(blocks.local_sphere(l, p)));
        }
        for p in rods.into_iter().flatten() {
            members.push(blocks.rod_member(p));
            local.push(padded(blocks.local_rod(l, p)));
        }
        LatticeTree {
            run: run.clone(),
            blocks,
            top: BoxTree::build(&boxes),
            firsts,
            bottom: BoxTree::build(&local),
            members,
        }
    }

    /// The closest hit on the ray before `tmax` (`any`: the first found).
    pub fn traverse(&self, ray: &Ray, tmax: f64, any: bool) -> Option<Hit> {
        let l = &self.run.lattice;
        let mut best = None;
        self.top
            .traverse(ray.origin, ray.dir, ray.tmin, tmax, |b, tmax| {
                let (first, corner) = self.firsts[b as usize];
                let mut tmax = tmax;
                let o = ray.origin - corner;
                self.bottom
                    .traverse(o, ray.dir, ray.tmin, tmax, |item, t_end| {
                        let m = self.members[item as usize];
                        let Some(n) = self.blocks.place(l, first, m) else {
                            return t_end;
                        };
                        let prim = l.member_prim(n, m);
                        let Some(t) = prim.intersect(ray.origin, ray.dir, ray.tmin, t_end) else {
                            return t_end;
                        };
                        best = Some(Hit {
                            t,
                            prim: self.run.first + l.member_id(n, m) as u32,
                        });
                        tmax = t;
                        if any {
                            f64::NEG_INFINITY
                        } else {
                            t
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
