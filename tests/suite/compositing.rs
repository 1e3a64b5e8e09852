//! The EXR as compositors read it, checked with OpenImageIO's own tools (`oiiotool`, from
//! Debian's openimageio-tools, which scripts/setup.sh installs): channels in layers, pixel
//! types, compression and header attributes; "over" a plate equals the plate as background
//! (premultiplied colour); depth along the look axis; the PNG's colour chunks.

use crate::common::cli::*;
use crate::common::*;

#[test]
fn channels_types_compression_and_header_as_openimageio_reads_them() {
    let d = Dir::new("exr-header");
    let scene = d.file("scene.toml", GOOD);
    let s = scene.to_str().unwrap();
    let plain = d.0.join("plain.exr");
    let p = plain.to_str().unwrap();
    let (code, err) = status(&["render", s, "-o", p, "-q", "--set", "camera.time=10"]);
    assert_eq!(code, Some(0), "{err}");
    let info = oiiotool(&["--info", "-v", plain.to_str().unwrap()]);
    for needle in [
        "46 channel, float openexr",
        "channel list: R, G, B, A, Z, CryptoMaterial00.R, CryptoMaterial00.G, CryptoMaterial00.B, CryptoMaterial00.A, CryptoMaterial01.R",
        "CryptoObject02.A, N.X, N.Y, N.Z, P.X, P.Y, P.Z, Pcam.X, Pcam.Y, Pcam.Z, Pref.X, Pref.Y, Pref.Z, doppler.V, lookback.V, material_id.V, object_id.V, primitive_id.V",
        "/name: \"CryptoObject\"",
        "/name: \"CryptoMaterial\"",
        "compression: \"zip\"",
        "software: \"rest-embree",
        "chromaticities: 0.64, 0.33, 0.3, 0.6, 0.15, 0.06, 0.3127, 0.329",
        "worldToCamera:",
        "worldToNDC:",
        "cameraTime: 10",
        "groupVelocities: \"cube: beta = [0.5, 0.0, 0.0]\"",
        "renderSamples: 1",
        "renderBackend:",
        "renderScene:",
        "renderOverrides: \"--set camera.time=10\"",
    ] {
        assert!(info.contains(needle), "`{needle}` in:\n{info}");
    }
    assert!(!info.contains("tile"), "scanlines, not tiles:\n{info}");
    // OpenEXR's own validator accepts what every compression and precision writes.
    for (name, extra) in [
        ("zips", &["--compression", "zips"][..]),
        ("rle", &["--compression", "rle", "--half"]),
        ("none", &["--compression", "none", "--passes", "none"]),
        ("crop", &["--tiles", "2x2", "--tile", "3"]),
    ] {
        let out = d.0.join(format!("{name}.exr"));
        let mut args = vec!["render", s, "-o", out.to_str().unwrap(), "-q"];
        args.extend_from_slice(extra);
        let (code, err) = status(&args);
        assert_eq!(code, Some(0), "{name}: {err}");
        assert!(
            crate::common::exrcheck::valid(&out),
            "exrcheck rejects the {name} EXR"
        );
    }
    assert!(
        crate::common::exrcheck::valid(&plain),
        "exrcheck rejects the default EXR"
    );
    let half = d.0.join("half.exr");
    let h = half.to_str().unwrap();
    let (code, err) = status(&["render", s, "-o", h, "-q", "--half", "--compression", "piz"]);
    assert_eq!(code, Some(0), "{err}");
    let info = oiiotool(&["--info", "-v", h]);
    assert!(
        crate::common::exrcheck::valid(&half),
        "exrcheck rejects the half, PIZ EXR"
    );
    for needle in [
        "R (half)",
        "A (half)",
        "N.X (half)",
        "doppler.V (half)",
        "Z (float)",
        "lookback.V (float)",
        "P.X (float)",
        "object_id.V (float)",
        "CryptoObject00.R (float)",
        "compression: \"piz\"",
    ] {
        assert!(info.contains(needle), "`{needle}` in:\n{info}");
    }
    let (code, err) = status(&["render", s, "-o", h, "--compression", "lzma"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("--compression") && err.contains("zip"),
        "{err}"
    );
}

/// `--passes` and `[image] passes` choose the channels; the colour of a render without passes
/// (which skips the centre rays) equals the full render's; an unknown name is refused with
/// the accepted ones.
#[test]
fn passes_choose_the_channels() {
    let d = Dir::new("exr-passes");
    let scene = d.file("scene.toml", GOOD);
    let s = scene.to_str().unwrap();
    let list = |file: &str, args: &[&str]| {
        let out = d.0.join(file);
        let o = out.to_str().unwrap();
        let mut all = vec!["render", s, "-o", o, "-q", "--samples", "4"];
        all.extend_from_slice(args);
        let (code, err) = status(&all);
        assert_eq!(code, Some(0), "{err}");
        let info = oiiotool(&["--info", "-v", o]);
        let line = info.lines().find(|l| l.contains("channel list:")).unwrap();
        line.split("channel list:")
            .nth(1)
            .unwrap()
            .trim()
            .to_string()
    };
    assert_eq!(list("none.exr", &["--passes", "none"]), "R, G, B, A");
    assert_eq!(
        list("some.exr", &["--passes", "depth,relativity"]),
        "R, G, B, A, Z, doppler.V, lookback.V"
    );
    assert_eq!(
        list("ids.exr", &["--set", "image.passes=[\"ids\", \"normal\"]"]),
        "R, G, B, A, N.X, N.Y, N.Z, material_id.V, object_id.V, primitive_id.V"
    );
    let crypto = list("crypto.exr", &["--passes", "cryptomatte"]);
    assert!(
        crypto.starts_with("R, G, B, A, CryptoMaterial00.R"),
        "{crypto}"
    );
    assert!(!crypto.contains("N.X"), "{crypto}");
    assert_eq!(list("all.exr", &[]).split(", ").count(), 46);
    let (_, _, none) = rest_embree::output::read_exr_channels(&d.0.join("none.exr")).unwrap();
    let (_, _, all) = rest_embree::output::read_exr_channels(&d.0.join("all.exr")).unwrap();
    for c in ["R", "G", "B", "A"] {
        assert_eq!(none[c], all[c], "channel {c}");
    }
    let o = d.0.join("bad.exr");
    let (code, err) = status(&[
        "render",
        s,
        "-o",
        o.to_str().unwrap(),
        "--passes",
        "depth,dopler",
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("--passes depth,dopler")
            && err.contains("`dopler` is not a pass")
            && err.contains("lookback, doppler"),
        "{err}"
    );
}

/// Names beyond Latin-1 (a scene file `雪 ünï.toml`, a group and its object named `雪 cube`)
/// go into the header as UTF-8, as OpenEXR stores strings: the exr crate's own conversion
/// panicked on them.
#[test]
fn unicode_names_reach_the_header() {
    let d = Dir::new("exr-unicode");
    let text = GOOD
        .replace("name = \"cube\"", "name = \"雪 cube\"")
        .replace("group = \"cube\"", "group = \"雪 cube\"");
    assert_ne!(text, GOOD);
    let scene = d.file("雪 ünï.toml", &text);
    let out = d.0.join("雪.exr");
    let (code, err) = status(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let info = oiiotool(&["--info", "-v", out.to_str().unwrap()]);
    for needle in [
        "雪 ünï.toml",
        "groupVelocities: \"雪 cube: beta",
        "manifest: \"{\"雪 cube",
    ] {
        assert!(info.contains(needle), "`{needle}` in:\n{info}");
    }
}

/// A transparent EXR (the default) "over" a constant plate in OpenImageIO equals a render
/// with that plate as the background (opaque: alpha 1), to 1e-6.
#[test]
fn over_a_plate_equals_the_plate_as_background() {
    let d = Dir::new("exr-over");
    let text = GOOD.replace(
        "height = 32\n",
        "height = 32\nsamples = 4\nbackground = [0.2, 0.3, 0.4]\n",
    );
    let scene = d.file("scene.toml", &text);
    let s = scene.to_str().unwrap();
    let (cut, plate, over) = (
        d.0.join("cut.exr"),
        d.0.join("plate.exr"),
        d.0.join("over.exr"),
    );
    for (out, set) in [
        (&cut, "image.transparent=true"),
        (&plate, "image.transparent=false"),
    ] {
        let (code, err) = status(&["render", s, "-o", out.to_str().unwrap(), "-q", "--set", set]);
        assert_eq!(code, Some(0), "{err}");
    }
    oiiotool(&[
        cut.to_str().unwrap(),
        "--ch",
        "R,G,B,A",
        "--pattern",
        "constant:color=0.2,0.3,0.4,1",
        "48x32",
        "4",
        "--over",
        "-o",
        over.to_str().unwrap(),
    ]);
    let read = |p: &std::path::Path| rest_embree::output::read_exr_channels(p).unwrap().2;
    let (cut, plate, over) = (read(&cut), read(&plate), read(&over));
    let edges = cut["A"].iter().filter(|&&a| a > 0.0 && a < 1.0).count();
    assert!(edges > 0, "the test needs partly covered pixels");
    assert!(
        plate["A"].iter().all(|&a| a == 1.0),
        "an opaque render has alpha 1"
    );
    for c in ["R", "G", "B"] {
        for (i, (o, p)) in over[c].iter().zip(&plate[c]).enumerate() {
            assert!(
                (o - p).abs() <= 1e-6,
                "{c} at {i}: over {o}, plate as background {p}"
            );
        }
    }
}

/// Z (depth) is the distance along the camera's look axis in its rest frame: the calibration
/// cube's near face lies in the plane y = 10, and a motion along x (of the cube or of the
/// camera) leaves that distance as it is.
#[test]
fn depth_is_the_distance_along_the_look_axis() {
    use rest_embree::spacetime::Velocity;
    // The camera's speeds are small: aberration turns what lies ahead toward its motion, out
    // of the narrow view at larger speeds.
    for (cube, camera) in [(0.0, 0.0), (0.9, 0.0), (0.0, 0.1), (0.5, -0.1)] {
        let speed = format!("velocity = [{cube:?}, 0, 0]");
        let text = cube_scene(10.0, &speed, -0.5, 10.0, [0.0, 0.0, 0.0]);
        let mut s = scene(&text);
        if camera != 0.0 {
            s.camera.velocity = Velocity::from_beta_vec(glam::DVec3::X * camera).unwrap();
        }
        for backend in backends() {
            let f = render_with(&s, backend);
            let near: Vec<f32> = f
                .pixels
                .iter()
                .filter(|p| p.normal == [0.0, -1.0, 0.0])
                .map(|p| p.depth)
                .collect();
            assert!(near.len() > 50, "the near face is seen ({})", near.len());
            for z in near {
                assert!(
                    (z - 10.0).abs() <= 1e-5,
                    "{backend}, {cube}/{camera}: depth {z}"
                );
            }
            for p in f.pixels.iter().filter(|p| p.alpha > 0.0) {
                assert_eq!(p.camera_position[2], p.depth, "Pcam.Z is the depth");
                assert_eq!(
                    (p.material_id, p.primitive_id),
                    (1, 1),
                    "the default material"
                );
            }
            for p in f.pixels.iter().filter(|p| p.alpha == 0.0) {
                assert_eq!(p.depth, rest_embree::render::DEPTH_FAR);
            }
        }
    }
}

/// A PNG is sRGB with the Software chunk, RGB unless the scene asks for transparency (then
/// RGBA, straight alpha).
#[test]
fn png_chunks_and_alpha() {
    let d = Dir::new("png-chunks");
    let scene = d.file("scene.toml", GOOD);
    let s = scene.to_str().unwrap();
    let (rgb, rgba) = (d.0.join("rgb.png"), d.0.join("rgba.png"));
    let (code, err) = status(&["render", s, "-o", rgb.to_str().unwrap(), "-q"]);
    assert_eq!(code, Some(0), "{err}");
    let set = ["--set", "image.transparent=true"];
    let (code, err) =
        status(&[&["render", s, "-o", rgba.to_str().unwrap(), "-q"][..], &set].concat());
    assert_eq!(code, Some(0), "{err}");
    let info = oiiotool(&["--info", "-v", rgb.to_str().unwrap()]);
    assert!(
        info.contains("3 channel") && info.contains("Software: \"rest-embree"),
        "{info}"
    );
    assert!(info.contains("sRGB"), "{info}");
    let info = oiiotool(&["--info", "-v", rgba.to_str().unwrap()]);
    assert!(
        info.contains("4 channel") && info.contains("R, G, B, A"),
        "{info}"
    );
}

/// The Cryptomatte layers, decoded by the specification (the layer found by its `name`
/// attribute, ids looked up in its manifest, ranks summed per name), give each object its
/// coverage: a whole pixel inside one object, and a pixel on the edge between two boxes split
/// in proportion to their areas in it.
#[test]
fn cryptomatte_decodes_to_each_objects_coverage() {
    use exr::prelude::*;
    let d = Dir::new("cryptomatte");
    // f = 100 px; the boxes meet at x = 0.03 at distance 10: 0.3 px right of the centre line
    // (columns 19 | 20 of 40), so pixel column 20 is 30% left box, 70% right box.
    let text = r#"
[camera]
position = [0, 0, 0]
direction = [0, 1, 0]
fov_y = 22.619864948
[image]
width = 40
height = 40
samples = 256
[[group]]
name = "g"
[[group.object]]
name = "left box"
type = "box"
min = [-2, 10, -1]
max = [0.03, 11, 1]
[[group.object]]
name = "right box"
type = "box"
min = [0.03, 10, -1]
max = [2, 11, 1]
"#;
    let scene = d.file("scene.toml", text);
    let out = d.0.join("out.exr");
    let (code, err) = status(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(&out)
        .unwrap();
    let text_attr = |name: &str| {
        image
            .layer_data
            .attributes
            .other
            .iter()
            .chain(&image.attributes.other)
            .find(|(k, _)| *k == name)
            .map(|(_, v)| match v {
                AttributeValue::Text(t) => t.to_string(),
                other => panic!("{name}: {other:?}"),
            })
    };
    let key = image
        .layer_data
        .attributes
        .other
        .iter()
        .find(|(k, v)| {
            k.to_string().ends_with("/name")
                && matches!(v, AttributeValue::Text(t) if t == "CryptoObject")
        })
        .map(|(k, _)| k.to_string().split('/').nth(1).unwrap().to_string())
        .expect("a CryptoObject layer");
    assert_eq!(
        text_attr(&format!("cryptomatte/{key}/hash")).unwrap(),
        "MurmurHash3_32"
    );
    let manifest: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(&text_attr(&format!("cryptomatte/{key}/manifest")).unwrap()).unwrap();
    let name_of: std::collections::HashMap<u32, String> = manifest
        .iter()
        .map(|(n, h)| {
            (
                u32::from_str_radix(h.as_str().unwrap(), 16).unwrap(),
                n.clone(),
            )
        })
        .collect();
    let channel = |name: &str| -> Vec<f32> {
        let c = image
            .layer_data
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .unwrap_or_else(|| panic!("channel {name}"));
        c.sample_data.values_as_f32().collect()
    };
    let alpha = channel("A");
    let mut coverage = vec![std::collections::HashMap::<String, f32>::new(); alpha.len()];
    for level in 0..3 {
        for (id, cov) in [("R", "G"), ("B", "A")] {
            let ids = channel(&format!("CryptoObject{level:02}.{id}"));
            let covs = channel(&format!("CryptoObject{level:02}.{cov}"));
            for (p, (&i, &c)) in ids.iter().zip(&covs).enumerate() {
                if c > 0.0 {
                    let name = name_of.get(&i.to_bits()).expect("every id in the manifest");
                    *coverage[p].entry(name.clone()).or_default() += c;
                }
            }
        }
    }
    let at =
        |x: usize, y: usize, name: &str| coverage[y * 40 + x].get(name).copied().unwrap_or(0.0);
    for y in 12..28 {
        let total: f32 = coverage[y * 40 + 20].values().sum();
        assert!(
            (total - alpha[y * 40 + 20]).abs() < 1e-6,
            "coverage adds up to alpha"
        );
        assert!(
            at(10, y, "left box") >= 0.99 && at(30, y, "right box") >= 0.99,
            "row {y}"
        );
        let (l, r) = (at(20, y, "left box"), at(20, y, "right box"));
        assert!(
            (l - 0.3).abs() <= 0.05 && (r - 0.7).abs() <= 0.05,
            "row {y}: {l} / {r}"
        );
    }
}

/// Ids per primitive tell a lattice's spheres and rods apart: (object_id, primitive_id) names
/// one primitive, the same one from whichever backend.
#[test]
fn primitive_ids_tell_a_lattices_parts_apart() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/lattice.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let sets = [
        ("--width 96".to_string(), "image.width=96".to_string()),
        ("--height 64".to_string(), "image.height=64".to_string()),
    ];
    let s = rest_embree::scene::load_str("lattice.toml", &text, &sets).unwrap();
    let frames: Vec<_> = backends().into_iter().map(|b| render_with(&s, b)).collect();
    let ids = |f: &rest_embree::render::Frame| -> Vec<(u32, u32, u32)> {
        let id = |p: &rest_embree::render::PixelValue| (p.object_id, p.material_id, p.primitive_id);
        f.pixels.iter().map(id).collect()
    };
    let distinct: std::collections::BTreeSet<u32> = frames[0]
        .pixels
        .iter()
        .map(|p| p.primitive_id)
        .filter(|&i| i > 0)
        .collect();
    assert!(
        distinct.len() > 50,
        "many primitives seen: {}",
        distinct.len()
    );
    let (a, b) = (ids(&frames[0]), ids(frames.last().unwrap()));
    let same = a.iter().zip(&b).filter(|(x, y)| x == y).count();
    assert!(
        same as f64 >= 0.99 * a.len() as f64,
        "{same} of {} pixels name the same primitive",
        a.len()
    );
}

/// A frame written to PNG from code keeps what it is: a transparent render (the library's
/// default) becomes RGBA, so its background is not turned black; an opaque one RGB.
#[test]
fn png_from_code_keeps_its_alpha() {
    let d = Dir::new("png-from-code");
    for (transparent, channels) in [(true, "4 channel"), (false, "3 channel")] {
        let mut s = scene(GOOD);
        s.image.transparent = Some(transparent);
        let f = render_with(&s, backends()[0]);
        let out = d.0.join(format!("{transparent}.png"));
        rest_embree::output::write(&f, &out).unwrap();
        let info = oiiotool(&["--info", out.to_str().unwrap()]);
        assert!(
            info.contains(channels),
            "transparent = {transparent}: {info}"
        );
    }
}
