//! Lights in time and the radar world (docs/physics.md §12.2-§12.3): a flash riding with the
//! camera lights what it sees, and a surface shows the light emitted at the event on the
//! flash's worldline that lies on the surface point's past light cone. The camera at the origin
//! looks along +y; the pixel at the image centre looks exactly along the axis.

use crate::common::*;
use rest_embree::scene::{Scene, Timing};

const SIZE: u32 = 9;
const FOV: f64 = 10.0;

/// A camera at rest at the origin with a flash, looking along +y at a plate whose near face is
/// at rest-frame y = `near` in a group moving at `beta` along y.
fn radar_scene(flash: &str, near: f64, beta: f64) -> Scene {
    scene(&format!(
        r#"
[camera]
position = [0, 0, 0]
direction = [0, 1, 0]
fov_y = {FOV}
flash = {{ intensity = 1, {flash} }}
[image]
width = {SIZE}
height = {SIZE}
[render]
ambient = 0
[[group]]
name = "plate"
velocity = [0, {beta:?}, 0]
[[group.object]]
type = "box"
min = [-100, {near:?}, -100]
max = [100, {:?}, 100]
"#,
        near + 1.0
    ))
}

/// The red channel of pixel (x, y) at view time `t`.
fn seen_at(s: &Scene, backend: &str, t: f64, (x, y): (u32, u32)) -> f64 {
    let mut s = s.clone();
    s.camera.time = t;
    render_with(&s, backend).get(x, y).values()[0] as f64
}

const CENTRE: (u32, u32) = (SIZE / 2, SIZE / 2);

/// A flash on from proper time 0 to w lights a plate at rest at distance d: the pixel looking
/// at angle θ off the axis sees the plate lit exactly from view time 2d/cos θ to 2d/cos θ + w,
/// and dark before and after.
#[test]
fn flash_lights_a_plate_at_rest_exactly_after_the_round_trip() {
    let (d, w) = (5.0, 0.5);
    let s = radar_scene(&format!("on = [[0, {w:?}]]"), d, 0.0);
    // Pixel (0, 4): 4 pixels left of the centre, at focal length f pixels.
    let f = 0.5 * SIZE as f64 / (0.5 * FOV).to_radians().tan();
    let cos_side = f / (f * f + 16.0).sqrt();
    for backend in backends() {
        for (pixel, cos) in [(CENTRE, 1.0), ((0, SIZE / 2), cos_side)] {
            let start = 2.0 * d / cos;
            let eps = 1e-6;
            let at = |t: f64| seen_at(&s, backend, t, pixel);
            assert_eq!(
                at(start - eps),
                0.0,
                "{backend} {pixel:?}: dark before the echo"
            );
            assert!(
                at(start + eps) > 0.0,
                "{backend} {pixel:?}: lit as the echo starts"
            );
            assert!(
                at(start + w - eps) > 0.0,
                "{backend} {pixel:?}: lit as it ends"
            );
            assert_eq!(
                at(start + w + eps),
                0.0,
                "{backend} {pixel:?}: dark after it"
            );
        }
    }
}

/// The view time of the echo's peak from pixel `pixel`, for a Gaussian flash: the log of a
/// Gaussian is a parabola, so three view times about a guess give its vertex exactly (the
/// plate's light is otherwise the same at every view time: no falloff, fixed angles).
fn echo_peak(s: &Scene, backend: &str, guess: f64, h: f64) -> f64 {
    let l = |t: f64| seen_at(s, backend, t, CENTRE).ln();
    let (a, b, c) = (l(guess - h), l(guess), l(guess + h));
    guess + 0.5 * h * (a - c) / (a - 2.0 * b + c)
}

/// A plate approaching at β, d away at world time 0, returns a flash emitted at proper time τ
/// at view time 2d/(1 + β) + τ (1 − β)/(1 + β): the echo is delayed by the light-cone algebra
/// and compressed by (1 − β)/(1 + β), so a Gaussian flash of width w comes back w(1 − β)/(1 + β)
/// wide (half its peak at half that from the peak).
#[test]
fn echo_from_an_approaching_plate_follows_the_light_cone() {
    let (d, w) = (6.0, 0.4);
    for beta in [0.5f64, 0.9] {
        let gamma = 1.0 / (1.0 - beta * beta).sqrt();
        // Rest-frame near face γd: at world time 0 it is d away.
        let s = radar_scene(
            &format!("pulse = {{ at = 0, width = {w:?} }}"),
            gamma * d,
            -beta,
        );
        let peak = 2.0 * d / (1.0 + beta);
        let echo_width = w * (1.0 - beta) / (1.0 + beta);
        for backend in backends() {
            let found = echo_peak(&s, backend, peak + 0.3 * echo_width, 0.5 * echo_width);
            report(
                &format!("radar echo delay, plate approaching at {beta}"),
                backend,
                peak,
                found,
                1e-6,
                "time",
            );
            let top = seen_at(&s, backend, peak, CENTRE);
            for side in [-0.5, 0.5] {
                let half = seen_at(&s, backend, peak + side * echo_width, CENTRE) / top;
                report(
                    &format!("radar echo at half width, β = {beta}"),
                    backend,
                    0.5,
                    half,
                    1e-5,
                    "of peak",
                );
            }
        }
    }
}

/// Sherwin's radar length: a rod of rest length L recedes at β along the line of sight; the
/// radar assigns to an echo emitted at τ and returned at t the distance (t − τ)/2 at time
/// (t + τ)/2. One flash's echoes from its two ends are (L/γ)/(1 − β) apart in distance (the
/// echo length); two flashes give each end's distance as a function of radar time, and at equal
/// radar time the ends are L/γ apart: the radar sees the Lorentz contraction. Each end is a
/// plate of its own render (on the axis the near end would hide the far one).
#[test]
fn radar_length_of_a_receding_rod_is_contracted() {
    let (d, len, beta) = (4.0, 3.0, 0.6f64);
    let gamma = 1.0 / (1.0 - beta * beta).sqrt();
    let w = 0.3;
    for backend in backends() {
        // Each end's (radar time, radar distance) for flashes at proper times 0 and 5.
        let radar = |end_rest: f64| -> Vec<(f64, f64)> {
            [0.0, 5.0]
                .iter()
                .map(|&tau| {
                    let flash = format!("pulse = {{ at = {tau:?}, width = {w:?} }}");
                    let s = radar_scene(&flash, end_rest, beta);
                    // The end is end_rest/γ away at world time 0.
                    let guess =
                        2.0 * end_rest / gamma / (1.0 - beta) + tau * (1.0 + beta) / (1.0 - beta);
                    let echo = w * (1.0 + beta) / (1.0 - beta);
                    let t = echo_peak(&s, backend, guess + 0.2 * echo, 0.5 * echo);
                    (0.5 * (t + tau), 0.5 * (t - tau))
                })
                .collect()
        };
        let near = radar(gamma * d);
        let far = radar(gamma * d + len);
        let echo_length = far[0].1 - near[0].1;
        report(
            "radar echo length of a rod receding at 0.6",
            backend,
            len / gamma / (1.0 - beta),
            echo_length,
            1e-4,
            "length",
        );
        // Each end's radar distance is linear in radar time; the far end's at the near end's
        // first radar time.
        let slope = (far[1].1 - far[0].1) / (far[1].0 - far[0].0);
        let far_then = far[0].1 + slope * (near[0].0 - far[0].0);
        report(
            "radar length of a rod receding at 0.6 (L/γ)",
            backend,
            len / gamma,
            far_then - near[0].1,
            1e-4,
            "length",
        );
        report("radar speed of the rod", backend, beta, slope, 1e-5, "c");
    }
}

#[test]
fn flash_rides_with_a_moving_camera_and_timings_are_checked() {
    // The flash rests where the camera's worldline is, in the camera's frame.
    let mut text = String::from(
        "[camera]\nposition = [1, 2, 3]\ntime = 4\ndirection = [0, 1, 0]\nvelocity = [0.6, 0, 0]\nflash = { pulse = { at = 2, width = 1 } }\n[[group]]\nname = \"g\"\n[[group.object]]\ntype = \"sphere\"\nradius = 1\ncenter = [0, 9, 0]\n",
    );
    let s = scene(&text);
    let flash = s.lights.last().expect("the flash is a light");
    assert_eq!(flash.velocity, s.camera.velocity);
    // The flash's times are on the camera's clock, which reads 4 at the imaging event, where
    // the camera frame's clock reads γ(t − βx) = 1.25 (4 − 0.6) = 4.25.
    let Timing::Pulse { at, width } = flash.timing else {
        panic!("a pulse: {:?}", flash.timing)
    };
    assert!((at - 2.25).abs() < 1e-12 && width == 1.0, "{at} {width}");
    // Camera frame: x' = γ(x − βt) = 1.25 (1 − 2.4) = −1.75.
    assert!((flash.position - glam::DVec3::new(-1.75, 2.0, 3.0)).length() < 1e-12);
    let mut bad = |from: &str, to: &str, needle: &str| {
        text = text.replace(from, to);
        let e = rest_embree::scene::load_str("r.toml", &text, &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{e}");
        text = text.replace(to, from);
    };
    bad(
        "width = 1 }",
        "width = 0 }",
        "r.toml:6: key `camera.flash.pulse.width`: must be greater than 0",
    );
    bad(
        "pulse = { at = 2, width = 1 }",
        "on = [[1, 0]]",
        "camera.flash.on`: interval 1 is [1, 0]",
    );
    bad(
        "pulse = { at = 2, width = 1 }",
        "table = [[1, 0], [1, 2]]",
        "row 2 must come after row 1",
    );
    bad(
        "pulse = { at = 2, width = 1 }",
        "table = [[1, -1]]",
        "factors are 0 or more",
    );
    bad(
        "pulse = { at = 2, width = 1 }",
        "on = [[0, 1]], table = [[0, 1]]",
        "give one of pulse, on and table",
    );
    bad(
        "pulse = { at = 2, width = 1 }",
        "pulse = { at = 2, width = 1, shape = 3 }",
        "camera.flash.pulse.shape",
    );
}

/// A flash on a camera whose worldline changes velocity rides along that worldline, found on
/// it event by event: with the camera at rest through the round trip (its velocity changes
/// only at world time 1000), the echo is exactly the one a camera at rest receives.
#[test]
fn a_flash_on_a_changing_worldline_rides_along_it() {
    let (d, w) = (5.0, 0.5);
    // Both in spectra (a light on a changing worldline is seen through them).
    let still = radar_scene(
        &format!("on = [[0, {w:?}]], color = {{ blackbody = 5800 }}"),
        d,
        0.0,
    );
    let text = |camera_motion: &str| {
        format!(
            r#"
[camera]
position = [0, 0, 0]
direction = [0, 1, 0]
fov_y = {FOV}
{camera_motion}
flash = {{ intensity = 1, on = [[0, {w:?}]], color = {{ blackbody = 5800 }} }}
[image]
width = {SIZE}
height = {SIZE}
[render]
ambient = 0
[[group]]
name = "plate"
[[group.object]]
type = "box"
min = [-100, {d:?}, -100]
max = [100, {:?}, 100]
"#,
            d + 1.0
        )
    };
    let moving = scene(&text(
        "worldline = [{ until = 1000, velocity = [0, 0, 0] }, { velocity = [0.5, 0, 0] }]",
    ));
    assert!(
        moving.lights[0].worldline.is_some(),
        "the flash has the camera's worldline"
    );
    for backend in backends() {
        for t in [
            2.0 * d - 1e-6,
            2.0 * d + 1e-6,
            2.0 * d + 0.3,
            2.0 * d + w + 1e-6,
        ] {
            let (a, b) = (
                seen_at(&still, backend, t, CENTRE),
                seen_at(&moving, backend, t, CENTRE),
            );
            assert!(
                (a - b).abs() <= 1e-6 * a.max(1e-30),
                "{backend} at {t}: {a} against {b}"
            );
            assert_eq!(a > 0.0, b > 0.0, "{backend} at {t}");
        }
    }
}
