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

mod directives;
use directives::{directives, task_flags_checked};

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
    /// An argument for sbatch, e.g. --sbatch-arg=--partition=long (repeat for more): written
    /// into every job script as an #SBATCH line (a script resubmitted by hand keeps it) and
    /// given to sbatch.
    #[arg(long = "sbatch-arg", value_name = "ARG", allow_hyphen_values = true)]
    pub sbatch_args: Vec<String>,
    /// Memory per task, as sbatch's --mem takes it (e.g. 8G); default: the render's own
    /// estimate with room to spare, said in the script.
    #[arg(long, value_name = "SIZE")]
    pub mem: Option<String>,
    /// Time limit per task, as sbatch's --time takes it (e.g. 2:00:00); default: estimated from
    /// a small render of the scene here, with room to spare, said in the script.
    #[arg(long, value_name = "TIME")]
    pub time: Option<String>,
    /// Image width in pixels, as for render.
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels, as for render.
    #[arg(long)]
    pub height: Option<u32>,
    /// Samples per pixel, as for render.
    #[arg(long)]
    pub samples: Option<u32>,
    /// The passes an EXR holds, as for render.
    #[arg(long, value_name = "LIST", value_parser = super::pass_list)]
    pub passes: Option<String>,
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

fn script(
    name: &str,
    logs: &Path,
    array: Option<u64>,
    directives: &[String],
    body: &str,
) -> String {
    let mut s = String::from("#!/bin/bash\n");
    let _ = writeln!(s, "#SBATCH --job-name={name}");
    for d in directives {
        match d.starts_with('#') {
            true => {
                let _ = writeln!(s, "{d}");
            }
            false => {
                let _ = writeln!(s, "#SBATCH {d}");
            }
        }
    }
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
    s.push_str("# The binary, the scene and every file it names are read by their full paths on the\n# node that runs a task: they must be on a file system every node sees (as the output is).\n");
    s.push_str("set -euo pipefail\n");
    s.push_str(body);
    s
}

fn slurm(args: &SlurmArgs) -> crate::Result<()> {
    let (scene, plan) = Plan::new(args)?;
    // A file the scene reads is no output, as render refuses it: here before anything is
    // submitted (a tiled still's is written by the assembly, which does not know the scene).
    match &scene.film {
        Some(f) if args.tiles.is_none() => {
            let pattern = film::FramePattern::parse(&args.output)?;
            let (first, last) = film::frame_range(f, args.frames)?;
            for k in first..=last {
                super::render_cmd::not_an_input(&scene, &pattern.path(k), &format!("frame {k}"))?;
            }
        }
        _ => super::render_cmd::not_an_input(&scene, &args.output, "the output")?,
    }
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
    /// The #SBATCH lines of every task's script but the job's name and logs: --mem, --time
    /// (each with how it was chosen, in a comment above) and the --sbatch-args.
    directives: Vec<String>,
}

impl Plan {
    /// The scene as every task will read it (everything a task would refuse is refused here,
    /// before anything is submitted), and the plan of its jobs.
    fn new(args: &SlurmArgs) -> crate::Result<(scene::Scene, Plan)> {
        let exe = std::env::current_exe().map_err(|e| Error::flag("farm", e))?;
        let scene_path = std::fs::canonicalize(&args.scene)
            .map_err(|e| Error::flag(&args.scene.display().to_string(), e))?;
        // The render flags a task is given, as the scene it reads is checked here.
        let mut render_flags: Vec<(String, String)> = Vec::new();
        for (flag, key, v) in [
            ("--width", "image.width", args.width),
            ("--height", "image.height", args.height),
            ("--samples", "image.samples", args.samples),
        ] {
            if let Some(v) = v {
                render_flags.push((format!("{flag} {v}"), format!("{key}={v}")));
            }
        }
        if let Some(list) = &args.passes {
            let names: Vec<String> = list.split(',').map(|n| format!("{:?}", n.trim())).collect();
            render_flags.push((
                format!("--passes {list}"),
                format!("image.passes=[{}]", names.join(", ")),
            ));
        }
        let mut overrides = render_flags.clone();
        overrides.extend(args.set.iter().map(|s| (format!("--set {s}"), s.clone())));
        // A tiled image may be larger than one frame; each tile's frame is checked below.
        let frame = match args.tiles {
            Some(_) => scene::FrameSize::InTiles,
            None => scene::FrameSize::Checked,
        };
        let scene = scene::load_file_as(&scene_path, &overrides, frame)?;
        let format = output::Format::for_path(&args.output).map_err(|e| e.on_flag("-o"))?;
        task_flags_checked(&scene_path, &render_flags, args, format)?;
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
        for (shown, _) in &render_flags {
            let (flag, value) = shown.split_once(' ').expect("a flag and its value");
            let _ = write!(flags, " {flag} {}", quote(value));
        }
        for s in &args.set {
            let _ = write!(flags, " --set {}", quote(s));
        }
        flags.push_str(" ${SLURM_CPUS_PER_TASK:+--threads $SLURM_CPUS_PER_TASK}");
        let directives = directives(&scene, format, args)?;
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
            directives,
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
        film::FramePattern::parse(&args.output)?;
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
            text: script(&self.name, &self.logs, Some(tasks), &self.directives, &body),
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
                text: script(&self.name, &self.logs, Some(1), &self.directives, &body),
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
            "{}tile={prefix}\nexec \"$exe\" render \"$scene\" -o \"${{tile}}${{SLURM_ARRAY_TASK_ID}}.exr\" --tiles {columns}x{rows} --tile \"$SLURM_ARRAY_TASK_ID\" --resume{}\n",
            self.common, self.flags
        );
        let render = Job {
            file: self.logs.join(format!("{}-tiles.sbatch", self.stem)),
            text: script(&self.name, &self.logs, Some(tasks), &self.directives, &body),
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
            text: script(
                &format!("{}-assemble", self.name),
                &self.logs,
                None,
                &self.directives,
                &body,
            ),
            tasks: 1,
        };
        Ok(vec![render, assemble])
    }
}

/// The CPUs a task has: sbatch's `-c N` or `--cpus-per-task=N` among the --sbatch-args, else 1.
fn cpus_per_task(args: &SlurmArgs) -> u64 {
    let a = &args.sbatch_args;
    a.iter()
        .enumerate()
        .find_map(|(i, x)| {
            let v = x
                .strip_prefix("--cpus-per-task=")
                .or_else(|| x.strip_prefix("-c").filter(|v| !v.is_empty()))
                .map(str::to_string)
                .or_else(|| {
                    (x == "-c" || x == "--cpus-per-task")
                        .then(|| a.get(i + 1).cloned())
                        .flatten()
                });
            v.and_then(|v| v.parse().ok())
        })
        .unwrap_or(1)
        .max(1)
}

/// A task's time limit estimated from a small render of the scene here (one tile's width, the
/// scene's samples up to 16): its time per pixel and sample on one core, times a task's
/// pixels, samples and frames on its CPUs, three times over, plus ten minutes; as
/// sbatch's D-HH:MM:SS, and how it was reached.
fn time_estimate(
    scene: &scene::Scene,
    args: &SlurmArgs,
    cpus: u64,
) -> crate::Result<(String, String)> {
    let (w, h) = scene.image.frame_size();
    let spp = scene.image.samples.max(1);
    let mut small = scene.clone();
    let pw = 64u32.min(w);
    let ph = ((u64::from(h) * u64::from(pw) / u64::from(w.max(1))) as u32).clamp(1, 64);
    small.image.width = pw;
    small.image.height = ph;
    small.image.crop = None;
    small.image.samples = spp.min(16);
    small.film = None;
    let backend_name = args
        .backend
        .clone()
        .unwrap_or_else(|| crate::accel::default_backend_name().to_string());
    let backend = crate::accel::backend_by_name(&backend_name)?;
    let t0 = std::time::Instant::now();
    let world = crate::render::World::build(&small, backend.as_ref())?;
    crate::render::render_world_passes(&small, &world, crate::render::Passes::All);
    let threads = rayon::current_num_threads() as f64;
    let per = t0.elapsed().as_secs_f64() * threads
        / (f64::from(pw) * f64::from(ph) * f64::from(small.image.samples));
    let frames = match (&scene.film, args.tiles) {
        (Some(f), None) => {
            let (first, last) = film::frame_range(f, args.frames)?;
            // Frames per task, as `film_jobs` deals them.
            (last - first + 1).div_ceil(MAX_TASKS)
        }
        _ => 1,
    };
    let pixels = match args.tiles {
        Some((c, r)) => (u64::from(w) * u64::from(h)).div_ceil(u64::from(c) * u64::from(r)),
        None => u64::from(w) * u64::from(h),
    };
    let secs = per * pixels as f64 * f64::from(spp) * frames as f64 / cpus as f64;
    let limit = (3.0 * secs + 600.0).ceil() as u64;
    let (d, h2, m, s2) = (
        limit / 86400,
        limit / 3600 % 24,
        limit / 60 % 60,
        limit % 60,
    );
    let why = format!(
        "a {pw}x{ph} render here took {:.2e} core-seconds a pixel and sample; a task renders {pixels} pixels at {spp} spp{} on {cpus} CPU{}, about {:.0} s; three times that and ten minutes",
        per,
        if frames > 1 { format!(" for {frames} frames") } else { String::new() },
        if cpus == 1 { "" } else { "s" },
        secs
    );
    Ok((format!("{d}-{h2:02}:{m:02}:{s2:02}"), why))
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
        crate::text::warn(format_args!(
            "farm: submitted job {id} ({tasks} task{}): {file}",
            plural(tasks)
        ));
        previous = Some(id);
    }
    crate::text::warn(format_args!(
        "farm: watch with `squeue --me` or `sacct -j JOBID`; stop with `scancel JOBID`; logs in {}",
        logs.display()
    ));
    Ok(())
}
