//! Probes for profiling one measure at a time, repeated for as long as asked, with the internals
//! the bench's table sums up (`examples/primary_ns.rs` and `examples/group_visits.rs` call these).

use super::primary::trace_primary;
use crate::accel::backend_by_name;
use crate::render::{render_world, World, WorldOptions};
use crate::scene::Scene;
use std::time::Instant;

/// What [`primary_ns`] measures.
pub const PRIMARY_MODES: [&str; 5] = ["layer", "layer-unfused", "bare", "bvh", "render"];

/// Nanoseconds per pixel of the paper's lattice at `size`², moving at `beta` along −x, on
/// `threads` threads, the fastest pass of as many as fit in `seconds`. `mode` is one of
/// [`PRIMARY_MODES`]: `layer` (the renderer's primary pass), `layer-unfused` (every primary ray
/// made one by one, no fans), `bare` (bare Embree on the same rest-frame rays), `bvh` (the
/// primary pass on the f64 BVH) or `render` (a whole render); `embree` names the Embree backend
/// for the modes that use it.
pub fn primary_ns(
    mode: &str,
    beta: f64,
    size: u32,
    seconds: f64,
    embree: &str,
    threads: usize,
) -> crate::Result<f64> {
    if !PRIMARY_MODES.contains(&mode) {
        let modes = PRIMARY_MODES.join(", ");
        return Err(crate::Error::flag(
            "mode",
            format!("unknown mode `{mode}`: {modes}"),
        ));
    }
    let sets = vec![
        format!("image.width={size}"),
        format!("image.height={size}"),
        "image.samples=1".to_string(),
        format!("group.lattice.velocity=[{:?},0,0]", -beta),
    ];
    let scene = super::paper("lattice", &sets)?;
    let backend = backend_by_name(if mode == "bvh" { "bvh" } else { embree })?;
    let options = WorldOptions {
        fused_primary: mode != "layer-unfused",
        ..WorldOptions::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| crate::Error::flag("threads", e.to_string()))?;
    let best = pool.install(|| -> crate::Result<f64> {
        if mode == "bare" {
            return bare(&scene, embree, options, seconds);
        }
        let world = World::build_with(&scene, backend.as_ref(), options)?;
        Ok(if mode == "render" {
            best_of(seconds, || {
                render_world(&scene, &world);
            })
        } else {
            best_of(seconds, || {
                trace_primary(&scene, &world);
            })
        })
    })?;
    Ok(best * 1e9 / (f64::from(size) * f64::from(size)))
}

/// The fastest of as many passes as fit in `seconds`, after one untimed.
fn best_of(seconds: f64, mut pass: impl FnMut()) -> f64 {
    pass();
    let (start, mut best) = (Instant::now(), f64::INFINITY);
    while start.elapsed().as_secs_f64() < seconds {
        let t = Instant::now();
        pass();
        best = best.min(t.elapsed().as_secs_f64());
    }
    best
}

/// Bare Embree on the rest-frame primary rays of the lattice's one group, through the same
/// Embree scene as the world's.
#[cfg(feature = "embree")]
fn bare(scene: &Scene, embree: &str, options: WorldOptions, seconds: f64) -> crate::Result<f64> {
    use rayon::prelude::*;
    let (world, accel) = super::world_and_accel(scene, embree, options)?;
    let Some(accel) = accel else {
        return Err(crate::Error::flag(
            "mode",
            "bare Embree needs the lattice's one group on Embree",
        ));
    };
    let tiles = super::bare_rays(scene, &world, &accel);
    Ok(best_of(seconds, || {
        let _: usize = tiles.par_iter().map(|t| accel.trace_bare(t)).sum();
    }))
}

#[cfg(not(feature = "embree"))]
fn bare(_: &Scene, _: &str, _: WorldOptions, _: f64) -> crate::Result<f64> {
    Err(crate::Error::flag(
        "mode",
        "bare Embree needs a build with the `embree` feature",
    ))
}

/// What many velocity groups cost against one group of the same boxes: for `n` groups and for
/// one, on `backend` at `size`² and `threads` threads, the build, first render, frame (build +
/// first render; the first render also builds what is built on first use, such as the light
/// trees' slices), primary pass and warm render, each the best of three; one line each, then
/// the ratios.
pub fn group_visits(n: usize, backend: &str, size: u32, threads: usize) -> crate::Result<String> {
    let many = super::many_groups(n, false, size)?;
    let one = super::many_groups(n, true, size)?;
    let accel = backend_by_name(backend)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| crate::Error::flag("threads", e.to_string()))?;
    let best = |mut f: Box<dyn FnMut() -> crate::Result<f64> + '_>| -> crate::Result<f64> {
        (0..3).try_fold(f64::INFINITY, |b, _| Ok(b.min(f()?)))
    };
    pool.install(|| {
        let (mut report, mut frames) = (String::new(), Vec::new());
        for (label, scene) in [("one group", &one), ("many groups", &many)] {
            let (mut build, mut first) = (f64::INFINITY, f64::INFINITY);
            let frame = best(Box::new(|| {
                let t = Instant::now();
                let w = World::build(scene, accel.as_ref())?;
                let b = t.elapsed().as_secs_f64();
                let t = Instant::now();
                render_world(scene, &w);
                let f = t.elapsed().as_secs_f64();
                build = build.min(b);
                first = first.min(f);
                Ok(b + f)
            }))?;
            let w = World::build(scene, accel.as_ref())?;
            render_world(scene, &w);
            let (mut rays, mut hits) = (0, 0);
            let primary = best(Box::new(|| {
                let t = Instant::now();
                (rays, hits) = trace_primary(scene, &w);
                Ok(t.elapsed().as_secs_f64())
            }))?;
            let warm = best(Box::new(|| {
                let t = Instant::now();
                render_world(scene, &w);
                Ok(t.elapsed().as_secs_f64())
            }))?;
            let per_ray = primary / rays as f64 * 1e9 * threads as f64;
            report += &format!(
                "{label}: build {build:.3} s, first render {first:.3} s, frame {frame:.3} s; \
                 primary {primary:.3} s ({per_ray:.0} ns/ray, {hits} hits of {rays}); \
                 warm render {warm:.3} s\n"
            );
            frames.push((frame, warm));
        }
        report += &format!(
            "{n} groups / one group, {backend}, {size}x{size}, {threads} thread(s): \
             frame {:.2}x, warm render {:.2}x\n",
            frames[1].0 / frames[0].0,
            frames[1].1 / frames[0].1
        );
        Ok(report)
    })
}
