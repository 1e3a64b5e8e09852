//! Nanoseconds per primary ray, the paper's lattice, on one thread unless told (diagnostics):
//! `cargo run --release --example primary_ns -- [mode] [beta] [size] [seconds] [backend] [threads]`
//! with mode `layer`, `layer-unfused`, `bare`, `bvh` or `render` (see
//! `rest_embree::bench::probe::primary_ns`) and the Embree backend's name for the modes that use
//! it (`embree`, or `embree-16` / `embree-8` for a packet width); defaults
//! `layer 0 512 2 embree 1`. Prints the fastest pass of as many as fit in the given seconds, in
//! ns per pixel (wall time, so on two threads about half the one-thread figure).
use rest_embree::bench::probe;

fn main() {
    let arg = |i: usize| std::env::args().nth(i);
    let number = |i: usize, default: f64| match arg(i) {
        None => default,
        Some(s) => s
            .parse()
            .unwrap_or_else(|_| fail(&format!("`{s}` is no number"))),
    };
    let mode = arg(1).unwrap_or_else(|| "layer".into());
    let beta = number(2, 0.0);
    let size = number(3, 512.0) as u32;
    let seconds = number(4, 2.0);
    let embree = arg(5).unwrap_or_else(|| "embree".into());
    let threads = number(6, 1.0) as usize;
    match probe::primary_ns(&mode, beta, size, seconds, &embree, threads) {
        Ok(ns) => println!("{mode} beta={beta} {size}x{size}: {ns:.2} ns per pixel"),
        Err(e) => fail(&e),
    }
}

fn fail(message: &dyn std::fmt::Display) -> ! {
    eprintln!("primary_ns: {message}");
    std::process::exit(2)
}
