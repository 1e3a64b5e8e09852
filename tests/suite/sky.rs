//! The sky (docs/scene-format.md, "The sky"): an equirectangular map in the convention of the
//! `equirectangular` camera, so that camera at rest, looking along +x with up +z, at the map's
//! size, renders the map back texel for texel; a camera moving through it sees the same sky
//! remapped by aberration (docs/physics.md §1: cos θ' = (cos θ + β)/(1 + β cos θ)), with the
//! Doppler shift and the searchlight off.

use crate::common::cli::Dir;
use crate::common::*;
use glam::DVec3;
use std::f64::consts::PI;

fn linear(v: u8) -> f64 {
    let v = f64::from(v) / 255.0;
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

fn scene(w: u32, h: u32, extra: &str) -> String {
    format!(
        "[camera]\nposition = [0, 0, 0]\ndirection = [1, 0, 0]\nup = [0, 0, 1]\nprojection = \"equirectangular\"\n{extra}\n\
         [image]\nwidth = {w}\nheight = {h}\n\n[sky]\nmap = \"sky.png\"\n\n[render]\ndoppler = false\nsearchlight = false\n"
    )
}

/// A texel's bytes: smooth in x and y (no edge anywhere but the wrap in x).
fn smooth(x: u32, y: u32, w: u32, h: u32) -> [u8; 3] {
    let u = (f64::from(x) + 0.5) / f64::from(w);
    let v = (f64::from(y) + 0.5) / f64::from(h);
    [
        (127.5 + 127.0 * (2.0 * PI * u).sin()) as u8,
        (255.0 * v) as u8,
        (127.5 + 127.0 * (2.0 * PI * u).cos()) as u8,
    ]
}

#[test]
fn the_equirectangular_camera_renders_the_sky_map_back() {
    let d = Dir::new("sky-back");
    let (w, h) = (96, 48);
    // Distinct texels: every pixel must land on its own.
    let texel = |x: u32, y: u32| [(x * 2) as u8, (y * 5) as u8, ((x * 7 + y * 3) % 256) as u8];
    write_png(&d.0.join("sky.png"), w, h, texel);
    let p = d.file("sky.toml", &scene(w, h, ""));
    let s = rest_embree::scene::load_file(&p, &[]).unwrap();
    for b in backends() {
        let f = render_with(&s, b);
        for y in 0..h {
            for x in 0..w {
                let got = f.pixels[(y * w + x) as usize].color;
                let want = texel(x, y).map(linear);
                for k in 0..3 {
                    assert!(
                        (f64::from(got[k]) - want[k]).abs() < 1e-6,
                        "{b}: pixel ({x}, {y}) channel {k}: {} against {}",
                        got[k],
                        want[k]
                    );
                }
                assert_eq!(f.pixels[(y * w + x) as usize].alpha, 1.0, "a sky is opaque");
            }
        }
    }
}

#[test]
fn a_moving_camera_sees_the_sky_remapped_by_aberration() {
    let d = Dir::new("sky-aberration");
    let (w, h) = (128, 64);
    write_png(&d.0.join("sky.png"), w, h, |x, y| smooth(x, y, w, h));
    let beta = 0.6;
    let p = d.file(
        "sky.toml",
        &scene(w, h, &format!("velocity = [{beta}, 0, 0]")),
    );
    let s = rest_embree::scene::load_file(&p, &[]).unwrap();
    // The map as the test reads it: bilinear over linear texels, u wrapping, v held.
    let map = |u: f64, v: f64| -> DVec3 {
        let t = |i: i64, j: i64| {
            let (i, j) = (
                i.rem_euclid(i64::from(w)) as u32,
                j.clamp(0, i64::from(h) - 1) as u32,
            );
            let c = smooth(i, j, w, h).map(linear);
            DVec3::new(c[0], c[1], c[2])
        };
        let (x, y) = (
            u * f64::from(w) - 0.5,
            (v * f64::from(h) - 0.5).clamp(0.0, f64::from(h) - 1.0),
        );
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (i, j) = (x0 as i64, y0 as i64);
        (t(i, j) * (1.0 - fx) + t(i + 1, j) * fx) * (1.0 - fy)
            + (t(i, j + 1) * (1.0 - fx) + t(i + 1, j + 1) * fx) * fy
    };
    // Without the searchlight, and with it: each texel then D⁴ brighter (radiance across a
    // change of frame, docs/physics.md §5.4), D = γ(1 + β cos θ_world) for the camera moving
    // toward the direction it looks in.
    let gamma = 1.0 / (1.0f64 - beta * beta).sqrt();
    for searchlight in [false, true] {
        let s = if searchlight {
            let set = [(
                "--set render.searchlight=true".to_string(),
                "render.searchlight=true".to_string(),
            )];
            rest_embree::scene::load_file(&p, &set).unwrap()
        } else {
            s.clone()
        };
        let f = render_with(&s, "bvh");
        let mut checked = 0;
        for y in 4..h - 4 {
            for x in 0..w {
                // The pixel's direction in the camera's frame (the camera's convention), then the
                // world's by aberration about the motion (+x), azimuth kept.
                let lon = ((f64::from(x) + 0.5) / f64::from(w) - 0.5) * 2.0 * PI;
                let lat = (0.5 - (f64::from(y) + 0.5) / f64::from(h)) * PI;
                let dc = DVec3::new(lat.cos() * lon.cos(), -lat.cos() * lon.sin(), lat.sin());
                let cos_c = dc.x;
                let cos_w = (cos_c - beta) / (1.0 - beta * cos_c);
                let side = DVec3::new(0.0, dc.y, dc.z);
                let sin_w = (1.0 - cos_w * cos_w).max(0.0).sqrt();
                let dw = DVec3::X * cos_w + side.normalize_or(DVec3::Z) * sin_w;
                let (lw, bw) = ((-dw.y).atan2(dw.x), dw.z.clamp(-1.0, 1.0).asin());
                let doppler = gamma * (1.0 + beta * dw.x);
                let bright = if searchlight { doppler.powi(4) } else { 1.0 };
                let want = map(lw / (2.0 * PI) + 0.5, 0.5 - bw / PI) * bright;
                let got = f.pixels[(y * w + x) as usize].color;
                // Where the map is smooth (away from its seam at u = 0 and 1).
                let u = lw / (2.0 * PI) + 0.5;
                if !(0.02..0.98).contains(&u) {
                    continue;
                }
                for k in 0..3 {
                    assert!(
                        (f64::from(got[k]) - want[k]).abs() < 2e-3 * bright.max(1.0),
                        "searchlight {searchlight}: pixel ({x}, {y}) channel {k}: {} against {}",
                        got[k],
                        want[k]
                    );
                }
                checked += 1;
            }
        }
        assert!(checked > 6000, "{checked} pixels checked");
    }
}

// ---- The star field (docs/physics.md §5.5) ----

/// A camera at the origin looking along +x with up +z, a sky of stars and nothing else.
fn star_scene(projection: &str, w: u32, h: u32, camera_extra: &str, sky_extra: &str) -> String {
    format!(
        "[camera]\nposition = [0, 0, 0]\ndirection = [1, 0, 0]\nup = [0, 0, 1]\n{projection}\n{camera_extra}\n\
         [image]\nwidth = {w}\nheight = {h}\n\n\
         [sky]\nstars = {{ count = 400, seed = 11, magnitudes = [0, 4], temperatures = [2500, 40000] }}\n{sky_extra}\n"
    )
}

/// Luminance (CIE Y) of linear sRGB.
fn lum(c: [f32; 3]) -> f64 {
    0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
}

/// The solid angle of pixel (x, y) of a pinhole camera of focal length `f` pixels, by a
/// midpoint rule over the pixel (cos³θ / f² per unit pixel area), not the closed form.
fn pinhole_pixel_sr(x: u32, y: u32, w: u32, h: u32, f: f64) -> f64 {
    let n = 8;
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            let u = f64::from(x) + (f64::from(i) + 0.5) / f64::from(n) - 0.5 * f64::from(w);
            let v = f64::from(y) + (f64::from(j) + 0.5) / f64::from(n) - 0.5 * f64::from(h);
            sum += f / (f * f + u * u + v * v).powf(1.5);
        }
    }
    sum / f64::from(n * n)
}

#[test]
fn a_star_field_holds_the_same_light_on_every_image_size() {
    let d = Dir::new("stars-flux");
    let fov: f64 = 70.0;
    let mut totals = Vec::new();
    for size in [48u32, 160] {
        let text = star_scene(&format!("fov_y = {fov}"), size, size, "", "");
        let p = d.file(&format!("stars-{size}.toml"), &text);
        let s = rest_embree::scene::load_file(&p, &[]).unwrap();
        // What the stars in view send, at rest: the sum of their irradiances.
        let half = (0.5 * fov.to_radians()).tan();
        let stars = &s.sky.as_ref().unwrap().stars.as_ref().unwrap().stars;
        let in_view: f64 = stars
            .iter()
            .filter(|st| {
                st.dir.x > 0.0
                    && (st.dir.y / st.dir.x).abs() < half
                    && (st.dir.z / st.dir.x).abs() < half
            })
            .map(|st| st.irradiance)
            .sum();
        let f = 0.5 * f64::from(size) / half;
        for b in backends() {
            let frame = render_with(&s, b);
            let mut total = 0.0;
            let mut lit = 0;
            for y in 0..size {
                for x in 0..size {
                    let c = frame.pixels[(y * size + x) as usize].color;
                    if lum(c) > 0.0 {
                        lit += 1;
                        total += lum(c) * pinhole_pixel_sr(x, y, size, size, f);
                    }
                }
            }
            assert!(lit > 20, "{b} at {size}²: {lit} pixels hold stars");
            assert!(
                (total / in_view - 1.0).abs() < 1e-4,
                "{b} at {size}²: the image holds {total}, the stars in view send {in_view}"
            );
            totals.push(total);
        }
    }
    assert!((totals[0] / totals[totals.len() - 1] - 1.0).abs() < 1e-4);
    // An orthographic camera looks one way only: it sees no point of the sky, and says nothing
    // is wrong.
    let text = star_scene(
        "projection = \"orthographic\"\nview_height = 4",
        32,
        32,
        "",
        "",
    );
    let s = rest_embree::scene::load_file(&d.file("ortho.toml", &text), &[]).unwrap();
    for b in backends() {
        let f = render_with(&s, b);
        assert!(f.pixels.iter().all(|p| p.color == [0.0; 3]), "{b}");
    }
}

/// The camera's pixel of a camera-frame direction, for the equirectangular camera looking
/// along +x with up +z (longitude toward its right, -y).
fn equirect_pixel(d: DVec3, w: u32, h: u32) -> (u32, u32) {
    let lon = (-d.y).atan2(d.x);
    let lat = d.z.clamp(-1.0, 1.0).asin();
    (
        ((lon / (2.0 * PI) + 0.5) * f64::from(w)) as u32,
        ((0.5 - lat / PI) * f64::from(h)) as u32,
    )
}

/// The law for a star seen from a frame where its light is shifted by D: a blackbody at D·T,
/// its irradiance D⁻² times that blackbody's over the rest one's (for luminance E at rest).
fn shifted_star(kelvin: f64, e: f64, d: f64) -> DVec3 {
    use rest_embree::spectrum::{camera::rgb_of, planck};
    let rest = rgb_of(|nm| planck(nm, kelvin));
    let y = rest.dot(DVec3::new(0.2126, 0.7152, 0.0722));
    rgb_of(|nm| planck(nm, d * kelvin)) * (e / y / (d * d))
}

#[test]
fn a_moving_camera_sees_each_star_aberrated_and_shifted_as_a_blackbody_at_d_t() {
    let d = Dir::new("stars-moving");
    let (w, h) = (720, 360);
    let beta: f64 = 0.9;
    let gamma = 1.0 / (1.0 - beta * beta).sqrt();
    let text = star_scene(
        "projection = \"equirectangular\"",
        w,
        h,
        &format!("velocity = [{beta}, 0, 0]"),
        "",
    );
    let p = d.file("stars.toml", &text);
    let s = rest_embree::scene::load_file(&p, &[]).unwrap();
    let stars = s
        .sky
        .as_ref()
        .unwrap()
        .stars
        .as_ref()
        .unwrap()
        .stars
        .clone();
    // Where each star should fall (aberration about +x, azimuth kept), and its light.
    let mut want: std::collections::HashMap<(u32, u32), Vec<DVec3>> = Default::default();
    for st in stars.iter() {
        let cos_w = st.dir.x;
        let cos_c = (cos_w + beta) / (1.0 + beta * cos_w);
        let side = DVec3::new(0.0, st.dir.y, st.dir.z).normalize_or(DVec3::Z);
        let dc = DVec3::X * cos_c + side * (1.0 - cos_c * cos_c).max(0.0).sqrt();
        let (x, y) = equirect_pixel(dc, w, h);
        // D = γ(1 + β cos θ_world) for a camera moving toward the star.
        let doppler = gamma * (1.0 + beta * cos_w);
        let lat = |py: f64| (0.5 - py / f64::from(h)) * PI;
        let sr =
            2.0 * PI / f64::from(w) * (lat(f64::from(y)).sin() - lat(f64::from(y) + 1.0).sin());
        want.entry((x, y))
            .or_default()
            .push(shifted_star(st.kelvin, st.irradiance, doppler) / sr);
    }
    for b in backends() {
        let f = render_with(&s, b);
        let mut checked = 0;
        for y in 0..h {
            for x in 0..w {
                let got = f.pixels[(y * w + x) as usize].color;
                match want.get(&(x, y)) {
                    None => assert_eq!(got, [0.0; 3], "{b}: pixel ({x}, {y}) holds no star"),
                    Some(v) => {
                        let sum: DVec3 = v.iter().copied().sum();
                        for k in 0..3 {
                            let rel = (f64::from(got[k]) - sum[k]).abs() / sum.max_element();
                            assert!(
                                rel < 1e-5,
                                "{b}: pixel ({x}, {y}) channel {k}: {} against {}",
                                got[k],
                                sum[k]
                            );
                        }
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 350, "{b}: {checked} stars checked");
    }
    // Bunching, in the rendered image: ahead of the camera a cap of half-angle 30° holds over
    // four times the stars it holds at rest (the aberration formula says 4.6 times the cap's
    // share of the sky).
    let f = render_with(&s, "bvh");
    let cos30 = 30f64.to_radians().cos();
    let ahead = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let lon = ((f64::from(x) + 0.5) / f64::from(w) - 0.5) * 2.0 * PI;
            let lat = (0.5 - (f64::from(y) + 0.5) / f64::from(h)) * PI;
            lat.cos() * lon.cos() > cos30 && f.pixels[(y * w + x) as usize].color != [0.0; 3]
        })
        .count();
    let at_rest = stars.iter().filter(|s| s.dir.x > cos30).count();
    assert!(
        ahead > 4 * at_rest,
        "{ahead} stars ahead against {at_rest} at rest"
    );
}

#[test]
fn a_moving_sky_looks_as_a_camera_moving_the_other_way_sees_it() {
    let d = Dir::new("stars-sky-moving");
    let (w, h) = (240, 120);
    let eq = "projection = \"equirectangular\"";
    let a = d.file(
        "a.toml",
        &star_scene(eq, w, h, "velocity = [0.3, 0.5, 0.2]", ""),
    );
    let b = d.file(
        "b.toml",
        &star_scene(eq, w, h, "", "velocity = [-0.3, -0.5, -0.2]"),
    );
    let (a, b) = (
        rest_embree::scene::load_file(&a, &[]).unwrap(),
        rest_embree::scene::load_file(&b, &[]).unwrap(),
    );
    let (fa, fb) = (render_with(&a, "bvh"), render_with(&b, "bvh"));
    let mut lit = 0;
    for (pa, pb) in fa.pixels.iter().zip(&fb.pixels) {
        lit += usize::from(pa.color != [0.0; 3]);
        for k in 0..3 {
            let scale = pa.color[k].abs().max(pb.color[k].abs()).max(1e-30);
            assert!(
                (pa.color[k] - pb.color[k]).abs() / scale < 1e-4,
                "{:?} against {:?}",
                pa.color,
                pb.color
            );
        }
    }
    assert!(lit > 300, "{lit}");
}

#[test]
fn bad_skies_are_clear_errors() {
    use crate::common::cli::fails;
    let cam = "[camera]\nposition = [0, 0, 0]\ndirection = [1, 0, 0]\nup = [0, 0, 1]\n\n";
    for (name, sky, needles) in [
        (
            "sky-empty",
            "[sky]\nintensity = 2\n",
            &["key `sky.map`", "stars"][..],
        ),
        (
            "stars-count",
            "[sky]\nstars = { count = 0 }\n",
            &["sky.stars.count", "whole number"],
        ),
        (
            "stars-no-count",
            "[sky]\nstars = { seed = 3 }\n",
            &["sky.stars.count"],
        ),
        (
            "stars-huge",
            "[sky]\nstars = { count = 1e12 }\n",
            &["sky.stars.count", "10000000"],
        ),
        (
            "stars-seed",
            "[sky]\nstars = { count = 5, seed = -1 }\n",
            &["sky.stars.seed"],
        ),
        (
            "stars-magnitudes",
            "[sky]\nstars = { count = 5, magnitudes = [6, 0] }\n",
            &["sky.stars.magnitudes", "low <= high"],
        ),
        (
            "stars-temperatures",
            "[sky]\nstars = { count = 5, temperatures = [0, 5000] }\n",
            &["sky.stars.temperatures"],
        ),
        (
            "stars-irradiance",
            "[sky]\nstars = { count = 5, irradiance = nan }\n",
            &["sky.stars.irradiance"],
        ),
        (
            "stars-unknown",
            "[sky]\nstars = { count = 5, colour = 3 }\n",
            &["sky.stars.colour"],
        ),
        (
            "sky-fast",
            "[sky]\nstars = { count = 5 }\nvelocity = [1, 0, 0]\n",
            &["sky.velocity"],
        ),
    ] {
        fails(name, &format!("{cam}{sky}"), &[], needles);
    }
    // Ten million stars are 2.1 GB with what finds them: refused within 100 MB, before any
    // star is made.
    fails(
        "stars-memory",
        &format!("{cam}[sky]\nstars = {{ count = 10000000 }}\n"),
        &["--max-memory", "100M"],
        &["sky.stars.count", "10000000 stars"],
    );
}

/// Stars are seen in a mirror: a camera looking into a flat mirror at rest sees, flipped, the
/// stars a camera turned round sees directly, at rest and moving at 0.6c along the mirror (the
/// mirror's reflection maps the one camera onto the other, velocity and all, and the bundles'
/// solid angles change frame on the way). A reflected ray finds the stars in the cone of its
/// pixel's solid angle, so a star may land in a neighbouring pixel or in two: the light in the
/// image is the same on average (within 2% here, 2,000 stars in view), and most star pixels
/// are the direct view's.
#[test]
fn stars_are_seen_in_a_mirror() {
    let d = Dir::new("stars-mirror");
    let (w, h) = (160u32, 160u32);
    let scene = |direction: &str, min: &str, max: &str, velocity: &str, mirror_v: &str| {
        format!(
            "[camera]\nposition = [0, 0, 0]\ndirection = {direction}\nup = [0, 0, 1]\nfov_y = 70\nvelocity = {velocity}\n\n\
             [image]\nwidth = {w}\nheight = {h}\n\n\
             [sky]\nstars = {{ count = 20000, seed = 5, magnitudes = [5, 5], irradiance = 0.1 }}\n\n\
             [[material]]\nname = \"mirror\"\ncolor = 0\nreflect = 1.0\n\n\
             [[group]]\nname = \"m\"\nvelocity = {mirror_v}\n[[group.object]]\ntype = \"box\"\nmin = {min}\nmax = {max}\nmaterial = \"mirror\"\n"
        )
    };
    let f = 0.5 * f64::from(h) / 35f64.to_radians().tan();
    // The camera's velocity and the mirror's: a mirror sliding along its own plane reflects as
    // one at rest, so it too shows the direct view (the bundles change frame into the mirror's
    // and out of it).
    for (velocity, mirror_v) in [
        ("[0, 0, 0]", "[0, 0, 0]"),
        ("[0, 0.6, 0]", "[0, 0, 0]"),
        ("[0, 0, 0]", "[0, 0.6, 0]"),
    ] {
        let mirror = scene(
            "[1, 0, 0]",
            "[5, -100, -100]",
            "[6, 100, 100]",
            velocity,
            mirror_v,
        );
        // Turned round, with the box out of sight behind the camera.
        let direct = scene(
            "[-1, 0, 0]",
            "[50, -1, -1]",
            "[51, 1, 1]",
            velocity,
            "[0, 0, 0]",
        );
        let mirror = rest_embree::scene::load_file(&d.file("mirror.toml", &mirror), &[]).unwrap();
        let direct = rest_embree::scene::load_file(&d.file("direct.toml", &direct), &[]).unwrap();
        for b in backends() {
            let (fm, fd) = (render_with(&mirror, b), render_with(&direct, b));
            let (mut light_m, mut light_d, mut lit, mut same) = (0.0, 0.0, 0, 0);
            for y in 0..h {
                for x in 0..w {
                    let sr = pinhole_pixel_sr(x, y, w, h, f);
                    // The mirror flips left and right.
                    let m = fm.pixels[(y * w + (w - 1 - x)) as usize].color;
                    let dd = fd.pixels[(y * w + x) as usize].color;
                    light_m += lum(m) * sr;
                    light_d += lum(dd) * sr;
                    if dd != [0.0; 3] {
                        lit += 1;
                        // Moving, the star found after the bounce takes the Doppler factor
                        // of the ray that found it, not of its own direction: they differ by
                        // up to a pixel's spread of D (D³ about 1% here).
                        let still = velocity == "[0, 0, 0]" && mirror_v == "[0, 0, 0]";
                        let tol = if still { 1e-4 } else { 0.02 };
                        let close =
                            (0..3).all(|k| (m[k] - dd[k]).abs() <= tol * dd[k].abs().max(1.0));
                        same += usize::from(close);
                    }
                }
            }
            let at = format!("{b}, camera at {velocity}, mirror at {mirror_v}");
            assert!(lit > 1000, "{at}: {lit} pixels hold stars");
            assert!(
                (light_m / light_d - 1.0).abs() < 0.02,
                "{at}: the mirror shows {light_m}, the direct view {light_d}"
            );
            // A pixel's cone is the circle of its area: a star in a corner of its pixel is
            // outside it (about 9% of the square) and found by a neighbour.
            assert!(
                same * 100 >= lit * 85,
                "{at}: {same} of {lit} star pixels as the direct view's"
            );
        }
    }
}
