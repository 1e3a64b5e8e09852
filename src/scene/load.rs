//! From the scene tree to a validated [`Scene`].

use super::camera_keys::{camera, film};
use super::doc::Doc;
use super::gltf_object;
use super::lights::light;
use super::model::*;
use super::objects::{add_mesh_data, add_object, material_and_transform, OBJECT_KEYS};
use super::reader::{SceneResult, Table};
use super::speed::velocity;
use super::surfaces::{material, sky, textures};
// A group's `worldline` key and the groups it makes.
use super::segments as worldline;
use super::settings::{image, render_settings};
use super::{PassSet, SceneError, Texture};
use crate::geometry::Geometry;
use crate::spacetime::Velocity;
use crate::spectrum::{Colour, Role};
use std::collections::HashMap;
use std::sync::Arc;

/// Read a scene file, apply overrides `(shown, KEY=VALUE)` in order (`shown` names the flag in
/// errors, e.g. `--set camera.time=3`), and validate the result.
pub fn load_file(
    path: &std::path::Path,
    overrides: &[(String, String)],
) -> Result<Scene, SceneError> {
    load_file_as(path, overrides, FrameSize::Checked)
}

/// Whether loading refuses a frame larger than one render holds ([`MAX_FRAME_PIXELS`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameSize {
    /// Refused at the key that sets it.
    Checked,
    /// Left to the caller, who renders the image in tiles and checks each tile's frame.
    InTiles,
}

/// As [`load_file`], the frame's size checked as `frame` says.
pub(crate) fn load_file_as(
    path: &std::path::Path,
    overrides: &[(String, String)],
    frame: FrameSize,
) -> Result<Scene, SceneError> {
    let shown = path.display().to_string();
    // The text alone first (`BYTES_PER_SCENE_BYTE`), before it is read; its values after.
    if let Ok(m) = std::fs::metadata(path) {
        let need = m.len().saturating_mul(crate::memory::BYTES_PER_SCENE_BYTE);
        let what = format!("reading a scene file of {}", crate::memory::human(m.len()));
        if let Some(why) = crate::memory::too_much(need, &what) {
            return Err(SceneError::new(shown, "", why));
        }
    }
    let text = read_bounded(path, &shown)?;
    // The tree is refused here, by the file's count of values, rather than aborted halfway.
    let need = crate::memory::scene_bytes(text.as_bytes());
    let what = format!(
        "reading the scene file ({}, every value kept with its line)",
        crate::memory::human(text.len() as u64)
    );
    if let Some(why) = crate::memory::too_much(need, &what) {
        return Err(SceneError::new(shown, "", why));
    }
    load_str_as(&shown, &text, overrides, frame)
}

/// The most a scene path that is not a regular file (a FIFO, `<(...)`, a device) is read: it
/// has no length to check beforehand, and `/dev/urandom` would never end.
const MAX_STREAMED_SCENE: u64 = 256 << 20;

/// The scene file's text, read a piece at a time: it ends with an error, not a hang or an
/// abort, where the file is not UTF-8 text, is larger than memory allows
/// (`BYTES_PER_SCENE_BYTE`) or, not being a regular file, runs past `MAX_STREAMED_SCENE`.
fn read_bounded(path: &std::path::Path, shown: &str) -> Result<String, SceneError> {
    use std::io::Read;
    let fail = |why: String| SceneError::new(shown, "", why);
    let mut file =
        std::fs::File::open(path).map_err(|e| fail(format!("cannot read the scene file: {e}")))?;
    let regular = file.metadata().map(|m| m.is_file()).unwrap_or(false);
    if file.metadata().is_ok_and(|m| m.is_dir()) {
        return Err(fail("cannot read the scene file: it is a directory".into()));
    }
    let mut text = Vec::new();
    let mut piece = vec![0u8; 1 << 16];
    // Bytes known to be whole UTF-8 so far (a piece may end inside a character).
    let mut checked = 0;
    loop {
        let n = match file.read(&mut piece) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(fail(format!("cannot read the scene file: {e}"))),
        };
        text.extend_from_slice(&piece[..n]);
        match std::str::from_utf8(&text[checked..]) {
            Ok(_) => checked = text.len(),
            Err(e) if e.error_len().is_some() => {
                return Err(fail(format!(
                    "not UTF-8 text (an invalid byte at byte {}): a scene is a TOML text file",
                    checked + e.valid_up_to()
                )))
            }
            Err(e) => checked += e.valid_up_to(),
        }
        let len = text.len() as u64;
        if !regular && len > MAX_STREAMED_SCENE {
            return Err(fail(format!(
                "not a regular file, and more than {} came from it: a scene is read whole",
                crate::memory::human(MAX_STREAMED_SCENE)
            )));
        }
        let need = len.saturating_mul(crate::memory::BYTES_PER_SCENE_BYTE);
        let what = format!("reading a scene file of over {}", crate::memory::human(len));
        if let Some(why) = crate::memory::too_much(need, &what) {
            return Err(fail(why));
        }
    }
    String::from_utf8(text).map_err(|_| fail("not UTF-8 text: it ends inside a character".into()))
}

/// As [`load_file`], from text; `file` names it in errors.
pub fn load_str(
    file: &str,
    text: &str,
    overrides: &[(String, String)],
) -> Result<Scene, SceneError> {
    load_str_as(file, text, overrides, FrameSize::Checked)
}

fn load_str_as(
    file: &str,
    text: &str,
    overrides: &[(String, String)],
    frame: FrameSize,
) -> Result<Scene, SceneError> {
    let mut doc = Doc::parse(file, text)?;
    for (shown, set) in overrides {
        doc.apply_set(shown, set, super::superseded)?;
    }
    let (scene, inputs) = super::inputs::recorded(|| build(&doc, frame));
    let mut scene = scene?;
    scene.inputs = inputs;
    Ok(scene)
}

fn build(doc: &Doc, frame: FrameSize) -> SceneResult<Scene> {
    let root = Table::root(doc)?;
    let image = match root.table("image")? {
        Some(t) => image(&t, frame)?,
        None => ImageSettings {
            width: 512,
            height: 512,
            samples: 1,
            background: Colour::grey(0.0, Role::Emitter),
            crop: None,
            transparent: None,
            passes: PassSet::ALL,
        },
    };
    let render = match root.table("render")? {
        Some(t) => render_settings(&t)?,
        None => RenderSettings::default(),
    };
    let textures = textures(&root)?;
    let (mut materials, material_ids) = materials(&root, &textures)?;
    let group_tables = root.tables("group")?;
    // Sized for a group each (a worldline's segments and a glTF file's nodes may add more).
    let mut groups: Vec<Group> = Vec::with_capacity(group_tables.len());
    let mut objects = Vec::new();
    let mut total: u64 = 0;
    let mut group_names = hashbrown::HashSet::with_capacity(group_tables.len());
    let mut imports = gltf_object::Imports::default();
    let mut meshes = super::shared_meshes::SharedMeshes::scan(&group_tables)?;
    // Many groups of plain objects are read on every thread (scene/many_groups.rs); where
    // that cannot give what the loop below gives, the loop reads them (fresh tables).
    let group_tables = match super::many_groups::plain(&group_tables) {
        Some(counts) => {
            match super::many_groups::read(group_tables, &counts, &material_ids, &materials) {
                Some(read) => {
                    (groups, objects, total) = read;
                    Vec::new()
                }
                None => root.tables("group")?,
            }
        }
        None => group_tables,
    };
    for t in &group_tables {
        let name = t.req_string("name")?;
        if !group_names.insert(name.to_string()) {
            return Err(t.error("name", format!("a group named `{name}` is defined twice")));
        }
        let (ids, index) = (&material_ids, groups.len());
        let g = group(
            t,
            name,
            ids,
            &mut materials,
            (&mut objects, 0),
            index,
            &mut total,
            &mut imports,
            &mut meshes,
        )?;
        // A glTF node's own group, named `<group>/<node>`: its name once among the groups (a
        // group of several worldline pieces names each piece so).
        let own: std::collections::BTreeSet<&str> = g
            .iter()
            .map(|x| x.name.as_str())
            .filter(|n| *n != name)
            .collect();
        for n in own {
            if !group_names.insert(n.to_string()) {
                return Err(t.error("object", format!("two groups are named `{n}` (a glTF file's nodes of one name, or a [[group]] named so)")));
            }
        }
        groups.extend(g);
    }
    // The camera: the scene's own, else a glTF file's.
    let (camera, flash) = match root.table("camera")? {
        Some(t) => camera(&t, gltf_object::file_camera(&imports))?,
        None => match gltf_object::camera(&imports) {
            Some(c) => (c, None),
            None => {
                return Err(root.missing_table(
                    "camera",
                    "the scene needs a [camera] table (or a glTF object whose file holds a perspective camera)",
                ))
            }
        },
    };
    // Without objects only a sky is worth rendering.
    if groups.iter().all(|g| g.geometry.is_empty()) && !root.has("sky") {
        return Err(root.error(
            "group",
            "the scene is empty: add a [[group]] with at least one [[group.object]] (box, sphere, rod, mesh, lattice or bar_array), or a [sky]",
        ));
    }
    if render.integrator == Integrator::Path && groups.iter().any(|g| g.geometry.spins()) {
        return Err(root.error(
            "render",
            "spinning objects are not built yet for integrator = \"path\" (Whitted shades them in each point's own frame)",
        ));
    }
    if render.integrator == Integrator::Path && groups.iter().any(|g| g.accelerated.is_some()) {
        return Err(root.error(
            "render",
            "groups on accelerated segments are not built yet for integrator = \"path\" (Whitted shades them in each point's own frame)",
        ));
    }
    let mut lights = Vec::new();
    let mut light_names = std::collections::HashSet::new();
    for t in root.tables("light")? {
        // `--set light.<name>.…` reaches the first of a name: the others could not be.
        if let Some(name) = t.string("name")? {
            if !light_names.insert(name) {
                return Err(t.error("name", format!("a light named `{name}` is defined twice")));
            }
        }
        lights.push(light(&t, &groups)?);
    }
    lights.extend(flash);
    lights.extend(imports.lights);
    let film = root.table("film")?.map(|t| film(&t, &camera)).transpose()?;
    let sky = root.table("sky")?.map(|t| sky(&t)).transpose()?;
    let fog = match root.table("fog")? {
        Some(t) => Some(fog(&t, &groups, &mut materials)?),
        None => None,
    };
    // A sky is meant to be seen: the image shows it unless the scene asks for transparency.
    let mut image = image;
    if sky.is_some() && image.transparent.is_none() {
        image.transparent = Some(false);
    }
    root.finish(&[
        "camera", "image", "render", "material", "texture", "light", "group", "film", "sky", "fog",
    ])?;
    Ok(Scene {
        camera,
        image,
        render,
        materials,
        lights,
        groups,
        objects,
        film,
        sky,
        fog,
        warnings: imports.warnings,
        inputs: Vec::new(),
    })
}

/// The scene's materials (the default white first, as id 0) and their ids by name.
fn materials(
    root: &Table,
    textures: &[super::surfaces::ReadTexture],
) -> SceneResult<(Vec<Material>, HashMap<String, u32>)> {
    let mut materials = vec![Material::default_white()];
    let mut material_ids: HashMap<String, u32> = HashMap::new();
    for t in root.tables("material")? {
        let m = material(&t, textures)?;
        if material_ids.contains_key(&m.name) {
            return Err(t.error(
                "name",
                format!("a material named `{}` is defined twice", m.name),
            ));
        }
        material_ids.insert(m.name.clone(), materials.len() as u32);
        materials.push(m);
    }
    Ok((materials, material_ids))
}

/// A `[[group]]` (its first group the `index`th, named `name`) and its objects, appended to
/// `objects`; `total` counts the scene's primitives. A group with a worldline of several
/// segments is a group per segment; a glTF file's top-level nodes that are groups of their own
/// (`groups = "nodes"`, or keyframed) follow, named `<name>/<node>`.
/// An object's id is the number beside `objects` (the ids before a list that starts
/// mid-scene, scene/many_groups.rs) plus the objects already in the list.
#[allow(clippy::too_many_arguments)]
pub(super) fn group(
    t: &Table,
    name: &str,
    material_ids: &HashMap<String, u32>,
    materials: &mut Vec<Material>,
    (objects, id_base): (&mut Vec<ObjectInfo>, usize),
    index: usize,
    total: &mut u64,
    imports: &mut gltf_object::Imports,
    meshes: &mut super::shared_meshes::SharedMeshes,
) -> SceneResult<Vec<Group>> {
    let segments = worldline::read(t, "direction", super::segments::Whose::Group)?;
    let velocity = match segments {
        Some(_) => Velocity::ZERO,
        None => velocity(t, "direction")?.unwrap_or(Velocity::ZERO),
    };
    let moves = segments.is_some() || velocity != Velocity::ZERO;
    let mut geometry = Geometry::default();
    let entries = t.tables("object")?;
    let mut own_groups = Vec::new();
    let mut object_names = std::collections::HashSet::new();
    for (k, o) in entries.iter().enumerate() {
        // `--set group.<group>.object.<name>.…` reaches the first of a name: the others could
        // not be.
        if let Some(object) = o.string("name")? {
            if !object_names.insert(object) {
                return Err(o.error(
                    "name",
                    format!(
                        "group `{name}` holds two objects named `{object}`: give each its own name"
                    ),
                ));
            }
        }
        let id = (id_base + objects.len()) as u32;
        let (first, implicit, parts) = (
            geometry.prims.len(),
            geometry.implicit.len(),
            geometry.parts.len(),
        );
        let kind = if o.string("type")? == Some("gltf") {
            let group = gltf_object::InGroup {
                velocity,
                moves,
                on_worldline: segments.is_some(),
            };
            let mut placed =
                gltf_object::place(o, group, materials, material_ids, imports, meshes)?;
            let (mat, place) = material_and_transform(o, material_ids)?;
            if let Some(mesh) = placed.stays.take() {
                let (geo, chosen) = (&mut geometry, placed.chosen.clone());
                add_mesh_data(o, id, mat, place, geo, total, mesh, chosen, material_ids)?;
            }
            let geo = &mut geometry;
            gltf_object::place_instances(
                o,
                id,
                mat,
                place,
                &placed,
                material_ids,
                (geo, total),
                meshes,
            )?;
            own_groups.push((k, placed.own, placed.chosen, mat, place));
            "gltf".to_string()
        } else {
            add_object(o, id, material_ids, &mut geometry, total, meshes)?
        };
        check_object(o, &kind, &geometry, materials, (first, implicit, parts))?;
        objects.push(ObjectInfo {
            name: o.string("name")?.map(str::to_string),
            kind,
            group: index,
        });
        o.finish(OBJECT_KEYS)?;
    }
    if let Some(key) = OBJECT_KEYS.iter().find(|k| **k != "name" && t.has(k)) {
        let n = t.get(key).expect("present");
        return Err(t.error_at(
            n,
            key,
            format!("`{key}` belongs to an object: address it as group.{name}.object.<object name or index>.{key}"),
        ));
    }
    t.finish(&[
        "name",
        "velocity",
        "direction",
        "beta",
        "rapidity",
        "one_minus_beta",
        "object",
        "worldline",
    ])?;
    let mut out = groups_of(
        t,
        name,
        geometry,
        segments.clone(),
        velocity,
        materials,
        total,
    )?;
    let mut own_names = std::collections::HashSet::new();
    for (k, own, chosen, mat, place) in own_groups {
        let o = &entries[k];
        for g in own {
            if !own_names.insert(g.node.clone()) {
                return Err(o.error(
                    "file",
                    format!("two top-level nodes are named `{}`: each is a group of its own, `{name}/{}`, and groups need names of their own (rename one in the file)", g.node, g.node),
                ));
            }
            let id = (id_base + objects.len()) as u32;
            let mut geometry = Geometry::default();
            let (geo, chosen) = (&mut geometry, chosen.clone());
            add_mesh_data(o, id, mat, place, geo, total, g.mesh, chosen, material_ids)?;
            check_object(o, "gltf", &geometry, materials, (0, 0, 0))?;
            // The object is named as its group, `<group>/<node>`: nodes of one name in two
            // entries' groups stay apart in the mattes and the probe.
            let named = format!("{name}/{}", g.node);
            objects.push(ObjectInfo {
                name: Some(named.clone()),
                kind: "gltf".into(),
                group: index + out.len(),
            });
            // A node of a moving group that is not keyframed moves with the group.
            let line = g.segments.or_else(|| segments.clone());
            out.extend(groups_of(
                o, &named, geometry, line, velocity, materials, total,
            )?);
        }
    }
    Ok(out)
}

/// The groups one group's geometry makes: one, or one per piece of its worldline (`segments`),
/// with what such groups cannot hold refused (`t` names where).
fn groups_of(
    t: &Table,
    name: &str,
    geometry: Geometry,
    segments: Option<Vec<super::worldline::Segment>>,
    velocity: Velocity,
    materials: &[Material],
    total: &mut u64,
) -> SceneResult<Vec<Group>> {
    let count = segments.as_deref().map_or(1, worldline::group_count);
    if count > 1 {
        // Each segment holds a copy of the group's listed primitives.
        let copies = (count - 1) as u64;
        let held = copies.saturating_mul(geometry.prims.len() as u64);
        super::objects::budget(t, "worldline", total, held)?;
        if holds_glass_or_media(&geometry, materials) {
            return Err(t.error(
                "worldline",
                "glass and media in a group whose velocity changes are not built yet (light inside them would be followed in one segment's frame)",
            ));
        }
    }
    if geometry.turns() {
        if segments.is_some() {
            return Err(t.error(
                "worldline",
                "a spinning box, wheel or rod about a cross axis in a group whose velocity changes is not built yet",
            ));
        }
        if holds_glass_or_media(&geometry, materials) {
            return Err(t.error(
                "object",
                "glass and media in a group with a spinning box, wheel or rod about a cross axis are not built yet (light inside them is followed in the group's frame, where the turning body is not)",
            ));
        }
        if geometry.len() > worldline::MAX_ACCELERATED_PRIMS {
            return Err(t.error(
                "object",
                format!("the group has {} primitives and a spinning box, wheel or rod about a cross axis: such a group is intersected primitive by primitive, at most {}", geometry.len(), worldline::MAX_ACCELERATED_PRIMS),
            ));
        }
    }
    if segments.as_deref().is_some_and(worldline::accelerates) {
        if let Some(why) = worldline::accelerated_refusal(&geometry) {
            return Err(t.error("worldline", why));
        }
    }
    let geometry = Arc::new(geometry);
    Ok(match segments {
        Some(s) => worldline::groups(t, name, geometry, &s)?,
        None => vec![Group {
            name: name.to_string(),
            velocity,
            geometry,
            window: None,
            accelerated: None,
            turn: None,
        }],
    })
}

/// Whether any part of `geometry` is glass or holds a medium: light inside it is followed in
/// its group's frame, which a group whose velocity changes or that holds a turning body lacks.
fn holds_glass_or_media(geometry: &Geometry, materials: &[Material]) -> bool {
    geometry.parts.iter().any(|p| {
        let m = &materials[p.material as usize];
        m.transmit > 0.0 || m.medium.is_some()
    })
}

/// Refuse an object just added to `geometry` (its held primitives from `first`, its implicit
/// ones from `implicit`, its parts from `parts`: an object's parts are the last added, so a
/// group of many objects is checked in time linear in them) that an image texture cannot be
/// mapped onto, or that reaches farther than coordinates may.
/// The keys that say where an object's points are, besides its `type`.
const PLACING_KEYS: [&str; 14] = [
    "center",
    "radius",
    "min",
    "max",
    "from",
    "to",
    "origin",
    "spacing",
    "counts",
    "length",
    "bar_size",
    "translate",
    "scale",
    "file",
];

fn check_object(
    o: &Table,
    kind: &str,
    geometry: &Geometry,
    materials: &[Material],
    (first, implicit, parts): (usize, usize, usize),
) -> SceneResult<()> {
    let own = &geometry.parts[parts..];
    let spins_inside = own.iter().any(|p| {
        let m = &materials[p.material as usize];
        p.spin.is_some() && (m.transmit > 0.0 || m.medium.is_some())
    });
    if spins_inside {
        return Err(o.error(
            "spin",
            "a spinning object of glass or with a medium is not built yet (light inside it would be followed in its group's frame, not its points')",
        ));
    }
    // An image needs a mapping: spheres, boxes and rods have one, a mesh its file's
    // texture coordinates.
    let imaged = |m: u32| {
        let m = &materials[m as usize];
        [&m.color_texture, &m.emission_texture]
            .into_iter()
            .flatten()
            .any(|t| matches!(**t, Texture::Image(_)))
    };
    // (A box turned into triangles keeps its box's mapping through its placement.)
    let unmapped = own.iter().any(|part| {
        let triangles = matches!(
            geometry.prim(part.start),
            crate::geometry::Primitive::Triangle { .. }
        );
        triangles
            && imaged(part.material)
            && part.corners.as_ref().is_none_or(|c| c.uvs.is_none())
            && part.placement.as_ref().is_none_or(|pl| pl.shape.is_none())
    });
    if unmapped {
        return Err(o.error(
            "material",
            "its material's texture is an image, and the mesh has no texture coordinates (vt in OBJ, u and v in PLY) to map it; spheres, boxes and rods have their own",
        ));
    }
    let held = geometry.prims[first..].iter().map(|p| p.bounds());
    let implicit = geometry.implicit[implicit..]
        .iter()
        .map(|r| r.shape.bounds());
    let reach = held
        .chain(implicit)
        .map(|b| b.min.abs().max(b.max.abs()).max_element())
        .fold(0.0, f64::max);
    if reach > super::envelope::MAX_MAGNITUDE {
        // The object as a whole (its `type`, or the mesh file whose points reach there),
        // unless a flag placed it (`--set ...center=`): then that flag, which the file's
        // lines do not show.
        let whole = if o.has("file") { "file" } else { "type" };
        let key = PLACING_KEYS
            .into_iter()
            .find(|k| o.set_by_flag(k))
            .unwrap_or(whole);
        return Err(o.error(key, super::envelope::reaches_too_far(kind, reach)));
    }
    Ok(())
}

/// `[fog]`: a medium (`sigma_a`, `sigma_s`, `g`, as a material's `medium`) filling all space
/// outside objects, at rest in the frame of group `group` (which must hold objects: its frame
/// is one the renderer builds).
fn fog(t: &Table, groups: &[Group], materials: &mut Vec<Material>) -> SceneResult<Fog> {
    let name = t.req_string("group")?;
    let Some(group) = groups.iter().position(|g| g.name == name) else {
        return Err(t.error("group", format!("no group is named `{name}`")));
    };
    if groups[group].window.is_some() {
        return Err(t.error(
            "group",
            format!("group `{name}` has a worldline of several segments: a fog resting in it is not built yet"),
        ));
    }
    if groups[group].geometry.is_empty() {
        return Err(t.error(
            "group",
            format!(
                "group `{name}` holds no objects; a fog rests in the frame of a group that does"
            ),
        ));
    }
    let medium = super::surfaces::medium(t, &["group"])?;
    materials.push(Material {
        name: "[fog]".into(),
        color: Colour::grey(0.0, Role::Reflectance),
        medium: Some(medium),
        ..Material::default_white()
    });
    Ok(Fog {
        group,
        material: (materials.len() - 1) as u32,
    })
}
