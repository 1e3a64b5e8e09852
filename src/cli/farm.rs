//! `rest-embree farm slurm`: a film or a still rendered by a SLURM job array, through `sbatch`
//! itself. One task per frame (or per run of frames, beyond SLURM's usual array size), or one
//! per tile of a still (`--tiles NxM`), joined by `rest-embree assemble` in a job that waits for
//! the array. The cluster's own tools watch and stop it: `squeue`, `sacct`, `scancel`.

use super::say;
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

/// `text` as one word for bash: as it is where every character is plain, else quoted.
fn shell_word(text: &str) -> String {
    let plain = !text.is_empty()
        && text
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c));
    match plain {
        true => text.to_string(),
        false => quote(text),
    }
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
    let (scene, plan) = Plan::new(args)?;
    let jobs = match (&scene.film, args.tiles) {
        (Some(f), None) => plan.film_jobs(f, args)?,
        (_, grid) => plan.image_jobs(&scene, grid, args)?,
    };
    if args.dry_run {
        print_jobs(&jobs, args);
        Ok(())
    } else {
        submit(&jobs, &plan.logs, args)
    }
}

/// What every job script of one submission shares: the output, where the scripts and logs go,
/// the jobs' name, the lines each task's script starts with and the flags each task's render
/// is given.
struct Plan {
    exe: String,
    /// The output's format, by its extension.
    format: output::Format,
    output: PathBuf,
    dir: PathBuf,
    stem: String,
    logs: PathBuf,
    name: String,
    common: String,
    flags: String,
}

impl Plan {
    /// The scene as every task will read it (everything a task would refuse is refused here,
    /// before anything is submitted), and the plan of its jobs.
    fn new(args: &SlurmArgs) -> crate::Result<(scene::Scene, Plan)> {
        let exe = std::env::current_exe().map_err(|e| Error::flag("farm", e))?;
        let scene_path = std::fs::canonicalize(&args.scene)
            .map_err(|e| Error::flag(&args.scene.display().to_string(), e))?;
        let overrides: Vec<(String, String)> = args
            .set
            .iter()
            .map(|s| (format!("--set {s}"), s.clone()))
            .collect();
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
        let output = script_safe_output(&args.output)?;
        let dir = output.parent().map(Path::to_path_buf).unwrap_or_default();
        let stem = output_stem(&output);
        let logs = dir.join("rest-embree-farm");
        let name = format!("rest-embree-{}", job_name(&stem));
        let exe = quote(&exe.display().to_string());
        let common = format!(
            "exe={exe}\nscene={}\n",
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
        let plan = Plan {
            exe,
            format,
            output,
            dir,
            stem,
            logs,
            name,
            common,
            flags,
        };
        Ok((scene, plan))
    }

    /// The output's path, quoted for bash.
    fn quoted_output(&self) -> String {
        quote(&self.output.display().to_string())
    }

    /// A film: one job array, each task a run of consecutive frames (one frame each, unless
    /// the film has more frames than an array takes tasks).
    fn film_jobs(&self, f: &crate::scene::Film, args: &SlurmArgs) -> crate::Result<Vec<Job>> {
        film::FramePattern::parse(&args.output).map_err(|m| Error::flag("-o", m))?;
        let (first, last) = film::frame_range(f, args.frames)?;
        let frames = last - first + 1;
        let per = frames.div_ceil(MAX_TASKS);
        let tasks = frames.div_ceil(per);
        let body = format!(
            "{}out={}\nfirst=$(( {first} + SLURM_ARRAY_TASK_ID * {per} ))\nlast=$(( first + {per} - 1 ))\nif (( last > {last} )); then last={last}; fi\nexec \"$exe\" render \"$scene\" -o \"$out\" --frames \"$first..$last\" --resume{}\n",
            self.common,
            self.quoted_output(),
            self.flags
        );
        Ok(vec![Job {
            file: self.logs.join(format!("{}-frames.sbatch", self.stem)),
            text: script(&self.name, &self.logs, Some(tasks), &body),
            tasks,
        }])
    }

    /// A still: one task, or (with `--tiles`) a job array of one task per tile and a job that
    /// assembles the tiles once it has finished.
    fn image_jobs(
        &self,
        scene: &scene::Scene,
        grid: Option<(u32, u32)>,
        args: &SlurmArgs,
    ) -> crate::Result<Vec<Job>> {
        if args.frames.is_some() {
            return Err(Error::flag(
                "--frames",
                "the scene is not a film: add a [film] table",
            ));
        }
        let Some((columns, rows)) = grid else {
            let body = format!(
                "{}out={}\nexec \"$exe\" render \"$scene\" -o \"$out\"{}\n",
                self.common,
                self.quoted_output(),
                self.flags
            );
            return Ok(vec![Job {
                file: self.logs.join(format!("{}-render.sbatch", self.stem)),
                text: script(&self.name, &self.logs, Some(1), &body),
                tasks: 1,
            }]);
        };
        let shown = format!("--tiles {columns}x{rows}");
        tiles::tile_crop(scene, self.format, (columns, rows), 0, &shown)?;
        let tasks = u64::from(columns) * u64::from(rows);
        check_array_size(tasks, (columns, rows))?;
        // The tile's name quoted as a whole (a `$(...)` in the output's name is text), then the
        // task's number.
        let tile = |i: &str| self.dir.join(format!("{}.tile-{i}.exr", self.stem));
        let prefix = self.dir.join(format!("{}.tile-", self.stem));
        let prefix = quote(&prefix.display().to_string());
        let body = format!(
            "{}tile={prefix}\nexec \"$exe\" render \"$scene\" -o \"${{tile}}${{SLURM_ARRAY_TASK_ID}}.exr\" --tiles {columns}x{rows} --tile \"$SLURM_ARRAY_TASK_ID\"{}\n",
            self.common, self.flags
        );
        let render = Job {
            file: self.logs.join(format!("{}-tiles.sbatch", self.stem)),
            text: script(&self.name, &self.logs, Some(tasks), &body),
            tasks,
        };
        let all: Vec<String> = (0..tasks)
            .map(|i| quote(&tile(&i.to_string()).display().to_string()))
            .collect();
        let body = format!(
            "exe={}\n\"$exe\" assemble -o {} {}\nrm -f {}\n",
            self.exe,
            self.quoted_output(),
            all.join(" "),
            all.join(" ")
        );
        let assemble = Job {
            file: self.logs.join(format!("{}-assemble.sbatch", self.stem)),
            text: script(&format!("{}-assemble", self.name), &self.logs, None, &body),
            tasks: 1,
        };
        Ok(vec![render, assemble])
    }
}

/// `output` made absolute, refused where it holds what an `#SBATCH --output` line cannot.
fn script_safe_output(output: &Path) -> crate::Result<PathBuf> {
    let output = absolute(output)?;
    let text = output.to_string_lossy();
    let Some(c) = text.chars().find(|c| c.is_whitespace() || c.is_control()) else {
        return Ok(output);
    };
    let what = match c {
        ' ' => "a space".to_string(),
        '\n' => "a line break".to_string(),
        '\t' => "a tab".to_string(),
        c => format!("the character {c:?}"),
    };
    Err(Error::flag(
        "-o",
        format!(
            "{:?} has {what}, which the job script's #SBATCH --output line cannot hold: choose a path without spaces or control characters",
            output.display()
        ),
    ))
}

/// The name the jobs and their scripts take from the output: its stem without a frame
/// pattern's `#` and the separators around it (`frames` where nothing is left).
fn output_stem(output: &Path) -> String {
    let stem = output
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("render")
        .replace('#', "");
    let stem = stem.trim_matches(['-', '_', '.']);
    match stem.is_empty() {
        true => "frames".to_string(),
        false => stem.to_string(),
    }
}

/// Refuse a job array of more tasks than the cluster's arrays take.
fn check_array_size(tasks: u64, (columns, rows): (u32, u32)) -> crate::Result<()> {
    let (max, read) = max_array_size();
    if tasks <= max {
        return Ok(());
    }
    let side = (max as f64).sqrt().floor() as u64;
    Err(Error::flag(
        "--tiles",
        format!(
            "{columns}x{rows} is {tasks} tiles, one task each, and the cluster's job arrays take at most {max} tasks (MaxArraySize {max}{}): choose fewer tiles, e.g. --tiles {side}x{side}",
            if read {
                ", from scontrol show config"
            } else {
                ": SLURM's default, as scontrol could not say"
            }
        ),
    ))
}

/// The sbatch command that submits `job` (after job `after`, where given).
fn sbatch_command(job: &Job, after: Option<&str>, args: &SlurmArgs) -> Vec<String> {
    let mut cmd = vec!["sbatch".to_string(), "--parsable".to_string()];
    if let Some(id) = after {
        cmd.push(format!("--dependency=afterok:{id}"));
    }
    cmd.extend(args.sbatch_args.iter().cloned());
    cmd.push(job.file.display().to_string());
    cmd
}

fn plural(n: u64) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

/// `--dry-run`: each job's script and the command that would submit it.
fn print_jobs(jobs: &[Job], args: &SlurmArgs) {
    for (i, job) in jobs.iter().enumerate() {
        let (file, tasks) = (job.file.display(), job.tasks);
        say(format_args!("# {file} ({tasks} task{})", plural(tasks)));
        say(&job.text);
        let after = (i > 0).then_some("JOBID");
        // Quoted as bash reads it: pasted, it runs the same sbatch, and nothing in an argument
        // (a `$(...)` in a --comment, say) runs.
        let cmd = sbatch_command(job, after, args)
            .iter()
            .map(|a| shell_word(a))
            .collect::<Vec<_>>()
            .join(" ");
        say(format_args!("# submitted with: {cmd}\n"));
    }
}

/// Write the job scripts into `logs` and submit them with sbatch, each job after the one
/// before; print each job's id.
fn submit(jobs: &[Job], logs: &Path, args: &SlurmArgs) -> crate::Result<()> {
    let found = std::env::var_os("PATH")
        .map(|p| std::env::split_paths(&p).any(|d| d.join("sbatch").is_file()))
        .unwrap_or(false);
    if !found {
        return Err(Error::flag(
            "farm slurm",
            "sbatch is not on PATH: run this where SLURM's commands are (a login node), or add --dry-run to see the job scripts",
        ));
    }
    std::fs::create_dir_all(logs)
        .map_err(|e| Error::flag("-o", format!("cannot make {}: {e}", logs.display())))?;
    let mut previous: Option<String> = None;
    for job in jobs {
        std::fs::write(&job.file, &job.text)
            .map_err(|e| Error::flag("-o", format!("cannot write {}: {e}", job.file.display())))?;
        let cmd = sbatch_command(job, previous.as_deref(), args);
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
        say(&id);
        let (tasks, file) = (job.tasks, job.file.display());
        eprintln!(
            "farm: submitted job {id} ({tasks} task{}): {file}",
            plural(tasks)
        );
        previous = Some(id);
    }
    eprintln!(
        "farm: watch with `squeue --me` or `sacct -j JOBID`; stop with `scancel JOBID`; logs in {}",
        logs.display()
    );
    Ok(())
}
