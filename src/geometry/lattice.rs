//! The paper's rod-and-sphere lattice as an implicit object: its primitives are numbered, and
//! made from their number when asked, so that a lattice of a billion nodes costs no memory per
//! primitive. Backends that instance it cut it into equal blocks of nodes ([`Blocks`]): one
//! block's primitives, placed at every block's corner, with the primitives that do not exist
//! (past the lattice's far faces) skipped by number.

use super::{Aabb, Primitive};
use glam::DVec3;

/// A cubic lattice of nodes joined by rods along the three axes, with a sphere at each node.
///
/// Its primitives, numbered from 0 (the order the scene lists them in, which is also the
/// order of [`spheres`](Self::spheres) then [`rods`](Self::rods)): the spheres, node (i, j, k)
/// at `i + nx (j + ny k)`; then the rods along x, along y and along z, each run numbered by
/// the node the rod starts from within the nodes such rods start from.
#[derive(Clone, Debug, PartialEq)]
pub struct Lattice {
    /// Nodes along x, y and z.
    pub counts: [u32; 3],
    /// From one node to the next along each axis.
    pub spacing: DVec3,
    /// Position of node (0, 0, 0).
    pub origin: DVec3,
    /// The rods' radius (0: no rods).
    pub rod_radius: f64,
    /// The spheres' radius (0: no spheres).
    pub sphere_radius: f64,
}

/// The unit step along an axis.
const STEPS: [[u32; 3]; 3] = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];

impl Lattice {
    /// How many spheres.
    pub fn sphere_count(&self) -> u64 {
        if self.sphere_radius > 0.0 {
            self.counts.iter().map(|&c| c as u64).product()
        } else {
            0
        }
    }

    /// How many rods.
    pub fn rod_count(&self) -> u64 {
        (0..3).map(|a| self.rods_along(a)).sum()
    }

    /// How many rods run along axis `a`.
    fn rods_along(&self, a: usize) -> u64 {
        if self.rod_radius <= 0.0 {
            return 0;
        }
        let mut n = self.counts.map(|c| c as u64);
        n[a] -= 1;
        n.iter().product()
    }

    /// Every primitive: spheres and rods.
    pub fn len(&self) -> u64 {
        self.sphere_count() + self.rod_count()
    }

    /// Whether it has no primitive.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The position of node (i, j, k).
    pub fn node(&self, i: u32, j: u32, k: u32) -> DVec3 {
        self.origin + DVec3::new(i as f64, j as f64, k as f64) * self.spacing
    }

    fn node_at(&self, n: [u32; 3]) -> DVec3 {
        self.node(n[0], n[1], n[2])
    }

    fn sphere_at(&self, n: [u32; 3]) -> Primitive {
        Primitive::Sphere {
            center: self.node_at(n),
            radius: self.sphere_radius,
        }
    }

    fn rod_at(&self, a: usize, n: [u32; 3]) -> Primitive {
        let s = STEPS[a];
        Primitive::Capsule {
            a: self.node_at(n),
            b: self.node(n[0] + s[0], n[1] + s[1], n[2] + s[2]),
            radius: self.rod_radius,
        }
    }

    /// The spheres, in number order.
    pub fn spheres(&self) -> impl Iterator<Item = Primitive> + '_ {
        let [nx, ny, nz] = self.counts;
        let on = self.sphere_radius > 0.0;
        (0..nz).filter(move |_| on).flat_map(move |k| {
            (0..ny).flat_map(move |j| (0..nx).map(move |i| self.sphere_at([i, j, k])))
        })
    }

    /// One rod per edge between neighbouring nodes, in number order.
    pub fn rods(&self) -> impl Iterator<Item = Primitive> + '_ {
        let [nx, ny, nz] = self.counts;
        let on = self.rod_radius > 0.0;
        (0..3usize).filter(move |_| on).flat_map(move |a| {
            let [di, dj, dk] = STEPS[a];
            (0..nz - dk).flat_map(move |k| {
                (0..ny - dj).flat_map(move |j| (0..nx - di).map(move |i| self.rod_at(a, [i, j, k])))
            })
        })
    }

    /// Primitive number `id` (below [`len`](Self::len)).
    pub fn prim(&self, id: u64) -> Primitive {
        let spheres = self.sphere_count();
        if id < spheres {
            return self.sphere_at(unflatten(id, self.counts));
        }
        let mut id = id - spheres;
        for a in 0..3 {
            let here = self.rods_along(a);
            if id < here {
                let mut dims = self.counts;
                dims[a] -= 1;
                return self.rod_at(a, unflatten(id, dims));
            }
            id -= here;
        }
        panic!("lattice primitive {id} past its {}", self.len())
    }

    /// The number of the sphere at node `n`.
    fn sphere_id(&self, n: [u32; 3]) -> u64 {
        flatten(n, self.counts)
    }

    /// The number of the rod along axis `a` from node `n`.
    fn rod_id(&self, a: usize, n: [u32; 3]) -> u64 {
        let mut dims = self.counts;
        dims[a] -= 1;
        self.sphere_count() + (0..a).map(|b| self.rods_along(b)).sum::<u64>() + flatten(n, dims)
    }

    /// The primitive a block's member makes at lattice node `n` (`Blocks::place`): the same
    /// primitive, to the bit, as the one of that number.
    #[inline]
    pub fn member_prim(&self, n: [u32; 3], m: Member) -> Primitive {
        match m.axis {
            SPHERE => self.sphere_at(n),
            a => self.rod_at(a as usize, n),
        }
    }

    /// The number of the primitive a block's member makes at lattice node `n`.
    pub fn member_id(&self, n: [u32; 3], m: Member) -> u64 {
        match m.axis {
            SPHERE => self.sphere_id(n),
            a => self.rod_id(a as usize, n),
        }
    }

    /// The box holding every primitive: the same box as the union of their boxes, to the bit.
    pub fn bounds(&self) -> Aabb {
        let r = self.reach();
        let far = self.counts.map(|c| c - 1);
        Aabb::new(self.origin - r, self.node_at(far) + r)
    }

    /// How far primitives reach beyond the nodes: the larger radius of the kinds present.
    fn reach(&self) -> DVec3 {
        let rods = if self.rod_count() > 0 {
            self.rod_radius
        } else {
            0.0
        };
        let spheres = if self.sphere_count() > 0 {
            self.sphere_radius
        } else {
            0.0
        };
        DVec3::splat(rods.max(spheres))
    }

    /// The same lattice moved by `d`.
    pub fn translated(&self, d: DVec3) -> Lattice {
        Lattice {
            origin: self.origin + d,
            ..self.clone()
        }
    }
}

/// `n` as a number in the mixed radix `dims`, x fastest.
fn flatten(n: [u32; 3], dims: [u32; 3]) -> u64 {
    n[0] as u64 + dims[0] as u64 * (n[1] as u64 + dims[1] as u64 * n[2] as u64)
}

fn unflatten(id: u64, dims: [u32; 3]) -> [u32; 3] {
    let (x, y) = (dims[0] as u64, dims[1] as u64);
    [(id % x) as u32, (id / x % y) as u32, (id / x / y) as u32]
}

/// One of a block's primitives: the sphere at a local node, or the rod from it along an axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Member {
    /// The node within the block.
    pub local: [u32; 3],
    /// The rod's axis (0, 1, 2), or [`SPHERE`].
    pub axis: u32,
}

/// A [`Member`]'s axis when it is the sphere.
pub const SPHERE: u32 = 3;

/// A lattice cut into blocks of equal numbers of nodes, for backends that build one block and
/// place it at every block's corner (Embree instances, the f64 BVH's two levels). A block owns
/// its nodes' spheres and the rods that start at its nodes (along +x, +y, +z, so a block's last
/// rods reach into the next block); blocks on the far faces hold numbers for nodes and rods
/// the lattice does not have, which [`Blocks::sphere`] and [`Blocks::rod`] answer None for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blocks {
    /// Nodes per block along each axis.
    pub size: [u32; 3],
    /// Blocks along each axis.
    pub grid: [u32; 3],
}

impl Blocks {
    /// Blocks of about √n nodes a side for a lattice n nodes long, so that the block's
    /// primitives and the blocks number alike (4 s³ against (n / s)³).
    pub fn of(l: &Lattice) -> Blocks {
        let longest = *l.counts.iter().max().expect("three counts") as f64;
        let side = (longest.sqrt().ceil() as u32).clamp(2, 64);
        let size = l.counts.map(|c| c.min(side));
        let grid = [0, 1, 2].map(|a| l.counts[a].div_ceil(size[a]));
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

    /// Node (0, 0, 0) of block `b` in lattice node numbers.
    fn first_node(&self, b: [u32; 3]) -> [u32; 3] {
        [0, 1, 2].map(|a| b[a] * self.size[a])
    }

    /// Where block `b` sits: its first node's position, the origin of its local coordinates.
    pub fn corner(&self, l: &Lattice, b: [u32; 3]) -> DVec3 {
        l.node_at(self.first_node(b))
    }

    /// The block's local node `p` (below [`nodes`](Self::nodes)) in lattice node numbers
    /// (with `sphere` and `rod`, the tests' numbering by arithmetic, against `place`).
    #[cfg(test)]
    fn node_of(&self, b: [u32; 3], p: u32) -> [u32; 3] {
        let local = unflatten(p as u64, self.size);
        let first = self.first_node(b);
        [0, 1, 2].map(|a| first[a] + local[a])
    }

    /// The block's sphere `p` (below `nodes`) as a member.
    pub fn sphere_member(&self, p: u32) -> Member {
        Member {
            local: unflatten(p as u64, self.size),
            axis: SPHERE,
        }
    }

    /// The block's rod `p` (below 3 `nodes`: along axis p / nodes) as a member.
    pub fn rod_member(&self, p: u32) -> Member {
        Member {
            local: unflatten((p % self.nodes()) as u64, self.size),
            axis: p / self.nodes(),
        }
    }

    /// The lattice node of member `m` in the block whose first node is `first` (`first_node`),
    /// if the lattice has that primitive.
    #[inline]
    pub fn place(&self, l: &Lattice, first: [u32; 3], m: Member) -> Option<[u32; 3]> {
        let n = [0, 1, 2].map(|a| first[a] + m.local[a]);
        let step = |a: usize| u32::from(m.axis == a as u32);
        let inside = (0..3).all(|a| n[a] + step(a) < l.counts[a]);
        inside.then_some(n)
    }

    /// Node (0, 0, 0) of block `b` in lattice node numbers.
    pub fn first_of(&self, b: [u32; 3]) -> [u32; 3] {
        self.first_node(b)
    }

    /// The lattice's number of the sphere at the block's local node `p`, if it has one there.
    #[cfg(test)]
    fn sphere(&self, l: &Lattice, b: [u32; 3], p: u32) -> Option<u64> {
        let n = self.node_of(b, p);
        (n.iter().zip(&l.counts).all(|(i, c)| i < c)).then(|| l.sphere_id(n))
    }

    /// The lattice's number of the block's rod `p`: along axis p / nodes from local node
    /// p % nodes, if the lattice has it.
    #[cfg(test)]
    fn rod(&self, l: &Lattice, b: [u32; 3], p: u32) -> Option<u64> {
        let a = (p / self.nodes()) as usize;
        let n = self.node_of(b, p % self.nodes());
        let inside = (0..3).all(|k| n[k] + STEPS[a][k] < l.counts[k]);
        inside.then(|| l.rod_id(a, n))
    }

    /// The box of the block's sphere `p` in its local coordinates (relative to its corner).
    pub fn local_sphere(&self, l: &Lattice, p: u32) -> Aabb {
        let n = unflatten(p as u64, self.size);
        let c = local(l, n);
        let r = DVec3::splat(l.sphere_radius);
        Aabb::new(c - r, c + r)
    }

    /// The box of the block's rod `p` in its local coordinates.
    pub fn local_rod(&self, l: &Lattice, p: u32) -> Aabb {
        let a = (p / self.nodes()) as usize;
        let n = unflatten((p % self.nodes()) as u64, self.size);
        let s = STEPS[a];
        let start = local(l, n);
        let end = local(l, [n[0] + s[0], n[1] + s[1], n[2] + s[2]]);
        let r = DVec3::splat(l.rod_radius);
        Aabb::new(start - r, end + r)
    }

    /// The box, in the lattice's coordinates, of what block `b` holds that exists.
    pub fn bounds(&self, l: &Lattice, b: [u32; 3]) -> Aabb {
        let first = self.first_node(b);
        // The last node the block's primitives reach: its own last one, or the next block's
        // first where rods run into it.
        let last = [0, 1, 2].map(|a| (first[a] + self.size[a]).min(l.counts[a] - 1));
        let r = l.reach();
        Aabb::new(l.node_at(first) - r, l.node_at(last) + r)
    }

    /// How far a primitive's box in local coordinates may be from the primitive moved by the
    /// block's corner, for any block: what rounding the corner and the nodes' positions can
    /// make (a few units in the last place of the lattice's largest coordinate), with a
    /// thousandfold margin.
    pub fn local_slack(&self, l: &Lattice) -> f64 {
        1e-12 * (l.bounds().max_abs() + l.bounds().diagonal())
    }
}

/// Node n's position relative to node (0, 0, 0).
fn local(l: &Lattice, n: [u32; 3]) -> DVec3 {
    DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64) * l.spacing
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(counts: [u32; 3], rod: f64, sphere: f64) -> Lattice {
        Lattice {
            counts,
            spacing: DVec3::new(1.0, 0.75, 1.25),
            origin: DVec3::new(-3.3, 0.1, 7.0),
            rod_radius: rod,
            sphere_radius: sphere,
        }
    }

    /// Numbering a primitive and making it from its number agree with the lists the scene
    /// gave before, in order, and the analytic bounds with the union of the boxes.
    #[test]
    fn numbers_name_the_listed_primitives() {
        for (counts, rod, sphere) in [
            ([3, 4, 5], 0.05, 0.15),
            ([1, 4, 2], 0.05, 0.0),
            ([2, 1, 1], 0.0, 0.2),
            ([1, 1, 1], 0.05, 0.15),
            ([5, 1, 3], 0.3, 0.1),
        ] {
            let l = lattice(counts, rod, sphere);
            let listed: Vec<Primitive> = l.spheres().chain(l.rods()).collect();
            assert_eq!(listed.len() as u64, l.len());
            for (id, p) in listed.iter().enumerate() {
                assert_eq!(l.prim(id as u64), *p, "{counts:?} #{id}");
            }
            let union = listed.iter().fold(Aabb::EMPTY, |b, p| b.union(&p.bounds()));
            assert_eq!(l.bounds(), union, "{counts:?}");
        }
    }

    /// Every primitive of the lattice is in exactly one block, at its number, inside the
    /// block's bounds and (moved by the block's corner) inside its local box.
    #[test]
    fn blocks_cover_every_primitive_once() {
        for counts in [[7, 5, 3], [10, 10, 10], [1, 9, 2], [30, 4, 17]] {
            let l = lattice(counts, 0.05, 0.15);
            let blocks = Blocks::of(&l);
            let mut seen = vec![0u8; l.len() as usize];
            let slack = blocks.local_slack(&l);
            for b in 0..blocks.count() {
                let bp = blocks.block(b);
                let corner = blocks.corner(&l, bp);
                let bounds = blocks.bounds(&l, bp);
                let mut check = |id: Option<u64>, local: Aabb| {
                    let Some(id) = id else { return };
                    seen[id as usize] += 1;
                    let pb = l.prim(id).bounds();
                    assert!(bounds.min.cmple(pb.min).all() && pb.max.cmple(bounds.max).all());
                    let moved = Aabb::new(local.min + corner, local.max + corner);
                    let d = (moved.min - pb.min).abs().max((moved.max - pb.max).abs());
                    assert!(d.max_element() <= slack, "{counts:?} block {bp:?}: {d}");
                };
                let first = blocks.first_of(bp);
                let member = |m: Member| {
                    let n = blocks.place(&l, first, m)?;
                    assert_eq!(l.prim(l.member_id(n, m)), l.member_prim(n, m));
                    Some(l.member_id(n, m))
                };
                for p in 0..blocks.nodes() {
                    let id = blocks.sphere(&l, bp, p);
                    assert_eq!(member(blocks.sphere_member(p)), id);
                    check(id, blocks.local_sphere(&l, p));
                }
                for p in 0..3 * blocks.nodes() {
                    let id = blocks.rod(&l, bp, p);
                    assert_eq!(member(blocks.rod_member(p)), id);
                    check(id, blocks.local_rod(&l, p));
                }
            }
            assert!(seen.iter().all(|&n| n == 1), "{counts:?}");
        }
    }

    #[test]
    fn blocks_are_about_the_square_root_of_the_lattice() {
        let b = Blocks::of(&lattice([1000, 1000, 1000], 0.05, 0.15));
        assert_eq!((b.size, b.grid), ([32; 3], [32; 3]));
        let b = Blocks::of(&lattice([100, 3, 1], 0.05, 0.15));
        assert_eq!((b.size, b.grid), ([10, 3, 1], [10, 1, 1]));
    }
}
