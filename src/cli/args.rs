//! The command line's words: its subcommands and flags as clap reads them, and the parsers
//! that check a flag's value as it is read.

use super::{farm, film, tiles, view_cmd};
use crate::{memory, output, render};
use clap::{Parser, Subcommand};
use std::path::PathBuf;

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
    // A negative number is a flag's value, so `--width -5` is said to be no width (clap
    // otherwise takes it for an unknown flag).
    #[command(allow_negative_numbers = true)]
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
    /// Smaller images and scenes, and shorter timings: the whole suite in under a minute on two
    /// cores, for a look (its figures vary more than the full suite's).
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
    #[arg(long, default_value_t = 3, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..))]
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
    /// What a still's file records of the command line (`renderOverrides`, and the render id
    /// `--resume` compares): the overrides as given, then the rule that stopped its rounds
    /// (--max-time, --target-rms), which decides how many samples it took.
    pub(super) fn recorded(&self) -> Vec<String> {
        let mut v: Vec<String> = self.overrides().into_iter().map(|(s, _)| s).collect();
        if let Some(t) = self.max_time {
            v.push(format!("--max-time {t:?}"));
        }
        if let Some(r) = self.target_rms {
            v.push(format!("--target-rms {r:?}"));
        }
        v
    }

    /// The first of --max-time and --target-rms given: a still's rounds, which a film's frames
    /// and the tiles of --tiles do not take.
    pub(super) fn stop_flag(&self) -> Option<&'static str> {
        [
            ("--max-time", self.max_time),
            ("--target-rms", self.target_rms),
        ]
        .into_iter()
        .find_map(|(f, v)| v.map(|_| f))
    }

    pub(super) fn stop_at(&self) -> Option<render::StopAt> {
        (self.max_time.is_some() || self.target_rms.is_some()).then(|| render::StopAt {
            max_time: self.max_time.map(std::time::Duration::from_secs_f64),
            target_rms: self.target_rms,
        })
    }
}

impl RenderArgs {
    /// Flags that would otherwise be lost without a word: a dedicated flag and a `--set` of
    /// the same key (the later `--set` won), and an EXR's options with `-o` naming a PNG.
    pub(super) fn check_flags(&self, format: output::Format) -> crate::Result<()> {
        // The keys `overrides` sets, each with the flag that set it (`--width 20`, `--set …`).
        let all = self.overrides();
        let keyed: Vec<(&str, &str)> = all
            .iter()
            .filter_map(|(shown, set)| Some((shown.as_str(), set.split_once('=')?.0.trim())))
            .collect();
        let (sets, dedicated): (Vec<_>, Vec<_>) = keyed
            .iter()
            .partition(|(shown, _)| shown.starts_with("--set "));
        for &&(shown, key) in &dedicated {
            if let Some(&&(again, _)) = sets.iter().find(|s| s.1 == key) {
                let flag = shown.split(' ').next().unwrap_or(shown);
                return Err(crate::Error::flag(
                    flag,
                    format!("`{again}` sets the same value: give one of the two"),
                ));
            }
        }
        if format == output::Format::Png {
            let exr_only = [
                ("--half", self.half),
                ("--compression", self.compression.is_some()),
                ("--passes", self.passes.is_some()),
            ];
            if let Some((flag, _)) = exr_only.into_iter().find(|e| e.1) {
                return Err(crate::Error::flag(
                    flag,
                    "applies to an EXR; `-o` names a PNG, which holds colour and alpha alone",
                ));
            }
        }
        Ok(())
    }

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
pub(super) fn positive(text: &str) -> Result<f64, String> {
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
pub(super) fn pass_list(text: &str) -> Result<String, String> {
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
pub(super) fn finite(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(format!("must be a finite number (got {v:?})")),
        Err(e) => Err(e.to_string()),
    }
}

pub(super) fn exr_compression(name: &str) -> Result<output::Compression, String> {
    output::Compression::by_name(name)
        .ok_or_else(|| format!("one of {}", output::Compression::NAMES.join(", ")))
}
