//! Spinning bodies of revolution (docs/physics.md §12.6): a sphere or rod spinning about its
//! axis keeps its shape in its group's frame, while every point of its surface moves with
//! v = ω × (p − c) and is shaded in its own rest frame.

use crate::common::*;
use glam::DVec3;

/// A white sphere of radius 2 at rest at the origin, seen from 10 away along −y, spinning about
/// z with rim speed `rim`; its colour a checker in longitude (so its turning shows).
fn spinning(rim: f64, time: f64, extra: &str) -> String {
    format!(
        r#"
[camera]
position = [0, -10, 0]
look_at = [0, 0, 0]
fov_y = 30
time = {time:?}
[image]
width = 64
height = 64
[render]
ambient = 0.3
[[light]]
position = [0, -10, 0]
[[texture]]
name = "stripes"
checker = {{ size = [0.7, 0.7, 0], color1 = [0.9, 0.9, 0.9], color2 = [0.2, 0.3, 0.8] }}
[[material]]
name = "paint"
color = "stripes"
[[group]]
name = "ball"
[[group.object]]
type = "sphere"
center = [0, 0, 0]
radius = 2
material = "paint"
spin = {{ axis = [0, 0, 1], omega = {:?} }}
{extra}
"#,
        rim / 2.0
    )
}

/// The outline is the sphere's at rest, pixel for pixel; the Doppler factor of every pixel
/// is the point velocity's: D = 1/(γ_u(1 + u·â)), â the look direction from the camera to
/// the point seen, u = ω ẑ × P (the camera and the ball's centre at rest).
#[test]
fn spinning_sphere_keeps_its_outline_and_shows_each_points_doppler_factor() {
    let omega = 0.9 / 2.0;
    for backend in backends() {
        let f = render_with(&scene(&spinning(0.9, 10.0, "")), backend);
        let still = render_with(&scene(&spinning(0.0, 10.0, "")), backend);
        assert_eq!(f.channel("A"), still.channel("A"), "{backend}: the outline");
        let (alpha, doppler) = (f.channel("A").unwrap(), f.channel("doppler.V").unwrap());
        let (px, py, pz) = (
            f.channel("P.X").unwrap(),
            f.channel("P.Y").unwrap(),
            f.channel("P.Z").unwrap(),
        );
        let (mut worst, mut lo, mut hi) = (0.0f64, f64::INFINITY, 0.0f64);
        for i in 0..alpha.len() {
            if alpha[i] < 1.0 {
                continue;
            }
            let p = DVec3::new(px[i] as f64, py[i] as f64, pz[i] as f64);
            let u = omega * DVec3::Z.cross(p);
            let a = (p - DVec3::new(0.0, -10.0, 0.0)).normalize();
            let gamma = 1.0 / (1.0 - u.length_squared()).sqrt();
            let d = 1.0 / (gamma * (1.0 + u.dot(a)));
            worst = worst.max((doppler[i] as f64 / d - 1.0).abs());
            (lo, hi) = (lo.min(d), hi.max(d));
        }
        // The limbs move at nearly 0.9c along the line of sight: D from ~0.23 to ~4.4.
        assert!(lo < 0.3 && hi > 3.5, "{backend}: limbs seen ({lo}, {hi})");
        report(
            "spinning sphere: each point's Doppler factor",
            backend,
            0.0,
            worst,
            5e-3,
            "relative",
        );
    }
}

/// The paint turns with the body: one period 2π/ω later the picture is the same (to rounding),
/// half a period later the stripes have moved.
#[test]
fn paint_turns_with_the_body() {
    let omega = 0.5 / 2.0;
    let period = 2.0 * std::f64::consts::PI / omega;
    for backend in backends() {
        let at = |t: f64| {
            render_with(&scene(&spinning(0.5, t, "")), backend)
                .channel("R")
                .unwrap()
        };
        let (a, b, c) = (at(10.0), at(10.0 + period), at(10.0 + 0.5 * period / 4.0));
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-4, "{backend}: a period later differs by {worst}");
        let moved = a
            .iter()
            .zip(&c)
            .filter(|(x, y)| (*x - *y).abs() > 0.05)
            .count();
        assert!(
            moved > 100,
            "{backend}: an eighth of a turn later {moved} pixels changed"
        );
    }
}

#[test]
fn bad_spins_are_refused() {
    let load = |text: &str| {
        rest_embree::scene::load_str("test.toml", text, &[])
            .unwrap_err()
            .to_string()
    };
    let e = load(&spinning(1.0, 0.0, ""));
    assert!(
        e.contains("test.toml:27: key `group.ball.object.0.spin.omega`: the rim would move at"),
        "{e}"
    );
    let lattice = spinning(0.5, 0.0, "").replace(
        "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 2",
        "type = \"lattice\"\ncounts = [2, 2, 2]",
    );
    let e = load(&lattice);
    assert!(e.contains("a spinning lattice is not built yet"), "{e}");
    // A spin without its rate was no spin, without a word (the fifth trial).
    let e = load(&spinning(0.5, 0.0, "").replace(", omega = 0.25", ""));
    assert!(
        e.contains("key `group.ball.object.0.spin.omega`: missing: give the rate of turning"),
        "{e}"
    );
    let turned_box = spinning(0.5, 0.0, "").replace(
        "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 2",
        "type = \"box\"\nmin = [-1, -1, -1]\nmax = [1, 1, 1]\nrotate = { axis = [0, 0, 1], degrees = 30 }",
    );
    let e = load(&turned_box);
    assert!(e.contains("a spinning mesh is not built yet"), "{e}");
    // A rod about a cross axis turns; about its own it is a body of revolution.
    let rod = spinning(0.5, 0.0, "").replace(
        "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 2",
        "type = \"rod\"\nfrom = [-1, 0, 0]\nto = [1, 0, 0]\nradius = 0.5",
    );
    scene(&rod);
    let path = spinning(0.5, 0.0, "").replace("[render]\n", "[render]\nintegrator = \"path\"\n");
    assert!(load(&path).contains("spinning objects are not built yet for integrator = \"path\""));
    // A rod about its own axis spins.
    scene(&rod.replace("axis = [0, 0, 1]", "axis = [-2, 0, 0]"));
}
