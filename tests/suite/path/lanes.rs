//! The path integrator's lanes (src/render/path/lanes.rs, the direct lanes of small groups)
//! change no picture.

use crate::common::*;
use rest_embree::render::Frame;

/// A closed room of diffuse boxes lit by a glowing sphere (as the Mitsuba anchor builds it),
/// with `extra` appended: the vertices the lanes take (Lambert surfaces at rest, a glowing
/// sphere at rest) and, with the extra objects, the ones they do not (a mirror, glass, a
/// point light, a glowing box, a moving group, a textured emitter).
fn room(extra: &str) -> String {
    let mut s = String::from(
        r#"
[camera]
position = [0, 0, 4.8]
look_at = [0, -0.5, -5]
fov_y = 62
[image]
width = 24
height = 24
samples = 6
background = 0
transparent = false
[render]
integrator = "path"
max_depth = 12
seed = 5
[[material]]
name = "wall"
color = [0.7, 0.7, 0.7]
[[material]]
name = "red"
color = [0.65, 0.08, 0.06]
[[material]]
name = "lamp"
emission = 12
[[group]]
name = "room"
"#,
    );
    for (lo, hi, m) in [
        ([-5.0, -5.5, -5.0], [5.0, -5.0, 5.0], "wall"),
        ([-5.0, 5.0, -5.0], [5.0, 5.5, 5.0], "wall"),
        ([-5.0, -5.0, -5.5], [5.0, 5.0, -5.0], "wall"),
        ([-5.0, -5.0, 5.0], [5.0, 5.0, 5.5], "wall"),
        ([-5.5, -5.0, -5.0], [-5.0, 5.0, 5.0], "red"),
        ([5.0, -5.0, -5.0], [5.5, 5.0, 5.0], "wall"),
    ] {
        s += &format!(
            "[[group.object]]\ntype = \"box\"\nmin = {lo:?}\nmax = {hi:?}\nmaterial = \"{m}\"\n"
        );
    }
    s += "[[group.object]]\ntype = \"sphere\"\ncenter = [-2, -3.2, -1]\nradius = 1.8\nmaterial = \"wall\"\n";
    s += "[[group.object]]\ntype = \"sphere\"\ncenter = [0, 4, 0]\nradius = 0.6\nmaterial = \"lamp\"\n";
    s + extra
}

/// What the lanes do not take: a rough mirror, clear glass, a point light, a glowing box, a
/// group moving at 0.5c, and more than 16 primitives in one group (an accelerator).
const ROOM_EXTRAS: &str = r#"
[[material]]
name = "mirror"
color = 0
reflect = 0.8
roughness = 0.3
[[material]]
name = "glass"
color = 0
transmit = 1
ior = 1.5
[[material]]
name = "panel"
emission = 3
[[light]]
position = [2, 3, 2]
intensity = 4
[[group.object]]
type = "box"
min = [0.5, -5, -3]
max = [3, -1, -0.5]
material = "mirror"
[[group.object]]
type = "box"
min = [-4.5, 4.0, -4.5]
max = [-3.0, 4.2, -3.0]
material = "panel"
[[group.object]]
type = "lattice"
counts = [3, 3, 1]
spacing = 0.5
sphere_radius = 0.1
rod_radius = 0.03
origin = [-1, 0, -4]
sphere_material = "wall"
rod_material = "wall"
[[group]]
name = "passing"
velocity = [0.5, 0, 0]
[[group.object]]
type = "sphere"
center = [2, 1, -2]
radius = 0.7
material = "glass"
"#;

/// The lanes change no picture: a bounce's Lambert vertices drawn in vector registers, one by
/// one (the switch `REST_EMBREE_SIMD=off` sets), or by the scalar path alone (no lanes), and
/// small groups through their direct lanes or an accelerator, give the same bytes, on every
/// backend, in the room where the lanes take nearly every vertex and with every kind of vertex
/// they leave to the scalar path. Every hit is exact in f64 on every backend, so Embree under
/// each instruction set (make test runs this under every `REST_EMBREE_ISA`) gives the f64
/// BVH's bytes too.
#[test]
fn the_lanes_change_no_picture() {
    use rest_embree::render::{RenderOptions, WorldOptions};
    let bits = |f: &Frame| -> Vec<u32> {
        f.pixels
            .iter()
            .flat_map(|p| p.color.map(f32::to_bits))
            .collect()
    };
    for text in [room(""), room(ROOM_EXTRAS)] {
        let sc = scene(&text);
        let render = |backend: &str, lanes: bool, simd: bool, direct_max: usize| {
            let b = rest_embree::accel::backend_by_name(backend).unwrap();
            let world = WorldOptions {
                lanes,
                simd,
                direct_max,
                ..Default::default()
            };
            let options = RenderOptions {
                world,
                ..Default::default()
            };
            let (frame, stats) = rest_embree::render(&sc, b.as_ref(), &options).unwrap();
            assert_eq!(stats.nonfinite_pixels, 0);
            frame
        };
        let direct = WorldOptions::default().direct_max;
        let reference = render("bvh", true, true, direct);
        assert!(
            reference.pixels.iter().any(|p| p.color[0] > 0.01),
            "the room is lit"
        );
        for backend in backends() {
            for (what, lanes, simd, direct_max) in [
                ("lanes in vector registers", true, true, direct),
                ("lanes one by one", true, false, direct),
                ("no lanes", false, false, direct),
                ("no lanes, SIMD on", false, true, direct),
                ("an accelerator for every group", true, true, 0),
            ] {
                let other = render(backend, lanes, simd, direct_max);
                assert!(
                    bits(&reference) == bits(&other),
                    "{backend}, {what}: not the f64 BVH's picture with lanes"
                );
            }
        }
    }
}
