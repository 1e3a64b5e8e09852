//! Embree under every instruction set this CPU has, sse2 up: each of Embree's code paths traces
//! packets of its own native width (4 lanes for SSE, 8 for AVX and AVX2, 16 for AVX-512) and
//! splits and copies any other before it calls back into user geometry, so the callbacks must
//! find their rays by the ids the queries give them, never by a lane's position. Each path, at
//! its native width and at one it is not native to, renders the same pictures as the f64 BVH:
//! the paper's scenes at 0.9c (the lattice listed and instanced, the bar array, the passing
//! spheres) and random scenes of 3 to 1,000 velocity groups of boxes, spheres and rods, with
//! mirrors, glass and shadows toward lights at rest and moving, seen from a camera at rest and
//! moving (every group through Embree, though the renderer would intersect a group of a few
//! primitives directly). And a panic in any callback is caught at the FFI boundary and fails
//! the render, naming the callback.

#![cfg(feature = "embree")]

use super::common::Rng;
use crate::accel::{Backend, Callback, EmbreeBackend, Isa};
use crate::render::{render, Frame, RenderOptions, WorldOptions};
use crate::scene::paper::paper;
use crate::scene::Scene;
use glam::DVec3;

/// The Embree backends to compare on this CPU: per instruction set it has, the native width
/// and one that is not native there (16 lanes below AVX-512; single rays on AVX-512, where
/// every packet width is native), each named for the failure messages.
fn backends() -> Vec<(String, EmbreeBackend)> {
    let on_cpu = Isa::on_cpu();
    assert!(!on_cpu.is_empty(), "an x86-64 CPU has SSE2 at least");
    let mut all = Vec::new();
    for isa in on_cpu {
        let other = if isa.native_width() == 16 { 1 } else { 16 };
        let native = EmbreeBackend::new().on_isa(isa).expect("the CPU has it");
        assert_eq!(
            native.packet_width().unwrap(),
            isa.native_width(),
            "{isa:?}"
        );
        all.push((format!("embree on {} (native)", isa.name()), native));
        let fixed = EmbreeBackend::with_packet_width(other)
            .on_isa(isa)
            .expect("the CPU has it");
        all.push((format!("embree on {}, width {other}", isa.name()), fixed));
    }
    all
}

/// Where two renders of one scene differ: pixels that see another object, or whose colour or
/// alpha differs by more than 1/255; None if none does.
fn disagreement(reference: &Frame, got: &Frame) -> Option<String> {
    let tol = 1.0 / 255.0;
    let mut bad = 0;
    let mut first = None;
    for (i, (p, q)) in reference.pixels.iter().zip(&got.pixels).enumerate() {
        let colour = (0..3).any(|k| (p.color[k] - q.color[k]).abs() > tol);
        if p.object_id != q.object_id || colour || (p.alpha - q.alpha).abs() > tol {
            bad += 1;
            first.get_or_insert(format!(
                "pixel ({}, {}): f64 BVH sees object {} colour {:?}, Embree object {} colour {:?}",
                i as u32 % reference.width,
                i as u32 / reference.width,
                p.object_id,
                p.color,
                q.object_id,
                q.color
            ));
        }
    }
    (bad > 0).then(|| {
        format!(
            "{bad} of {} pixels differ; first {}",
            got.pixels.len(),
            first.unwrap()
        )
    })
}

/// Renders `scene` on the f64 BVH and on every backend of `backends()`, and fails naming each
/// backend whose picture differs.
fn agrees_everywhere(what: &str, scene: &Scene, world: WorldOptions) {
    let options = RenderOptions {
        world,
        ..RenderOptions::default()
    };
    let bvh = crate::accel::backend_by_name("bvh").unwrap();
    let (reference, _) = render(scene, bvh.as_ref(), &options).unwrap();
    let hits = reference.pixels.iter().filter(|p| p.object_id != 0).count();
    assert!(
        hits > reference.pixels.len() / 30,
        "{what}: the scene should fill the picture (only {hits} pixels hit)"
    );
    let mut failures = Vec::new();
    for (name, backend) in backends() {
        match render(scene, &backend, &options) {
            Ok((frame, _)) => {
                if let Some(d) = disagreement(&reference, &frame) {
                    failures.push(format!("{name}: {d}"));
                }
            }
            Err(e) => failures.push(format!("{name}: {e}")),
        }
        assert!(backend.faults().unwrap().check().is_ok(), "{name}: a fault");
        assert_eq!(backend.faults().unwrap().count(), 0, "{name}: a fault");
    }
    assert!(failures.is_empty(), "{what}:\n{}", failures.join("\n"));
}

fn small(name: &str, sets: &[&str]) -> Scene {
    let mut all = vec!["image.width=96", "image.height=72", "image.samples=1"];
    all.extend_from_slice(sets);
    let sets: Vec<String> = all.iter().map(|s| s.to_string()).collect();
    paper(name, &sets).unwrap()
}

#[test]
fn the_paper_lattice_at_0_9c_agrees_on_every_isa() {
    let s = small("lattice", &["group.lattice.velocity=[-0.9, 0, 0]"]);
    agrees_everywhere("lattice at 0.9c", &s, WorldOptions::default());
}

/// The lattice held as itself: Embree instances of one block, whose callbacks make each
/// member from its number (instanced_blocks.rs).
#[test]
fn the_paper_lattice_instanced_agrees_on_every_isa() {
    let s = small("lattice", &["group.lattice.velocity=[-0.9, 0, 0]"]);
    let world = WorldOptions {
        instance_over: 100,
        ..WorldOptions::default()
    };
    agrees_everywhere("lattice at 0.9c, instanced", &s, world);
}

#[test]
fn the_paper_bar_array_at_0_9c_agrees_on_every_isa() {
    let s = small("bar_array", &["group.bars.velocity=[0.9, 0, 0]"]);
    agrees_everywhere("bar array at 0.9c", &s, WorldOptions::default());
    let world = WorldOptions {
        instance_over: 10,
        ..WorldOptions::default()
    };
    agrees_everywhere("bar array at 0.9c, instanced", &s, world);
}

#[test]
fn the_passing_spheres_at_0_9c_agree_on_every_isa() {
    let sets: Vec<(String, String)> = [
        "image.width=120",
        "image.height=40",
        "image.samples=1",
        "group.spheres.velocity=[0.9, 0, 0]",
    ]
    .iter()
    .map(|s| (format!("--set {s}"), s.to_string()))
    .collect();
    let text = include_str!("../../scenes/passing_spheres.toml");
    let s = crate::scene::load_str("scenes/passing_spheres.toml", text, &sets).unwrap();
    agrees_everywhere("passing spheres at 0.9c", &s, WorldOptions::default());
}

/// `n` groups of boxes, spheres and rods with mixed velocities up to 0.9c (every fourth group
/// shares the velocity of the one before, so some merge), mirrors and glass among them, a
/// light at rest and one moving; the camera moving at 0.5c where `moving_camera` says so.
fn random_groups(n: usize, seed: u64, moving_camera: bool) -> Scene {
    let mut r = Rng(seed);
    let camera_velocity = if moving_camera {
        "[0.3, 0.4, 0]"
    } else {
        "[0, 0, 0]"
    };
    let mut s = format!(
        r#"
[camera]
position = [0, -40, 4]
look_at = [0, 0, 0]
fov_y = 55
time = 40
velocity = {camera_velocity}
[image]
width = 96
height = 72
background = [0.05, 0.05, 0.1]
[render]
max_depth = 4
[[material]]
name = "matte"
color = [0.7, 0.5, 0.3]
specular = 0.3
[[material]]
name = "mirror"
color = 0.1
reflect = 0.7
[[material]]
name = "glass"
color = 0.05
transmit = 0.8
ior = 1.5
[[light]]
position = [10, -30, 30]
[[light]]
position = [-20, -10, 20]
velocity = [0.4, 0, 0]
intensity = 0.6
"#
    );
    // Spread over the view (±20 high at 40 away), and the bigger the fewer.
    let spread = 8.0 + (n as f64).cbrt() * 2.0;
    let size = 8.0 / (n as f64).cbrt();
    let mut v = DVec3::ZERO;
    for i in 0..n {
        if i % 4 != 3 {
            v = r.unit() * r.range(0.0, 0.9);
        }
        // Where the group is at world time 0, about when the light seen at the imaging event
        // (time 40, 40 away) left it.
        let c = DVec3::new(
            r.range(-spread, spread),
            r.range(-spread, spread) * 0.5,
            r.range(-spread, spread) * 0.75,
        );
        let material = ["matte", "mirror", "glass"][i % 3];
        s += &format!(
            "[[group]]\nname = \"g{i}\"\nvelocity = [{:?}, {:?}, {:?}]\n[[group.object]]\nmaterial = \"{material}\"\n",
            v.x, v.y, v.z
        );
        let h = size * r.range(0.5, 1.0);
        s += &match r.next_u64() % 3 {
            0 => format!(
                "type = \"box\"\nmin = [{:?}, {:?}, {:?}]\nmax = [{:?}, {:?}, {:?}]\n",
                c.x - h,
                c.y - h,
                c.z - h,
                c.x + h,
                c.y + h,
                c.z + h
            ),
            1 => format!(
                "type = \"sphere\"\ncenter = [{:?}, {:?}, {:?}]\nradius = {h:?}\n",
                c.x, c.y, c.z
            ),
            _ => {
                let a = r.unit() * h * 1.5;
                format!(
                    "type = \"rod\"\nfrom = [{:?}, {:?}, {:?}]\nto = [{:?}, {:?}, {:?}]\nradius = {:?}\n",
                    c.x - a.x,
                    c.y - a.y,
                    c.z - a.z,
                    c.x + a.x,
                    c.y + a.y,
                    c.z + a.z,
                    h * 0.4
                )
            }
        };
    }
    crate::scene::load_str(&format!("{n}-groups.toml"), &s, &[]).unwrap()
}

/// Every group through Embree: the renderer would intersect a group of a few primitives
/// directly in f64, without its accelerator.
fn through_embree() -> WorldOptions {
    WorldOptions {
        direct_max: 0,
        ..WorldOptions::default()
    }
}

#[test]
fn three_groups_agree_on_every_isa() {
    agrees_everywhere("3 groups", &random_groups(3, 1, false), through_embree());
}

#[test]
fn twenty_groups_seen_by_a_moving_camera_agree_on_every_isa() {
    agrees_everywhere("20 groups", &random_groups(20, 2, true), through_embree());
}

#[test]
fn a_hundred_groups_agree_on_every_isa() {
    agrees_everywhere(
        "100 groups",
        &random_groups(100, 3, false),
        through_embree(),
    );
    let s = random_groups(100, 4, true);
    agrees_everywhere("100 groups, camera moving", &s, through_embree());
    // And as the renderer runs by default: small groups in f64, through Embree's culler.
    agrees_everywhere("100 groups, default", &s, WorldOptions::default());
}

#[test]
fn a_thousand_groups_agree_on_every_isa() {
    agrees_everywhere(
        "1000 groups",
        &random_groups(1000, 5, true),
        through_embree(),
    );
}

/// A panic inside any callback is caught before it reaches Embree, and the render fails with
/// an error naming the callback, under each instruction set: the exact primitives' closest-hit
/// (fans of primary rays) and occlusion (shadow rays) callbacks, the instanced blocks' two,
/// and the culler's over many groups.
#[test]
fn a_panic_in_any_callback_fails_the_render() {
    let lattice = small("lattice", &["group.lattice.velocity=[-0.9, 0, 0]"]);
    let instanced = WorldOptions {
        instance_over: 100,
        ..WorldOptions::default()
    };
    let groups = random_groups(1000, 6, false);
    let cases = [
        (Callback::Intersect, &lattice, WorldOptions::default()),
        (Callback::Occluded, &lattice, WorldOptions::default()),
        (Callback::BlockIntersect, &lattice, instanced),
        (Callback::BlockOccluded, &lattice, instanced),
        (Callback::Cull, &groups, WorldOptions::default()),
    ];
    assert_eq!(cases.len(), Callback::ALL.len());
    for (callback, scene, world) in cases {
        for isa in Isa::on_cpu() {
            let what = format!("{} callback on {}", callback.name(), isa.name());
            let backend = EmbreeBackend::new()
                .on_isa(isa)
                .unwrap()
                .with_fault_injected_in(Some(callback));
            let options = RenderOptions {
                world,
                ..RenderOptions::default()
            };
            let e = render(scene, &backend, &options)
                .err()
                .unwrap_or_else(|| panic!("{what}: the render should fail"))
                .to_string();
            let want = format!("Embree's {} callback panicked", callback.name());
            assert!(e.contains(&want), "{what}: {e}");
            // The backend stays usable: a new world on it renders.
            render(scene, &backend, &options).unwrap_or_else(|e| panic!("{what}, again: {e}"));
        }
    }
}
