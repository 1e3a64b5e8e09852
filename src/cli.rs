//! The command line: `rest-embree render SCENE -o OUT.{exr,png} [options]`.

use crate::{accel, bench, output, render, scene};
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(
    name = "rest-embree",
    version = env!("REST_EMBREE_LONG_VERSION"),
    about = "Special-relativistic ray tracer (REST-frame algorithm)"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a scene file to an EXR (linear, with passes) or PNG (sRGB) image.
    Render(RenderArgs),
    /// Measure each backend's speed and error on the same scenes (default: the paper's lattice).
    Bench(BenchArgs),
    /// List the intersection backends of this build.
    Backends,
}

#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// A scene file to measure; without one, the paper's lattice at beta 0, 0.5, 0.9, 0.99.
    pub scene: Option<PathBuf>,
    /// Backends to measure (repeatable; default: every backend of this build).
    #[arg(long = "backend")]
    pub backends: Vec<String>,
    /// Image width (default 512).
    #[arg(long, default_value_t = 512)]
    pub width: u32,
    /// Image height (default 512).
    #[arg(long, default_value_t = 512)]
    pub height: u32,
    /// Samples per pixel (default 1).
    #[arg(long, default_value_t = 1)]
    pub samples: u32,
    /// Override any scene value, as for render.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Primary-ray passes per backend; the fastest counts.
    #[arg(long, default_value_t = 3)]
    pub repeat: usize,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Also write the rows as CSV to this file.
    #[arg(long)]
    pub csv: Option<PathBuf>,
}

#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// Output image; the format follows the extension (.exr or .png).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Intersection backend (see `rest-embree backends`).
    #[arg(long)]
    pub backend: Option<String>,
    /// Image width in pixels (overrides image.width).
    #[arg(long)]
    pub width: Option<i64>,
    /// Image height in pixels (overrides image.height).
    #[arg(long)]
    pub height: Option<i64>,
    /// Samples per pixel (overrides image.samples).
    #[arg(long)]
    pub samples: Option<i64>,
    /// World time of the imaging event (overrides camera.time).
    #[arg(long, allow_negative_numbers = true)]
    pub time: Option<f64>,
    /// Override any scene value with a TOML value, e.g. 'group.cube.velocity=[0.99,0,0]'.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

impl RenderArgs {
    /// The overrides in the order they apply: the dedicated flags, then every --set.
    pub fn overrides(&self) -> Vec<(String, String)> {
        let mut v = Vec::new();
        let mut flag = |name: &str, key: &str, val: Option<String>| {
            if let Some(x) = val {
                v.push((format!("--{name} {x}"), format!("{key}={x}")));
            }
        };
        flag("width", "image.width", self.width.map(|x| x.to_string()));
        flag("height", "image.height", self.height.map(|x| x.to_string()));
        flag(
            "samples",
            "image.samples",
            self.samples.map(|x| x.to_string()),
        );
        flag("time", "camera.time", self.time.map(|x| format!("{x:?}")));
        for s in &self.set {
            v.push((format!("--set {s}"), s.clone()));
        }
        v
    }
}

pub fn run(cli: Cli) -> ExitCode {
    match cli.command {
        Command::Backends => {
            for (i, name) in accel::backend_names().iter().enumerate() {
                println!("{name}{}", if i == 0 { " (default)" } else { "" });
            }
            ExitCode::SUCCESS
        }
        Command::Render(args) => report(run_render(&args)),
        Command::Bench(args) => report(run_bench(&args)),
    }
}

fn report(r: Result<(), String>) -> ExitCode {
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn set_threads(threads: Option<usize>) -> Result<(), String> {
    if let Some(n) = threads {
        if n == 0 {
            return Err("--threads: must be at least 1".into());
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| format!("--threads: {e}"))?;
    }
    Ok(())
}

fn run_bench(args: &BenchArgs) -> Result<(), String> {
    set_threads(args.threads)?;
    let backends = if args.backends.is_empty() {
        accel::backend_names()
            .iter()
            .map(|s| s.to_string())
            .collect()
    } else {
        args.backends.clone()
    };
    for b in &backends {
        accel::backend_by_name(b).map_err(|e| format!("--backend: {e}"))?;
    }
    let mut sets = vec![
        format!("image.width={}", args.width),
        format!("image.height={}", args.height),
        format!("image.samples={}", args.samples),
    ];
    sets.extend(args.set.iter().cloned());
    let cases = match &args.scene {
        None => bench::default_cases(&sets).map_err(|e| e.to_string())?,
        Some(path) => {
            let overrides: Vec<(String, String)> = sets
                .iter()
                .map(|s| (format!("--set {s}"), s.clone()))
                .collect();
            vec![bench::Case {
                name: path.display().to_string(),
                scene: scene::load_file(path, &overrides).map_err(|e| e.to_string())?,
            }]
        }
    };
    let rows = bench::run(&cases, &backends, args.repeat)?;
    println!("threads: {}", rayon::current_num_threads());
    print!("{}", bench::table(&rows));
    if let Some(p) = &args.csv {
        std::fs::write(p, bench::csv(&rows)).map_err(|e| format!("--csv {}: {e}", p.display()))?;
    }
    Ok(())
}

fn run_render(args: &RenderArgs) -> Result<(), String> {
    // Check everything that can be checked before the (possibly long) render.
    output::Format::for_path(&args.output).map_err(|e| format!("-o: {e}"))?;
    let backend_name = args
        .backend
        .clone()
        .unwrap_or_else(|| accel::default_backend_name().to_string());
    let backend = accel::backend_by_name(&backend_name).map_err(|e| format!("--backend: {e}"))?;
    set_threads(args.threads)?;
    let scene = scene::load_file(&args.scene, &args.overrides()).map_err(|e| e.to_string())?;
    let (frame, stats) = render::render(&scene, backend.as_ref())?;
    if stats.nonfinite_pixels > 0 {
        eprintln!(
            "warning: {} pixels came out NaN or infinite and were set to black; please report this scene",
            stats.nonfinite_pixels
        );
    }
    output::write(&frame, &args.output)?;
    if !args.quiet {
        let secs = stats.trace_time.as_secs_f64();
        eprintln!(
            "{}: {}x{}, {} spp, {} primitives in {} groups, backend {backend_name}: build {:.3} s, render {:.3} s ({:.2} M primary rays/s)",
            args.output.display(),
            scene.image.frame_size().0,
            scene.image.frame_size().1,
            scene.image.samples,
            scene.primitive_count(),
            scene.groups.len(),
            stats.build_time.as_secs_f64(),
            secs,
            stats.primary_rays as f64 / secs.max(1e-9) / 1e6
        );
    }
    Ok(())
}
