//! The Hsiung–Dunn calibration (docs/physics.md §2.4), measured on rendered images: a unit cube moving
//! along +x, seen perpendicularly from the origin with f = 1000 px, placed so that its near face
//! is imaged symmetrically about the axis. The near face is exactly f/(γh) wide; the trailing
//! face turns into view.

use crate::common::*;

#[test]
fn cube_widths_match_section_2_4() {
    let cases = cases();
    let rows = cases["cube_perpendicular"].as_array().unwrap();
    let mut checked = 0;
    for backend in backends() {
        for row in rows {
            let (h, beta) = (row["h"].as_f64().unwrap(), row["beta"].as_f64().unwrap());
            let rear_x = row["rest_frame_rear_face_X"].as_f64().unwrap();
            let near = row["near_face_width_px"].as_f64().unwrap();
            let rear = row["rear_face_width_px"].as_f64().unwrap();
            // The near face width is exactly f·sqrt(1 − β²)/h.
            assert_rel(
                near,
                1000.0 * (1.0 - beta * beta).sqrt() / h,
                1e-9,
                "table self-check",
            );
            let frame = render_with(
                &scene(&cube_scene(
                    h,
                    &format!("velocity = [{beta:?}, 0, 0]"),
                    rear_x,
                    0.0,
                    [0.0; 3],
                )),
                backend,
            );
            let got_near = face_width(&frame, [0.0, -1.0, 0.0]) as f64;
            let got_rear = face_width(&frame, [-1.0, 0.0, 0.0]) as f64;
            report(
                &format!("cube h={h} beta={beta}: near face width"),
                backend,
                near,
                got_near,
                1.0,
                "px",
            );
            report(
                &format!("cube h={h} beta={beta}: trailing face width"),
                backend,
                rear,
                got_rear,
                1.0,
                "px",
            );
            checked += 1;
        }
    }
    assert!(checked >= 9);
}

#[test]
fn the_shipped_calibration_scene_shows_the_contraction() {
    // The scene file of the README's figure series: t0 = h puts the near face's centre on the
    // axis, close enough to symmetric that the width is f·sqrt(1 − β²)/h to well under a pixel.
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/calibration_cube.toml");
    for backend in backends() {
        for beta in [0.0f64, 0.1, 0.5, 0.9, 0.99] {
            let sets = [
                (
                    "--set".to_string(),
                    format!("group.cube.velocity=[{beta}, 0, 0]"),
                ),
                ("--set".to_string(), "image.samples=1".to_string()),
            ];
            let scene = rest_embree::scene::load_file(path.as_ref(), &sets).unwrap();
            let frame = render_with(&scene, backend);
            let y = frame.height / 2;
            let near = (0..frame.width)
                .filter(|&x| frame.get(x, y).object_id == 1 && frame.get(x, y).normal[1] < -0.5)
                .count() as f64;
            let expect = 1000.0 * (1.0 - beta * beta).sqrt() / 10.0;
            assert!(
                (near - expect).abs() <= 1.0,
                "{backend} beta {beta}: {near} px, expected {expect:.3}"
            );
        }
    }
}
