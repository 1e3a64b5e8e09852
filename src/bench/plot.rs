//! The benchmark's plot: render time (x, log scale) against error (y, RMS against the 16-spp
//! f64 render, log scale), one point per row that has both, coloured by setting, written as a
//! PNG with a built-in 5×7 pixel font (no plotting library needed).

use super::Row;
use std::path::Path;

const W: usize = 900;
const H: usize = 560;
const LEFT: usize = 90;
const RIGHT: usize = 260;
const TOP: usize = 30;
const BOTTOM: usize = 60;

struct Canvas {
    px: Vec<[u8; 3]>,
}

impl Canvas {
    fn set(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as usize) < W && (y as usize) < H {
            self.px[y as usize * W + x as usize] = c;
        }
    }
    fn line(&mut self, (x0, y0): (i64, i64), (x1, y1): (i64, i64), c: [u8; 3]) {
        let n = (x1 - x0).abs().max((y1 - y0).abs()).max(1);
        for k in 0..=n {
            self.set(x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n, c);
        }
    }
    fn dot(&mut self, x: i64, y: i64, c: [u8; 3]) {
        for dy in -3i64..=3 {
            for dx in -3i64..=3 {
                if dx * dx + dy * dy <= 9 {
                    self.set(x + dx, y + dy, c);
                }
            }
        }
    }
    fn text(&mut self, x: i64, y: i64, s: &str, c: [u8; 3]) {
        for (i, ch) in s.chars().enumerate() {
            let g = glyph(ch);
            for (row, bits) in g.iter().enumerate() {
                for col in 0..5 {
                    if bits & (0x10 >> col) != 0 {
                        self.set(x + i as i64 * 6 + col, y + row as i64, c);
                    }
                }
            }
        }
    }
}

/// 5×7 glyphs for the characters the plot uses (others draw as a box).
fn glyph(c: char) -> [u8; 7] {
    match c.to_ascii_lowercase() {
        '0' => [0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e],
        '1' => [0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e],
        '2' => [0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f],
        '3' => [0x1f, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0e],
        '4' => [0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02],
        '5' => [0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e],
        '6' => [0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e],
        '7' => [0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e],
        '9' => [0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c],
        'a' => [0x00, 0x00, 0x0e, 0x01, 0x0f, 0x11, 0x0f],
        'b' => [0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x1e],
        'c' => [0x00, 0x00, 0x0e, 0x10, 0x10, 0x11, 0x0e],
        'd' => [0x01, 0x01, 0x0d, 0x13, 0x11, 0x11, 0x0f],
        'e' => [0x00, 0x00, 0x0e, 0x11, 0x1f, 0x10, 0x0e],
        'f' => [0x06, 0x09, 0x08, 0x1c, 0x08, 0x08, 0x08],
        'g' => [0x00, 0x0f, 0x11, 0x11, 0x0f, 0x01, 0x0e],
        'h' => [0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11],
        'i' => [0x04, 0x00, 0x0c, 0x04, 0x04, 0x04, 0x0e],
        'k' => [0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12],
        'l' => [0x0c, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e],
        'm' => [0x00, 0x00, 0x1a, 0x15, 0x15, 0x11, 0x11],
        'n' => [0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11],
        'o' => [0x00, 0x00, 0x0e, 0x11, 0x11, 0x11, 0x0e],
        'p' => [0x00, 0x00, 0x1e, 0x11, 0x1e, 0x10, 0x10],
        'r' => [0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10],
        's' => [0x00, 0x00, 0x0e, 0x10, 0x0e, 0x01, 0x1e],
        't' => [0x08, 0x08, 0x1c, 0x08, 0x08, 0x09, 0x06],
        'u' => [0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0d],
        'v' => [0x00, 0x00, 0x11, 0x11, 0x11, 0x0a, 0x04],
        'w' => [0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0a],
        'x' => [0x00, 0x00, 0x11, 0x0a, 0x04, 0x0a, 0x11],
        'y' => [0x00, 0x00, 0x11, 0x11, 0x0f, 0x01, 0x0e],
        'z' => [0x00, 0x00, 0x1f, 0x02, 0x04, 0x08, 0x1f],
        '.' => [0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c],
        '-' => [0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00],
        '=' => [0x00, 0x00, 0x1f, 0x00, 0x1f, 0x00, 0x00],
        '(' => [0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02],
        ')' => [0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08],
        ',' => [0x00, 0x00, 0x00, 0x00, 0x0c, 0x04, 0x08],
        ' ' => [0; 7],
        _ => [0x1f, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1f],
    }
}

/// One colour per setting of the full suite (eleven), so no two share one.
const PALETTE: [[u8; 3]; 12] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [23, 190, 207],
    [188, 189, 34],
    [0, 0, 0],
    [127, 127, 127],
    [100, 20, 120],
];

/// Plot the rows that have a render time and an error against the 16-spp reference.
pub fn plot_png(rows: &[Row], path: &Path) -> crate::Result<()> {
    let pts: Vec<(String, f64, f64)> = rows
        .iter()
        .filter_map(|r| {
            let e = r.vs_hi.as_ref()?.rms;
            (r.render_s.is_finite() && r.render_s > 0.0 && e > 0.0)
                .then(|| (format!("{} {}spp", r.setting, r.spp), r.render_s, e))
        })
        .collect();
    let mut c = Canvas {
        px: vec![[255, 255, 255]; W * H],
    };
    let (x0, x1, y0, y1) = (
        LEFT as i64,
        (W - RIGHT) as i64,
        (H - BOTTOM) as i64,
        TOP as i64,
    );
    c.line((x0, y0), (x1, y0), [0, 0, 0]);
    c.line((x0, y0), (x0, y1), [0, 0, 0]);
    c.text(x0 + 120, y0 + 40, "render time (s, log)", [0, 0, 0]);
    c.text(8, y1 - 20, "rms error vs 16 spp f64 (log)", [0, 0, 0]);
    if pts.is_empty() {
        c.text(
            x0 + 40,
            (y0 + y1) / 2,
            "no rows with a 16 spp reference",
            [0, 0, 0],
        );
    } else {
        let lg = |v: f64| v.log10();
        let (tmin, tmax) = pts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(lg(p.1)), b.max(lg(p.1)))
            });
        let (emin, emax) = pts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(lg(p.2)), b.max(lg(p.2)))
            });
        let (tmin, tmax) = (tmin.floor(), tmax.ceil().max(tmin.floor() + 1.0));
        let (emin, emax) = (emin.floor(), emax.ceil().max(emin.floor() + 1.0));
        let sx = |t: f64| x0 + ((lg(t) - tmin) / (tmax - tmin) * (x1 - x0) as f64) as i64;
        let sy = |e: f64| y0 - ((lg(e) - emin) / (emax - emin) * (y0 - y1) as f64) as i64;
        for d in tmin as i64..=tmax as i64 {
            let x = x0 + ((d as f64 - tmin) / (tmax - tmin) * (x1 - x0) as f64) as i64;
            c.line((x, y0), (x, y0 + 5), [0, 0, 0]);
            c.text(x - 12, y0 + 12, &format!("1e{d}"), [0, 0, 0]);
        }
        for d in emin as i64..=emax as i64 {
            let y = y0 - ((d as f64 - emin) / (emax - emin) * (y0 - y1) as f64) as i64;
            c.line((x0 - 5, y), (x0, y), [0, 0, 0]);
            c.text(x0 - 40, y - 3, &format!("1e{d}"), [0, 0, 0]);
        }
        let mut labels: Vec<String> = Vec::new();
        for (label, t, e) in &pts {
            let k = labels.iter().position(|l| l == label).unwrap_or_else(|| {
                labels.push(label.clone());
                labels.len() - 1
            });
            c.dot(sx(*t), sy(*e), PALETTE[k % PALETTE.len()]);
        }
        for (k, l) in labels.iter().enumerate() {
            let y = y1 + 14 * k as i64;
            c.dot(x1 + 20, y + 3, PALETTE[k % PALETTE.len()]);
            c.text(x1 + 30, y, l, [0, 0, 0]);
        }
    }
    let failed = |e: &dyn std::fmt::Display| {
        crate::Error::image(
            path,
            format!("cannot write `{}`: {e}", path.display()),
            None,
        )
    };
    let file = std::fs::File::create(path).map_err(|e| failed(&e))?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), W as u32, H as u32);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let data: Vec<u8> = c.px.iter().flatten().copied().collect();
    enc.write_header()
        .and_then(|mut w| w.write_image_data(&data))
        .map_err(|e| failed(&e))
}
