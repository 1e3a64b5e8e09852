//! glTF 2.0 files (`.gltf` with its buffers and images beside it or in data URIs, or `.glb`)
//! read through the `gltf` crate into what the scene holds: the default scene's top-level
//! nodes, each with the triangles of its whole subtree placed by every transform below it
//! (`MeshData`, in the file's coordinates at the file's time 0), the materials, the point
//! lights and perspective cameras of the subtree, and the keyframed translations of top-level
//! nodes. The buffers are read here, not by the crate: every file is checked to be a regular
//! file and against the memory limit before it is read, and every accessor against its data.
//! What goes wrong is said in words; the caller names the scene's line and key.
//!
//! Here the file as a whole (its parts, read, the checks the crate's validation leaves out);
//! bytes from files and URIs in `files.rs`, the node tree in `nodes.rs`, materials in
//! `materials.rs`, translation keys in `keys.rs`.

mod files;
mod keys;
mod materials;
mod nodes;

use files::{buffers, read_file};
use keys::{translation_at, translations};
use materials::material;
use nodes::{node_matrix, Reading};

use super::mesh_file::MeshData;
use super::texture::Texels;
use glam::DVec3;
use std::path::Path;

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
#[derive(Clone)]
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
    /// The meshes several nodes place, each read once in its own coordinates, by mesh index
    /// (the nodes' `placements` name them).
    pub shared: std::collections::BTreeMap<usize, MeshData>,
}

/// A top-level node and everything below it.
#[derive(Clone)]
pub(crate) struct TopNode {
    pub name: String,
    /// The subtree's triangles (none where it has no mesh); `material_of` gives the file's
    /// material by index.
    pub mesh: Option<MeshData>,
    /// Its placements of meshes several nodes place (`GltfData::shared`).
    pub placements: Vec<nodes::MeshPlacement>,
    /// Its keyframed translation: (file time, translation), times increasing; the node stands
    /// as at time 0 in `mesh`.
    pub keys: Option<Vec<(f64, DVec3)>>,
}

/// A metallic-roughness material (with the transmission, IOR and emissive-strength
/// extensions), its colours linear RGB.
#[derive(Clone)]
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
#[derive(Clone)]
pub(crate) struct Image {
    pub shown: String,
    pub width: usize,
    pub height: usize,
    pub texels: Texels,
}

/// A `KHR_lights_punctual` point light.
#[derive(Clone)]
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

/// Read the glTF file at `path`. A mesh that several nodes place is held once, unless a node
/// placing it is a group of its own (`split_all`: every top-level node; else a keyframed one),
/// whose group is built alone: it holds a copy. `share_every`: every mesh is held so, as for
/// a file that several entries of the scene place.
pub(crate) fn read(path: &Path, split_all: bool, share_every: bool) -> Result<GltfData, GltfError> {
    let bytes = read_file(path)?;
    // A `.glb` without its magic would be read as JSON, and said to be bad JSON.
    let glb = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if glb && !bytes.starts_with(b"glTF") {
        return Err("not a readable glTF: a .glb must begin with the bytes `glTF` (a binary glTF's magic), and this one does not".into());
    }
    if glb {
        glb_length_checked(&bytes)?;
    }
    let gltf = parse(&bytes)?;
    drop(bytes);
    let base = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let buffers = buffers(&gltf, &base)?;
    sparse_indices_checked(gltf.document.as_json(), &buffers)?;
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
        uses: if share_every {
            vec![2; gltf.meshes().len()]
        } else {
            mesh_uses(&scene, gltf.meshes().len())
        },
        shared: Default::default(),
        share: true,
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
        reading.share = !split_all && keys.is_none();
        let (mut mesh, mut placements) = (MeshData::default(), Vec::new());
        reading.walk(&node, local, top, 0, &mut mesh, &mut placements)?;
        let name = node
            .name()
            .map_or_else(|| format!("node{}", node.index()), str::to_string);
        nodes.push(TopNode {
            name,
            mesh: (!mesh.triangles.is_empty()).then_some(mesh),
            placements,
            keys,
        });
    }
    // The walk has refused cycles: each keyed node's subtree is a tree.
    fn holds_camera(n: &gltf::Node) -> bool {
        n.camera().is_some() || n.children().any(|c| holds_camera(&c))
    }
    if let Some(n) = gltf
        .nodes()
        .find(|n| keys.contains_key(&n.index()) && holds_camera(n))
    {
        reading.warnings.push(format!(
            "node {}'s translation is animated and it holds a camera: the camera stands where it is at time 0 (give [camera] a velocity or worldline to move it)",
            n.index()
        ));
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
        shared: reading.shared,
    })
}

/// How many nodes of `scene` place each of the file's `meshes` meshes, counted to 2 (all the
/// walk asks: one, or several). A node reached twice is counted twice here and refused by the
/// walk; the count stops after 2^24 nodes, where a cycle would keep it going.
fn mesh_uses(scene: &gltf::Scene, meshes: usize) -> Vec<usize> {
    let mut uses = vec![0; meshes];
    let mut stack: Vec<gltf::Node> = scene.nodes().collect();
    let mut budget = 1usize << 24;
    while let Some(n) = stack.pop() {
        budget -= 1;
        if budget == 0 {
            break;
        }
        if let Some(u) = n.mesh().and_then(|m| uses.get_mut(m.index())) {
            *u = (*u + 1).min(2);
        }
        stack.extend(n.children());
    }
    uses
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

/// A binary glTF's header gives the file's whole length (bytes 8 to 12, little-endian): a
/// file cut short or with bytes after it says otherwise.
fn glb_length_checked(bytes: &[u8]) -> Result<(), GltfError> {
    let Some(said) = bytes.get(8..12) else {
        return Err(format!(
            "not a readable glTF: a .glb's header is 12 bytes, and this file has {}",
            bytes.len()
        )
        .into());
    };
    let said = u32::from_le_bytes([said[0], said[1], said[2], said[3]]);
    if u64::from(said) != bytes.len() as u64 {
        return Err(format!(
            "not a readable glTF: its .glb header says the file is {said} bytes long, and it is {} (cut short, or joined to other bytes)",
            bytes.len()
        )
        .into());
    }
    Ok(())
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
    // A node's transform as glTF 2.0 allows it: a matrix or TRS, not both (the crate takes
    // the matrix and drops the rest), a matrix that is an affine TRS (last row 0, 0, 0, 1),
    // a rotation of unit length (a zero one read as no rotation).
    for (i, node) in root.nodes.iter().enumerate() {
        let trs = node.translation.is_some() || node.rotation.is_some() || node.scale.is_some();
        if let Some(m) = node.matrix {
            if trs {
                return Err(format!(
                    "node {i} gives both a matrix and translation, rotation or scale; glTF 2.0 takes one or the other"
                )
                .into());
            }
            if [m[3], m[7], m[11], m[15]] != [0.0, 0.0, 0.0, 1.0] {
                return Err(format!(
                    "node {i}'s matrix is not a placement (its last row is {:?}, not [0, 0, 0, 1])",
                    [m[3], m[7], m[11], m[15]]
                )
                .into());
            }
        }
        if let Some(q) = node.rotation {
            let len =
                q.0.iter()
                    .map(|x| f64::from(*x).powi(2))
                    .sum::<f64>()
                    .sqrt();
            if len.is_nan() || (len - 1.0).abs() > 1e-3 {
                return Err(format!(
                    "node {i}'s rotation {:?} is not a unit quaternion (its length is {len})",
                    q.0
                )
                .into());
            }
        }
    }
    // glTF 2.0 only (a 1.0 file's keys mean other things), as `asset` says.
    let major = |v: &str| v.split('.').next().map(str::to_string);
    if major(&root.asset.version).as_deref() != Some("2")
        || root
            .asset
            .min_version
            .as_deref()
            .and_then(major)
            .as_deref()
            .is_some_and(|m| m != "2")
    {
        return Err(format!(
            "its asset.version is \"{}\"{}: this reader reads glTF 2.0",
            crate::text::shown(&root.asset.version),
            root.asset
                .min_version
                .as_deref()
                .map(|m| format!(" (minVersion \"{}\")", crate::text::shown(m)))
                .unwrap_or_default()
        )
        .into());
    }
    // Every buffer holds at least a byte, and every view lies within the bytes its buffer
    // declares (the reader checks the buffer's bytes reach that far: `files::buffers`).
    for (b, buffer) in root.buffers.iter().enumerate() {
        if buffer.byte_length.0 == 0 {
            return Err(format!("buffer {b}'s byteLength is 0; glTF 2.0 asks at least 1").into());
        }
    }
    for (v, view) in root.buffer_views.iter().enumerate() {
        let Some(buffer) = root.buffers.get(view.buffer.value()) else {
            continue;
        };
        let end = (view.byte_offset.map_or(0, |o| o.0)).saturating_add(view.byte_length.0);
        if end > buffer.byte_length.0 {
            return Err(format!(
                "buffer view {v} reaches byte {end} of buffer {}, past the {} bytes its byteLength declares",
                view.buffer.value(),
                buffer.byte_length.0
            )
            .into());
        }
    }
    // The crate's readers assert that an element fits its stride (a panic otherwise), and
    // glTF 2.0 asks an accessor's offsets to be multiples of its component's size.
    for (i, acc) in root.accessors.iter().enumerate() {
        let (Valid(c), Valid(t), Some(view)) = (acc.component_type, acc.type_, acc.buffer_view)
        else {
            continue;
        };
        let Some(view) = root.buffer_views.get(view.value()) else {
            continue;
        };
        let (size, element) = (c.0.size(), c.0.size() * t.multiplicity());
        if let Some(stride) = view.byte_stride {
            if stride.0 < element || stride.0 % size != 0 {
                return Err(format!(
                    "accessor {i}: its buffer view's byteStride {} does not hold its {element}-byte elements in steps of {size} bytes, as glTF 2.0 requires",
                    stride.0
                )
                .into());
            }
        }
        let offset = (acc.byte_offset.map_or(0, |o| o.0))
            .saturating_add(view.byte_offset.map_or(0, |o| o.0));
        if offset % size as u64 != 0 {
            return Err(format!(
                "accessor {i}: its data starts at byte {offset} of its buffer, not a multiple of its {size}-byte components, as glTF 2.0 requires"
            )
            .into());
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
                    (Some(C::U8 | C::U16 | C::U32), Some(T::Scalar), _) => {
                        return Err(format!(
                            "mesh {m} primitive {p}: its indices accessor has no elements (count 0)"
                        )
                        .into())
                    }
                    _ => return Err(bad("indices")),
                }
            }
            for (semantic, a) in &prim.attributes {
                let (c, t, n) = kind(a.value());
                // The kind this reader takes, where the file gives another.
                let wanted = match semantic {
                    Valid(Semantic::Positions | Semantic::Normals)
                        if !(c == Some(C::F32) && t == Some(T::Vec3)) =>
                    {
                        Some("VEC3 of FLOAT")
                    }
                    Valid(Semantic::TexCoords(0))
                        if !(matches!(c, Some(C::F32 | C::U8 | C::U16)) && t == Some(T::Vec2)) =>
                    {
                        Some("VEC2 of FLOAT, UNSIGNED_BYTE or UNSIGNED_SHORT")
                    }
                    _ => None,
                };
                // As the file names it: POSITION, NORMAL, TEXCOORD_0.
                let name = || semantic.to_string();
                if let Some(wanted) = wanted {
                    return Err(format!(
                        "mesh {m} primitive {p}: its {} accessor is not {wanted}, as glTF 2.0 requires",
                        name()
                    )
                    .into());
                }
                if n == 0 {
                    return Err(format!(
                        "mesh {m} primitive {p}: its {} accessor has no elements (count 0)",
                        name()
                    )
                    .into());
                }
            }
        }
    }
    Ok(())
}

/// A sparse accessor's indices within its elements: the crate's reader skips one past them
/// without a word, leaving the element the file meant to change as it was.
fn sparse_indices_checked(root: &gltf::json::Root, buffers: &[Vec<u8>]) -> Result<(), GltfError> {
    use gltf::json::validation::Checked::Valid;
    for (i, acc) in root.accessors.iter().enumerate() {
        let Some(sparse) = &acc.sparse else { continue };
        let ix = &sparse.indices;
        let (Valid(kind), Some(view)) = (
            ix.component_type,
            root.buffer_views.get(ix.buffer_view.value()),
        ) else {
            continue;
        };
        let size = kind.0.size();
        let start = view
            .byte_offset
            .map_or(0, |o| o.0)
            .saturating_add(ix.byte_offset.0);
        let len = sparse.count.0.saturating_mul(size as u64);
        let bytes = buffers
            .get(view.buffer.value())
            .and_then(|b| {
                b.get(usize::try_from(start).ok()?..usize::try_from(start.checked_add(len)?).ok()?)
            })
            .ok_or_else(|| format!("accessor {i}: its sparse indices lie outside their buffer"))?;
        let mut indices = bytes.chunks_exact(size).map(|c| match size {
            1 => u64::from(c[0]),
            2 => u64::from(u16::from_le_bytes([c[0], c[1]])),
            _ => u64::from(u32::from_le_bytes([c[0], c[1], c[2], c[3]])),
        });
        if let Some(bad) = indices.find(|&k| k >= acc.count.0) {
            return Err(format!(
                "accessor {i}: a sparse index {bad} is past its {} elements",
                acc.count.0
            )
            .into());
        }
    }
    Ok(())
}
