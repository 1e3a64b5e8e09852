//! What every task's script says to sbatch (`#SBATCH` lines: memory, time, the user's own
//! arguments), each checked in a form sbatch takes, and the task's render flags checked as
//! `render` checks them: what sbatch or a task would refuse is refused before submitting.

use super::*;

/// The #SBATCH lines every task's script carries (with a comment after each of --mem and
/// --time saying how it was chosen): --mem and --time as given or estimated, then the
/// --sbatch-args (a comment for one sbatch's lines cannot hold).
pub(super) fn directives(
    scene: &scene::Scene,
    format: output::Format,
    args: &SlurmArgs,
) -> crate::Result<Vec<String>> {
    let cpus = cpus_per_task(args);
    let mut out = Vec::new();
    match &args.mem {
        Some(m) => out.push(format!("--mem={m}")),
        None => {
            // The render's own estimate (strips of the image, the primitives), half again
            // for the allocator and the process, and 256 MiB for the binary and its libraries.
            let need = crate::cli::memory_need(scene, format, cpus as usize);
            let mib = (need as f64 * 1.5 / (1 << 20) as f64).ceil() as u64 + 256;
            out.push(format!(
                "--mem={mib}M\n# (--mem: the render's estimate of {} MiB, half again, and 256 MiB for the process; --mem sets it)",
                need >> 20
            ));
        }
    }
    match &args.time {
        Some(t) => out.push(format!("--time={t}")),
        None => {
            let (limit, why) = time_estimate(scene, args, cpus)?;
            out.push(format!("--time={limit}\n# (--time: {why}; --time sets it)"));
        }
    }
    for a in &args.sbatch_args {
        if a.chars().any(char::is_control) {
            return Err(Error::flag(
                "--sbatch-arg",
                format!("`{}` has a control character", crate::text::shown(a)),
            ));
        }
        // sbatch's command line outranks the script's own --array: every task would render
        // the same frame or tile. (getopt takes any prefix of --array from --ar on.)
        let long = a.split('=').next().unwrap_or(a);
        if a.starts_with("-a") || long.len() >= 4 && "--array".starts_with(long) {
            return Err(Error::flag(
                "--sbatch-arg",
                format!(
                    "`{}`: the farm makes the job array itself, one task per frame or tile (--frames and --tiles choose them)",
                    crate::text::shown(a)
                ),
            ));
        }
        // sbatch splits an #SBATCH line at spaces: an argument with one goes on sbatch's
        // command line alone, and the script says so.
        match a.chars().any(char::is_whitespace) {
            false => out.push(a.clone()),
            true => out.push(format!(
                "# (given to sbatch on its command line, not here: it holds a space) {}",
                crate::text::shown(a)
            )),
        }
    }
    let forms = [
        (
            "--mem",
            &args.mem,
            slurm_size as fn(&str) -> bool,
            "a whole number of megabytes, or one with K, M, G or T (8G; 0 is all of a node's)",
        ),
        (
            "--time",
            &args.time,
            slurm_time,
            "minutes, minutes:seconds, hours:minutes:seconds, days-hours, days-hours:minutes, days-hours:minutes:seconds or UNLIMITED",
        ),
    ];
    for (flag, v, fits, accepted) in forms {
        if let Some(v) = v.as_ref().filter(|v| !fits(v)) {
            return Err(Error::flag(
                flag,
                format!(
                    "`{}` is no value sbatch takes: {accepted}",
                    crate::text::shown(v)
                ),
            ));
        }
    }
    Ok(out)
}

/// Whether sbatch's --mem takes `v`: digits, then at most one of its units, which may end in
/// B (8G, 8GB).
fn slurm_size(v: &str) -> bool {
    let unit = |s: &str| s.ends_with(['K', 'M', 'G', 'T', 'k', 'm', 'g', 't']);
    let v = match v.strip_suffix(['B', 'b']) {
        Some(rest) if unit(rest) => rest,
        _ => v,
    };
    let digits = v.trim_end_matches(['K', 'M', 'G', 'T', 'k', 'm', 'g', 't']);
    v.len() - digits.len() <= 1 && !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())
}

/// Whether sbatch's --time takes `v`: one of its six forms of whole numbers, or no limit.
fn slurm_time(v: &str) -> bool {
    if ["UNLIMITED", "INFINITE"]
        .iter()
        .any(|w| v.eq_ignore_ascii_case(w))
    {
        return true;
    }
    let number = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let (days, rest) = match v.split_once('-') {
        Some((d, rest)) => (Some(d), rest),
        None => (None, v),
    };
    let parts: Vec<&str> = rest.split(':').collect();
    days.is_none_or(number) && parts.len() <= 3 && parts.iter().all(|p| number(p))
}

/// A task's flags read as `render` reads them, and refused here as a task would refuse them
/// (an EXR's flag on a PNG, a value given twice), before anything is submitted.
pub(super) fn task_flags_checked(
    scene: &Path,
    render_flags: &[(String, String)],
    args: &SlurmArgs,
    format: output::Format,
) -> crate::Result<()> {
    use clap::Parser;
    let mut argv: Vec<String> = ["rest-embree", "render"].map(String::from).to_vec();
    argv.push(scene.display().to_string());
    argv.extend(["-o".to_string(), args.output.display().to_string()]);
    for (shown, _) in render_flags {
        let (flag, value) = shown.split_once(' ').expect("a flag and its value");
        argv.extend([flag.to_string(), value.to_string()]);
    }
    for s in &args.set {
        argv.extend(["--set".to_string(), s.clone()]);
    }
    match crate::cli::args::Cli::try_parse_from(&argv) {
        Ok(crate::cli::args::Cli {
            command: crate::cli::args::Command::Render(task),
        }) => task.check_flags(format),
        // The farm's own flags were read by the same parsers: a task reads them as they are.
        _ => Ok(()),
    }
}
