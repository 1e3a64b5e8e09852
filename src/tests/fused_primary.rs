//! Fans of primary rays (`World::primary_hits`): where the backend makes a packet's primary
//! rays itself (Embree, four lanes per AVX2 vector) the renders are those of the rays made one
//! by one, to the bit, in every pass.

#![cfg(feature = "embree")]

use crate::accel::backend_by_name;
use crate::bench::trace_primary;
use crate::render::{render_world, CameraRays, Frame, World, WorldOptions};
use crate::scene::paper::paper;
use crate::scene::Scene;

fn lattice(sets: &[&str]) -> Scene {
    let mut all = vec!["image.width=96", "image.height=80", "image.samples=1"];
    all.extend_from_slice(sets);
    let sets: Vec<String> = all.iter().map(|s| s.to_string()).collect();
    paper("lattice", &sets).unwrap()
}

/// The first pixel where two frames differ, with both values.
fn first_difference(a: &Frame, b: &Frame) -> Option<String> {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .enumerate()
        .find(|(_, (p, q))| p != q)
        .map(|(i, (p, q))| format!("pixel {i}: {p:?} vs {q:?}"))
}

/// Renders `scene` on Embree with fans and without; asserts they are the same frame and, where
/// `fans` says so, that the fans were really used. On 16- and 8-wide packets (a fan of 16 lanes
/// is two packets there, as `intersect8` splits 16 rays).
fn same_with_and_without_fans(scene: &Scene, fans: bool) {
    for name in ["embree-16", "embree-8"] {
        same_on(name, scene, fans);
    }
}

fn same_on(name: &str, scene: &Scene, fans: bool) {
    let backend = backend_by_name(name).unwrap();
    let with = World::build(scene, backend.as_ref()).unwrap();
    let options = WorldOptions {
        fused_primary: false,
        ..WorldOptions::default()
    };
    let without = World::build_with(scene, backend.as_ref(), options).unwrap();
    let cam = CameraRays::new(&scene.camera, scene.image.width, scene.image.height);
    assert!(!without.serves_fans(&cam));
    if fans && std::arch::is_x86_feature_detected!("avx2") {
        assert!(
            with.serves_fans(&cam),
            "the fused path should serve this scene"
        );
    }
    let (a, b) = (
        render_world(scene, &with).0,
        render_world(scene, &without).0,
    );
    if let Some(d) = first_difference(&a, &b) {
        panic!("with fans / without: {d}");
    }
    assert_eq!(trace_primary(scene, &with), trace_primary(scene, &without));
}

#[test]
fn lattice_at_every_speed() {
    for b in ["0", "0.5", "0.9", "0.99"] {
        same_with_and_without_fans(
            &lattice(&[&format!("group.lattice.velocity=[-{b},0,0]")]),
            true,
        );
    }
}

#[test]
fn tiles_cut_by_the_image_edge() {
    // 97 × 81: the last tiles are a pixel wide or tall, and the corner tile (at rest the lattice
    // fills the view, so the screen cull keeps it) is one ray, which goes through Embree's
    // single-ray traversal either way. (Single-ray and packet traversal differ only on rays
    // grazing a box within f32 rounding, which this scene need not have: removing that rule
    // from the fans does not fail this test; it holds by construction.)
    let mut s = lattice(&["group.lattice.velocity=[0,0,0]"]);
    (s.image.width, s.image.height) = (97, 81);
    same_with_and_without_fans(&s, true);
}

#[test]
fn lone_rays() {
    // A tile of one pixel is a fan of one ray, which the Embree backend declines (it goes
    // through single-ray traversal): the renderer makes it one by one and keeps it among the
    // fans' columns, where the tile before (in the same buffers) left its own. Crops of
    // 17 × 1 pixels (a tile of 16, then one of 1) along two rows, so that lone rays meet the
    // lattice, and miss it after a first lane that met it, must come out as without fans.
    let backend = backend_by_name("embree").unwrap();
    let (mut meets, mut misses_after_a_hit) = (0, 0);
    for y in [7, 21] {
        for x in 0..80 {
            let crop = format!("image.crop=[{x},{y},17,1]");
            let s = lattice(&["group.lattice.velocity=[-0.5,0,0]", &crop]);
            let frame = render_world(&s, &World::build(&s, backend.as_ref()).unwrap()).0;
            let (first, lone) = (frame.get(0, 0).alpha > 0.0, frame.get(16, 0).alpha > 0.0);
            meets += u32::from(lone);
            misses_after_a_hit += u32::from(first && !lone);
            same_with_and_without_fans(&s, true);
        }
    }
    assert!(
        meets > 10 && misses_after_a_hit > 10,
        "{meets}, {misses_after_a_hit}"
    );
}

#[test]
fn moving_camera_samples_and_crop() {
    for sets in [
        &[
            "group.lattice.velocity=[-0.3,0,0]",
            "camera.velocity=[0.6,0.2,0]",
        ][..],
        &["group.lattice.velocity=[-0.9,0,0]", "image.samples=3"][..],
        &[
            "group.lattice.velocity=[-0.5,0,0]",
            "camera.direction=[1,-1,1]",
        ][..],
        &[
            "image.crop=[30,20,41,37]",
            "group.lattice.one_minus_beta=1e-9",
            "group.lattice.direction=[-1,0,0]",
        ][..],
    ] {
        same_with_and_without_fans(&lattice(sets), true);
    }
    let bars = paper(
        "bar_array",
        &[
            "image.width=64",
            "image.height=64",
            "group.bars.velocity=[0.9,0,0]",
        ]
        .map(String::from),
    )
    .unwrap();
    same_with_and_without_fans(&bars, true);
}

/// A group of `objects` (TOML `[[group.object]]` bodies) at 0.5c, seen from among them.
fn one_group(objects: &[String]) -> Scene {
    let mut text = String::from(
        "[camera]\nposition = [0, -6, 0.3]\nlook_at = [0, 0, 0]\nup = [0, 0, 1]\nfov_y = 70\n\
         time = 0\n[image]\nwidth = 64\nheight = 48\nsamples = 1\n\
         [[light]]\nposition = [2, -4, 5]\n\
         [[group]]\nname = \"g\"\nvelocity = [-0.5, 0, 0]\n",
    );
    for o in objects {
        text += &format!("[[group.object]]\n{o}\n");
    }
    crate::scene::load_str("one_group.toml", &text, &[]).unwrap()
}

#[test]
fn every_way_the_backend_reads_hits_back() {
    // Embree names a hit by geometry and primitive. Spheres and rods are one geometry, boxes
    // another, a mesh a third, refined after Embree rather than exact. Where each geometry's
    // primitives are a run of the scene's (kinds in blocks) the fans read hits back with no
    // lookup; interleaved kinds, or a mesh, take the general way.
    let (sphere, cube, rod) = (
        |x: f64, z: f64| format!("type = \"sphere\"\ncenter = [{x}, 0, {z}]\nradius = 0.45"),
        |x: f64, z: f64| {
            format!(
                "type = \"box\"\nmin = [{}, -0.4, {}]\nmax = [{}, 0.4, {}]",
                x - 0.4,
                z - 0.4,
                x + 0.4,
                z + 0.4
            )
        },
        |x: f64| format!("type = \"rod\"\nfrom = [{x}, -1, -3]\nto = [{x}, 1, 3]\nradius = 0.1"),
    );
    let xs = [-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0];
    let in_blocks: Vec<String> = (xs.iter().map(|&x| sphere(x, 1.0)))
        .chain(xs.iter().map(|&x| rod(x + 0.5)))
        .chain(xs.iter().map(|&x| cube(x, -1.0)))
        .collect();
    let interleaved: Vec<String> = xs
        .iter()
        .flat_map(|&x| [sphere(x, 1.0), cube(x, -1.0), rod(x + 0.5)])
        .collect();
    let mesh = "type = \"mesh\"\nvertices = [[-4, 2, -3], [4, 2, -3], [0, 2, 3]]\n\
                indices = [[0, 1, 2]]"
        .to_string();
    let with_mesh: Vec<String> = in_blocks.iter().cloned().chain([mesh]).collect();
    for (what, objects) in [
        ("in blocks", &in_blocks),
        ("interleaved", &interleaved),
        ("with a mesh", &with_mesh),
    ] {
        let scene = one_group(objects);
        same_with_and_without_fans(&scene, true);
        // Both of Embree's ways against the f64 BVH, which names primitives its own way: a
        // read-back that named the wrong primitive on both would pass the test above.
        let frame = |name: &str| {
            let world = World::build(&scene, backend_by_name(name).unwrap().as_ref()).unwrap();
            render_world(&scene, &world).0
        };
        super::common::same_picture(&frame("embree"), &frame("bvh"), what, 0.001, 1e-4);
        let world = World::build(&scene, backend_by_name("embree").unwrap().as_ref()).unwrap();
        let (rays, hits) = trace_primary(&scene, &world);
        assert!(
            hits > rays / 10 && hits < rays,
            "{hits} of {rays} rays hit: the test needs hits and misses"
        );
    }
}

#[test]
fn scenes_fans_do_not_serve_are_unchanged() {
    // One box: intersected directly, no accelerator.
    let cube = paper(
        "calibration_cube",
        &[
            "image.width=64",
            "image.height=64",
            "group.cube.velocity=[0.5,0,0]",
        ]
        .map(String::from),
    )
    .unwrap();
    // Seen from afar, so rays are clipped to the group's bounds; other projections.
    let far = lattice(&["camera.position=[-300,0,0]", "camera.time=300"]);
    let ortho = lattice(&["camera.projection=orthographic", "camera.view_height=12"]);
    let sky = lattice(&[
        "camera.projection=equirectangular",
        "group.lattice.velocity=[-0.5,0,0]",
    ]);
    let backend = backend_by_name("embree").unwrap();
    for scene in [&cube, &far, &ortho, &sky] {
        let world = World::build(scene, backend.as_ref()).unwrap();
        let cam = CameraRays::new(&scene.camera, scene.image.width, scene.image.height);
        assert!(!world.serves_fans(&cam));
        same_with_and_without_fans(scene, false);
    }
    // Backends without a path for fans: the BVH, Embree's single rays.
    let scene = lattice(&["group.lattice.velocity=[-0.9,0,0]"]);
    let cam = CameraRays::new(&scene.camera, scene.image.width, scene.image.height);
    for name in ["bvh", "embree-single"] {
        let world = World::build(&scene, backend_by_name(name).unwrap().as_ref()).unwrap();
        assert!(!world.serves_fans(&cam), "{name}");
    }
}
