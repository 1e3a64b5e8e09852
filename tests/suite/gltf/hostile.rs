//! Bad glTF files (docs/scene-format.md, "glTF files"): each a clear error naming the scene,
//! the key and the file, exit status 1; mutated files load or are refused, none panics.

use super::{keyed_box, nested_nodes, Doc};
use crate::common::cli::{status, Dir};
use crate::meshes::with_object;
use serde_json::json;

/// The command's exit status and message on the scene with this glTF object.
fn refused(d: &Dir, file: &str, bytes: &[u8]) -> String {
    std::fs::write(d.0.join(file), bytes).unwrap();
    let scene = d.file(
        "bad.toml",
        &with_object(&format!("type = \"gltf\"\nfile = \"{file}\"")),
    );
    let out = d.0.join("out.png");
    let (code, err) = status(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(1), "{file}: {err}");
    assert!(
        err.contains("bad.toml") && err.contains(file) && err.contains("file"),
        "{file}: {err}"
    );
    err
}

#[test]
fn bad_gltf_files_are_clear_errors() {
    let d = Dir::new("gltf-bad");
    let good = Doc::unit_box(nested_nodes());
    // A buffer that is not there.
    let err = refused(&d, "missing.gltf", good.beside("gone.bin").as_bytes());
    assert!(err.contains("gone.bin"), "{err}");
    // An index past the vertices.
    let mut bad = Doc::unit_box(nested_nodes());
    let at = bad.bin.len() - 4;
    bad.bin[at..].copy_from_slice(&99u32.to_le_bytes());
    let err = refused(&d, "index.glb", &bad.glb());
    assert!(
        err.contains("index 99") && err.contains("8 vertices"),
        "{err}"
    );
    // A matrix beyond f32 (infinite when read).
    let mut inf = Doc::unit_box(nested_nodes());
    inf.json["nodes"][1] =
        json!({"mesh": 0, "matrix": [1e39, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]});
    let err = refused(&d, "matrix.glb", &inf.glb());
    assert!(
        err.contains("not finite") || err.contains("not a readable glTF"),
        "{err}"
    );
    // A node cycle.
    let mut cycle = Doc::unit_box(nested_nodes());
    cycle.json["nodes"][1]["children"] = json!([0]);
    let err = refused(&d, "cycle.glb", &cycle.glb());
    assert!(
        err.contains("tree") || err.contains("not a readable glTF"),
        "{err}"
    );
    // A buffer that is a FIFO.
    let fifo = d.0.join("pipe.bin");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let err = refused(&d, "fifo.gltf", good.beside("pipe.bin").as_bytes());
    assert!(err.contains("not a regular file"), "{err}");
    // A STEP key: a body cannot jump.
    let step = keyed_box(&[(0.0, [0.0, 10.5, 0.0]), (1.0, [0.1, 10.5, 0.0])], "STEP");
    let err = refused(&d, "step.glb", &step.glb());
    assert!(err.contains("STEP"), "{err}");
    // What the crate's readers would unwrap or call unreachable on: FLOAT indices, an image in
    // a buffer view without its MIME type, a camera without the projection its type names.
    let mut float_ix = Doc::unit_box(nested_nodes());
    float_ix.json["accessors"][1]["componentType"] = json!(5126);
    let err = refused(&d, "float.glb", &float_ix.glb());
    assert!(err.contains("indices") && err.contains("kind"), "{err}");
    let mut image = Doc::unit_box(nested_nodes());
    image.json["images"] = json!([{"bufferView": 0}]);
    let err = refused(&d, "image.glb", &image.glb());
    assert!(err.contains("image 0"), "{err}");
    let mut cam = Doc::unit_box(nested_nodes());
    cam.json["cameras"] = json!([{"type": "perspective", "orthographic": {"xmag": 1, "ymag": 1, "zfar": 10, "znear": 1}}]);
    cam.json["nodes"][0]["camera"] = json!(0);
    let err = refused(&d, "camera.glb", &cam.glb());
    assert!(err.contains("camera 0"), "{err}");
    let mut fov = Doc::unit_box(nested_nodes());
    fov.json["cameras"] =
        json!([{"type": "perspective", "perspective": {"yfov": 4.0, "znear": 0.1}}]);
    fov.json["nodes"][0]["camera"] = json!(0);
    let err = refused(&d, "fov.glb", &fov.glb());
    assert!(err.contains("yfov"), "{err}");
    // A POSITION accessor of the wrong type, and one running past its buffer.
    let positions = |doc: &Doc| {
        doc.json["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
            .as_u64()
            .unwrap() as usize
    };
    let mut flat = Doc::unit_box(nested_nodes());
    let pos = positions(&flat);
    flat.json["accessors"][pos]["type"] = json!("VEC2");
    let err = refused(&d, "flat.glb", &flat.glb());
    assert!(
        err.contains("POSITION") && err.contains("VEC3") && !err.contains("Valid("),
        "{err}"
    );
    let mut long = Doc::unit_box(nested_nodes());
    let pos = positions(&long);
    long.json["accessors"][pos]["count"] = json!(800);
    let err = refused(&d, "long.glb", &long.glb());
    assert!(err.contains("POSITION") && err.contains("outside"), "{err}");
    // Factors glTF keeps in [0, 1] given beyond, and a negative emissive strength: refused
    // naming the material and the key, not clamped into another colour.
    for (key, mut material) in [
        (
            "baseColorFactor",
            json!({"pbrMetallicRoughness": {"baseColorFactor": [2.0, -1.0, 0.5, 1.0]}}),
        ),
        (
            "metallicFactor",
            json!({"pbrMetallicRoughness": {"metallicFactor": 1.5}}),
        ),
        (
            "roughnessFactor",
            json!({"pbrMetallicRoughness": {"roughnessFactor": -0.25}}),
        ),
        ("emissiveFactor", json!({"emissiveFactor": [1.0, 3.0, 0.0]})),
        (
            "emissiveStrength",
            json!({"emissiveFactor": [1.0, 1.0, 1.0],
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": -2.0}}}),
        ),
    ] {
        material["name"] = json!("paint");
        let mut paint = Doc::unit_box(nested_nodes());
        paint.json["meshes"][0]["primitives"][0]["material"] = json!(0);
        paint.json["materials"] = json!([material]);
        let err = refused(&d, "paint.glb", &paint.glb());
        let range = if key == "emissiveStrength" {
            "0 or more"
        } else {
            "[0, 1]"
        };
        assert!(
            err.contains("`paint`") && err.contains(key) && err.contains(range),
            "{key}: {err}"
        );
    }
    // Beyond a scene's own material's limits: an index of refraction below 1, an emission
    // beyond the envelope's 1e15.
    for (key, material) in [
        (
            "ior",
            json!({"name": "paint", "extensions": {"KHR_materials_ior": {"ior": 0.5}}}),
        ),
        (
            "emissiveStrength",
            json!({"name": "paint", "emissiveFactor": [1.0, 1.0, 1.0],
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1e30}}}),
        ),
    ] {
        let mut paint = Doc::unit_box(nested_nodes());
        paint.json["meshes"][0]["primitives"][0]["material"] = json!(0);
        paint.json["materials"] = json!([material]);
        let err = refused(&d, "limits.glb", &paint.glb());
        assert!(err.contains("`paint`") && err.contains(key), "{key}: {err}");
    }
    // Transforms glTF 2.0 does not allow, each read as another placement before: a matrix
    // beside a translation (the translation dropped), a projective matrix, a zero rotation
    // (read as none).
    for (node, needle) in [
        (
            json!({"mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 10.5, 0, 1], "translation": [1, 0, 0]}),
            "both a matrix",
        ),
        (
            json!({"mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.5, 0, 10.5, 0, 1]}),
            "last row",
        ),
        (
            json!({"mesh": 0, "translation": [0, 10.5, 0], "rotation": [0, 0, 0, 0]}),
            "unit quaternion",
        ),
    ] {
        let mut odd = Doc::unit_box(nested_nodes());
        odd.json["nodes"][1] = node;
        let err = refused(&d, "transform.glb", &odd.glb());
        assert!(err.contains("node 1") && err.contains(needle), "{err}");
    }
    // Counts that say what is wrong: past the buffer (it read as no vertices), no indices at
    // all, and eight vertices without indices (it said "8 indices").
    let mut huge = Doc::unit_box(nested_nodes());
    huge.json["accessors"][pos]["count"] = json!(1u64 << 63);
    let err = refused(&d, "huge.glb", &huge.glb());
    assert!(err.contains("claims 9223372036854775808 vertices"), "{err}");
    let mut none = Doc::unit_box(nested_nodes());
    none.json["accessors"][1]["count"] = json!(0);
    let err = refused(&d, "none.glb", &none.glb());
    assert!(err.contains("indices accessor has no elements"), "{err}");
    let mut bare = Doc::unit_box(nested_nodes());
    bare.json["meshes"][0]["primitives"][0]
        .as_object_mut()
        .unwrap()
        .remove("indices");
    let err = refused(&d, "bare.glb", &bare.glb());
    assert!(err.contains("8 vertices and no indices"), "{err}");
    // A sparse index past its accessor's elements (the reader skipped it without a word).
    let mut sparse = Doc::unit_box(nested_nodes());
    let offset = sparse.bin.len();
    sparse.bin.extend_from_slice(&60u32.to_le_bytes());
    for x in [0.0f32, 5.0, 0.0] {
        sparse.bin.extend_from_slice(&x.to_le_bytes());
    }
    sparse.json["buffers"][0]["byteLength"] = json!(sparse.bin.len());
    let views = sparse.json["bufferViews"].as_array_mut().unwrap();
    views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": 4}));
    views.push(json!({"buffer": 0, "byteOffset": offset + 4, "byteLength": 12}));
    let n = views.len();
    sparse.json["accessors"][pos]["sparse"] = json!({"count": 1,
        "indices": {"bufferView": n - 2, "componentType": 5125},
        "values": {"bufferView": n - 1}});
    let err = refused(&d, "sparse.glb", &sparse.glb());
    assert!(err.contains("sparse index 60 is past its 8"), "{err}");
    // A key beyond the envelope's times, as a TOML worldline's `until` would be.
    let late = keyed_box(
        &[(0.0, [0.0, 10.5, 0.0]), (1e30, [0.1, 10.5, 0.0])],
        "LINEAR",
    );
    std::fs::write(d.0.join("late.glb"), late.glb()).unwrap();
    let scene = d.file(
        "late.toml",
        &super::at_time("type = \"gltf\"\nfile = \"late.glb\"", "", 10.0),
    );
    let err = rest_embree::scene::load_file(&scene, &[])
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("late.toml") && err.contains("key 1") && err.contains("1e15"),
        "{err}"
    );
    // A camera whose node flattens it (it said the file held no camera).
    let mut flat_cam = Doc::unit_box(nested_nodes());
    flat_cam.json["cameras"] =
        json!([{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}]);
    flat_cam.json["nodes"][0]["camera"] = json!(0);
    flat_cam.json["nodes"][0]["scale"] = json!([0, 0, 0]);
    let err = refused(&d, "flatcam.glb", &flat_cam.glb());
    assert!(err.contains("camera 0") && err.contains("node 0"), "{err}");
    // A field of view below the scene's least (1e-6°).
    let mut narrow = Doc::unit_box(nested_nodes());
    narrow.json["cameras"] =
        json!([{"type": "perspective", "perspective": {"yfov": 1e-12, "znear": 0.1}}]);
    narrow.json["nodes"][0]["camera"] = json!(0);
    let err = refused(&d, "narrow.glb", &narrow.glb());
    assert!(err.contains("yfov") && err.contains("1e-6"), "{err}");
    // A stride smaller than a VEC3 (the crate's reader asserted: a panic), and data that does
    // not start on a whole component.
    let pos = positions(&Doc::unit_box(nested_nodes()));
    let mut stride = Doc::unit_box(nested_nodes());
    stride.json["bufferViews"][0]["byteStride"] = json!(4);
    let err = refused(&d, "stride.glb", &stride.glb());
    assert!(
        err.contains(&format!("accessor {pos}")) && err.contains("byteStride 4"),
        "{err}"
    );
    let mut skew = Doc::unit_box(nested_nodes());
    skew.json["accessors"][pos]["byteOffset"] = json!(1);
    let err = refused(&d, "skew.glb", &skew.glb());
    assert!(err.contains("not a multiple"), "{err}");
    // Two top-level nodes of one name, each a group of its own: refused, naming it.
    let mut twins = Doc::unit_box(json!([
        {"name": "Ship", "translation": [0, 10.5, 0], "mesh": 0},
        {"name": "Ship", "translation": [2, 10.5, 0], "mesh": 0}
    ]));
    twins.json["scenes"][0]["nodes"] = json!([0, 1]);
    std::fs::write(d.0.join("twins.glb"), twins.glb()).unwrap();
    let scene = d.file(
        "twins.toml",
        &with_object("type = \"gltf\"\nfile = \"twins.glb\"\ngroups = \"nodes\""),
    );
    let err = rest_embree::scene::load_file(&scene, &[])
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("`Ship`") && err.contains("twins.toml"),
        "{err}"
    );
    // Not glTF at all, and a data URI over the memory limit.
    let err = refused(&d, "junk.glb", b"glTF\x02\0\0\0junk");
    assert!(err.contains("not a readable glTF"), "{err}");
    // A .glb without its magic was read as JSON: "expected value at line 1 column 1".
    let err = refused(&d, "magic.glb", b"GLTF\x02\0\0\0junk");
    assert!(err.contains("must begin with the bytes `glTF`"), "{err}");
    // A .glb whose header's length is not the file's (bytes after it, or a length of 20) was
    // read as if it were.
    let mut joined = good.glb();
    let whole = joined.len();
    joined.extend_from_slice(b"more");
    let err = refused(&d, "joined.glb", &joined);
    assert!(
        err.contains(&format!(
            "says the file is {whole} bytes long, and it is {}",
            whole + 4
        )),
        "{err}"
    );
    let mut twenty = good.glb();
    twenty[8..12].copy_from_slice(&20u32.to_le_bytes());
    let err = refused(&d, "twenty.glb", &twenty);
    assert!(err.contains("says the file is 20 bytes long"), "{err}");
    // glTF 1.0 (or 3.0) by its asset's word, and a minVersion past 2.
    for (asset, said) in [
        (json!({"version": "1.0"}), "asset.version is \"1.0\""),
        (json!({"version": "3.0"}), "asset.version is \"3.0\""),
        (
            json!({"version": "2.0", "minVersion": "3.0"}),
            "(minVersion \"3.0\")",
        ),
    ] {
        let mut old = Doc::unit_box(nested_nodes());
        old.json["asset"] = asset;
        let err = refused(&d, "version.glb", &old.glb());
        assert!(err.contains(said) && err.contains("glTF 2.0"), "{err}");
    }
    // A buffer of byteLength 0, and a view past the bytes its buffer declares (the bytes
    // were there, so it was read).
    let mut empty = Doc::unit_box(nested_nodes());
    empty.json["buffers"][0]["byteLength"] = json!(0);
    let err = refused(&d, "empty.glb", &empty.glb());
    assert!(err.contains("buffer 0's byteLength is 0"), "{err}");
    let mut short = Doc::unit_box(nested_nodes());
    let declared = short.bin.len() - 4;
    short.json["buffers"][0]["byteLength"] = json!(declared);
    let err = refused(&d, "short.glb", &short.glb());
    assert!(
        err.contains("buffer view")
            && err.contains(&format!(
                "past the {declared} bytes its byteLength declares"
            )),
        "{err}"
    );
    let big = format!(
        "data:application/octet-stream;base64,{}",
        "A".repeat(4 << 20)
    );
    let mut j = good.json.clone();
    j["buffers"][0]["uri"] = json!(big);
    std::fs::write(d.0.join("big.gltf"), j.to_string()).unwrap();
    let scene = d.file(
        "big.toml",
        &with_object("type = \"gltf\"\nfile = \"big.gltf\""),
    );
    let out = d.0.join("out.png");
    let (code, err) = status(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--max-memory",
        "50M",
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("big.gltf") && err.contains("max-memory"),
        "{err}"
    );
}

/// Bytes of a `.glb` flipped, cut and replaced at random (a fixed seed), in its JSON and its
/// buffer: every one loads or is refused, and none panics.
#[test]
fn mutated_gltf_files_load_or_are_refused() {
    let d = Dir::new("gltf-fuzz");
    let mut doc = Doc::unit_box(nested_nodes());
    let times = doc.accessor(&[0.0, 40.0], "SCALAR", 2);
    let values = doc.accessor(&[0.0, 10.0, 0.0, 20.0, 10.0, 0.0], "VEC3", 2);
    doc.json["animations"] = json!([{
        "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
        "samplers": [{"input": times, "output": values}]
    }]);
    let glb = doc.glb();
    let scene = d.file(
        "fuzz.toml",
        &with_object("type = \"gltf\"\nfile = \"fuzz.glb\"").replace("group = \"cube\"\n", ""),
    );
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let (mut loaded, mut refused) = (0, 0);
    for _ in 0..1500 {
        let mut bytes = glb.clone();
        for _ in 0..1 + next() % 4 {
            let at = (next() % bytes.len() as u64) as usize;
            match next() % 3 {
                0 => bytes[at] ^= 1 << (next() % 8),
                1 => bytes[at] = b"0123456789-.e,:[]{}\""[(next() % 20) as usize],
                _ => bytes.truncate(at.max(12)),
            }
        }
        std::fs::write(d.0.join("fuzz.glb"), &bytes).unwrap();
        match rest_embree::scene::load_file(&scene, &[]) {
            Ok(_) => loaded += 1,
            Err(e) => {
                let e = e.to_string();
                // The file, or the entry that places it (a valid file placing a vertex beyond
                // the envelope is the entry's error).
                assert!(
                    e.contains("fuzz.glb") || e.contains("group.cube.object.0"),
                    "{e}"
                );
                refused += 1;
            }
        }
    }
    eprintln!("{loaded} loaded, {refused} refused");
    assert!(
        loaded > 0 && refused > 0,
        "{loaded} loaded, {refused} refused"
    );
}
