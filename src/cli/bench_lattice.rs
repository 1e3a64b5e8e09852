//! The bench's billion-primitive row, measured in a process of its own: `rest-embree
//! bench-lattice N SIZE BACKEND THREADS` (hidden) renders the paper's lattice grown to N³
//! nodes, at SIZE², 1 sample per pixel, 0.9c, to an EXR with every pass, by running the
//! `render` command itself here, and prints a Markdown line: the whole command's wall time and
//! the process's peak memory (a fresh process, so no earlier row's heap counts).

use crate::bench;
use std::time::Instant;

/// Spawn this program once per backend and collect their lines.
pub(crate) fn summary(quick: bool, backends: &[&str]) -> String {
    let (n, size) = if quick { (200, 256) } else { (1000, 1024) };
    let threads = rayon::current_num_threads().to_string();
    let mut out = String::new();
    for b in backends {
        let line = std::env::current_exe()
            .and_then(|exe| {
                std::process::Command::new(exe)
                    .args([
                        "bench-lattice",
                        &n.to_string(),
                        &size.to_string(),
                        b,
                        &threads,
                    ])
                    .output()
            })
            .map(|o| {
                let text = String::from_utf8_lossy(&o.stdout);
                text.lines().last().unwrap_or_default().to_string()
            })
            .unwrap_or_else(|e| format!("- lattice {n}^3, {b}: not measured: {e}"));
        out.push_str(&line);
        out.push('\n');
    }
    out
}

/// Render it here and say what it cost.
pub(crate) fn here(n: u32, size: u32, backend: &str, threads: &str) -> String {
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
        return format!("{what}: not measured: {e}");
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
        (Ok(wall), Some(peak)) => {
            format!("{what}: whole command {wall:.2} s, peak memory {peak:.0} MiB")
        }
        (Ok(wall), None) => format!("{what}: whole command {wall:.2} s"),
        (Err(e), _) => format!("{what}: not measured: {e}"),
    }
}
