//! A sample allocates nothing: a tile's buffers are made once (the worker's `TileScratch`, and
//! each tile's sums) and refilled sample after sample, so the allocations of a tile do not grow
//! with its samples per pixel. Counted on this thread (allocation-counter, a
//! dev-dependency that counts the test binaries' allocations per thread) for Whitted's shading
//! with point lights, mirrors and glass and for the path integrator, in RGB and in spectra.

use super::common::scene;
use crate::accel::backend_by_name;
use crate::render::{render_tile, CameraRays, Emitters, Passes, Seen, TileScratch, View, World};
use crate::scene::Integrator;
use crate::spectrum::Sampled;
use glam::DVec3;

/// Two groups (one moving), a floor, a mirror ball, a glass ball and a glowing ball, lit by
/// two point lights; `render` its [render] table.
fn room(render: &str) -> String {
    format!(
        r#"
[camera]
position = [0, -8, 2]
look_at = [0, 0, 0.5]
up = [0, 0, 1]
fov_y = 40
[image]
width = 16
height = 16
[render]
{render}
[[light]]
position = [3, -3, 6]
intensity = 20
[[light]]
position = [-3, -2, 4]
intensity = 5
[[material]]
name = "floor"
color = 0.7
[[material]]
name = "mirror"
color = 0.1
reflect = 0.8
[[material]]
name = "glass"
color = 0
transmit = 1
ior = 1.5
[[material]]
name = "glow"
emission = 4
[[group]]
name = "still"
[[group.object]]
type = "box"
min = [-8, -8, -1]
max = [8, 8, 0]
material = "floor"
[[group.object]]
type = "sphere"
center = [-1.2, 0, 0.8]
radius = 0.8
material = "mirror"
[[group]]
name = "moving"
velocity = [0.6, 0, 0]
[[group.object]]
type = "sphere"
center = [1.2, 0, 0.8]
radius = 0.8
material = "glass"
[[group.object]]
type = "sphere"
center = [0, 2, 1.5]
radius = 0.5
material = "glow"
"#
    )
}

/// Twelve boxes, each its own velocity group (so the world has group trees and the light at
/// rest a light tree), on a floor, lit by one point light; `render` its [render] table.
fn many_groups(render: &str) -> String {
    let mut s = format!(
        r#"
[camera]
position = [0, -12, 3]
look_at = [0, 0, 0.5]
up = [0, 0, 1]
fov_y = 50
[image]
width = 16
height = 16
[render]
{render}
[[light]]
position = [2, -4, 8]
intensity = 30
[[material]]
name = "white"
color = 0.7
[[group]]
name = "floor"
[[group.object]]
type = "box"
min = [-9, -9, -1]
max = [9, 9, 0]
material = "white"
"#
    );
    for i in 0..12 {
        let (x, y) = ((i % 4) as f64 * 2.5 - 3.75, (i / 4) as f64 * 2.5 - 2.5);
        let v = 0.05 * i as f64;
        s.push_str(&format!(
            "[[group]]\nname = \"box{i}\"\nvelocity = [{v}, 0, 0]\n[[group.object]]\ntype = \"box\"\nmin = [{}, {}, 0]\nmax = [{}, {}, 1]\nmaterial = \"white\"\n",
            x - 0.5, y - 0.5, x + 0.5, y + 0.5
        ));
    }
    s
}

/// The allocations of rendering the scene's one tile with `samples` samples per pixel, on
/// this thread, after a first render has grown the worker's buffers.
fn tile_allocations(toml: &str, samples: u32, spectral: bool, passes: Passes) -> u64 {
    let mut sc = scene(toml);
    sc.image.samples = samples;
    let world = World::build(&sc, backend_by_name("bvh").unwrap().as_ref()).unwrap();
    let cam = CameraRays::new(&sc.camera, sc.image.width, sc.image.height);
    let emitters = (sc.render.integrator == Integrator::Path).then(|| Emitters::new(&sc, &world));
    let view = View {
        cam: &cam,
        cull: None,
        stars: None,
        cones: None,
        emitters: emitters.as_ref(),
        sample_base: 0,
    };
    let mut scratch = TileScratch::default();
    let mut tile = || match spectral {
        true => {
            let seen = Seen::of(&sc);
            let t = render_tile::<Sampled>(seen, &sc, &world, &view, (0, 0), passes, &mut scratch);
            assert_eq!(t.nonfinite, 0);
        }
        false => {
            let seen = Seen::NONE;
            let t = render_tile::<DVec3>(seen, &sc, &world, &view, (0, 0), passes, &mut scratch);
            assert_eq!(t.nonfinite, 0);
        }
    };
    tile();
    allocation_counter::measure(tile).count_total
}

#[test]
fn a_sample_allocates_nothing() {
    for (render, what) in [
        ("max_depth = 4", "Whitted"),
        (
            "integrator = \"path\"\nmax_depth = 6",
            "the path integrator",
        ),
    ] {
        for (toml, scene) in [(room(render), "room"), (many_groups(render), "12 groups")] {
            for spectral in [false, true] {
                // The mattes count the objects each pixel's samples saw on the stack up to four (the
                // room has four); a pixel that sees more keeps its counts on the heap, which grow
                // with the objects it sees, not with its samples.
                let all = match scene {
                    "room" => &[Passes::Colour, Passes::All][..],
                    _ => &[Passes::Colour][..],
                };
                for &passes in all {
                    let few = tile_allocations(&toml, 8, spectral, passes);
                    let many = tile_allocations(&toml, 64, spectral, passes);
                    assert!(few > 0, "the count counts");
                    assert_eq!(
                    few, many,
                    "{what}, {scene} (spectral {spectral}, {passes:?}): a tile allocates {few} times with 8 samples a pixel, {many} with 64"
                );
                }
            }
        }
    }
}
