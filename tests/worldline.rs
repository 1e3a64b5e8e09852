//! Worldlines of uniform segments (docs/physics.md §12.4): a group whose velocity changes at
//! given world times is a group per segment, each seen only at emission events within its
//! segment's times, and the merge by emission time picks among them.

mod common;
use common::*;
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
            1e-4,
            "length",
        );
    }
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
            "worldline.0.acceleration`: segments of constant proper acceleration are not built yet",
        ),
        (
            "worldline = [{ until = 2, velocity = [1.2, 0, 0] }, { velocity = [0, 0, 0] }]",
            "worldline.0.velocity",
        ),
        ("worldline = []", "give at least one segment"),
    ];
    for (motion, needle) in cases {
        let e = rest_embree::scene::load_str("test.toml", &sphere_scene(motion, 0.0), &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{motion}:\n{e}");
    }
}
