//! `rest-embree bench`: the cases picked by `--case` (or a scene file), measured, reported as
//! a table, a summary, CSV and a plot.

use super::say;
use super::*;

/// The cases `--case` asks for: for each text, the case of that name, or where no case has it,
/// every case whose name contains it (so `lattice beta=0.9` is that case alone, `beta=0.9` also
/// its variants and 0.99).
fn pick_cases(all: Vec<bench::LazyCase>, texts: &[String]) -> crate::Result<Vec<bench::LazyCase>> {
    let names: Vec<String> = all.iter().map(|c| c.name.clone()).collect();
    let named = |t: &String| names.contains(t);
    let wanted = |name: &str| {
        texts.iter().any(|t| {
            if named(t) {
                name == t
            } else {
                name.contains(t.as_str())
            }
        })
    };
    let picked: Vec<bench::LazyCase> = all.into_iter().filter(|c| wanted(&c.name)).collect();
    if picked.is_empty() {
        return Err(Error::flag(
            "--case",
            format!(
                "no case of the suite matches {}; the cases are: {}",
                texts.join(", "),
                names.join("; ")
            ),
        ));
    }
    Ok(picked)
}

/// The bench, its `--out` folder removed again if this run made it and a refusal left it
/// empty.
pub(super) fn run_bench(args: &BenchArgs) -> crate::Result<()> {
    let existed = args.out.exists();
    let result = bench_into(args);
    if result.is_err() && !existed {
        // Only an empty folder goes.
        let _ = std::fs::remove_dir(&args.out);
    }
    result
}

fn bench_into(args: &BenchArgs) -> crate::Result<()> {
    set_threads(args.threads)?;
    // What can be refused is refused before anything is measured.
    if args.scene.is_none() && !args.set.is_empty() {
        return Err(Error::flag(
            "--set",
            "sets values of a scene file: give one (rest-embree bench SCENE.toml --set ...); the suite's cases set their own",
        ));
    }
    if args.scene.is_some() && !args.cases.is_empty() {
        return Err(Error::flag(
            "--case",
            "picks cases of the fixed suite; a scene file is measured whole (choose its settings with --backend)",
        ));
    }
    if args.cases.iter().any(|c| c.trim().is_empty()) {
        return Err(Error::flag(
            "--case",
            "is empty: give a case's name, or a part of one",
        ));
    }
    let out_flag = format!("--out {}", args.out.display());
    std::fs::create_dir_all(&args.out)
        .map_err(|e| Error::flag(&out_flag, super::render_cmd::folder_error(&args.out, &e)))?;
    let probe = args.out.join(format!(".probe-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| Error::flag(&out_flag, e))?;
    let _ = std::fs::remove_file(&probe);
    let cases = match &args.scene {
        None => {
            let all = bench::cases(args.quick);
            if args.cases.is_empty() {
                all
            } else {
                pick_cases(all, &args.cases)?
            }
        }
        Some(path) => {
            let overrides: Vec<(String, String)> = args
                .set
                .iter()
                .map(|s| (format!("--set {s}"), s.clone()))
                .collect();
            let scene = scene::load_file(path, &overrides)?;
            let names: Vec<String> = if args.backends.is_empty() {
                accel::backend_names()
                    .iter()
                    .map(|s| s.to_string())
                    .collect()
            } else {
                args.backends.clone()
            };
            for n in &names {
                let (backend, _, _) = bench::parse_setting(n)?;
                accel::backend_by_name(backend).map_err(|e| e.on_flag("--backend"))?;
            }
            let refs: Vec<&str> = names.iter().map(String::as_str).collect();
            vec![bench::LazyCase::ready(
                bench::Case::new(&path.display().to_string(), scene, &refs).with_bare(),
            )]
        }
    };
    // On a terminal a bar over the cases; otherwise a line per case.
    let bar = std::io::IsTerminal::is_terminal(&std::io::stderr()).then(|| {
        let bar = indicatif::ProgressBar::new(cases.len() as u64);
        let style =
            "bench [{bar:30}] {pos}/{len} cases, {elapsed} elapsed, about {eta} left: {msg}";
        bar.set_style(
            indicatif::ProgressStyle::with_template(style)
                .expect("a valid template")
                .progress_chars("=> "),
        );
        bar
    });
    // Measured first, while the process's heap is fresh.
    let files = if args.scene.is_none() && args.cases.is_empty() {
        bench::scene_files(args.quick)
    } else {
        String::new()
    };
    let mut started = 0;
    let rows = bench::run(
        &cases,
        bench::Timing::new(args.repeat, args.quick),
        |name| match &bar {
            Some(bar) => {
                bar.set_position(started);
                bar.set_message(name.to_string());
                started += 1;
            }
            None => crate::text::warn(format_args!("bench: {name}")),
        },
    );
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let rows = rows?;
    let table = bench::table(&rows);
    let mut summary = bench::summary(&rows);
    summary.push_str(&files);
    if args.scene.is_none() && args.cases.is_empty() {
        // The measures beside the table, each said as it starts: some take tens of seconds.
        let step = |what: &str| crate::text::warn(format_args!("bench: {what}"));
        for b in accel::backend_names() {
            step(&format!("a film's cost ({b})"));
            summary.push_str(&bench::film_cost(args.quick, b)?);
        }
        for b in accel::backend_names() {
            step(&format!("the viewer's latency ({b})"));
            summary.push_str(&crate::view::latency(args.quick, b)?);
        }
        step("the 1000^3 lattice");
        summary.push_str(&bench_lattice::summary(args.quick, &accel::backend_names()));
        step("the path integrator's noise against time");
        summary.push_str(&bench::path_noise(args.quick, &accel::backend_names())?);
        step("the path integrator's cost per sample");
        summary.push_str(&bench::path_room(
            args.quick,
            accel::default_backend_name(),
        )?);
        step("EXR writing");
        summary.push_str(&bench::exr_writing(
            args.quick,
            accel::default_backend_name(),
        )?);
        step("threads");
        summary.push_str(&bench::thread_scaling(
            args.quick,
            accel::default_backend_name(),
        )?);
    }
    // Which of Embree's code paths ran (its instruction set decides its packet width).
    let embree = match accel::embree_summary()? {
        Some(e) => format!(" Embree: {e}."),
        None => String::new(),
    };
    say(format_args!(
        "threads: {}.{embree}\n\n{table}\n{summary}",
        rayon::current_num_threads()
    ));
    let md = format!(
        "Measured with `rest-embree bench{}` on {} threads{}.{embree}\n\n{table}\n{summary}",
        if args.quick { " --quick" } else { "" },
        rayon::current_num_threads(),
        cpu_model().map_or(String::new(), |m| format!(" of {m}"))
    );
    let write = |name: &str, text: &str| {
        std::fs::write(args.out.join(name), text).map_err(|e| Error::flag(&out_flag, e))
    };
    write("bench.md", &md)?;
    write("bench.csv", &bench::csv(&rows))?;
    bench::plot_svg(&rows, &args.out.join("bench.svg"))?;
    crate::text::warn(format_args!(
        "bench: wrote bench.md, bench.csv and bench.svg to {}",
        args.out.display()
    ));
    Ok(())
}

/// The CPU's model as Linux names it (`/proc/cpuinfo`), where it does: the figures are this
/// machine's, and its instruction sets decide several of them.
fn cpu_model() -> Option<String> {
    let info = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("model name"))?;
    let name = line.split_once(':')?.1.trim();
    (!name.is_empty()).then(|| name.split_whitespace().collect::<Vec<_>>().join(" "))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn picked(texts: &[&str]) -> crate::Result<Vec<String>> {
        let texts: Vec<String> = texts.iter().map(|t| t.to_string()).collect();
        Ok(pick_cases(bench::cases(true), &texts)?
            .into_iter()
            .map(|c| c.name)
            .collect())
    }

    #[test]
    fn a_case_name_picks_that_case_and_other_text_every_case_holding_it() {
        assert_eq!(picked(&["lattice beta=0.9"]).unwrap(), ["lattice beta=0.9"]);
        let some = picked(&["beta=0.9"]).unwrap();
        assert!(some.len() >= 4, "{some:?}");
        assert!(some.iter().all(|n| n.contains("beta=0.9")), "{some:?}");
        assert!(some.contains(&"lattice beta=0.99".to_string()), "{some:?}");
        let both = picked(&["lattice beta=0", "lattice beta=0.5"]).unwrap();
        assert_eq!(both, ["lattice beta=0", "lattice beta=0.5"]);
        let err = picked(&["no such case"]).unwrap_err().to_string();
        assert!(
            err.contains("--case") && err.contains("lattice beta=0.99"),
            "{err}"
        );
    }
}
