//! The f64 BVH's two levels for an object held as itself (`ImplicitRun`: a lattice, a bar
//! array): a tree over its blocks' boxes, and one tree over a block's members in the block's
//! own coordinates, which every block shares (the ray moved by the block's first node walks
//! it). The leaves test the object's own primitive, made from its member and node, on the
//! caller's ray: the same test, on the same primitive and ray, as the listed object's BVH
//! makes, so the hits are the same to the bit wherever both trees reach the primitive (the
//! local boxes are padded so that they do).

use super::{Hit, Ray};
use crate::geometry::{Aabb, Blocks, BoxTree, ImplicitRun, Member};
use glam::DVec3;

pub(super) struct InstancedTree {
    run: ImplicitRun,
    blocks: Blocks,
    /// Over the blocks, by number, in the object's coordinates.
    top: BoxTree,
    /// Each block's first node and its position, by number.
    firsts: Vec<([u32; 3], DVec3)>,
    /// Over one block's members in its local coordinates; items index `members`.
    bottom: BoxTree,
    members: Vec<Member>,
}

impl InstancedTree {
    pub fn build(run: &ImplicitRun) -> InstancedTree {
        let shape = &run.shape;
        let blocks = Blocks::of(shape.grid());
        let positions = (0..blocks.count()).map(|b| blocks.block(b));
        let firsts: Vec<([u32; 3], DVec3)> = positions
            .clone()
            .map(|b| blocks.first_of(b))
            .map(|first| (first, shape.node(first)))
            .collect();
        let boxes: Vec<Aabb> = positions.map(|b| shape.block_bounds(&blocks, b)).collect();
        let pad = DVec3::splat(shape.local_slack());
        let members: Vec<Member> = shape.members(&blocks).into_iter().flatten().collect();
        let local: Vec<Aabb> = members
            .iter()
            .map(|&m| {
                let b = shape.local_box(m);
                Aabb::new(b.min - pad, b.max + pad)
            })
            .collect();
        InstancedTree {
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
        let shape = &self.run.shape;
        let grid = shape.grid();
        let mut best = None;
        self.top
            .traverse(ray.origin, ray.dir, ray.tmin, tmax, |b, tmax| {
                let (first, corner) = self.firsts[b as usize];
                let mut tmax = tmax;
                let o = ray.origin - corner;
                self.bottom
                    .traverse(o, ray.dir, ray.tmin, tmax, |item, t_end| {
                        let m = self.members[item as usize];
                        let Some(n) = self.blocks.place(grid, first, m) else {
                            return t_end;
                        };
                        let prim = shape.member_prim(n, m);
                        let Some(t) = prim.intersect(ray.origin, ray.dir, ray.tmin, t_end) else {
                            return t_end;
                        };
                        best = Some(Hit {
                            t,
                            prim: self.run.first + shape.member_id(n, m) as u32,
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
