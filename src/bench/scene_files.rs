//! What reading a scene file costs: the peak memory above the file's own text, per byte of the
//! file, and the time, for the two shapes of big file people write: an inline mesh (a file of
//! numbers) and many small velocity groups (a file of keys and tables).

use super::memory::{peak_mib, reset_peak};
use std::fmt::Write;
use std::time::Instant;

/// An inline mesh of `triangles` separate triangles.
fn inline_mesh(triangles: usize) -> String {
    let mut rng = crate::rng::Rng(7);
    let mut unit = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    let mut s = String::from(
        "[camera]\nposition = [0.3, 0.2, 10]\nlook_at = [0, 0, 0]\n\n[[group]]\nname = \"mesh\"\n\
         velocity = [0.5, 0, 0]\n\n[[group.object]]\ntype = \"mesh\"\nvertices = [\n",
    );
    for _ in 0..3 * triangles {
        let _ = writeln!(s, "  [{:.6}, {:.6}, {:.6}],", unit(), unit(), unit());
    }
    s.push_str("]\nindices = [\n");
    for t in 0..triangles {
        let _ = writeln!(s, "  [{}, {}, {}],", 3 * t, 3 * t + 1, 3 * t + 2);
    }
    s.push_str("]\n");
    s
}

/// `n` groups of one sphere each.
fn many_groups(n: usize) -> String {
    let mut s = String::from("[camera]\nposition = [0.3, 0.2, 10]\nlook_at = [0, 0, 0]\n");
    for i in 0..n {
        let _ = write!(
            s,
            "\n[[group]]\nname = \"g{i}\"\nvelocity = [0.1, 0.0, 0.0]\n\n[[group.object]]\n\
             type = \"sphere\"\ncenter = [{i}.0, 0.0, 0.0]\nradius = 0.25\n"
        );
    }
    s
}

/// A binary (little-endian) PLY of a height field of about `triangles` triangles over
/// [-1, 1]², its vertices shared by the triangles around them (float positions, int indices),
/// as a scanner or a modeller writes a big mesh.
fn write_ply_terrain(path: &std::path::Path, triangles: usize) -> std::io::Result<usize> {
    use std::io::Write as _;
    let n = (((triangles / 2) as f64).sqrt().ceil() as usize).max(1);
    let (verts, faces) = ((n + 1) * (n + 1), 2 * n * n);
    let mut out = std::io::BufWriter::with_capacity(1 << 20, std::fs::File::create(path)?);
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment rest-embree bench terrain\n\
         element vertex {verts}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
    )?;
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (
                2.0 * i as f64 / n as f64 - 1.0,
                2.0 * j as f64 / n as f64 - 1.0,
            );
            let z = 0.08 * ((7.0 * x).sin() * (5.0 * y).cos()) + 0.03 * (23.0 * (x + y)).sin();
            for c in [x, y, z] {
                out.write_all(&(c as f32).to_le_bytes())?;
            }
        }
    }
    let at = |i: usize, j: usize| (j * (n + 1) + i) as i32;
    for j in 0..n {
        for i in 0..n {
            for t in [
                [at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                [at(i, j), at(i + 1, j + 1), at(i, j + 1)],
            ] {
                out.write_all(&[3u8])?;
                for k in t {
                    out.write_all(&k.to_le_bytes())?;
                }
            }
        }
    }
    out.flush()?;
    Ok(faces)
}

/// What reading, building and rendering a scene file cost: its frame, the seconds of each
/// step, and the peak memory above the process's start, after reading and at the end (MiB).
struct Measured {
    frame: crate::render::Frame,
    read: f64,
    read_peak: f64,
    build: f64,
    render: f64,
    peak: f64,
}

/// Read the scene file at `path`, build its world on `backend` and render it, measuring each.
fn measure(path: &std::path::Path, backend: &str) -> Result<Measured, Box<dyn std::error::Error>> {
    reset_peak();
    let base = peak_mib().unwrap_or(0.0);
    let t0 = Instant::now();
    let scene = crate::scene::load_file(path, &[])?;
    let read = t0.elapsed().as_secs_f64();
    let read_peak = peak_mib().unwrap_or(0.0) - base;
    let b = crate::accel::backend_by_name(backend)?;
    let t1 = Instant::now();
    let world = crate::render::World::build(&scene, b.as_ref())?;
    let build = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let (frame, _) = crate::render::render_world(&scene, &world);
    let render = t2.elapsed().as_secs_f64();
    Ok(Measured {
        frame,
        read,
        read_peak,
        build,
        render,
        peak: peak_mib().unwrap_or(0.0) - base,
    })
}

/// Write a terrain of about `triangles` triangles as a PLY file, then read it through a
/// scene, build the world and render it at `size`², as a Markdown line with the time and
/// peak memory of each step.
fn mesh_file_here(triangles: usize, size: u32, backend: &str) -> String {
    let dir = std::env::temp_dir().join(format!("rest-embree-bench-mesh-{}", std::process::id()));
    let line = (|| -> Result<String, Box<dyn std::error::Error>> {
        std::fs::create_dir_all(&dir)?;
        let ply = dir.join("terrain.ply");
        let faces = write_ply_terrain(&ply, triangles)?;
        let file_mb = std::fs::metadata(&ply).map(|m| m.len()).unwrap_or(0) as f64 / 1e6;
        let text = format!(
            "[camera]\nposition = [0, -2.2, 1.4]\nlook_at = [0, 0, 0]\nup = [0, 0, 1]\ntime = 2.6\n\n\
             [image]\nwidth = {size}\nheight = {size}\n\n\
             [[light]]\nposition = [2, -2, 4]\n\n\
             [[group]]\nname = \"terrain\"\nvelocity = [0.9, 0, 0]\n\n\
             [[group.object]]\ntype = \"mesh\"\nfile = \"terrain.ply\"\n"
        );
        let scene_path = dir.join("terrain.toml");
        std::fs::write(&scene_path, text)?;
        let Measured {
            frame,
            read,
            read_peak,
            build,
            render,
            peak,
        } = measure(&scene_path, backend)?;
        let hit = frame.pixels.iter().filter(|p| p.color != [0.0; 3]).count();
        Ok(format!(
            "- mesh file, a binary PLY of {faces} triangles ({file_mb:.0} MB), {backend}, \
             moving at 0.9c: read in {read:.2} s (peak {read_peak:.0} MiB), built in {build:.2} s, \
             rendered at {size}² in {render:.2} s ({hit} pixels not black); peak memory \
             {peak:.0} MiB above the process's start = {:.0} bytes per triangle",
            peak * 1048576.0 / faces as f64
        ))
    })();
    let _ = std::fs::remove_dir_all(&dir);
    line.unwrap_or_else(|e| format!("- mesh file of {triangles} triangles: not measured: {e}"))
}

/// Write a terrain of about `triangles` triangles as a PLY file and a scene that places it
/// `placements` times (a grid of entries naming the one file, each turned its own way, so the
/// mesh is held once), then read, build and render it at `size`² on `backend`, as a Markdown
/// line with the time and peak memory of each step.
fn mesh_instances_here(placements: usize, triangles: usize, size: u32, backend: &str) -> String {
    let dir = std::env::temp_dir().join(format!(
        "rest-embree-bench-instances-{}",
        std::process::id()
    ));
    let line = (|| -> Result<String, Box<dyn std::error::Error>> {
        std::fs::create_dir_all(&dir)?;
        let faces = write_ply_terrain(&dir.join("terrain.ply"), triangles)?;
        let side = (placements as f64).sqrt().ceil() as usize;
        let reach = 1.1 * side as f64;
        let mut text = format!(
            "[camera]\nposition = [0, {:.3}, {:.3}]\nlook_at = [0, 0, 0]\nup = [0, 0, 1]\n\n\
             [image]\nwidth = {size}\nheight = {size}\n\n\
             [[light]]\nposition = [2, -2, {:.3}]\n\n\
             [[group]]\nname = \"field\"\n",
            -1.6 * reach - 2.0,
            1.2 * reach + 1.0,
            2.0 * reach + 2.0
        );
        for k in 0..placements {
            let (i, j) = ((k % side) as f64, (k / side) as f64);
            let _ = write!(
                text,
                "\n[[group.object]]\ntype = \"mesh\"\nfile = \"terrain.ply\"\n\
                 translate = [{:.3}, {:.3}, 0]\nrotate = {{ axis = [0, 0, 1], degrees = {} }}\n",
                2.2 * i - reach + 1.1,
                2.2 * j - reach + 1.1,
                (k * 37) % 360
            );
        }
        let scene_path = dir.join("field.toml");
        std::fs::write(&scene_path, text)?;
        let Measured {
            frame,
            read,
            build,
            render,
            peak,
            ..
        } = measure(&scene_path, backend)?;
        let hit = frame.pixels.iter().filter(|p| p.object_id > 0).count();
        let times = match placements {
            1 => "once".to_string(),
            n => format!("{n} times"),
        };
        Ok(format!(
            "- mesh placed {times}, a binary PLY of {faces} triangles, {backend}: \
             read in {read:.2} s, built in {build:.2} s, rendered at {size}² in {render:.2} s \
             ({hit} pixels see it); peak memory {peak:.0} MiB above the process's start"
        ))
    })();
    let _ = std::fs::remove_dir_all(&dir);
    line.unwrap_or_else(|e| format!("- mesh placed {placements} times: not measured: {e}"))
}

/// Markdown lines, one per kind of file. Each file is read in a process of its own (this
/// program, run again): in a process that has freed memory before, the reading would reuse it
/// and its peak would not show.
pub(crate) fn summary(quick: bool) -> String {
    let scale = if quick { 1 } else { 4 };
    let mut out = String::new();
    let triangles = if quick { 200_000 } else { 10_000_000 };
    let placed = if quick { 20_000 } else { 1_000_000 };
    let mut peaks = Vec::new();
    for (kind, size) in [
        ("groups".to_string(), 10_000 * scale),
        ("mesh".to_string(), 25_000 * scale),
        ("mesh-file".to_string(), triangles),
        // One placement of a mesh, then many: what the placements cost beside the mesh.
        (format!("instances-{placed}"), 1),
        (format!("instances-{placed}"), if quick { 50 } else { 1000 }),
    ] {
        let line = std::env::current_exe()
            .and_then(|exe| {
                std::process::Command::new(exe)
                    .args(["bench-scene-file", &kind, &size.to_string()])
                    .output()
            })
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
            .unwrap_or_else(|e| format!("- scene file, {kind}: not measured: {e}"));
        let _ = writeln!(out, "{line}");
        peaks.push(peak_of(&line));
    }
    // The placements' cost: the peak of many placements against one's.
    if let [.., Some(one), Some(many)] = peaks[..] {
        let _ = writeln!(
            out,
            "- so the placements cost {:.2}x one placement's peak memory",
            many / one
        );
    }
    out
}

/// The "peak memory N MiB" a line says.
fn peak_of(line: &str) -> Option<f64> {
    let after = line.rsplit("peak memory ").next()?;
    after.split(' ').next()?.parse().ok()
}

/// Generate a file of `kind` (`groups`: that many groups of one sphere; `mesh`: that many
/// triangles inline), read it here, and say what it cost as a Markdown line.
pub(crate) fn scene_file_here(kind: &str, size: usize) -> String {
    // `instances-T`: a mesh of T triangles placed `size` times.
    if let Some(triangles) = kind.strip_prefix("instances-").and_then(|t| t.parse().ok()) {
        let px = if triangles < 1_000_000 { 256 } else { 1024 };
        return mesh_instances_here(size, triangles, px, crate::accel::default_backend_name());
    }
    if kind == "mesh-file" {
        let px = if size < 1_000_000 { 256 } else { 1024 };
        return mesh_file_here(size, px, crate::accel::default_backend_name());
    }
    let (what, text) = match kind {
        "groups" => (format!("{size} groups of one sphere"), many_groups(size)),
        "mesh" => (
            format!("an inline mesh of {size} triangles"),
            inline_mesh(size),
        ),
        _ => return format!("- scene file: no generated file of kind `{kind}`"),
    };
    let start = Instant::now();
    reset_peak();
    let before = peak_mib();
    let loaded = crate::scene::load_str("bench.toml", &text, &[]);
    let after = peak_mib();
    let secs = start.elapsed().as_secs_f64();
    let mb = text.len() as f64 / 1e6;
    match (loaded, before, after) {
        (Ok(_), Some(b), Some(a)) => format!(
            "- scene file, {what} ({mb:.1} MB): read in {secs:.2} s, peak memory {:.0} MiB \
             above its text = {:.1} bytes per byte of the file; the estimate a render checks \
             against its memory, an upper bound, {:.0} MiB",
            a - b,
            (a - b) * 1048576.0 / text.len() as f64,
            crate::memory::scene_bytes(text.as_bytes()) as f64 / 1048576.0
        ),
        (Ok(_), _, _) => format!("- scene file, {what} ({mb:.1} MB): read in {secs:.2} s"),
        (Err(e), _, _) => format!("- scene file, {what}: not read: {e}"),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn both_files_are_read_and_measured() {
        for (kind, size) in [("groups", 100), ("mesh", 100)] {
            let s = super::scene_file_here(kind, size);
            assert!(s.contains("read in") && !s.contains("not read"), "{s}");
        }
        // A mesh placed 30 times: held once, in view.
        let s = super::scene_file_here("instances-2000", 30);
        assert!(
            s.contains("placed 30 times") && s.contains("2048 triangles"),
            "{s}"
        );
        assert_eq!(super::peak_of("a; peak memory 291 MiB above"), Some(291.0));
        assert!(!s.contains(" 0 pixels see it"), "{s}");
        // A PLY file written, read, built and rendered: the terrain is in view.
        let s = super::scene_file_here("mesh-file", 2000);
        assert!(
            s.contains("2048 triangles") && s.contains("rendered at 256²"),
            "{s}"
        );
        let lit: u64 = s
            .split(" pixels not black")
            .next()
            .and_then(|a| a.rsplit('(').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or(0);
        assert!(lit > 256 * 256 / 10, "{s}");
    }
}
