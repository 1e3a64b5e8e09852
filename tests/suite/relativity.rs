//! Whole-image invariants: β = 0 is the classical picture, and the principle of relativity
//! (objects at v with the camera at rest ≡ objects at rest with the camera at −v, same event).

use crate::common::*;
use glam::DVec3;
use rest_embree::render::Frame;
use rest_embree::spacetime::{Boost, Event, Velocity};

const OBJECTS: &str = r#"
[[material]]
name = "lit"
color = [0.7, 0.5, 0.3]
specular = 0.3
[[material]]
name = "mirror"
color = [0.1, 0.1, 0.1]
reflect = 0.6
[[material]]
name = "glow"
color = [0, 0, 0]
emission = [0.2, 0.9, 0.4]
[[group.object]]
type = "sphere"
center = [0, 8, 0]
radius = 1.5
material = "mirror"
[[group.object]]
type = "box"
min = [-4, 10, -1]
max = [-2, 12, 1]
material = "lit"
[[group.object]]
type = "rod"
from = [1, 6, -2]
to = [4, 9, 2]
radius = 0.3
material = "glow"
[[group.object]]
type = "lattice"
counts = [4, 3, 3]
spacing = 1.2
origin = [-2, 14, -1]
material = "lit"
"#;

fn scene_text(camera: &str, group_velocity: DVec3, light: &str) -> String {
    format!(
        "[camera]\n{camera}\nfov_y = 70\n[image]\nwidth = 160\nheight = 120\n[[light]]\n{light}\n[[group]]\nname = \"g\"\nvelocity = [{}, {}, {}]\n{OBJECTS}",
        group_velocity.x, group_velocity.y, group_velocity.z
    )
}

fn mismatch_share(a: &Frame, b: &Frame) -> f64 {
    let n = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| p.object_id != q.object_id)
        .count();
    n as f64 / a.pixels.len() as f64
}

#[test]
fn objects_moving_at_v_equal_camera_moving_at_minus_v() {
    let v = DVec3::new(0.6, -0.3, 0.2);
    let (t0, x0) = (14.0, DVec3::new(0.5, -3.0, 0.7));
    // Scene A: world = the camera's frame; the group moves at v; one light moves with the
    // group, a blackbody light stays with the camera (so light crosses frames on every leg:
    // the colours are spectral, Doppler-shifted and searchlight-scaled in both scenes).
    let a_text = scene_text(
        &format!(
            "position = [{}, {}, {}]\ntime = {t0}\ndirection = [0.1, 1, 0.05]",
            x0.x, x0.y, x0.z
        ),
        v,
        "position = [3, 2, 8]\ngroup = \"g\"\n[[light]]\nposition = [-2, 1, 6]\ncolor = { blackbody = 4500, luminance = 0.6 }",
    );
    // Scene B: world = the group's frame; the same imaging event, boosted; the camera and the
    // second light move at −v (that light's frame is A's world, so its position is the same).
    let e = Boost::to_rest(&Velocity::from_beta_vec(v).unwrap()).event(Event::new(t0, x0));
    let b_text = scene_text(
        &format!(
            "position = [{:.17e}, {:.17e}, {:.17e}]\ntime = {:.17e}\ndirection = [0.1, 1, 0.05]\nvelocity = [{}, {}, {}]",
            e.x.x, e.x.y, e.x.z, e.t, -v.x, -v.y, -v.z
        ),
        DVec3::ZERO,
        &format!(
            "position = [3, 2, 8]\n[[light]]\nposition = [-2, 1, 6]\ncolor = {{ blackbody = 4500, luminance = 0.6 }}\nvelocity = [{}, {}, {}]",
            -v.x, -v.y, -v.z
        ),
    );
    for backend in backends() {
        let (sa, sb) = (scene(&a_text), scene(&b_text));
        assert!(rest_embree::render::needs_spectra(&sa) && rest_embree::render::needs_spectra(&sb));
        let a = render_with(&sa, backend);
        let b = render_with(&sb, backend);
        let hit = a.pixels.iter().filter(|p| p.object_id != 0).count();
        assert!(
            hit > a.pixels.len() / 25,
            "the objects must fill part of the image ({hit} px)"
        );
        let share = mismatch_share(&a, &b);
        assert!(
            share < 0.002,
            "{backend}: {:.3}% of pixels see another object",
            share * 100.0
        );
        let mut worst_color = 0.0f32;
        let mut worst_doppler = 0.0f32;
        for (p, q) in a.pixels.iter().zip(&b.pixels) {
            if p.object_id == q.object_id && p.object_id != 0 {
                worst_doppler = worst_doppler.max((p.doppler - q.doppler).abs() / p.doppler);
                for c in 0..3 {
                    worst_color = worst_color.max((p.color[c] - q.color[c]).abs());
                }
            }
        }
        assert!(
            worst_doppler < 1e-5,
            "{backend}: Doppler differs by {worst_doppler}"
        );
        assert!(
            worst_color < 2e-3,
            "{backend}: colour differs by {worst_color}"
        );
    }
}

#[test]
fn beta_zero_is_the_classical_picture() {
    let text = scene_text(
        "position = [0.5, -3, 0.7]\ntime = 0\ndirection = [0.1, 1, 0.05]",
        DVec3::ZERO,
        "position = [3, 2, 8]",
    );
    let s = scene(&text);
    // An independent classical pinhole tracer: brute force over every primitive.
    let (w, h) = (s.image.width, s.image.height);
    let cam = &s.camera;
    let f = 0.5 * h as f64 / (70f64.to_radians() / 2.0).tan();
    let geo = &s.groups[0].geometry;
    let classical: Vec<u32> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let d = (f * cam.forward
                + (x as f64 + 0.5 - w as f64 / 2.0) * cam.right
                + (h as f64 / 2.0 - y as f64 - 0.5) * cam.up)
                .normalize();
            let mut best = (f64::INFINITY, 0u32);
            for (i, p) in geo.prims.iter().enumerate() {
                if let Some(t) = p.intersect(cam.position, d, 0.0, best.0) {
                    best = (t, geo.part_of(i as u32).object + 1);
                }
            }
            best.1
        })
        .collect();
    for backend in backends() {
        let frame = render_with(&s, backend);
        let differ = frame
            .pixels
            .iter()
            .zip(&classical)
            .filter(|(p, c)| p.object_id != **c)
            .count();
        assert!(
            differ as f64 <= 0.001 * frame.pixels.len() as f64,
            "{backend}: {differ} pixels differ from the classical picture"
        );
        // A static scene looks the same at any view time, and every Doppler factor is 1.
        let later = scene(&text.replace("time = 0", "time = 1234.5"));
        let frame2 = render_with(&later, backend);
        assert!(mismatch_share(&frame, &frame2) == 0.0);
        for (p, q) in frame.pixels.iter().zip(&frame2.pixels) {
            assert_eq!(p.color, q.color);
            if p.object_id != 0 {
                assert!((p.doppler - 1.0).abs() < 1e-6);
            }
        }
    }
}

#[test]
fn rendering_is_reproducible_with_samples() {
    let text = scene_text(
        "position = [0, -3, 0]\ndirection = [0, 1, 0]",
        DVec3::new(0.8, 0.0, 0.0),
        "position = [3, 2, 8]",
    );
    let s = scene(&text.replace("height = 120", "height = 120\nsamples = 5"));
    for backend in backends() {
        let a = render_with(&s, backend);
        let b = render_with(&s, backend);
        assert_eq!(a, b, "identical input, identical output");
        let covered: f32 = a.pixels.iter().map(|p| p.alpha).sum();
        assert!(covered > 0.0);
        assert!(
            a.pixels.iter().any(|p| p.alpha > 0.0 && p.alpha < 1.0),
            "anti-aliased edges have partial alpha"
        );
    }
}

/// A render of colour alone (what a PNG holds) has the full render's colour and alpha, bit for
/// bit, leaves the passes empty, and with several samples traces no ray for them.
#[test]
fn colour_only_renders_skip_the_passes() {
    use rest_embree::render::Passes;
    use rest_embree::RenderOptions;
    let text = scene_text(
        "position = [0, -3, 0]\ndirection = [0, 1, 0]",
        DVec3::new(0.8, 0.0, 0.0),
        "position = [3, 2, 8]",
    );
    for samples in [1u32, 3] {
        let s = scene(&text.replace(
            "height = 120",
            &format!("height = 120\nsamples = {samples}"),
        ));
        for backend in backends() {
            let b = rest_embree::accel::backend_by_name(backend).unwrap();
            let render = |passes| {
                let options = RenderOptions {
                    passes,
                    ..Default::default()
                };
                rest_embree::render(&s, b.as_ref(), &options).unwrap()
            };
            let (all, all_stats) = render(Passes::All);
            let (colour, colour_stats) = render(Passes::Colour);
            assert!(all
                .pixels
                .iter()
                .any(|p| p.object_id > 0 && p.lookback > 0.0));
            for (p, q) in all.pixels.iter().zip(&colour.pixels) {
                assert_eq!((p.color, p.alpha), (q.color, q.alpha), "{backend}");
                assert_eq!(
                    (q.object_id, q.lookback, q.doppler, q.normal, q.position),
                    (0, 0.0, 0.0, [0.0; 3], [0.0; 3]),
                    "{backend}: no passes"
                );
            }
            // With several samples the passes have a centre ray of their own per pixel.
            let extra = u64::from(samples > 1);
            assert_eq!(
                all_stats.primary_rays * u64::from(samples),
                colour_stats.primary_rays * (u64::from(samples) + extra),
                "{backend}"
            );
        }
    }
}
