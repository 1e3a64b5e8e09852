//! The shutter (`[camera] shutter`): an exposure of s in the camera's proper time, centred on
//! the imaging event. Each sample sees from its own event on the camera's worldline, so the
//! picture is the mean over the exposure of the instant pictures (docs/physics.md §12.1).

use crate::common::*;
use rest_embree::render::Frame;

/// A thin box moving along x across an orthographic camera at rest looking along +y: its
/// image at view time t covers x from a/γ + β(t − y0 − d) (the trailing face) to b/γ + β(t − y0)
/// (the near face's leading edge), so over an exposure [t0 − s/2, t0 + s/2] each pixel's
/// alpha is the share of pixel and exposure that this interval covers.
#[test]
fn orthographic_box_blurs_into_the_exact_ramp() {
    let (w, h, ppu) = (241u32, 3u32, 10.0);
    let (beta, shutter, t0) = (0.6f64, 1.0f64, 0.0f64);
    let (a, b, y0, d) = (-2.0f64, 2.0f64, 10.0f64, 0.2f64);
    let gamma = 1.0 / (1.0 - beta * beta).sqrt();
    let text = format!(
        r#"
[camera]
position = [0, 0, 0]
direction = [0, 1, 0]
projection = "orthographic"
view_height = {}
time = {t0:?}
shutter = {shutter:?}
[image]
width = {w}
height = {h}
samples = 256
[[group]]
name = "box"
velocity = [{beta:?}, 0, 0]
[[group.object]]
type = "box"
min = [{a:?}, {y0:?}, -5]
max = [{b:?}, {:?}, 5]
"#,
        h as f64 / ppu,
        y0 + d
    );
    // The covered interval at world time t, and a pixel's covered share over the exposure.
    let covered = |t: f64| (a / gamma + beta * (t - y0 - d), b / gamma + beta * (t - y0));
    let expected = |px: u32| {
        let x0 = (px as f64 - 0.5 * w as f64) / ppu;
        let x1 = x0 + 1.0 / ppu;
        let steps = 4000;
        (0..steps)
            .map(|i| {
                let t = t0 - 0.5 * shutter + shutter * (i as f64 + 0.5) / steps as f64;
                let (lo, hi) = covered(t);
                (hi.min(x1) - lo.max(x0)).max(0.0) * ppu
            })
            .sum::<f64>()
            / steps as f64
    };
    for backend in backends() {
        let f = render_with(&scene(&text), backend);
        let alpha = f.channel("A").unwrap();
        let mut ramp = 0;
        let mut worst = 0.0f64;
        for px in 0..w {
            let e = expected(px);
            if e > 0.01 && e < 0.99 {
                ramp += 1;
            }
            worst = worst.max((alpha[(w + px) as usize] as f64 - e).abs());
        }
        // β s = 0.6 world units of blur at each end: 6 px of ramp each.
        assert!(
            ramp >= 10,
            "{backend}: the exposure blurs both ends ({ramp} px of ramp)"
        );
        report(
            "shutter ramp, worst pixel",
            backend,
            0.0,
            worst,
            0.02,
            "alpha",
        );
        assert!(
            worst < 0.02,
            "{backend}: alpha off the exact ramp by {worst}"
        );
    }
}

const MOVING: &str = r#"
[camera]
position = [0, -6, 0]
look_at = [0, 0, 0]
fov_y = 50
velocity = [0, 0.7, 0]
time = 0
shutter = 4
[image]
width = 64
height = 40
samples = 32
background = [0.05, 0.05, 0.1]
transparent = false
[render]
ambient = 0.2
[[light]]
position = [0, -8, 6]
intensity = 1
[[group]]
name = "ball"
velocity = [-0.8, 0, 0]
[[group.object]]
type = "sphere"
center = [-8, 0, 0]
radius = 1.2
material = "red"
[[material]]
name = "red"
color = [0.9, 0.2, 0.1]
"#;

/// Σ|a − b| over Σ|b|, over every pixel's R, G, B and A.
fn relative_difference(a: &Frame, b: &[[f64; 4]]) -> f64 {
    let size: f64 = b.iter().flatten().map(|v| v.abs()).sum();
    let sum: f64 = a
        .pixels
        .iter()
        .zip(b)
        .map(|(p, q)| {
            let v = p.values();
            (0..4).map(|k| (v[k] as f64 - q[k]).abs()).sum::<f64>() / 4.0
        })
        .sum();
    4.0 * sum / size
}

/// The mean of narrow exposures over the interval equals one wide exposure: a camera moving
/// at 0.7c (γ = 1.4) toward where it looks watches a sphere cross its view at 0.8c. Narrow
/// render i is the camera at proper time τᵢ (the midpoints of 32 equal parts of the exposure)
/// on its worldline, world time γτᵢ from the imaging event.
#[test]
fn wide_exposure_is_the_mean_of_narrow_ones() {
    let wide_scene = scene(MOVING);
    let n = 32;
    let cam = wide_scene.camera.clone();
    let gamma = cam.velocity.gamma();
    let with = |samples: u32, shutter: f64, time: f64| {
        let mut s = wide_scene.clone();
        s.image.samples = samples;
        s.camera = cam.at_time(time);
        s.camera.shutter = shutter;
        s
    };
    for backend in backends() {
        let mut mean = vec![[0.0f64; 4]; 64 * 40];
        for i in 0..n {
            let tau = cam.shutter * ((i as f64 + 0.5) / n as f64 - 0.5);
            let f = render_with(&with(32, 0.0, cam.time + gamma * tau), backend);
            for (m, p) in mean.iter_mut().zip(&f.pixels) {
                for (mk, v) in m.iter_mut().zip(p.values()) {
                    *mk += v as f64 / n as f64;
                }
            }
        }
        let against = |shutter: f64| {
            relative_difference(&render_with(&with(256, shutter, cam.time), backend), &mean)
        };
        let wide = against(cam.shutter);
        // The exposure taken as world time instead of proper time is γ = 1.4 times too short.
        let wrong = against(cam.shutter / gamma);
        let instant = against(0.0);
        report(
            "shutter: wide against the mean of narrow",
            backend,
            0.0,
            wide,
            0.0025,
            "relative",
        );
        assert!(
            wrong > 3.0 * wide && instant > 5.0 * wide,
            "{backend}: the test tells exposures apart ({wide}; world time {wrong}, instant {instant})"
        );
    }
}

/// The same on an accelerated worldline: the camera at rest until world time −3, then
/// accelerating at 0.3 toward where it looks until world time 8, so the exposure of 4 proper
/// time about the imaging event at world time 0 is all acceleration (β from 0.2 to 0.89).
/// Narrow render i is the camera at its clock's τᵢ on the worldline, with its velocity there.
/// The picture changes more over this exposure than over the uniform one, so the pixels'
/// sampling noise (the narrow renders share their sub-pixel positions) leaves more in Σ|Δ|;
/// the signed difference, the bias, is checked tightly.
#[test]
fn wide_exposure_on_an_accelerating_camera_is_the_mean_of_narrow_ones() {
    let text = MOVING.replace(
        "velocity = [0, 0.7, 0]",
        "worldline = [{ until = -3, velocity = [0, 0, 0] }, { until = 8, acceleration = [0, 0.3, 0] }]",
    );
    let wide_scene = scene(&text);
    let n = 32;
    let cam = wide_scene.camera.clone();
    let with = |samples: u32, shutter: f64, time: f64| {
        let mut s = wide_scene.clone();
        s.image.samples = samples;
        s.camera = cam.at_time(time);
        s.camera.shutter = shutter;
        s
    };
    for backend in backends() {
        let mut mean = vec![[0.0f64; 4]; 64 * 40];
        for i in 0..n {
            let tau = cam.shutter * ((i as f64 + 0.5) / n as f64 - 0.5);
            let f = render_with(&with(32, 0.0, cam.world_time_at(cam.time + tau)), backend);
            for (m, p) in mean.iter_mut().zip(&f.pixels) {
                for (mk, v) in m.iter_mut().zip(p.values()) {
                    *mk += v as f64 / n as f64;
                }
            }
        }
        let wide = render_with(&with(256, cam.shutter, cam.time), backend);
        let unsigned = relative_difference(&wide, &mean);
        let instant = relative_difference(&render_with(&with(256, 0.0, cam.time), backend), &mean);
        let bias = (0..3)
            .map(|k| {
                let (mut d, mut size) = (0.0, 0.0);
                for (p, q) in wide.pixels.iter().zip(&mean) {
                    d += p.values()[k] as f64 - q[k];
                    size += q[k].abs();
                }
                (d / size).abs()
            })
            .fold(0.0, f64::max);
        report(
            "shutter on an accelerating camera: wide against the mean of narrow",
            backend,
            0.0,
            unsigned,
            0.005,
            "relative",
        );
        report(
            "shutter on an accelerating camera: bias of wide against the mean of narrow",
            backend,
            0.0,
            bias,
            5e-4,
            "relative",
        );
        assert!(
            instant > 5.0 * unsigned,
            "{backend}: the test tells exposures apart ({unsigned}; instant {instant})"
        );
    }
}

#[test]
fn shutter_zero_is_an_instant_and_negative_is_refused() {
    let open = scene(MOVING);
    let mut closed = open.clone();
    closed.camera.shutter = 0.0;
    let zero = scene(&MOVING.replace("shutter = 4", "shutter = 0"));
    let without = scene(&MOVING.replace("shutter = 4\n", ""));
    assert_eq!(zero.camera, closed.camera);
    assert_eq!(without.camera, closed.camera);
    let a = render_with(&zero, "bvh");
    let b = render_with(&without, "bvh");
    assert_eq!(a.pixels, b.pixels, "shutter = 0 is today's picture");
    let err = rest_embree::scene::load_str(
        "bad.toml",
        &MOVING.replace("shutter = 4", "shutter = -1"),
        &[],
    )
    .unwrap_err()
    .to_string();
    eprintln!("{err}");
    assert!(
        err.contains("bad.toml") && err.contains("bad.toml:8:") && err.contains("camera.shutter"),
        "{err}"
    );
}

/// The passes come from the imaging event whatever the samples' times, with one sample too.
#[test]
fn passes_are_taken_at_the_imaging_event() {
    let mut open = scene(MOVING);
    open.image.samples = 1;
    let mut instant = open.clone();
    instant.camera.shutter = 0.0;
    for backend in backends() {
        let a = render_with(&open, backend);
        let b = render_with(&instant, backend);
        for pass in ["lookback.V", "P.X", "object_id"] {
            assert_eq!(a.channel(pass), b.channel(pass), "{backend}: {pass}");
        }
        assert_ne!(
            a.channel("R"),
            b.channel("R"),
            "{backend}: the colour is exposed"
        );
    }
}
