//! Compare two EXRs written by `rest-embree render`, channel by channel: how many values
//! differ and by how much at most (absolute, and relative to the larger magnitude):
//! `cargo run --release --example exr_diff -- A.exr B.exr`. Exit status 1 if any differ.

use std::io::Write;

/// Stop quietly when the reader has gone (`| head`).
fn say(written: std::io::Result<()>) {
    if written.is_err() {
        std::process::exit(2)
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [a, b] = args.as_slice() else {
        eprintln!("usage: exr_diff A.exr B.exr");
        std::process::exit(2)
    };
    let read = |p: &String| {
        rest_embree::output::read_exr_channels(p.as_ref()).unwrap_or_else(|e| {
            eprintln!("{p}: {e}");
            std::process::exit(2)
        })
    };
    let ((wa, ha, ca), (wb, hb, cb)) = (read(a), read(b));
    if (wa, ha) != (wb, hb) {
        eprintln!("{a} is {wa}x{ha}, {b} is {wb}x{hb}");
        std::process::exit(1)
    }
    let mut names: Vec<_> = ca.keys().chain(cb.keys()).cloned().collect();
    names.sort();
    names.dedup();
    let mut any = false;
    let mut out = std::io::stdout().lock();
    for n in names {
        let (Some(x), Some(y)) = (ca.get(&n), cb.get(&n)) else {
            say(writeln!(out, "{n:>10}: only in one file"));
            any = true;
            continue;
        };
        let (mut count, mut abs, mut rel) = (0usize, 0f32, 0f32);
        for (&p, &q) in x.iter().zip(y) {
            if p.to_bits() != q.to_bits() {
                count += 1;
                let d = (p - q).abs();
                abs = abs.max(d);
                rel = rel.max(d / p.abs().max(q.abs()));
            }
        }
        any |= count > 0;
        say(writeln!(
            out,
            "{n:>10}: {count:>8} of {} differ, max abs {abs:.3e}, max rel {rel:.3e}",
            x.len()
        ));
    }
    std::process::exit(i32::from(any))
}
