//! The path integrator's run time against its error (the mission's "run time against error"):
//! the demo scene of glowing spheres passing at 0.7c (scenes/glowing_pass.toml) at 16, 64 and
//! 256 samples per pixel on each backend, each image's RMS error against a reference of 4096
//! samples (its own noise taken out in quadrature), beside the noise the progressive renderer
//! estimates from its rounds.

use crate::accel::backend_by_name;
use crate::render::{render_progressive, Passes, StopAt, World};
use std::fmt::Write as _;

const SCENE: &str = include_str!("../../scenes/glowing_pass.toml");

fn scene(width: u32, samples: u32) -> crate::Result<crate::scene::Scene> {
    let sets: Vec<(String, String)> = [
        format!("image.width={width}"),
        format!("image.height={}", width * 9 / 16),
        format!("image.samples={samples}"),
    ]
    .into_iter()
    .map(|s| (format!("--set {s}"), s))
    .collect();
    Ok(crate::scene::load_str(
        "scenes/glowing_pass.toml",
        SCENE,
        &sets,
    )?)
}

/// The RMS over pixels and channels of the difference of two frames' colours.
fn rms(a: &crate::render::Frame, b: &crate::render::Frame) -> f64 {
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(p, q)| {
            (0..3).map(move |c| (f64::from(p.color[c]) - f64::from(q.color[c])).powi(2))
        })
        .sum();
    (sum / (3 * a.pixels.len()) as f64).sqrt()
}

/// Markdown lines: per backend and samples per pixel, the seconds and the RMS error.
pub(crate) fn summary(quick: bool, backends: &[&str]) -> crate::Result<String> {
    let (width, reference_spp) = if quick { (64, 1024) } else { (192, 4096) };
    let mut lines = String::new();
    for &backend in backends {
        let b = backend_by_name(backend)?;
        let world = World::build(&scene(width, 4)?, b.as_ref())?;
        let everything = StopAt::default();
        let reference = scene(width, reference_spp)?;
        let (truth, _, done) =
            render_progressive(&reference, &world, Passes::Colour, everything, None)?;
        let own = done.rms.unwrap_or(0.0);
        let _ = writeln!(
            lines,
            "- Path integrator, scenes/glowing_pass.toml at {width}x{}, {backend}: reference {reference_spp} spp (its own estimated noise {own:.4})",
            width * 9 / 16
        );
        for spp in [16, 64, 256] {
            let sc = scene(width, spp)?;
            let mut out = None;
            let secs = super::fastest(super::Timing::new(if quick { 1 } else { 2 }, quick), || {
                out = Some(render_progressive(
                    &sc,
                    &world,
                    Passes::Colour,
                    everything,
                    None,
                ));
            });
            let (frame, _, d) = out.expect("rendered")?;
            let err = (rms(&frame, &truth).powi(2) - own * own).max(0.0).sqrt();
            let est = d.rms.map_or("-".into(), |r| format!("{r:.4}"));
            let _ = writeln!(
                lines,
                "  - {spp} spp: {secs:.3} s, RMS error {err:.4} (estimated from its rounds: {est})"
            );
        }
    }
    Ok(lines)
}

#[cfg(test)]
mod tests {
    /// Four lines per backend; the error falls as the samples rise.
    #[test]
    fn error_falls_with_samples() {
        let lines = super::summary(true, &["bvh"]).unwrap();
        assert_eq!(lines.lines().count(), 4, "{lines}");
        let errors: Vec<f64> = lines
            .lines()
            .skip(1)
            .map(|l| {
                let e = l.split("RMS error ").nth(1).unwrap();
                e.split_whitespace().next().unwrap().parse().unwrap()
            })
            .collect();
        assert!(errors[0] > errors[1] && errors[1] > errors[2], "{lines}");
        // Quadrupling the samples halves the noise of an unbiased estimate; the caustics'
        // rare bright paths (the glass, the metal ball) make the measured ratio stray from 2.
        for w in errors.windows(2) {
            assert!((1.3..3.5).contains(&(w[0] / w[1])), "{lines}");
        }
    }
}
