//! The sky (docs/scene-format.md, "The sky"): an equirectangular map in the convention of the
//! `equirectangular` camera, so that camera at rest, looking along +x with up +z, at the map's
//! size, renders the map back texel for texel; a camera moving through it sees the same sky
//! remapped by aberration (docs/physics.md §1: cos θ' = (cos θ + β)/(1 + β cos θ)), with the
//! Doppler shift and the searchlight off.

mod common;
use common::cli::Dir;
use common::*;
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
            let want = map(lw / (2.0 * PI) + 0.5, 0.5 - bw / PI);
            let got = f.pixels[(y * w + x) as usize].color;
            // Where the map is smooth (away from its seam at u = 0 and 1).
            let u = lw / (2.0 * PI) + 0.5;
            if !(0.02..0.98).contains(&u) {
                continue;
            }
            for k in 0..3 {
                assert!(
                    (f64::from(got[k]) - want[k]).abs() < 2e-3,
                    "pixel ({x}, {y}) channel {k}: {} against {}",
                    got[k],
                    want[k]
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 6000, "{checked} pixels checked");
}
