//! The path integrator's cost per sample, on the closed room of diffuse boxes lit by a glowing
//! ball (scenes/room.toml, the scene `make docs` also renders beside Mitsuba 3) and on the
//! glowing spheres passing at 0.7c against the same scene at rest (scenes/glowing_pass.toml):
//! milliseconds per sample per pixel over the whole image (the slope between two sample counts,
//! so the fixed costs drop out), the RMS error against a reference at equal samples, and what
//! the lanes buy (the same render with them one by one, and without them).

use crate::accel::backend_by_name;
use crate::render::{render_world_passes, Frame, Passes, World, WorldOptions};
use crate::scene::Scene;
use std::fmt::Write as _;

const ROOM: &str = include_str!("../../scenes/room.toml");
const GLOW: &str = include_str!("../../scenes/glowing_pass.toml");

fn load(name: &str, text: &str, sets: &[String]) -> crate::Result<Scene> {
    let sets: Vec<(String, String)> = sets
        .iter()
        .map(|s| (format!("--set {s}"), s.clone()))
        .collect();
    Ok(crate::scene::load_str(name, text, &sets)?)
}

fn room(size: u32, samples: u32, seed: u32) -> crate::Result<Scene> {
    let sets = [
        format!("image.width={size}"),
        format!("image.height={size}"),
        format!("image.samples={samples}"),
        format!("render.seed={seed}"),
    ];
    load("scenes/room.toml", ROOM, &sets)
}

/// The luminance RMS of the difference of two frames (Rec. 709 weights).
fn rms(a: &Frame, b: &Frame) -> f64 {
    let lum = |c: [f32; 3]| 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64;
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| (lum(p.color) - lum(q.color)).powi(2))
        .sum();
    (sum / a.pixels.len() as f64).sqrt()
}

/// Seconds per sample per pixel of `scene` over the image: the fastest render at `hi` samples
/// less the fastest at `lo`, over `hi − lo`.
fn per_sample(scene: &Scene, world: &World, (lo, hi): (u32, u32), t: super::Timing) -> f64 {
    let at = |spp: u32| {
        let mut sc = scene.clone();
        sc.image.samples = spp;
        super::fastest(t, || {
            render_world_passes(&sc, world, Passes::Colour);
        })
    };
    (at(hi) - at(lo)) / f64::from(hi - lo)
}

/// Markdown lines for the summary.
pub(crate) fn summary(quick: bool, backend: &str) -> crate::Result<String> {
    let b = backend_by_name(backend)?;
    let (size, lo, hi, reference_spp, repeat) = if quick {
        (64, 4, 16, 256, 1)
    } else {
        (192, 16, 64, 1024, 2)
    };
    let mut lines = String::new();
    let scene = room(size, hi, 11)?;
    let ms = |s: f64| s * 1e3;
    let mut cost = Vec::new();
    for (what, lanes, simd) in [
        ("lanes in vector registers", true, true),
        ("lanes one by one", true, false),
        ("no lanes", false, false),
    ] {
        let options = WorldOptions {
            lanes,
            simd,
            ..WorldOptions::default()
        };
        let world = World::build_with(&scene, b.as_ref(), options)?;
        cost.push((
            what,
            per_sample(&scene, &world, (lo, hi), super::Timing::new(repeat, quick)),
        ));
    }
    let world = World::build(&scene, b.as_ref())?;
    let truth = render_world_passes(&room(size, reference_spp, 7)?, &world, Passes::Colour).0;
    let noisy = render_world_passes(&scene, &world, Passes::Colour).0;
    let _ = writeln!(
        lines,
        "- Path integrator, scenes/room.toml at {size}x{size} (depth 12), {backend}: {:.2} ms per \
         sample per pixel over the image ({}: {}), luminance RMS {:.4} at {hi} spp against {reference_spp} spp",
        ms(cost[0].1),
        cost[1..]
            .iter()
            .map(|(w, s)| format!("{w} {:.2} ms", ms(*s)))
            .collect::<Vec<_>>()
            .join(", "),
        cost[1..]
            .iter()
            .map(|(_, s)| format!("{:.2}x", s / cost[0].1))
            .collect::<Vec<_>>()
            .join(" and "),
        rms(&noisy, &truth),
    );
    // The moving demo against the same scene at rest.
    let glow = |v: &str| {
        let sets = [
            format!("image.width={}", size),
            format!("image.height={}", size * 9 / 16),
            format!("group.lamps.velocity=[{v}, 0, 0]"),
        ];
        load("scenes/glowing_pass.toml", GLOW, &sets)
    };
    let mut glow_cost = Vec::new();
    for v in ["0.7", "0"] {
        let sc = glow(v)?;
        let world = World::build(&sc, b.as_ref())?;
        glow_cost.push(per_sample(
            &sc,
            &world,
            (lo / 2, hi / 2),
            super::Timing::new(repeat, quick),
        ));
    }
    let _ = writeln!(
        lines,
        "- Path integrator, scenes/glowing_pass.toml at {size}x{}, {backend}: {:.2} ms per sample \
         with the lamps at 0.7c, {:.2} ms at rest ({:.2}x)",
        size * 9 / 16,
        ms(glow_cost[0]),
        ms(glow_cost[1]),
        glow_cost[0] / glow_cost[1]
    );
    Ok(lines)
}

#[cfg(test)]
mod tests {
    /// Two lines, each with its figures.
    #[test]
    fn room_and_glow_lines() {
        let s = super::summary(true, "bvh").unwrap();
        assert_eq!(s.lines().count(), 2, "{s}");
        assert!(
            s.contains("ms per sample per pixel") && s.contains("RMS"),
            "{s}"
        );
        assert!(s.contains("0.7c") && s.contains("x)"), "{s}");
    }
}
