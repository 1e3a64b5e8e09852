//! Objects of a velocity group: boxes, spheres, rods, meshes and the procedural lattice and bars,
//! read into rest-frame primitives within the scene's limits.

use super::procedural::{BarArray, Lattice};
use super::reader::{SceneResult, Table};
use super::shared_meshes::SharedMeshes;
use super::transform::{Transform, KEYS};
use crate::geometry::{Blocks, Implicit};
use crate::geometry::{Geometry, Primitive};
use glam::DVec3;
use std::collections::HashMap;

/// The most primitives one scene may hold (a guard against typos like `counts = [1000000, ...]`).
pub(crate) const MAX_PRIMITIVES: u64 = 200_000_000;

pub(super) const OBJECT_KEYS: &[&str] = &[
    "type",
    "name",
    "material",
    "min",
    "max",
    "center",
    "radius",
    "from",
    "to",
    "vertices",
    "indices",
    "counts",
    "spacing",
    "origin",
    "rod_radius",
    "sphere_radius",
    "rod_material",
    "sphere_material",
    "bar_size",
    "length",
    "axis",
    "file",
    "materials",
    "translate",
    "rotate",
    "scale",
    "spin",
    "spokes",
    "rim_segments",
    "hub_radius",
    "groups",
    "time_scale",
    "camera",
    "of",
];

fn material_ref(
    t: &Table,
    key: &str,
    ids: &HashMap<String, u32>,
    default: u32,
) -> SceneResult<u32> {
    match t.string(key)? {
        None => Ok(default),
        Some(name) => ids.get(name).copied().ok_or_else(|| {
            let mut known: Vec<&str> = ids.keys().map(String::as_str).collect();
            known.sort();
            let n = t.get(key).expect("read above");
            t.error_at(
                n,
                key,
                format!(
                    "no material named `{name}` (materials: {})",
                    if known.is_empty() {
                        "none defined".into()
                    } else {
                        known.join(", ")
                    }
                ),
            )
        }),
    }
}

pub(super) fn budget(t: &Table, key: &str, total: &mut u64, add: u64) -> SceneResult<()> {
    *total = total.saturating_add(add);
    if *total > MAX_PRIMITIVES {
        return Err(t.error(
            key,
            format!(
                "the scene would hold {} primitives, more than the limit of {MAX_PRIMITIVES}",
                *total
            ),
        ));
    }
    let what = format!("a scene of {} primitives", *total);
    let need = total.saturating_mul(crate::memory::BYTES_PER_PRIMITIVE);
    if let Some(why) = crate::memory::too_much(need, &what) {
        return Err(t.error(key, why));
    }
    Ok(())
}

/// A lattice or bar array is held as itself, whatever its size: rendered, one of more than
/// [`INSTANCE_OVER`](crate::geometry::INSTANCE_OVER) primitives is built from one block of them
/// (`Blocks`), costing the block's primitives and one placement per block; a smaller one is
/// listed primitive by primitive, counting against the scene's limit as any object does.
fn implicit_budget(t: &Table, total: &mut u64, shape: &Implicit) -> SceneResult<()> {
    if shape.len() <= crate::geometry::INSTANCE_OVER {
        return budget(t, "counts", total, shape.len());
    }
    let what = format!(
        "an object of {} primitives in {} blocks",
        shape.len(),
        Blocks::of(shape.grid()).count()
    );
    if let Some(why) = crate::memory::too_much(crate::memory::implicit_bytes(shape), &what) {
        return Err(at_value(t, "counts", why));
    }
    Ok(())
}

/// A mesh file of at most [`INSTANCE_OVER`](crate::geometry::INSTANCE_OVER) triangles is listed
/// triangle by triangle, counting against the scene's limit as any object does; a bigger one is
/// held as itself (shared vertices), its memory checked as such, corner data included.
fn mesh_budget(t: &Table, total: &mut u64, mesh: &super::mesh_file::MeshData) -> SceneResult<()> {
    use crate::memory::{BYTES_PER_CORNER_NORMALS, BYTES_PER_CORNER_UVS, BYTES_PER_HELD_TRIANGLE};
    let n = mesh.triangles.len() as u64;
    let corners = u64::from(mesh.normals.is_some()) * BYTES_PER_CORNER_NORMALS
        + u64::from(mesh.uvs.is_some()) * BYTES_PER_CORNER_UVS;
    if n <= crate::geometry::INSTANCE_OVER {
        return budget(t, "file", total, n);
    }
    let need = n.saturating_mul(BYTES_PER_HELD_TRIANGLE + corners);
    let what = format!("a mesh of {n} triangles");
    if let Some(why) = crate::memory::too_much(need, &what) {
        return Err(at_value(t, "file", why));
    }
    Ok(())
}

/// An error about the value of `key` (on its line), or the table's where it has none.
fn at_value(t: &Table, key: &str, why: impl Into<String>) -> super::SceneError {
    match t.get(key) {
        Some(n) => t.error_at(n, key, why),
        None => t.error(key, why),
    }
}

/// The twelve triangles of the box from `min` to `max`, two per face, counter-clockwise seen
/// from outside.
fn box_triangles(min: DVec3, max: DVec3) -> [[DVec3; 3]; 12] {
    let c = |i: usize| {
        DVec3::new(
            if i & 1 == 0 { min.x } else { max.x },
            if i & 2 == 0 { min.y } else { max.y },
            if i & 4 == 0 { min.z } else { max.z },
        )
    };
    // Each face's corners in order around it, seen from outside.
    let faces = [
        [0, 2, 3, 1], // z = min
        [4, 5, 7, 6], // z = max
        [0, 1, 5, 4], // y = min
        [2, 6, 7, 3], // y = max
        [0, 4, 6, 2], // x = min
        [1, 3, 7, 5], // x = max
    ];
    let mut out = [[DVec3::ZERO; 3]; 12];
    for (f, q) in faces.iter().enumerate() {
        out[2 * f] = [c(q[0]), c(q[1]), c(q[2])];
        out[2 * f + 1] = [c(q[0]), c(q[2]), c(q[3])];
    }
    out
}

/// The scene material of each material a mesh file names (OBJ's `usemtl`): the one
/// `materials = { file_name = "scene_name" }` gives, else the scene's material of the same
/// name, else the object's `material`.
pub(super) fn file_materials(
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
                    "the file names no materials (usemtl)".to_string()
                } else {
                    format!("the file's materials: {}", in_file.join(", "))
                };
                return Err(map.error_at(
                    map.get(k).expect("a key of the table"),
                    k,
                    format!("the mesh file has no material `{k}` ({named})"),
                ));
            };
            chosen[i] = material_ref(&map, k, mats, default)?;
        }
    }
    Ok(chosen)
}

/// The mesh `file` names, relative to the scene file's folder; errors name the scene's line
/// and key, and the mesh file with its own line.
fn read_mesh_file(t: &Table) -> SceneResult<super::mesh_file::MeshData> {
    let name = t.req_string("file")?;
    read_mesh_at(t, "file", t.path_beside(name))
}

/// The mesh file at `path`, which `t`'s `key` names; errors name the scene's line and key, and
/// the mesh file with its own line.
fn read_mesh_at(
    t: &Table,
    key: &str,
    path: std::path::PathBuf,
) -> SceneResult<super::mesh_file::MeshData> {
    let node = t.get(key).expect("read by the caller");
    if let Ok(m) = std::fs::metadata(&path) {
        let need = m
            .len()
            .saturating_mul(super::mesh_file::BYTES_PER_FILE_BYTE);
        let what = format!(
            "reading the mesh file {} ({})",
            path.display(),
            crate::memory::human(m.len())
        );
        if let Some(why) = crate::memory::too_much(need, &what) {
            return Err(t.error_at(node, key, why));
        }
    }
    super::mesh_file::read(&path).map_err(|e| {
        let at = e.line.map_or(String::new(), |l| format!(":{l}"));
        t.error_at(node, key, format!("{}{at}: {}", path.display(), e.message))
    })
}

pub(super) fn add_object(
    t: &Table,
    id: u32,
    mats: &HashMap<String, u32>,
    geo: &mut Geometry,
    total: &mut u64,
    meshes: &mut SharedMeshes,
) -> SceneResult<String> {
    let kind = t.req_string("type")?;
    let mat = material_ref(t, "material", mats, 0)?;
    let transform = Transform::read(t)?;
    let mut adding = Adding {
        t,
        id,
        mat,
        transform,
        geo,
        total,
    };
    // The shape before its transform, where it is a box, sphere or rod.
    let original = match kind {
        "box" => Some(adding.add_box()?),
        "sphere" => Some(adding.add_sphere()?),
        "rod" => Some(adding.add_rod()?),
        "mesh" if t.has("file") && meshes.is_shared(t)? => {
            let path = t.path_beside(t.req_string("file")?);
            adding.add_shared_mesh(mats, meshes, "file", path)?;
            None
        }
        "mesh" if t.has("file") => adding.add_mesh_file(mats).map(|_| None)?,
        "instance" => {
            if let Some(k) = ["file", "vertices", "indices"]
                .into_iter()
                .find(|k| t.has(k))
            {
                return Err(at_value(
                    t,
                    k,
                    "an instance places the mesh of the object its `of` names; give the file there",
                ));
            }
            let path = meshes.file_of_instance(t)?;
            adding.add_shared_mesh(mats, meshes, "of", path)?;
            None
        }
        "mesh" => adding.add_inline_mesh().map(|_| None)?,
        "lattice" | "bar_array" if transform.is_some() => {
            let key = KEYS
                .into_iter()
                .find(|k| t.has(k))
                .expect("a transform has a key");
            return Err(at_value(
                t,
                key,
                format!(
                    "transforms apply to boxes, spheres, rods and meshes; a {kind} is placed by its own keys (origin, center, spacing, axis)"
                ),
            ));
        }
        "lattice" => adding.add_lattice(mats).map(|_| None)?,
        "wheel" if transform.is_some() => {
            let key = KEYS
                .into_iter()
                .find(|k| t.has(k))
                .expect("a transform has a key");
            return Err(at_value(
                t,
                key,
                "a wheel is placed by its own keys (center, axis, radius)",
            ));
        }
        "wheel" => Some(adding.add_wheel()?),
        "bar_array" => adding.add_bar_array().map(|_| None)?,
        other => {
            let n = t.get("type").expect("read above");
            return Err(t.error_at(
                n,
                "type",
                format!(
                    "unknown object type `{other}` (box, sphere, rod, mesh, instance, gltf, lattice, bar_array, wheel)"
                ),
            ));
        }
    };
    if let Some(spin) = t.table("spin")? {
        let prims: Vec<Primitive> = adding
            .geo
            .parts
            .iter()
            .filter(|p| p.object == id)
            .flat_map(|p| p.start..p.end)
            .filter(|&i| (i as usize) < adding.geo.prims.len())
            .map(|i| adding.geo.prims[i as usize])
            .collect();
        let spin = super::spin_keys::read_spin(&spin, kind, &prims)?;
        adding.geo.set_spin(id, spin);
    }
    // Textures turn and move with the object (a box turned by quarter turns as exactly as its
    // corners were).
    if let Some(x) = transform {
        adding.geo.set_placement(
            id,
            std::sync::Arc::new(crate::geometry::Placement {
                scale: x.scale,
                rotation: x.axis_permutation().unwrap_or(x.rotation),
                translate: x.translate,
                shape: original,
            }),
        );
    }
    Ok(kind.to_string())
}

/// The factor of a uniform scale (1 without a transform): a sphere or rod stays one under a
/// uniform scale only.
fn uniform_scale(t: &Table, transform: Option<Transform>, what: &str) -> SceneResult<f64> {
    match transform {
        Some(x) if !x.is_uniform() => Err(at_value(
            t,
            "scale",
            format!(
                "a {what} scaled unevenly is no longer a {what}: give one factor, or use a mesh"
            ),
        )),
        _ => Ok(transform.map_or(1.0, |x| x.scale.x)),
    }
}

/// An object being added: its table, id, material and transform, the group's geometry it goes
/// into, and the scene's count of primitives so far.
struct Adding<'t, 'a> {
    t: &'t Table<'a>,
    id: u32,
    mat: u32,
    transform: Option<Transform>,
    geo: &'t mut Geometry,
    total: &'t mut u64,
}

impl Adding<'_, '_> {
    /// A box (`min`, `max`): itself, moved by quarter turns, or its twelve triangles turned any
    /// other way; returns the box as given.
    fn add_box(&mut self) -> SceneResult<Primitive> {
        let (t, id, mat, transform) = (self.t, self.id, self.mat, self.transform);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        let (min, max) = (t.req_vec3("min")?, t.req_vec3("max")?);
        if min.cmpge(max).any() {
            return Err(t.error("max", "every coordinate of max must exceed min"));
        }
        match transform {
            None => {
                budget(t, "type", total, 1)?;
                geo.push_part(id, mat, [Primitive::Cuboid { min, max }]);
            }
            // Turned by quarter turns: still a box, its corners moved.
            Some(x) if x.axis_permutation().is_some() => {
                let exact = Transform {
                    rotation: x.axis_permutation().expect("checked"),
                    ..x
                };
                let (a, b) = (exact.point(min), exact.point(max));
                budget(t, "type", total, 1)?;
                geo.push_part(
                    id,
                    mat,
                    [Primitive::Cuboid {
                        min: a.min(b),
                        max: a.max(b),
                    }],
                );
            }
            // Turned otherwise: its twelve triangles.
            Some(x) => {
                budget(t, "type", total, 12)?;
                geo.push_part(
                    id,
                    mat,
                    box_triangles(min, max).map(|v| Primitive::Triangle {
                        v: v.map(|p| x.point(p)),
                    }),
                );
            }
        }
        Ok(Primitive::Cuboid { min, max })
    }

    /// A sphere (`center`, `radius`); returns it as given.
    fn add_sphere(&mut self) -> SceneResult<Primitive> {
        let (t, id, mat, transform) = (self.t, self.id, self.mat, self.transform);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        let center = t.req_vec3("center")?;
        let radius = t.f64_where("radius", None, |v| v > 0.0, "greater than 0")?;
        let s = uniform_scale(t, transform, "sphere")?;
        let given = Primitive::Sphere { center, radius };
        let center = transform.map_or(center, |x| x.point(center));
        budget(t, "type", total, 1)?;
        geo.push_part(
            id,
            mat,
            [Primitive::Sphere {
                center,
                radius: radius * s,
            }],
        );
        Ok(given)
    }

    /// A spoked wheel (`center`, `axis` [0, 0, 1], `radius` of the rim's centre line,
    /// `spokes` 8, `rim_segments` 6 per spoke, `rod_radius` radius/25, `hub_radius` three rod
    /// radii): a hub sphere, then the spokes and the rim as rods; returns the hub.
    fn add_wheel(&mut self) -> SceneResult<Primitive> {
        let (t, id, mat) = (self.t, self.id, self.mat);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        let center = t.req_vec3("center")?;
        let axis = t.vec3("axis")?.unwrap_or(DVec3::Z);
        if !(axis.is_finite() && axis.length() > 0.0) {
            return Err(t.error("axis", "must be a direction, not zero"));
        }
        let axis = axis.normalize();
        let radius = t.f64_where("radius", None, |v| v > 0.0, "greater than 0")?;
        let spokes = t.uint("spokes", Some(8), 1, 1000)? as usize;
        let rim_segments = t.uint("rim_segments", Some(6 * spokes as u64), 3, 100_000)? as usize;
        let rod = t.f64_where(
            "rod_radius",
            Some(radius / 25.0),
            |v| v > 0.0,
            "greater than 0",
        )?;
        let hub = t.f64_where("hub_radius", Some(3.0 * rod), |v| v > 0.0, "greater than 0")?;
        // Two directions across the axis.
        let u = axis.any_orthonormal_vector();
        let v = axis.cross(u);
        let at = |k: usize, n: usize| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            center + radius * (a.cos() * u + a.sin() * v)
        };
        let hub_prim = Primitive::Sphere {
            center,
            radius: hub,
        };
        let mut prims = vec![hub_prim];
        prims.extend((0..spokes).map(|k| Primitive::Capsule {
            a: center,
            b: at(k, spokes),
            radius: rod,
        }));
        prims.extend((0..rim_segments).map(|k| Primitive::Capsule {
            a: at(k, rim_segments),
            b: at(k + 1, rim_segments),
            radius: rod,
        }));
        budget(t, "type", total, prims.len() as u64)?;
        geo.push_part(id, mat, prims);
        Ok(hub_prim)
    }

    /// A rod (`from`, `to`, `radius`), a capsule; returns it as given.
    fn add_rod(&mut self) -> SceneResult<Primitive> {
        let (t, id, mat, transform) = (self.t, self.id, self.mat, self.transform);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        let (a, b) = (t.req_vec3("from")?, t.req_vec3("to")?);
        let radius = t.f64_where("radius", None, |v| v > 0.0, "greater than 0")?;
        let s = uniform_scale(t, transform, "rod")?;
        let given = Primitive::Capsule { a, b, radius };
        let (a, b) = transform.map_or((a, b), |x| (x.point(a), x.point(b)));
        budget(t, "type", total, 1)?;
        geo.push_part(
            id,
            mat,
            [Primitive::Capsule {
                a,
                b,
                radius: radius * s,
            }],
        );
        Ok(given)
    }

    /// A mesh read from `file`, held as itself: its vertices once and its triangles' indices,
    /// in runs of one material each (`mats`: the scene's materials by name).
    fn add_mesh_file(&mut self, mats: &HashMap<String, u32>) -> SceneResult<()> {
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
}

/// The entry `t`'s `material` (for triangles its file gives none) and transform.
pub(super) fn material_and_transform(
    t: &Table,
    mats: &HashMap<String, u32>,
) -> SceneResult<(u32, Option<Transform>)> {
    Ok((material_ref(t, "material", mats, 0)?, Transform::read(t)?))
}

/// A mesh as read (from any file) as an object held as itself in `geo`: placed by `transform`,
/// its file's materials `chosen` (by index), remapped by the entry's `materials` table, those
/// it names none `mat`.
#[allow(clippy::too_many_arguments)]
pub(super) fn add_mesh_data(
    t: &Table,
    id: u32,
    mat: u32,
    transform: Option<Transform>,
    geo: &mut Geometry,
    total: &mut u64,
    mut mesh: super::mesh_file::MeshData,
    chosen: Vec<u32>,
    mats: &HashMap<String, u32>,
) -> SceneResult<()> {
    mesh_budget(t, total, &mesh)?;
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
        Some(&m) if m != super::mesh_file::NO_MATERIAL => chosen[m as usize],
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
    /// A mesh file placed more than once in the scene (by `file`, or an instance's `of`, the
    /// entry's `key`), held once: this entry one placement of it.
    fn add_shared_mesh(
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
            mesh_budget(t, total, &mesh)?;
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
    fn add_inline_mesh(&mut self) -> SceneResult<()> {
        let (t, id, mat, transform) = (self.t, self.id, self.mat, self.transform);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        let vn = t
            .get("vertices")
            .ok_or_else(|| t.error("vertices", "missing: give [[x, y, z], ...]"))?;
        let verts = match &vn.val {
            super::doc::Val::Array(items) => items
                .iter()
                .map(|e| {
                    t.numbers_of(e, "vertices", Some(3))
                        .map(|v| DVec3::new(v[0], v[1], v[2]))
                })
                .collect::<SceneResult<Vec<_>>>()?,
            _ => return Err(t.error_at(vn, "vertices", "expected an array of [x, y, z]")),
        };
        let inn = t
            .get("indices")
            .ok_or_else(|| t.error("indices", "missing: give [[i, j, k], ...]"))?;
        let tris = match &inn.val {
            super::doc::Val::Array(items) => items
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

    /// A lattice (`counts`, `spacing`, `origin`, its radii and materials), held as itself.
    fn add_lattice(&mut self, mats: &HashMap<String, u32>) -> SceneResult<()> {
        let (t, id, mat) = (self.t, self.id, self.mat);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        let counts = t
            .uints("counts", 3, 1, 1_000_000)?
            .ok_or_else(|| t.error("counts", "missing: give the node counts [nx, ny, nz]"))?;
        let spacing = t.positive_scalar_or_array("spacing", 3, Some(1.0))?;
        let l = Lattice {
            counts: [counts[0] as u32, counts[1] as u32, counts[2] as u32],
            spacing: DVec3::from_slice(&spacing),
            origin: t.vec3("origin")?.unwrap_or(DVec3::ZERO),
            rod_radius: t.f64_where("rod_radius", Some(0.05), |v| v >= 0.0, "0 or more")?,
            sphere_radius: t.f64_where("sphere_radius", Some(0.15), |v| v >= 0.0, "0 or more")?,
        };
        if l.rod_radius == 0.0 && l.sphere_radius == 0.0 {
            return Err(t.error(
                "rod_radius",
                "rod_radius and sphere_radius are both 0: the lattice would be empty",
            ));
        }
        let sm = material_ref(t, "sphere_material", mats, mat)?;
        let rm = material_ref(t, "rod_material", mats, mat)?;
        let runs = [(l.sphere_count(), sm), (l.rod_count(), rm)];
        let shape = Implicit::Lattice(l);
        implicit_budget(t, total, &shape)?;
        geo.push_implicit(id, &runs, shape)
            .map_err(|why| at_value(t, "counts", why.to_string()))?;
        Ok(())
    }

    /// A bar array (`counts`, `spacing`, `bar_size`, `length`, `axis`, `center`), held as
    /// itself.
    fn add_bar_array(&mut self) -> SceneResult<()> {
        let (t, id, mat) = (self.t, self.id, self.mat);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        let counts = t
            .uints("counts", 2, 1, 100_000)?
            .ok_or_else(|| t.error("counts", "missing: give the bar counts [n1, n2]"))?;
        let spacing = t.positive_scalar_or_array("spacing", 2, Some(2.0))?;
        let bar_size = t.positive_scalar_or_array("bar_size", 2, Some(0.5))?;
        let axis = match t.string("axis")?.unwrap_or("z") {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            other => {
                let n = t.get("axis").expect("read above");
                return Err(t.error_at(n, "axis", format!("unknown axis `{other}` (x, y or z)")));
            }
        };
        let b = BarArray {
            counts: [counts[0] as u32, counts[1] as u32],
            spacing: [spacing[0], spacing[1]],
            bar_size: [bar_size[0], bar_size[1]],
            length: t.f64_where("length", Some(2.0), |v| v > 0.0, "greater than 0")?,
            axis,
            center: t.vec3("center")?.unwrap_or(DVec3::ZERO),
        };
        let runs = [(b.len(), mat)];
        let shape = Implicit::Bars(b);
        implicit_budget(t, total, &shape)?;
        geo.push_implicit(id, &runs, shape)
            .map_err(|why| at_value(t, "counts", why.to_string()))?;
        Ok(())
    }
}
