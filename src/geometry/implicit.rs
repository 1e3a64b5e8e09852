//! Objects held as themselves (`Implicit`): the lattice and the bar array, whose primitives are
//! numbered and made from their numbers when asked, and big triangle meshes (an
//! [`IndexedMesh`]: shared vertices, three indices a triangle). Backends that instance a
//! lattice or bar array cut its grid of nodes into equal blocks ([`Blocks`]): one block's
//! primitives ([`Member`]s), placed at every block's first node, with the numbers the object
//! does not have (past its far faces) skipped. A mesh has no grid: backends build over its
//! triangles (its grid methods answer as for an object of no nodes).

use super::{Aabb, BarArray, IndexedMesh, Lattice, MeshInstance, Primitive};
use glam::DVec3;
use std::sync::Arc;

/// Lattices, bar arrays and meshes of more primitives than this are held as themselves
/// (instanced, or as shared vertices) by default (`WorldOptions::instance_over`): about where
/// holding them so starts to pay for itself; the bench measures both sides of it
/// (docs/performance.md, the lattice and bar array rows, instanced and listed).
pub(crate) const INSTANCE_OVER: u64 = 100_000;

/// An object held as itself.
#[derive(Clone, Debug, PartialEq)]
pub enum Implicit {
    /// Spheres at the nodes of a cubic grid, rods along its edges.
    Lattice(Lattice),
    /// Box-shaped bars on a plane grid.
    Bars(BarArray),
    /// A triangle mesh, its vertices shared.
    Mesh(Arc<IndexedMesh>),
    /// A mesh held once for several placements, at one of them.
    Instance(Arc<MeshInstance>),
}

/// One of a block's primitives: the sphere or bar at a local node, or the rod from it along an
/// axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Member {
    /// The node within the block.
    pub local: [u32; 3],
    /// The rod's axis (0, 1, 2), or [`SPHERE`] or [`BAR`].
    pub axis: u32,
}

/// A [`Member`]'s axis when it is a lattice's sphere.
pub(crate) const SPHERE: u32 = 3;
/// A [`Member`]'s axis when it is a bar.
pub(crate) const BAR: u32 = 4;

/// `n` as a number in the mixed radix `dims`, x fastest.
pub(super) fn flatten(n: [u32; 3], dims: [u32; 3]) -> u64 {
    n[0] as u64 + dims[0] as u64 * (n[1] as u64 + dims[1] as u64 * n[2] as u64)
}

/// The inverse of [`flatten`].
pub(super) fn unflatten(id: u64, dims: [u32; 3]) -> [u32; 3] {
    let (x, y) = (dims[0] as u64, dims[1] as u64);
    [(id % x) as u32, (id / x % y) as u32, (id / x / y) as u32]
}

impl Implicit {
    /// How many primitives.
    pub fn len(&self) -> u64 {
        match self {
            Implicit::Lattice(l) => l.len(),
            Implicit::Bars(b) => b.len(),
            Implicit::Mesh(m) => m.len(),
            Implicit::Instance(m) => m.len(),
        }
    }

    /// Whether it has no primitive.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Primitive number `id` (below [`len`](Self::len)).
    pub fn prim(&self, id: u64) -> Primitive {
        match self {
            Implicit::Lattice(l) => l.prim(id),
            Implicit::Bars(b) => b.prim(id),
            Implicit::Mesh(m) => m.triangle(id),
            Implicit::Instance(m) => m.triangle(id),
        }
    }

    /// Every primitive, in number order.
    pub fn listed(&self) -> Box<dyn Iterator<Item = Primitive> + '_> {
        match self {
            Implicit::Lattice(l) => Box::new(l.spheres().chain(l.rods())),
            Implicit::Bars(b) => Box::new(b.bars()),
            Implicit::Mesh(m) => Box::new((0..m.len()).map(|i| m.triangle(i))),
            Implicit::Instance(m) => Box::new((0..m.len()).map(|i| m.triangle(i))),
        }
    }

    /// The box holding every primitive: the union of their boxes, to the bit.
    pub fn bounds(&self) -> Aabb {
        match self {
            Implicit::Lattice(l) => l.bounds(),
            Implicit::Bars(b) => b.bounds(),
            Implicit::Mesh(m) => m.bounds(),
            Implicit::Instance(m) => m.bounds(),
        }
    }

    /// The same object moved by `d`.
    pub fn translated(&self, d: DVec3) -> Implicit {
        match self {
            Implicit::Lattice(l) => Implicit::Lattice(l.translated(d)),
            Implicit::Bars(b) => Implicit::Bars(b.translated(d)),
            Implicit::Mesh(m) => Implicit::Mesh(Arc::new(m.translated(d))),
            Implicit::Instance(m) => Implicit::Instance(Arc::new(m.translated(d))),
        }
    }

    /// Its grid of nodes: nodes along each axis.
    pub fn grid(&self) -> [u32; 3] {
        match self {
            Implicit::Lattice(l) => l.counts,
            Implicit::Bars(b) => b.grid(),
            Implicit::Mesh(_) | Implicit::Instance(_) => [0; 3],
        }
    }

    /// The position of node `n`.
    pub fn node(&self, n: [u32; 3]) -> DVec3 {
        match self {
            Implicit::Lattice(l) => l.node_at(n),
            Implicit::Bars(b) => b.node_at(n),
            Implicit::Mesh(_) | Implicit::Instance(_) => DVec3::ZERO,
        }
    }

    /// The primitive member `m` makes at node `n`: the one of that number, to the bit.
    #[inline]
    pub fn member_prim(&self, n: [u32; 3], m: Member) -> Primitive {
        match self {
            Implicit::Lattice(l) => l.member_prim(n, m),
            Implicit::Bars(b) => b.member_prim(n, m),
            Implicit::Mesh(mesh) => mesh.triangle(0),
            Implicit::Instance(mesh) => mesh.triangle(0),
        }
    }

    /// The number of the primitive member `m` makes at node `n`.
    #[inline]
    pub fn member_id(&self, n: [u32; 3], m: Member) -> u64 {
        match self {
            Implicit::Lattice(l) => l.member_id(n, m),
            Implicit::Bars(b) => b.member_id(n, m),
            Implicit::Mesh(_) | Implicit::Instance(_) => 0,
        }
    }

    /// The box of member `m` relative to its block's first node.
    pub fn local_box(&self, m: Member) -> Aabb {
        match self {
            Implicit::Lattice(l) => l.local_box(m),
            Implicit::Bars(b) => b.local_box(m),
            Implicit::Mesh(_) | Implicit::Instance(_) => Aabb::EMPTY,
        }
    }

    /// A block's members by the kind of shape they are (a lattice's spheres, its rods; the
    /// bars), the kinds it has.
    pub fn members(&self, blocks: &Blocks) -> Vec<Vec<Member>> {
        let nodes = blocks.nodes();
        let at = |p: u32| blocks.local(p);
        match self {
            Implicit::Lattice(l) => {
                let mut kinds = Vec::new();
                if l.sphere_count() > 0 {
                    kinds.push(
                        (0..nodes)
                            .map(|p| Member {
                                local: at(p),
                                axis: SPHERE,
                            })
                            .collect(),
                    );
                }
                if l.rod_count() > 0 {
                    kinds.push(
                        (0..3 * nodes)
                            .map(|p| Member {
                                local: at(p % nodes),
                                axis: p / nodes,
                            })
                            .collect(),
                    );
                }
                kinds
            }
            Implicit::Bars(_) => vec![(0..nodes)
                .map(|p| Member {
                    local: at(p),
                    axis: BAR,
                })
                .collect()],
            Implicit::Mesh(_) | Implicit::Instance(_) => Vec::new(),
        }
    }

    /// How many members a block has ([`members`](Self::members) without making them).
    pub fn member_count(&self, blocks: &Blocks) -> u64 {
        let kinds = match self {
            Implicit::Lattice(l) => {
                u64::from(l.sphere_count() > 0) + 3 * u64::from(l.rod_count() > 0)
            }
            Implicit::Bars(_) => 1,
            Implicit::Mesh(_) | Implicit::Instance(_) => 0,
        };
        kinds * u64::from(blocks.nodes())
    }

    /// The box, in the object's coordinates, of what block `b` holds that exists.
    pub fn block_bounds(&self, blocks: &Blocks, b: [u32; 3]) -> Aabb {
        let grid = self.grid();
        let first = blocks.first_of(b);
        let (last, reach) = match self {
            // A block's rods run into the next block's first nodes.
            Implicit::Lattice(l) => (
                [0, 1, 2].map(|a| (first[a] + blocks.size[a]).min(grid[a] - 1)),
                l.reach(),
            ),
            Implicit::Bars(bars) => (
                [0, 1, 2].map(|a| (first[a] + blocks.size[a] - 1).min(grid[a] - 1)),
                bars.reach(),
            ),
            Implicit::Mesh(_) | Implicit::Instance(_) => return Aabb::EMPTY,
        };
        Aabb::new(self.node(first) - reach, self.node(last) + reach)
    }

    /// How far a member's local box may be from the primitive moved by its block's first
    /// node, for any block: what rounding the nodes' positions can make (a few units in the
    /// last place of the object's largest coordinate), with a thousandfold margin.
    pub fn local_slack(&self) -> f64 {
        let b = self.bounds();
        1e-12 * (b.max_abs() + b.diagonal())
    }
}

/// A grid of nodes cut into blocks of equal numbers of nodes, for backends that build one
/// block and place it at every block's first node (Embree instances, the f64 BVH's two
/// levels). A lattice's block owns its nodes' spheres and the rods that start at them (along
/// +x, +y, +z, so its last rods reach into the next block); blocks on the far faces hold
/// members the object does not have, which [`Blocks::place`] answers None for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blocks {
    /// Nodes per block along each axis.
    pub size: [u32; 3],
    /// Blocks along each axis.
    pub grid: [u32; 3],
}

impl Blocks {
    /// Blocks of about √n nodes a side for a grid n nodes long, so that a block's primitives
    /// and the blocks number alike (a lattice: 4 s³ against (n / s)³).
    pub fn of(grid: [u32; 3]) -> Blocks {
        let longest = *grid.iter().max().expect("three counts") as f64;
        let side = (longest.sqrt().ceil() as u32).clamp(2, 64);
        let size = grid.map(|c| c.min(side));
        let grid = [0, 1, 2].map(|a| grid[a].div_ceil(size[a]));
        Blocks { size, grid }
    }

    /// How many blocks.
    pub fn count(&self) -> u64 {
        self.grid.iter().map(|&g| g as u64).product()
    }

    /// Nodes of one block.
    pub fn nodes(&self) -> u32 {
        self.size.iter().product()
    }

    /// Block number `b`'s grid position (x fastest).
    pub fn block(&self, b: u64) -> [u32; 3] {
        unflatten(b, self.grid)
    }

    /// Local node number `p` of a block.
    pub fn local(&self, p: u32) -> [u32; 3] {
        unflatten(p as u64, self.size)
    }

    /// Node (0, 0, 0) of block `b` in the object's node numbers.
    pub fn first_of(&self, b: [u32; 3]) -> [u32; 3] {
        [0, 1, 2].map(|a| b[a] * self.size[a])
    }

    /// The node of member `m` in the block whose first node is `first`, if the object (whose
    /// grid is `grid`) has that primitive: its node inside the grid and, for a rod, the node
    /// it runs to as well.
    #[inline]
    pub fn place(&self, grid: [u32; 3], first: [u32; 3], m: Member) -> Option<[u32; 3]> {
        let n = [0, 1, 2].map(|a| first[a] + m.local[a]);
        let step = |a: usize| u32::from(m.axis == a as u32);
        let inside = (0..3).all(|a| n[a] + step(a) < grid[a]);
        inside.then_some(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(counts: [u32; 3], rod: f64, sphere: f64) -> Implicit {
        Implicit::Lattice(Lattice {
            counts,
            spacing: DVec3::new(1.0, 0.75, 1.25),
            origin: DVec3::new(-3.3, 0.1, 7.0),
            rod_radius: rod,
            sphere_radius: sphere,
        })
    }

    fn bars(counts: [u32; 2], axis: usize) -> Implicit {
        Implicit::Bars(BarArray {
            counts,
            spacing: [2.0, 1.5],
            bar_size: [0.5, 0.4],
            length: 3.0,
            axis,
            center: DVec3::new(1.0, -2.0, 0.5),
        })
    }

    /// Numbers make the primitives the scene listed, in order, and the analytic bounds are the
    /// union of their boxes to the bit; every primitive is made by exactly one member of one
    /// block, at its number, inside the block's bounds and (moved by the block's first node)
    /// inside the member's local box.
    #[test]
    fn blocks_cover_every_primitive_once() {
        let shapes = [
            lattice([7, 5, 3], 0.05, 0.15),
            lattice([10, 10, 10], 0.05, 0.15),
            lattice([1, 9, 2], 0.05, 0.0),
            lattice([30, 4, 17], 0.0, 0.15),
            lattice([3, 4, 5], 0.05, 0.15),
            lattice([1, 4, 2], 0.05, 0.0),
            lattice([2, 1, 1], 0.0, 0.2),
            lattice([1, 1, 1], 0.05, 0.15),
            lattice([5, 1, 3], 0.3, 0.1),
            bars([11, 11], 2),
            bars([40, 3], 0),
            bars([1, 17], 1),
        ];
        for shape in shapes {
            let listed: Vec<Primitive> = shape.listed().collect();
            assert_eq!(listed.len() as u64, shape.len());
            for (id, p) in listed.iter().enumerate() {
                assert_eq!(shape.prim(id as u64), *p);
            }
            let union = listed.iter().fold(Aabb::EMPTY, |b, p| b.union(&p.bounds()));
            assert_eq!(shape.bounds(), union, "{shape:?}");
            let blocks = Blocks::of(shape.grid());
            let mut seen = vec![0u8; shape.len() as usize];
            let slack = shape.local_slack();
            for b in 0..blocks.count() {
                let bp = blocks.block(b);
                let first = blocks.first_of(bp);
                let corner = shape.node(first);
                let bounds = shape.block_bounds(&blocks, bp);
                let members: Vec<Member> = shape.members(&blocks).into_iter().flatten().collect();
                assert_eq!(members.len() as u64, shape.member_count(&blocks));
                for &m in &members {
                    let Some(n) = blocks.place(shape.grid(), first, m) else {
                        continue;
                    };
                    let id = shape.member_id(n, m);
                    seen[id as usize] += 1;
                    assert_eq!(shape.member_prim(n, m), listed[id as usize]);
                    let pb = listed[id as usize].bounds();
                    assert!(bounds.min.cmple(pb.min).all() && pb.max.cmple(bounds.max).all());
                    let local = shape.local_box(m);
                    let moved = Aabb::new(local.min + corner, local.max + corner);
                    let d = (moved.min - pb.min).abs().max((moved.max - pb.max).abs());
                    assert!(d.max_element() <= slack, "{shape:?} block {bp:?}: {d}");
                }
            }
            assert!(seen.iter().all(|&n| n == 1), "{shape:?}");
        }
    }

    #[test]
    fn blocks_are_about_the_square_root_of_the_grid() {
        let b = Blocks::of([1000, 1000, 1000]);
        assert_eq!((b.size, b.grid), ([32; 3], [32; 3]));
        let b = Blocks::of([100, 3, 1]);
        assert_eq!((b.size, b.grid), ([10, 3, 1], [10, 1, 1]));
    }
}
