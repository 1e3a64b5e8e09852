//! Procedural objects for the paper's experiments, generated straight into primitive arrays so
//! that lattices of millions of primitives never pass through the scene file object by object.

pub use crate::geometry::Lattice;
use crate::geometry::Primitive;
use glam::DVec3;

/// An `n × m` array of box-shaped bars, all along one axis, laid out in the perpendicular plane.
#[derive(Clone, Debug, PartialEq)]
pub struct BarArray {
    pub counts: [u32; 2],
    pub spacing: [f64; 2],
    /// Cross-section of a bar along the two plane axes.
    pub bar_size: [f64; 2],
    pub length: f64,
    /// 0, 1, 2 for x, y, z.
    pub axis: usize,
    /// Centre of the whole array.
    pub center: DVec3,
}

impl BarArray {
    pub fn bars(&self) -> impl Iterator<Item = Primitive> + '_ {
        let (a1, a2) = match self.axis {
            0 => (1, 2),
            1 => (2, 0),
            _ => (0, 1),
        };
        let [n1, n2] = self.counts;
        (0..n2).flat_map(move |j| {
            (0..n1).map(move |i| {
                let mut c = self.center;
                c[a1] += (i as f64 - (n1 - 1) as f64 / 2.0) * self.spacing[0];
                c[a2] += (j as f64 - (n2 - 1) as f64 / 2.0) * self.spacing[1];
                let mut h = DVec3::ZERO;
                h[a1] = self.bar_size[0] / 2.0;
                h[a2] = self.bar_size[1] / 2.0;
                h[self.axis] = self.length / 2.0;
                Primitive::Cuboid {
                    min: c - h,
                    max: c + h,
                }
            })
        })
    }
}
