//! The paper's bar array as an implicit object, numbered as the lattice is (`lattice.rs`): bar
//! (i, j) is number `i + n1 j`, the order the scene always listed them in.

use super::implicit::{flatten, unflatten, Member};
use super::{Aabb, Primitive};
use glam::DVec3;

/// An `n × m` array of box-shaped bars, all along one axis, laid out in the perpendicular plane.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BarArray {
    /// Bars along the two plane axes.
    pub counts: [u32; 2],
    /// From one bar's centre to the next along the two plane axes.
    pub spacing: [f64; 2],
    /// Cross-section of a bar along the two plane axes.
    pub bar_size: [f64; 2],
    /// Each bar's length along `axis`.
    pub length: f64,
    /// 0, 1, 2 for x, y, z.
    pub axis: usize,
    /// Centre of the whole array.
    pub center: DVec3,
}

impl BarArray {
    /// The plane's two axes, in the order of `counts`.
    fn plane(&self) -> (usize, usize) {
        match self.axis {
            0 => (1, 2),
            1 => (2, 0),
            _ => (0, 1),
        }
    }

    /// The grid of bars as a grid of nodes: `[n1, n2, 1]`.
    pub fn grid(&self) -> [u32; 3] {
        [self.counts[0], self.counts[1], 1]
    }

    /// How many bars.
    pub fn len(&self) -> u64 {
        self.counts.iter().map(|&c| c as u64).product()
    }

    /// Whether it has no bar.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The centre of bar (`n[0]`, `n[1]`).
    pub fn node_at(&self, n: [u32; 3]) -> DVec3 {
        let (a1, a2) = self.plane();
        let [n1, n2] = self.counts;
        let mut c = self.center;
        c[a1] += (n[0] as f64 - (n1 - 1) as f64 / 2.0) * self.spacing[0];
        c[a2] += (n[1] as f64 - (n2 - 1) as f64 / 2.0) * self.spacing[1];
        c
    }

    /// A bar's half size along x, y and z.
    pub fn reach(&self) -> DVec3 {
        let (a1, a2) = self.plane();
        let mut h = DVec3::ZERO;
        h[a1] = self.bar_size[0] / 2.0;
        h[a2] = self.bar_size[1] / 2.0;
        h[self.axis] = self.length / 2.0;
        h
    }

    fn bar_at(&self, n: [u32; 3]) -> Primitive {
        let (c, h) = (self.node_at(n), self.reach());
        Primitive::Cuboid {
            min: c - h,
            max: c + h,
        }
    }

    /// The bars, in number order.
    pub fn bars(&self) -> impl Iterator<Item = Primitive> + '_ {
        (0..self.len()).map(|id| self.prim(id))
    }

    /// Bar number `id` (below [`len`](Self::len)).
    pub fn prim(&self, id: u64) -> Primitive {
        self.bar_at(unflatten(id, self.grid()))
    }

    /// The bar a block's member makes at node `n`.
    pub fn member_prim(&self, n: [u32; 3], _: Member) -> Primitive {
        self.bar_at(n)
    }

    /// The number of the bar at node `n`.
    pub fn member_id(&self, n: [u32; 3], _: Member) -> u64 {
        flatten(n, self.grid())
    }

    /// The box of member `m` relative to its block's first bar's centre.
    pub fn local_box(&self, m: Member) -> Aabb {
        let (a1, a2) = self.plane();
        let mut c = DVec3::ZERO;
        c[a1] = m.local[0] as f64 * self.spacing[0];
        c[a2] = m.local[1] as f64 * self.spacing[1];
        let h = self.reach();
        Aabb::new(c - h, c + h)
    }

    /// The box holding every bar: the union of their boxes, to the bit.
    pub fn bounds(&self) -> Aabb {
        let h = self.reach();
        let [n1, n2] = self.counts;
        Aabb::new(
            self.node_at([0; 3]) - h,
            self.node_at([n1 - 1, n2 - 1, 0]) + h,
        )
    }

    /// The same array moved by `d`.
    pub fn translated(&self, d: DVec3) -> BarArray {
        BarArray {
            center: self.center + d,
            ..self.clone()
        }
    }
}
