//! Spinning bodies that are not of revolution about their axis (docs/physics.md §12.6): a bar
//! and a spoked wheel turn in their group's frame, and each ray meets the body where the point
//! it reaches, turned back by ω T, lies in its shape at time 0.

use crate::common::*;
use glam::DVec3;

const W: u32 = 600;
const H: u32 = 41;
const F: f64 = 500.0;

/// A camera at rest at (0, −10, 0) looking along +y at view time `time`, and `object` at rest.
fn view(object: &str, time: f64, width: u32, height: u32, focal: f64) -> String {
    format!(
        r#"
[camera]
position = [0, -10, 0]
direction = [0, 1, 0]
up = [0, 0, 1]
fov_y = {fov}
time = {time:?}
[image]
width = {width}
height = {height}
passes = ["all"]
[render]
ambient = 0.3
[[light]]
position = [0, -10, 0]
[[group]]
name = "spinner"
[[group.object]]
{object}
"#,
        fov = fov_for_focal(focal, height),
    )
}

const OMEGA: f64 = 0.4;

fn bar(omega: f64) -> String {
    format!("type = \"box\"\nmin = [-2, -0.2, -0.3]\nmax = [2, 0.2, 0.3]\nspin = {{ axis = [0, 0, 1], omega = {omega:?} }}")
}

fn wheel(omega: Option<f64>) -> String {
    let spin = omega.map_or(String::new(), |w| {
        format!("spin = {{ axis = [0, -1, 0], omega = {w:?} }}")
    });
    format!(
        "type = \"wheel\"\ncenter = [0, 0, 0]\naxis = [0, -1, 0]\nradius = 2\nspokes = 8\n{spin}"
    )
}

/// The bar spinning at ω = 0.4 about z (its ends at 0.8c), seen along the centre row: every
/// pixel is covered where an independent march along its ray (small steps, each event's point
/// turned back by ω T and tested against the bar at time 0, then bisection) finds the bar, at
/// that lookback; each point's Doppler factor is its velocity's.
#[test]
fn a_spinning_bar_is_where_the_march_along_the_ray_finds_it() {
    let time = 10.0;
    let first = |u: f64| -> Option<f64> {
        let d = DVec3::new(u, F, 0.0).normalize();
        let inside = |l: f64| {
            let p = DVec3::new(0.0, -10.0, 0.0) + l * d;
            let back = glam::DQuat::from_rotation_z(-OMEGA * (time - l));
            let q = back * p;
            q.x.abs() <= 2.0 && q.y.abs() <= 0.2 && q.z.abs() <= 0.3
        };
        first_entry(inside, 5.0, 15.0, 1e-4)
    };
    let row = (H / 2) as usize * W as usize;
    for backend in backends() {
        let f = render_with(&scene(&view(&bar(OMEGA), time, W, H, F)), backend);
        let (alpha, lookback, doppler) = (
            f.channel("A").unwrap(),
            f.channel("lookback.V").unwrap(),
            f.channel("doppler.V").unwrap(),
        );
        let (px, py) = (f.channel("P.X").unwrap(), f.channel("P.Y").unwrap());
        let (mut covered, mut mismatched, mut worst, mut worst_d) = (0, 0, 0.0f64, 0.0f64);
        for x in 0..W as usize {
            let u = x as f64 + 0.5 - W as f64 / 2.0;
            let i = row + x;
            let truth = first(u);
            if (alpha[i] > 0.0) != truth.is_some() {
                mismatched += 1;
                continue;
            }
            let Some(lambda) = truth else { continue };
            assert!(
                lookback[i].is_finite() && doppler[i].is_finite(),
                "{backend}: pixel {x}"
            );
            covered += 1;
            worst = worst.max((lookback[i] as f64 / lambda - 1.0).abs());
            let p = DVec3::new(px[i] as f64, py[i] as f64, 0.0);
            let v = OMEGA * DVec3::Z.cross(p);
            let a = DVec3::new(u, F, 0.0).normalize();
            let d = 1.0 / ((1.0 - v.length_squared()).powf(-0.5) * (1.0 + v.dot(a)));
            worst_d = worst_d.max((doppler[i] as f64 / d - 1.0).abs());
        }
        assert!(covered > 30, "{backend}: {covered} pixels see the bar");
        assert_eq!(
            mismatched, 0,
            "{backend}: pixels the march and the render disagree on"
        );
        report(
            "spinning bar: lookback against a march along the ray",
            backend,
            0.0,
            worst,
            1e-6,
            "relative",
        );
        report(
            "spinning bar: each point's Doppler factor",
            backend,
            0.0,
            worst_d,
            1e-4,
            "relative",
        );
    }
}

/// Standing still (ω = 0), the wheel traced by the march is the wheel traced by the exact
/// tests of its hub and rods.
#[test]
fn a_wheel_at_omega_zero_is_the_still_wheel() {
    for backend in backends() {
        let still = render_with(&scene(&view(&wheel(None), 10.0, 96, 96, 150.0)), backend);
        let marched = render_with(
            &scene(&view(&wheel(Some(0.0)), 10.0, 96, 96, 150.0)),
            backend,
        );
        // The same pixels see the same rods; the spinning one is shaded through spectra (it
        // might move), the still one in RGB, which differ by rounding of the colour matching.
        same_picture(&still, &marched, "wheel at omega 0", 0.0, 2e-3);
        let (a, b) = (
            still.channel("lookback.V").unwrap(),
            marched.channel("lookback.V").unwrap(),
        );
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-5, "{backend}: lookback differs by {worst}");
    }
}

/// An eight-spoked wheel (rim of 48 rods) looks the same every eighth of a turn, 2π/(8ω) of
/// view time apart, and not a sixteenth of a turn later.
#[test]
fn a_spoked_wheel_repeats_every_spoke() {
    let omega = 0.44;
    let step = std::f64::consts::TAU / (8.0 * omega);
    for backend in backends() {
        let at = |t: f64| {
            render_with(
                &scene(&view(&wheel(Some(omega)), t, 96, 96, 150.0)),
                backend,
            )
        };
        let (a, b, c) = (at(10.0), at(10.0 + step), at(10.0 + 0.5 * step));
        same_picture(&a, &b, "a spoke later", 3.0 / (96.0 * 96.0), 1e-3);
        let moved = a
            .pixels
            .iter()
            .zip(&c.pixels)
            .filter(|(p, q)| p.object_id != q.object_id)
            .count();
        assert!(
            moved > 50,
            "{backend}: half a spoke later {moved} pixels changed"
        );
    }
}

#[test]
fn bad_wheels_are_refused() {
    let load = |object: &str| {
        rest_embree::scene::load_str("test.toml", &view(object, 0.0, 8, 8, 10.0), &[])
            .unwrap_err()
            .to_string()
    };
    let e = load(&wheel(Some(0.5)));
    assert!(
        e.contains("key `group.spinner.object.0.spin.omega`: the rim would move at"),
        "{e}"
    );
    let e = load("type = \"wheel\"\ncenter = [0, 0, 0]\nradius = 1\nspokes = 0");
    assert!(e.contains("object.0.spokes"), "{e}");
    let e = load("type = \"wheel\"\ncenter = [0, 0, 0]\nradius = 1\nscale = 2");
    assert!(e.contains("a wheel is placed by its own keys"), "{e}");
}

/// Far in time (about 10⁶ turns later... a million units of time) the bar looks as it did a
/// whole number of turns before: its rays start near the imaging event in the group's time,
/// so their lookbacks stay small however late the view.
#[test]
fn a_bar_a_million_units_of_time_later_is_the_same_bar() {
    let period = std::f64::consts::TAU / OMEGA;
    let turns = (1e6 / period).round();
    for backend in backends() {
        let at = |t: f64| render_with(&scene(&view(&bar(OMEGA), t, 120, 41, 100.0)), backend);
        let (a, b) = (at(10.0), at(10.0 + turns * period));
        same_picture(&a, &b, "a million units later", 2.0 / (120.0 * 41.0), 1e-3);
        let (la, lb) = (
            a.channel("lookback.V").unwrap(),
            b.channel("lookback.V").unwrap(),
        );
        let worst = la
            .iter()
            .zip(&lb)
            .filter(|(x, y)| **x > 0.0 && **y > 0.0)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-4, "{backend}: lookbacks differ by {worst}");
    }
}

/// A spacetime translation of the whole scene leaves the picture of a turning bar, at rest and
/// in a moving group: the body's epoch moves with the group's time, so it stands at the same
/// angle at the moved events (before, it showed turned by ω Δt).
#[test]
fn a_translated_scene_with_a_turning_bar_renders_the_same() {
    use rest_embree::spacetime::Event;
    let still = view(&bar(OMEGA), 10.0, 120, 41, 100.0);
    let moving = still.replace(
        "name = \"spinner\"",
        "name = \"spinner\"\nvelocity = [0.3, 0, 0.2]",
    );
    assert_ne!(still, moving);
    for text in [still, moving] {
        let s = scene(&text);
        for backend in backends() {
            let a = render_with(&s, backend);
            for shift in [
                Event::new(3.7, DVec3::new(1.0, -2.0, 0.5)),
                Event::new(-250.0, DVec3::new(0.0, 40.0, -3.0)),
            ] {
                let b = render_with(&s.translated(shift), backend);
                same_picture(&a, &b, "translated", 2.0 / (120.0 * 41.0), 1e-3);
            }
        }
    }
}
