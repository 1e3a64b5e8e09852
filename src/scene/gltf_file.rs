//! glTF 2.0 files (`.gltf` with its buffers and images beside it or in data URIs, or `.glb`)
//! read through the `gltf` crate into what the scene holds: the default scene's top-level
//! nodes, each with the triangles of its whole subtree placed by every transform below it
//! (`MeshData`, in the file's coordinates at the file's time 0), the materials, the point
//! lights and perspective cameras of the subtree, and the keyframed translations of top-level
//! nodes. The buffers are read here, not by the crate: every file is checked to be a regular
//! file and against the memory limit before it is read, and every accessor against its data.
//! What goes wrong is said in words; the caller names the scene's line and key.

use super::mesh_file::{MeshData, NO_MATERIAL};
use super::texture::Texels;
use glam::{DMat3, DMat4, DVec3};
use std::path::{Path, PathBuf};

/// Why a glTF file cannot be taken, in words.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct GltfError(pub String);

impl std::fmt::Display for GltfError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl From<String> for GltfError {
    fn from(s: String) -> GltfError {
        GltfError(s)
    }
}

impl From<&str> for GltfError {
    fn from(s: &str) -> GltfError {
        GltfError(s.into())
    }
}

/// A glTF file as the scene takes it.
pub(crate) struct GltfData {
    /// The default scene's top-level nodes, in the file's order.
    pub nodes: Vec<TopNode>,
    /// The file's materials, by index (primitives name them by index).
    pub materials: Vec<GltfMaterial>,
    /// Its point lights, where the nodes put them (time 0).
    pub lights: Vec<PointLight>,
    /// Its perspective cameras, where the nodes put them (time 0).
    pub cameras: Vec<CameraView>,
    /// What the file has that is not taken, one sentence each.
    pub warnings: Vec<String>,
}

/// A top-level node and everything below it.
pub(crate) struct TopNode {
    pub name: String,
    /// The subtree's triangles (none where it has no mesh); `material_of` gives the file's
    /// material by index.
    pub mesh: Option<MeshData>,
    /// Its keyframed translation: (file time, translation), times increasing; the node stands
    /// as at time 0 in `mesh`.
    pub keys: Option<Vec<(f64, DVec3)>>,
}

/// A metallic-roughness material (with the transmission, IOR and emissive-strength
/// extensions), its colours linear RGB.
pub(crate) struct GltfMaterial {
    pub name: String,
    pub base_color: DVec3,
    pub base_texture: Option<Image>,
    pub metallic: f64,
    pub roughness: f64,
    pub transmission: f64,
    pub ior: f64,
    /// The emissive factor times the emissive strength.
    pub emissive: DVec3,
    pub emissive_texture: Option<Image>,
}

/// An image a material uses: where it came from (for messages and the texture's name) and its
/// linear texels.
pub(crate) struct Image {
    pub shown: String,
    pub width: usize,
    pub height: usize,
    pub texels: Texels,
}

/// A `KHR_lights_punctual` point light.
pub(crate) struct PointLight {
    /// The top-level node it is under.
    pub top: usize,
    pub position: DVec3,
    pub color: DVec3,
    /// Candela.
    pub intensity: f64,
}

/// A perspective camera.
#[derive(Clone)]
pub(crate) struct CameraView {
    pub name: String,
    pub position: DVec3,
    pub forward: DVec3,
    pub up: DVec3,
    /// The vertical field of view, radians.
    pub fov_y: f64,
}

/// Bytes of memory the reading takes per byte of the files read, at most (the buffers as read,
/// then positions, indices and corner data in f64), for the check before reading.
pub(crate) const BYTES_PER_FILE_BYTE: u64 = 24;

/// Bytes a placed vertex and triangle take as read (position, corner normals and texture
/// coordinates, indices, material), for the running check against the memory limit.
const BYTES_PER_VERTEX: u64 = 24 + 12 + 8;
const BYTES_PER_TRIANGLE: u64 = 12 + 72 + 48 + 4;

/// Deepest node hierarchy taken (a guard for the recursion; real files are a few levels).
const MAX_DEPTH: usize = 256;

/// The extensions this reader maps (the rest are named in a warning).
const MAPPED: [&str; 4] = [
    "KHR_lights_punctual",
    "KHR_materials_transmission",
    "KHR_materials_ior",
    "KHR_materials_emissive_strength",
];

/// Read the glTF file at `path`.
pub(crate) fn read(path: &Path) -> Result<GltfData, GltfError> {
    let bytes = read_file(path)?;
    let gltf = parse(&bytes)?;
    drop(bytes);
    let base = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let buffers = buffers(&gltf, &base)?;
    let mut warnings = Vec::new();
    if let Some(e) = gltf
        .extensions_required()
        .find(|e| !MAPPED.contains(e) && *e != "KHR_texture_transform")
    {
        return Err(
            format!("it requires the extension {e}, which this renderer does not read").into(),
        );
    }
    let unmapped: Vec<&str> = gltf
        .extensions_used()
        .filter(|e| !MAPPED.contains(e))
        .collect();
    if !unmapped.is_empty() {
        warnings.push(format!(
            "its extensions {} are not mapped and are ignored",
            unmapped.join(", ")
        ));
    }
    let materials = gltf
        .materials()
        .map(|m| material(&m, &buffers, &base, &mut warnings))
        .collect::<Result<Vec<_>, GltfError>>()?;
    let scene = gltf
        .default_scene()
        .or_else(|| gltf.scenes().next())
        .ok_or("it has no scene")?;
    let keys = translations(&gltf, &buffers, &mut warnings)?;
    let mut reading = Reading {
        buffers: &buffers,
        held: 0,
        seen: vec![false; gltf.nodes().len()],
        lights: Vec::new(),
        cameras: Vec::new(),
        warnings,
    };
    let mut nodes = Vec::new();
    for (top, node) in scene.nodes().enumerate() {
        let keys = keys.get(&node.index()).cloned();
        let mut local = node_matrix(&node)?;
        if let Some(k) = &keys {
            // The node as it stands at the file's time 0.
            let at0 = translation_at(k, 0.0);
            local.w_axis = at0.extend(1.0);
        }
        let mut mesh = MeshData::default();
        reading.walk(&node, local, top, 0, &mut mesh)?;
        let name = node
            .name()
            .map_or_else(|| format!("node{}", node.index()), str::to_string);
        nodes.push(TopNode {
            name,
            mesh: (!mesh.triangles.is_empty()).then_some(mesh),
            keys,
        });
    }
    let untaken = gltf.animations().count() > 0
        && keys
            .keys()
            .any(|n| !scene.nodes().any(|top| top.index() == *n));
    if untaken {
        reading.warnings.push(
            "a translation of a node below the top level is animated: only top-level nodes move, the others stand as at time 0".into(),
        );
    }
    Ok(GltfData {
        nodes,
        materials,
        lights: reading.lights,
        cameras: reading.cameras,
        warnings: reading.warnings,
    })
}

/// The document and binary chunk of a `.gltf` or `.glb`, validated. The crate's validation
/// indexes the accessors by each primitive's POSITION before checking that index (a bad one
/// panics): checked first.
fn parse(bytes: &[u8]) -> Result<gltf::Gltf, GltfError> {
    let unread = |e: gltf::Error| format!("not a readable glTF: {e}");
    let raw = gltf::Gltf::from_slice_without_validation(bytes).map_err(unread)?;
    let root = raw.document.as_json();
    let accessors = root.accessors.len();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            if prim.attributes.values().any(|a| a.value() >= accessors) {
                return Err(format!(
                    "not a readable glTF: mesh {m} primitive {p} names an accessor past its {accessors}"
                ).into());
            }
        }
    }
    let document = gltf::Document::from_json(raw.document.into_json()).map_err(unread)?;
    checked_beyond_validation(document.as_json())?;
    Ok(gltf::Gltf {
        document,
        blob: raw.blob,
    })
}

/// What the crate's readers unwrap or call unreachable on and its validation lets through:
/// an image without its MIME type or URI, a camera without the projection its type names, and
/// accessors of a kind a primitive's indices, positions, normals or texture coordinates cannot
/// be (FLOAT indices, say), or of no elements.
fn checked_beyond_validation(root: &gltf::json::Root) -> Result<(), GltfError> {
    use gltf::json::accessor::{ComponentType as C, Type as T};
    use gltf::json::mesh::Semantic;
    use gltf::json::validation::Checked::Valid;
    for (i, img) in root.images.iter().enumerate() {
        let whole = match img.buffer_view {
            Some(_) => img.mime_type.is_some(),
            None => img.uri.is_some(),
        };
        if !whole {
            return Err(format!(
                "image {i} names neither a buffer view with its MIME type nor a URI"
            )
            .into());
        }
    }
    for (i, cam) in root.cameras.iter().enumerate() {
        let whole = match cam.type_ {
            Valid(gltf::json::camera::Type::Perspective) => cam.perspective.is_some(),
            Valid(gltf::json::camera::Type::Orthographic) => cam.orthographic.is_some(),
            _ => false,
        };
        if !whole {
            return Err(format!("camera {i} lacks the projection its type names").into());
        }
    }
    let kind = |a: usize| {
        let acc = &root.accessors[a];
        let c = match acc.component_type {
            Valid(g) => Some(g.0),
            _ => None,
        };
        let t = match acc.type_ {
            Valid(t) => Some(t),
            _ => None,
        };
        (c, t, acc.count.0)
    };
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let bad = |what: &str| -> GltfError {
                format!("mesh {m} primitive {p}: its {what} accessor is of a kind this reader does not take").into()
            };
            if let Some(ix) = &prim.indices {
                match kind(ix.value()) {
                    (Some(C::U8 | C::U16 | C::U32), Some(T::Scalar), n) if n > 0 => {}
                    _ => return Err(bad("indices")),
                }
            }
            for (semantic, a) in &prim.attributes {
                let (c, t, n) = kind(a.value());
                let fine = match semantic {
                    Valid(Semantic::Positions | Semantic::Normals) => {
                        c == Some(C::F32) && t == Some(T::Vec3)
                    }
                    Valid(Semantic::TexCoords(0)) => {
                        matches!(c, Some(C::F32 | C::U8 | C::U16)) && t == Some(T::Vec2)
                    }
                    _ => true,
                };
                if !fine || n == 0 {
                    return Err(bad(&format!("{semantic:?}")));
                }
            }
        }
    }
    Ok(())
}

/// A file's bytes, if it is a regular file within the memory limit.
fn read_file(path: &Path) -> Result<Vec<u8>, GltfError> {
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot read it: {e}"))?;
    if !meta.is_file() {
        return Err("it is not a regular file".into());
    }
    let need = meta.len().saturating_mul(BYTES_PER_FILE_BYTE);
    let what = format!(
        "reading {} ({})",
        path.display(),
        crate::memory::human(meta.len())
    );
    if let Some(why) = crate::memory::too_much(need, &what) {
        return Err(why.into());
    }
    std::fs::read(path).map_err(|e| format!("cannot read it: {e}").into())
}

/// The bytes a URI names: a data URI (base64), or a file relative to `base`.
fn uri_bytes(uri: &str, base: &Path) -> Result<(Vec<u8>, String), GltfError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or("a data URI that is not base64")?;
        let need = (data.len() as u64 / 4 * 3).saturating_mul(BYTES_PER_FILE_BYTE);
        if let Some(why) = crate::memory::too_much(need, "a data URI") {
            return Err(why.into());
        }
        use base64::Engine;
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(data.trim_end())
            .map_err(|e| format!("a data URI that is not base64: {e}"))?;
        return Ok((bytes, "a data URI".into()));
    }
    if uri.contains("://") {
        return Err(format!("`{}` is not a file beside it", crate::text::shown(uri)).into());
    }
    let path: PathBuf = base.join(percent_decoded(uri));
    let bytes = read_file(&path).map_err(|why| format!("{}: {why}", path.display()))?;
    Ok((bytes, path.display().to_string()))
}

/// A relative URI's path with its %XX escapes decoded.
fn percent_decoded(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        match (
            b[i],
            b.get(i + 1).and_then(|&c| hex(c)),
            b.get(i + 2).and_then(|&c| hex(c)),
        ) {
            (b'%', Some(h), Some(l)) => {
                out.push((h * 16 + l) as u8);
                i += 3;
            }
            (c, _, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Every buffer's bytes, each at least as long as the file says it is.
fn buffers(gltf: &gltf::Gltf, base: &Path) -> Result<Vec<Vec<u8>>, GltfError> {
    gltf.buffers()
        .map(|b| {
            let bytes = match b.source() {
                gltf::buffer::Source::Bin => gltf.blob.clone().ok_or_else(|| {
                    format!("buffer {} is the binary chunk, which it lacks", b.index())
                })?,
                gltf::buffer::Source::Uri(uri) => {
                    uri_bytes(uri, base)
                        .map_err(|why| format!("buffer {}: {why}", b.index()))?
                        .0
                }
            };
            if bytes.len() < b.length() {
                return Err(format!(
                    "buffer {} holds {} bytes, less than the {} it claims",
                    b.index(),
                    bytes.len(),
                    b.length()
                )
                .into());
            }
            Ok(bytes)
        })
        .collect()
}

/// A node's local matrix, in f64, checked finite.
fn node_matrix(node: &gltf::Node) -> Result<DMat4, GltfError> {
    let m = node.transform().matrix();
    let m = DMat4::from_cols_array_2d(&m.map(|c| c.map(f64::from)));
    if !m.is_finite() {
        return Err(format!("node {}'s transform is not finite", node.index()).into());
    }
    Ok(m)
}

/// The keyframe value at file time `t` (linear between keys, held before the first and after
/// the last).
pub(crate) fn translation_at(keys: &[(f64, DVec3)], t: f64) -> DVec3 {
    let i = keys.partition_point(|&(k, _)| k <= t);
    match i {
        0 => keys[0].1,
        i if i == keys.len() => keys[i - 1].1,
        i => {
            let ((t0, a), (t1, b)) = (keys[i - 1], keys[i]);
            a + (b - a) * ((t - t0) / (t1 - t0))
        }
    }
}

/// The keyframed translations, by node index. A STEP or CUBICSPLINE translation is refused (a
/// body cannot jump, and a cubic path is not uniform segments); rotations, scales and morph
/// weights are ignored with a warning.
fn translations(
    gltf: &gltf::Gltf,
    buffers: &[Vec<u8>],
    warnings: &mut Vec<String>,
) -> Result<std::collections::HashMap<usize, Vec<(f64, DVec3)>>, GltfError> {
    use gltf::animation::{util::ReadOutputs, Interpolation, Property};
    let mut out = std::collections::HashMap::new();
    let mut ignored = false;
    for anim in gltf.animations() {
        for (c, ch) in anim.channels().enumerate() {
            // The crate's validation leaves a channel's target unchecked (its accessors would
            // panic on a bad one): checked here, on the JSON.
            let target = &gltf.as_json().animations[anim.index()].channels[c].target;
            let property = match (&target.path, target.node.value() < gltf.nodes().len()) {
                (gltf::json::validation::Checked::Valid(p), true) => *p,
                _ => {
                    return Err(format!(
                        "animation {}'s channel {c} targets no node or no property",
                        anim.index()
                    )
                    .into())
                }
            };
            let node = ch.target().node();
            if property != Property::Translation {
                ignored = true;
                continue;
            }
            let what = || {
                format!(
                    "animation {}'s translation of node {}",
                    anim.index(),
                    node.index()
                )
            };
            match ch.sampler().interpolation() {
                Interpolation::Linear => {}
                Interpolation::Step => {
                    return Err(format!(
                        "{} is STEP: a body cannot jump from place to place (key it LINEAR)",
                        what()
                    )
                    .into())
                }
                Interpolation::CubicSpline => {
                    return Err(format!(
                        "{} is CUBICSPLINE: only LINEAR keys become uniform motion",
                        what()
                    )
                    .into())
                }
            }
            let reader = ch.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let times: Vec<f64> = reader
                .read_inputs()
                .ok_or_else(|| format!("{}: its times cannot be read", what()))?
                .map(f64::from)
                .collect();
            let values: Vec<DVec3> = match reader.read_outputs() {
                Some(ReadOutputs::Translations(v)) => {
                    v.map(|p| DVec3::from_array(p.map(f64::from))).collect()
                }
                _ => return Err(format!("{}: its values cannot be read", what()).into()),
            };
            if times.is_empty() || times.len() != values.len() {
                return Err(format!(
                    "{}: {} times and {} values",
                    what(),
                    times.len(),
                    values.len()
                )
                .into());
            }
            if let Some(i) = (0..times.len()).find(|&i| {
                !times[i].is_finite()
                    || !values[i].is_finite()
                    || (i > 0 && times[i] <= times[i - 1])
            }) {
                return Err(format!(
                    "{}: key {i} (time {}, value {}) is not finite or not after the one before",
                    what(),
                    times[i],
                    values[i]
                )
                .into());
            }
            let keys = thinned(times.into_iter().zip(values).collect());
            if out.insert(node.index(), keys).is_some() {
                return Err(format!("{} is the node's second translation", what()).into());
            }
        }
    }
    if ignored {
        warnings.push(
            "its rotation, scale and morph-weight animations are ignored (only translations become motion)".into(),
        );
    }
    Ok(out)
}

/// `keys` without those that lie on the uniform motion between the keys kept around them (to
/// a millionth of its displacement): an exporter that samples every frame (Blender's) writes a
/// straight motion as one key a frame, each rounded to f32, which would otherwise be as many
/// segments of velocities a part in 10^7 apart. What is left moves through every key given.
fn thinned(keys: Vec<(f64, DVec3)>) -> Vec<(f64, DVec3)> {
    let on_line = |a: (f64, DVec3), c: (f64, DVec3), b: (f64, DVec3)| {
        let at = a.1 + (c.1 - a.1) * ((b.0 - a.0) / (c.0 - a.0));
        let tolerance = 1e-6
            * (c.1 - a.1)
                .length()
                .max(1e-9 * (a.1.length() + c.1.length()));
        (b.1 - at).length() <= tolerance
    };
    let mut out = vec![keys[0]];
    let mut from = 0;
    for j in 2..keys.len() {
        if !(from + 1..j).all(|i| on_line(keys[from], keys[j], keys[i])) {
            from = j - 1;
            out.push(keys[from]);
        }
    }
    if keys.len() > 1 {
        out.push(keys[keys.len() - 1]);
    }
    out
}

/// Reading the node tree.
struct Reading<'a> {
    buffers: &'a [Vec<u8>],
    /// Bytes the placed triangles take so far.
    held: u64,
    /// Nodes already placed: a node reached twice is refused (the nodes of a scene are a tree).
    seen: Vec<bool>,
    lights: Vec<PointLight>,
    cameras: Vec<CameraView>,
    warnings: Vec<String>,
}

impl Reading<'_> {
    fn walk(
        &mut self,
        node: &gltf::Node,
        world: DMat4,
        top: usize,
        depth: usize,
        mesh: &mut MeshData,
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
            self.add_mesh(&m, world, mesh)?;
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
                gltf::camera::Projection::Perspective(p)
                    if !(f64::from(p.yfov()) > 0.0
                        && f64::from(p.yfov()) < std::f64::consts::PI) =>
                {
                    return Err(format!(
                        "camera {}'s yfov {} is not between 0 and π",
                        cam.index(),
                        p.yfov()
                    )
                    .into())
                }
                gltf::camera::Projection::Perspective(p) => {
                    let forward = world.transform_vector3(-DVec3::Z).normalize_or_zero();
                    let up = world.transform_vector3(DVec3::Y).normalize_or_zero();
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
            self.walk(&child, m, top, depth + 1, mesh)?;
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
            if prim.mode() != gltf::mesh::Mode::Triangles {
                self.warnings.push(format!(
                    "{} is not triangles ({:?}): it is ignored",
                    what(),
                    prim.mode()
                ));
                continue;
            }
            let reader = prim.reader(|b| self.buffers.get(b.index()).map(Vec::as_slice));
            let positions: Vec<DVec3> = reader
                .read_positions()
                .ok_or_else(|| format!("{} has no positions", what()))?
                .map(|p| world.transform_point3(DVec3::from_array(p.map(f64::from))))
                .collect();
            let n = positions.len();
            let indices: Vec<u32> = match (reader.read_indices(), prim.indices()) {
                (Some(i), _) => i.into_u32().collect(),
                (None, None) => (0..n as u32).collect(),
                (None, Some(_)) => {
                    return Err(format!("{}: its indices lie outside their buffer", what()).into())
                }
            };
            if !indices.len().is_multiple_of(3) {
                return Err(format!(
                    "{}: {} indices, not a whole number of triangles",
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
fn face_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<[DVec3; 3]> {
    triangles
        .iter()
        .map(|t| {
            let v = t.map(|i| positions[i as usize]);
            [(v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero(); 3]
        })
        .collect()
}

/// A material as the file gives it.
fn material(
    m: &gltf::Material,
    buffers: &[Vec<u8>],
    base: &Path,
    warnings: &mut Vec<String>,
) -> Result<GltfMaterial, GltfError> {
    let index = m.index().unwrap_or(0);
    let name = m
        .name()
        .map_or_else(|| format!("material{index}"), str::to_string);
    let pbr = m.pbr_metallic_roughness();
    let f = pbr.base_color_factor().map(f64::from);
    let base_color = DVec3::new(f[0], f[1], f[2]);
    let image = |info: Option<gltf::texture::Info>,
                 role: &str|
     -> Result<Option<Image>, GltfError> {
        let Some(info) = info else { return Ok(None) };
        if info.tex_coord() != 0 {
            return Err(format!(
                "material `{name}`'s {role} texture uses texture coordinates {}; only set 0 is read",
                info.tex_coord()
            ).into());
        }
        image(&info.texture().source(), buffers, base).map(Some)
    };
    let base_texture = image(pbr.base_color_texture(), "base colour")?;
    let emissive_texture = image(m.emissive_texture(), "emissive")?;
    if pbr.metallic_roughness_texture().is_some()
        || m.normal_texture().is_some()
        || m.occlusion_texture().is_some()
    {
        warnings.push(format!(
            "material `{name}`'s metallic-roughness, normal and occlusion textures are not mapped (their factors are)"
        ));
    }
    let strength = f64::from(m.emissive_strength().unwrap_or(1.0));
    let e = m.emissive_factor().map(f64::from);
    let out = GltfMaterial {
        name,
        base_color,
        base_texture,
        metallic: f64::from(pbr.metallic_factor()),
        roughness: f64::from(pbr.roughness_factor()),
        transmission: m
            .transmission()
            .map_or(0.0, |t| f64::from(t.transmission_factor())),
        ior: f64::from(m.ior().unwrap_or(1.5)),
        emissive: DVec3::new(e[0], e[1], e[2]) * strength,
        emissive_texture,
    };
    let numbers = [out.metallic, out.roughness, out.transmission, out.ior];
    if !out.base_color.is_finite()
        || !out.emissive.is_finite()
        || numbers.iter().any(|x| !x.is_finite())
    {
        return Err(format!("material `{}` has a number that is not finite", out.name).into());
    }
    Ok(out)
}

/// An image's texels: a PNG in a buffer view, a data URI or a file beside the glTF file (PNG
/// or EXR).
fn image(img: &gltf::Image, buffers: &[Vec<u8>], base: &Path) -> Result<Image, GltfError> {
    let (bytes, shown, mime) = match img.source() {
        gltf::image::Source::View { view, mime_type } => {
            let data = &buffers[view.buffer().index()];
            let range = view.offset()..view.offset() + view.length();
            let bytes = data
                .get(range)
                .ok_or_else(|| format!("image {}'s buffer view is past its buffer", img.index()))?;
            (
                bytes.to_vec(),
                format!("image {}", img.index()),
                Some(mime_type.to_string()),
            )
        }
        gltf::image::Source::Uri { uri, mime_type } => {
            if !uri.starts_with("data:") && uri.to_ascii_lowercase().ends_with(".exr") {
                let path = base.join(percent_decoded(uri));
                let (w, h, texels) =
                    super::texture::read_image(&path).map_err(|e| e.to_string())?;
                return Ok(Image {
                    shown: path.display().to_string(),
                    width: w,
                    height: h,
                    texels,
                });
            }
            let (bytes, shown) = uri_bytes(uri, base)?;
            (bytes, shown, mime_type.map(str::to_string))
        }
    };
    if !bytes.starts_with(b"\x89PNG") {
        return Err(format!(
            "{shown} ({}) is not a PNG: only PNG (and EXR) textures are read; export with PNG images",
            mime.as_deref().unwrap_or("no type given")
        ).into());
    }
    let (w, h, texels) = super::texture::read_png(std::io::Cursor::new(bytes), Path::new(&shown))
        .map_err(|e| e.to_string())?;
    Ok(Image {
        shown,
        width: w,
        height: h,
        texels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_hold_before_and_after_and_are_linear_between() {
        let k = [(1.0, DVec3::X), (3.0, DVec3::new(3.0, 2.0, 0.0))];
        assert_eq!(translation_at(&k, 0.0), DVec3::X);
        assert_eq!(translation_at(&k, 2.0), DVec3::new(2.0, 1.0, 0.0));
        assert_eq!(translation_at(&k, 9.0), DVec3::new(3.0, 2.0, 0.0));
    }

    #[test]
    fn keys_on_a_straight_motion_are_one_segment() {
        // A baked motion: a key a frame, rounded to f32, then a stop and a turn.
        let mut keys: Vec<(f64, DVec3)> = (1..=49)
            .map(|f| {
                let t = f64::from(f as f32 / 24.0);
                (t, DVec3::new(f64::from((f - 1) as f32 / 24.0), -1.5, -10.0))
            })
            .collect();
        keys.push((3.0, keys[48].1));
        keys.push((4.0, keys[48].1 + DVec3::Y));
        let kept = thinned(keys.clone());
        assert_eq!(kept, vec![keys[0], keys[48], keys[49], keys[50]]);
        // A curve keeps its keys.
        let curve: Vec<(f64, DVec3)> = (0..10)
            .map(|i| {
                (
                    f64::from(i),
                    DVec3::new(f64::from(i), f64::from(i * i), 0.0),
                )
            })
            .collect();
        assert_eq!(thinned(curve.clone()), curve);
        assert_eq!(thinned(vec![curve[0]]), vec![curve[0]]);
    }

    #[test]
    fn uris_lose_their_escapes() {
        assert_eq!(percent_decoded("my%20mesh.bin"), "my mesh.bin");
        assert_eq!(percent_decoded("100%"), "100%");
        assert_eq!(percent_decoded("a%zz"), "a%zz");
    }
}
