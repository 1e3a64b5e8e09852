//! Orthographic views and Scott & Viner's diagrams.
//!
//! The orthographic camera sends parallel rays from an image plane that is simultaneous in the
//! camera's frame (the far-field limit of a pinhole). A box moving across such a view shows its
//! near face contracted to exactly L0/γ and its trailing face, depth L_d, exactly β·L_d wide.
//!
//! Scott & Viner (1965) drew diagrams of where a point observer sees a plane grid: the apparent
//! (retarded) positions, in which lines perpendicular to the motion become hyperbolas. The P
//! pass holds exactly those positions, so an orthographic top view of the P pass is their
//! diagram; every hit must satisfy x_app = γ(X − β·sqrt(X² + ρ²)) (docs/physics.md §2.1, §4.2).

use crate::common::*;
use glam::DVec3;
use rest_embree::spacetime::Velocity;

#[test]
fn orthographic_box_shows_exact_contraction_and_trailing_face() {
    // 201 rows over a view height of 2: 100.5 px per unit.
    let (w, h, view) = (401u32, 201u32, 2.0f64);
    let ppu = h as f64 / view;
    for beta in [0.0f64, 0.5, 0.9, 0.99] {
        // In view: the near face (y = 10) is imaged when the box is at lab x = X/γ − 10β, so
        // its rest-frame centre X = 10γβ puts it on the axis.
        let g = Velocity::from_beta(DVec3::X, beta).unwrap().gamma();
        let text = format!(
            r#"
[camera]
position = [0, 0, 0]
direction = [0, 1, 0]
projection = "orthographic"
view_height = {view}
[image]
width = {w}
height = {h}
[[group]]
name = "box"
velocity = [{beta:?}, 0, 0]
[[group.object]]
type = "box"
min = [{:?}, 10, -0.5]
max = [{:?}, 11, 0.5]
"#,
            g * beta * 10.0 - 0.5,
            g * beta * 10.0 + 0.5
        );
        for backend in backends() {
            let f = render_with(&scene(&text), backend);
            let near = face_width(&f, [0.0, -1.0, 0.0]) as f64;
            let rear = face_width(&f, [-1.0, 0.0, 0.0]) as f64;
            report(
                &format!("orthographic box beta={beta}: near face L0/γ"),
                backend,
                ppu / g,
                near,
                1.0,
                "px",
            );
            report(
                &format!("orthographic box beta={beta}: trailing face β·depth"),
                backend,
                ppu * beta,
                rear,
                1.0,
                "px",
            );
        }
    }
}

#[test]
fn scott_viner_plane_grid_diagram_from_the_p_pass() {
    // A plane grid (rest frame z = 0) moving along x, seen from above and behind. For every
    // pixel, the P pass (apparent position, relative to the observer) and the Pref pass (the
    // same point in the grid's frame) must obey §2.1: x_app = γ(X − β·sqrt(X² + ρ²)) with ρ
    // the perpendicular offset, unchanged. For a line across the motion (fixed X) that is
    // Scott & Viner's hyperbola; lines along the motion stay straight.
    let cam = DVec3::new(0.0, -5.0, 12.0);
    // About the light-travel time to the grid's centre, so the grid is in view at any speed.
    let t0 = 15.0;
    let mut objects = String::new();
    for x in [-9.0, -6.0, -3.0, 0.0, 3.0, 6.0, 9.0] {
        objects += &format!(
            "[[group.object]]\ntype = \"box\"\nmin = [{:?}, 0, -0.1]\nmax = [{:?}, 30, 0]\n",
            x - 0.1,
            x + 0.1
        );
    }
    for y in [0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0] {
        objects += &format!(
            "[[group.object]]\ntype = \"box\"\nmin = [-9.1, {:?}, -0.1]\nmax = [9.1, {:?}, 0]\n",
            y - 0.1,
            y + 0.1
        );
    }
    for beta in [0.5, 0.9, 0.99] {
        let v = Velocity::from_beta(DVec3::X, beta).unwrap();
        let g = v.gamma();
        let text = format!(
            r#"
[camera]
position = [{:?}, {:?}, {:?}]
look_at = [0, 12, 0]
fov_y = 90
time = {t0:?}
[image]
width = 320
height = 240
[[group]]
name = "grid"
velocity = [{beta:?}, 0, 0]
{objects}"#,
            cam.x, cam.y, cam.z
        );
        for backend in backends() {
            let f = render_with(&scene(&text), backend);
            let (mut worst_x, mut worst_perp, mut n) = (0.0f64, 0.0f64, 0);
            for p in f.pixels.iter().filter(|p| p.object_id != 0) {
                let app = DVec3::new(
                    p.position[0] as f64,
                    p.position[1] as f64,
                    p.position[2] as f64,
                ) - cam;
                // The observation event (t0, cam) sits at x' = γ(cam.x − β t0) in the grid's frame;
                // X is the rest-frame offset of the seen point from it.
                let big_x = p.rest_position[0] as f64 - g * (cam.x - beta * t0);
                let perp = DVec3::new(0.0, p.rest_position[1] as f64, p.rest_position[2] as f64)
                    - DVec3::new(0.0, cam.y, cam.z);
                let rho = perp.length();
                let want = g * (big_x - beta * (big_x * big_x + rho * rho).sqrt());
                worst_x = worst_x.max((app.x - want).abs() / (1.0 + app.x.abs()));
                worst_perp =
                    worst_perp.max((DVec3::new(0.0, app.y, app.z) - perp).length() / (1.0 + rho));
                n += 1;
            }
            assert!(n > 200, "{backend}: the grid is in view ({n} px)");
            report(
                &format!("Scott-Viner grid beta={beta}: x_app = γ(X − β√(X²+ρ²)) on every pixel"),
                backend,
                0.0,
                worst_x,
                1e-5,
                "relative",
            );
            report(
                &format!("Scott-Viner grid beta={beta}: perpendicular offsets unchanged"),
                backend,
                0.0,
                worst_perp,
                1e-5,
                "relative",
            );
        }
    }
}
