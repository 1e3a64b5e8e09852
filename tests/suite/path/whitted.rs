//! The path integrator beside Whitted's: the same picture where neither bounces (point
//! lights alone) and where the only bounces are smooth (stars in a mirror), and the same bytes
//! on any number of threads.

use super::lit_by_points;
use crate::common::*;
use rest_embree::render::Frame;

#[test]
fn point_lights_without_bounces_give_whitted_picture() {
    // A white Lambert surface facing a point light of intensity I at distance 1 shows
    // radiance I in both integrators; with no bounce and no ambient light nothing else adds.
    for backend in backends() {
        let w = render_with(&scene(&lit_by_points("whitted", 0)), backend);
        let p = render_with(&scene(&lit_by_points("path", 0)), backend);
        let mut lit = 0;
        for y in 0..w.height {
            for x in 0..w.width {
                let (a, b) = (w.get(x, y), p.get(x, y));
                assert_eq!(a.object_id, b.object_id);
                for c in 0..3 {
                    let (a, b) = (f64::from(a.color[c]), f64::from(b.color[c]));
                    assert!(
                        (a - b).abs() <= 1e-5 * a.abs().max(1e-3),
                        "pixel ({x}, {y}) channel {c}: Whitted {a}, path {b} on {backend}"
                    );
                }
                lit += usize::from(a.color[0] > 0.01);
            }
        }
        assert!(lit > 400, "most of the picture is lit ({lit})");
    }
}

#[test]
fn same_seed_same_bytes_on_any_number_of_threads() {
    let text = lit_by_points("path", 3).replace("samples = 1", "samples = 4");
    let sc = scene(&text);
    let render_on = |threads: usize, sc: &rest_embree::scene::Scene| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| render_with(sc, "bvh"))
    };
    let one = render_on(1, &sc);
    let two = render_on(2, &sc);
    let three = render_on(3, &sc);
    let bytes = |f: &Frame| -> Vec<u32> {
        f.pixels
            .iter()
            .flat_map(|p| p.color.map(f32::to_bits))
            .collect()
    };
    assert_eq!(bytes(&one), bytes(&two), "1 thread against 2");
    assert_eq!(bytes(&one), bytes(&three), "1 thread against 3");
    let other = scene(&text.replace("max_depth = 3", "max_depth = 3\nseed = 7"));
    assert_ne!(
        bytes(&one),
        bytes(&render_on(2, &other)),
        "another seed, other noise"
    );
}

/// Stars seen in a perfect mirror: the path integrator carries the pixel's bundle through
/// smooth bounces as Whitted's rays do, so with a mirror alone the two pictures are the same,
/// the camera at rest and moving at 0.6c along the mirror.
#[test]
fn stars_in_a_mirror_as_whitted_sees_them() {
    let text = |integrator: &str, velocity: &str| {
        format!(
            "[camera]\nposition = [0, 0, 0]\ndirection = [1, 0, 0]\nup = [0, 0, 1]\nfov_y = 70\nvelocity = {velocity}\n\
             [image]\nwidth = 48\nheight = 48\n\
             [render]\nintegrator = \"{integrator}\"\n\
             [sky]\nstars = {{ count = 20000, seed = 5, magnitudes = [5, 5], irradiance = 0.1 }}\n\
             [[material]]\nname = \"mirror\"\ncolor = 0\nreflect = 1.0\n\
             [[group]]\nname = \"m\"\n[[group.object]]\ntype = \"box\"\nmin = [5, -100, -100]\nmax = [6, 100, 100]\nmaterial = \"mirror\"\n"
        )
    };
    for velocity in ["[0, 0, 0]", "[0, 0.6, 0]"] {
        for backend in backends() {
            let w = render_with(&scene(&text("whitted", velocity)), backend);
            let p = render_with(&scene(&text("path", velocity)), backend);
            let (mut stars, mut total) = (0, 0.0);
            for (a, b) in w.pixels.iter().zip(&p.pixels) {
                for c in 0..3 {
                    let (a, b) = (f64::from(a.color[c]), f64::from(b.color[c]));
                    assert!(
                        (a - b).abs() <= 1e-5 * a.abs().max(1e-6),
                        "Whitted {a}, path {b} (camera at {velocity}, {backend})"
                    );
                    total += b;
                }
                stars += usize::from(a.color[1] > 0.0);
            }
            assert!(
                stars > 50 && total > 0.0,
                "stars are seen in the mirror ({stars})"
            );
        }
    }
}
