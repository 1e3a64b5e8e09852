//! What many velocity groups cost against one group of the same boxes (diagnostics):
//! `cargo run --release --example group_visits -- [groups] [backend] [size] [threads]`
//! (defaults 10000 embree 256 1; see `rest_embree::bench::probe::group_visits`).
use rest_embree::bench::probe;

fn main() {
    let arg = |i: usize| std::env::args().nth(i);
    let n: usize = arg(1).and_then(|s| s.parse().ok()).unwrap_or(10000);
    let name = arg(2).unwrap_or_else(|| "embree".into());
    let size: u32 = arg(3).and_then(|s| s.parse().ok()).unwrap_or(256);
    let threads: usize = arg(4).and_then(|s| s.parse().ok()).unwrap_or(1);
    match probe::group_visits(n, &name, size, threads) {
        Ok(report) => print!("{report}"),
        Err(e) => {
            eprintln!("group_visits: {e}");
            std::process::exit(2)
        }
    }
}
