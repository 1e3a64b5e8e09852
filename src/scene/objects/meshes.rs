//! Mesh entries: `mesh` from a file (held as itself, or once for several placements) or given
//! inline, and `instance`; the mesh files' materials and the scene's limits for them.

use super::{at_value, budget, material_ref, Adding};
use crate::geometry::{Geometry, Implicit, Primitive};
use crate::scene::reader::{SceneResult, Table};
use crate::scene::shared_meshes::SharedMeshes;
use crate::scene::transform::Transform;
use glam::DVec3;
use std::collections::HashMap;

/// A mesh file of at most [`INSTANCE_OVER`](crate::geometry::INSTANCE_OVER) triangles is listed
/// triangle by triangle, counting against the scene's limit as any object does; a bigger one is
/// held as itself (shared vertices), its memory checked as such, corner data included.
fn mesh_budget(
    t: &Table,
    total: &mut u64,
    mesh: &crate::scene::mesh_file::MeshData,
    key: &str,
) -> SceneResult<()> {
    use crate::memory::{BYTES_PER_CORNER_NORMALS, BYTES_PER_CORNER_UVS, BYTES_PER_HELD_TRIANGLE};
    let n = mesh.triangles.len() as u64;
    let corners = u64::from(mesh.normals.is_some()) * BYTES_PER_CORNER_NORMALS
        + u64::from(mesh.uvs.is_some()) * BYTES_PER_CORNER_UVS;
    if n <= crate::geometry::INSTANCE_OVER {
        return budget(t, key, total, n);
    }
    let need = n.saturating_mul(BYTES_PER_HELD_TRIANGLE + corners);
    let what = format!("a mesh of {n} triangles");
    if let Some(why) = crate::memory::too_much(need, &what) {
        return Err(at_value(t, key, why));
    }
    Ok(())
}

/// The scene material of each material a mesh file names (OBJ's `usemtl`): the one
/// `materials = { file_name = "scene_name" }` gives, else the scene's material of the same
/// name, else the object's `material`.
pub(in crate::scene) fn file_materials(
    t: &Table,
    in_file: &[String],
    mats: &HashMap<String, u32>,
    default: u32,
    mut chosen: Vec<u32>,
) -> SceneResult<Vec<u32>> {
    if let Some(map) = t.table("materials")? {
        let keys: Vec<&str> = map.keys().collect();
        for k in keys {
            let Some(i) = in_file.iter().position(|n| n == k) else {
                let named = if in_file.is_empty() {
                    "the file names no materials".to_string()
                } else {
                    format!("the file's materials: {}", in_file.join(", "))
                };
                return Err(map.error_at(
                    map.get(k).expect("a key of the table"),
                    k,
                    format!("the file has no material `{k}` ({named})"),
                ));
            };
            chosen[i] = material_ref(&map, k, mats, default)?;
        }
    }
    Ok(chosen)
}

/// The mesh `file` names, relative to the scene file's folder; errors name the scene's line
/// and key, and the mesh file with its own line.
fn read_mesh_file(t: &Table) -> SceneResult<crate::scene::mesh_file::MeshData> {
    let name = t.req_string("file")?;
    read_mesh_at(t, "file", t.path_beside(name))
}

/// The mesh file at `path`, which `t`'s `key` names; errors name the scene's line and key, and
/// the mesh file with its own line.
fn read_mesh_at(
    t: &Table,
    key: &str,
    path: std::path::PathBuf,
) -> SceneResult<crate::scene::mesh_file::MeshData> {
    let node = t.get(key).expect("read by the caller");
    if let Ok(m) = std::fs::metadata(&path) {
        let need = m
            .len()
            .saturating_mul(crate::scene::mesh_file::BYTES_PER_FILE_BYTE);
        let what = format!(
            "reading the mesh file {} ({})",
            path.display(),
            crate::memory::human(m.len())
        );
        if let Some(why) = crate::memory::too_much(need, &what) {
            return Err(t.error_at(node, key, why));
        }
    }
    crate::scene::mesh_file::read(&path).map_err(|e| {
        let at = e.line.map_or(String::new(), |l| format!(":{l}"));
        t.error_at(node, key, format!("{}{at}: {}", path.display(), e.message))
    })
}

/// A mesh as read (from any file) as an object held as itself in `geo`: placed by `transform`,
/// its file's materials `chosen` (by index), remapped by the entry's `materials` table, those
/// it names none `mat`.
#[allow(clippy::too_many_arguments)]
pub(in crate::scene) fn add_mesh_data(
    t: &Table,
    id: u32,
    mat: u32,
    transform: Option<Transform>,
    geo: &mut Geometry,
    total: &mut u64,
    mut mesh: crate::scene::mesh_file::MeshData,
    chosen: Vec<u32>,
    mats: &HashMap<String, u32>,
) -> SceneResult<()> {
    mesh_budget(t, total, &mesh, "file")?;
    // The corner data, moved out of the mesh as read; normals turn with the mesh and
    // take the inverse of its scale.
    let normals = match transform {
        Some(x) => mesh.normals.take().map(|n| {
            let turn = |n: DVec3| (x.rotation * (n / x.scale)).normalize_or_zero();
            n.into_iter().map(|c| c.map(turn)).collect()
        }),
        None => mesh.normals.take(),
    };
    let uvs = mesh.uvs.take();
    let corners =
        (normals.is_some() || uvs.is_some()).then_some(crate::geometry::Corners { normals, uvs });
    // Runs of triangles of one material, each a part of the object.
    let chosen = file_materials(t, &mesh.materials, mats, mat, chosen)?;
    let material_of = |i: usize| match mesh.material_of.get(i) {
        Some(&m) if m != crate::scene::mesh_file::NO_MATERIAL => chosen[m as usize],
        _ => mat,
    };
    let n = mesh.triangles.len();
    let mut bounds = Vec::new();
    let mut start = 0;
    while start < n {
        let m = material_of(start);
        let end = (start + 1..n).find(|&i| material_of(i) != m).unwrap_or(n);
        bounds.push((start, end, m));
        start = end;
    }
    // One material: the corner data as read, not a copy of it.
    let runs: Vec<_> = match (bounds.as_slice(), corners) {
        ([(_, _, m)], c) => vec![(n as u64, *m, c.map(std::sync::Arc::new))],
        (_, c) => bounds
            .iter()
            .map(|&(start, end, m)| {
                let part = c.as_ref().map(|c| {
                    std::sync::Arc::new(crate::geometry::Corners {
                        normals: c.normals.as_ref().map(|v| v[start..end].to_vec()),
                        uvs: c.uvs.as_ref().map(|v| v[start..end].to_vec()),
                    })
                });
                ((end - start) as u64, m, part)
            })
            .collect(),
    };
    // Held as itself: its vertices once, placed, and its triangles' indices.
    let positions = match transform {
        Some(x) => mesh.positions.iter().map(|&p| x.point(p)).collect(),
        None => mesh.positions,
    };
    let shape = Implicit::Mesh(std::sync::Arc::new(crate::geometry::IndexedMesh::new(
        positions,
        mesh.triangles,
    )));
    geo.push_implicit_with(id, &runs, shape)
        .map_err(|why| at_value(t, "file", why.to_string()))?;
    Ok(())
}

impl Adding<'_, '_> {
    /// A mesh read from `file`, held as itself: its vertices once and its triangles' indices,
    /// in runs of one material each (`mats`: the scene's materials by name).
    pub(super) fn add_mesh_file(&mut self, mats: &HashMap<String, u32>) -> SceneResult<()> {
        let (t, id, mat, transform) = (self.t, self.id, self.mat, self.transform);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        if let Some(k) = ["vertices", "indices"].into_iter().find(|k| t.has(k)) {
            return Err(at_value(
                t,
                k,
                "a mesh is given by `file` or by `vertices` and `indices`, not both",
            ));
        }
        let mesh = read_mesh_file(t)?;
        let chosen = mesh
            .materials
            .iter()
            .map(|n| mats.get(n).copied().unwrap_or(mat))
            .collect();
        add_mesh_data(t, id, mat, transform, geo, total, mesh, chosen, mats)
    }

    /// A mesh file placed more than once in the scene (by `file`, or an instance's `of`, the
    /// entry's `key`), held once: this entry one placement of it.
    pub(super) fn add_shared_mesh(
        &mut self,
        mats: &HashMap<String, u32>,
        meshes: &mut SharedMeshes,
        key: &str,
        path: std::path::PathBuf,
    ) -> SceneResult<()> {
        let (t, id, mat, transform) = (self.t, self.id, self.mat, self.transform);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        if let Some(k) = ["vertices", "indices"].into_iter().find(|k| t.has(k)) {
            return Err(at_value(
                t,
                k,
                "a mesh is given by `file` or by `vertices` and `indices`, not both",
            ));
        }
        let shared = meshes.get(path.clone(), || {
            let mesh = read_mesh_at(t, key, path)?;
            mesh_budget(t, total, &mesh, "file")?;
            Ok(mesh)
        })?;
        // Each placement costs a little of its own; the mesh was counted when read.
        budget(t, "type", total, 1)?;
        let names = shared.materials();
        let chosen = names
            .iter()
            .map(|n| mats.get(n).copied().unwrap_or(mat))
            .collect();
        let chosen = file_materials(t, names, mats, mat, chosen)?;
        shared
            .place(id, mat, transform, &chosen, geo)
            .map_err(|why| at_value(t, key, why.to_string()))
    }

    /// A mesh given inline (`vertices`, `indices`), one primitive per triangle.
    pub(super) fn add_inline_mesh(&mut self) -> SceneResult<()> {
        let (t, id, mat, transform) = (self.t, self.id, self.mat, self.transform);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        let vn = t
            .get("vertices")
            .ok_or_else(|| t.error("vertices", "missing: give [[x, y, z], ...]"))?;
        let verts = match &vn.val {
            crate::scene::doc::Val::Array(items) => items
                .iter()
                .map(|e| t.vec3_of(e, "vertices"))
                .collect::<SceneResult<Vec<_>>>()?,
            _ => return Err(t.error_at(vn, "vertices", "expected an array of [x, y, z]")),
        };
        let inn = t
            .get("indices")
            .ok_or_else(|| t.error("indices", "missing: give [[i, j, k], ...]"))?;
        let tris = match &inn.val {
            crate::scene::doc::Val::Array(items) => items
                .iter()
                .map(|e| {
                    let v = t.numbers_of(e, "indices", Some(3))?;
                    let mut idx = [0usize; 3];
                    for (k, x) in v.iter().enumerate() {
                        if x.fract() != 0.0 || *x < 0.0 || *x as usize >= verts.len() {
                            return Err(t.error_at(
                                e,
                                "indices",
                                format!("index {x} is not a vertex (there are {})", verts.len()),
                            ));
                        }
                        idx[k] = *x as usize;
                    }
                    Ok(Primitive::Triangle {
                        v: idx.map(|i| transform.map_or(verts[i], |x| x.point(verts[i]))),
                    })
                })
                .collect::<SceneResult<Vec<_>>>()?,
            _ => return Err(t.error_at(inn, "indices", "expected an array of [i, j, k]")),
        };
        if tris.is_empty() {
            return Err(t.error_at(inn, "indices", "the mesh has no triangles"));
        }
        budget(t, "type", total, tris.len() as u64)?;
        geo.push_part(id, mat, tris);
        Ok(())
    }
}
