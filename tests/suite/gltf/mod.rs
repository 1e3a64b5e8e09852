//! glTF scenes (docs/scene-format.md, "glTF files"): a box placed by a node hierarchy, in a
//! `.gltf` with a data URI, a `.gltf` with a `.bin` beside it and a `.glb`, renders as the
//! `box` object on both backends, at rest and moving; a node keyframed at constant velocity
//! renders, between its keys, as the object given that velocity, pixel for pixel; materials,
//! point lights and cameras map as documented; bad files are clear errors.

use crate::common::cli::{Dir, GOOD};
use crate::common::*;
use crate::meshes::{differing, load, with_object, BOX_FACES};
use doc::{keyed_box, nested_nodes, Doc};
use glam::DVec3;
use rest_embree::scene::Scene;
use serde_json::json;

mod doc;
mod hostile;

/// `scene` renders on backend `b` as `reference` (GOOD's box, object 1, in view): no pixel off
/// the silhouette differs, and fewer than one in fifty in all.
fn renders_as_the_box(reference: &Scene, scene: &Scene, b: &str, what: &str) {
    let (a, m) = (render_with(reference, b), render_with(scene, b));
    let hit = a.pixels.iter().filter(|p| p.object_id == 1).count();
    assert!(hit > 100, "the box is in view ({hit} pixels)");
    let (all, inside) = differing(&a, &m);
    eprintln!("{what} on {b}: {all} of {hit} box pixels differ");
    assert_eq!(inside, 0, "{what} on {b}: {all} differ, {inside} inside");
    assert!(all * 50 < a.pixels.len(), "{what} on {b}: {all} differ");
}

#[test]
fn a_box_from_gltf_renders_as_the_box_in_every_container() {
    let d = Dir::new("gltf-box");
    let doc = Doc::unit_box(nested_nodes());
    d.file("embedded.gltf", &doc.embedded());
    d.file("beside.gltf", &doc.beside("the%20box.bin"));
    std::fs::write(d.0.join("the box.bin"), &doc.bin).unwrap();
    std::fs::write(d.0.join("box.glb"), doc.glb()).unwrap();
    for velocity in ["[0, 0, 0]", "[0.5, 0, 0]"] {
        let set = format!("group.cube.velocity={velocity}");
        let sets = ["image.width=96", "image.height=64", set.as_str()];
        let reference = load(&d, "box.toml", GOOD, &sets);
        for file in ["embedded.gltf", "beside.gltf", "box.glb"] {
            let text = with_object(&format!("type = \"gltf\"\nfile = \"{file}\""));
            let scene = load(&d, "gltf.toml", &text, &sets);
            for b in backends() {
                renders_as_the_box(&reference, &scene, b, &format!("{file} at {velocity}"));
            }
        }
    }
}

/// The unit box as six primitives, one a face, each a TRIANGLE_STRIP or a TRIANGLE_FAN of the
/// face's four corners, renders as the box of triangle lists; a primitive's morph targets are
/// said to be ignored.
#[test]
fn strips_and_fans_render_as_the_triangles_they_list() {
    let d = Dir::new("gltf-strips");
    let sets = ["image.width=96", "image.height=64"];
    let reference = load(&d, "box.toml", GOOD, &sets);
    for (mode, order) in [(5, [1, 2, 0, 3]), (6, [0, 1, 2, 3])] {
        // Strip (f1, f2, f0, f3): triangles (f1, f2, f0) and (f2, f3, f0); fan (f0, f1, f2,
        // f3): the same two; the list's are (f0, f1, f2) and (f0, f2, f3), turned the same way.
        let mut doc = Doc::unit_box(nested_nodes());
        let mut primitives = Vec::new();
        for f in BOX_FACES {
            let offset = doc.bin.len();
            for k in order {
                doc.bin.extend_from_slice(&(f[k] - 1).to_le_bytes());
            }
            let views = doc.json["bufferViews"].as_array_mut().unwrap();
            views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": 16}));
            let view = views.len() - 1;
            let accessors = doc.json["accessors"].as_array_mut().unwrap();
            accessors.push(
                json!({"bufferView": view, "componentType": 5125, "count": 4, "type": "SCALAR"}),
            );
            let ix = accessors.len() - 1;
            primitives.push(json!({"attributes": {"POSITION": 0}, "indices": ix, "mode": mode}));
        }
        doc.json["buffers"][0]["byteLength"] = json!(doc.bin.len());
        primitives[0]["targets"] = json!([{"POSITION": 0}]);
        doc.json["meshes"][0]["primitives"] = json!(primitives);
        std::fs::write(d.0.join("faces.glb"), doc.glb()).unwrap();
        let scene = load(
            &d,
            "faces.toml",
            &with_object("type = \"gltf\"\nfile = \"faces.glb\""),
            &sets,
        );
        assert!(
            !scene.warnings.iter().any(|w| w.contains("not triangles")),
            "{:?}",
            scene.warnings
        );
        assert!(
            scene
                .warnings
                .iter()
                .any(|w| w.contains("morph targets are ignored")),
            "{:?}",
            scene.warnings
        );
        for b in backends() {
            renders_as_the_box(&reference, &scene, b, &format!("mode {mode}"));
        }
    }
}

/// A keyframed node that holds the camera: the camera stands as at time 0, and says so.
#[test]
fn a_keyframed_camera_is_said_to_stand() {
    let d = Dir::new("gltf-keyed-camera");
    let mut doc = keyed_box(
        &[(0.0, [0.0, 10.5, 0.0]), (1.0, [0.1, 10.5, 0.0])],
        "LINEAR",
    );
    doc.json["cameras"] =
        json!([{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}]);
    doc.json["nodes"][0]["camera"] = json!(0);
    std::fs::write(d.0.join("cam.glb"), doc.glb()).unwrap();
    let scene = load(
        &d,
        "cam.toml",
        &at_time("type = \"gltf\"\nfile = \"cam.glb\"", "", 10.0),
        &[],
    );
    assert!(
        scene.warnings.iter().any(|w| w.contains("holds a camera")),
        "{:?}",
        scene.warnings
    );
    // Keyed without a camera: no such word.
    let plain = keyed_box(
        &[(0.0, [0.0, 10.5, 0.0]), (1.0, [0.1, 10.5, 0.0])],
        "LINEAR",
    );
    std::fs::write(d.0.join("plain.glb"), plain.glb()).unwrap();
    let scene = load(
        &d,
        "plain.toml",
        &at_time("type = \"gltf\"\nfile = \"plain.glb\"", "", 10.0),
        &[],
    );
    assert!(!scene.warnings.iter().any(|w| w.contains("holds a camera")));
}

/// GOOD's box (or `object` in its place) at rest in the world (its light too), seen at camera
/// time `time`.
fn at_time(object: &str, velocity: &str, time: f64) -> String {
    let text = match object {
        "box" => GOOD.to_string(),
        _ => with_object(object),
    };
    text.replace("group = \"cube\"\n", "")
        .replace("velocity = [0.5, 0, 0]", velocity)
        .replace("time = 10", &format!("time = {time}"))
}

#[test]
fn a_node_keyed_at_constant_velocity_is_the_box_given_that_velocity() {
    let d = Dir::new("gltf-keys");
    // The box's node keyed from (0, 10.5, 0) at the file's time 0 to (20, 10.5, 0) at 40 s:
    // 0.5c along x, through where GOOD's box is at time 0.
    let doc = keyed_box(
        &[(0.0, [0.0, 10.5, 0.0]), (40.0, [20.0, 10.5, 0.0])],
        "LINEAR",
    );
    std::fs::write(d.0.join("keys.glb"), doc.glb()).unwrap();
    let sets = ["image.width=96", "image.height=64"];
    // Seen at camera time 11 the light left the box near time 0.5, between the keys.
    let reference = load(
        &d,
        "v.toml",
        &at_time("box", "velocity = [0.5, 0, 0]", 11.0),
        &sets,
    );
    let keyed = load(
        &d,
        "k.toml",
        &at_time(
            "type = \"gltf\"\nfile = \"keys.glb\"",
            "velocity = [0, 0, 0]",
            11.0,
        ),
        &sets,
    );
    let names: Vec<&str> = keyed.groups.iter().map(|g| g.name.as_str()).collect();
    assert!(
        names.contains(&"cube/box"),
        "the keyed node is a group of its own: {names:?}"
    );
    for b in backends() {
        let (a, k) = (render_with(&reference, b), render_with(&keyed, b));
        let hit = a.pixels.iter().filter(|p| p.alpha > 0.0).count();
        assert!(hit > 100, "the box is in view ({hit} pixels)");
        let same = a
            .pixels
            .iter()
            .zip(&k.pixels)
            .filter(|(p, q)| p.color == q.color && p.alpha == q.alpha)
            .count();
        assert_eq!(
            same,
            a.pixels.len(),
            "on {b}: {} pixels differ",
            a.pixels.len() - same
        );
    }
    // Keys faster than light are refused, naming the node and the keys.
    let fast = keyed_box(
        &[(0.0, [0.0, 10.5, 0.0]), (1.0, [2.0, 10.5, 0.0])],
        "LINEAR",
    );
    std::fs::write(d.0.join("fast.glb"), fast.glb()).unwrap();
    let path = d.file(
        "fast.toml",
        &at_time(
            "type = \"gltf\"\nfile = \"fast.glb\"",
            "velocity = [0, 0, 0]",
            11.0,
        ),
    );
    let err = rest_embree::scene::load_file(&path, &[])
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("fast.toml")
            && err.contains("`box`")
            && err.contains("2.000000c")
            && err.contains("time_scale"),
        "{err}"
    );
    // Ten scene units a second, it moves at 0.2c.
    let sets = ["group.cube.object.0.time_scale=10"];
    let slow = load(
        &d,
        "fast.toml",
        &std::fs::read_to_string(&path).unwrap(),
        &sets,
    );
    let moving = slow
        .groups
        .iter()
        .filter(|g| g.name == "cube/box")
        .map(|g| g.velocity.beta())
        .fold(0.0, f64::max);
    assert!((moving - 0.2).abs() < 1e-12, "{moving}");
}

#[test]
fn materials_lights_and_cameras_map_as_documented() {
    let d = Dir::new("gltf-map");
    let mut doc = Doc::unit_box(json!([
        {"name": "box", "translation": [0, 10.5, 0], "mesh": 0},
        {"name": "lamp", "translation": [1, 2, 3], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        // Looking down -z turned to look along +y: a quarter turn about x.
        {"name": "eye", "translation": [0, 0, 0], "rotation": [std::f64::consts::FRAC_1_SQRT_2, 0, 0, std::f64::consts::FRAC_1_SQRT_2], "camera": 0}
    ]));
    doc.json["scenes"][0]["nodes"] = json!([0, 1, 2]);
    doc.json["meshes"][0]["primitives"][0]["material"] = json!(0);
    doc.json["materials"] = json!([{
        "name": "paint",
        "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 1.0], "metallicFactor": 0.25, "roughnessFactor": 0.5},
        "emissiveFactor": [1.0, 0.5, 0.0],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0},
                        "KHR_materials_transmission": {"transmissionFactor": 0.5},
                        "KHR_materials_ior": {"ior": 1.33}}
    }]);
    doc.json["extensionsUsed"] = json!([
        "KHR_lights_punctual",
        "KHR_materials_emissive_strength",
        "KHR_materials_transmission",
        "KHR_materials_ior",
        "KHR_materials_clearcoat"
    ]);
    doc.json["extensions"] = json!({"KHR_lights_punctual": {"lights": [{"type": "point", "color": [1.0, 0.5, 0.25], "intensity": 8.0}]}});
    doc.json["cameras"] =
        json!([{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}]);
    std::fs::write(d.0.join("all.glb"), doc.glb()).unwrap();
    let no_camera = GOOD
        .replace(
            "[camera]\nposition = [0, 0, 0]\nlook_at = [0, 10, 0]\nfov_y = 30\ntime = 10\n",
            "",
        )
        .replace(
            "type = \"box\"\nmin = [-0.5, 10, -0.5]\nmax = [0.5, 11, 0.5]",
            "type = \"gltf\"\nfile = \"all.glb\"",
        );
    let scene = load(&d, "all.toml", &no_camera, &[]);
    // The camera: at its node, looking along the node's -z turned to +y, up +z.
    let c = &scene.camera;
    assert!(
        c.position.length() < 1e-12
            && (c.forward - DVec3::Y).length() < 1e-6
            && (c.up - DVec3::Z).length() < 1e-6,
        "{c:?}"
    );
    match c.projection {
        rest_embree::scene::Projection::Pinhole { fov_y } => assert!((fov_y - 0.5).abs() < 1e-7),
        ref p => panic!("{p:?}"),
    }
    // The light: at its node, colour times candela / 683 lm/W, falling off as 1/r², resting in
    // the group.
    let l = scene.lights.last().unwrap();
    assert_eq!(l.position, DVec3::new(1.0, 2.0, 3.0));
    assert!(l.inverse_square && (l.velocity.beta() - 0.5).abs() < 1e-15);
    let want = rest_embree::spectrum::Colour::rgb(
        DVec3::new(1.0, 0.5, 0.25),
        rest_embree::spectrum::Role::Emitter,
    )
    .scaled(8.0 / 683.0);
    assert_eq!(l.radiance, want);
    // The material: its own, as the table in the docs maps it.
    let m = scene
        .materials
        .iter()
        .find(|m| m.name == "paint")
        .expect("the file's material");
    assert_eq!(
        (m.reflect, m.roughness, m.transmit),
        (0.25, 0.5, 0.5 * 0.75)
    );
    assert!((m.ior - 1.33).abs() < 1e-6);
    let emission = rest_embree::spectrum::Colour::rgb(
        DVec3::new(4.0, 2.0, 0.0),
        rest_embree::spectrum::Role::Emitter,
    );
    assert_eq!(m.emission.as_ref(), Some(&emission));
    let paint = scene
        .materials
        .iter()
        .position(|m| m.name == "paint")
        .unwrap() as u32;
    assert!(scene.groups[0]
        .geometry
        .parts
        .iter()
        .all(|p| p.material == paint));
    // The unmapped extension is named.
    assert!(
        scene
            .warnings
            .iter()
            .any(|w| w.contains("KHR_materials_clearcoat")),
        "{:?}",
        scene.warnings
    );
    // A [[material]] of the same name takes the file's material's place.
    let own = no_camera
        .replace("name = \"white\"", "name = \"paint\"")
        .replace("material = \"white\"", "");
    let scene = load(&d, "own.toml", &own, &[]);
    let ids: Vec<u32> = scene.groups[0]
        .geometry
        .parts
        .iter()
        .map(|p| p.material)
        .collect();
    assert!(
        ids.iter().all(|&i| i == 1),
        "the scene's `paint` (id 1): {ids:?}"
    );
    assert_eq!(
        scene.materials.iter().filter(|m| m.name == "paint").count(),
        1
    );
}

/// A mesh that several nodes place is held once (its placements Embree instances of one scene
/// and, in the BVH, one tree walked in each node's frame) and renders as the same file with a
/// mesh of its own for each node: on both backends, at rest and moving, every pixel but the
/// silhouettes' within a millionth. A node that mirrors the mesh is copied, turned inside out
/// as glTF asks.
#[test]
fn a_mesh_several_nodes_place_is_held_once_and_renders_as_copies() {
    let d = Dir::new("gltf-instances");
    let placements = json!([
        {"name": "row", "children": [1, 2, 3, 4]},
        {"mesh": 0, "translation": [-2.4, 10.5, 0], "scale": [0.6, 0.6, 0.6]},
        {"mesh": 0, "translation": [-0.8, 10.5, 0.2], "scale": [0.5, 0.9, 0.6],
         "rotation": [0.2, 0.0, 0.3826834, 0.9016]},
        {"mesh": 0, "translation": [0.8, 10.5, -0.2], "scale": [-0.6, 0.6, 0.6]},
        {"mesh": 0, "matrix": [0.6, 0, 0, 0, 0.25, 0.6, 0, 0, 0, 0.1, 0.5, 0, 2.4, 10.5, 0, 1]}
    ]);
    let shared = Doc::unit_box(placements.clone());
    // The same, each node with a mesh of its own (the same triangles): each placed as a copy.
    let mut copies = Doc::unit_box(placements);
    let mesh = copies.json["meshes"][0].clone();
    copies.json["meshes"] = json!([mesh, mesh, mesh, mesh]);
    for k in 1..=4 {
        copies.json["nodes"][k]["mesh"] = json!(k - 1);
    }
    std::fs::write(d.0.join("shared.glb"), shared.glb()).unwrap();
    std::fs::write(d.0.join("copies.glb"), copies.glb()).unwrap();
    for velocity in ["[0, 0, 0]", "[0.5, 0, 0]"] {
        let set = format!("group.cube.velocity={velocity}");
        let sets = ["image.width=160", "image.height=96", set.as_str()];
        let load_file = |file: &str| {
            let text = with_object(&format!("type = \"gltf\"\nfile = \"{file}\""));
            load(&d, &format!("{file}.toml"), &text, &sets)
        };
        let (a, b) = (load_file("shared.glb"), load_file("copies.glb"));
        let held = |s: &rest_embree::scene::Scene| {
            s.groups[0]
                .geometry
                .implicit
                .iter()
                .filter(|r| matches!(r.shape, rest_embree::geometry::Implicit::Instance(_)))
                .count()
        };
        assert_eq!(
            (held(&a), held(&b)),
            (3, 0),
            "three placements held, the mirror copied"
        );
        assert_eq!(a.groups[0].geometry.len(), b.groups[0].geometry.len());
        for be in backends() {
            let (x, y) = (render_with(&a, be), render_with(&b, be));
            let seen = x.pixels.iter().filter(|p| p.object_id == 1).count();
            assert!(seen > 300, "{be}: {seen} pixels see the boxes");
            let (all, inside) = close_but_edges(&x, &y);
            eprintln!("{be} at {velocity}: {all} pixels differ beyond 1e-6");
            assert_eq!(
                inside, 0,
                "{be} at {velocity}: {all} differ, {inside} inside"
            );
        }
    }
    // A node that is a group of its own (`groups = "nodes"`) holds copies: its group is built
    // alone. The same frame as the file of a mesh per node.
    let sets = ["image.width=160", "image.height=96"];
    let load_nodes = |file: &str| {
        let text = with_object(&format!(
            "type = \"gltf\"\nfile = \"{file}\"\ngroups = \"nodes\""
        ));
        load(&d, &format!("{file}-nodes.toml"), &text, &sets)
    };
    let (a, b) = (load_nodes("shared.glb"), load_nodes("copies.glb"));
    let instances = a
        .groups
        .iter()
        .flat_map(|g| &g.geometry.implicit)
        .filter(|r| matches!(r.shape, rest_embree::geometry::Implicit::Instance(_)))
        .count();
    assert_eq!(instances, 0, "a node's own group holds copies");
    for be in backends() {
        let (x, y) = (render_with(&a, be), render_with(&b, be));
        assert!(x.pixels.iter().filter(|p| p.alpha > 0.0).count() > 300);
        let (all, inside) = close_but_edges(&x, &y);
        assert_eq!(
            inside, 0,
            "{be}, groups = nodes: {all} differ, {inside} inside"
        );
    }
}

/// A glTF file that two entries place (in two groups, moving apart) is read once: each of its
/// meshes held once and both groups' placements of it one mesh (the same `Arc`), and the
/// frame is that of the second entry naming a copy of the file, read on its own, on both
/// backends (every pixel but the silhouettes' within a millionth).
#[test]
fn a_gltf_file_two_entries_place_is_read_once_and_renders_as_two_files() {
    let d = Dir::new("gltf-two-entries");
    let nodes = json!([
        {"name": "pair", "children": [1, 2]},
        {"mesh": 0, "translation": [-0.6, 10.5, 0], "scale": [0.5, 0.5, 0.5]},
        {"mesh": 0, "translation": [0.6, 10.5, 0.1], "rotation": [0.2, 0.0, 0.3826834, 0.9016],
         "scale": [0.4, 0.6, 0.5]}
    ]);
    let glb = Doc::unit_box(nodes).glb();
    std::fs::write(d.0.join("pair.glb"), &glb).unwrap();
    std::fs::write(d.0.join("again.glb"), &glb).unwrap();
    let scene = |second: &str| {
        let text = with_object("type = \"gltf\"\nfile = \"pair.glb\"\ntranslate = [-1.2, 0, 0]");
        format!(
            "{text}\n[[group]]\nname = \"other\"\nvelocity = [-0.4, 0.1, 0]\n\
             [[group.object]]\ntype = \"gltf\"\nfile = \"{second}\"\n\
             translate = [1.2, 0.3, 0]\nscale = 0.8\n"
        )
    };
    let sets = ["image.width=160", "image.height=96"];
    let (a, b) = (
        load(&d, "twice.toml", &scene("./pair.glb"), &sets),
        load(&d, "apart.toml", &scene("again.glb"), &sets),
    );
    let meshes = |s: &rest_embree::scene::Scene| -> Vec<_> {
        s.groups
            .iter()
            .flat_map(|g| &g.geometry.implicit)
            .filter_map(|r| match &r.shape {
                rest_embree::geometry::Implicit::Instance(i) => Some(i.mesh.clone()),
                _ => None,
            })
            .collect()
    };
    let held = meshes(&a);
    assert_eq!(held.len(), 4, "two placements in each group");
    assert!(
        held.iter().all(|m| std::sync::Arc::ptr_eq(m, &held[0])),
        "one mesh for both entries"
    );
    let apart = meshes(&b);
    assert_eq!(apart.len(), 4);
    assert!(
        !std::sync::Arc::ptr_eq(&apart[0], &apart[3]),
        "two files, two meshes"
    );
    assert_eq!(a.groups.len(), 2);
    // A file that places its mesh once, named by two entries: the mesh held once, each
    // entry's group placing it once.
    let single = Doc::unit_box(json!([{"name": "one", "translation": [0, 10.5, 0]}]));
    let mut single = single;
    single.json["nodes"][0]["mesh"] = json!(0);
    std::fs::write(d.0.join("single.glb"), single.glb()).unwrap();
    let text = with_object("type = \"gltf\"\nfile = \"single.glb\"\ntranslate = [-1.2, 0, 0]");
    let text = format!(
        "{text}\n[[group]]\nname = \"other\"\nvelocity = [-0.4, 0.1, 0]\n\
         [[group.object]]\ntype = \"gltf\"\nfile = \"single.glb\"\ntranslate = [1.2, 0.3, 0]\n"
    );
    let once = meshes(&load(&d, "single.toml", &text, &sets));
    assert_eq!(once.len(), 2, "one placement in each group");
    assert!(
        std::sync::Arc::ptr_eq(&once[0], &once[1]),
        "one mesh for both entries"
    );
    for be in backends() {
        let (x, y) = (render_with(&a, be), render_with(&b, be));
        let seen = x.pixels.iter().filter(|p| p.alpha > 0.0).count();
        assert!(seen > 300, "{be}: {seen} pixels see the boxes");
        let (all, inside) = close_but_edges(&x, &y);
        eprintln!("{be}: {all} pixels differ beyond 1e-6");
        assert_eq!(inside, 0, "{be}: {all} differ, {inside} inside");
    }
}

/// How many pixels of two frames differ by more than a millionth of their colour, and how many
/// of those lie away from a silhouette (`meshes::differing`, with a tolerance for the last bits
/// of f32 that rays rebased to a slightly other box give).
fn close_but_edges(
    a: &rest_embree::render::Frame,
    b: &rest_embree::render::Frame,
) -> (usize, usize) {
    let close = |p: &rest_embree::render::PixelValue, q: &rest_embree::render::PixelValue| {
        p.alpha == q.alpha
            && (0..3).all(|k| (p.color[k] - q.color[k]).abs() <= 1e-6 * p.color[k].abs().max(1e-3))
    };
    let mut b2 = b.clone();
    for (p, q) in b2.pixels.iter_mut().zip(&a.pixels) {
        if close(p, q) {
            *p = *q;
        }
    }
    differing(a, &b2)
}

/// With `groups = "nodes"` a top-level node's object is named as its group, `<group>/<node>`
/// (docs/scene-format.md): one file placed by two entries in two groups gives objects of two
/// names, which the mattes and the probe tell apart.
#[test]
fn a_node_of_its_own_is_named_group_slash_node() {
    let d = Dir::new("gltf-node-names");
    let doc = Doc::unit_box(json!([{"name": "CubeA", "translation": [0, 10.5, 0], "mesh": 0}]));
    std::fs::write(d.0.join("cube.glb"), doc.glb()).unwrap();
    let text = with_object("type = \"gltf\"\nfile = \"cube.glb\"\ngroups = \"nodes\"");
    let text = format!(
        "{text}\n[[group]]\nname = \"other\"\nvelocity = [-0.4, 0, 0]\n\
         [[group.object]]\ntype = \"gltf\"\nfile = \"cube.glb\"\ngroups = \"nodes\"\n"
    );
    let s = load(&d, "two.toml", &text, &[]);
    let names: Vec<&str> = s.objects.iter().filter_map(|o| o.name.as_deref()).collect();
    assert_eq!(names, ["cube/CubeA", "other/CubeA"]);
    for o in s.objects.iter().filter(|o| o.name.is_some()) {
        assert_eq!(o.name.as_deref(), Some(s.groups[o.group].name.as_str()));
    }
}
