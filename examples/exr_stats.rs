//! Print per-channel statistics of an EXR written by `rest-embree render`:
//! `cargo run --release --example exr_stats -- IMAGE.exr`.

use std::io::Write;
use std::process::ExitCode;

fn main() -> ExitCode {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: exr_stats IMAGE.exr");
        return ExitCode::FAILURE;
    };
    let (w, h, ch) = match rest_embree::output::read_exr_channels(path.as_ref()) {
        Ok(read) => read,
        Err(e) => {
            eprintln!("error: {path}: {e}");
            return ExitCode::FAILURE;
        }
    };
    let mut names: Vec<_> = ch.keys().cloned().collect();
    names.sort();
    let mut lines = vec![format!("{path}: {w}x{h}")];
    for n in names {
        let v = &ch[&n];
        let finite: Vec<f32> = v.iter().copied().filter(|x| x.is_finite()).collect();
        let min = finite.iter().copied().fold(f32::INFINITY, f32::min);
        let max = finite.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let nonzero = v.iter().filter(|&&x| x != 0.0).count();
        lines.push(format!(
            "{n:>10}: min {min:<12.6} max {max:<12.6} nonzero {nonzero:>8} non-finite {}",
            v.len() - finite.len()
        ));
    }
    // Written, not println!: a reader that stops early (`| head`) closes the pipe, which is an
    // end, not a panic.
    let mut out = std::io::stdout().lock();
    for line in lines {
        if writeln!(out, "{line}").is_err() {
            break;
        }
    }
    ExitCode::SUCCESS
}
