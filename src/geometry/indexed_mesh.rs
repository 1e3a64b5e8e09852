//! A triangle mesh held as itself: its vertices once, each triangle three indices into them, as
//! a mesh file has it. A big mesh costs its vertices and indices, not a primitive of its own
//! per triangle; its triangles are made from their numbers when asked, and backends take its
//! shared vertex buffer (Embree's triangle geometry) or build over its triangles (the BVH).
//! Vertices that are all f32 numbers (a binary PLY's, a glTF file's, placed as the file has
//! them) are held as f32, half the bytes, and widened to f64 exactly when read: the same
//! numbers either way.

use super::{Aabb, Primitive};
use glam::DVec3;

/// Vertices and triangles, in the group's rest frame.
#[derive(Clone, PartialEq)]
pub struct IndexedMesh {
    positions: Vertices,
    triangles: Vec<[u32; 3]>,
    bounds: Aabb,
    /// The digest of its numbers (`digest::mesh_digest`), made on first use.
    digest: super::digest::Memo,
}

/// A mesh's vertices: in f32 where every coordinate is an f32 number, else in f64.
#[derive(Clone, PartialEq)]
enum Vertices {
    Wide(Vec<DVec3>),
    Narrow(Vec<[f32; 3]>),
}

impl Vertices {
    /// `positions`, narrowed where that loses nothing.
    fn of(positions: Vec<DVec3>) -> Vertices {
        let is_f32 = |x: f64| f64::from(x as f32) == x;
        if positions
            .iter()
            .all(|p| is_f32(p.x) && is_f32(p.y) && is_f32(p.z))
        {
            Vertices::Narrow(
                positions
                    .iter()
                    .map(|p| [p.x as f32, p.y as f32, p.z as f32])
                    .collect(),
            )
        } else {
            Vertices::Wide(positions)
        }
    }

    fn len(&self) -> usize {
        match self {
            Vertices::Wide(v) => v.len(),
            Vertices::Narrow(v) => v.len(),
        }
    }

    #[inline(always)]
    fn at(&self, i: usize) -> DVec3 {
        match self {
            Vertices::Wide(v) => v[i],
            Vertices::Narrow(v) => {
                let [x, y, z] = v[i];
                DVec3::new(x.into(), y.into(), z.into())
            }
        }
    }

    fn bytes(&self) -> usize {
        match self {
            Vertices::Wide(v) => std::mem::size_of_val(v.as_slice()),
            Vertices::Narrow(v) => std::mem::size_of_val(v.as_slice()),
        }
    }
}

/// Its counts and a digest of its numbers, as [`Geometry`](super::Geometry)'s.
impl std::fmt::Debug for IndexedMesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("IndexedMesh")
            .field("positions", &self.vertex_count())
            .field("triangles", &self.triangles.len())
            .field(
                "digest",
                &format_args!("{:016x}", super::digest::mesh_digest(self)),
            )
            .finish()
    }
}

impl IndexedMesh {
    /// A mesh of these vertices and triangles (every index below `positions.len()`).
    pub fn new(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> IndexedMesh {
        debug_assert!(triangles
            .iter()
            .all(|t| t.iter().all(|&i| (i as usize) < positions.len())));
        // The union of the triangles' boxes: the vertices they use.
        let mut bounds = Aabb::EMPTY;
        for t in &triangles {
            for &i in t {
                bounds.grow(positions[i as usize]);
            }
        }
        IndexedMesh {
            positions: Vertices::of(positions),
            triangles,
            bounds,
            digest: Default::default(),
        }
    }

    /// Where its digest is kept.
    pub(super) fn digest_memo(&self) -> &super::digest::Memo {
        &self.digest
    }

    /// How many triangles.
    pub fn len(&self) -> u64 {
        self.triangles.len() as u64
    }

    /// Whether it has no triangle.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Triangle number `id` (below [`len`](Self::len)).
    #[inline]
    pub fn triangle(&self, id: u64) -> Primitive {
        let t = self.triangles[id as usize];
        Primitive::Triangle {
            v: t.map(|i| self.positions.at(i as usize)),
        }
    }

    /// Vertex number `i` (below [`vertex_count`](Self::vertex_count)).
    #[inline]
    pub fn position(&self, i: u32) -> DVec3 {
        self.positions.at(i as usize)
    }

    /// How many vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// The vertices, in order.
    pub fn positions(&self) -> impl ExactSizeIterator<Item = DVec3> + '_ {
        (0..self.vertex_count()).map(|i| self.positions.at(i))
    }

    /// The triangles, as indices into the vertices.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The box holding every triangle.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The same mesh moved by `d` (each vertex as `Primitive::translated` moves a corner).
    pub fn translated(&self, d: DVec3) -> IndexedMesh {
        IndexedMesh::new(
            self.positions().map(|p| p + d).collect(),
            self.triangles.clone(),
        )
    }

    /// The memory it holds, in bytes.
    pub fn bytes(&self) -> u64 {
        (self.positions.bytes() + std::mem::size_of_val(self.triangles.as_slice())) as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Vertices that are f32 numbers are held in f32, any other in f64, and read back as the
    /// same f64 numbers either way.
    #[test]
    fn vertices_are_held_narrow_only_where_that_loses_nothing() {
        let triangles = vec![[0, 1, 2], [2, 1, 3]];
        let exact = vec![
            DVec3::new(0.5, -0.0, f64::from(3.0e38f32)),
            DVec3::new(f64::from(-1.0e-38f32), 16_777_216.0, f64::from(0.1f32)),
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(
                f64::from(f32::MIN_POSITIVE) / 8.0,
                -7.25,
                f64::from(1.0e-3f32),
            ),
        ];
        // One number each that f32 does not hold: more digits, beyond its range, too small.
        let inexact = [
            DVec3::new(0.1, 0.0, 0.0),
            DVec3::new(0.0, 16_777_217.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0e39),
            DVec3::new(1.0e-46, 0.0, 0.0),
        ];
        let m = IndexedMesh::new(exact.clone(), triangles.clone());
        assert!(matches!(m.positions, Vertices::Narrow(_)));
        assert_eq!(m.bytes(), 4 * 12 + 2 * 12);
        let back: Vec<DVec3> = m.positions().collect();
        for (a, b) in back.iter().zip(&exact) {
            for k in 0..3 {
                assert_eq!(a[k].to_bits(), b[k].to_bits(), "{a} against {b}");
            }
        }
        assert_eq!(
            m.triangle(1),
            Primitive::Triangle {
                v: [exact[2], exact[1], exact[3]]
            }
        );
        for p in inexact {
            let mut positions = exact.clone();
            positions[3] = p;
            let m = IndexedMesh::new(positions.clone(), triangles.clone());
            assert!(matches!(m.positions, Vertices::Wide(_)), "{p}");
            assert_eq!(m.position(3), p);
            assert_eq!(m.bytes(), 4 * 24 + 2 * 12);
        }
    }
}
