//! The command line: `rest-embree render SCENE -o OUT.{exr,png} [options]` (a still, a tile of
//! one: `tiles.rs`, or a film's frames: `film.rs`), `assemble`, `farm slurm` (`farm.rs`),
//! `backends` and `bench`.

mod bench_cmd;
mod bench_lattice;
mod farm;
mod film;
mod hints;
mod tiles;
pub(crate) use crate::text::say;
mod view_cmd;

use crate::render::Passes;
use crate::{accel, bench, memory, output, render, scene, Error};
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(
    name = "rest-embree",
    version = env!("REST_EMBREE_LONG_VERSION"),
    about = "Special-relativistic ray tracer (REST-frame algorithm)"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub(crate) enum Command {
    /// Render a scene file to an EXR (linear, with passes) or PNG (sRGB) image.
    Render(RenderArgs),
    /// Explore a scene in the browser: velocities, camera and passes on controls, refined while
    /// nothing changes; save the view as a scene file or render it to an EXR.
    View(view_cmd::ViewArgs),
    /// Measure each backend's speed and error on the same scenes (default: the paper's lattice).
    Bench(BenchArgs),
    /// List the intersection backends of this build, and the instruction set Embree runs here.
    Backends,
    /// Join EXR tiles (from `render --tiles NxM --tile I`) into the EXR of the whole image.
    Assemble {
        /// The whole image (EXR).
        #[arg(short, long)]
        output: PathBuf,
        /// The tiles, in any order.
        #[arg(required = true)]
        tiles: Vec<PathBuf>,
        /// The most memory joining may use, e.g. 2G (default: the machine's available memory);
        /// joining is done in bands of rows, and refused before it starts if even that needs
        /// more.
        #[arg(long, value_name = "SIZE", value_parser = memory::parse_size)]
        max_memory: Option<u64>,
    },
    /// Render on a cluster through its scheduler: `farm slurm SCENE -o OUT ...`.
    Farm {
        #[command(subcommand)]
        scheduler: farm::Scheduler,
    },
    /// The bench's own: read a generated scene file of one kind (`groups` or `mesh`) and size in
    /// this fresh process, and print what it cost.
    #[command(hide = true)]
    BenchSceneFile { kind: String, size: usize },
    /// The bench's own: render the paper's lattice grown to N^3 nodes at SIZE^2 in this fresh
    /// process (`bench_lattice.rs`), and print what it cost.
    #[command(hide = true)]
    BenchLattice {
        n: u32,
        size: u32,
        backend: String,
        threads: String,
    },
    /// A profiling probe: nanoseconds per primary ray on the paper's lattice (src/bench/probe.rs,
    /// `primary_ns`): MODE is layer, layer-unfused, bare, bvh or render; EMBREE the Embree
    /// backend's name for the modes that use it (embree, embree-16, embree-8). Prints the
    /// fastest pass of as many as fit in SECONDS, in ns per pixel.
    #[command(hide = true)]
    ProbePrimaryNs {
        #[arg(default_value = "layer")]
        mode: String,
        #[arg(default_value_t = 0.0)]
        beta: f64,
        #[arg(default_value_t = 512)]
        size: u32,
        #[arg(default_value_t = 2.0)]
        seconds: f64,
        #[arg(default_value = "embree")]
        embree: String,
        #[arg(default_value_t = 1)]
        threads: usize,
    },
    /// A profiling probe: what many velocity groups cost against one group of the same boxes
    /// (src/bench/probe.rs, `group_visits`).
    #[command(hide = true)]
    ProbeGroupVisits {
        #[arg(default_value_t = 10000)]
        groups: usize,
        #[arg(default_value = "embree")]
        backend: String,
        #[arg(default_value_t = 256)]
        size: u32,
        #[arg(default_value_t = 1)]
        threads: usize,
    },
}

#[derive(clap::Args, Debug)]
pub(crate) struct BenchArgs {
    /// Measure this scene file instead of the fixed suite (the paper's lattice at four speeds,
    /// a 100^3 lattice, 1 to 10,000 velocity groups, merging).
    pub scene: Option<PathBuf>,
    /// Settings to measure on SCENE (repeatable): a backend name, optionally with a skip
    /// switched off, e.g. 'embree no-cull' (default: every backend of this build).
    #[arg(long = "backend")]
    pub backends: Vec<String>,
    /// Smaller images and scenes: the whole suite in well under a minute.
    #[arg(long)]
    pub quick: bool,
    /// Only this case of the suite, or where no case has this name, every case whose name
    /// contains it (repeatable).
    #[arg(long = "case")]
    pub cases: Vec<String>,
    /// Override any value of SCENE, as for render.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Primary-ray passes and renders per row; the fastest of each counts.
    #[arg(long, default_value_t = 3)]
    pub repeat: usize,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Where to write bench.md, bench.csv and bench.svg.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

#[derive(clap::Args, Debug)]
pub(crate) struct RenderArgs {
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
    #[arg(long, allow_negative_numbers = true, value_parser = finite)]
    pub time: Option<f64>,
    /// Override any scene value with a TOML value, e.g. 'group.cube.velocity=[0.99,0,0]'.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Store colour, alpha, normals and the Doppler factor as half floats in an EXR (positions,
    /// depth, lookback and ids stay full floats); values beyond ±65504 saturate there.
    #[arg(long)]
    pub half: bool,
    /// The passes an EXR holds beside colour and alpha, comma-separated (`none` for colour and
    /// alpha alone; see `[image] passes`): depth, lookback, doppler, object_id, material_id,
    /// primitive_id, normal, position, rest_position, camera_position, cryptomatte; or the
    /// shorthands all (the default), ids, relativity.
    #[arg(long, value_name = "LIST")]
    #[arg(value_parser = pass_list)]
    pub passes: Option<String>,
    /// An EXR's compression: zip (default), zips, piz, rle or none.
    #[arg(long, value_name = "NAME", value_parser = exr_compression)]
    pub compression: Option<output::Compression>,
    /// The most memory the render may use, e.g. 8G or 512M (default: the machine's available
    /// memory); a render that would need more is refused before it starts.
    #[arg(long, value_name = "SIZE", value_parser = memory::parse_size)]
    pub max_memory: Option<u64>,
    /// Render only these frames of the scene's film: A..B (both included) or one frame N,
    /// counted from 0.
    #[arg(long, value_name = "A..B", value_parser = film::parse_frames)]
    pub frames: Option<(u64, u64)>,
    /// Render one still of a scene with a [film] to a plain file name: frame N with
    /// `--frames N`, else the scene's own view (its camera's time). `--frames N` with a plain
    /// name does the same without it.
    #[arg(long)]
    pub still: bool,
    /// Skip the frames of a film whose files are finished images of this very render (every
    /// block decodes, the size and the render's id match); likewise a still or a tile.
    #[arg(long)]
    pub resume: bool,
    /// Render one tile of a grid of N columns and M rows over the image (with --tile), to an
    /// EXR that `rest-embree assemble` joins with the others.
    #[arg(long, value_name = "NxM", value_parser = tiles::parse_grid, requires = "tile")]
    pub tiles: Option<(u32, u32)>,
    /// Which tile of --tiles: 0 is the top left, counted row by row.
    #[arg(long, value_name = "I", requires = "tiles")]
    pub tile: Option<u32>,
    /// Render in rounds of samples until this many seconds have passed (a round that would
    /// end later is not begun; at least one is rendered); the scene's samples stay the most.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = seconds)]
    pub max_time: Option<f64>,
    /// Render in rounds of samples until the estimated RMS noise of the image (the standard
    /// error of the pixels' means, linear RGB) is at most this; the scene's samples stay the
    /// most.
    #[arg(long, value_name = "RMS", allow_negative_numbers = true, value_parser = positive)]
    pub target_rms: Option<f64>,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

impl RenderArgs {
    /// When a progressive render stops (None: not progressive, every sample at once).
    fn stop_at(&self) -> Option<render::StopAt> {
        (self.max_time.is_some() || self.target_rms.is_some()).then(|| render::StopAt {
            max_time: self.max_time.map(std::time::Duration::from_secs_f64),
            target_rms: self.target_rms,
        })
    }
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
        if let Some(list) = &self.passes {
            // Shown as typed; applied as the TOML array of its names.
            let names: Vec<String> = list
                .split(',')
                .map(str::trim)
                .filter(|n| !n.is_empty())
                .map(|n| format!("{n:?}"))
                .collect();
            v.push((
                format!("--passes {list}"),
                format!("image.passes=[{}]", names.join(", ")),
            ));
        }
        for s in &self.set {
            v.push((format!("--set {s}"), s.clone()));
        }
        v
    }
}

/// A finite number above 0 (a budget of noise).
fn positive(text: &str) -> Result<f64, String> {
    match finite(text)? {
        v if v > 0.0 => Ok(v),
        v => Err(format!("must be above 0 (got {v})")),
    }
}

/// The most seconds a time budget may be (about 31 years: any more is a mistake).
pub(crate) const MAX_SECONDS: f64 = 1e9;

/// A time budget in seconds: above 0 and at most `MAX_SECONDS`.
pub(crate) fn seconds(text: &str) -> Result<f64, String> {
    match positive(text)? {
        v if v <= MAX_SECONDS => Ok(v),
        v => Err(format!(
            "must be at most {MAX_SECONDS:e} seconds, about 31 years (got {v:e})"
        )),
    }
}

/// A `--passes` list: names separated by commas, none of them empty, and `none` alone (with
/// other names it says two things; so does `all` with `none`). The names themselves are
/// checked as `[image] passes` are.
fn pass_list(text: &str) -> Result<String, String> {
    let names: Vec<&str> = text.split(',').map(str::trim).collect();
    if names.iter().all(|n| n.is_empty()) {
        return Err(
            "is empty: give pass names separated by commas, `all`, or `none` for colour and alpha alone"
                .into(),
        );
    }
    if names.iter().any(|n| n.is_empty()) {
        return Err(format!("`{text}` has an empty name between commas"));
    }
    if names.len() > 1 && names.contains(&"none") {
        return Err(format!(
            "`{text}`: `none` (colour and alpha alone) cannot stand with other passes"
        ));
    }
    Ok(text.to_string())
}

/// A finite number (clap takes `nan` and `inf` for f64).
fn finite(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(format!("must be a finite number (got {v:?})")),
        Err(e) => Err(e.to_string()),
    }
}

/// The `rest-embree` command: parse the command line and run it. Help and version print and
/// exit 0; every argument error, like every other user error, prints and exits 1.
pub fn main() -> ExitCode {
    // Ctrl-C, SIGTERM, SIGHUP: no half-written file is left behind (a handler that cannot be
    // installed only loses that).
    let _ = ctrlc::set_handler(|| {
        // A viewer stops serving and returns, cleaning up itself.
        if crate::view::interrupt() {
            return;
        }
        output::file::remove_partial_files();
        eprintln!("interrupted");
        std::process::exit(130);
    });
    match parse() {
        Ok(cli) => run(cli),
        Err(code) => code,
    }
}

fn exr_compression(name: &str) -> Result<output::Compression, String> {
    output::Compression::by_name(name)
        .ok_or_else(|| format!("one of {}", output::Compression::NAMES.join(", ")))
}

fn parse() -> Result<Cli, ExitCode> {
    Cli::try_parse().map_err(|e| {
        let _ = e.print();
        if e.use_stderr() {
            let args: Vec<String> = std::env::args().collect();
            if let Some(hint) = hints::quoting_hint(&args) {
                eprintln!("\n{hint}");
            }
            ExitCode::FAILURE
        } else {
            ExitCode::SUCCESS
        }
    })
}

fn run(cli: Cli) -> ExitCode {
    match cli.command {
        Command::Backends => report(accel::backend_report().map(|lines| {
            for line in lines {
                say(line);
            }
        })),
        Command::Render(args) => report(run_render(&args)),
        Command::View(args) => report(view_cmd::run_view(&args)),
        Command::Bench(args) => report(bench_cmd::run_bench(&args)),
        Command::Assemble {
            output,
            tiles,
            max_memory,
        } => {
            memory::set_limit(max_memory);
            report(run_assemble(&output, &tiles))
        }
        Command::Farm { scheduler } => report(farm::run(&scheduler)),
        Command::BenchSceneFile { kind, size } => {
            say(bench::scene_file_here(&kind, size));
            ExitCode::SUCCESS
        }
        Command::BenchLattice {
            n,
            size,
            backend,
            threads,
        } => {
            let (line, wall) = bench_lattice::here(n, size, &backend, &threads);
            say(line);
            if let Some(wall) = wall {
                say(format_args!("{} {wall}", bench_lattice::WALL));
            }
            ExitCode::SUCCESS
        }
        Command::ProbePrimaryNs {
            mode,
            beta,
            size,
            seconds,
            embree,
            threads,
        } => match bench::probe::primary_ns(&mode, beta, size, seconds, &embree, threads) {
            Ok(ns) => {
                say(format_args!(
                    "{mode} beta={beta} {size}x{size}: {ns:.2} ns per pixel"
                ));
                ExitCode::SUCCESS
            }
            Err(e) => report(Err(crate::Error::flag("probe-primary-ns", e.to_string()))),
        },
        Command::ProbeGroupVisits {
            groups,
            backend,
            size,
            threads,
        } => match bench::probe::group_visits(groups, &backend, size, threads) {
            Ok(text) => {
                print!("{text}");
                ExitCode::SUCCESS
            }
            Err(e) => report(Err(crate::Error::flag("probe-group-visits", e.to_string()))),
        },
    }
}

fn report(r: crate::Result<()>) -> ExitCode {
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // A message may quote a file's text: each line cut and its control characters
            // escaped, whatever the file held.
            eprintln!("{}", crate::text::terminal_safe(&format!("error: {e}")));
            ExitCode::FAILURE
        }
    }
}

/// Render to `args.output`: an EXR with every pass, whole; a PNG with colour alone (the passes,
/// and with several samples their extra ray per pixel, are skipped), written strip by strip as it
/// is rendered, so a large image is never held whole. A bar shows the progress when stderr is a
/// terminal (and not --quiet).
fn render_to_file(
    scene: &scene::Scene,
    world: &render::World,
    backend_name: &str,
    format: output::Format,
    args: &RenderArgs,
    path: &Path,
) -> crate::Result<render::RenderStats> {
    use std::io::IsTerminal;
    let t1 = std::time::Instant::now();
    let (w, h) = scene.image.frame_size();
    let watching = !args.quiet && std::io::stderr().is_terminal();
    let pixels = u64::from(w) * u64::from(h);
    let progress = watching.then(|| match args.stop_at() {
        // Rounds of samples: a bar per round, and the rounds, samples and noise so far.
        Some(_) => render::Progress::rounds(pixels),
        None => render::Progress::new(pixels),
    });
    let progress = progress.as_ref();
    let mut stats = render::RenderStats::default();
    let written = match format {
        output::Format::Exr => {
            let exr = output::ExrOptions {
                compression: args.compression.unwrap_or_default(),
                half: args.half,
                // The flags that change nothing in the picture (--threads, -o) stay out of the
                // header: the same render makes the same file.
                ..output::ExrOptions::for_render(
                    scene,
                    backend_name,
                    &args.scene.display().to_string(),
                    &args
                        .overrides()
                        .into_iter()
                        .map(|(shown, _)| shown)
                        .collect::<Vec<_>>(),
                )
            };
            let written = output::write_exr_in_strips(path, (w, h), true, &exr, |put| {
                let strip = memory::STRIP_PIXELS;
                // Colour and alpha alone need no centre ray per pixel.
                let passes = match scene.image.passes.is_empty() {
                    true => Passes::Colour,
                    false => Passes::All,
                };
                stats = render_pixels(scene, world, passes, strip, progress, args, put)?;
                Ok(())
            });
            progress.inspect(|p| p.finish());
            // Rendering and writing are one here.
            stats.trace_time = t1.elapsed();
            written
        }
        output::Format::Png => {
            let alpha = scene.image.is_transparent();
            let shown: Vec<String> = args.overrides().into_iter().map(|(s, _)| s).collect();
            let id = output::header::render_id(scene, backend_name, &shown);
            let written = output::write_png_in_strips(path, (w, h), alpha, Some(&id), |put| {
                let strip = memory::STRIP_PIXELS;
                let colour = Passes::Colour;
                stats = render_pixels(scene, world, colour, strip, progress, args, put)?;
                Ok(())
            });
            progress.inspect(|p| p.finish());
            // Rendering and writing are one here.
            stats.trace_time = t1.elapsed();
            written
        }
    };
    // A render that failed while its file was written (a fault the backend recorded) is
    // reported as itself, naming the scene; the file was not written.
    written.map_err(|e| match e.root() {
        Error::Backend(m) => Error::backend(format!(
            "rendering `{}` into `{}` failed: {m}; the file was not written",
            args.scene.display(),
            path.display()
        )),
        e => e,
    })?;
    Ok(stats)
}

/// Render the frame and hand its pixels to `put`: strip by strip as they are rendered, or,
/// with --max-time or --target-rms, whole after the last round (and say what the rounds did).
fn render_pixels(
    scene: &scene::Scene,
    world: &render::World,
    passes: Passes,
    strip: u64,
    progress: Option<&render::Progress>,
    args: &RenderArgs,
    put: &mut dyn FnMut(&render::Frame) -> std::result::Result<(), crate::Cause>,
) -> std::result::Result<render::RenderStats, crate::Cause> {
    let Some(stop) = args.stop_at() else {
        return render::render_world_in_strips(scene, world, passes, strip, progress, put);
    };
    let (frame, stats, done) = render::render_progressive(scene, world, passes, stop, progress)?;
    progress.inspect(|p| p.finish());
    put(&frame)?;
    if !args.quiet {
        let rms = done
            .rms
            .map_or("not estimated (one round)".to_string(), |r| {
                format!("{r:.3e}")
            });
        eprintln!(
            "{} spp in {} rounds, stopped by {}: estimated RMS noise {rms}",
            done.samples, done.rounds, done.stopped_by
        );
    }
    Ok(stats)
}

/// Refuse a render whose frame and geometry would not fit in memory, blaming the image size.
fn fits_in_memory(
    scene: &scene::Scene,
    format: output::Format,
    args: &RenderArgs,
) -> crate::Result<()> {
    let (w, h) = scene.image.frame_size();
    let prims = scene.primitive_count() as u64;
    let need = memory_need(scene, format, rayon::current_num_threads());
    let what = format!("a {w}x{h} render of {prims} primitives");
    let Some(why) = memory::too_much(need, &what) else {
        return Ok(());
    };
    let why = format!(
        "{why}; render it in crops (image.crop) or smaller, or allow more with --max-memory"
    );
    Err(match (args.width, args.height) {
        (Some(_), _) => Error::flag("--width", why),
        (None, Some(_)) => Error::flag("--height", why),
        _ => Error::Scene(scene::SceneError::new(
            args.scene.display().to_string(),
            "image.width",
            why,
        )),
    })
}

/// The memory a render of `scene` to `format` on `threads` threads needs, estimated: a strip of
/// the image (whole pairs of rows of tiles: images are written strip by strip) and the
/// scene's primitives.
pub(crate) fn memory_need(scene: &scene::Scene, format: output::Format, threads: usize) -> u64 {
    let (w, _) = scene.image.frame_size();
    let (fw, fh) = scene.image.frame_size();
    let pixels = u64::from(fw) * u64::from(fh);
    let row = u64::from(w) * u64::from(render::TILE);
    let strip = |least: u64| least.max(4 * threads as u64 * row) + 2 * row;
    let held = match format {
        output::Format::Exr => pixels
            .min(strip(memory::STRIP_PIXELS))
            .saturating_mul(memory::BYTES_PER_PIXEL_EXR),
        output::Format::Png => pixels
            .min(strip(memory::STRIP_PIXELS))
            .saturating_mul(memory::BYTES_PER_PIXEL_PNG),
    };
    held.saturating_add(scene.primitive_bytes())
}

/// Whether two paths name one existing file (through links).
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// More threads than this per core only costs memory (each has a stack) and switching.
const THREADS_PER_CORE: usize = 8;

fn set_threads(threads: Option<usize>) -> crate::Result<()> {
    if let Some(n) = threads {
        if n == 0 {
            return Err(Error::flag("--threads", "must be at least 1"));
        }
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        if n > THREADS_PER_CORE * cores {
            return Err(Error::flag(
                "--threads",
                format!(
                    "{n} is more than {THREADS_PER_CORE} per core ({} on this machine's {cores} cores)",
                    THREADS_PER_CORE * cores
                ),
            ));
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| Error::flag("--threads", e))?;
    }
    Ok(())
}

fn run_render(args: &RenderArgs) -> crate::Result<()> {
    // Check everything that can be checked before the (possibly long) render.
    let format = output::Format::for_path(&args.output).map_err(|e| e.on_flag("-o"))?;
    let backend_name = args
        .backend
        .clone()
        .unwrap_or_else(|| accel::default_backend_name().to_string());
    let backend = accel::backend_by_name(&backend_name).map_err(|e| e.on_flag("--backend"))?;
    set_threads(args.threads)?;
    if same_file(&args.scene, &args.output) {
        return Err(Error::flag(
            "-o",
            format!(
                "`{}` is the scene file itself; it was left as it is",
                args.output.display()
            ),
        ));
    }
    memory::set_limit(args.max_memory);
    // A tiled image may be larger than one frame; its tile's frame is checked below.
    let frame = match args.tiles {
        Some(_) => scene::FrameSize::InTiles,
        None => scene::FrameSize::Checked,
    };
    let mut scene = scene::load_file_as(&args.scene, &args.overrides(), frame)?;
    // A PNG is opaque (the background composited, alpha 1) unless the scene asks for
    // `transparent = true` (then RGBA); an EXR is transparent unless it asks otherwise.
    if format == output::Format::Png {
        scene.image.transparent.get_or_insert(false);
    }
    if let (Some(grid), Some(index)) = (args.tiles, args.tile) {
        let what = format!("tile {index}");
        output::file::refuse_link(&args.output, &what).map_err(|e| e.on_flag("-o"))?;
        let shown = format!("--tiles {}x{} --tile {index}", grid.0, grid.1);
        scene.image.crop = Some(tiles::tile_crop(&scene, format, grid, index, &shown)?);
    }
    fits_in_memory(&scene, format, args)?;
    // Said once per command (a film's frames share it), and not under --quiet.
    if let Some(w) = render::extrapolation_warning(&scene).filter(|_| !args.quiet) {
        eprintln!("{w}");
    }
    // One frame of a film to a plain name (no run of #): a still of that frame.
    let plain = !args
        .output
        .file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.contains('#'));
    let single = args.frames.filter(|(a, b)| a == b).map(|(a, _)| a);
    if plain && (single.is_some() || args.still) {
        match (&scene.film, single) {
            (Some(film), Some(k)) => {
                film::frame_range(film, Some((k, k)))?;
                scene = scene.film_frame(k).expect("a film");
            }
            (None, Some(_)) => {
                return Err(Error::flag(
                    "--frames",
                    "the scene is not a film: add a [film] table (start, end, fps or step), or leave --frames out",
                ))
            }
            (_, None) => scene.film = None,
        }
    } else if args.still {
        return Err(Error::flag(
            "--still",
            "renders one picture: give a plain file name (no run of #), and at most one frame",
        ));
    } else if scene.film.is_some() || args.frames.is_some() {
        if let Some(flag) = [
            ("--max-time", args.max_time),
            ("--target-rms", args.target_rms),
        ]
        .iter()
        .find_map(|(f, v)| v.map(|_| *f))
        {
            return Err(Error::flag(
                flag,
                "applies to a still image; a film's frames render their `samples` each",
            ));
        }
        return film::run(&scene, backend.as_ref(), &backend_name, format, args);
    }
    // A still (or a farm's tile) already written whole by this very render is kept.
    if args.resume && std::fs::symlink_metadata(&args.output).is_ok() {
        let shown: Vec<String> = args.overrides().into_iter().map(|(s, _)| s).collect();
        let id = output::header::render_id(&scene, &backend_name, &shown);
        let size = scene.image.frame_size();
        match output::finished(&args.output, format, size, &id) {
            Ok(()) => {
                if !args.quiet {
                    eprintln!(
                        "{}: a finished image of this render already (--resume): kept",
                        args.output.display()
                    );
                }
                return Ok(());
            }
            Err(why) if !args.quiet => eprintln!(
                "{} is not a finished image of this render ({why}): rendering it again",
                args.output.display()
            ),
            Err(_) => {}
        }
    }
    let t0 = std::time::Instant::now();
    let world = render::World::build(&scene, backend.as_ref())?;
    let build_time = t0.elapsed();
    // Into a folder that does not exist yet, as a film's frames go.
    if let Some(dir) = args.output.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| {
            Error::flag(
                "-o",
                format!("cannot make the folder {}: {e}", dir.display()),
            )
        })?;
    }
    let mut stats = render_to_file(&scene, &world, &backend_name, format, args, &args.output)?;
    stats.build_time = build_time;
    warn_nonfinite(&stats, args.quiet);
    if !args.quiet {
        let secs = stats.trace_time.as_secs_f64();
        eprintln!(
            "{}: {}x{}, {} spp, {} primitive{} in {} group{}, backend {backend_name}: build {:.3} s, render {:.3} s ({:.2} M primary rays/s)",
            args.output.display(),
            scene.image.frame_size().0,
            scene.image.frame_size().1,
            stats.samples.unwrap_or(scene.image.samples),
            scene.primitive_count(),
            if scene.primitive_count() == 1 { "" } else { "s" },
            scene.groups.len(),
            if scene.groups.len() == 1 { "" } else { "s" },
            stats.build_time.as_secs_f64(),
            secs,
            stats.primary_rays as f64 / secs.max(1e-9) / 1e6
        );
    }
    Ok(())
}

fn run_assemble(output: &Path, tiles: &[PathBuf]) -> crate::Result<()> {
    if output::Format::for_path(output).map_err(|e| e.on_flag("-o"))? != output::Format::Exr {
        return Err(Error::flag(
            "-o",
            "the assembled image is an EXR: give a .exr",
        ));
    }
    if tiles.iter().any(|t| same_file(t, output)) {
        return Err(Error::flag(
            "-o",
            "is one of the tiles; it was left as it is",
        ));
    }
    output::assemble(tiles, output)
}

fn warn_nonfinite(stats: &render::RenderStats, quiet: bool) {
    if stats.nonfinite_pixels > 0 && !quiet {
        eprintln!(
            "warning: {} pixels came out NaN or infinite and were set to black; please report this scene",
            stats.nonfinite_pixels
        );
    }
}
