//! Worldlines of uniform segments (docs/physics.md §12.4): a group whose velocity changes at
//! given world times is a group per segment, each seen only at emission events within its
//! segment's times, and the merge by emission time picks among them.

use crate::common::*;
use rest_embree::render::Frame;

fn sphere_scene(motion: &str, time: f64) -> String {
    format!(
        r#"
[camera]
position = [0, -10, 0]
look_at = [0, 0, 0]
fov_y = 24
time = {time:?}
[image]
width = 96
height = 64
[[light]]
position = [-5, -10, 8]
[[group]]
name = "ball"
{motion}
[[group.object]]
type = "sphere"
center = [0, 0, 0]
radius = 1
"#
    )
}

fn bytes(f: &Frame) -> Vec<u32> {
    f.pixels
        .iter()
        .flat_map(|p| p.values().map(f32::to_bits))
        .collect()
}

#[test]
fn one_segment_and_equal_segments_are_the_uniform_group_to_the_bit() {
    let uniform = sphere_scene("velocity = [0.8, 0, 0]", 10.0);
    let one = sphere_scene("worldline = [{ velocity = [0.8, 0, 0] }]", 10.0);
    let two = sphere_scene(
        "worldline = [{ until = -1, velocity = [0.8, 0, 0] }, { until = 3, beta = 0.8, direction = [1, 0, 0] }, { velocity = [0.8, 0, 0] }]",
        10.0,
    );
    for backend in backends() {
        let u = bytes(&render_with(&scene(&uniform), backend));
        assert_eq!(
            u,
            bytes(&render_with(&scene(&one), backend)),
            "{backend}: one segment"
        );
        assert_eq!(
            u,
            bytes(&render_with(&scene(&two), backend)),
            "{backend}: equal segments"
        );
    }
}

const STOPS: &str = "worldline = [{ until = 0, velocity = [0.8, 0, 0] }, { velocity = [0, 0, 0] }]";

/// A ball moving at 0.8c stops at world time 0 at the world origin. Long before its light
/// from the stop arrives it looks as if it moved for ever, long after as if it always rested;
/// in between (view time 9.4: the front left after the stop, the limb before it) every pixel
/// shows the segment whose times hold its emission event: a hit with
/// D = 1 (at rest, as the camera is) left at t_e ≥ 0 from the sphere |P| = 1, any other left
/// at t_e ≤ 0 from the moving sphere γ²(x − 0.8 t_e)² + y² + z² = 1.
#[test]
fn a_ball_that_stops_is_seen_in_each_segment_at_its_times() {
    let gamma = 1.0 / (1.0f64 - 0.64).sqrt();
    for backend in backends() {
        // Emission at view time − 10 ± 1: before the stop at view time 7, after it at 13.
        for (t, forever) in [
            (7.0, "velocity = [0.8, 0, 0]"),
            (13.0, "velocity = [0, 0, 0]"),
        ] {
            let a = render_with(&scene(&sphere_scene(STOPS, t)), backend);
            let b = render_with(&scene(&sphere_scene(forever, t)), backend);
            // Two groups clip rays to their bounds where one does not: Embree's f32 hit points
            // move by its rounding.
            same_picture(&a, &b, &format!("{backend}: at view time {t}"), 0.0, 2e-3);
        }
        let f = render_with(&scene(&sphere_scene(STOPS, 9.4)), backend);
        let ch = |name: &str| f.channel(name).unwrap();
        let (alpha, lookback, doppler) = (ch("A"), ch("lookback.V"), ch("doppler.V"));
        let (px, py, pz) = (ch("P.X"), ch("P.Y"), ch("P.Z"));
        let (mut resting, mut moving, mut worst) = (0, 0, 0.0f64);
        for i in 0..alpha.len() {
            if alpha[i] == 0.0 {
                continue;
            }
            let te = 9.4 - lookback[i] as f64;
            let (x, y, z) = (px[i] as f64, py[i] as f64, pz[i] as f64);
            let off = if (doppler[i] as f64 - 1.0).abs() < 1e-6 {
                resting += 1;
                assert!(
                    te >= -1e-4,
                    "{backend}: a resting hit left at {te}, before the stop"
                );
                (x * x + y * y + z * z).sqrt() - 1.0
            } else {
                moving += 1;
                assert!(
                    te <= 1e-4,
                    "{backend}: a moving hit left at {te}, after the stop"
                );
                let xr = gamma * (x - 0.8 * te);
                (xr * xr + y * y + z * z).sqrt() - 1.0
            };
            worst = worst.max(off.abs());
        }
        assert!(
            resting > 50 && moving > 50,
            "{backend}: both segments seen ({resting}, {moving})"
        );
        report(
            "a stopping ball: hits on their segment's sphere",
            backend,
            0.0,
            worst,
            1e-5,
            "length",
        );
    }
}

/// The render's line counts the groups the file names, a worldline's pieces as the rest frames
/// they are; the EXR's `groupVelocities` says which piece each entry is.
#[test]
fn a_worldline_is_one_group_of_several_rest_frames() {
    use crate::common::cli::{oiiotool, status, Dir};
    let d = Dir::new("worldline-pieces");
    let three = "worldline = [{ until = -1, velocity = [0.8, 0, 0] }, { until = 3, velocity = [0, 0, 0] }, { velocity = [-0.5, 0, 0] }]";
    let text = sphere_scene(three, 10.0)
        + "[[group]]\nname = \"still\"\n[[group.object]]\ntype = \"sphere\"\ncenter = [3, 0, 0]\nradius = 1\n";
    let file = d.file("pieces.toml", &text);
    let out = d.0.join("pieces.exr");
    let (code, err) = status(&[
        "render",
        file.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("2 primitives in 2 groups (4 rest frames)"),
        "{err}"
    );
    let info = oiiotool(&["--info", "-v", out.to_str().unwrap()]);
    for needle in [
        "\"ball: beta = [0.8, 0.0, 0.0] (piece 1 of 3 of its worldline)\"",
        "\"ball: beta = [0.0, 0.0, 0.0] (piece 2 of 3 of its worldline)\"",
        "\"ball: beta = [-0.5, 0.0, 0.0] (piece 3 of 3 of its worldline)\"",
        "\"still: beta = [0.0, 0.0, 0.0]\"",
    ] {
        assert!(info.contains(needle), "`{needle}` in:\n{info}");
    }
    // A scene without worldlines says its groups as before.
    let plain = d.file("plain.toml", &sphere_scene("velocity = [0.5, 0, 0]", 10.0));
    let (code, err) = status(&[
        "render",
        plain.to_str().unwrap(),
        "-o",
        d.0.join("p.png").to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("1 primitive in 1 group, backend"), "{err}");
}

#[test]
fn bad_worldlines_name_the_key() {
    let cases = [
        (
            "worldline = [{ velocity = [0.8, 0, 0] }, { velocity = [0, 0, 0] }]",
            "test.toml:14: key `group.ball.worldline.0.until`: missing: segment 1 needs",
        ),
        (
            "worldline = [{ until = 2, velocity = [0.8, 0, 0] }, { until = 1, velocity = [0.1, 0, 0] }, { velocity = [0, 0, 0] }]",
            "worldline.1.until`: segment 2 ends at 1, not after the segment before it (2)",
        ),
        (
            "velocity = [0.1, 0, 0]\nworldline = [{ velocity = [0.8, 0, 0] }]",
            "give the motion either as a velocity or as a worldline, not both",
        ),
        (
            "worldline = [{ until = 2, acceleration = [0.1, 0, 0] }]",
            "worldline.0.acceleration`: the first segment cannot accelerate",
        ),
        (
            "worldline = [{ until = 2, velocity = [1.2, 0, 0] }, { velocity = [0, 0, 0] }]",
            "worldline.0.velocity",
        ),
        ("worldline = []", "give at least one segment"),
    ];
    let many: Vec<String> = (0..5000)
        .map(|k| format!("{{ until = {k}, velocity = [0.{}, 0, 0] }}", k % 9))
        .collect();
    let many = format!("worldline = [{}]", many.join(", "));
    let cases = cases
        .into_iter()
        .chain([(many.as_str(), "5000 segments: at most 4096")]);
    for (motion, needle) in cases {
        let e = rest_embree::scene::load_str("test.toml", &sphere_scene(motion, 0.0), &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{motion}:\n{e}");
    }
}

/// The travelling twin: out at 0.8c (γ = 5/3) from x = 3 at world time 0, turning at world
/// time 10, back at 0.8c; 12 years of its proper time to 20 of the world's.
fn twin(lamp_pulse_at: f64, width: f64) -> String {
    format!(
        r#"
[camera]
position = [3, 0, 0]
time = 0
direction = [-1, 0, 0]
fov_y = 20
worldline = [{{ until = 10, velocity = [0.8, 0, 0] }}, {{ velocity = [-0.8, 0, 0] }}]
[image]
width = 33
height = 33
[render]
ambient = 0
[film]
start = 0
end = 12
step = 0.5
clock = "proper"
[[light]]
position = [2, 0, 0]
pulse = {{ at = {lamp_pulse_at:?}, width = {width:?} }}
[[group]]
name = "home"
[[group.object]]
type = "sphere"
center = [0, 0, 0]
radius = 1
"#
    )
}

/// A film on the camera's clock steps its proper time: frame k is at τ = k/2, world time
/// t = γτ out and 10 + γ(τ − 6) back, with the camera's velocity there; and each frame is, to
/// the bit, the picture of a uniformly moving camera at that event with that velocity.
#[test]
fn a_film_on_the_travellers_clock_follows_its_worldline() {
    let s = scene(&twin(0.0, 1.0));
    let film = s.film.as_ref().unwrap();
    assert_eq!(film.frame_count(), 25);
    for k in [0u64, 5, 12, 13, 20, 24] {
        let tau = 0.5 * k as f64;
        let t = if tau <= 6.0 {
            tau / 0.6
        } else {
            10.0 + (tau - 6.0) / 0.6
        };
        let x = if t <= 10.0 {
            3.0 + 0.8 * t
        } else {
            11.0 - 0.8 * (t - 10.0)
        };
        let f = s.film_frame(k).unwrap();
        assert!(
            (f.camera.time - t).abs() < 1e-12,
            "frame {k}: t = {}",
            f.camera.time
        );
        assert!(
            (f.camera.position.x - x).abs() < 1e-12,
            "frame {k}: x = {}",
            f.camera.position.x
        );
        let bx = f.camera.velocity.beta_vec().x;
        assert!(
            (bx - if t < 10.0 { 0.8 } else { -0.8 }).abs() < 1e-15,
            "frame {k}: β = {bx}"
        );
        if k == 5 || k == 20 {
            // The same camera written as a uniformly moving one at the frame's event.
            let p = f.camera.position;
            let text = twin(0.0, 1.0)
                .replace(
                    "worldline = [{ until = 10, velocity = [0.8, 0, 0] }, { velocity = [-0.8, 0, 0] }]",
                    &format!("velocity = [{bx:?}, 0, 0]"),
                )
                .replace("position = [3, 0, 0]", &format!("position = [{:?}, {:?}, {:?}]", p.x, p.y, p.z))
                .replace("time = 0\n", &format!("time = {:?}\n", f.camera.time));
            let uniform = scene(&text);
            assert!(uniform.camera.worldline.is_none() && uniform.camera.time == f.camera.time);
            for backend in backends() {
                let a = render_with(&f, backend);
                let b = render_with(&uniform, backend);
                assert_eq!(
                    bytes(&a),
                    bytes(&b),
                    "{backend}: frame {k} as a uniform camera"
                );
            }
        }
    }
}

/// Home's lamp (at x = 2, lighting the point x = 1 of home that the traveller's centre pixel
/// sees) flashes a Gaussian pulse of width w. A flash at world time t_L reaches the traveller
/// going out at world time 5(t_L + 3), proper time 3(t_L + 3); coming back at world time
/// (19 + t_L)/1.8, proper time 6 + 0.6((19 + t_L)/1.8 − 10). Home's clock is seen running at
/// 1/3 going out and 3 times coming back (the Doppler factor √((1 ∓ β)/(1 ± β))), so the pulse
/// is seen 3w wide, then w/3 (docs/physics.md §12.5).
#[test]
fn the_traveller_sees_home_slow_then_fast() {
    let w = 0.2;
    for (t_lamp, tau_peak, seen_width) in [(-2.0, 3.0, 3.0 * w), (5.0, 8.0, w / 3.0)] {
        let s = scene(&twin(t_lamp, w));
        for backend in backends() {
            let at = |tau: f64| {
                let mut f = s.clone();
                f.camera = s.camera.at_time(s.camera.world_time_at(tau));
                render_with(&f, backend).get(16, 16).values()[0] as f64
            };
            let h = 0.5 * seen_width;
            let (a, b, c) = (
                at(tau_peak + 0.1 * h - h).ln(),
                at(tau_peak + 0.1 * h).ln(),
                at(tau_peak + 1.1 * h).ln(),
            );
            let peak = tau_peak + 0.1 * h + 0.5 * h * (a - c) / (a - 2.0 * b + c);
            report(
                &format!("twin: home's flash at {t_lamp} seen at proper time"),
                backend,
                tau_peak,
                peak,
                1e-6,
                "time",
            );
            let half = at(tau_peak + h) / at(tau_peak);
            report(
                &format!("twin: home's flash at {t_lamp}, half maximum at half its seen width"),
                backend,
                0.5,
                half,
                1e-5,
                "of peak",
            );
        }
    }
}

#[test]
fn bad_camera_worldlines_and_clocks_are_refused() {
    let good = twin(0.0, 1.0);
    for (from, to, needle) in [
        (
            "clock = \"proper\"",
            "clock = \"mine\"",
            "test.toml:17: key `film.clock`: unknown clock `mine`",
        ),
        (
            "fov_y = 20",
            "fov_y = 20\nvelocity = [0.1, 0, 0]",
            "give the motion either as a velocity or as a worldline",
        ),
    ] {
        let text = good.replace(from, to);
        let e = rest_embree::scene::load_str("test.toml", &text, &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{to}:\n{e}");
    }
}

#[test]
fn glass_in_a_group_that_changes_velocity_is_refused() {
    let text = sphere_scene(STOPS, 0.0).replace(
        "radius = 1\n",
        "radius = 1\nmaterial = \"glass\"\n[[material]]\nname = \"glass\"\ntransmit = 0.9\n",
    );
    let e = rest_embree::scene::load_str("test.toml", &text, &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("group.ball.worldline`: glass and media in a group whose velocity changes are not built yet"),
        "{e}"
    );
    // One velocity throughout is the uniform group, glass and all.
    let same = "worldline = [{ until = 0, velocity = [0.8, 0, 0] }, { velocity = [0.8, 0, 0] }]";
    scene(&sphere_scene(same, 0.0).replace(
        "radius = 1\n",
        "radius = 1\nmaterial = \"glass\"\n[[material]]\nname = \"glass\"\ntransmit = 0.9\n",
    ));
}

/// A lamp on a worldline is found on it at the emission event on each lit point's past light
/// cone: while every such event lies in its first segment (the lamp moving at 0.6c until world
/// time 1000), it lights the scene as the uniformly moving lamp does.
#[test]
fn a_lamp_on_a_worldline_lights_as_its_segment_does() {
    // A uniformly moving light's `position` is in its rest frame (its origin passing the
    // world's at world time 0); a worldline's is where it is at world time 0: x = x'/γ.
    let lamp = |motion: &str, x: f64| {
        format!(
            r#"
[camera]
position = [0, -10, 0]
look_at = [0, 0, 0]
fov_y = 30
time = 4
[image]
width = 48
height = 32
[[light]]
position = [{x:?}, -4, 3]
intensity = 2
color = {{ blackbody = 5800 }}
{motion}
[[group]]
name = "ball"
[[group.object]]
type = "sphere"
center = [0, 0, 0]
radius = 1.5
[[group.object]]
type = "box"
min = [-8, -3, -2.5]
max = [8, 3, -1.5]
"#
        )
    };
    let uniform = scene(&lamp("velocity = [0.6, 0, 0]", -7.5));
    let line = scene(&lamp(
        "worldline = [{ until = 1000, velocity = [0.6, 0, 0] }, { velocity = [-0.3, 0, 0] }]",
        -6.0,
    ));
    assert!(line.lights[0].worldline.is_some());
    for backend in backends() {
        let (a, b) = (render_with(&uniform, backend), render_with(&line, backend));
        let worst = a
            .pixels
            .iter()
            .zip(&b.pixels)
            .flat_map(|(p, q)| {
                (0..3).map(move |k| (p.color[k] - q.color[k]).abs() / p.color[k].abs().max(1e-3))
            })
            .fold(0.0f32, f32::max);
        assert!(
            worst < 1e-5,
            "{backend}: colours differ by {worst} (relative)"
        );
        assert!(
            b.pixels
                .iter()
                .all(|p| p.color.iter().all(|c| c.is_finite())),
            "{backend}: finite colours"
        );
        let lit = a.pixels.iter().filter(|p| p.color[0] > 0.01).count();
        assert!(lit > 100, "{backend}: {lit} pixels lit");
    }
}
