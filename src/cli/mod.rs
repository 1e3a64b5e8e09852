//! The command line: `rest-embree render SCENE -o OUT.{exr,png} [options]` (a still, a tile of
//! one: `tiles.rs`, or a film's frames: `film.rs`), `assemble`, `farm slurm` (`farm.rs`),
//! `backends` and `bench`.

mod args;
mod bench_cmd;
mod bench_lattice;
mod farm;
mod film;
mod hints;
mod render_cmd;
mod tiles;
mod view_cmd;

pub(crate) use crate::text::say;
pub(crate) use args::*;
pub(crate) use render_cmd::memory_need;
use render_cmd::{render_to_file, run_assemble, run_render, warn_nonfinite};

use crate::{accel, bench, memory, output, scene, Error};
use clap::Parser;
use std::process::ExitCode;

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
        crate::text::warn("interrupted");
        std::process::exit(130);
    });
    match parse() {
        Ok(cli) => run(cli),
        Err(code) => code,
    }
}

fn parse() -> Result<Cli, ExitCode> {
    Cli::try_parse().map_err(|e| {
        let _ = e.print();
        if e.use_stderr() {
            let args: Vec<String> = std::env::args().collect();
            if let Some(hint) = hints::quoting_hint(&args) {
                crate::text::warn(format_args!("\n{hint}"));
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
                crate::text::say(text.trim_end_matches('\n'));
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
            crate::text::warn(crate::text::terminal_safe(&format!("error: {e}")));
            ExitCode::FAILURE
        }
    }
}

fn set_threads(threads: Option<usize>) -> crate::Result<()> {
    if let Some(n) = threads {
        crate::render::thread_count_ok(n).map_err(|e| Error::flag("--threads", e))?;
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| Error::flag("--threads", e))?;
    }
    Ok(())
}
