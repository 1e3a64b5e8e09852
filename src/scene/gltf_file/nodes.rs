//! The node tree of the default scene: transforms composed down it, meshes placed (normals,
//! texture coordinates, winding), point lights and perspective cameras where it puts them.

use super::{CameraView, GltfError, PointLight, BYTES_PER_TRIANGLE, BYTES_PER_VERTEX, MAX_DEPTH};
use crate::scene::mesh_file::{MeshData, NO_MATERIAL};
use glam::{DMat3, DMat4, DVec3};

/// A node's local matrix, in f64, checked finite.
pub(super) fn node_matrix(node: &gltf::Node) -> Result<DMat4, GltfError> {
    let m = node.transform().matrix();
    let m = DMat4::from_cols_array_2d(&m.map(|c| c.map(f64::from)));
    if !m.is_finite() {
        return Err(format!("node {}'s transform is not finite", node.index()).into());
    }
    Ok(m)
}

/// Reading the node tree.
pub(super) struct Reading<'a> {
    pub buffers: &'a [Vec<u8>],
    /// Bytes the placed triangles take so far.
    pub held: u64,
    /// Nodes already placed: a node reached twice is refused (the nodes of a scene are a tree).
    pub seen: Vec<bool>,
    pub lights: Vec<PointLight>,
    pub cameras: Vec<CameraView>,
    pub warnings: Vec<String>,
    /// How many nodes of the scene place each mesh, by mesh index: one placed by several is
    /// read once, in its own coordinates (`shared`), and each node's placement recorded.
    pub uses: Vec<usize>,
    /// The meshes placed by several nodes, read once in their own coordinates, by index.
    pub shared: std::collections::BTreeMap<usize, MeshData>,
    /// Whether the top-level node being walked may hold placements of shared meshes (else it
    /// is a group of its own, and holds copies).
    pub share: bool,
}

/// A node's placement of a mesh that several nodes place: the mesh's index and where the
/// node puts it.
pub(crate) type MeshPlacement = (usize, DMat4);

impl Reading<'_> {
    pub(super) fn walk(
        &mut self,
        node: &gltf::Node,
        world: DMat4,
        top: usize,
        depth: usize,
        mesh: &mut MeshData,
        placements: &mut Vec<MeshPlacement>,
    ) -> Result<(), GltfError> {
        let i = node.index();
        if std::mem::replace(&mut self.seen[i], true) {
            return Err(format!(
                "node {i} is reached twice: the nodes of a scene must form a tree"
            )
            .into());
        }
        if depth > MAX_DEPTH {
            return Err(format!("its node hierarchy is deeper than {MAX_DEPTH}").into());
        }
        if node.skin().is_some() || node.weights().is_some() {
            self.warnings.push(format!(
                "node {i}'s skin and morph weights are ignored (its mesh is taken in its rest pose)"
            ));
        }
        if let Some(m) = node.mesh() {
            // A mirroring placement turns the triangles' winding, which a shared mesh cannot
            // do per placement: it is copied.
            let mirrors = DMat3::from_mat4(world).determinant() < 0.0;
            if self.share && self.uses[m.index()] > 1 && !mirrors {
                if !self.shared.contains_key(&m.index()) {
                    let mut own = MeshData::default();
                    self.add_mesh(&m, DMat4::IDENTITY, &mut own)?;
                    self.shared.insert(m.index(), own);
                }
                // As `add_mesh` refuses it for a copy.
                if DMat3::from_mat4(world).determinant() == 0.0 {
                    return Err(format!(
                        "mesh {} is placed by a transform that flattens it",
                        m.index()
                    )
                    .into());
                }
                // A mesh of no triangles (points, lines: warned) places nothing.
                if !self.shared[&m.index()].triangles.is_empty() {
                    placements.push((m.index(), world));
                }
            } else {
                self.add_mesh(&m, world, mesh)?;
            }
        }
        let origin = world.transform_point3(DVec3::ZERO);
        if let Some(light) = node.light() {
            match light.kind() {
                gltf::khr_lights_punctual::Kind::Point
                    if !(light.intensity().is_finite()
                        && light.intensity() >= 0.0
                        && light.color().iter().all(|c| c.is_finite() && *c >= 0.0)) =>
                {
                    return Err(format!(
                        "light {}'s colour or intensity is not a finite number of 0 or more",
                        light.index()
                    )
                    .into())
                }
                gltf::khr_lights_punctual::Kind::Point => self.lights.push(PointLight {
                    top,
                    position: origin,
                    color: DVec3::from_array(light.color().map(f64::from)),
                    intensity: f64::from(light.intensity()),
                }),
                _ => self.warnings.push(format!(
                    "light {} is a spot or directional light, which are not built: it is ignored",
                    light.index()
                )),
            }
        }
        if let Some(cam) = node.camera() {
            match cam.projection() {
                // The scene's own least field of view (`fov_y`, in degrees) holds here too.
                gltf::camera::Projection::Perspective(p)
                    if !(f64::from(p.yfov()).to_degrees() >= crate::scene::envelope::MIN_FOV_DEG
                        && f64::from(p.yfov()) < std::f64::consts::PI) =>
                {
                    return Err(format!(
                        "camera {}'s yfov {} is not between {:e} rad ({:e}°) and π",
                        cam.index(),
                        p.yfov(),
                        crate::scene::envelope::MIN_FOV_DEG.to_radians(),
                        crate::scene::envelope::MIN_FOV_DEG
                    )
                    .into())
                }
                gltf::camera::Projection::Perspective(p) => {
                    let forward = world.transform_vector3(-DVec3::Z).normalize_or_zero();
                    let up = world.transform_vector3(DVec3::Y).normalize_or_zero();
                    if forward == DVec3::ZERO || up == DVec3::ZERO || forward.cross(up) == DVec3::ZERO {
                        return Err(format!(
                            "camera {} is placed by node {}, whose transform leaves it no view direction or up (a scale of 0?)",
                            cam.index(),
                            node.index()
                        )
                        .into());
                    }
                    self.cameras.push(CameraView {
                        name: cam
                            .name()
                            .or(node.name())
                            .map_or_else(|| format!("camera{}", cam.index()), str::to_string),
                        position: origin,
                        forward,
                        up,
                        fov_y: f64::from(p.yfov()),
                    })
                }
                gltf::camera::Projection::Orthographic(_) => self.warnings.push(format!(
                    "camera {} is orthographic: it is ignored (give [camera] projection = \"orthographic\")",
                    cam.index()
                )),
            }
        }
        for child in node.children() {
            let m = world * node_matrix(&child)?;
            self.walk(&child, m, top, depth + 1, mesh, placements)?;
        }
        Ok(())
    }

    /// Append `m`'s triangles placed by `world` to `mesh`.
    fn add_mesh(
        &mut self,
        m: &gltf::Mesh,
        world: DMat4,
        mesh: &mut MeshData,
    ) -> Result<(), GltfError> {
        let linear = DMat3::from_mat4(world);
        let normal_matrix = linear.inverse().transpose();
        if !normal_matrix.is_finite() || linear.determinant() == 0.0 {
            return Err(format!(
                "mesh {} is placed by a transform that flattens it",
                m.index()
            )
            .into());
        }
        // A mirroring transform turns the triangles' fronts: glTF then flips their winding.
        let mirrored = linear.determinant() < 0.0;
        for prim in m.primitives() {
            let what = || format!("mesh {} primitive {}", m.index(), prim.index());
            use gltf::mesh::Mode;
            let mode = prim.mode();
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                self.warnings.push(format!(
                    "{} is not triangles ({:?}): it is ignored",
                    what(),
                    mode
                ));
                continue;
            }
            if prim.morph_targets().next().is_some() {
                self.warnings.push(format!(
                    "{}'s morph targets are ignored (it is taken in its base shape)",
                    what()
                ));
            }
            let reader = prim.reader(|b| self.buffers.get(b.index()).map(Vec::as_slice));
            let positions: Vec<DVec3> = reader
                .read_positions()
                .ok_or_else(|| {
                    format!(
                        "{}: its POSITION accessor is missing or lies outside its buffer",
                        what()
                    )
                })?
                .map(|p| world.transform_point3(DVec3::from_array(p.map(f64::from))))
                .collect();
            let n = positions.len();
            // A count past what the buffer can hold (2^63, say) reads as no vertices.
            let claimed = prim
                .get(&gltf::Semantic::Positions)
                .map_or(n, |a| a.count());
            if claimed != n {
                return Err(format!(
                    "{}: its POSITION accessor claims {claimed} vertices; its buffer holds {n}",
                    what()
                )
                .into());
            }
            let indices: Vec<u32> = match (reader.read_indices(), prim.indices()) {
                (Some(i), _) => i.into_u32().collect(),
                (None, None) => (0..n as u32).collect(),
                (None, Some(_)) => {
                    return Err(format!("{}: its indices lie outside their buffer", what()).into())
                }
            };
            let indices = match mode {
                Mode::TriangleStrip => strip_triangles(&indices),
                Mode::TriangleFan => fan_triangles(&indices),
                _ => indices,
            };
            if indices.is_empty() {
                return Err(format!("{}: it makes no triangle ({} vertices)", what(), n).into());
            }
            if !indices.len().is_multiple_of(3) {
                let given = match prim.indices() {
                    Some(_) => "indices",
                    None => "vertices and no indices",
                };
                return Err(format!(
                    "{}: {} {given}, not a whole number of triangles",
                    what(),
                    indices.len()
                )
                .into());
            }
            if let Some(&bad) = indices.iter().find(|&&i| i as usize >= n) {
                return Err(format!("{}: index {bad} is past its {n} vertices", what()).into());
            }
            if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
                return Err(format!("{}: a vertex is not finite ({p})", what()).into());
            }
            let present = |sem: gltf::Semantic| prim.get(&sem).is_some();
            if (present(gltf::Semantic::Normals) && reader.read_normals().is_none())
                || (present(gltf::Semantic::TexCoords(0)) && reader.read_tex_coords(0).is_none())
            {
                return Err(format!(
                    "{}: its normals or texture coordinates lie outside their buffer",
                    what()
                )
                .into());
            }
            let normals: Option<Vec<DVec3>> = reader.read_normals().map(|it| {
                it.map(|v| {
                    (normal_matrix * DVec3::from_array(v.map(f64::from))).normalize_or_zero()
                })
                .collect()
            });
            let uvs: Option<Vec<[f64; 2]>> = reader.read_tex_coords(0).map(|it| {
                // glTF's v runs down the image; the meshes' (OBJ's) runs up.
                it.into_f32()
                    .map(|[u, v]| [f64::from(u), 1.0 - f64::from(v)])
                    .collect()
            });
            for (what_, len) in [
                ("normals", normals.as_ref().map(Vec::len)),
                ("texture coordinates", uvs.as_ref().map(Vec::len)),
            ] {
                if len.is_some_and(|l| l != n) {
                    return Err(format!(
                        "{}: {} {what_} for {n} vertices",
                        what(),
                        len.unwrap_or(0)
                    )
                    .into());
                }
            }
            if uvs
                .as_ref()
                .is_some_and(|u| u.iter().any(|c| !c[0].is_finite() || !c[1].is_finite()))
            {
                return Err(format!("{}: a texture coordinate is not finite", what()).into());
            }
            // The file's triangles as placed so far, every placement of a mesh a copy: against
            // the scene's limits before they are made (a small file can place one big mesh
            // many times).
            self.held += (n as u64).saturating_mul(BYTES_PER_VERTEX)
                + (indices.len() as u64 / 3).saturating_mul(BYTES_PER_TRIANGLE);
            if let Some(why) = crate::memory::too_much(self.held, "the triangles the file places") {
                return Err(why.into());
            }
            let material = prim.material().index().map_or(NO_MATERIAL, |i| i as u32);
            let offset = mesh.positions.len() as u32;
            let before = mesh.triangles.len();
            mesh.positions.extend(positions);
            for t in indices.chunks_exact(3) {
                let t = if mirrored {
                    [t[0], t[2], t[1]]
                } else {
                    [t[0], t[1], t[2]]
                };
                mesh.triangles.push(t.map(|i| i + offset));
            }
            let added = mesh.triangles.len() - before;
            // Corner data: where a primitive lacks it and others have it, its triangles get
            // their own face normal (flat, as without normals) and texture coordinate 0.
            let corners = &mesh.triangles[before..];
            let local = |t: &[u32; 3]| t.map(|i| (i - offset) as usize);
            let new_normals: Vec<[DVec3; 3]> = match &normals {
                Some(nv) => corners.iter().map(|t| local(t).map(|i| nv[i])).collect(),
                None => face_normals(&mesh.positions, corners),
            };
            let new_uvs: Vec<[[f64; 2]; 3]> = match &uvs {
                Some(uv) => corners.iter().map(|t| local(t).map(|i| uv[i])).collect(),
                None => vec![[[0.0; 2]; 3]; added],
            };
            if normals.is_some() && mesh.normals.is_none() {
                mesh.normals = Some(face_normals(&mesh.positions, &mesh.triangles[..before]));
            }
            if uvs.is_some() && mesh.uvs.is_none() {
                mesh.uvs = Some(vec![[[0.0; 2]; 3]; before]);
            }
            if let Some(v) = &mut mesh.normals {
                v.extend(new_normals);
            }
            if let Some(v) = &mut mesh.uvs {
                v.extend(new_uvs);
            }
            mesh.material_of
                .extend(std::iter::repeat_n(material, added));
        }
        Ok(())
    }
}

/// Each triangle's face normal at its three corners (flat shading, as without normals).
pub(super) fn face_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<[DVec3; 3]> {
    triangles
        .iter()
        .map(|t| {
            let v = t.map(|i| positions[i as usize]);
            [(v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero(); 3]
        })
        .collect()
}

/// The triangles of a TRIANGLE_STRIP, as glTF 2.0 lists them (§3.7.2.1): triangle i is
/// (v[i], v[i+1+i%2], v[i+2-i%2]), every other one turned so that all face one way.
fn strip_triangles(v: &[u32]) -> Vec<u32> {
    (0..v.len().saturating_sub(2))
        .flat_map(|i| [v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]])
        .collect()
}

/// The triangles of a TRIANGLE_FAN, as glTF 2.0 lists them: triangle i is
/// (v[i+1], v[i+2], v[0]).
fn fan_triangles(v: &[u32]) -> Vec<u32> {
    (0..v.len().saturating_sub(2))
        .flat_map(|i| [v[i + 1], v[i + 2], v[0]])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip's and a fan's triangles all face the way their first does (glTF's order), and
    /// cover what the equivalent list covers.
    #[test]
    fn strips_and_fans_are_the_triangles_gltf_lists() {
        // A row of five points on a zig-zag in the plane z = 0, and a fan around the origin.
        let strip_points = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
        ];
        let fan_points = [
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
        ];
        let v = [0, 1, 2, 3, 4];
        let strip = strip_triangles(&v);
        assert_eq!(strip, vec![0, 1, 2, 1, 3, 2, 2, 3, 4]);
        let fan = fan_triangles(&v);
        assert_eq!(fan, vec![1, 2, 0, 2, 3, 0, 3, 4, 0]);
        for (tris, points) in [(strip, strip_points), (fan, fan_points)] {
            let facing: Vec<f64> = tris
                .chunks(3)
                .map(|t| {
                    let [a, b, c] = [0, 1, 2].map(|k| points[t[k] as usize]);
                    (b - a).cross(c - a).z
                })
                .collect();
            assert!(
                facing.iter().all(|&z| z * facing[0] > 0.0),
                "{tris:?}: {facing:?}"
            );
        }
        assert!(strip_triangles(&[0, 1]).is_empty() && fan_triangles(&[]).is_empty());
    }
}
