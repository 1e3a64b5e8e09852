//! `rest-embree render` of a film: the frames of `[film]` (or the part `--frames A..B`), each
//! written whole to the file the `-o` pattern names (`out/frame-####.exr`), the groups and their
//! accelerators built once for all of them; `--resume` skips the frames already written.

use super::{render_to_file, warn_nonfinite, RenderArgs};
use crate::{accel, output, render, scene, Error};
use std::path::{Path, PathBuf};

/// `--frames`: `A..B` (both included) or `N`.
pub(super) fn parse_frames(text: &str) -> Result<(u64, u64), String> {
    let number = |t: &str| {
        t.trim()
            .parse::<u64>()
            .map_err(|_| format!("`{t}` is not a frame number (0, 1, 2, ...)"))
    };
    let (a, b) = match text.split_once("..") {
        Some((a, b)) => (number(a)?, number(b.trim_start_matches('='))?),
        None => {
            let n = number(text)?;
            (n, n)
        }
    };
    if b < a {
        return Err(format!(
            "the range {a}..{b} is empty: the first frame comes after the last"
        ));
    }
    Ok((a, b))
}

/// An output path with a run of `#` in its file name, replaced by the frame number padded with
/// zeros to the run's length.
pub(super) struct FramePattern {
    dir: PathBuf,
    before: String,
    width: usize,
    after: String,
}

impl FramePattern {
    /// The pattern `-o` gives; an error blamed on `-o` if it is none.
    pub fn parse(path: &Path) -> crate::Result<FramePattern> {
        let bad = |m: &str| Error::flag("-o", m);
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .ok_or_else(|| bad("the output needs a file name"))?;
        let start = name.find('#').ok_or_else(|| {
            bad("a film needs a frame pattern: a run of # in the file name, e.g. out/frame-####.exr")
        })?;
        let width = name[start..].chars().take_while(|&c| c == '#').count();
        let after = &name[start + width..];
        if after.contains('#') {
            return Err(bad("the file name has more than one run of #; give one"));
        }
        Ok(FramePattern {
            dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
            before: name[..start].to_string(),
            width,
            after: after.to_string(),
        })
    }

    pub fn path(&self, frame: u64) -> PathBuf {
        let w = self.width;
        self.dir
            .join(format!("{}{frame:0w$}{}", self.before, self.after))
    }
}

/// The frames `requested` (all by default), or why the film has no such frames.
pub(super) fn frame_range(
    film: &scene::Film,
    requested: Option<(u64, u64)>,
) -> crate::Result<(u64, u64)> {
    let count = film.frame_count();
    let (first, last) = requested.unwrap_or((0, count - 1));
    if last >= count {
        return Err(Error::flag(
            &format!("--frames {first}..{last}"),
            format!(
                "the film has frames 0..{} (view times {:?} to {:?})",
                count - 1,
                film.time(0),
                film.time(count - 1)
            ),
        ));
    }
    Ok((first, last))
}

/// Render the film's frames in order, each to its own file.
pub(super) fn run(
    scene: &scene::Scene,
    backend: &dyn accel::Backend,
    backend_name: &str,
    format: output::Format,
    args: &RenderArgs,
) -> crate::Result<()> {
    let Some(film) = &scene.film else {
        return Err(Error::flag(
            "--frames",
            "the scene is not a film: add a [film] table (start, end, fps or step) or --set film.end=... --set film.fps=...",
        ));
    };
    let (first, last) = frame_range(film, args.frames)?;
    let pattern = FramePattern::parse(&args.output)?;
    if let Some(dir) = pattern.dir.to_str().filter(|d| !d.is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::flag("-o", super::render_cmd::folder_error(Path::new(dir), &e)))?;
    }
    // Every frame's file, before any is written: none may be a link (it could lead to another
    // frame, which would be lost).
    for k in first..=last {
        let what = format!("frame {k}");
        crate::output::file::refuse_link(&pattern.path(k), &what)
            .map_err(|m| Error::flag("-o", m))?;
        super::render_cmd::not_an_input(scene, &pattern.path(k), &what)?;
    }
    let t0 = std::time::Instant::now();
    let rest = render::RestGroups::build(scene, backend, render::WorldOptions::default())?;
    let build = t0.elapsed().as_secs_f64();
    let (mut rendered, mut skipped) = (0u64, 0u64);
    let mut render_secs = 0.0;
    let shown: Vec<String> = args.overrides().into_iter().map(|(s, _)| s).collect();
    // A frame is done only if its file is a finished image of this very frame
    // (`output::finished`: every block decoded); anything else in its place is rendered again.
    // The files are checked all at once, on every core, before the first frame renders.
    let done: Vec<Option<crate::Result<()>>> = match args.resume {
        false => vec![None; (last - first + 1) as usize],
        true => {
            use rayon::prelude::*;
            (first..=last)
                .into_par_iter()
                .map(|k| {
                    let path = pattern.path(k);
                    std::fs::symlink_metadata(&path).ok()?;
                    let frame_scene = scene.film_frame(k).expect("a film");
                    let id = crate::output::header::render_id(&frame_scene, backend_name, &shown);
                    let size = frame_scene.image.frame_size();
                    let storage = (args.compression.unwrap_or_default(), args.half);
                    Some(crate::output::finished(&path, format, size, &id, storage))
                })
                .collect()
        }
    };
    for k in first..=last {
        let path = pattern.path(k);
        let frame_scene = scene.film_frame(k).expect("a film");
        match &done[(k - first) as usize] {
            Some(Ok(())) => {
                skipped += 1;
                continue;
            }
            Some(Err(why)) if !args.quiet => crate::text::warn(format_args!(
                "frame {k}: {} is not a finished frame of this render ({why}): rendering it again",
                path.display()
            )),
            Some(Err(_)) => {}
            None => {}
        }
        let t1 = std::time::Instant::now();
        let world = render::World::aim(&frame_scene, &rest, backend)?;
        let stats = render_to_file(
            &frame_scene,
            &world,
            backend_name,
            format,
            args,
            &path,
            None,
        )?;
        let secs = t1.elapsed().as_secs_f64();
        render_secs += secs;
        rendered += 1;
        warn_nonfinite(&stats, args.quiet);
        if !args.quiet {
            crate::text::warn(format_args!(
                "frame {k} ({} of {}..{last}), view time {:?}: {} in {secs:.3} s",
                k - first + 1,
                first,
                film.time(k),
                path.display()
            ));
        }
    }
    if !args.quiet {
        crate::text::warn(format_args!(
            "film: {rendered} frames rendered, {skipped} already there; build {build:.3} s once, frames {render_secs:.3} s ({backend_name})"
        ));
    }
    Ok(())
}
