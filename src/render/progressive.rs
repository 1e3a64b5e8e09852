//! A render that goes on in rounds of samples until a time budget, a target noise or the
//! scene's `samples` is reached (`render --max-time`, `--target-rms`). Each round is a whole
//! frame of a few stratified samples per pixel, jittered anew (`sample_offset`'s `base`) and
//! with its own random numbers for the path integrator, so the mean over any number of whole
//! rounds is unbiased. The noise is measured from the rounds themselves: the spread of a
//! pixel's round means gives the standard error of its mean.

use super::{Passes, RenderStats, Rows};
use crate::scene::Scene;
use std::time::{Duration, Instant};

/// Samples per pixel in each round (fewer where the scene asks for fewer in all).
pub(crate) const ROUND: u32 = 4;

/// When a progressive render stops (whichever comes first; `samples` always bounds it).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StopAt {
    /// Stop before a round that would end after this long (at least one round is rendered).
    pub max_time: Option<Duration>,
    /// Stop once the estimated RMS noise (the standard error of the pixels' means, over the
    /// pixels and the three channels, linear RGB) is at most this (after two rounds at least).
    pub target_rms: Option<f64>,
}

/// What a progressive render did.
#[derive(Clone, Debug)]
pub struct Converged {
    /// Samples per pixel rendered.
    pub samples: u32,
    /// Rounds rendered.
    pub rounds: u32,
    /// The estimated RMS noise of the image (None after one round).
    pub rms: Option<f64>,
    /// What stopped it: "time", "target" or "samples".
    pub stopped_by: &'static str,
}

/// Render `scene` (its `samples` the most per pixel) in rounds until `stop` says so. The frame
/// holds the passes of the first round's centre rays and the mean colour and coverage of all.
/// `progress`, where given, shows each round's pixels, and the rounds, samples, noise and time
/// left so far.
pub(crate) fn render(
    scene: &Scene,
    world: &super::World,
    passes: Passes,
    stop: StopAt,
    progress: Option<&super::Progress>,
) -> crate::Result<(super::Frame, RenderStats, Converged)> {
    let t0 = Instant::now();
    let cap = scene.image.samples.max(1);
    let k = ROUND.min(cap);
    let mut round_scene = scene.clone();
    round_scene.image.samples = k;
    let (_, h) = scene.image.frame_size();
    // Per pixel: the sums of the round means and of their squares, per channel; the coverage.
    let mut sums: Vec<[f64; 6]> = Vec::new();
    let mut alpha: Vec<f64> = Vec::new();
    let mut first: Option<super::Frame> = None;
    let mut stats = RenderStats::default();
    let (mut done, mut rounds) = (0u32, 0u32);
    let mut rms: Option<f64> = None;
    let stopped_by = loop {
        let t_round = Instant::now();
        let round_passes = if rounds == 0 { passes } else { Passes::Colour };
        if let Some(p) = progress {
            let noise = rms.map_or("RMS not yet known".into(), |r: f64| format!("RMS {r:.2e}"));
            let target = stop
                .target_rms
                .map_or(String::new(), |t| format!(" (target {t:.1e})"));
            let left = stop.max_time.map_or(String::new(), |m| {
                let s = m.saturating_sub(t0.elapsed()).as_secs_f64();
                format!(", {s:.0} s left")
            });
            p.next_round(format!(
                "round {}, {done}/{cap} spp, {noise}{target}{left}",
                rounds + 1
            ));
        }
        let rows = Rows::new(&round_scene, world, round_passes, progress).with_sample_base(done);
        let (frame, s) = rows.render(0..h);
        world.check()?;
        stats.primary_rays += s.primary_rays;
        stats.nonfinite_pixels += s.nonfinite_pixels;
        sums.resize(frame.pixels.len(), [0.0; 6]);
        alpha.resize(frame.pixels.len(), 0.0);
        for ((acc, a), p) in sums.iter_mut().zip(alpha.iter_mut()).zip(&frame.pixels) {
            for c in 0..3 {
                let v = f64::from(p.color[c]);
                acc[c] += v;
                acc[3 + c] += v * v;
            }
            *a += f64::from(p.alpha);
        }
        if first.is_none() {
            first = Some(frame);
        }
        done += k;
        rounds += 1;
        rms = (rounds >= 2).then(|| noise(&sums, rounds));
        if done + k > cap {
            break "samples";
        }
        if let (Some(target), Some(r)) = (stop.target_rms, rms) {
            if r <= target {
                break "target";
            }
        }
        if let Some(max) = stop.max_time {
            if t0.elapsed() + t_round.elapsed() > max {
                break "time";
            }
        }
    };
    let mut frame = first.expect("one round at least");
    let n = f64::from(rounds);
    for ((p, acc), a) in frame.pixels.iter_mut().zip(&sums).zip(&alpha) {
        p.color = [0, 1, 2].map(|c| (acc[c] / n) as f32);
        p.alpha = (a / n) as f32;
    }
    stats.trace_time = t0.elapsed();
    stats.samples = Some(done);
    let converged = Converged {
        samples: done,
        rounds,
        rms,
        stopped_by,
    };
    Ok((frame, stats, converged))
}

/// The RMS over pixels and channels of the standard error of each pixel's mean, from its
/// `rounds` (≥ 2) round means: s² / R with s² = (Σm² − (Σm)²/R) / (R − 1).
fn noise(sums: &[[f64; 6]], rounds: u32) -> f64 {
    let r = f64::from(rounds);
    let total: f64 = sums
        .iter()
        .map(|acc| {
            (0..3)
                .map(|c| {
                    let var = (acc[3 + c] - acc[c] * acc[c] / r).max(0.0) / (r - 1.0);
                    var / r
                })
                .sum::<f64>()
        })
        .sum();
    (total / (3 * sums.len().max(1)) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::noise;

    /// Round means 1, 2, 3 in every channel: s² = 1, the standard error² 1/3.
    #[test]
    fn noise_is_the_standard_error_of_the_mean() {
        let acc = [6.0, 6.0, 6.0, 14.0, 14.0, 14.0];
        let got = noise(&[acc, acc], 3);
        assert!((got - (1.0f64 / 3.0).sqrt()).abs() < 1e-15, "{got}");
        assert_eq!(noise(&[[4.0, 4.0, 4.0, 8.0, 8.0, 8.0]], 2), 0.0);
    }
}
