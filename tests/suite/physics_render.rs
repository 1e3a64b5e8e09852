//! Render-based physics tests (docs/physics.md §2–§5): the image is rendered on every backend, then
//! measured, and compared with the known answer. Run with `-- --nocapture` to see each
//! measurement as a row of docs/ACCURACY.md.

use crate::common::*;
use glam::DVec3;
use rest_embree::render::Frame;
use rest_embree::spacetime::Velocity;

/// A JSON array of numbers from the cases file.
fn floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .expect("an array")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

fn gamma(beta: f64) -> f64 {
    Velocity::from_beta(DVec3::X, beta).unwrap().gamma()
}

// ---------------------------------------------------------------------------------------------
// §3.3: the moving sphere's outline on a pinhole image (f = 1000 px), to half a pixel.

/// Full image: odd sizes, so pixel centres fall on u = 0 and v = 0.
const SPH_H: u32 = 2001;

fn sphere_scene(beta: f64, c0: [f64; 3], r: f64, width: u32, crop: [u32; 4]) -> String {
    let g = gamma(beta);
    format!(
        r#"
[camera]
position = [0, 0, 0]
direction = [0, 1, 0]
fov_y = {fov:?}
[image]
width = {width}
height = {SPH_H}
samples = 16
crop = [{}, {}, {}, {}]
[[group]]
name = "s"
velocity = [{beta:?}, 0, 0]
[[group.object]]
type = "sphere"
center = [{cx:?}, {cy:?}, {cz:?}]
radius = {r:?}
"#,
        crop[0],
        crop[1],
        crop[2],
        crop[3],
        fov = fov_for_focal(1000.0, SPH_H),
        cx = g * c0[0],
        cy = c0[1],
        cz = c0[2],
    )
}

#[test]
fn sphere_outlines_3_3() {
    let cases = cases();
    for case in cases["sphere"].as_array().unwrap() {
        let beta = case["beta"].as_f64().unwrap();
        let c0 = floats(&case["c0"]);
        let r = case["R"].as_f64().unwrap();
        let p = &case["pinhole_f1000_axis_y"];
        let (cu, a, b) = (
            p["ellipse_centre_u"].as_f64().unwrap(),
            p["semi_axis_u"].as_f64().unwrap(),
            p["semi_axis_v"].as_f64().unwrap(),
        );
        let name = format!("sphere {} beta={beta}", case["case"].as_str().unwrap());
        // Wide enough to hold the ellipse; u = px − W/2.
        let half = (cu.abs() + a + 8.0).ceil() as u32;
        let width = 2 * half + 1;
        let w2 = width as f64 / 2.0;
        let x0 = (w2 + cu - a - 4.0).floor().max(0.0) as u32;
        let row_w = ((2.0 * a + 8.0).ceil() as u32).min(width - x0);
        let col_x = (w2 + cu).floor() as u32;
        let y0 = (SPH_H as f64 / 2.0 - b - 4.0).floor() as u32;
        let col_h = (2.0 * b + 8.0).ceil() as u32;
        for backend in backends() {
            let row = render_with(
                &scene(&sphere_scene(
                    beta,
                    [c0[0], c0[1], c0[2]],
                    r,
                    width,
                    [x0, SPH_H / 2, row_w, 1],
                )),
                backend,
            );
            let col = render_with(
                &scene(&sphere_scene(
                    beta,
                    [c0[0], c0[1], c0[2]],
                    r,
                    width,
                    [col_x, y0, 1, col_h],
                )),
                backend,
            );
            let alpha = |f: &Frame| f.pixels.iter().map(|p| p.alpha).collect::<Vec<f32>>();
            let (l, rr) = alpha_extent(&alpha(&row)).expect("the sphere is on the row");
            let (t, bb) = alpha_extent(&alpha(&col)).expect("the sphere is on the column");
            let centre = (l + rr) / 2.0 + x0 as f64 - w2;
            report(
                &format!("{name}: ellipse centre u"),
                backend,
                cu,
                centre,
                0.5,
                "px",
            );
            report(
                &format!("{name}: semi-axis u"),
                backend,
                a,
                (rr - l) / 2.0,
                0.5,
                "px",
            );
            report(
                &format!("{name}: semi-axis v"),
                backend,
                b,
                (bb - t) / 2.0,
                0.5,
                "px",
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// §4.1 and §4.2: marks on a rod parallel to the motion; a rod perpendicular to it.

const ROW_W: u32 = 30001;

/// Thin boxes (rest frame) on a camera at the origin looking along +y, f = 1000 px, row v = 0.
fn rods_scene(
    beta: f64,
    boxes: &[([f64; 3], [f64; 3])],
    crop_row: Option<u32>,
    height: u32,
) -> String {
    let mut s = format!(
        r#"
[camera]
position = [0, 0, 0]
direction = [0, 1, 0]
fov_y = {fov:?}
[image]
width = {ROW_W}
height = {height}
crop = [0, {row}, {ROW_W}, 1]
[[group]]
name = "rod"
velocity = [{beta:?}, 0, 0]
"#,
        fov = fov_for_focal(1000.0, height),
        row = crop_row.unwrap_or(height / 2),
    );
    for (lo, hi) in boxes {
        s += &format!(
            "[[group.object]]\ntype = \"box\"\nmin = [{:?}, {:?}, {:?}]\nmax = [{:?}, {:?}, {:?}]\n",
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
        );
    }
    s
}

#[test]
fn marks_on_a_rod_parallel_to_the_motion_4_1() {
    let cases = cases();
    let hw = 1e-4;
    for case in cases["rod_parallel"].as_array().unwrap() {
        let beta = case["beta"].as_f64().unwrap();
        let d = case["D"].as_f64().unwrap();
        let xi = floats(&case["xi"]);
        let u = floats(&case["u"]);
        let on_axis = case["case"].as_str().unwrap().ends_with("image_on_axis");
        let g = gamma(beta);
        let x_mark0 = if on_axis { beta * g * d } else { 0.0 };
        // Ten segments between the marks, each its own object; its near face is at y = D − hw.
        let boxes: Vec<_> = (0..10)
            .map(|j| {
                (
                    [x_mark0 + xi[j], d - hw, -hw],
                    [x_mark0 + xi[j + 1], d + hw, hw],
                )
            })
            .collect();
        for backend in backends() {
            let f = render_with(&scene(&rods_scene(beta, &boxes, None, 2001)), backend);
            let ids: Vec<u32> = f.pixels.iter().map(|p| p.object_id).collect();
            for j in 1..10 {
                // The mark between segment j (id j) and j + 1: the midpoint of the last pixel of
                // one and the first of the next.
                let last = ids
                    .iter()
                    .rposition(|&i| i == j as u32)
                    .expect("segment seen") as f64;
                let first = ids
                    .iter()
                    .position(|&i| i == j as u32 + 1)
                    .expect("segment seen") as f64;
                let measured = (last + first) / 2.0 + 0.5 - ROW_W as f64 / 2.0;
                report(
                    &format!(
                        "rod marks {} beta={beta}: mark xi={}",
                        case["case"].as_str().unwrap(),
                        xi[j]
                    ),
                    backend,
                    u[j] * d / (d - hw),
                    measured,
                    1.0,
                    "px",
                );
            }
        }
    }
}

#[test]
fn rod_perpendicular_to_the_motion_is_a_hyperbola_4_2() {
    let cases = cases();
    let hw = 0.02;
    for case in cases["rod_perpendicular_hyperbola"].as_array().unwrap() {
        let beta = case["beta"].as_f64().unwrap();
        let x0 = case["x0"].as_f64().unwrap();
        let zs = floats(&case["z"]);
        let us = floats(&case["u"]);
        let (g, d) = (gamma(beta), 10.0);
        let x = g * x0;
        let rod = [([x - hw, d - hw, -12.0], [x + hw, d + hw, 12.0])];
        // The image of a vertical edge of the thin box at rest-frame x = ex, depth ey, height z.
        let edge_u = |ex: f64, ey: f64, z: f64| {
            1000.0 / ey * g * (ex - beta * (ex * ex + ey * ey + z * z).sqrt())
        };
        for backend in backends() {
            for (k, &z) in zs.iter().enumerate() {
                // Row of v = f z / D; H = 2001 puts pixel centres on whole v.
                let row = (1000.0 - 1000.0 * z / d) as u32;
                let f = render_with(&scene(&rods_scene(beta, &rod, Some(row), 2001)), backend);
                let hit: Vec<f64> = f
                    .pixels
                    .iter()
                    .enumerate()
                    .filter(|(_, p)| p.object_id == 1)
                    .map(|(i, _)| i as f64 + 0.5 - ROW_W as f64 / 2.0)
                    .collect();
                assert!(!hit.is_empty(), "{backend}: the rod is seen at z = {z}");
                let centre = (hit[0] + hit[hit.len() - 1]) / 2.0;
                // The thin box's image on this row spans the images of its four vertical edges;
                // the table's u(z) is that of its axis (hw → 0), which must lie inside.
                let edges: Vec<f64> = [(-hw, -hw), (hw, -hw), (-hw, hw), (hw, hw)]
                    .iter()
                    .map(|(dx, dy)| edge_u(x + dx, d + dy, z * (d + dy) / d))
                    .collect();
                let lo = edges.iter().cloned().fold(f64::INFINITY, f64::min);
                let hi = edges.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
                assert!(
                    us[k] >= lo - 0.01 && us[k] <= hi + 0.01,
                    "table u {} outside the box image [{lo}, {hi}]",
                    us[k]
                );
                report(
                    &format!(
                        "rod along z beta={beta} x0={x0}: image centre at z={z} (axis u {:.3})",
                        us[k]
                    ),
                    backend,
                    (lo + hi) / 2.0,
                    centre,
                    1.0,
                    "px",
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// §2.2: apparent length of a short plate along the motion, seen at angle θ, |r_app| = 10.

#[test]
fn apparent_lengths_2_2() {
    let table = [
        (0.5, [0.302169, 0.600000, 0.866025, 1.000000, 0.763708]),
        (0.9, [0.122481, 0.260339, 0.435890, 0.686349, 0.988067]),
        (0.99, [0.037975, 0.081718, 0.141067, 0.241917, 0.494505]),
    ];
    let (l0, dist, f, t) = (0.2, 10.0, 20000.0, 1e-5);
    let size = 2001u32;
    for (beta, perps) in table {
        let g = gamma(beta);
        for (k, l_perp) in perps.iter().enumerate() {
            let th = (30.0 + 30.0 * k as f64).to_radians();
            // The centre is seen at θ from +x, 10 away: its emission event is (−10, 10 ŝ);
            // in the rest frame X = γ(x − βt) = γ(10 cos θ + 10 β).
            let (cx, cy) = (g * dist * (th.cos() + beta), dist * th.sin());
            let text = format!(
                r#"
[camera]
position = [0, 0, 0]
direction = [{:?}, {:?}, 0]
fov_y = {:?}
[image]
width = {size}
height = {size}
samples = 16
crop = [0, {}, {size}, 1]
[[group]]
name = "plate"
velocity = [{beta:?}, 0, 0]
[[group.object]]
type = "box"
min = [{:?}, {:?}, -1]
max = [{:?}, {:?}, 1]
"#,
                th.cos(),
                th.sin(),
                fov_for_focal(f, size),
                size / 2,
                cx - l0 / 2.0,
                cy - t,
                cx + l0 / 2.0,
                cy + t
            );
            for backend in backends() {
                let fr = render_with(&scene(&text), backend);
                let alpha: Vec<f32> = fr.pixels.iter().map(|p| p.alpha).collect();
                let (a, b) = alpha_extent(&alpha).expect("the plate is seen");
                // Small-object limit: angular size L_perp·L0/|r_app| (error O((L0/r)²) ≈ 4e-4).
                let want = f * l_perp * l0 / dist;
                report(
                    &format!(
                        "plate L0=0.2 beta={beta} theta={}: projected length",
                        30 * (k + 1)
                    ),
                    backend,
                    want,
                    b - a,
                    0.5 + 1e-3 * want,
                    "px",
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// §5.1: the doppler pass equals D = 1/(γ(1 + β·ŝ)) pixel by pixel (and with a moving camera,
// D = γ_c(1 + β_c·ŝ_W)/(γ_g(1 + β_g·ŝ_W)), ŝ_W the world-frame view direction).

/// The world-frame view direction of a pinhole pixel for a camera moving at `vc`, by the vector
/// aberration formula of §1.2 (independent of the renderer's boosts).
fn world_dir(s_cam: DVec3, vc: DVec3) -> DVec3 {
    if vc == DVec3::ZERO {
        return s_cam;
    }
    // The world frame moves at −vc relative to the camera.
    let b = -vc;
    let (bl, bh) = (b.length(), b.normalize());
    let g = 1.0 / (1.0 - bl * bl).sqrt();
    (s_cam + ((g - 1.0) * s_cam.dot(bh) + g * bl) * bh) / (g * (1.0 + b.dot(s_cam)))
}

#[test]
fn doppler_pass_5_1() {
    let (w, h, fov) = (96u32, 72u32, 70.0f64);
    for (vg, vc) in [
        (DVec3::new(0.9, 0.0, 0.0), DVec3::ZERO),
        (DVec3::new(-0.5, 0.3, 0.4), DVec3::ZERO),
        (DVec3::new(0.0, -0.99, 0.0), DVec3::ZERO),
        (DVec3::new(0.6, 0.0, 0.0), DVec3::new(0.0, 0.5, 0.2)),
    ] {
        let text = format!(
            r#"
[camera]
position = [0, -3, 0]
direction = [0, 1, 0]
fov_y = {fov}
velocity = [{:?}, {:?}, {:?}]
time = 5
[image]
width = {w}
height = {h}
[[group]]
name = "g"
velocity = [{:?}, {:?}, {:?}]
[[group.object]]
type = "lattice"
counts = [6, 6, 6]
spacing = 1.5
origin = [-4, 2, -4]
rod_radius = 0.2
sphere_radius = 0.4
"#,
            vc.x, vc.y, vc.z, vg.x, vg.y, vg.z
        );
        let s = scene(&text);
        let fpx = 0.5 * h as f64 / (0.5 * fov.to_radians()).tan();
        let (gg, gc) = (
            1.0 / (1.0 - vg.length_squared()).sqrt(),
            1.0 / (1.0 - vc.length_squared()).sqrt(),
        );
        for backend in backends() {
            let f = render_with(&s, backend);
            let mut worst = 0.0f64;
            let mut n = 0;
            for y in 0..h {
                for x in 0..w {
                    let p = f.get(x, y);
                    if p.object_id == 0 {
                        continue;
                    }
                    let (u, v) = (
                        x as f64 + 0.5 - w as f64 / 2.0,
                        h as f64 / 2.0 - y as f64 - 0.5,
                    );
                    // Camera axes: forward +y, up +z, right = forward × up = +x.
                    let s_cam = DVec3::new(u, fpx, v).normalize();
                    let s_w = world_dir(s_cam, vc);
                    let d = gc * (1.0 + vc.dot(s_w)) / (gg * (1.0 + vg.dot(s_w)));
                    worst = worst.max(((p.doppler as f64 - d) / d).abs());
                    n += 1;
                }
            }
            assert!(n > 200, "{backend}: enough pixels hit ({n})");
            report(
                &format!("doppler pass, group {vg:?}, camera {vc:?}: worst relative error"),
                backend,
                0.0,
                worst,
                1e-6,
                "relative",
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// §4.3: a camera moving through a static scene sees the static panorama remapped by aberration.

#[test]
fn moving_camera_equals_aberrated_panorama_4_3() {
    let (w, h) = (240u32, 120u32);
    let base = |v: &str| {
        format!(
            r#"
[camera]
position = [0.3, 0.2, 0.1]
direction = [1, 0, 0]
projection = "equirectangular"
velocity = {v}
time = 7
[image]
width = {w}
height = {h}
[[group]]
name = "lattice"
[[group.object]]
type = "lattice"
counts = [7, 7, 7]
spacing = 2
origin = [-6, -6, -6]
rod_radius = 0.08
sphere_radius = 0.3
"#
        )
    };
    let dir_of = |x: f64, y: f64| {
        let lon = (x / w as f64 - 0.5) * 2.0 * std::f64::consts::PI;
        let lat = (0.5 - y / h as f64) * std::f64::consts::PI;
        // forward +x, up +z, right = forward × up = −y.
        DVec3::new(lat.cos() * lon.cos(), -lat.cos() * lon.sin(), lat.sin())
    };
    let pixel_of = |d: DVec3| {
        let lat = d.z.clamp(-1.0, 1.0).asin();
        let lon = (-d.y).atan2(d.x);
        let x = ((lon / (2.0 * std::f64::consts::PI) + 0.5) * w as f64).floor() as i64;
        let y = ((0.5 - lat / std::f64::consts::PI) * h as f64).floor() as i64;
        (
            x.rem_euclid(w as i64) as u32,
            y.clamp(0, h as i64 - 1) as u32,
        )
    };
    for u in [0.5, 0.9, 0.99] {
        let stat = scene(&base("[0, 0, 0]"));
        let moving = scene(&base(&format!("[{u}, 0, 0]")));
        let g = gamma(u);
        for backend in backends() {
            let a = render_with(&stat, backend);
            let b = render_with(&moving, backend);
            let (mut compared, mut mismatched, mut worst_d) = (0, 0, 0.0f64);
            for y in 0..h {
                for x in 0..w {
                    let s_cam = dir_of(x as f64 + 0.5, y as f64 + 0.5);
                    // cos θ_scene = (cos θ_cam − u)/(1 − u cos θ_cam), azimuth unchanged.
                    let c = s_cam.x;
                    let cs = (c - u) / (1.0 - u * c);
                    let perp = DVec3::new(0.0, s_cam.y, s_cam.z);
                    let s_scene = if perp.length() > 0.0 {
                        DVec3::new(cs, 0.0, 0.0)
                            + perp.normalize() * (1.0 - cs * cs).max(0.0).sqrt()
                    } else {
                        DVec3::new(cs.signum(), 0.0, 0.0)
                    };
                    let (sx, sy) = pixel_of(s_scene);
                    // Compare only where the static panorama is uniform around the lookup.
                    let id = a.get(sx, sy).object_id;
                    let uniform = (-1i64..=1).all(|dy| {
                        (-1i64..=1).all(|dx| {
                            let nx = (sx as i64 + dx).rem_euclid(w as i64) as u32;
                            let ny = (sy as i64 + dy).clamp(0, h as i64 - 1) as u32;
                            a.get(nx, ny).object_id == id
                        })
                    });
                    if !uniform {
                        continue;
                    }
                    compared += 1;
                    let p = b.get(x, y);
                    if p.object_id != id {
                        mismatched += 1;
                    }
                    if p.object_id != 0 {
                        let d = 1.0 / (g * (1.0 - u * c));
                        worst_d = worst_d.max(((p.doppler as f64 - d) / d).abs());
                    }
                }
            }
            assert!(
                compared > (w * h / 4) as usize,
                "enough pixels compared ({compared})"
            );
            report(
                &format!("aberration remap u={u}: share of mismatched pixels"),
                backend,
                0.0,
                mismatched as f64 / compared as f64,
                1e-3,
                "share",
            );
            report(
                &format!("aberration remap u={u}: Doppler D = 1/(γ(1 − u cos θ))"),
                backend,
                0.0,
                worst_d,
                1e-6,
                "relative",
            );
        }
    }
}
