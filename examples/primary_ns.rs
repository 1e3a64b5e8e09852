//! Nanoseconds per primary ray, the paper's lattice, on one thread unless told (diagnostics,
//! and the figures the README quotes per ray):
//! `cargo run --release --example primary_ns -- [mode] [beta] [size] [seconds] [backend] [threads]`
//! with mode `layer` (the renderer's primary pass, `trace_primary`), `layer-unfused` (the same
//! with every primary ray made one by one, no fans), `bare` (bare Embree on the same rest-frame
//! rays, as the bench's baseline), `bvh` (the primary pass on the f64 BVH) or `render` (a whole
//! render, per pixel), and the Embree backend's name for the modes that use it (`embree`, or
//! `embree-16` / `embree-8` for a packet width); defaults `layer 0 512 2 embree 1`. Prints
//! the fastest pass of as many as fit in the given seconds, in ns per pixel (wall time, so on
//! two threads about half the one-thread figure). Every mode runs its tiles in parallel, as
//! the bench does.
use rest_embree::accel::backend_by_name;
use rest_embree::render::{render_world, trace_primary, World, WorldOptions};
use std::time::Instant;

fn main() {
    let arg = |i: usize| std::env::args().nth(i);
    let mode = arg(1).unwrap_or_else(|| "layer".into());
    let beta = arg(2).unwrap_or_else(|| "0".into());
    let size: u32 = arg(3).and_then(|s| s.parse().ok()).unwrap_or(512);
    let seconds: f64 = arg(4).and_then(|s| s.parse().ok()).unwrap_or(2.0);
    let embree = arg(5).unwrap_or_else(|| "embree".into());
    let threads: usize = arg(6).and_then(|s| s.parse().ok()).unwrap_or(1);
    let sets = vec![
        format!("image.width={size}"),
        format!("image.height={size}"),
        "image.samples=1".to_string(),
        format!("group.lattice.velocity=[-{beta},0,0]"),
    ];
    let scene = rest_embree::bench::paper("lattice", &sets).unwrap_or_else(|e| fail(&e));
    let modes = ["layer", "layer-unfused", "bare", "bvh", "render"];
    if !modes.contains(&mode.as_str()) {
        fail(&format!("unknown mode `{mode}`: {}", modes.join(", ")));
    }
    let backend =
        backend_by_name(if mode == "bvh" { "bvh" } else { &embree }).unwrap_or_else(|e| fail(&e));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let options = WorldOptions {
            fused_primary: mode != "layer-unfused",
            ..WorldOptions::default()
        };
        if mode == "bare" {
            return bare(&scene, &embree, options, seconds, size, &beta);
        }
        let world = World::build_with(&scene, backend.as_ref(), options).unwrap();
        let mut pass: Box<dyn FnMut()> = match mode.as_str() {
            "layer" | "layer-unfused" | "bvh" => Box::new(|| {
                trace_primary(&scene, &world);
            }),
            "render" => Box::new(|| {
                render_world(&scene, &world);
            }),
            other => fail(&format!("unknown mode `{other}`")),
        };
        report(&mode, &beta, size, best_of(seconds, &mut pass));
    });
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

fn report(mode: &str, beta: &str, size: u32, best: f64) {
    let pixels = f64::from(size) * f64::from(size);
    println!(
        "{mode} beta={beta} {size}x{size}: {:.2} ns per pixel",
        best * 1e9 / pixels
    );
}

fn fail(message: &dyn std::fmt::Display) -> ! {
    eprintln!("primary_ns: {message}");
    std::process::exit(2)
}

/// Bare Embree on the rest-frame primary rays of the lattice's one group, through the same
/// Embree scene as the world's (`bench::world_and_accel`).
#[cfg(feature = "embree")]
fn bare(
    scene: &rest_embree::scene::Scene,
    embree: &str,
    options: WorldOptions,
    seconds: f64,
    size: u32,
    beta: &str,
) {
    use rayon::prelude::*;
    let (world, accel) =
        rest_embree::bench::world_and_accel(scene, embree, options).unwrap_or_else(|e| fail(&e));
    let Some(accel) = accel else {
        fail(&"bare Embree needs the lattice's one group on Embree")
    };
    let tiles = rest_embree::bench::bare_rays(scene, &world, &accel);
    let pass = || {
        let _: usize = tiles.par_iter().map(|t| accel.trace_bare(t)).sum();
    };
    report("bare", beta, size, best_of(seconds, pass));
}

#[cfg(not(feature = "embree"))]
fn bare(_: &rest_embree::scene::Scene, _: &str, _: WorldOptions, _: f64, _: u32, _: &str) {
    fail(&"bare Embree needs a build with the `embree` feature")
}
