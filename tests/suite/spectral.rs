//! Colour as a camera records it: the Doppler shift and the searchlight effect, against closed
//! forms (docs/physics.md, "Light and colour"), on every backend.

use crate::common::*;
use rest_embree::render::Frame;
use rest_embree::spectrum::camera;

/// The centre pixel of a 9 × 9 render.
fn centre(f: &Frame) -> rest_embree::render::PixelValue {
    *f.get(f.width / 2, f.height / 2)
}

/// The centre pixel of the scene `text` rendered on `backend`.
fn centre_of(text: &str, backend: &str) -> rest_embree::render::PixelValue {
    centre(&render_with(&scene(text), backend))
}

/// The chromaticity of a pixel's linear sRGB.
fn xy(p: &rest_embree::render::PixelValue) -> (f64, f64) {
    camera::chromaticity(camera::XYZ_TO_SRGB.inverse() * glam::DVec3::from(rgb(p)))
}

fn rgb(p: &rest_embree::render::PixelValue) -> [f64; 3] {
    p.color.map(f64::from)
}

/// Every channel within `rel` of the other's largest channel.
fn same_colour(a: [f64; 3], b: [f64; 3], rel: f64, what: &str) {
    let scale = b.iter().cloned().fold(0.0, f64::max);
    assert!(scale > 1e-4, "{what}: the reference is dark ({b:?})");
    for k in 0..3 {
        assert!(
            (a[k] - b[k]).abs() <= rel * scale,
            "{what}: channel {k}: {a:?} vs {b:?}"
        );
    }
}

/// A 9 × 9 view from the origin along `direction`, `fov_y` degrees high, with no ambient light
/// (each scene's light is its own): the head of every scene here.
fn narrow_view(direction: [f64; 3], fov_y: f64) -> String {
    let [x, y, z] = direction;
    format!(
        "[camera]\nposition = [0, 0, 0]\ndirection = [{x:?}, {y:?}, {z:?}]\nfov_y = {fov_y:?}\n\
         [image]\nwidth = 9\nheight = 9\n[render]\nambient = 0\n"
    )
}

/// A 9 × 9 view along +x from the origin, narrow enough that a sphere of radius 5 at distance
/// 50 fills it; one emissive sphere whose rest-frame centre is `x` and whose group moves at
/// `beta` along x.
fn glowing_sphere(emission: &str, x: f64, beta: f64) -> String {
    let head = narrow_view([1.0, 0.0, 0.0], 1.0);
    format!(
        r#"{head}
[[material]]
name = "glow"
emission = {emission}
[[group]]
name = "s"
velocity = [{beta}, 0, 0]
[[group.object]]
type = "sphere"
center = [{x}, 0, 0]
radius = 5
material = "glow"
"#
    )
}

/// Where the sphere's centre must sit in its rest frame for the camera to see it at distance
/// 50 now: its centre was at x = 50 at t = −50 (x = 50 + β(t + 50)), so x' = γ(x − βt).
fn rest_x(beta: f64) -> f64 {
    let g = 1.0 / (1.0 - beta * beta).sqrt();
    g * 50.0 * (1.0 + beta)
}

/// A blackbody at T seen with Doppler factor D (read from the doppler pass) is, channel by
/// channel, the blackbody at D·T at rest: D⁵ B_λ(Dλ, T) = B_λ(λ, DT).
#[test]
fn a_moving_blackbody_looks_like_a_blackbody_at_d_t() {
    let t = 5000.0;
    let emission = |k: f64| format!("{{ blackbody = {k:?}, scale = 1e-7 }}");
    for backend in backends() {
        for beta in [-0.3f64, 0.3, -0.6] {
            // β < 0: approaching (D > 1); β > 0: receding.
            let p = centre_of(&glowing_sphere(&emission(t), rest_x(beta), beta), backend);
            let d = f64::from(p.doppler);
            let phi = (-beta).atanh();
            assert_rel(d, phi.exp(), 1e-6, "head-on D = e^φ");
            let still = centre_of(&glowing_sphere(&emission(d * t), 50.0, 0.0), backend);
            same_colour(rgb(&p), rgb(&still), 0.005, &format!("{backend} β {beta}"));
            // And the shift is real: the colour differs from the blackbody at T.
            let plain = centre_of(&glowing_sphere(&emission(t), 50.0, 0.0), backend);
            let (a, b) = (rgb(&p), rgb(&plain));
            assert!(
                (a[2] / a[0] - b[2] / b[0]).abs() > 0.05,
                "{backend} β {beta}: no shift"
            );
        }
    }
}

/// A Gaussian line (λ0, w, s) seen with D is the line (λ0/D, w/D, s·D⁴) at rest.
#[test]
fn a_moving_line_is_a_shifted_line() {
    for backend in backends() {
        for beta in [-0.2f64, 0.25] {
            let line = "{ line = 560, fwhm = 60, scale = 0.05 }";
            let p = centre_of(&glowing_sphere(line, rest_x(beta), beta), backend);
            let d = f64::from(p.doppler);
            let shifted = format!(
                "{{ line = {:?}, fwhm = {:?}, scale = {:?} }}",
                560.0 / d,
                60.0 / d,
                0.05 * d.powi(4)
            );
            let still = centre_of(&glowing_sphere(&shifted, 50.0, 0.0), backend);
            same_colour(rgb(&p), rgb(&still), 0.005, &format!("{backend} β {beta}"));
        }
    }
}

/// §5.3's plate: a grey Lambertian plate facing the camera at apparent distance 20, seen head-on
/// and at 90°, lit by a blackbody point light at the camera (both at rest) or riding with the
/// plate. `moving` is the plate's rest-frame placement and velocity; returns the scene.
fn plate(
    min: [f64; 3],
    max: [f64; 3],
    velocity: [f64; 3],
    light: &str,
    direction: [f64; 3],
) -> String {
    let head = narrow_view(direction, 0.5);
    format!(
        r#"{head}max_depth = 0
[[material]]
name = "grey"
color = 0.5
[[light]]
{light}
falloff = "inverse_square"
[[group]]
name = "plate"
velocity = [{vx:?}, {vy:?}, {vz:?}]
[[group.object]]
type = "box"
min = [{:?}, {:?}, {:?}]
max = [{:?}, {:?}, {:?}]
material = "grey"
"#,
        min[0],
        min[1],
        min[2],
        max[0],
        max[1],
        max[2],
        vx = velocity[0],
        vy = velocity[1],
        vz = velocity[2],
    )
}

fn bb_light(position: &str, kelvin: f64, scale: f64, group: bool) -> String {
    let g = if group { "group = \"plate\"\n" } else { "" };
    format!("position = {position}\ncolor = {{ blackbody = {kelvin:?}, scale = {scale:?} }}\n{g}")
}

/// The worked example of §5.3: light and camera together at rest, the plate approaching or
/// receding head-on at β. Its light reaches the camera as L_cam(λ) = D_out⁵ D_in³ ρ B(D_in D_out
/// λ, T)/r² = ρ B(λ, T')/(D_in² r²), T' = T (1 + β)/(1 − β) for approach: the plate at rest lit
/// by T' with the light's scale over D_in² (so the chromaticity of T', and a bolometric ratio
/// of D_in²·D_out⁴ = ((1 + β)/(1 − β))³, 27 at β = 0.5, as in the table).
#[test]
fn a_plate_approaching_a_light_at_the_camera() {
    let (t, s, d) = (4000.0, 1e-2, 20.0);
    for backend in backends() {
        for beta in [0.1f64, 0.5, -0.5] {
            // β > 0: the plate approaches (moves along −x toward the camera).
            let phi = beta.atanh();
            // Front face seen at distance d now: reflected at t = −d at x = d, moving at −β:
            // x' = γ(x + βt) = d e^{−φ}.
            let front = d * (-phi).exp();
            let moving = plate(
                [front, -0.5, -0.5],
                [front + 0.1, 0.5, 0.5],
                [-beta, 0.0, 0.0],
                &bb_light("[0, 0, 0]", t, s, false),
                [1.0, 0.0, 0.0],
            );
            let p = centre_of(&moving, backend);
            assert_rel(f64::from(p.doppler), phi.exp(), 1e-6, "D_out = e^φ");
            let (d_in, d_out) = (phi.exp(), phi.exp());
            let reference = plate(
                [d, -0.5, -0.5],
                [d + 0.1, 0.5, 0.5],
                [0.0; 3],
                &bb_light("[0, 0, 0]", t * d_in * d_out, s / (d_in * d_in), false),
                [1.0, 0.0, 0.0],
            );
            let b = centre_of(&reference, backend);
            same_colour(
                rgb(&p),
                rgb(&b),
                0.005,
                &format!("{backend} head-on β {beta}"),
            );
            let ((x, y), (x0, y0)) = (xy(&p), xy(&b));
            assert!(
                (x - x0).abs() < 1e-3 && (y - y0).abs() < 1e-3,
                "{backend}: chromaticity"
            );
        }
    }
}

/// §5.3's 90° case: the plate passes the camera with its normal across the motion, seen at 90°
/// in the camera frame. D_in = γ and D_out = 1/γ cancel: the colour is the plate's at rest, and
/// it dims by exactly γ⁻³ at every wavelength.
#[test]
fn a_plate_passing_sideways_dims_by_gamma_cubed() {
    let (t, s, d) = (5500.0, 1e-2, 20.0);
    for backend in backends() {
        for beta in [0.5f64, 0.9] {
            let g = 1.0 / (1.0 - beta * beta).sqrt();
            // Reflected at t = −d at (0, d, 0), moving at +β along x: x' = γ(x − βt) = γβd.
            let x = g * beta * d;
            let moving = plate(
                [x - 0.1, d, -0.1],
                [x + 0.1, d + 0.05, 0.1],
                [beta, 0.0, 0.0],
                &bb_light("[0, 0, 0]", t, s, false),
                [0.0, 1.0, 0.0],
            );
            let p = centre_of(&moving, backend);
            assert_rel(f64::from(p.doppler), 1.0 / g, 1e-5, "D_out = 1/γ");
            let reference = plate(
                [-0.1 / g, d, -0.1],
                [0.1 / g, d + 0.05, 0.1],
                [0.0; 3],
                &bb_light("[0, 0, 0]", t, s * g.powi(-3), false),
                [0.0, 1.0, 0.0],
            );
            let b = centre_of(&reference, backend);
            same_colour(rgb(&p), rgb(&b), 0.005, &format!("{backend} 90° β {beta}"));
        }
    }
}

/// With the light riding along with the plate, only D_out shifts: the plate looks lit by the
/// blackbody at D·T, at the brightness of the plate at rest.
#[test]
fn a_light_riding_with_the_plate_shifts_by_d_out_alone() {
    let (t, s, d) = (4000.0, 1e-2, 20.0);
    for backend in backends() {
        for beta in [0.5f64, -0.3] {
            let phi = beta.atanh();
            let front = d * (-phi).exp();
            // The light 3 units in front of the plate and 1 up, in the plate's frame.
            let light = format!("[{:?}, 0, 1]", front - 3.0);
            let moving = plate(
                [front, -0.5, -0.5],
                [front + 0.1, 0.5, 0.5],
                [-beta, 0.0, 0.0],
                &bb_light(&light, t, s, true),
                [1.0, 0.0, 0.0],
            );
            let p = centre_of(&moving, backend);
            let d_out = f64::from(p.doppler);
            assert_rel(d_out, phi.exp(), 1e-6, "D_out = e^φ");
            let reference = plate(
                [front, -0.5, -0.5],
                [front + 0.1, 0.5, 0.5],
                [0.0; 3],
                &bb_light(&light, t * d_out, s, false),
                [1.0, 0.0, 0.0],
            );
            let b = centre_of(&reference, backend);
            same_colour(
                rgb(&p),
                rgb(&b),
                0.005,
                &format!("{backend} riding β {beta}"),
            );
        }
    }
}

/// §6's table: blackbodies at rest, seen through the camera, have the chromaticities that the
/// 1 nm CIE integral gives (tests/data/blackbody_colours.json), within 0.002.
#[test]
fn blackbody_chromaticities_match_the_table() {
    let table: serde_json::Value =
        serde_json::from_str(include_str!("../data/blackbody_colours.json")).unwrap();
    let rows = table["rows"].as_array().expect("rows");
    assert!(rows.len() >= 8);
    for backend in backends() {
        for row in rows {
            let k = row["T_eff_K"].as_f64().unwrap();
            let f = centre_of(
                &glowing_sphere(&format!("{{ blackbody = {k:?} }}"), 50.0, 0.0),
                backend,
            );
            let (x, y) = xy(&f);
            let (x0, y0) = (row["x"].as_f64().unwrap(), row["y"].as_f64().unwrap());
            assert!(
                (x - x0).abs() < 0.002 && (y - y0).abs() < 0.002,
                "{backend} {k} K: ({x:.5}, {y:.5}) vs ({x0}, {y0})"
            );
        }
    }
}

/// A mirror at rest facing the camera at 45° and a glowing sphere coming at the mirror head-on
/// along the reflected direction: the mirror, in the camera's frame, shows the sphere's
/// blackbody at D·T with D = e^φ of the sphere seen along the reflected ray. With the mirror
/// riding along with the sphere instead, the light crosses no frame between them, and the
/// mirror shows the blackbody at D_out·T, D_out the mirror's own Doppler factor (the pass).
#[test]
fn a_mirror_between_frames_passes_the_shift_on() {
    let mirror_scene = |beta: f64, mirror_rides: bool, sphere_x: f64, kelvin: f64| {
        // A moving mirror is seen where it was 10 time units ago: shifted by β·10 along x in
        // the world, so its rest-frame centre is put where that brings it onto the view axis.
        let dx = if mirror_rides {
            10.0 * beta / (1.0 - beta * beta).sqrt()
        } else {
            0.0
        };
        let mirror = format!(
            r#"
[[group.object]]
type = "mesh"
vertices = [[{a:?}, 7, -3], [{b:?}, 13, -3], [{b:?}, 13, 3], [{a:?}, 7, 3]]
indices = [[0, 1, 2], [0, 2, 3]]
material = "mirror"
"#,
            a = dx - 3.0,
            b = dx + 3.0
        );
        let mirror = mirror.as_str();
        let (still, riding) = if mirror_rides {
            ("", mirror)
        } else {
            (mirror, "")
        };
        let head = narrow_view([0.0, 1.0, 0.0], 0.5);
        format!(
            r#"{head}
[[material]]
name = "mirror"
color = 0
reflect = 1
[[material]]
name = "glow"
emission = {{ blackbody = {kelvin:?}, scale = 1e-7 }}
[[group]]
name = "moving"
velocity = [{beta:?}, 0, 0]
[[group.object]]
type = "sphere"
center = [{sphere_x:?}, 10, 0]
radius = 5
material = "glow"
{riding}
[[group]]
name = "still"
{still}
"#
        )
    };
    let t = 5000.0;
    for backend in backends() {
        // The mirror (the plane x − y + 10 = 0 through (0, 10, 0)) sends the view along +y to
        // +x: the sphere's near side is seen at x = 40 (50 along the path), and the sphere
        // comes toward the mirror at −β. Its centre was at x = 45 at t = −50.
        let beta: f64 = 0.4;
        let g = 1.0 / (1.0 - beta * beta).sqrt();
        // x(t) = 45 − β(t + 50); moving at −β, its rest-frame x' = γ(x + βt) = γ(45 − 50β).
        let rest = g * (45.0 - 50.0 * beta);
        let a = centre_of(&mirror_scene(-beta, false, rest, t), backend);
        let d = (beta.atanh()).exp();
        let b = centre_of(&mirror_scene(0.0, false, 45.0, d * t), backend);
        same_colour(rgb(&a), rgb(&b), 0.005, &format!("{backend} still mirror"));
        // The mirror riding with the sphere (group "moving"), slower and closer, so that the
        // view, aberrated in their frame, still meets the sphere after the mirror: only the
        // mirror's own D_out.
        let (beta, near) = (0.2, 18.0);
        let p = centre_of(&mirror_scene(-beta, true, near, t), backend);
        assert!(p.object_id == 2, "{backend}: the centre sees the mirror");
        let d_out = f64::from(p.doppler);
        assert!(
            (d_out - 1.0).abs() > 0.01,
            "{backend}: the mirror moves ({d_out})"
        );
        let ref_scene = mirror_scene(0.0, false, near, d_out * t);
        let e = centre_of(&ref_scene, backend);
        same_colour(rgb(&p), rgb(&e), 0.005, &format!("{backend} riding mirror"));
    }
}

/// The spectral path runs only where something needs it.
#[test]
fn spectral_work_only_where_needed() {
    use rest_embree::render::needs_spectra;
    let base = glowing_sphere("[1, 0.5, 0.2]", 50.0, 0.0);
    assert!(!needs_spectra(&scene(&base)), "all at rest, all RGB");
    let moving = glowing_sphere("[1, 0.5, 0.2]", 50.0, 0.5);
    assert!(needs_spectra(&scene(&moving)), "a moving group");
    let bb = glowing_sphere("{ blackbody = 3000 }", 50.0, 0.0);
    assert!(needs_spectra(&scene(&bb)), "a spectrum");
    let off = moving.replace(
        "ambient = 0",
        "ambient = 0\ndoppler = false\nsearchlight = false",
    );
    assert!(!needs_spectra(&scene(&off)), "both switches off");
    let doppler_only = moving.replace("ambient = 0", "ambient = 0\nsearchlight = false");
    assert!(needs_spectra(&scene(&doppler_only)), "one switch on");
    // A moving camera and a background that is not black: the sky is seen shifted.
    let sky = base
        .replace("fov_y = 1.0", "fov_y = 1.0\nvelocity = [0, 0.3, 0]")
        .replace("height = 9", "height = 9\nbackground = 0.2");
    assert!(
        needs_spectra(&scene(&sky)),
        "a moving camera against the sky"
    );
}
