//! Textures (docs/scene-format.md, "Textures"): a checker laid out in the rest frame of its
//! object's group moves and deforms with the object exactly as geometry does: a plate with a
//! checker renders as the same plate built from small boxes of alternating materials, at rest
//! and at 0.6c and 0.9c, on both backends, Doppler shift and searchlight included. Bad texture
//! references are clear errors.

use crate::common::cli::{status, Dir};
use crate::common::*;
use rest_embree::render::{Frame, PixelValue};

const HEAD: &str = r#"[camera]
position = [0.3, -3.0, 2.2]
look_at = [0, 0, 0]
fov_y = 50
time = 0

[image]
width = 120
height = 90

[[material]]
name = "light"
color = [0.9, 0.85, 0.7]

[[material]]
name = "dark"
color = [0.1, 0.2, 0.5]

[[light]]
position = [1, -2, 4]
intensity = 30
"#;

/// The plate, a checker of 0.5 squares over x and y in [-1, 1], top face at z = 0.
fn checker_plate(velocity: &str) -> String {
    format!(
        "{HEAD}\n[[texture]]\nname = \"squares\"\nchecker = {{ size = [0.5, 0.5, 0], color1 = [0.9, 0.85, 0.7], color2 = [0.1, 0.2, 0.5] }}\n\n\
         [[material]]\nname = \"checked\"\ncolor = \"squares\"\n\n\
         [[group]]\nname = \"plate\"\nvelocity = {velocity}\n\
         [[group.object]]\ntype = \"box\"\nmin = [-1, -1, -0.1]\nmax = [1, 1, 0]\nmaterial = \"checked\"\n"
    )
}

/// The same plate as sixteen boxes, each of the colour the checker gives its square.
fn boxes_plate(velocity: &str) -> String {
    let mut s = format!("{HEAD}\n[[group]]\nname = \"plate\"\nvelocity = {velocity}\n");
    for i in -2i32..2 {
        for j in -2..2 {
            let (x, y) = (f64::from(i) * 0.5, f64::from(j) * 0.5);
            let m = if (i + j).rem_euclid(2) == 0 {
                "light"
            } else {
                "dark"
            };
            s.push_str(&format!(
                "[[group.object]]\ntype = \"box\"\nmin = [{x:?}, {y:?}, -0.1]\nmax = [{:?}, {:?}, 0]\nmaterial = \"{m}\"\n",
                x + 0.5,
                y + 0.5
            ));
        }
    }
    s
}

fn at(f: &Frame, x: i64, y: i64) -> &PixelValue {
    &f.pixels[(y * i64::from(f.width) + x) as usize]
}

#[test]
fn a_checker_moves_and_deforms_as_boxes_do() {
    let d = Dir::new("texture-checker");
    for velocity in ["[0, 0, 0]", "[0.6, 0, 0]", "[-0.5, 0.7, 0]"] {
        let load = |name: &str, text: &str| {
            let p = d.file(name, text);
            rest_embree::scene::load_file(&p, &[]).unwrap_or_else(|e| panic!("{e}"))
        };
        let (checker, boxes) = (
            load("checker.toml", &checker_plate(velocity)),
            load("boxes.toml", &boxes_plate(velocity)),
        );
        for b in backends() {
            let (c, x) = (render_with(&checker, b), render_with(&boxes, b));
            let (w, h) = (i64::from(c.width), i64::from(c.height));
            let (mut light, mut dark, mut inside) = (0, 0, 0);
            for yy in 0..h {
                for xx in 0..w {
                    let (p, q) = (at(&c, xx, yy), at(&x, xx, yy));
                    match q.material_id {
                        2 => light += 1,
                        3 => dark += 1,
                        _ => {}
                    }
                    if p.color == q.color && p.alpha == q.alpha {
                        continue;
                    }
                    // Only where the boxes meet: a neighbour of another box or none.
                    let edge = (-1..=1).any(|dy| {
                        (-1..=1).any(|dx| {
                            let (u, v) = (xx + dx, yy + dy);
                            (0..w).contains(&u)
                                && (0..h).contains(&v)
                                && at(&x, u, v).object_id != q.object_id
                        })
                    });
                    if !edge {
                        inside += 1;
                    }
                }
            }
            assert!(
                light > 150 && dark > 150,
                "{velocity} on {b}: both colours in view ({light}, {dark})"
            );
            assert_eq!(
                inside, 0,
                "{velocity} on {b}: pixels off the squares' edges differ"
            );
        }
    }
}

/// An emitting checker glows in its two colours; unknown and malformed textures are refused
/// at their key with what is accepted.
#[test]
fn emission_textures_and_bad_textures() {
    let d = Dir::new("texture-bad");
    let glow = checker_plate("[0, 0, 0]").replace("color = \"squares\"", "emission = \"squares\"");
    let p = d.file("glow.toml", &glow);
    let scene = rest_embree::scene::load_file(&p, &[]).unwrap();
    let f = render_with(&scene, "bvh");
    let hit: Vec<[f32; 3]> = f
        .pixels
        .iter()
        .filter(|p| p.object_id == 1)
        .map(|p| p.color)
        .collect();
    assert!(
        hit.iter().any(|c| (c[0] - 0.9).abs() < 0.02)
            && hit.iter().any(|c| (c[2] - 0.5).abs() < 0.02),
        "both emitted colours seen"
    );
    let base = checker_plate("[0, 0, 0]");
    for (from, to, needles) in [
        (
            "color = \"squares\"",
            "color = \"squarez\"",
            &[
                "key `material.checked.color`",
                "no texture is named `squarez`",
                "textures: squares",
            ][..],
        ),
        ("size = [0.5, 0.5, 0], ", "", &["size", "missing"][..]),
        (
            "size = [0.5, 0.5, 0]",
            "size = [0, 0, 0]",
            &["size", "greater than 0"][..],
        ),
        (
            "color2 = [0.1, 0.2, 0.5]",
            "color2 = \"blue\"",
            &["color2", "a colour is"][..],
        ),
        (
            "checker = {",
            "checkers = {",
            &["key `texture.squares.checkers`", "did you mean `checker`?"][..],
        ),
    ] {
        let text = base.replace(from, to);
        assert_ne!(text, base, "{from}");
        let s = d.file("bad.toml", &text);
        let out = d.0.join("bad.png");
        let (code, err) = status(&["render", s.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        assert_eq!(code, Some(1), "{to}: {err}");
        assert!(err.contains("bad.toml:"), "{to}: {err}");
        for n in needles {
            assert!(err.contains(n), "{to}: `{n}` in {err}");
        }
        assert!(!out.exists());
    }
}

/// An image on a sphere: longitude and latitude as docs/scene-format.md maps them. The camera
/// on -y sees longitudes from -180° (its left) to 0° (its right), u from 0 to 0.5: the image's
/// first quarter (green) left of the centre, its second (red) right of it, its back half
/// (blue) nowhere; the top half at full brightness, the bottom half at half (sRGB 188).
#[test]
fn an_image_wraps_a_sphere_by_longitude_and_latitude() {
    let d = Dir::new("texture-image");
    write_png(&d.0.join("map.png"), 64, 32, |x, y| {
        let v = if y < 16 { 255 } else { 188 };
        match x {
            0..16 => [0, v, 0],
            16..32 => [v, 0, 0],
            _ => [0, 0, v],
        }
    });
    let text = "[camera]\nposition = [0, -5, 0]\nlook_at = [0, 0, 0]\nfov_y = 30\n\n[image]\nwidth = 64\nheight = 64\n\n\
                [[texture]]\nname = \"map\"\nimage = \"map.png\"\n\n[[material]]\nname = \"planet\"\nemission = \"map\"\n\n\
                [[group]]\nname = \"planet\"\n[[group.object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"planet\"\n";
    let p = d.file("planet.toml", text);
    let scene = rest_embree::scene::load_file(&p, &[]).unwrap();
    for b in backends() {
        let f = render_with(&scene, b);
        let px = |x: i64, y: i64| at(&f, x, y).color;
        // Left of centre, above: green; right, above: red; right, below: red at half.
        let (left, right, below) = (px(24, 26), px(40, 26), px(40, 38));
        assert!(
            left[1] > 0.95 && left[0] < 0.02 && left[2] < 0.02,
            "{b}: {left:?}"
        );
        assert!(
            right[0] > 0.95 && right[1] < 0.02 && right[2] < 0.02,
            "{b}: {right:?}"
        );
        assert!(
            (below[0] - 0.503).abs() < 0.01 && below[2] < 0.02,
            "{b}: {below:?}"
        );
        assert!(
            f.pixels.iter().all(|p| p.color[2] < 0.02),
            "{b}: the back half is not seen"
        );
    }
    // A mesh cannot take an image yet; an image that is not one is refused.
    d.file("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n");
    d.file("junk.png", "not a png");
    // A PNG whose header claims 2^30 pixels a side (its decoder's limits refused it as
    // "limits are exceeded", from the fifth trial): its size is said.
    let chunk = |kind: &[u8], data: &[u8]| {
        let mut c = (data.len() as u32).to_be_bytes().to_vec();
        c.extend_from_slice(kind);
        c.extend_from_slice(data);
        // PNG's CRC-32 over the kind and the data, bit by bit.
        let mut crc = !0u32;
        for &byte in kind.iter().chain(data) {
            crc ^= u32::from(byte);
            for _ in 0..8 {
                crc = if crc & 1 == 1 {
                    (crc >> 1) ^ 0xEDB8_8320
                } else {
                    crc >> 1
                };
            }
        }
        c.extend_from_slice(&(!crc).to_be_bytes());
        c
    };
    let mut huge = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = (1u32 << 30).to_be_bytes().to_vec();
    ihdr.extend_from_slice(&(1u32 << 30).to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    huge.extend(chunk(b"IHDR", &ihdr));
    huge.extend(chunk(b"IDAT", &[0; 16]));
    std::fs::write(d.0.join("huge.png"), huge).unwrap();
    for (from, to, needles) in [
        (
            "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1",
            "type = \"mesh\"\nfile = \"tri.obj\"",
            &["material", "no texture coordinates"][..],
        ),
        (
            "image = \"map.png\"",
            "image = \"junk.png\"",
            &["junk.png", "not a readable PNG"][..],
        ),
        (
            "image = \"map.png\"",
            "image = \"huge.png\"",
            &[
                "huge.png",
                "it is 1073741824x1073741824; a texture has 1 to 2^28 texels",
            ][..],
        ),
        (
            "image = \"map.png\"",
            "image = \"gone.exr\"",
            &["gone.exr", "cannot read it"][..],
        ),
        (
            "image = \"map.png\"",
            "image = \"map.jpg\"",
            &["map.jpg", "cannot read it"][..],
        ),
    ] {
        let bad = text.replace(from, to);
        assert_ne!(bad, text);
        let s = d.file("bad.toml", &bad);
        let out = d.0.join("bad.png");
        let (code, err) = status(&["render", s.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        assert_eq!(code, Some(1), "{to}: {err}");
        for n in needles {
            assert!(err.contains(n), "{to}: `{n}` in {err}");
        }
    }
}

/// The planet demo loads and renders (a small image): its map is where the scene says.
#[test]
fn the_planet_demo_renders() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let sets = [
        ("--width 48".to_string(), "image.width=48".to_string()),
        ("--height 32".to_string(), "image.height=32".to_string()),
    ];
    let scene = rest_embree::scene::load_file(&root.join("scenes/planet.toml"), &sets).unwrap();
    let f = render_with(&scene, "bvh");
    assert_all_finite(&f, "bvh");
    assert!(
        f.pixels.iter().filter(|p| p.object_id == 1).count() > 20,
        "the planet is in view"
    );
}

/// A mesh's texture coordinates from its file map an image onto it: a square of two triangles
/// whose corners take the image's corners shows each quarter of a 2 x 2 image in its place
/// (vt's v up from the bottom, as OBJ has it).
#[test]
fn a_mesh_maps_an_image_by_its_texture_coordinates() {
    let d = Dir::new("texture-uv");
    write_png(&d.0.join("quads.png"), 2, 2, |x, y| match (x, y) {
        (0, 0) => [255, 0, 0],
        (1, 0) => [0, 255, 0],
        (0, 1) => [0, 0, 255],
        _ => [255, 255, 255],
    });
    // A square in the plane y = 0, facing -y, x and z from -1 to 1.
    d.file(
        "square.obj",
        "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    );
    let text = "[camera]\nposition = [0, -5, 0]\nlook_at = [0, 0, 0]\nfov_y = 30\n\n[image]\nwidth = 64\nheight = 64\n\n\
                [[texture]]\nname = \"quads\"\nimage = \"quads.png\"\n\n[[material]]\nname = \"lit\"\nemission = \"quads\"\n\n\
                [[group]]\nname = \"square\"\n[[group.object]]\ntype = \"mesh\"\nfile = \"square.obj\"\nmaterial = \"lit\"\n";
    let scene = rest_embree::scene::load_file(&d.file("uv.toml", text), &[]).unwrap();
    for b in backends() {
        let f = render_with(&scene, b);
        // Top left of the square (x < 0, z > 0): the image's top left texel, red.
        let c = |x: i64, y: i64| at(&f, x, y).color;
        let near =
            |got: [f32; 3], want: [f32; 3]| got.iter().zip(want).all(|(g, w)| (g - w).abs() < 0.05);
        assert!(
            near(c(20, 20), [1.0, 0.0, 0.0]),
            "{b}: top left {:?}",
            c(20, 20)
        );
        assert!(
            near(c(43, 20), [0.0, 1.0, 0.0]),
            "{b}: top right {:?}",
            c(43, 20)
        );
        assert!(
            near(c(20, 43), [0.0, 0.0, 1.0]),
            "{b}: bottom left {:?}",
            c(20, 43)
        );
        assert!(
            near(c(43, 43), [1.0, 1.0, 1.0]),
            "{b}: bottom right {:?}",
            c(43, 43)
        );
    }
}

/// Textures turn and move with their object: an object placed by `scale`, `rotate` and
/// `translate`, seen by a camera placed the same way, is the picture of the object as given
/// (a sphere with an image, and a box turned by 30°, so twelve triangles, with an image and
/// with a checker), all but silhouette pixels equal.
#[test]
fn textures_turn_and_move_with_their_object() {
    let d = Dir::new("texture-placed");
    write_png(&d.0.join("map.png"), 64, 32, |x, y| {
        [(x * 4) as u8, (y * 8) as u8, ((x * 7 + y * 3) % 256) as u8]
    });
    let scene = |object: &str, place: &str, camera: [f64; 3], look: [f64; 3]| {
        format!(
            "[camera]\nposition = {camera:?}\nlook_at = {look:?}\nup = [0, 0, 1]\nfov_y = 30\n\n\
             [image]\nwidth = 64\nheight = 64\n\n\
             [[texture]]\nname = \"map\"\nimage = \"map.png\"\n\n\
             [[texture]]\nname = \"squares\"\nchecker = {{ size = 0.3, color1 = [1, 0.5, 0], color2 = [0, 0.2, 1] }}\n\n\
             [[material]]\nname = \"map\"\nemission = \"map\"\n\n[[material]]\nname = \"squares\"\nemission = \"squares\"\n\n\
             [[group]]\nname = \"g\"\n[[group.object]]\n{object}\n{place}\n"
        )
    };
    // Scaled by 2, turned 30° about z, moved by (2, 1, 0.5): the camera at 5 units on -y
    // becomes 10 units along the turned -y from the moved centre.
    let a = 30f64.to_radians();
    let (t, k) = ([2.0, 1.0, 0.5], 2.0);
    let cam = [
        t[0] + k * 5.0 * a.sin(),
        t[1] - k * 5.0 * a.cos(),
        t[2] + k * 1.5,
    ];
    let place = "scale = 2\nrotate = { axis = [0, 0, 1], degrees = 30 }\ntranslate = [2, 1, 0.5]";
    for (what, object) in [
        (
            "sphere",
            "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"map\"",
        ),
        (
            "box",
            "type = \"box\"\nmin = [-1, -1, -1]\nmax = [1, 1, 1]\nmaterial = \"map\"",
        ),
        (
            "checker box",
            "type = \"box\"\nmin = [-1, -1, -1]\nmax = [1, 1, 1]\nmaterial = \"squares\"",
        ),
    ] {
        let given = d.file(
            "given.toml",
            &scene(object, "", [0.0, -5.0, 1.5], [0.0, 0.0, 0.0]),
        );
        let placed = d.file("placed.toml", &scene(object, place, cam, t));
        let (given, placed) = (
            rest_embree::scene::load_file(&given, &[]).unwrap(),
            rest_embree::scene::load_file(&placed, &[]).unwrap(),
        );
        for b in backends() {
            let (fa, fb) = (render_with(&given, b), render_with(&placed, b));
            let lit = fa.pixels.iter().filter(|p| p.color != [0.0; 3]).count();
            assert!(lit > 800, "{what}, {b}: {lit} pixels show it");
            same_picture(&fa, &fb, &format!("{what}, {b}"), 0.03, 0.02);
            // Not a picture that any placement would match: the texture varies across it.
            let distinct: std::collections::HashSet<[u32; 3]> = fa
                .pixels
                .iter()
                .map(|p| p.color.map(|c| (c * 50.0) as u32))
                .collect();
            let least = if what == "checker box" { 3 } else { 9 };
            assert!(
                distinct.len() >= least,
                "{what}, {b}: {} colours",
                distinct.len()
            );
        }
    }
}
