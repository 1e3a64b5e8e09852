//! The benchmark's plot: render time (x, log scale) against error (y, RMS against the 16-spp
//! f64 render, log scale), one point per row that has both, coloured by setting, drawn with
//! plotters as SVG (text in SVG needs no font on the machine that draws it).

use super::Row;
use plotters::prelude::*;
use std::path::Path;

/// One colour per setting of the full suite (eleven), so no two share one.
const PALETTE: [RGBColor; 12] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(0, 0, 0),
    RGBColor(127, 127, 127),
    RGBColor(100, 20, 120),
];

/// The decades around `values` (at least one): the axis range of a log scale.
fn decades(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v.log10()), b.max(v.log10()))
    });
    let lo = lo.floor();
    10f64.powf(lo)..10f64.powf(hi.ceil().max(lo + 1.0))
}

/// Plot the rows that have a render time and an error against the 16-spp reference.
pub(crate) fn plot_svg(rows: &[Row], path: &Path) -> crate::Result<()> {
    let pts: Vec<(String, f64, f64)> = rows
        .iter()
        .filter_map(|r| {
            let e = r.vs_hi.as_ref()?.rms;
            (r.render_s.is_finite() && r.render_s > 0.0 && e > 0.0)
                .then(|| (format!("{} {}spp", r.setting, r.spp), r.render_s, e))
        })
        .collect();
    draw(&pts, path).map_err(|e| {
        crate::Error::image(
            path,
            format!("cannot write `{}`: {e}", path.display()),
            None,
        )
    })
}

fn draw(pts: &[(String, f64, f64)], path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let (x, y) = if pts.is_empty() {
        (0.1..10.0, 1e-4..1e-2)
    } else {
        (
            decades(pts.iter().map(|p| p.1)),
            decades(pts.iter().map(|p| p.2)),
        )
    };
    let mut chart = ChartBuilder::on(&root)
        .caption("run time against error", ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(x.log_scale(), y.log_scale())?;
    chart
        .configure_mesh()
        .x_desc("render time (s)")
        .y_desc("RMS error against 16 spp, f64 BVH")
        .x_label_formatter(&|v| format!("{v:e}"))
        .y_label_formatter(&|v| format!("{v:e}"))
        .draw()?;
    if pts.is_empty() {
        root.draw(&Text::new(
            "no rows with a 16 spp reference",
            (300, 280),
            ("sans-serif", 16),
        ))?;
    }
    let mut labels: Vec<&str> = Vec::new();
    for (label, _, _) in pts {
        if !labels.contains(&label.as_str()) {
            labels.push(label);
        }
    }
    for (k, label) in labels.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let mine = pts.iter().filter(|p| p.0 == *label);
        chart
            .draw_series(mine.map(|p| Circle::new((p.1, p.2), 4, colour.filled())))?
            .label(*label)
            .legend(move |(x, y)| Circle::new((x, y), 4, colour.filled()));
    }
    if !labels.is_empty() {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
    }
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decades_hold_the_values() {
        let r = decades([0.02, 3.0].into_iter());
        assert!((r.start - 0.01).abs() < 1e-12 && (r.end - 10.0).abs() < 1e-9);
        let one = decades([5.0].into_iter());
        assert!((one.start - 1.0).abs() < 1e-12 && (one.end - 10.0).abs() < 1e-9);
    }
}
