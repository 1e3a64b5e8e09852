//! Where primary rays spend their time among many velocity groups (diagnostics):
//! `cargo run --release --example group_visits -- 10000 [backend]` (one thread).
use rest_embree::render::{trace_primary, World};
use std::time::Instant;

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(10000);
    let s = rest_embree::bench::many_groups(n, false, 256).unwrap();
    let one = rest_embree::bench::many_groups(n, true, 256).unwrap();
    let name = std::env::args().nth(2).unwrap_or_else(|| "embree".into());
    let backend = rest_embree::accel::backend_by_name(&name).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    pool.install(|| {
        for (name, scene) in [("one group", &one), ("many groups", &s)] {
            let t = Instant::now();
            let w = World::build(scene, backend.as_ref()).unwrap();
            let build = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let (rays, hits) = trace_primary(scene, &w);
            let tp = t.elapsed().as_secs_f64();
            // The first render also builds what is built on first use; the second is warm.
            let t = Instant::now();
            let _ = rest_embree::render::render_world(scene, &w);
            let first = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let _ = rest_embree::render::render_world(scene, &w);
            let tr = t.elapsed().as_secs_f64();
            println!("{name}: build {build:.3} s, primary {tp:.3} s ({:.0} ns/ray, {hits} hits of {rays}), first render {first:.3} s, render {tr:.3} s", tp / rays as f64 * 1e9);
        }
    });
}
