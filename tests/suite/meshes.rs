//! Meshes from files and transforms (docs/scene-format.md, "Meshes from files", "Transforms"):
//! a box written as OBJ, as ASCII PLY and as binary PLY renders as the `box` object, on both
//! backends, at rest and moving; a scaled, turned and moved mesh equals the same mesh written
//! already transformed; a box turned by quarter turns stays a box, turned otherwise becomes its
//! triangles; bad mesh files are clear errors naming the scene's line and key and the mesh
//! file's own line.

use crate::common::cli::{status, Dir, GOOD};
use crate::common::*;
use glam::{DMat3, DVec3};
use rest_embree::render::Frame;

/// The unit box of GOOD, from (-0.5, 10, -0.5) to (0.5, 11, 0.5): its corners, and its faces
/// counter-clockwise seen from outside (1-based, as OBJ counts).
pub(crate) fn box_corners() -> Vec<DVec3> {
    (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { -0.5 } else { 0.5 },
                if i & 2 == 0 { 10.0 } else { 11.0 },
                if i & 4 == 0 { -0.5 } else { 0.5 },
            )
        })
        .collect()
}
pub(crate) const BOX_FACES: [[u32; 4]; 6] = [
    [1, 3, 4, 2],
    [5, 6, 8, 7],
    [1, 2, 6, 5],
    [3, 7, 8, 4],
    [1, 5, 7, 3],
    [2, 4, 8, 6],
];

fn obj(corners: &[DVec3]) -> String {
    let mut s = String::from("# a box\no box\n");
    for c in corners {
        s.push_str(&format!("v {:?} {:?} {:?}\n", c.x, c.y, c.z));
    }
    for f in BOX_FACES {
        s.push_str(&format!("f {} {} {} {}\n", f[0], f[1], f[2], f[3]));
    }
    s
}

/// The box as an ASCII STL: two facets per face (STL has no polygons).
fn stl(corners: &[DVec3]) -> String {
    let mut s = String::from("solid box\n");
    for f in BOX_FACES {
        for t in [[f[0], f[1], f[2]], [f[0], f[2], f[3]]] {
            s.push_str("  facet normal 0 0 0\n    outer loop\n");
            for i in t {
                let c = corners[i as usize - 1];
                s.push_str(&format!("      vertex {:?} {:?} {:?}\n", c.x, c.y, c.z));
            }
            s.push_str("    endloop\n  endfacet\n");
        }
    }
    s.push_str("endsolid box\n");
    s
}

fn ply_ascii(corners: &[DVec3]) -> String {
    let mut s = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n",
        corners.len()
    );
    for c in corners {
        s.push_str(&format!("{:?} {:?} {:?}\n", c.x, c.y, c.z));
    }
    for f in BOX_FACES {
        s.push_str(&format!(
            "4 {} {} {} {}\n",
            f[0] - 1,
            f[1] - 1,
            f[2] - 1,
            f[3] - 1
        ));
    }
    s
}

fn ply_binary(corners: &[DVec3]) -> Vec<u8> {
    let mut b = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face 6\nproperty list uchar uint vertex_indices\nend_header\n",
        corners.len()
    )
    .into_bytes();
    for c in corners {
        for x in [c.x, c.y, c.z] {
            b.extend_from_slice(&(x as f32).to_le_bytes());
        }
    }
    for f in BOX_FACES {
        b.push(4);
        for i in f {
            b.extend_from_slice(&(i - 1).to_le_bytes());
        }
    }
    b
}

/// GOOD with its box replaced by `object` (the lines after `type = ...`).
pub(crate) fn with_object(object: &str) -> String {
    let text = GOOD.replace(
        "type = \"box\"\nmin = [-0.5, 10, -0.5]\nmax = [0.5, 11, 0.5]",
        object,
    );
    assert_ne!(text, GOOD, "GOOD's box is replaced");
    text
}

pub(crate) fn load(d: &Dir, name: &str, text: &str, sets: &[&str]) -> rest_embree::scene::Scene {
    let path = d.file(name, text);
    let sets: Vec<(String, String)> = sets
        .iter()
        .map(|s| (format!("--set {s}"), s.to_string()))
        .collect();
    rest_embree::scene::load_file(&path, &sets).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Pixels whose colour or coverage differ, and of those, how many are not on a silhouette (a
/// pixel with a neighbour, in `a`, of another object id or coverage).
pub(crate) fn differing(a: &Frame, b: &Frame) -> (usize, usize) {
    let (w, h) = (a.width as i64, a.height as i64);
    fn at(f: &Frame, x: i64, y: i64) -> &rest_embree::render::PixelValue {
        &f.pixels[(y * i64::from(f.width) + x) as usize]
    }
    let (mut all, mut inside) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let (p, q) = (at(a, x, y), at(b, x, y));
            if p.color == q.color && p.alpha == q.alpha {
                continue;
            }
            all += 1;
            let edge = (-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    let (u, v) = (x + dx, y + dy);
                    (0..w).contains(&u)
                        && (0..h).contains(&v)
                        && (at(a, u, v).object_id != p.object_id || at(a, u, v).alpha != p.alpha)
                })
            });
            if !edge {
                inside += 1;
            }
        }
    }
    (all, inside)
}

#[test]
fn a_box_as_obj_and_ply_renders_as_the_box() {
    let d = Dir::new("mesh-box");
    d.file("box.obj", &obj(&box_corners()));
    d.file("box.ply", &ply_ascii(&box_corners()));
    std::fs::write(d.0.join("box-binary.ply"), ply_binary(&box_corners())).unwrap();
    d.file("box.stl", &stl(&box_corners()));
    for velocity in ["[0, 0, 0]", "[0.5, 0, 0]", "[-0.3, 0.6, 0.2]"] {
        let set = format!("group.cube.velocity={velocity}");
        let sets = ["image.width=96", "image.height=64", set.as_str()];
        let reference = load(&d, "box.toml", GOOD, &sets);
        for file in ["box.obj", "box.ply", "box-binary.ply", "box.stl"] {
            let text = with_object(&format!("type = \"mesh\"\nfile = \"{file}\""));
            let mesh = load(&d, "mesh.toml", &text, &sets);
            for b in backends() {
                let (a, m) = (render_with(&reference, b), render_with(&mesh, b));
                assert!(
                    a.pixels.iter().any(|p| p.object_id == 1),
                    "the box is in view"
                );
                let (all, inside) = differing(&a, &m);
                let hit = a.pixels.iter().filter(|p| p.object_id == 1).count();
                eprintln!("{file} on {b} at {velocity}: {all} of {hit} box pixels differ");
                assert_eq!(
                    inside, 0,
                    "{file} on {b} at {velocity}: {all} pixels differ, {inside} off the silhouette"
                );
                assert!(
                    all * 50 < a.pixels.len(),
                    "{file} on {b} at {velocity}: {all} differ"
                );
            }
        }
    }
}

#[test]
fn a_transformed_mesh_equals_the_mesh_written_transformed() {
    let d = Dir::new("mesh-transform");
    // A box shape off the origin, scaled unevenly, turned about two axes, moved: the file the
    // scene transforms, against the same corners transformed here and written out.
    let shape: Vec<DVec3> = box_corners()
        .into_iter()
        .map(|c| (c - DVec3::new(0.0, 10.5, 0.0)) * DVec3::new(0.7, 0.4, 0.9))
        .collect();
    let scale = DVec3::new(1.5, 0.5, 2.0);
    let turn = DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 2.0) / 3.0, 35f64.to_radians());
    let turn = DMat3::from_axis_angle(DVec3::Z, (-20f64).to_radians()) * turn;
    let moved = DVec3::new(0.2, 10.5, -0.1);
    let placed: Vec<DVec3> = shape.iter().map(|&p| turn * (scale * p) + moved).collect();
    d.file("shape.obj", &obj(&shape));
    d.file("placed.obj", &obj(&placed));
    let transformed = with_object(
        "type = \"mesh\"\nfile = \"shape.obj\"\nscale = [1.5, 0.5, 2.0]\n\
         rotate = [{ axis = [1, 2, 2], degrees = 35 }, { axis = [0, 0, 1], degrees = -20 }]\n\
         translate = [0.2, 10.5, -0.1]",
    );
    let sets = ["image.width=96", "image.height=64"];
    let a = load(&d, "a.toml", &transformed, &sets);
    let b = load(
        &d,
        "b.toml",
        &with_object("type = \"mesh\"\nfile = \"placed.obj\""),
        &sets,
    );
    for backend in backends() {
        let (fa, fb) = (render_with(&a, backend), render_with(&b, backend));
        assert!(fa.pixels.iter().any(|p| p.object_id == 1), "in view");
        let (all, inside) = differing(&fa, &fb);
        assert_eq!(
            inside, 0,
            "{backend}: {all} differ, {inside} off the silhouette"
        );
        assert!(all * 100 < fa.pixels.len(), "{backend}: {all} differ");
    }
    // A box turned a quarter turn about z and moved stays a box: the box with x and y swapped.
    let turned = with_object(
        "type = \"box\"\nmin = [-0.5, -0.5, -0.5]\nmax = [0.5, 1.5, 0.5]\n\
         rotate = { axis = [0, 0, 1], degrees = 90 }\ntranslate = [0, 10.5, 0]",
    );
    let swapped = with_object("type = \"box\"\nmin = [-1.5, 10, -0.5]\nmax = [0.5, 11, 0.5]");
    let (t, s) = (
        load(&d, "t.toml", &turned, &sets),
        load(&d, "s.toml", &swapped, &sets),
    );
    assert_eq!(t.primitive_count(), 1, "still one box");
    let (ft, fs) = (render_with(&t, "bvh"), render_with(&s, "bvh"));
    assert!(ft
        .pixels
        .iter()
        .zip(&fs.pixels)
        .all(|(p, q)| p.color == q.color && p.alpha == q.alpha));
    // Turned by another angle: its twelve triangles, the same as the file of its corners.
    let oblique = with_object(
        "type = \"box\"\nmin = [-0.5, 10, -0.5]\nmax = [0.5, 11, 0.5]\n\
         rotate = { axis = [0, 1, 0], degrees = 30 }",
    );
    let o = load(&d, "o.toml", &oblique, &sets);
    assert_eq!(o.primitive_count(), 12);
    let r = DMat3::from_axis_angle(DVec3::Y, 30f64.to_radians());
    d.file(
        "oblique.obj",
        &obj(&box_corners().iter().map(|&c| r * c).collect::<Vec<_>>()),
    );
    let of = load(
        &d,
        "of.toml",
        &with_object("type = \"mesh\"\nfile = \"oblique.obj\""),
        &sets,
    );
    let (fo, ff) = (render_with(&o, "bvh"), render_with(&of, "bvh"));
    let (all, inside) = differing(&fo, &ff);
    assert_eq!(inside, 0, "{all} differ");
}

/// Each bad mesh or transform is refused with exit status 1, naming the scene file's line and
/// key and, inside a mesh file, its line; nothing is written.
#[test]
fn bad_meshes_and_transforms_are_clear_errors() {
    let d = Dir::new("mesh-bad");
    d.file("bad-v.obj", "v 0 0 0\nv 1 0 x\nv 0 1 0\nf 1 2 3\n");
    d.file("bad-f.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    d.file("empty.obj", "# nothing\nv 0 0 0\n");
    d.file("bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 zz\n0 1 0\n3 0 1 2\n");
    d.file("range.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
    d.file("model.3ds", "not a mesh\n");
    d.file(
        "bad.stl",
        "solid x\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 zz\n",
    );
    d.file("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    std::fs::create_dir_all(d.0.join("folder.obj")).unwrap();
    d.file(
        "two.obj",
        "v 0 10 0\nv 1 10 0\nv 0 11 0\nusemtl hull\nf 1 2 3\n",
    );
    let cases: [(&str, &[&str]); 18] = [
        ("type = \"mesh\"\nfile = \"missing.obj\"", &["missing.obj", "cannot read it"]),
        ("type = \"mesh\"\nfile = \"bad-v.obj\"", &["bad-v.obj:2", "position parse error"]),
        ("type = \"mesh\"\nfile = \"bad-f.obj\"", &["bad-f.obj:4", "names vertex 9"]),
        ("type = \"mesh\"\nfile = \"empty.obj\"", &["empty.obj", "no triangles"]),
        ("type = \"mesh\"\nfile = \"bad.ply\"", &["bad.ply", "not a readable PLY"]),
        ("type = \"mesh\"\nfile = \"range.ply\"", &["range.ply", "vertex 7"]),
        ("type = \"mesh\"\nfile = \"model.3ds\"", &["model.3ds", ".obj, .ply"]),
        ("type = \"mesh\"\nfile = \"bad.stl\"", &["bad.stl", "not a readable STL"]),
        ("type = \"mesh\"\nfile = \"nan.obj\"", &["nan.obj:2", "not a finite number"]),
        ("type = \"mesh\"\nfile = \"folder.obj\"", &["folder.obj", "not a regular file"]),
        (
            "type = \"mesh\"\nfile = \"bad-f.obj\"\nvertices = [[0, 0, 0]]",
            &["vertices", "not both"],
        ),
        (
            "type = \"sphere\"\ncenter = [0, 10, 0]\nradius = 1\nscale = [1, 2, 1]",
            &["key `group.cube.object.0.scale`", "no longer a sphere"],
        ),
        (
            "type = \"box\"\nmin = [-0.5, 10, -0.5]\nmax = [0.5, 11, 0.5]\nrotate = { axis = [0, 0, 0], degrees = 3 }",
            &["axis", "must not be zero"],
        ),
        (
            "type = \"lattice\"\ncounts = [2, 2, 2]\ntranslate = [1, 0, 0]",
            &["translate", "transforms apply to"],
        ),
        (
            "type = \"mesh\"\nfile = \"two.obj\"\nmaterials = { wing = \"white\" }",
            &["materials.wing", "the file has no material `wing`", "hull"],
        ),
        (
            "type = \"mesh\"\nfile = \"two.obj\"\nscale = [-1, 1, 1]",
            &["scale", "a mirrored placement is not taken"],
        ),
        (
            "type = \"mesh\"\nfile = \"two.obj\"\nmaterials = { hull = \"paint\" }",
            &["materials.hull", "no material named `paint`"],
        ),
        (
            "type = \"box\"\nmin = [-0.5, 10, -0.5]\nmax = [0.5, 11, 0.5]\nmaterials = { hull = \"white\" }",
            &["materials", "not used with the other keys"],
        ),
    ];
    for (object, needles) in cases {
        let scene = d.file("scene.toml", &with_object(object));
        let out = d.0.join("out.png");
        let (code, err) = status(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, Some(1), "{object}: {err}");
        assert!(
            err.contains("scene.toml:"),
            "{object}: the scene's line in: {err}"
        );
        for n in needles {
            assert!(err.contains(n), "{object}: `{n}` in: {err}");
        }
        assert!(!out.exists());
    }
}

/// A sphere written as a mesh of 16 x 32 quads: with its vertex normals it shades smoothly,
/// within a few percent of the exact sphere (a mesh's silhouette is a polygon, so only pixels
/// both renders see the sphere in are compared); without them, faceted, several times farther.
#[test]
fn vertex_normals_shade_a_mesh_smoothly() {
    let d = Dir::new("mesh-smooth");
    let (rings, segments) = (16, 32);
    let mut obj = String::new();
    let centre = DVec3::new(0.0, 10.0, 0.0);
    for i in 0..=rings {
        for j in 0..segments {
            let (th, ph) = (
                std::f64::consts::PI * i as f64 / rings as f64,
                2.0 * std::f64::consts::PI * j as f64 / segments as f64,
            );
            let n = DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
            let p = centre + n;
            obj.push_str(&format!(
                "v {:?} {:?} {:?}\nvn {:?} {:?} {:?}\n",
                p.x, p.y, p.z, n.x, n.y, n.z
            ));
        }
    }
    let flat_obj = obj
        .lines()
        .filter(|l| !l.starts_with("vn"))
        .map(|l| format!("{l}\n"))
        .collect::<String>();
    let (mut faces, mut flat_faces) = (String::new(), String::new());
    for i in 0..rings {
        for j in 0..segments {
            let k = |i: usize, j: usize| 1 + i * segments + j % segments;
            let q = [k(i, j), k(i + 1, j), k(i + 1, j + 1), k(i, j + 1)];
            faces.push_str(&format!(
                "f {0}//{0} {1}//{1} {2}//{2} {3}//{3}\n",
                q[0], q[1], q[2], q[3]
            ));
            flat_faces.push_str(&format!("f {} {} {} {}\n", q[0], q[1], q[2], q[3]));
        }
    }
    d.file("smooth.obj", &(obj + &faces));
    d.file("flat.obj", &(flat_obj + &flat_faces));
    let sets = [
        "image.width=96",
        "image.height=64",
        "group.cube.velocity=[0, 0, 0]",
    ];
    let sphere = load(
        &d,
        "sphere.toml",
        &with_object("type = \"sphere\"\ncenter = [0, 10, 0]\nradius = 1"),
        &sets,
    );
    let smooth = load(
        &d,
        "smooth.toml",
        &with_object("type = \"mesh\"\nfile = \"smooth.obj\""),
        &sets,
    );
    let flat = load(
        &d,
        "flat.toml",
        &with_object("type = \"mesh\"\nfile = \"flat.obj\""),
        &sets,
    );
    for b in backends() {
        let (s, m, f) = (
            render_with(&sphere, b),
            render_with(&smooth, b),
            render_with(&flat, b),
        );
        let error = |o: &Frame| {
            let (mut sum, mut n) = (0.0, 0);
            for (p, q) in s.pixels.iter().zip(&o.pixels) {
                if p.object_id == 1 && q.object_id == 1 {
                    sum += (0..3)
                        .map(|k| f64::from((p.color[k] - q.color[k]).abs()))
                        .sum::<f64>();
                    n += 1;
                }
            }
            assert!(n > 300, "{b}: {n} pixels compared");
            sum / n as f64
        };
        let (es, ef) = (error(&m), error(&f));
        let level = s
            .pixels
            .iter()
            .filter(|p| p.object_id == 1)
            .map(|p| f64::from(p.color[0] + p.color[1] + p.color[2]))
            .sum::<f64>()
            / s.pixels.iter().filter(|p| p.object_id == 1).count() as f64;
        assert!(
            es < 0.03 * level,
            "{b}: smooth mesh off the sphere by {es} (level {level})"
        );
        assert!(ef > 3.0 * es, "{b}: flat {ef} against smooth {es}");
    }
}

/// An OBJ's `usemtl` names choose the scene's materials: by the same name, by the object's
/// `materials` table, else the object's `material`; each run of triangles is a part of the
/// object with its material, and the primitive ids still count the object's triangles.
#[test]
fn obj_materials_map_to_the_scenes_by_name() {
    let d = Dir::new("mesh-materials");
    d.file(
        "ship.obj",
        "v 0 10 0\nv 1 10 0\nv 0 11 0\nv 1 11 0\nv 0 10 1\n\
         f 1 2 3\nusemtl red\nf 2 4 3\nf 1 2 5\nusemtl paint\nf 1 3 5\nusemtl other\nf 2 4 5\n",
    );
    let text = with_object(
        "type = \"mesh\"\nfile = \"ship.obj\"\nmaterials = { paint = \"blue\" }",
    ) + "\n[[material]]\nname = \"red\"\ncolor = [1, 0, 0]\n\n[[material]]\nname = \"blue\"\ncolor = [0, 0, 1]\n";
    let s = load(&d, "scene.toml", &text, &[]);
    let id = |n: &str| s.materials.iter().position(|m| m.name == n).unwrap() as u32;
    let g = &s.groups[0].geometry;
    let by_triangle: Vec<u32> = (0..5).map(|p| g.part_of(p).material).collect();
    assert_eq!(
        by_triangle,
        [id("white"), id("red"), id("red"), id("blue"), id("white")]
    );
    assert_eq!(g.parts.len(), 4);
    let ids: Vec<u32> = (0..5).map(|p| g.index_in_object(p)).collect();
    assert_eq!(ids, [0, 1, 2, 3, 4]);
}

/// A mesh file's triangles are held as the file has them (shared vertices, three indices a
/// triangle; Embree's triangle geometry over them) when the mesh is big, and listed one by one
/// when it is small: both give the same picture, to the bit, on both backends, with normals,
/// texture coordinates, materials and a transform, at rest and at 0.9c; in a group that also
/// holds a sphere, a box and a lattice (instanced where the mesh is held), so the held mesh
/// shares its Embree scene with user geometries and instances.
#[test]
fn a_mesh_held_as_itself_renders_as_listed() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let d = Dir::new("mesh-held");
    let text = std::fs::read_to_string(root.join("rocket.toml"))
        .unwrap()
        .replace("\"rocket.obj\"", &format!("{:?}", root.join("rocket.obj")))
        .replace("\"rocket-paint.png\"", &format!("{:?}", root.join("rocket-paint.png")))
        + "\n[[group.object]]\ntype = \"sphere\"\ncenter = [-2.5, 0, 1]\nradius = 0.6\n\
           \n[[group.object]]\ntype = \"box\"\nmin = [-1.5, 0, -1.6]\nmax = [-0.5, 1, -1]\nmaterial = \"fins\"\n\
           \n[[group.object]]\ntype = \"lattice\"\ncounts = [4, 3, 3]\nspacing = 0.6\norigin = [-3, 0.5, -1.8]\n\
           rod_radius = 0.04\nsphere_radius = 0.1\n";
    let path = d.file("rocket.toml", &text);
    for velocity in ["[0, 0, 0]", "[0.9, 0, 0]"] {
        let sets: Vec<(String, String)> = [
            "image.width=96".to_string(),
            "image.height=48".to_string(),
            "image.samples=1".to_string(),
            format!("group.rocket.velocity={velocity}"),
        ]
        .into_iter()
        .map(|s| (format!("--set {s}"), s))
        .collect();
        let scene = rest_embree::scene::load_file(&path, &sets).unwrap();
        for b in backends() {
            // Listed (the default for a mesh of a few thousand triangles) and held.
            let listed = render_held(&scene, b, u64::MAX);
            let held = render_held(&scene, b, 0);
            for object in 1..=4 {
                let seen = listed
                    .pixels
                    .iter()
                    .filter(|p| p.object_id == object)
                    .count();
                assert!(
                    seen > 20,
                    "{b} at {velocity}: {seen} pixels see object {object}"
                );
            }
            for (i, (l, h)) in listed.pixels.iter().zip(&held.pixels).enumerate() {
                assert_eq!(
                    (l.color, l.object_id, l.material_id),
                    (h.color, h.object_id, h.material_id),
                    "{b} at {velocity}: pixel {i}"
                );
            }
        }
    }
}
