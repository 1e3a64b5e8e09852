//! `rest-embree farm slurm`: a film or a still rendered by a SLURM job array, through `sbatch`
//! itself. One task per frame (or per run of frames, beyond SLURM's usual array size), or one
//! per tile of a still (`--tiles NxM`), joined by `rest-embree assemble` in a job that waits for
//! the array. The cluster's own tools watch and stop it: `squeue`, `sacct`, `scancel`.

use super::{film, tiles};
use crate::{output, scene, Error};
use clap::Subcommand;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The most tasks one array is given (SLURM's default `MaxArraySize` is 1001); longer films get
/// runs of consecutive frames per task.
const MAX_TASKS: u64 = 1000;

/// SLURM's default `MaxArraySize`: job arrays of indices 0 to 1000.
const DEFAULT_MAX_ARRAY_SIZE: u64 = 1001;

/// The cluster's `MaxArraySize` (`scontrol show config`), and whether it was read there (else
/// SLURM's default).
fn max_array_size() -> (u64, bool) {
    let read = std::process::Command::new("scontrol")
        .args(["show", "config"])
        .stdin(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .output()
        .ok()
        .filter(|o| o.status.success())
        .and_then(|o| {
            String::from_utf8_lossy(&o.stdout).lines().find_map(|l| {
                let (key, value) = l.split_once('=')?;
                (key.trim() == "MaxArraySize")
                    .then(|| value.trim().parse::<u64>().ok())
                    .flatten()
            })
        });
    match read {
        Some(n) => (n, true),
        None => (DEFAULT_MAX_ARRAY_SIZE, false),
    }
}

#[derive(Subcommand, Debug)]
pub(crate) enum Scheduler {
    /// Submit to SLURM: a job array (one task per frame of a film, or per tile of a still) and,
    /// for tiles, a job that assembles them once the array has finished.
    Slurm(SlurmArgs),
}

#[derive(clap::Args, Debug)]
pub(crate) struct SlurmArgs {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// The output: a frame pattern for a film (out/frame-####.exr), a file for a still.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Only these frames of the film: A..B (both included) or N.
    #[arg(long, value_name = "A..B", value_parser = film::parse_frames)]
    pub frames: Option<(u64, u64)>,
    /// Split a still into N columns x M rows of tiles, one task each (an EXR output).
    #[arg(long, value_name = "NxM", value_parser = tiles::parse_grid)]
    pub tiles: Option<(u32, u32)>,
    /// An argument for sbatch, e.g. --sbatch-arg=--partition=long (repeat for more).
    #[arg(long = "sbatch-arg", value_name = "ARG", allow_hyphen_values = true)]
    pub sbatch_args: Vec<String>,
    /// Override a scene value in every task, as `render --set`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// The intersection backend of every task.
    #[arg(long)]
    pub backend: Option<String>,
    /// Print the job scripts and the sbatch commands instead of submitting them.
    #[arg(long)]
    pub dry_run: bool,
}

pub(crate) fn run(scheduler: &Scheduler) -> crate::Result<()> {
    match scheduler {
        Scheduler::Slurm(args) => slurm(args),
    }
}

/// `text` quoted for bash.
fn quote(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

fn absolute(path: &Path) -> crate::Result<PathBuf> {
    std::path::absolute(path).map_err(|e| Error::flag("-o", e))
}

/// One job script: its name, what it does, and its text.
struct Job {
    file: PathBuf,
    text: String,
    tasks: u64,
}

/// `text` for a `#SBATCH --output` line, which sbatch reads itself (no shell): its own
/// `%` patterns (`%j`, `%A`) written `%%` where the text means a `%`.
fn slurm_pattern(text: &str) -> String {
    text.replace('%', "%%")
}

/// A job name of the output's stem: letters, digits, `.`, `_` and `-`, the rest `_`.
fn job_name(stem: &str) -> String {
    stem.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-') {
                c
            } else {
                '_'
            }
        })
        .collect()
}

fn script(name: &str, logs: &Path, array: Option<u64>, body: &str) -> String {
    let mut s = String::from("#!/bin/bash\n");
    let _ = writeln!(s, "#SBATCH --job-name={name}");
    let logs = slurm_pattern(&logs.display().to_string());
    match array {
        Some(n) => {
            let _ = writeln!(s, "#SBATCH --array=0-{}", n - 1);
            let _ = writeln!(s, "#SBATCH --output={logs}/{name}-%A_%a.out");
        }
        None => {
            let _ = writeln!(s, "#SBATCH --output={logs}/{name}-%j.out");
        }
    }
    s.push_str("# Written by `rest-embree farm slurm`. Watch: squeue --me, sacct -j JOBID; stop: scancel JOBID.\n");
    s.push_str("set -euo pipefail\n");
    s.push_str(body);
    s
}

fn slurm(args: &SlurmArgs) -> crate::Result<()> {
    let exe = std::env::current_exe().map_err(|e| Error::flag("farm", e))?;
    let scene_path = std::fs::canonicalize(&args.scene)
        .map_err(|e| Error::flag(&args.scene.display().to_string(), e))?;
    let overrides: Vec<(String, String)> = args
        .set
        .iter()
        .map(|s| (format!("--set {s}"), s.clone()))
        .collect();
    // Everything a task would refuse is refused here, before anything is submitted.
    // A tiled image may be larger than one frame; each tile's frame is checked below.
    let frame = match args.tiles {
        Some(_) => scene::FrameSize::InTiles,
        None => scene::FrameSize::Checked,
    };
    let scene = scene::load_file_as(&scene_path, &overrides, frame)?;
    let format = output::Format::for_path(&args.output).map_err(|e| e.on_flag("-o"))?;
    if let Some(b) = &args.backend {
        crate::accel::backend_by_name(b).map_err(|e| e.on_flag("--backend"))?;
    }
    let output = absolute(&args.output)?;
    if let Some(c) = output
        .to_string_lossy()
        .chars()
        .find(|c| c.is_whitespace() || c.is_control())
    {
        let what = match c {
            ' ' => "a space".to_string(),
            '\n' => "a line break".to_string(),
            '\t' => "a tab".to_string(),
            c => format!("the character {c:?}"),
        };
        return Err(Error::flag(
            "-o",
            format!(
                "{:?} has {what}, which the job script's #SBATCH --output line cannot hold: choose a path without spaces or control characters",
                output.display()
            ),
        ));
    }
    let dir = output.parent().map(Path::to_path_buf).unwrap_or_default();
    let stem = output
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("render")
        .replace('#', "");
    let stem = stem.trim_matches(['-', '_', '.']).to_string();
    let stem = if stem.is_empty() {
        "frames".to_string()
    } else {
        stem
    };
    let logs = dir.join("rest-embree-farm");
    let name = format!("rest-embree-{}", job_name(&stem));

    let mut common = format!(
        "exe={}\nscene={}\n",
        quote(&exe.display().to_string()),
        quote(&scene_path.display().to_string())
    );
    let mut flags = String::from(" -q");
    if let Some(b) = &args.backend {
        let _ = write!(flags, " --backend {}", quote(b));
    }
    for s in &args.set {
        let _ = write!(flags, " --set {}", quote(s));
    }
    flags.push_str(" ${SLURM_CPUS_PER_TASK:+--threads $SLURM_CPUS_PER_TASK}");

    let mut jobs = Vec::new();
    match (&scene.film, args.tiles) {
        (Some(f), None) => {
            film::FramePattern::parse(&args.output).map_err(|m| Error::flag("-o", m))?;
            let (first, last) = film::frame_range(f, args.frames)?;
            let frames = last - first + 1;
            let per = frames.div_ceil(MAX_TASKS);
            let tasks = frames.div_ceil(per);
            let _ = write!(
                common,
                "out={}\nfirst=$(( {first} + SLURM_ARRAY_TASK_ID * {per} ))\nlast=$(( first + {per} - 1 ))\nif (( last > {last} )); then last={last}; fi\n",
                quote(&output.display().to_string())
            );
            let body = format!("{common}exec \"$exe\" render \"$scene\" -o \"$out\" --frames \"$first..$last\" --resume{flags}\n");
            jobs.push(Job {
                file: logs.join(format!("{stem}-frames.sbatch")),
                text: script(&name, &logs, Some(tasks), &body),
                tasks,
            });
        }
        (_, grid) => {
            let (columns, rows) = grid.unwrap_or((1, 1));
            if grid.is_some() {
                let shown = format!("--tiles {columns}x{rows}");
                tiles::tile_crop(&scene, format, (columns, rows), 0, &shown)?;
            }
            if args.frames.is_some() {
                return Err(Error::flag(
                    "--frames",
                    "the scene is not a film: add a [film] table",
                ));
            }
            let tasks = u64::from(columns) * u64::from(rows);
            // One task a tile, in one job array: no more than the cluster takes.
            let (max, read) = max_array_size();
            if tasks > max {
                let side = (max as f64).sqrt().floor() as u64;
                return Err(Error::flag(
                    "--tiles",
                    format!(
                        "{columns}x{rows} is {tasks} tiles, one task each, and the cluster's job arrays take at most {max} tasks (MaxArraySize {max}{}): choose fewer tiles, e.g. --tiles {side}x{side}",
                        if read {
                            ", from scontrol show config"
                        } else {
                            ": SLURM's default, as scontrol could not say"
                        }
                    ),
                ));
            }
            let tile = |i: &str| dir.join(format!("{stem}.tile-{i}.exr"));
            if grid.is_none() {
                let _ = writeln!(common, "out={}", quote(&output.display().to_string()));
                jobs.push(Job {
                    file: logs.join(format!("{stem}-render.sbatch")),
                    text: script(
                        &name,
                        &logs,
                        Some(1),
                        &format!("{common}exec \"$exe\" render \"$scene\" -o \"$out\"{flags}\n"),
                    ),
                    tasks: 1,
                });
            } else {
                // The tile's name quoted as a whole (a `$(...)` in the output's name is text),
                // then the task's number.
                let prefix = quote(&dir.join(format!("{stem}.tile-")).display().to_string());
                let body = format!(
                    "{common}tile={prefix}\nexec \"$exe\" render \"$scene\" -o \"${{tile}}${{SLURM_ARRAY_TASK_ID}}.exr\" --tiles {columns}x{rows} --tile \"$SLURM_ARRAY_TASK_ID\"{flags}\n"
                );
                jobs.push(Job {
                    file: logs.join(format!("{stem}-tiles.sbatch")),
                    text: script(&name, &logs, Some(tasks), &body),
                    tasks,
                });
                let all: Vec<String> = (0..tasks)
                    .map(|i| quote(&tile(&i.to_string()).display().to_string()))
                    .collect();
                let body = format!(
                    "exe={}\n\"$exe\" assemble -o {} {}\nrm -f {}\n",
                    quote(&exe.display().to_string()),
                    quote(&output.display().to_string()),
                    all.join(" "),
                    all.join(" ")
                );
                jobs.push(Job {
                    file: logs.join(format!("{stem}-assemble.sbatch")),
                    text: script(&format!("{name}-assemble"), &logs, None, &body),
                    tasks: 1,
                });
            }
        }
    }

    let sbatch = |job: &Job, after: Option<&str>| {
        let mut cmd = vec!["sbatch".to_string(), "--parsable".to_string()];
        if let Some(id) = after {
            cmd.push(format!("--dependency=afterok:{id}"));
        }
        cmd.extend(args.sbatch_args.iter().cloned());
        cmd.push(job.file.display().to_string());
        cmd
    };
    if args.dry_run {
        for (i, job) in jobs.iter().enumerate() {
            println!(
                "# {} ({} task{})",
                job.file.display(),
                job.tasks,
                if job.tasks == 1 { "" } else { "s" }
            );
            println!("{}", job.text);
            let after = (i > 0).then_some("JOBID");
            println!("# submitted with: {}\n", sbatch(job, after).join(" "));
        }
        return Ok(());
    }
    let found = std::env::var_os("PATH")
        .map(|p| std::env::split_paths(&p).any(|d| d.join("sbatch").is_file()))
        .unwrap_or(false);
    if !found {
        return Err(Error::flag(
            "farm slurm",
            "sbatch is not on PATH: run this where SLURM's commands are (a login node), or add --dry-run to see the job scripts",
        ));
    }
    std::fs::create_dir_all(&logs)
        .map_err(|e| Error::flag("-o", format!("cannot make {}: {e}", logs.display())))?;
    let mut previous: Option<String> = None;
    for job in &jobs {
        std::fs::write(&job.file, &job.text)
            .map_err(|e| Error::flag("-o", format!("cannot write {}: {e}", job.file.display())))?;
        let cmd = sbatch(job, previous.as_deref());
        let out = std::process::Command::new(&cmd[0])
            .args(&cmd[1..])
            .output()
            .map_err(|e| Error::flag("farm slurm", format!("cannot run sbatch: {e}")))?;
        if !out.status.success() {
            return Err(Error::flag(
                "farm slurm",
                format!(
                    "`{}` failed: {}",
                    cmd.join(" "),
                    String::from_utf8_lossy(&out.stderr).trim()
                ),
            ));
        }
        let id = String::from_utf8_lossy(&out.stdout)
            .trim()
            .split(';')
            .next()
            .unwrap_or_default()
            .to_string();
        println!("{id}");
        eprintln!(
            "farm: submitted job {id} ({} task{}): {}",
            job.tasks,
            if job.tasks == 1 { "" } else { "s" },
            job.file.display()
        );
        previous = Some(id);
    }
    eprintln!(
        "farm: watch with `squeue --me` or `sacct -j JOBID`; stop with `scancel JOBID`; logs in {}",
        logs.display()
    );
    Ok(())
}
