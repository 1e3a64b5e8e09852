//! The bench's report: its rows as a Markdown table, and the summary lines derived from them
//! (ratios between settings, and against the scenes measured beside them).

use super::Row;
use std::fmt::Write as _;

fn opt(v: Option<f64>, f: impl Fn(f64) -> String) -> String {
    v.filter(|x| x.is_finite())
        .map(f)
        .unwrap_or_else(|| "—".into())
}

/// The rows as a Markdown table, with the derived ratios the issue asks for.
pub(crate) fn table(rows: &[Row]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| case | setting | spp | image | prims | groups | build s | primary Mrays/s | render s | whole s | peak MiB | differing px vs f64 (same spp) | RMS vs f64 16 spp |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {}x{} | {} | {} | {:.3} | {:.2} | {} | {} | {} | {} | {} |",
            r.case,
            r.setting,
            r.spp,
            r.width,
            r.height,
            r.primitives,
            r.groups,
            r.build_s,
            r.mrays_per_s(),
            opt(Some(r.render_s), |x| format!("{x:.3}")),
            opt(Some(r.whole_s()), |x| format!("{x:.3}")),
            opt(r.peak_mib, |x| format!("{x:.0}")),
            opt(
                r.vs_same.as_ref().map(|c| c.differing_share()),
                |x| format!("{:.3}%", 100.0 * x)
            ),
            opt(r.vs_hi.as_ref().map(|c| c.rms), |x| format!("{x:.2e}")),
        );
    }
    s
}

/// The headline ratios, computed from the rows.
pub(crate) fn summary(rows: &[Row]) -> String {
    let mut s = String::new();
    let find = |case: &str, setting: &str| {
        rows.iter()
            .find(|r| r.case == case && r.setting == setting && r.spp == 1)
    };
    let cases: Vec<&str> = {
        let mut v: Vec<&str> = rows.iter().map(|r| r.case.as_str()).collect();
        v.dedup();
        v
    };
    for c in &cases {
        if let (Some(e), Some(b)) = (find(c, "embree"), find(c, "embree bare (no relativity)")) {
            let _ = write!(s, "- {c}: embree through the relativistic layer / bare Embree on the same rays = {:.2}", e.mrays_per_s() / b.mrays_per_s());
            if let Some(n) = find(c, "embree no-cull") {
                let _ = write!(
                    s,
                    " (without bounds and screen culling: {:.2})",
                    n.mrays_per_s() / b.mrays_per_s()
                );
            }
            if let Some(n) = find(c, "embree no-fused") {
                let _ = write!(
                    s,
                    " (primary rays made one by one, no fans: {:.2})",
                    n.mrays_per_s() / b.mrays_per_s()
                );
            }
            s.push('\n');
        }
        if let (Some(e), Some(b)) = (find(c, "embree"), find(c, "bvh")) {
            let _ = writeln!(
                s,
                "- {c}: embree / bvh primary throughput = {:.2}x (render time {:.2}x, whole command {:.2}x)",
                e.mrays_per_s() / b.mrays_per_s(),
                b.render_s / e.render_s,
                b.whole_s() / e.whole_s()
            );
        }
    }
    // Every pass (the default EXR) against an EXR of colour and alpha and a PNG (colour alone):
    // the render, and the whole command (its file written).
    for all in rows.iter().filter(|r| r.setting == "embree") {
        let find = |setting: &str| {
            rows.iter()
                .find(|r| r.case == all.case && r.spp == all.spp && r.setting == setting)
        };
        let (Some(rgba), Some(png)) = (find("embree rgba"), find("embree colour-only")) else {
            continue;
        };
        let _ = writeln!(
            s,
            "- {} at {} spp (embree): render time with every pass {:.3} s, colour only {:.3} s \
             ({:.2}x as fast); whole command to the default EXR {:.3} s, to an EXR of colour and \
             alpha {:.3} s ({:.2}x as fast), to a PNG {:.3} s ({:.2}x)",
            all.case,
            all.spp,
            all.render_s,
            rgba.render_s,
            all.render_s / rgba.render_s,
            all.whole_s(),
            rgba.whole_s(),
            all.whole_s() / rgba.whole_s(),
            png.whole_s(),
            all.whole_s() / png.whole_s(),
        );
    }
    // Rows against the scene measured beside them: many groups against the same boxes in one
    // group, light as a camera records it against the RGB render.
    for r in rows.iter() {
        if let Some(o) = &r.beside {
            let _ = writeln!(
                s,
                "- {} ({}): render time {:.3} s = {:.2}x that of {} ({:.3} s); \
                 build + first render {:.3} s = {:.2}x ({:.3} s)",
                r.case,
                r.setting,
                r.render_s,
                r.render_s / o.render_s,
                o.what,
                o.render_s,
                r.build_s + r.first_render_s,
                (r.build_s + r.first_render_s) / (o.build_s + o.first_render_s),
                o.build_s + o.first_render_s
            );
        }
    }
    for r in rows.iter().filter(|r| r.case.contains("^3")) {
        let _ = writeln!(
            s,
            "- {} ({}): build {:.2} s + first render {:.2} s = {:.2} s wall, peak {} MiB",
            r.case,
            r.setting,
            r.build_s,
            r.first_render_s,
            r.build_s + r.first_render_s,
            opt(r.peak_mib, |x| format!("{x:.0}"))
        );
    }
    s
}
