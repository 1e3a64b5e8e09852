//! Print per-channel statistics of an EXR written by `rest-embree render`:
//! `cargo run --release --example exr_stats -- IMAGE.exr`.

fn main() {
    let path = std::env::args().nth(1).expect("usage: exr_stats IMAGE.exr");
    let (w, h, ch) = rest_embree::output::read_exr_channels(path.as_ref())
        .unwrap_or_else(|e| panic!("{path}: {e}"));
    println!("{path}: {w}x{h}");
    let mut names: Vec<_> = ch.keys().cloned().collect();
    names.sort();
    for n in names {
        let v = &ch[&n];
        let finite: Vec<f32> = v.iter().copied().filter(|x| x.is_finite()).collect();
        let min = finite.iter().copied().fold(f32::INFINITY, f32::min);
        let max = finite.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let nonzero = v.iter().filter(|&&x| x != 0.0).count();
        println!(
            "{n:>10}: min {min:<12.6} max {max:<12.6} nonzero {nonzero:>8} non-finite {}",
            v.len() - finite.len()
        );
    }
}
