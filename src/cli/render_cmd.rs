//! `rest-embree render` and `assemble`: the scene loaded and checked, the memory it needs
//! against the limit, the render to its file (a still, a tile, a film's frames), and what is
//! said about it.

use super::{film, set_threads, tiles, RenderArgs};
use crate::render::Passes;
use crate::{accel, memory, output, render, scene, Error};
use std::path::{Path, PathBuf};

/// The EXR's options for a render of `scene`: its header's attributes and Cryptomatte
/// manifests, the compression and sample type the flags ask for.
pub(super) fn exr_options(
    scene: &scene::Scene,
    backend_name: &str,
    args: &RenderArgs,
) -> output::ExrOptions {
    output::ExrOptions {
        compression: args.compression.unwrap_or_default(),
        half: args.half,
        // The flags that change nothing in the picture (--threads, -o) stay out of the
        // header: the same render makes the same file.
        ..output::ExrOptions::for_render(
            scene,
            backend_name,
            &args.scene.display().to_string(),
            &args.recorded(),
        )
    }
}

/// Render `scene` to `path`: an EXR with every pass, whole; a PNG with colour alone (the passes,
/// and with several samples their extra ray per pixel, are skipped), written strip by strip as it
/// is rendered, so a large image is never held whole. A bar shows the progress when stderr is a
/// terminal (and not --quiet).
/// An EXR's options are `made` already, or made here.
pub(super) fn render_to_file(
    scene: &scene::Scene,
    world: &render::World,
    backend_name: &str,
    format: output::Format,
    args: &RenderArgs,
    path: &Path,
    made: Option<output::ExrOptions>,
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
            let mut exr = match made {
                Some(exr) => exr,
                None => exr_options(scene, backend_name, args),
            };
            // Colour and alpha alone need no centre ray per pixel.
            let passes = match scene.image.passes.is_empty() {
                true => Passes::Colour,
                false => Passes::All,
            };
            // A still rendered in rounds (--max-time, --target-rms) is whole before its file is
            // begun: its header says the samples it took, not the most it could.
            let rounds = args
                .stop_at()
                .map(|stop| render_rounds(scene, world, passes, stop, progress, args));
            if let Some(Ok((_, s))) = &rounds {
                exr = exr.with_samples(s.samples.unwrap_or(scene.image.samples));
            }
            let written = output::write_exr_in_strips(path, (w, h), true, &exr, |put| {
                stats = match rounds {
                    Some(done) => {
                        let (frame, s) = done?;
                        put(&frame)?;
                        s
                    }
                    None => render::render_world_in_strips(
                        scene,
                        world,
                        passes,
                        memory::STRIP_PIXELS,
                        progress,
                        put,
                    )?,
                };
                Ok(())
            });
            progress.inspect(|p| p.finish());
            // Rendering and writing are one here.
            stats.trace_time = t1.elapsed();
            written
        }
        output::Format::Png => {
            let alpha = scene.image.is_transparent();
            let shown = args.recorded();
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
    let (frame, stats) = render_rounds(scene, world, passes, stop, progress, args)?;
    put(&frame)?;
    Ok(stats)
}

/// The frame rendered in rounds until `stop` (--max-time, --target-rms), and what the rounds
/// did said.
fn render_rounds(
    scene: &scene::Scene,
    world: &render::World,
    passes: Passes,
    stop: render::StopAt,
    progress: Option<&render::Progress>,
    args: &RenderArgs,
) -> std::result::Result<(render::Frame, render::RenderStats), crate::Cause> {
    let (frame, stats, done) = render::render_progressive(scene, world, passes, stop, progress)?;
    progress.inspect(|p| p.finish());
    if !args.quiet {
        let rms = done
            .rms
            .map_or("not estimated (one round)".to_string(), |r| {
                format!("{r:.3e}")
            });
        crate::text::warn(format_args!(
            "{} spp in {} rounds, stopped by {}: estimated RMS noise {rms}",
            done.samples, done.rounds, done.stopped_by
        ));
    }
    Ok((frame, stats))
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
    let per_thread = memory::STRIP_TILE_ROWS_PER_THREAD * threads as u64;
    let strip = |least: u64| least.max(per_thread * row) + 2 * row;
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

/// Why the folder `dir` of an output could not be made: a file in the way named (`-o
/// scene.toml/out.png` said "File exists"), else the system's reason.
pub(super) fn folder_error(dir: &Path, e: &std::io::Error) -> String {
    let in_the_way = dir
        .ancestors()
        .find(|a| !a.as_os_str().is_empty() && a.exists() && !a.is_dir());
    match in_the_way {
        Some(file) => format!(
            "cannot make the folder {}: {} is a file, not a folder",
            dir.display(),
            file.display()
        ),
        None => format!("cannot make the folder {}: {e}", dir.display()),
    }
}

/// Whether two paths name one existing file (through links).
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// An output that would replace a file the scene reads (a texture, a sky map, a mesh, a glTF
/// file or one of its buffers or images) refused: the render would overwrite its own input.
/// `what` says which output (`-o`, or a film's frame).
pub(super) fn not_an_input(scene: &scene::Scene, out: &Path, what: &str) -> crate::Result<()> {
    match scene.inputs.iter().find(|input| same_file(input, out)) {
        Some(input) => Err(Error::flag(
            "-o",
            format!(
                "{what} `{}` is {}, which the scene reads; it was left as it is",
                out.display(),
                input.display()
            ),
        )),
        None => Ok(()),
    }
}

pub(super) fn run_render(args: &RenderArgs) -> crate::Result<()> {
    // Check everything that can be checked before the (possibly long) render.
    let format = output::Format::for_path(&args.output).map_err(|e| e.on_flag("-o"))?;
    args.check_flags(format)?;
    let backend_name = args
        .backend
        .clone()
        .unwrap_or_else(|| accel::default_backend_name().to_string());
    let backend = accel::backend_by_name(&backend_name).map_err(|e| e.on_flag("--backend"))?;
    set_threads(args.threads)?;
    crate::render::simd_env_checked()?;
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
        // Each tile would stop at its own noise or time: the tiles would not join into the
        // one render `assemble` makes of them.
        if let Some(flag) = args.stop_flag() {
            return Err(Error::flag(
                flag,
                "applies to a whole still; a tile of --tiles renders its `samples`, so that the tiles join into one render",
            ));
        }
        let what = format!("tile {index}");
        output::file::refuse_link(&args.output, &what).map_err(|e| e.on_flag("-o"))?;
        let shown = format!("--tiles {}x{} --tile {index}", grid.0, grid.1);
        scene.image.crop = Some(tiles::tile_crop(&scene, format, grid, index, &shown)?);
    }
    fits_in_memory(&scene, format, args)?;
    // Said once per command (a film's frames share it), and not under --quiet.
    if let Some(w) = render::extrapolation_warning(&scene).filter(|_| !args.quiet) {
        crate::text::warn(w);
    }
    if !args.quiet {
        for w in &scene.warnings {
            crate::text::warn(format_args!("warning: {}", crate::text::shown(w)));
        }
    }
    // One frame of a film to a plain name (no run of #): a still of that frame.
    let plain = !args
        .output
        .file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.contains('#'));
    let single = args.frames.filter(|(a, b)| a == b).map(|(a, _)| a);
    if plain && (single.is_some() || args.still) || scene.film.is_none() && args.frames.is_none() {
        not_an_input(&scene, &args.output, "the output")?;
    }
    if plain && (single.is_some() || args.still) {
        if args.frames.is_some() && single.is_none() {
            return Err(Error::flag(
                "--frames",
                "--still renders one picture: give one frame (--frames K), not a range",
            ));
        }
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
        if let Some(flag) = args.stop_flag() {
            return Err(Error::flag(
                flag,
                "applies to a still image; a film's frames render their `samples` each",
            ));
        }
        return film::run(&scene, backend.as_ref(), &backend_name, format, args);
    }
    // A still (or a farm's tile) already written whole by this very render is kept.
    if args.resume && std::fs::symlink_metadata(&args.output).is_ok() {
        let shown = args.recorded();
        let id = output::header::render_id(&scene, &backend_name, &shown);
        let size = scene.image.frame_size();
        let storage = (args.compression.unwrap_or_default(), args.half);
        match output::finished(&args.output, format, size, &id, storage) {
            Ok(()) => {
                if !args.quiet {
                    crate::text::warn(format_args!(
                        "{}: a finished image of this render already (--resume): kept",
                        args.output.display()
                    ));
                }
                return Ok(());
            }
            Err(why) if !args.quiet => crate::text::warn(format_args!(
                "{} is not a finished image of this render ({why}): rendering it again",
                args.output.display()
            )),
            Err(_) => {}
        }
    }
    let t0 = std::time::Instant::now();
    // The EXR's header (the render id hashes the whole scene; 100,000 groups' Cryptomatte
    // names) is made on a thread of its own while the world builds, mostly on one core.
    let (world, exr) = std::thread::scope(|s| {
        let beside = format == output::Format::Exr && rayon::current_num_threads() > 1;
        let exr = beside.then(|| s.spawn(|| exr_options(&scene, &backend_name, args)));
        let world = render::World::build(&scene, backend.as_ref());
        let build_time = t0.elapsed();
        let exr = exr.map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)));
        (world.map(|w| (w, build_time)), exr)
    });
    let (world, build_time) = world?;
    // Into a folder that does not exist yet, as a film's frames go.
    if let Some(dir) = args.output.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| Error::flag("-o", folder_error(dir, &e)))?;
    }
    let mut stats = render_to_file(
        &scene,
        &world,
        &backend_name,
        format,
        args,
        &args.output,
        exr,
    )?;
    stats.build_time = build_time;
    warn_nonfinite(&stats, args.quiet);
    if !args.quiet {
        let secs = stats.trace_time.as_secs_f64();
        // As the file has them: a worldline's pieces are groups of their own to the renderer,
        // one rest frame each, said beside.
        let named = scene.named_groups().count();
        let primitives: usize = scene
            .named_groups()
            .map(|g| g.geometry.len() as usize)
            .sum();
        crate::text::warn(format_args!(
            "{}: {}x{}, {} spp, {} primitive{} in {} group{}{}, backend {backend_name}: build {:.3} s, render {:.3} s ({:.2} M primary rays/s)",
            args.output.display(),
            scene.image.frame_size().0,
            scene.image.frame_size().1,
            stats.samples.unwrap_or(scene.image.samples),
            primitives,
            if primitives == 1 { "" } else { "s" },
            named,
            if named == 1 { "" } else { "s" },
            if named == scene.groups.len() {
                String::new()
            } else {
                format!(" ({} rest frames)", scene.groups.len())
            },
            stats.build_time.as_secs_f64(),
            secs,
            stats.primary_rays as f64 / secs.max(1e-9) / 1e6
        ));
    }
    // The command ends here and its process with it: the world and the scene are left to the
    // operating system, which takes their memory back at once, instead of being freed piece by
    // piece (100,000 groups' trees, Embree scenes and tables took 0.09 s of a 3 s command).
    std::mem::forget(world);
    std::mem::forget(scene);
    Ok(())
}

pub(super) fn run_assemble(output: &Path, tiles: &[PathBuf]) -> crate::Result<()> {
    // A name of no image format is asked for as an EXR, the one assemble writes.
    if !matches!(output::Format::for_path(output), Ok(output::Format::Exr)) {
        return Err(Error::flag(
            "-o",
            format!(
                "`{}`: the assembled image is an EXR: give a name ending in .exr",
                output.display()
            ),
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

pub(super) fn warn_nonfinite(stats: &render::RenderStats, quiet: bool) {
    if stats.nonfinite_pixels > 0 && !quiet {
        crate::text::warn(format_args!(
            "warning: {} pixels came out NaN or infinite and were set to black; please report this scene",
            stats.nonfinite_pixels
        ));
    }
}
