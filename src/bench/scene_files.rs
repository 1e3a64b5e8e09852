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

/// Markdown lines, one per kind of file. Each file is read in a process of its own (this
/// program, run again): in a process that has freed memory before, the reading would reuse it
/// and its peak would not show.
pub(crate) fn summary(quick: bool) -> String {
    let scale = if quick { 1 } else { 4 };
    let mut out = String::new();
    for (kind, size) in [("groups", 10_000 * scale), ("mesh", 25_000 * scale)] {
        let line = std::env::current_exe()
            .and_then(|exe| {
                std::process::Command::new(exe)
                    .args(["bench-scene-file", kind, &size.to_string()])
                    .output()
            })
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
            .unwrap_or_else(|e| format!("- scene file, {kind}: not measured: {e}"));
        let _ = writeln!(out, "{line}");
    }
    out
}

/// Generate a file of `kind` (`groups`: that many groups of one sphere; `mesh`: that many
/// triangles inline), read it here, and say what it cost as a Markdown line.
pub(crate) fn scene_file_here(kind: &str, size: usize) -> String {
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
    }
}
