//! What writing an EXR costs: the paper's lattice at 0.9c rendered once, then written with the
//! default passes and with colour and alpha alone, beside OpenImageIO's `oiiotool` writing the
//! same channels with the same compression (its own timing of its `-o`, from `--runstats`, so
//! reading its input is not counted).

use crate::accel::backend_by_name;
use crate::output::{self, ExrOptions};
use crate::render::{render_world, World};
use crate::scene::PassSet;
use std::fmt::Write as _;
use std::path::Path;

/// Markdown lines: each writer's seconds and raw MB/s.
pub(crate) fn summary(quick: bool, backend: &str) -> crate::Result<String> {
    let size = if quick { 512 } else { 1024 };
    let scene = super::paper(
        "lattice",
        &[
            format!("image.width={size}"),
            format!("image.height={size}"),
            "group.lattice.velocity=[-0.9, 0, 0]".into(),
        ],
    )?;
    let b = backend_by_name(backend)?;
    let world = World::build(&scene, b.as_ref())?;
    let (frame, _) = render_world(&scene, &world);
    world.check()?;
    let dir = std::env::temp_dir().join(format!("rest-embree-bench-exr-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| {
        crate::Error::image(
            &dir,
            "cannot make the bench's folder",
            Some(std::sync::Arc::new(e)),
        )
    })?;
    let result = (|| {
        let mut lines = String::new();
        let pixels = f64::from(size) * f64::from(size);
        let mut default_s = f64::NAN;
        for (what, passes) in [
            ("default passes", PassSet::ALL),
            ("colour and alpha alone", PassSet::NONE),
        ] {
            let exr = ExrOptions {
                passes,
                ..ExrOptions::for_render(&scene, backend, "bench", &[])
            };
            let path = dir.join("ours.exr");
            let secs = super::fastest(super::Timing::new(3, quick), || {
                output::write_with(&frame, &path, &exr).expect("bench EXR written");
            });
            let channels = channel_count(&path)?;
            let mb = pixels * 4.0 * channels as f64 / 1e6;
            let vs = if passes == PassSet::ALL {
                default_s = secs;
                String::new()
            } else {
                format!(", {:.1}x faster than the default", default_s / secs)
            };
            let _ = writeln!(
                lines,
                "- EXR writing, {what} ({channels} channels, {mb:.0} MB raw, zip), the lattice at {size}x{size}: {secs:.3} s = {:.0} MB/s{vs}",
                mb / secs
            );
            if passes == PassSet::ALL {
                lines.push_str(&oiiotool_line(&path, mb, secs));
            }
        }
        Ok(lines)
    })();
    let _ = std::fs::remove_dir_all(&dir);
    result
}

fn channel_count(path: &Path) -> crate::Result<usize> {
    let (_, _, channels) = output::read_exr_channels(path)?;
    Ok(channels.len())
}

/// oiiotool writing the file at `path` again, same channels and compression: its `-o` time
/// by `--runstats`, fastest of three; a line saying why where it cannot run.
fn oiiotool_line(path: &Path, mb: f64, ours: f64) -> String {
    let copy = path.with_file_name("oiiotool.exr");
    let mut best = f64::INFINITY;
    let mut version = String::new();
    for _ in 0..3 {
        let out = std::process::Command::new("oiiotool")
            .arg("--runstats")
            .arg(path)
            .args(["--compression", "zip", "-o"])
            .arg(&copy)
            .output();
        let Some(out) = out.ok().filter(|o| o.status.success()) else {
            return "- EXR writing, oiiotool: not measured (oiiotool did not run; scripts/setup.sh installs openimageio-tools)\n".into();
        };
        let text = String::from_utf8_lossy(&out.stdout);
        let o = text.lines().find_map(|l| {
            let (name, secs) = l.split_once(':')?;
            (name.trim() == "-o").then(|| secs.trim().parse::<f64>().ok())?
        });
        match o {
            Some(s) => best = best.min(s),
            None => {
                return "- EXR writing, oiiotool: not measured (no `-o` time in its --runstats)\n"
                    .into()
            }
        }
        if version.is_empty() {
            version = std::process::Command::new("oiiotool")
                .arg("--version")
                .output()
                .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
                .unwrap_or_default();
        }
    }
    format!(
        "- EXR writing, oiiotool {version} writing the same channels, zip ({threads} threads): {best:.3} s = {:.0} MB/s; rest-embree's writer is {:.2}x its speed\n",
        mb / best,
        best / ours,
        threads = rayon::current_num_threads(),
    )
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_writing_lines_are_measured() {
        let lines = super::summary(true, "bvh").unwrap();
        eprintln!("{lines}");
        assert!(lines.contains("default passes (46 channels"), "{lines}");
        assert!(
            lines.contains("colour and alpha alone (4 channels"),
            "{lines}"
        );
        assert!(lines.contains("oiiotool"), "{lines}");
        assert_eq!(lines.lines().count(), 3, "{lines}");
    }
}
