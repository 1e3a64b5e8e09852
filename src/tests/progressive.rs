//! Progressive renders (`render --max-time`, `--target-rms`): rounds of samples whose mean is
//! unbiased, whose estimated noise is the noise the image really has, and whose first round
//! is an ordinary render.

use crate::accel::backend_by_name;
use crate::render::{render_progressive, render_world, Passes, StopAt, World};

/// A glowing sphere over a diffuse floor beside a rough metal ball (no glass: no caustics,
/// whose rare bright paths would make any noise estimate slow to settle).
fn scene(samples: u32) -> crate::scene::Scene {
    let text = format!(
        r#"
[camera]
position = [0, 3, 10]
look_at = [0, 0.5, 0]
fov_y = 40
[image]
width = 32
height = 24
samples = {samples}
background = 0.05
transparent = false
[render]
integrator = "path"
max_depth = 4
[[material]]
name = "floor"
color = 0.6
[[material]]
name = "metal"
color = 0
reflect = 0.8
roughness = 0.3
[[material]]
name = "lamp"
emission = [8, 6, 4]
[[group]]
name = "still"
[[group.object]]
type = "box"
min = [-10, -1, -10]
max = [10, 0, 10]
material = "floor"
[[group.object]]
type = "sphere"
center = [-1.5, 1, 0]
radius = 1
material = "metal"
[[group]]
name = "lamp"
velocity = [0.5, 0, 0]
[[group.object]]
type = "sphere"
center = [1.5, 2.5, -1]
radius = 0.6
material = "lamp"
"#
    );
    crate::scene::load_str("progressive.toml", &text, &[]).unwrap()
}

fn colours(f: &crate::render::Frame) -> Vec<[f32; 3]> {
    f.pixels.iter().map(|p| p.color).collect()
}

/// The RMS over pixels and channels of the difference of two images.
fn rms(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |c| (f64::from(p[c]) - f64::from(q[c])).powi(2)))
        .sum();
    (sum / (3 * a.len()) as f64).sqrt()
}

#[test]
fn rounds_average_to_the_image_and_know_their_noise() {
    let backend = backend_by_name("bvh").unwrap();
    let reference = scene(1024);
    let world = World::build(&reference, backend.as_ref()).unwrap();
    let (full, _, done) =
        render_progressive(&reference, &world, Passes::Colour, StopAt::default(), None).unwrap();
    assert_eq!(
        (done.samples, done.rounds, done.stopped_by),
        (1024, 256, "samples")
    );
    let ref_noise = done.rms.unwrap();
    let stop = StopAt {
        target_rms: Some(0.02),
        max_time: None,
    };
    let (quick, _, q) =
        render_progressive(&scene(1024), &world, Passes::Colour, stop, None).unwrap();
    assert_eq!(q.stopped_by, "target");
    let estimated = q.rms.unwrap();
    assert!(estimated <= 0.02 && q.samples < 1024, "{q:?}");
    // The error against the reference, less the reference's own noise: the quick image's.
    let measured = (rms(&colours(&quick), &colours(&full)).powi(2) - ref_noise.powi(2)).sqrt();
    assert!(
        (0.75..1.33).contains(&(estimated / measured)),
        "estimated noise {estimated}, measured {measured} (reference's own {ref_noise}), {q:?}"
    );
    // Unbiased: the mean brightness agrees within a few standard errors.
    let mean = |c: &[[f32; 3]]| c.iter().map(|p| f64::from(p[0])).sum::<f64>() / c.len() as f64;
    let (a, b) = (mean(&colours(&quick)), mean(&colours(&full)));
    let se = estimated / (colours(&quick).len() as f64).sqrt();
    assert!(
        (a - b).abs() < 5.0 * se + 1e-4,
        "means {a} and {b} (standard error {se})"
    );
}

#[test]
fn one_round_is_the_ordinary_render_and_threads_change_nothing() {
    let backend = backend_by_name("bvh").unwrap();
    let sc = scene(4);
    let world = World::build(&sc, backend.as_ref()).unwrap();
    let (whole, _) = render_world(&sc, &world);
    let (one, _, done) =
        render_progressive(&sc, &world, Passes::All, StopAt::default(), None).unwrap();
    assert_eq!((done.rounds, done.samples), (1, 4));
    assert_eq!(
        super::differing_pixels(&whole, &one),
        0,
        "the same pixels, passes too"
    );
    let stop = StopAt {
        target_rms: Some(1e-9),
        max_time: None,
    };
    let many = scene(40);
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| render_progressive(&many, &world, Passes::Colour, stop, None).unwrap())
    };
    let (a, b) = (run(1), run(2));
    assert_eq!((a.2.samples, a.2.stopped_by), (40, "samples"));
    assert_eq!(colours(&a.0), colours(&b.0), "1 thread against 2");
}
