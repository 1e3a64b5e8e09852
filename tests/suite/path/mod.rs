//! The path integrator (`[render] integrator = "path"`) against answers known in closed form:
//! a white furnace (a diffuse sphere around a glowing ball) at rest and riding along with the
//! camera at 0.6c and seen from outside through an opening as it moves (its glow times D⁵), a
//! diffuse plane under a uniform sky, a glowing sphere over a plane (direct
//! light only, small and large), a glowing ceiling sliding at 0.6c over a floor at rest (the
//! floor's light the integral of D⁵ cos θ over the ceiling's directions). Beside them: the
//! path integrator against Whitted's and on any number of threads (whitted.rs), its settings
//! on the command line (command_line.rs), its lanes (lanes.rs).

use crate::common::*;
use rest_embree::render::Frame;

mod command_line;
mod lanes;
mod whitted;

/// The mean red value of the pixels whose object id is `id`, and how many there are.
fn mean_of(frame: &Frame, id: u32) -> (f64, usize) {
    let (mut sum, mut n) = (0.0, 0);
    for y in 0..frame.height {
        for x in 0..frame.width {
            let p = frame.get(x, y);
            if p.object_id == id {
                sum += f64::from(p.color[0]);
                n += 1;
            }
        }
    }
    (sum / n.max(1) as f64, n)
}

/// A closed diffuse sphere (radius 10, albedo `rho`) around a glowing ball (radius 1, radiance
/// 100) at its centre; the camera inside, looking at the wall away from the ball; every group
/// and the camera moving at `velocity`.
fn furnace(rho: f64, velocity: &str, emission: &str) -> String {
    format!(
        r#"
[camera]
position = [0, 0, 5]
direction = [0, 0, 1]
up = [0, 1, 0]
fov_y = 40
velocity = {velocity}
[image]
width = 24
height = 24
samples = 256
background = 0
transparent = false
[render]
integrator = "path"
max_depth = 64
[[material]]
name = "wall"
color = {rho}
[[material]]
name = "lamp"
emission = {emission}
[[group]]
name = "wall"
velocity = {velocity}
[[group.object]]
type = "sphere"
center = [0, 0, 0]
radius = 10
material = "wall"
[[group]]
name = "lamp"
velocity = {velocity}
[[group.object]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "lamp"
"#
    )
}

/// The furnace's wall radiance: every point of the inner wall sees the ball (radiance L, a
/// fraction q = (r/R)² of its cosine-weighted view) and the rest of the wall, so
/// L_w = ρ (q L + (1 − q) L_w) (docs/physics.md §10.4).
fn furnace_answer(rho: f64, l: f64) -> f64 {
    let q: f64 = 0.01;
    rho * q * l / (1.0 - rho * (1.0 - q))
}

#[test]
fn white_furnace_at_rest() {
    for backend in backends() {
        for rho in [0.5, 0.8] {
            let f = render_with(&scene(&furnace(rho, "[0, 0, 0]", "100")), backend);
            let (mean, n) = mean_of(&f, 1);
            assert_eq!(n, 24 * 24, "every pixel sees the wall");
            let want = furnace_answer(rho, 100.0);
            let case = format!("path: white furnace, albedo {rho}");
            report(&case, backend, want, mean, 0.01 * want, "");
            assert_rel(mean, want, 0.01, &format!("furnace ρ = {rho} on {backend}"));
        }
    }
}

#[test]
fn white_furnace_riding_along_at_0_6c_is_the_one_at_rest() {
    // A blackbody lamp makes the render spectral, so every change of frame is followed.
    let lamp = "{ blackbody = 5000, luminance = 100 }";
    for backend in backends() {
        let rest = render_with(&scene(&furnace(0.8, "[0, 0, 0]", lamp)), backend);
        let moving = render_with(&scene(&furnace(0.8, "[0.6, 0, 0]", lamp)), backend);
        for c in 0..3 {
            let m = |f: &Frame| {
                let s: f64 = (0..f.height)
                    .flat_map(|y| (0..f.width).map(move |x| (x, y)))
                    .map(|(x, y)| f64::from(f.get(x, y).color[c]))
                    .sum();
                s / f64::from(f.width * f.height)
            };
            let (a, b) = (m(&rest), m(&moving));
            assert!(a > 1.0, "the wall glows ({a})");
            assert_rel(
                b,
                a,
                0.005,
                &format!("channel {c} moving against at rest, {backend}"),
            );
        }
    }
}

/// A closed diffuse sphere (radius 10, albedo 0.8, flat spectra) with a round opening of
/// half-angle 12° about its −z pole, written as 48 × 96 flat triangles, around a glowing ball
/// off the axis; the furnace moving along −z at `beta` toward a camera at rest on the axis
/// outside, which looks in through the opening at the far wall about the +z pole.
fn open_furnace(beta: f64) -> String {
    let (rings, segments) = (48, 96);
    let hole = 12f64.to_radians();
    let mut vertices = Vec::new();
    for i in 0..=rings {
        // From the +z pole (θ = 0) to the opening's rim (θ = π − hole).
        let theta = (std::f64::consts::PI - hole) * i as f64 / rings as f64;
        for j in 0..segments {
            let phi = 2.0 * std::f64::consts::PI * j as f64 / segments as f64;
            let (x, y, z) = (
                10.0 * theta.sin() * phi.cos(),
                10.0 * theta.sin() * phi.sin(),
                10.0 * theta.cos(),
            );
            vertices.push(format!("[{x}, {y}, {z}]"));
        }
    }
    let mut indices = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            let a = i * segments + j;
            let b = i * segments + (j + 1) % segments;
            let (c, d) = (a + segments, b + segments);
            indices.push(format!("[{a}, {b}, {d}]"));
            indices.push(format!("[{a}, {d}, {c}]"));
        }
    }
    let flat = |v: f64| format!("{{ wavelengths = [100, 3000], values = [{v}, {v}] }}");
    format!(
        r#"
[camera]
position = [0, 0, -40]
direction = [0, 0, 1]
up = [0, 1, 0]
fov_y = 2
[image]
width = 12
height = 12
samples = 512
background = 0
transparent = false
[render]
integrator = "path"
max_depth = 64
[[material]]
name = "wall"
color = {wall}
[[material]]
name = "lamp"
emission = {lamp}
[[group]]
name = "furnace"
velocity = [0, 0, {v}]
[[group.object]]
type = "mesh"
vertices = [{vertices}]
indices = [{indices}]
material = "wall"
[[group.object]]
type = "sphere"
center = [0, 6, 0]
radius = 1
material = "lamp"
"#,
        wall = flat(0.8),
        lamp = flat(100.0),
        v = -beta,
        vertices = vertices.join(", "),
        indices = indices.join(", "),
    )
}

/// The same furnace seen from outside through its opening, moving toward the camera: what
/// the camera records of the glow inside (light that has bounced any number of times between
/// walls at rest in the furnace's frame) is the glow at rest times D⁵, D = √((1 + β)/(1 − β))
/// along the axis (flat spectra: the shift changes nothing else; docs/physics.md §5.2, §10.1).
#[test]
fn moving_furnace_seen_through_an_opening_glows_by_d5() {
    for backend in backends() {
        let rest = render_with(&scene(&open_furnace(0.0)), backend);
        let (at_rest, n) = mean_of(&rest, 1);
        assert_eq!(
            n,
            12 * 12,
            "every pixel sees the far wall through the opening"
        );
        assert!(at_rest > 0.1, "the wall glows ({at_rest})");
        for beta in [0.3, -0.3] {
            let moving = render_with(&scene(&open_furnace(beta)), backend);
            let (glow, n) = mean_of(&moving, 1);
            assert_eq!(n, 12 * 12, "β = {beta}: still through the opening");
            let want = ((1.0 + beta) / (1.0 - beta)).sqrt().powi(5);
            report(
                &format!("path: furnace seen through its opening at {beta}c, glow over rest"),
                backend,
                want,
                glow / at_rest,
                0.02 * want,
                "",
            );
            assert_rel(
                glow / at_rest,
                want,
                0.02,
                &format!("β = {beta} on {backend}"),
            );
        }
    }
}

#[test]
fn diffuse_plane_under_a_uniform_sky_is_albedo_times_sky() {
    for backend in backends() {
        for depth in [0, 3] {
            let text = format!(
                r#"
[camera]
position = [0, 5, 5]
look_at = [0, 0, 0]
fov_y = 30
[image]
width = 16
height = 16
samples = 4
background = 2.5
transparent = false
[render]
integrator = "path"
max_depth = {depth}
[[material]]
name = "floor"
color = 0.4
[[group]]
name = "floor"
[[group.object]]
type = "box"
min = [-100, -1, -100]
max = [100, 0, 100]
material = "floor"
"#
            );
            let f = render_with(&scene(&text), backend);
            let (mean, n) = mean_of(&f, 1);
            assert_eq!(n, 256);
            // Cosine-weighted draws meet the sky with weight ρ exactly: no noise at all.
            assert_rel(
                mean,
                0.4 * 2.5,
                1e-9,
                &format!("depth {depth} on {backend}"),
            );
        }
    }
}

/// A glowing sphere (radiance 10, radius r) with its centre d above a diffuse plane (albedo
/// 0.5), a camera looking at the point below it from the side, direct light only.
fn lamp_over_plane(r: f64, d: f64) -> String {
    format!(
        r#"
[camera]
position = [5, 2, 0]
look_at = [0, 0, 0]
fov_y = 0.2
[image]
width = 4
height = 4
samples = 2048
background = 0
transparent = false
[render]
integrator = "path"
max_depth = 0
[[material]]
name = "floor"
color = 0.5
[[material]]
name = "lamp"
emission = 10
[[group]]
name = "floor"
[[group.object]]
type = "box"
min = [-100, -1, -100]
max = [100, 0, 100]
material = "floor"
[[group.object]]
type = "sphere"
center = [0, {d}, 0]
radius = {r}
material = "lamp"
"#
    )
}

#[test]
fn glowing_sphere_lights_a_plane_as_its_solid_angle_says() {
    // A Lambert sphere of radiance L filling a cone of half-angle α straight overhead gives
    // irradiance π L sin²α; the plane sends back ρ/π of it: ρ L (r/d)².
    for backend in backends() {
        for (r, d) in [(0.25, 2.0), (1.5, 2.0)] {
            let f = render_with(&scene(&lamp_over_plane(r, d)), backend);
            let (got, _) = mean_of(&f, 1);
            let want = 0.5 * 10.0 * (r / d) * (r / d);
            let case = format!("path: glowing sphere over a plane, r/d = {}", r / d);
            report(&case, backend, want, got, 0.01 * want, "");
            assert_rel(got, want, 0.01, &format!("r = {r}, d = {d} on {backend}"));
        }
    }
}

/// A floor at rest (albedo 0.5) under a glowing ceiling 1 above it (radiance 1, flat
/// spectrum), the ceiling sliding along x at `beta`; the camera at rest between them.
fn sliding_ceiling(beta: f64, look_at: [f64; 3]) -> String {
    let [x, y, z] = look_at;
    format!(
        r#"
[camera]
position = [0, 0.5, 0]
look_at = [{x}, {y}, {z}]
fov_y = 10
[image]
width = 8
height = 8
samples = 256
background = 0
transparent = false
[render]
integrator = "path"
max_depth = 0
[[material]]
name = "floor"
color = 0.5
[[material]]
name = "glow"
emission = {{ wavelengths = [300, 900], values = [1, 1] }}
[[group]]
name = "floor"
[[group.object]]
type = "box"
min = [-3000, -1, -3000]
max = [3000, 0, 3000]
material = "floor"
[[group]]
name = "ceiling"
velocity = [{beta}, 0, 0]
[[group.object]]
type = "box"
min = [-3000, 1, -3000]
max = [3000, 2, 3000]
material = "glow"
"#
    )
}

/// (1/π) ∫ cos θ D⁵ dω over the upper hemisphere, D = 1/(γ(1 − β u_x)) for light travelling
/// along u (downward) from an emitter moving at β along x: what the sliding ceiling's light on
/// the floor is, relative to its light at rest (flat spectra: the shift changes nothing else).
fn sliding_ceiling_factor(beta: f64) -> f64 {
    let gamma = 1.0 / (1.0 - beta * beta).sqrt();
    let (n_theta, n_phi) = (2000, 2000);
    let mut sum = 0.0;
    for i in 0..n_theta {
        let theta = (i as f64 + 0.5) / n_theta as f64 * std::f64::consts::FRAC_PI_2;
        for j in 0..n_phi {
            let phi = (j as f64 + 0.5) / n_phi as f64 * 2.0 * std::f64::consts::PI;
            let ux = theta.sin() * phi.cos();
            let d = 1.0 / (gamma * (1.0 - beta * ux));
            sum += theta.cos() * theta.sin() * d.powi(5);
        }
    }
    let dw =
        std::f64::consts::FRAC_PI_2 / n_theta as f64 * 2.0 * std::f64::consts::PI / n_phi as f64;
    sum * dw / std::f64::consts::PI
}

#[test]
fn sliding_glowing_ceiling_lights_a_floor_by_d5() {
    assert_rel(
        sliding_ceiling_factor(0.0),
        1.0,
        1e-6,
        "the quadrature at rest",
    );
    let (down, up) = ([0.3, 0.0, 0.2], [0.3, 1.0, 0.2]);
    for backend in backends() {
        let ceiling = mean_of(&render_with(&scene(&sliding_ceiling(0.0, up)), backend), 2).0;
        let rest = mean_of(
            &render_with(&scene(&sliding_ceiling(0.0, down)), backend),
            1,
        )
        .0;
        assert_rel(
            rest,
            0.5 * ceiling,
            0.01,
            "the floor under a ceiling at rest",
        );
        let moving = mean_of(
            &render_with(&scene(&sliding_ceiling(0.6, down)), backend),
            1,
        )
        .0;
        let want = sliding_ceiling_factor(0.6);
        report(
            "path: ceiling sliding at 0.6c over a floor, light over rest",
            backend,
            want,
            moving / rest,
            0.015 * want,
            "",
        );
        assert_rel(moving / rest, want, 0.015, &format!("D⁵ on {backend}"));
    }
}

/// Two groups and a camera in motion, diffuse surfaces, two point lights (one moving), no
/// ambient light: with `integrator` and `max_depth`.
fn lit_by_points(integrator: &str, depth: u32) -> String {
    format!(
        r#"
[camera]
position = [0, 2, 9]
look_at = [0, 0.5, 0]
fov_y = 40
velocity = [0.3, 0, 0]
[image]
width = 40
height = 30
samples = 1
background = 0
transparent = false
[render]
integrator = "{integrator}"
max_depth = {depth}
ambient = 0
[[material]]
name = "floor"
color = [0.7, 0.6, 0.5]
[[material]]
name = "ball"
color = {{ wavelengths = [400, 550, 700], values = [0.2, 0.7, 0.4] }}
[[light]]
position = [3, 5, 4]
intensity = 30
[[light]]
position = [-4, 3, 2]
intensity = 12
velocity = [0, 0, -0.5]
[[group]]
name = "floor"
[[group.object]]
type = "box"
min = [-20, -1, -20]
max = [20, 0, 20]
material = "floor"
[[group]]
name = "balls"
velocity = [0.5, 0, 0]
[[group.object]]
type = "sphere"
center = [-1, 1, 0]
radius = 1
material = "ball"
[[group.object]]
type = "box"
min = [1, 0, -1]
max = [2.5, 1.5, 0.5]
material = "ball"
"#
    )
}
