//! One mesh placed many times (`Implicit::Instance`): the mesh held once in its own
//! coordinates, shared (`Arc`) by every placement, and each placement an [`Affine`] map. A
//! placement's triangles are made when asked, each corner placed by the same arithmetic a
//! mesh placed by copying its vertices uses (`Affine::point`), so an instance and the copy find
//! the same triangles to the bit. Backends build one structure over the mesh and trace rays
//! moved into each placement's frame (Embree's instance geometry; the f64 BVH's
//! `accel/instance_tree.rs`), testing the placed triangle itself.

use super::{Aabb, IndexedMesh, Primitive};
use glam::{DMat3, DVec3};
use std::sync::Arc;

/// Where a mesh's own coordinates go: scaled along its axes, then the linear map, then moved.
/// From a scene file the linear map is a rotation (`scale`, `rotate`, `translate`); from a
/// glTF node's matrix it is any invertible 3x3 map with a unit scale.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Affine {
    /// Applied first, along the object's own axes.
    pub scale: DVec3,
    /// Then this map.
    pub linear: DMat3,
    /// Then moved by this.
    pub translate: DVec3,
    /// What turns a normal (after dividing by `scale`): `linear`'s inverse transpose, which is
    /// `linear` itself for a rotation.
    pub normal_linear: DMat3,
    /// `linear`'s inverse, which takes rays back into the object's coordinates.
    pub inverse: DMat3,
}

impl Affine {
    /// Nothing moved.
    pub const IDENTITY: Affine = Affine {
        scale: DVec3::ONE,
        linear: DMat3::IDENTITY,
        translate: DVec3::ZERO,
        normal_linear: DMat3::IDENTITY,
        inverse: DMat3::IDENTITY,
    };

    /// `scale`, then the rotation `rotation`, then `translate`.
    pub fn rigid(scale: DVec3, rotation: DMat3, translate: DVec3) -> Affine {
        Affine {
            scale,
            linear: rotation,
            translate,
            normal_linear: rotation,
            inverse: rotation.transpose(),
        }
    }

    /// Any invertible linear map, then `translate` (None where `linear` is singular).
    pub fn general(linear: DMat3, translate: DVec3) -> Option<Affine> {
        let det = linear.determinant();
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inverse = linear.inverse();
        Some(Affine {
            scale: DVec3::ONE,
            linear,
            translate,
            normal_linear: inverse.transpose(),
            inverse,
        })
    }

    /// Where a point of the object goes.
    #[inline]
    pub fn point(&self, p: DVec3) -> DVec3 {
        self.linear * (self.scale * p) + self.translate
    }

    /// Where a normal of the object turns (unit; zero for a zero normal).
    #[inline]
    pub fn normal(&self, n: DVec3) -> DVec3 {
        (self.normal_linear * (n / self.scale)).normalize_or_zero()
    }

    /// A point of the placed object back in the object's coordinates (up to rounding).
    #[inline]
    pub fn local_point(&self, p: DVec3) -> DVec3 {
        (self.inverse * (p - self.translate)) / self.scale
    }

    /// A direction back in the object's coordinates: a ray's t is the same in both frames.
    #[inline]
    pub fn local_dir(&self, d: DVec3) -> DVec3 {
        (self.inverse * d) / self.scale
    }

    /// The same placement moved by `d`.
    pub fn translated(&self, d: DVec3) -> Affine {
        Affine {
            translate: self.translate + d,
            ..*self
        }
    }

    /// A box holding everything of `b` placed: its corners' box, padded by far more than the
    /// placing's rounding.
    pub fn placed_box(&self, b: &Aabb) -> Aabb {
        if b.min.cmpgt(b.max).any() {
            return Aabb::EMPTY;
        }
        let mut out = Aabb::EMPTY;
        for c in b.corners() {
            out.grow(self.point(c));
        }
        let pad = 1e-12 * (out.max_abs() + out.diagonal());
        Aabb::new(out.min - DVec3::splat(pad), out.max + DVec3::splat(pad))
    }
}

/// A shared mesh at one placement.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshInstance {
    /// The mesh in its own coordinates, the same `Arc` for every placement of it.
    pub mesh: Arc<IndexedMesh>,
    /// This placement.
    pub place: Affine,
    /// The placed mesh's box (`Affine::placed_box`), made once.
    bounds: Aabb,
}

impl MeshInstance {
    /// `mesh` at `place`.
    pub fn new(mesh: Arc<IndexedMesh>, place: Affine) -> MeshInstance {
        let bounds = place.placed_box(&mesh.bounds());
        MeshInstance {
            mesh,
            place,
            bounds,
        }
    }

    /// How many triangles.
    pub fn len(&self) -> u64 {
        self.mesh.len()
    }

    /// Whether it has no triangle.
    pub fn is_empty(&self) -> bool {
        self.mesh.is_empty()
    }

    /// Triangle `id`, placed.
    #[inline]
    pub fn triangle(&self, id: u64) -> Primitive {
        let t = self.mesh.triangles()[id as usize];
        Primitive::Triangle {
            v: t.map(|i| self.place.point(self.mesh.position(i))),
        }
    }

    /// A box holding every placed triangle (not their union to the bit: a little larger).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The same placement moved by `d`.
    pub fn translated(&self, d: DVec3) -> MeshInstance {
        MeshInstance::new(self.mesh.clone(), self.place.translated(d))
    }

    /// The mesh copied to this placement: what the instance stands for.
    pub fn copied(&self) -> IndexedMesh {
        IndexedMesh::new(
            self.mesh.positions().map(|p| self.place.point(p)).collect(),
            self.mesh.triangles().to_vec(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn turned() -> Affine {
        Affine::rigid(
            DVec3::new(2.0, 0.5, 3.0),
            DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7),
            DVec3::new(10.0, -4.0, 1e3),
        )
    }

    #[test]
    fn points_go_back_where_they_came_from() {
        let a = turned();
        let g = Affine::general(
            DMat3::from_cols_array(&[1.0, 0.2, 0.0, 0.0, 2.0, 0.3, 0.5, 0.0, 1.5]),
            DVec3::new(1.0, 2.0, 3.0),
        )
        .unwrap();
        for x in [a, g] {
            for p in [DVec3::new(0.3, -1.0, 2.0), DVec3::new(-5.0, 7.0, 0.1)] {
                assert!((x.local_point(x.point(p)) - p).length() < 1e-12 * 1e3);
                // A ray's t is kept: o + t d placed is the placed o plus t times the placed d.
                let d = DVec3::new(0.2, 0.9, -0.4);
                let back = x.local_point(x.point(p) + 2.5 * (x.point(p + d) - x.point(p)));
                let along =
                    x.local_point(x.point(p)) + 2.5 * x.local_dir(x.point(p + d) - x.point(p));
                assert!((back - along).length() < 1e-9, "{back} {along}");
            }
        }
        assert!(Affine::general(DMat3::ZERO, DVec3::ZERO).is_none());
    }

    #[test]
    fn normals_stay_normal_to_placed_faces() {
        // A face's two edges placed, and its normal placed, stay at right angles (a
        // non-uniform scale and a shear included).
        let shear = Affine::general(
            DMat3::from_cols_array(&[1.0, 0.0, 0.0, 0.8, 1.0, 0.0, 0.0, 0.0, 2.0]),
            DVec3::ZERO,
        )
        .unwrap();
        for x in [turned(), shear] {
            let (e1, e2) = (DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0));
            let n = x.normal(e1.cross(e2));
            let (p1, p2) = (
                x.point(e1) - x.point(DVec3::ZERO),
                x.point(e2) - x.point(DVec3::ZERO),
            );
            assert!(n.dot(p1).abs() < 1e-12 && n.dot(p2).abs() < 1e-12, "{n}");
            assert!((n.length() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn an_instance_is_its_copy() {
        let mesh = Arc::new(IndexedMesh::new(
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.3),
                DVec3::new(1.0, 1.0, -2.0),
            ],
            vec![[0, 1, 2], [1, 3, 2]],
        ));
        let inst = MeshInstance::new(mesh, turned());
        let copy = inst.copied();
        for i in 0..2 {
            assert_eq!(inst.triangle(i), copy.triangle(i));
        }
        // Its box holds the copy's, by little more.
        let (b, c) = (inst.bounds(), copy.bounds());
        assert!(b.min.cmple(c.min).all() && b.max.cmpge(c.max).all());
        assert!(b.diagonal() < 2.0 * c.diagonal());
        assert_eq!(
            inst.translated(DVec3::X).place.translate,
            turned().translate + DVec3::X
        );
    }
}
