//! `[[group.object]] type = "gltf"`: a glTF file's default scene placed in a group. Its
//! materials join the scene's (a `[[material]]` of the same name takes a material's place),
//! its point lights rest in the group, its perspective cameras are offered to a scene without
//! `[camera]`, and its top-level nodes are the group's triangles, or groups of their own: every
//! node with `groups = "nodes"`, and a node whose translation is keyframed always (its keys
//! become a worldline of uniform segments, the file's seconds times `time_scale` scene time
//! units). The mapping is tabled in docs/scene-format.md.

use super::gltf_file::{self, CameraView, GltfData, GltfMaterial};
use super::mesh_file::MeshData;
use super::model::{Light, Material};
use super::reader::{SceneResult, Table};
use super::shared_meshes::{Shared, SharedMeshes};
use super::transform::Transform;
use super::worldline::{Motion, Segment};
use crate::spacetime::Velocity;
use crate::spectrum::{Colour, Role};
use glam::{DMat3, DMat4, DVec3};
use std::collections::HashMap;
use std::sync::Arc;

/// The luminous efficacy by which a glTF light's candela become the scene's radiant intensity.
pub(super) const LUMENS_PER_WATT: f64 = 683.0;

/// What the glTF objects of a scene bring beside their triangles: gathered while the groups
/// are read, used once they are.
#[derive(Default)]
pub(super) struct Imports {
    /// Their point lights.
    pub lights: Vec<Light>,
    /// Their perspective cameras (by name), the first first.
    pub cameras: Vec<CameraView>,
    /// The one a `camera = "name"` on an entry chose.
    pub chosen_camera: Option<CameraView>,
    /// What their files hold that is not taken.
    pub warnings: Vec<String>,
}

/// A top-level node that is a group of its own.
pub(super) struct OwnGroup {
    /// The node's name (the group is `<group>/<node>`).
    pub node: String,
    pub mesh: MeshData,
    /// Its worldline, where it is keyframed.
    pub segments: Option<Vec<Segment>>,
}

/// What one glTF entry puts in its group: the triangles that stay in it (their materials
/// chosen) and the nodes that are groups of their own.
pub(super) struct Placed {
    pub stays: Option<MeshData>,
    /// The placements, in the group, of meshes the file places several times: each mesh held
    /// once, and where each node puts it (before the entry's own transform).
    pub instances: Vec<(Arc<Shared>, DMat4)>,
    pub own: Vec<OwnGroup>,
    /// The scene material of each of the file's materials, by index.
    pub chosen: Vec<u32>,
}

/// How the group an entry is in moves.
pub(super) struct InGroup {
    pub velocity: Velocity,
    /// Whether it has a velocity or a worldline.
    pub moves: bool,
    /// Whether it has a worldline.
    pub on_worldline: bool,
}

/// Read the entry `t`'s file (once, where several entries place it: `meshes`) and place it:
/// its materials appended to `materials` (and named in `ids` where the scene names none so),
/// lights and cameras into `imports`.
pub(super) fn place(
    t: &Table,
    group: InGroup,
    materials: &mut Vec<Material>,
    ids: &HashMap<String, u32>,
    imports: &mut Imports,
    meshes: &mut SharedMeshes,
) -> SceneResult<Placed> {
    let name = t.req_string("file")?;
    let node = t.get("file").expect("read above");
    let path = t.path_beside(name);
    let split_all = match t.string("groups")?.unwrap_or("one") {
        "one" => false,
        "nodes" => true,
        other => {
            let n = t.get("groups").expect("read above");
            return Err(t.error_at(
                n,
                "groups",
                format!("unknown grouping `{other}` (one: the whole file in this group; nodes: a group per top-level node)"),
            ));
        }
    };
    let (data, held) = meshes
        .gltf(&path, split_all)
        .map_err(|why| t.error_at(node, "file", format!("{}: {why}", path.display())))?;
    let transform = Transform::read(t)?;
    let time_scale = t.f64_where(
        "time_scale",
        Some(1.0),
        |v| v > 0.0 && v.is_finite(),
        "more than 0 (scene time units per second of the file's clock)",
    )?;
    let GltfData {
        nodes,
        materials: file_materials,
        lights,
        cameras,
        warnings,
        shared: _,
    } = data;
    let shown = path.display().to_string();
    imports
        .warnings
        .extend(warnings.into_iter().map(|w| format!("{shown}: {w}")));
    // The file's materials: the scene's own of the same name, else the file's, appended.
    let default = materials.len();
    let chosen: Vec<u32> = file_materials
        .iter()
        .map(|m| match ids.get(&m.name) {
            Some(&id) => id,
            None => {
                materials.push(material(m));
                (materials.len() - 1) as u32
            }
        })
        .collect();
    debug_assert!(materials.len() >= default);
    let place_point = |p: DVec3| transform.map_or(p, |x| x.point(p));
    let place_dir =
        |d: DVec3| transform.map_or(d, |x| (x.rotation * (d * x.scale)).normalize_or_zero());
    let animated: Vec<usize> = (0..nodes.len())
        .filter(|&i| nodes[i].keys.is_some())
        .collect();
    if group.on_worldline && !lights.is_empty() {
        return Err(t.error(
            "file",
            format!("{shown} has point lights and the group a worldline: a light resting in a group whose velocity changes is not built yet (as for a [[light]] with `group`)"),
        ));
    }
    for l in lights {
        let moving = nodes[l.top].keys.is_some();
        if moving {
            imports.warnings.push(format!(
                "{shown}: a light under keyframed node `{}` rests where it is at time 0",
                nodes[l.top].name
            ));
        }
        imports.lights.push(Light {
            position: place_point(l.position),
            // Candela (lm/sr) as radiant intensity (W/sr) at 683 lm/W: how Blender's
            // exporter turns its watts into candela, undone.
            radiance: Colour::rgb(l.color, Role::Emitter).scaled(l.intensity / LUMENS_PER_WATT),
            velocity: if moving {
                Velocity::ZERO
            } else {
                group.velocity
            },
            inverse_square: true,
            timing: super::Timing::Steady,
            worldline: None,
        });
    }
    let placed_cameras: Vec<CameraView> = cameras
        .into_iter()
        .map(|c| CameraView {
            position: place_point(c.position),
            forward: place_dir(c.forward),
            up: place_dir(c.up),
            ..c
        })
        .collect();
    if let Some(want) = t.string("camera")? {
        let found = placed_cameras.iter().find(|c| c.name == want);
        let Some(c) = found else {
            let names: Vec<&str> = placed_cameras.iter().map(|c| c.name.as_str()).collect();
            let n = t.get("camera").expect("read above");
            return Err(t.error_at(
                n,
                "camera",
                format!(
                    "{shown} has no perspective camera named `{want}` (its cameras: {})",
                    if names.is_empty() {
                        "none".into()
                    } else {
                        names.join(", ")
                    }
                ),
            ));
        };
        imports.chosen_camera = Some(c.clone());
    }
    imports.cameras.extend(placed_cameras);
    if group.moves && !animated.is_empty() {
        return Err(t.error(
            "file",
            format!(
                "{shown}: node `{}` is keyframed and the group has a velocity or worldline: give the node's motion in one of them (a keyframed node moves from rest in the scene's frame)",
                nodes[animated[0]].name
            ),
        ));
    }
    if nodes
        .iter()
        .all(|n| n.mesh.is_none() && n.placements.is_empty())
    {
        return Err(t.error_at(
            node,
            "file",
            format!("{shown}: its scene places no triangles"),
        ));
    }
    let mut stays: Option<MeshData> = None;
    let mut own = Vec::new();
    let mut instances = Vec::new();
    for n in nodes {
        // (A node that is a group of its own holds copies, made by the reader: its group is
        // built alone.)
        instances.extend(n.placements.iter().map(|(k, w)| (held[k].clone(), *w)));
        let segments = match &n.keys {
            Some(keys) => Some(segments(keys, time_scale, transform).map_err(|why| {
                t.error(
                    "time_scale",
                    format!("{shown}: node `{}`'s keys: {why}", n.name),
                )
            })?),
            None => None,
        };
        let Some(mut mesh) = n.mesh else { continue };
        mesh.materials = file_materials.iter().map(|m| m.name.clone()).collect();
        if split_all || segments.is_some() {
            own.push(OwnGroup {
                node: n.name,
                mesh,
                segments,
            });
        } else {
            match &mut stays {
                None => stays = Some(mesh),
                Some(all) => append(all, mesh),
            }
        }
    }
    Ok(Placed {
        stays,
        instances,
        own,
        chosen,
    })
}

/// The placements of meshes the entry `t`'s file places several times (`Placed::instances`)
/// into `geo` as object `id`: each a placement of the mesh held once, placed by its node and
/// then by the entry's `transform`; the file's materials `chosen`, remapped by the entry's
/// `materials`, those it names none `mat`. Each mesh counts against the scene's limit once,
/// however many entries place it (`SharedMeshes::first_count`).
#[allow(clippy::too_many_arguments)]
pub(super) fn place_instances(
    t: &Table,
    id: u32,
    mat: u32,
    transform: Option<Transform>,
    placed: &Placed,
    ids: &HashMap<String, u32>,
    (geo, total): (&mut crate::geometry::Geometry, &mut u64),
    meshes: &mut SharedMeshes,
) -> SceneResult<()> {
    let Some((first, _)) = placed.instances.first() else {
        return Ok(());
    };
    let chosen =
        super::objects::file_materials(t, first.materials(), ids, mat, placed.chosen.clone())?;
    for (shared, world) in &placed.instances {
        if meshes.first_count(shared) {
            super::objects::budget(t, "file", total, shared.len())?;
        }
        super::objects::budget(t, "file", total, 1)?;
        let (linear, at) = (DMat3::from_mat4(*world), world.w_axis.truncate());
        let (linear, at) = match transform {
            Some(x) => (
                x.rotation * DMat3::from_diagonal(x.scale) * linear,
                x.point(at),
            ),
            None => (linear, at),
        };
        let place = crate::geometry::Affine::general(linear, at)
            .filter(|a| a.inverse.is_finite() && a.translate.is_finite())
            .ok_or_else(|| {
                t.error(
                    "file",
                    "a node places a mesh by a transform that flattens it",
                )
            })?;
        shared
            .place_at(id, mat, place, &chosen, geo)
            .map_err(|why| t.error("file", why.to_string()))?;
    }
    Ok(())
}

/// The camera the scene's glTF files offer: the one an entry named, else the first.
pub(super) fn file_camera(imports: &Imports) -> Option<&CameraView> {
    imports.chosen_camera.as_ref().or(imports.cameras.first())
}

/// The camera a scene without `[camera]` takes from its glTF files ([`file_camera`]), at rest at
/// time 0.
pub(super) fn camera(imports: &Imports) -> Option<super::Camera> {
    let c = file_camera(imports)?;
    let forward = c.forward.normalize_or_zero();
    let right = forward.cross(c.up).normalize_or_zero();
    if forward == DVec3::ZERO
        || right == DVec3::ZERO
        || !(c.fov_y > 0.0 && c.fov_y < std::f64::consts::PI)
    {
        return None;
    }
    Some(super::Camera {
        position: c.position,
        time: 0.0,
        forward,
        right,
        up: right.cross(forward),
        projection: super::Projection::Pinhole { fov_y: c.fov_y },
        velocity: Velocity::ZERO,
        shutter: 0.0,
        worldline: None,
    })
}

/// `b`'s triangles after `a`'s (the same file: the same material names).
fn append(a: &mut MeshData, b: MeshData) {
    let offset = a.positions.len() as u32;
    let before = a.triangles.len();
    a.positions.extend(b.positions);
    a.triangles
        .extend(b.triangles.into_iter().map(|t| t.map(|i| i + offset)));
    fn join<T: Clone>(
        a: &mut Option<Vec<T>>,
        b: Option<Vec<T>>,
        before: usize,
        added: usize,
        fill: T,
    ) {
        match (a.as_mut(), b) {
            (Some(x), Some(y)) => x.extend(y),
            (Some(x), None) => x.extend(std::iter::repeat_n(fill, added)),
            (None, Some(y)) => {
                let mut x = vec![fill; before];
                x.extend(y);
                *a = Some(x);
            }
            (None, None) => {}
        }
    }
    let added = a.triangles.len() - before;
    // A node without normals beside one with them: its triangles' face normals.
    let face = b.normals.is_none() && a.normals.is_some();
    join(&mut a.uvs, b.uvs, before, added, [[0.0; 2]; 3]);
    let a_had_normals = a.normals.is_some();
    join(&mut a.normals, b.normals, before, added, [DVec3::ZERO; 3]);
    if let Some(n) = &mut a.normals {
        let fix = |range: std::ops::Range<usize>, n: &mut Vec<[DVec3; 3]>| {
            for k in range {
                let v = a.triangles[k].map(|i| a.positions[i as usize]);
                n[k] = [(v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero(); 3];
            }
        };
        if face {
            fix(before..before + added, n);
        } else if !a_had_normals {
            fix(0..before, n);
        }
    }
    a.material_of.extend(b.material_of);
}

/// A glTF material as the scene's: base colour (and its texture, times the factor) as the
/// diffuse `color`, metallic as the mirror share `reflect` with `roughness`, transmission of
/// the dielectric share as `transmit` with `ior`, emissive factor times strength (and its
/// texture) as `emission`. The factors are glTF's ranges, as the reader checked them
/// (`gltf_file::materials`).
fn material(m: &GltfMaterial) -> Material {
    let d = Material::default_white();
    let texture = |img: &gltf_file::Image, factor: DVec3, role: Role| {
        let texels: super::texture::Texels = if factor == DVec3::ONE {
            img.texels.clone()
        } else {
            let f = factor.as_vec3().to_array();
            img.texels
                .iter()
                .map(|t| [t[0] * f[0], t[1] * f[1], t[2] * f[2]])
                .collect()
        };
        Arc::new(super::Texture::Image(super::ImageTexture::new(
            img.shown.clone(),
            img.width,
            img.height,
            texels,
            role,
        )))
    };
    let base = m.base_color;
    let color_texture = m
        .base_texture
        .as_ref()
        .map(|i| texture(i, base, Role::Reflectance));
    let emissive = m.emissive;
    let emission_texture = m
        .emissive_texture
        .as_ref()
        .filter(|_| emissive != DVec3::ZERO)
        .map(|i| texture(i, emissive, Role::Emitter));
    let first = |t: &Arc<super::Texture>| t.colours().next().cloned();
    let metallic = m.metallic;
    Material {
        name: m.name.clone(),
        color: color_texture
            .as_ref()
            .and_then(first)
            .unwrap_or_else(|| Colour::rgb(base, Role::Reflectance)),
        reflect: metallic,
        transmit: m.transmission * (1.0 - metallic),
        ior: m.ior.max(1.0),
        roughness: m.roughness,
        emission: match &emission_texture {
            Some(t) => first(t),
            None => (emissive != DVec3::ZERO).then(|| Colour::rgb(emissive, Role::Emitter)),
        },
        color_texture,
        emission_texture,
        ..d
    }
}

/// A node's keys as a worldline: at rest until the first key, uniform between keys, at rest
/// after the last; the node's displacement turned and scaled as the entry places the file.
pub(super) fn segments(
    keys: &[(f64, DVec3)],
    time_scale: f64,
    transform: Option<Transform>,
) -> Result<Vec<Segment>, gltf_file::GltfError> {
    let turn = |d: DVec3| transform.map_or(d, |x| x.rotation * (d * x.scale));
    // Scene times within the envelope, as a TOML worldline's `until` must be.
    let limit = super::envelope::MAX_MAGNITUDE;
    if let Some((k, t)) = keys
        .iter()
        .map(|&(t, _)| t)
        .enumerate()
        .find(|&(_, t)| (t * time_scale).abs() > limit)
    {
        return Err(gltf_file::GltfError(format!(
            "key {k} is at scene time {:e} (file time {t} × time_scale); at most {limit:e} is taken",
            t * time_scale
        )));
    }
    let rest = Motion::Uniform(Velocity::ZERO);
    let mut out = vec![Segment {
        until: Some(keys[0].0 * time_scale),
        motion: rest,
    }];
    for (k, w) in keys.windows(2).enumerate() {
        let ((t0, a), (t1, b)) = (w[0], w[1]);
        let beta = turn(b - a) / ((t1 - t0) * time_scale);
        let v = Velocity::from_beta_vec(beta).map_err(|_| {
            gltf_file::GltfError(format!(
                "from key {k} to key {} it would move at {:.6}c (a speed of c or more); raise time_scale",
                k + 1,
                beta.length()
            ))
        })?;
        out.push(Segment {
            until: Some(t1 * time_scale),
            motion: Motion::Uniform(v),
        });
    }
    out.push(Segment {
        until: None,
        motion: rest,
    });
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_become_uniform_segments_from_rest_to_rest() {
        let keys = [(0.0, DVec3::ZERO), (2.0, DVec3::new(1.0, 0.0, 0.0))];
        let s = segments(&keys, 1.0, None).unwrap();
        assert_eq!(s.len(), 3);
        assert_eq!(s[1].until, Some(2.0));
        match s[1].motion {
            Motion::Uniform(v) => {
                assert!((v.beta_vec() - DVec3::new(0.5, 0.0, 0.0)).length() < 1e-15)
            }
            _ => panic!("uniform"),
        }
        // Ten scene units per second: a tenth of the speed.
        let s = segments(&keys, 10.0, None).unwrap();
        assert_eq!(s[0].until, Some(0.0));
        assert_eq!(s[1].until, Some(20.0));
        match s[1].motion {
            Motion::Uniform(v) => assert!((v.beta().abs() - 0.05).abs() < 1e-15),
            _ => panic!("uniform"),
        }
        // Faster than light is refused with the keys named.
        let fast = [(0.0, DVec3::ZERO), (1.0, DVec3::new(2.0, 0.0, 0.0))];
        let why = segments(&fast, 1.0, None).unwrap_err().0;
        assert!(
            why.contains("key 0 to key 1") && why.contains("2.000000c"),
            "{why}"
        );
    }
}
