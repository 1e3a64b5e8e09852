//! The bench's billion-primitive row and the paper's lattice as a whole command, each measured
//! in a process of its own: `rest-embree bench-lattice N SIZE BACKEND THREADS` (hidden) renders
//! the paper's lattice grown to N³ nodes, at SIZE², 1 sample per pixel, 0.9c, to an EXR with
//! every pass, by running the `render` command itself here, and prints a Markdown line (the
//! whole command's wall time and the process's peak memory: a fresh process, so no earlier
//! row's heap counts) and then `whole_s` and the seconds.

use crate::bench;
use std::time::Instant;

/// What the child prints after its Markdown line: this word, then the whole command's seconds.
pub(crate) const WALL: &str = "whole_s";

/// The billion-node lattice, once per backend; then the paper's own lattice (10³) at the same
/// size, as issue 24 times the whole command, the fastest of three processes per backend (taken
/// in turn), with the ratio of the first backend's time to the others'.
pub(crate) fn summary(quick: bool, backends: &[&str]) -> String {
    let (n, size) = if quick { (200, 256) } else { (1000, 1024) };
    let mut out = String::new();
    for b in backends {
        out.push_str(&child(n, size, b).0);
        out.push('\n');
    }
    let mut best: Vec<(String, Option<f64>)> = vec![(String::new(), None); backends.len()];
    for _ in 0..3 {
        for (b, kept) in backends.iter().zip(best.iter_mut()) {
            let (line, wall) = child(10, size, b);
            if kept.1.is_none() || wall.is_some_and(|w| kept.1.is_some_and(|k| w < k)) {
                *kept = (line, wall);
            }
        }
    }
    for (line, _) in &best {
        out.push_str(line);
        out.push('\n');
    }
    if let (Some(first), Some(Some(base))) = (backends.first(), best.first().map(|b| b.1)) {
        for (b, (_, wall)) in backends.iter().zip(&best).skip(1) {
            if let Some(w) = wall {
                out.push_str(&format!(
                    "- lattice 10^3 at {size}^2, whole command time {b} / {first} = {:.2}x\n",
                    w / base
                ));
            }
        }
    }
    out
}

/// Run `bench-lattice` in a process of its own: its line, and the whole command's seconds.
fn child(n: u32, size: u32, backend: &str) -> (String, Option<f64>) {
    let threads = rayon::current_num_threads().to_string();
    let run = std::env::current_exe().and_then(|exe| {
        std::process::Command::new(exe)
            .args([
                "bench-lattice",
                &n.to_string(),
                &size.to_string(),
                backend,
                &threads,
            ])
            .output()
    });
    match run {
        Ok(o) => {
            let text = String::from_utf8_lossy(&o.stdout);
            let wall = text
                .lines()
                .find_map(|l| l.strip_prefix(WALL))
                .and_then(|w| w.trim().parse().ok());
            let line = text
                .lines()
                .find(|l| l.starts_with("- "))
                .unwrap_or_default()
                .to_string();
            (line, wall)
        }
        Err(e) => (
            format!("- lattice {n}^3, {backend}: not measured: {e}"),
            None,
        ),
    }
}

/// Render it here and say what it cost: a Markdown line, and the whole command's seconds.
pub(crate) fn here(n: u32, size: u32, backend: &str, threads: &str) -> (String, Option<f64>) {
    let dir =
        std::env::temp_dir().join(format!("rest-embree-bench-lattice-{}", std::process::id()));
    let what = format!(
        "- lattice {n}^3 ({} primitives) at {size}^2, 1 spp, 0.9c, EXR, {backend}",
        {
            let n = n as u64;
            n * n * n + 3 * (n - 1) * n * n
        }
    );
    if let Err(e) = std::fs::create_dir_all(&dir) {
        return (format!("{what}: not measured: {e}"), None);
    }
    let scene = dir.join("lattice.toml");
    let image = dir.join("lattice.exr");
    let text = bench::PAPER_SCENES
        .iter()
        .find(|(name, _)| *name == "lattice")
        .map(|(_, t)| *t)
        .expect("the paper's lattice is built in");
    let half = (n as f64 - 1.0) / 2.0;
    let sets = [
        format!("image.width={size}"),
        format!("image.height={size}"),
        "image.samples=1".into(),
        format!("group.lattice.object.lattice.counts=[{n},{n},{n}]"),
        format!(
            "group.lattice.object.lattice.origin=[0,{},{}]",
            -half, -half
        ),
        "group.lattice.velocity=[-0.9,0,0]".into(),
    ];
    let mut args: Vec<String> = ["rest-embree", "render"].map(String::from).to_vec();
    args.push(scene.display().to_string());
    args.extend(["-o".into(), image.display().to_string()]);
    args.extend([
        "--backend".into(),
        backend.into(),
        "--threads".into(),
        threads.into(),
    ]);
    for s in sets {
        args.extend(["--set".into(), s]);
    }
    let result = std::fs::write(&scene, text)
        .map_err(|e| e.to_string())
        .and_then(|()| {
            let cli =
                <super::Cli as clap::Parser>::try_parse_from(&args).map_err(|e| e.to_string())?;
            bench::reset_peak();
            let start = Instant::now();
            let code = super::run(cli);
            let wall = start.elapsed().as_secs_f64();
            (code == std::process::ExitCode::SUCCESS)
                .then_some(wall)
                .ok_or_else(|| "the render failed".to_string())
        });
    let _ = std::fs::remove_dir_all(&dir);
    match (result, bench::peak_mib()) {
        (Ok(wall), Some(peak)) => (
            format!("{what}: whole command {wall:.2} s, peak memory {peak:.0} MiB"),
            Some(wall),
        ),
        (Ok(wall), None) => (format!("{what}: whole command {wall:.2} s"), Some(wall)),
        (Err(e), _) => (format!("{what}: not measured: {e}"), None),
    }
}
