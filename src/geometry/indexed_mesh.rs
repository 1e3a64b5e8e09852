//! A triangle mesh held as itself: its vertices once, each triangle three indices into them, as
//! a mesh file has it. A big mesh costs its vertices and indices, not a primitive of its own
//! per triangle; its triangles are made from their numbers when asked, and backends take its
//! shared vertex buffer (Embree's triangle geometry) or build over its triangles (the BVH).

use super::{Aabb, Primitive};
use glam::DVec3;

/// Vertices and triangles, in the group's rest frame.
#[derive(Clone, PartialEq)]
pub struct IndexedMesh {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    bounds: Aabb,
    /// The digest of its numbers (`digest::mesh_digest`), made on first use.
    digest: super::digest::Memo,
}

/// Its counts and a digest of its numbers, as [`Geometry`](super::Geometry)'s.
impl std::fmt::Debug for IndexedMesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("IndexedMesh")
            .field("positions", &self.positions.len())
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
            positions,
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
            v: t.map(|i| self.positions[i as usize]),
        }
    }

    /// The vertices.
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
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
            self.positions.iter().map(|&p| p + d).collect(),
            self.triangles.clone(),
        )
    }

    /// The memory it holds, in bytes.
    pub fn bytes(&self) -> u64 {
        (self.positions.len() * std::mem::size_of::<DVec3>()
            + self.triangles.len() * std::mem::size_of::<[u32; 3]>()) as u64
    }
}
