//! Light in glass travels at c/n in the glass's rest frame (docs/physics.md §9): the event a
//! ray through a slab leaves its back face is found there, n times the thickness back in time.
//! With the slab moving, the delay in the world frame follows from the boosts alone, and must be
//! Fizeau's: light crossing a slab of rest thickness L moving at β along the light takes
//! L/(γ(u − β)) with u = (1/n + β)/(1 + β/n), relativistic velocity addition (c = 1).

use crate::accel::backend_by_name;
use crate::render::{Seen, Shader, World};
use crate::spacetime::NullRay;
use glam::DVec3;

/// A glass slab 2 thick (rest frame) across x, moving at `beta` along +x, seen by a camera on
/// the +x axis looking down −x (the light it sees travels along +x, through the slab).
fn slab(beta: f64, n: f64) -> crate::scene::Scene {
    let text = format!(
        r#"
[camera]
position = [40, 0, 0]
direction = [-1, 0, 0]
up = [0, 0, 1]
fov_y = 10
time = 0
[image]
width = 3
height = 3
[[material]]
name = "glass"
color = 0
transmit = 1
ior = {n}
[[group]]
name = "slab"
velocity = [{beta}, 0, 0]
[[group.object]]
type = "box"
min = [-1, -50, -50]
max = [1, 50, 50]
material = "glass"
"#
    );
    crate::scene::load_str("slab.toml", &text, &[]).unwrap()
}

#[test]
fn light_crossing_a_moving_slab_is_dragged_as_fizeau_found() {
    for backend in ["bvh", "embree"] {
        let Ok(b) = backend_by_name(backend) else {
            continue;
        };
        for n in [1.0, 1.33, 1.5, 2.4] {
            for beta in [0.0, 0.3, 0.6, -0.6, 0.99] {
                let scene = slab(beta, n);
                let world = World::build(&scene, b.as_ref()).unwrap();
                let shader = Shader::<DVec3>::new(&scene, &world, Seen::NONE);
                let ray = NullRay::new(scene.camera.imaging_event(), DVec3::NEG_X);
                let hit = world.closest_hit(&ray, 0.0).expect("the slab's front face");
                let entry = ray.at(hit.lambda);
                let dir = hit.dir / hit.s;
                assert!(
                    (dir - DVec3::NEG_X).length() < 1e-12,
                    "along the axis in its frame"
                );
                let (_, exit, dist) = shader
                    .inside_hit(hit.group, entry, DVec3::NEG_X, dir, n)
                    .expect("the back face");
                let delay = entry.t - exit.t;
                assert!(
                    (dist - 2.0).abs() < 1e-9,
                    "the way through, rest frame: {dist}"
                );
                let gamma = 1.0 / (1.0 - beta * beta).sqrt();
                let u = (1.0 / n + beta) / (1.0 + beta / n);
                let want = 2.0 / (gamma * (u - beta));
                let err = (delay - want).abs() / want;
                assert!(
                    err < 1e-9,
                    "n = {n}, β = {beta} on {backend}: delay {delay}, Fizeau {want} ({err:e})"
                );
                if beta == 0.0 {
                    assert!((delay - 2.0 * n).abs() < 1e-12, "at rest: n L");
                }
                // The exit is on the back face, 2 behind the front in the slab's frame.
                let front = world.groups[0].boost.event(entry).x.x;
                let back = world.groups[0].boost.event(exit).x.x;
                assert!((front - back - 2.0).abs() < 1e-9, "{front} {back}");
            }
        }
    }
}
