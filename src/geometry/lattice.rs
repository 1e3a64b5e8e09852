//! The paper's rod-and-sphere lattice as an implicit object: its primitives are numbered, and
//! made from their number when asked, so that a lattice of a billion nodes costs no memory per
//! primitive. Backends that instance it cut it into equal blocks of nodes ([`Blocks`]): one
//! block's primitives, placed at every block's corner, with the primitives that do not exist
//! (past the lattice's far faces) skipped by number.

use super::implicit::{flatten, unflatten, Member, SPHERE};
use super::{Aabb, Primitive};
use glam::DVec3;

/// A cubic lattice of nodes joined by rods along the three axes, with a sphere at each node.
///
/// Its primitives, numbered from 0 (the order the scene lists them in, which is also the
/// order of [`spheres`](Self::spheres) then [`rods`](Self::rods)): the spheres, node (i, j, k)
/// at `i + nx (j + ny k)`; then the rods along x, along y and along z, each run numbered by
/// the node the rod starts from within the nodes such rods start from.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
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

    /// The position of node `n`.
    pub fn node_at(&self, n: [u32; 3]) -> DVec3 {
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

    /// The box of member `m` relative to its block's first node.
    pub fn local_box(&self, m: Member) -> Aabb {
        let start = local(self, m.local);
        if m.axis == SPHERE {
            let r = DVec3::splat(self.sphere_radius);
            return Aabb::new(start - r, start + r);
        }
        let s = STEPS[m.axis as usize];
        let n = m.local;
        let end = local(self, [n[0] + s[0], n[1] + s[1], n[2] + s[2]]);
        let r = DVec3::splat(self.rod_radius);
        Aabb::new(start - r, end + r)
    }

    /// How far primitives reach beyond the nodes: the larger radius of the kinds present.
    pub fn reach(&self) -> DVec3 {
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

/// Node n's position relative to node (0, 0, 0).
fn local(l: &Lattice, n: [u32; 3]) -> DVec3 {
    DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64) * l.spacing
}
