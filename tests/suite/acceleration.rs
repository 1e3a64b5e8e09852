//! Segments of constant proper acceleration (docs/physics.md §12.7): a Born-rigid body in
//! hyperbolic motion, intersected in closed form along each past light-cone ray. Checked
//! against an independent search along the ray in Rindler coordinates, against the uniform
//! picture as the acceleration goes to zero, and for the Doppler factor of each point.

use crate::common::*;
use glam::DVec3;

const W: u32 = 600;
const H: u32 = 41;
const F: f64 = 500.0;

/// A unit sphere at the group's origin, at rest until world time 0, then accelerating along
/// +x at `a` until world time `until`; the camera at rest at (0, −10, 0) at view time `time`,
/// looking along +y.
fn accelerating(a: f64, until: f64, time: f64, samples: u32) -> String {
    format!(
        r#"
[camera]
position = [0, -10, 0]
direction = [0, 1, 0]
fov_y = {fov}
time = {time:?}
[image]
width = {W}
height = {H}
samples = {samples}
passes = ["all"]
[[light]]
position = [0, -10, 0]
[[group]]
name = "ball"
worldline = [{{ until = 0, velocity = [0, 0, 0] }}, {{ until = {until:?}, acceleration = [{a:?}, 0, 0] }}]
[[group.object]]
type = "sphere"
center = [0, 0, 0]
radius = 1
"#,
        fov = fov_for_focal(F, H),
    )
}

/// The independent answer: walk along the centre-row ray through pixel x (centre u = x − W/2)
/// in small steps, and at each event ask where the body's point there would be: in Rindler
/// coordinates about the horizon 1/a behind the start, ρ = √(X² − T²) and θ = artanh(T/X), the
/// point at shape coordinate (ρ − 1/a, y, z), seen only for θ in [0, θ_end]. The first
/// lookback at which that point lies in the unit sphere, refined by bisection; None if none.
fn first_inside(a: f64, until: f64, time: f64, u: f64) -> Option<f64> {
    let theta_end = (a * until).asinh();
    let d = DVec3::new(u, F, 0.0).normalize();
    let inside = |lambda: f64| {
        let t = time - lambda;
        let p = DVec3::new(0.0, -10.0, 0.0) + lambda * d;
        let x = 1.0 / a + p.x;
        if x <= t.abs() {
            return false;
        }
        let theta = (t / x).atanh();
        if !(0.0..=theta_end).contains(&theta) {
            return false;
        }
        let rho = (x * x - t * t).sqrt();
        DVec3::new(rho - 1.0 / a, p.y, p.z).length() < 1.0
    };
    first_entry(inside, 0.0, 40.0, 1e-3)
}

/// Where the centre row's outline lies, to a small fraction of a pixel: the pixel coordinate
/// at which the independent search stops finding the body, by bisection between `inside` and
/// `outside` pixel coordinates.
fn edge(a: f64, until: f64, time: f64, inside: f64, outside: f64) -> f64 {
    let (mut i, mut o) = (inside, outside);
    for _ in 0..30 {
        let mid = 0.5 * (i + o);
        if first_inside(a, until, time, mid - W as f64 / 2.0).is_some() {
            i = mid;
        } else {
            o = mid;
        }
    }
    0.5 * (i + o)
}

/// A stationary camera watching the sphere accelerate from rest: every pixel of the centre row
/// sees it exactly where the independent search does, at the same lookback, and the outline
/// lies where the search puts it to 0.5 px; each point's Doppler factor is its velocity's,
/// D = 1/(γ(1 + β·â)), β = tanh θ along x at the point's Rindler time θ.
#[test]
fn an_accelerating_sphere_is_where_the_search_along_the_ray_finds_it() {
    let (a, until, time) = (0.25, 8.0, 14.0);
    let row = (H / 2) as usize * W as usize;
    for backend in backends() {
        let f = render_with(&scene(&accelerating(a, until, time, 1)), backend);
        let (alpha, lookback, doppler) = (
            f.channel("A").unwrap(),
            f.channel("lookback.V").unwrap(),
            f.channel("doppler.V").unwrap(),
        );
        let (mut covered, mut worst_lookback, mut worst_d) = (0, 0.0f64, 0.0f64);
        for x in 0..W as usize {
            let u = x as f64 + 0.5 - W as f64 / 2.0;
            let truth = first_inside(a, until, time, u);
            let i = row + x;
            assert_eq!(alpha[i] > 0.0, truth.is_some(), "{backend}: pixel {x}");
            let Some(lambda) = truth else { continue };
            covered += 1;
            worst_lookback = worst_lookback.max((lookback[i] as f64 / lambda - 1.0).abs());
            // The point's velocity at its emission event, and D there.
            let dir = DVec3::new(u, F, 0.0).normalize();
            let (t, x_w) = (time - lambda, lambda * dir.x);
            let beta = t / (1.0 / a + x_w);
            let gamma = 1.0 / (1.0 - beta * beta).sqrt();
            let d = 1.0 / (gamma * (1.0 + beta * dir.x));
            worst_d = worst_d.max((doppler[i] as f64 / d - 1.0).abs());
        }
        assert!(
            covered > 20,
            "{backend}: the sphere is seen ({covered} pixels)"
        );
        report(
            "accelerating sphere: lookback against a search along the ray",
            backend,
            0.0,
            worst_lookback,
            1e-6,
            "relative",
        );
        report(
            "accelerating sphere: each point's Doppler factor",
            backend,
            0.0,
            worst_d,
            1e-5,
            "relative",
        );
    }
    // The outline at 64 samples a pixel against the bisected edges of the search.
    let f = render_with(&scene(&accelerating(a, until, time, 64)), "bvh");
    let alpha = f.channel("A").unwrap();
    let (start, end) = alpha_extent(&alpha[row..row + W as usize]).expect("seen");
    let (mid_in, left_out, right_out) = (0.5 * (start + end), start - 3.0, end + 3.0);
    let (true_start, true_end) = (
        edge(a, until, time, mid_in, left_out),
        edge(a, until, time, mid_in, right_out),
    );
    report(
        "accelerating sphere: left outline",
        "bvh",
        true_start,
        start,
        0.5,
        "px",
    );
    report(
        "accelerating sphere: right outline",
        "bvh",
        true_end,
        end,
        0.5,
        "px",
    );
}

/// Where the light cone of the view cuts the segment's end, the coasting piece after it takes
/// over on the hyperplane of simultaneity of the frame moving with the body there. The
/// independent model, piece by piece: at rest before world time 0; Rindler coordinates between;
/// after, at rest in the frame S_end moving at rapidity θ_end, whose time T cosh θ_end − X sinh
/// θ_end (about the horizon) is then positive and in which the body keeps its shape at
/// X_e = 1/a + ξ.
#[test]
fn the_coast_after_the_acceleration_takes_over_on_the_moving_frames_simultaneity() {
    let (a, until, time) = (0.25f64, 4.5f64, 14.0f64);
    let theta_end = (a * until).asinh();
    let (ce, se) = (theta_end.cosh(), theta_end.sinh());
    // The shape point at lookback λ along the ray through pixel centre u, and its piece.
    let point = |u: f64, lambda: f64| -> (DVec3, u8) {
        let d = DVec3::new(u, F, 0.0).normalize();
        let t = time - lambda;
        let p = DVec3::new(0.0, -10.0, 0.0) + lambda * d;
        if t < 0.0 {
            return (p, 0);
        }
        let x = 1.0 / a + p.x;
        let t_end = t * ce - x * se;
        if t_end >= 0.0 {
            let x_end = x * ce - t * se;
            return (DVec3::new(x_end - 1.0 / a, p.y, p.z), 2);
        }
        let rho = (x * x - t * t).sqrt();
        (DVec3::new(rho - 1.0 / a, p.y, p.z), 1)
    };
    let first = |u: f64| -> Option<(f64, u8)> {
        let inside = |l: f64| point(u, l).0.length() < 1.0;
        first_entry(inside, 0.0, 40.0, 1e-3).map(|l| (l, point(u, l).1))
    };
    let row = (H / 2) as usize * W as usize;
    for backend in backends() {
        let f = render_with(&scene(&accelerating(a, until, time, 1)), backend);
        let (alpha, lookback) = (f.channel("A").unwrap(), f.channel("lookback.V").unwrap());
        let (mut pieces, mut worst) = ([0; 3], 0.0f64);
        for x in 0..W as usize {
            let u = x as f64 + 0.5 - W as f64 / 2.0;
            let truth = first(u);
            let i = row + x;
            assert_eq!(alpha[i] > 0.0, truth.is_some(), "{backend}: pixel {x}");
            if let Some((lambda, piece)) = truth {
                pieces[piece as usize] += 1;
                worst = worst.max((lookback[i] as f64 / lambda - 1.0).abs());
            }
        }
        assert!(
            pieces[1] > 5 && pieces[2] > 5,
            "{backend}: both pieces seen: {pieces:?}"
        );
        report(
            "accelerating sphere across its segment's end: lookback",
            backend,
            0.0,
            worst,
            1e-6,
            "relative",
        );
    }
}

/// A rod across the acceleration (its surface meets each ray's path through shape space in a
/// quartic, so it is marched): every pixel of the centre row is covered where the independent
/// march finds it, at its lookback.
#[test]
fn an_accelerating_rod_is_where_the_search_along_the_ray_finds_it() {
    let (a, until, time) = (0.25f64, 8.0f64, 14.0f64);
    let text = accelerating(a, until, time, 1).replace(
        "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1",
        "type = \"rod\"\nfrom = [0, -0.8, -1]\nto = [0.3, 0.8, 1]\nradius = 0.4",
    );
    let (p0, p1, r) = (DVec3::new(0.0, -0.8, -1.0), DVec3::new(0.3, 0.8, 1.0), 0.4);
    let theta_end = (a * until).asinh();
    let first = |u: f64| -> Option<f64> {
        let d = DVec3::new(u, F, 0.0).normalize();
        let inside = |lambda: f64| {
            let t = time - lambda;
            let p = DVec3::new(0.0, -10.0, 0.0) + lambda * d;
            let x = 1.0 / a + p.x;
            if x <= t.abs() {
                return false;
            }
            let theta = (t / x).atanh();
            if !(0.0..=theta_end).contains(&theta) {
                return false;
            }
            let q = DVec3::new((x * x - t * t).sqrt() - 1.0 / a, p.y, p.z);
            let ab = p1 - p0;
            let h = ((q - p0).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
            (q - (p0 + h * ab)).length() < r
        };
        first_entry(inside, 0.0, 40.0, 1e-3)
    };
    let row = (H / 2) as usize * W as usize;
    for backend in backends() {
        let f = render_with(&scene(&text), backend);
        let (alpha, lookback) = (f.channel("A").unwrap(), f.channel("lookback.V").unwrap());
        let (mut covered, mut worst) = (0, 0.0f64);
        for x in 0..W as usize {
            let u = x as f64 + 0.5 - W as f64 / 2.0;
            let truth = first(u);
            let i = row + x;
            assert_eq!(alpha[i] > 0.0, truth.is_some(), "{backend}: pixel {x}");
            if let Some(lambda) = truth {
                covered += 1;
                worst = worst.max((lookback[i] as f64 / lambda - 1.0).abs());
            }
        }
        assert!(
            covered > 10,
            "{backend}: the rod is seen ({covered} pixels)"
        );
        report(
            "accelerating rod: lookback against a search along the ray",
            backend,
            0.0,
            worst,
            1e-6,
            "relative",
        );
    }
}

/// As the acceleration goes to zero, the accelerated segment's picture becomes the uniform one:
/// the same pixels covered and lookbacks that differ by O(a).
#[test]
fn tiny_accelerations_give_the_uniform_picture() {
    let uniform = |time: f64| {
        format!(
            r#"
[camera]
position = [0, -10, 0]
direction = [0, 1, 0]
fov_y = {fov}
time = {time:?}
[image]
width = {W}
height = {H}
passes = ["all"]
[[light]]
position = [0, -10, 0]
[[group]]
name = "ball"
velocity = [0, 0, 0]
[[group.object]]
type = "sphere"
center = [0, 0, 0]
radius = 1
"#,
            fov = fov_for_focal(F, H),
        )
    };
    for backend in backends() {
        let still = render_with(&scene(&uniform(14.0)), backend);
        for a in [1e-6, 1e-9] {
            let f = render_with(&scene(&accelerating(a, 20.0, 14.0, 1)), backend);
            let (l0, l1) = (
                still.channel("lookback.V").unwrap(),
                f.channel("lookback.V").unwrap(),
            );
            let differ = still
                .channel("A")
                .unwrap()
                .iter()
                .zip(f.channel("A").unwrap())
                .filter(|(p, q)| **p != *q)
                .count();
            assert!(
                differ <= 2,
                "{backend} a {a}: {differ} pixels differ in coverage"
            );
            let worst = l0
                .iter()
                .zip(&l1)
                .filter(|(p, q)| **p > 0.0 && **q > 0.0)
                .map(|(p, q)| (p - q).abs() as f64)
                .fold(0.0, f64::max);
            report(
                "tiny acceleration against the uniform picture: lookback",
                backend,
                0.0,
                worst,
                1e4 * a + 1e-5,
                "time",
            );
            same_picture(&still, &f, "tiny acceleration", 2.0 / (W * H) as f64, 1e-3);
        }
    }
}

/// A camera accelerating sees, at each imaging event, what a uniformly moving camera with its
/// velocity there sees.
#[test]
fn an_accelerating_camera_sees_with_its_velocity_at_the_imaging_event() {
    let world = |camera: &str| {
        format!(
            r#"
[camera]
look_at = [0, 0, 0]
fov_y = 40
time = 6
{camera}
[image]
width = 96
height = 64
[[light]]
position = [-5, -10, 8]
[[group]]
name = "lattice"
[[group.object]]
type = "lattice"
origin = [-3, -3, -3]
counts = [4, 4, 4]
spacing = 2.0
sphere_radius = 0.15
rod_radius = 0.03
"#
        )
    };
    let accelerating = world(
        "position = [0, -12, 0]\nworldline = [{ until = 0, velocity = [0, 0, 0] }, { until = 30, acceleration = [0.2, 0, 0] }]",
    );
    let s = scene(&accelerating);
    let line = s.camera.worldline.as_ref().expect("a worldline");
    // The anchor is the imaging event: at time 6 the camera is at (0, −12, 0).
    let (p, v) = (line.position(6.0), line.velocity(6.0).beta_vec());
    assert!((p - DVec3::new(0.0, -12.0, 0.0)).length() < 1e-12);
    assert!((v.x - (0.2f64 * 6.0).asinh().tanh()).abs() < 1e-12, "{v}");
    let uniform = world(&format!(
        "position = [{:?}, {:?}, {:?}]\nvelocity = [{:?}, {:?}, {:?}]",
        p.x, p.y, p.z, v.x, v.y, v.z
    ));
    for backend in backends() {
        let a = render_with(&s, backend);
        let b = render_with(&scene(&uniform), backend);
        same_picture(&a, &b, "accelerating camera", 0.0, 1e-4);
    }
}

#[test]
fn bad_accelerations_name_the_key() {
    let base = |motion: &str, object: &str| {
        format!(
            "[camera]\nposition = [0, -10, 0]\nlook_at = [0, 0, 0]\n[[group]]\nname = \"ball\"\n{motion}\n[[group.object]]\n{object}\n"
        )
    };
    let sphere = "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1";
    let cases = [
        (
            base("worldline = [{ until = 0, velocity = [0, 0, 0] }, { acceleration = [0.1, 0, 0] }]", sphere),
            "test.toml:6: key `group.ball.worldline.1.acceleration`: segment 2 accelerates for ever",
        ),
        (
            base("worldline = [{ until = 0, velocity = [0, 0, 0] }, { until = 3, acceleration = [0, 0, 0] }]", sphere),
            "worldline.1.acceleration`: give a proper acceleration that is not zero",
        ),
        (
            base("worldline = [{ until = 0, velocity = [0, 0, 0] }, { until = 3, acceleration = [0.1, 0, 0], velocity = [0.2, 0, 0] }]", sphere),
            "worldline.1.velocity`: an accelerated segment starts with the velocity the one before it ended with",
        ),
        (
            base("worldline = [{ until = 0, velocity = [0, 0, 0] }, { until = 3, acceleration = [2, 0, 0] }]", sphere),
            "key `group.ball.worldline`: at acceleration 2 the horizon lies 5e-1 behind the group's origin, and the group reaches 1e0 behind it",
        ),
        (
            base("worldline = [{ until = 0, velocity = [0, 0, 0] }, { until = 3, acceleration = [0.1, 0, 0] }]", "type = \"lattice\"\norigin = [0, 0, 0]\ncounts = [20, 20, 20]\nspacing = 1.0\nsphere_radius = 0.1\nrod_radius = 0.02"),
            "primitives: a group with an accelerated segment is intersected primitive by primitive, at most 4096",
        ),
        (
            format!("[render]\nintegrator = \"path\"\n{}", base("worldline = [{ until = 0, velocity = [0, 0, 0] }, { until = 3, acceleration = [0.1, 0, 0] }]", sphere)),
            "groups on accelerated segments are not built yet for integrator = \"path\"",
        ),
        // An acceleration that ends past the speeds the renderer keeps exact (rapidity
        // 0.4 × 1e13 by its end) was taken, its beta 1 in the header; so was a last uniform
        // segment's `until`, which the motion ignores (both from the fifth trial).
        (
            base("worldline = [{ until = 5, velocity = [0.5, 0, 0] }, { until = 1e13, acceleration = [0.4, 0, 0] }]", sphere),
            "worldline.1.acceleration`: segment 2 reaches rapidity",
        ),
        (
            base("worldline = [{ until = 0, velocity = [0, 0, 0] }, { until = 1e9, acceleration = [0.4, 0, 0] }]", sphere),
            "by its end (world time 1000000000), beyond the speeds rest-embree renders correctly: rapidity up to 20.0",
        ),
        (
            base("worldline = [{ until = 0, velocity = [0, 0, 0] }, { until = 1e9, acceleration = [0.4, 0, 0] }, { velocity = [0, 0, 0] }]", sphere),
            "worldline.1.acceleration`: segment 2 reaches rapidity",
        ),
        (
            base("worldline = [{ until = 5, velocity = [0.5, 0, 0] }, { until = 9, velocity = [0, 0, 0] }]", sphere),
            "test.toml:6: key `group.ball.worldline.1.until`: the last segment lasts for ever, so it has no end at 9",
        ),
        (
            base("velocity = [0, 0, 0]", sphere).replace(
                "look_at = [0, 0, 0]",
                "look_at = [0, 0, 0]\nworldline = [{ until = 0, velocity = [0, 0, 0] }, { until = 1e13, acceleration = [0.4, 0, 0] }]",
            ),
            "camera.worldline.1.acceleration`: segment 2 reaches rapidity",
        ),
    ];
    for (text, needle) in cases {
        let e = rest_embree::scene::load_str("test.toml", &text, &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{text}\n{e}");
    }
}

/// Moving the whole scene (camera, groups, the accelerated segment's start) by a spacetime
/// translation leaves the picture: the segment's start moves in its own frame, its shape not.
#[test]
fn a_translated_scene_with_an_accelerated_segment_renders_the_same() {
    use rest_embree::spacetime::Event;
    let s = scene(&accelerating(0.25, 4.5, 14.0, 1));
    for backend in backends() {
        let a = render_with(&s, backend);
        for shift in [
            Event::new(3.0, DVec3::new(2.0, -1.0, 0.5)),
            Event::new(-40.0, DVec3::new(100.0, 0.0, -30.0)),
        ] {
            let b = render_with(&s.translated(shift), backend);
            same_picture(&a, &b, "translated", 2.0 / (W * H) as f64, 1e-4);
        }
    }
}
