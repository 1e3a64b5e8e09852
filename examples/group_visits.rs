//! What many velocity groups cost against one group of the same boxes (diagnostics):
//! `cargo run --release --example group_visits -- [groups] [backend] [size] [threads]`
//! (defaults 10000 embree 256 1). A frame is build + first render (the first render also builds
//! what is built on first use, such as the light trees' slices), the best of three; the warm
//! render is the best of three more.
use rest_embree::render::{render_world, trace_primary, World};
use std::time::Instant;

fn best(runs: usize, mut f: impl FnMut() -> f64) -> f64 {
    (0..runs).map(|_| f()).fold(f64::INFINITY, f64::min)
}

fn main() {
    let arg = |i: usize| std::env::args().nth(i);
    let n: usize = arg(1).and_then(|s| s.parse().ok()).unwrap_or(10000);
    let name = arg(2).unwrap_or_else(|| "embree".into());
    let size: u32 = arg(3).and_then(|s| s.parse().ok()).unwrap_or(256);
    let threads: usize = arg(4).and_then(|s| s.parse().ok()).unwrap_or(1);
    let many = rest_embree::bench::many_groups(n, false, size).unwrap();
    let one = rest_embree::bench::many_groups(n, true, size).unwrap();
    let backend = rest_embree::accel::backend_by_name(&name).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut frames = Vec::new();
        for (label, scene) in [("one group", &one), ("many groups", &many)] {
            let (mut build, mut first) = (f64::INFINITY, f64::INFINITY);
            let frame = best(3, || {
                let t = Instant::now();
                let w = World::build(scene, backend.as_ref()).unwrap();
                let b = t.elapsed().as_secs_f64();
                let t = Instant::now();
                let _ = render_world(scene, &w);
                let f = t.elapsed().as_secs_f64();
                build = build.min(b);
                first = first.min(f);
                b + f
            });
            let w = World::build(scene, backend.as_ref()).unwrap();
            let _ = render_world(scene, &w);
            let (mut rays, mut hits) = (0, 0);
            let primary = best(3, || {
                let t = Instant::now();
                (rays, hits) = trace_primary(scene, &w);
                t.elapsed().as_secs_f64()
            });
            let warm = best(3, || {
                let t = Instant::now();
                let _ = render_world(scene, &w);
                t.elapsed().as_secs_f64()
            });
            println!(
                "{label}: build {build:.3} s, first render {first:.3} s, frame {frame:.3} s; \
                 primary {primary:.3} s ({:.0} ns/ray, {hits} hits of {rays}); warm render {warm:.3} s",
                primary / rays as f64 * 1e9 * threads as f64
            );
            frames.push((frame, warm));
        }
        println!(
            "{n} groups / one group, {name}, {size}x{size}, {threads} thread(s): frame {:.2}x, warm render {:.2}x",
            frames[1].0 / frames[0].0,
            frames[1].1 / frames[0].1
        );
    });
}
