//! Procedural objects for the paper's experiments, generated straight into primitive arrays so
//! that lattices of millions of primitives never pass through the scene file object by object.

use crate::geometry::Primitive;
use glam::DVec3;

/// A cubic lattice of nodes joined by rods along the three axes, with a sphere at each node.
#[derive(Clone, Debug, PartialEq)]
pub struct Lattice {
    pub counts: [u32; 3],
    pub spacing: DVec3,
    /// Position of node (0, 0, 0).
    pub origin: DVec3,
    pub rod_radius: f64,
    pub sphere_radius: f64,
}

impl Lattice {
    pub fn sphere_count(&self) -> u64 {
        if self.sphere_radius > 0.0 {
            self.counts.iter().map(|&c| c as u64).product()
        } else {
            0
        }
    }

    pub fn rod_count(&self) -> u64 {
        if self.rod_radius <= 0.0 {
            return 0;
        }
        let [x, y, z] = self.counts.map(|c| c as u64);
        (x - 1) * y * z + x * (y - 1) * z + x * y * (z - 1)
    }

    fn node(&self, i: u32, j: u32, k: u32) -> DVec3 {
        self.origin + DVec3::new(i as f64, j as f64, k as f64) * self.spacing
    }

    pub fn spheres(&self) -> impl Iterator<Item = Primitive> + '_ {
        let [nx, ny, nz] = self.counts;
        let on = self.sphere_radius > 0.0;
        (0..nz).filter(move |_| on).flat_map(move |k| {
            (0..ny).flat_map(move |j| {
                (0..nx).map(move |i| Primitive::Sphere {
                    center: self.node(i, j, k),
                    radius: self.sphere_radius,
                })
            })
        })
    }

    /// One rod per edge between neighbouring nodes.
    pub fn rods(&self) -> impl Iterator<Item = Primitive> + '_ {
        let [nx, ny, nz] = self.counts;
        let on = self.rod_radius > 0.0;
        let steps = [(1u32, 0u32, 0u32), (0, 1, 0), (0, 0, 1)];
        steps
            .into_iter()
            .filter(move |_| on)
            .flat_map(move |(di, dj, dk)| {
                (0..nz - dk).flat_map(move |k| {
                    (0..ny - dj).flat_map(move |j| {
                        (0..nx - di).map(move |i| Primitive::Capsule {
                            a: self.node(i, j, k),
                            b: self.node(i + di, j + dj, k + dk),
                            radius: self.rod_radius,
                        })
                    })
                })
            })
    }
}

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
