//! The camera's spectral response: CIE 1931 2° colour matching to XYZ, then linear sRGB
//! (IEC 61966-2-1 primaries, D65 white, no chromatic adaptation).
//!
//! The camera reads radiance at `SAMPLES` (64) fixed wavelengths, the geometric centres of bins of
//! equal width in ln λ over 380-780 nm (so a Doppler shift, a factor on every wavelength, moves
//! them all by the same distance in ln λ); bin i weighs by the integral of x̄, ȳ, z̄ over the bin
//! (trapezoids on the 1 nm table). Radiance that is constant over each bin is integrated
//! exactly; docs/physics.md gives the error against the 1 nm integral for blackbodies, lines
//! and the white.

use super::cie_data::{CMF_1931, CMF_START, D65, D65_START, D65_STEP};
use super::{planck, Sampled, SAMPLES};
use glam::{DMat3, DVec3};
use std::sync::OnceLock;

/// The band the camera sees, nm.
pub(crate) const BAND: (f64, f64) = (380.0, 780.0);

/// XYZ to linear sRGB (IEC 61966-2-1's matrix, rows R, G, B).
pub const XYZ_TO_SRGB: DMat3 = DMat3::from_cols_array(&[
    3.2406, -0.9689, 0.0557, -1.5372, 1.8758, -0.2040, -0.4986, 0.0415, 1.0570,
]);

/// sRGB's chromaticities (red, green, blue, white) as the EXR header states them.
pub(crate) const SRGB_CHROMATICITIES: [[f32; 2]; 4] =
    [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06], [0.3127, 0.3290]];

/// The bins' width in ln λ.
pub(crate) fn ln_step() -> f64 {
    (BAND.1 / BAND.0).ln() / SAMPLES as f64
}

struct Response {
    lambda: [f64; SAMPLES],
    /// The linear sRGB weights by channel, for vectorised sums.
    rgb_rows: [[f64; SAMPLES]; 3],
    /// x̄, ȳ, z̄ integrated over each bin.
    xyz: [DVec3; SAMPLES],
    /// D65 over the quadrature's Y, so the white has Y = 1 exactly as the camera reads it.
    white_scale: f64,
    /// The white's Planck continuations below and above D65's table: its end value over
    /// Planck's law there, times `white_scale`.
    below: f64,
    above: f64,
}

fn cmf_at(nm: f64) -> DVec3 {
    let x = nm - CMF_START;
    if x < 0.0 || x > (CMF_1931.len() - 1) as f64 {
        return DVec3::ZERO;
    }
    let k = (x as usize).min(CMF_1931.len() - 2);
    let t = x - k as f64;
    DVec3::from(CMF_1931[k]).lerp(DVec3::from(CMF_1931[k + 1]), t)
}

fn response() -> &'static Response {
    static R: OnceLock<Response> = OnceLock::new();
    R.get_or_init(|| {
        let h = ln_step();
        let mut lambda = [0.0; SAMPLES];
        let mut xyz = [DVec3::ZERO; SAMPLES];
        for i in 0..SAMPLES {
            let edge = |k: usize| BAND.0 * (k as f64 * h).exp();
            let (a, b) = (
                edge(i),
                if i + 1 == SAMPLES {
                    BAND.1
                } else {
                    edge(i + 1)
                },
            );
            lambda[i] = BAND.0 * ((i as f64 + 0.5) * h).exp();
            // Trapezoids through the table's points inside the bin and its two ends.
            let mut pts = vec![a];
            pts.extend((a.ceil() as i64..=b.floor() as i64).map(|n| n as f64));
            pts.push(b);
            pts.dedup();
            xyz[i] = pts
                .windows(2)
                .map(|w| 0.5 * (cmf_at(w[0]) + cmf_at(w[1])) * (w[1] - w[0]))
                .sum();
        }
        let rgb = xyz.map(|w| (XYZ_TO_SRGB * w).to_array());
        let (below, above) = (
            D65[0] / planck(D65_START, WHITE_KELVIN),
            D65[D65.len() - 1] / planck(D65_END, WHITE_KELVIN),
        );
        let y: f64 = (0..SAMPLES)
            .map(|i| xyz[i].y * d65_extended(lambda[i], below, above))
            .sum();
        let rgb_rows = [0, 1, 2].map(|c| rgb.map(|w| w[c]));
        Response {
            lambda,
            rgb_rows,
            xyz,
            white_scale: 1.0 / y,
            below: below / y,
            above: above / y,
        }
    })
}

/// The temperature of the Planck curve that continues D65 beyond its table.
const WHITE_KELVIN: f64 = 6504.0;
const D65_END: f64 = D65_START + D65_STEP * (D65.len() - 1) as f64;

/// D65's relative power at `nm`, linear between its 5 nm table entries; beyond the table
/// (300-780 nm) the Planck curve at 6504 K times `below` or `above` (matching the end values),
/// so the white is defined, smooth and physically plausible at every wavelength.
#[inline]
fn d65_extended(nm: f64, below: f64, above: f64) -> f64 {
    if nm <= D65_START {
        return below * planck(nm, WHITE_KELVIN);
    }
    if nm >= D65_END {
        return above * planck(nm, WHITE_KELVIN);
    }
    let x = (nm - D65_START) / D65_STEP;
    let k = (x as usize).min(D65.len() - 2);
    let t = x - k as f64;
    D65[k] + t * (D65[k + 1] - D65[k])
}

/// The white at `nm` (see [`white`]), for loops that hold the response.
#[inline]
fn white_in(r: &Response, nm: f64) -> f64 {
    if nm <= D65_START {
        r.below * planck(nm, WHITE_KELVIN)
    } else if nm >= D65_END {
        r.above * planck(nm, WHITE_KELVIN)
    } else {
        d65_extended(nm, 0.0, 0.0) * r.white_scale
    }
}

/// `scale · σ(c, shift·λ_i) · white(shift·λ_i)` at every camera wavelength: an RGB emitter.
pub(crate) fn illuminant(coeffs: &[f64; 3], scale: f64, shift: f64) -> [f64; SAMPLES] {
    let r = response();
    std::array::from_fn(|i| {
        let nm = shift * r.lambda[i];
        scale * super::sigmoid_poly(coeffs, nm) * white_in(r, nm)
    })
}

/// Half a camera bin's width in ln λ: bin i spans λ_i·e^{∓h}, in any frame (a shift multiplies
/// both ends).
pub(crate) fn bin_half_ln() -> f64 {
    (BAND.1 / BAND.0).ln() / (2 * SAMPLES) as f64
}

/// The camera's wavelengths, nm (bin centres, increasing).
pub fn wavelengths() -> &'static [f64; SAMPLES] {
    &response().lambda
}

/// The white of RGB emitters at `nm`: D65 (extended by Planck's law at 6504 K beyond 300-780 nm),
/// scaled so the camera reads it as Y = 1, which is linear sRGB (1, 1, 1) to the matrix's
/// four digits.
pub fn white(nm: f64) -> f64 {
    white_in(response(), nm)
}

/// CIE XYZ of radiance sampled at the camera's wavelengths.
pub(crate) fn xyz(s: &Sampled) -> DVec3 {
    let r = response();
    (0..SAMPLES).map(|i| r.xyz[i] * s.0[i]).sum()
}

/// Linear sRGB of radiance sampled at the camera's wavelengths.
pub fn rgb(s: &Sampled) -> DVec3 {
    DVec3::from(super::kernels::dot3(&response().rgb_rows, &s.0))
}

/// Linear sRGB of the radiance `f(nm)` at rest.
pub fn rgb_of(f: impl Fn(f64) -> f64) -> DVec3 {
    rgb(&Sampled(wavelengths().map(f)))
}

/// Linear sRGB of the radiance `f(nm)` by the 1 nm sum of the CIE table over 360-830 nm: the
/// reference the camera's quadrature is measured against (docs/physics.md).
pub(crate) fn reference_rgb_of(f: impl Fn(f64) -> f64) -> DVec3 {
    let xyz: DVec3 = CMF_1931
        .iter()
        .enumerate()
        .map(|(k, c)| DVec3::from(*c) * f(CMF_START + k as f64))
        .sum();
    XYZ_TO_SRGB * xyz
}

/// The camera's error on `f`: the largest channel difference from [`reference_rgb_of`], over
/// the reference's largest channel.
pub fn quadrature_error(f: impl Fn(f64) -> f64) -> f64 {
    let (got, want) = (rgb_of(&f), reference_rgb_of(&f));
    (got - want).abs().max_element() / want.abs().max_element()
}

/// Chromaticity (x, y) of XYZ.
pub fn chromaticity(xyz: DVec3) -> (f64, f64) {
    let s = xyz.x + xyz.y + xyz.z;
    (xyz.x / s, xyz.y / s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The white reads as Y = 1 and as sRGB (1, 1, 1) to the matrix's precision.
    #[test]
    fn the_white_is_white() {
        let w = rgb_of(white);
        assert!((w - DVec3::ONE).abs().max_element() < 1e-3, "{w}");
        let y = xyz(&Sampled(wavelengths().map(white))).y;
        assert!((y - 1.0).abs() < 1e-12, "{y}");
    }

    /// The 6504 K continuation meets D65's table at both ends.
    #[test]
    fn d65_is_continuous_at_its_ends() {
        for end in [300.0, 780.0] {
            let (a, b) = (white(end - 1e-9), white(end + 1e-9));
            assert!((a - b).abs() < 1e-6 * a, "{end}: {a} vs {b}");
        }
        assert!(white(5000.0) > 0.0 && white(100.0) > 0.0);
    }

    /// The camera's wavelengths integrate what the physics tests use within 1% of the 1 nm
    /// CIE sum: blackbodies from 1625 K to 26000 K, the white, and Gaussian lines at least
    /// 20 nm wide anywhere in 420-680 nm.
    #[test]
    fn the_quadrature_is_within_one_percent() {
        for k in [
            1625.0, 3250.0, 4875.0, 6500.0, 9750.0, 13000.0, 19500.0, 26000.0,
        ] {
            let e = quadrature_error(|nm| planck(nm, k));
            assert!(e < 0.01, "{k} K: {e}");
        }
        assert!(quadrature_error(white) < 0.01);
        for fwhm in [20.0, 40.0, 60.0] {
            for c in (0..=260).map(|i| 420.0 + i as f64) {
                let line = super::super::Spectrum::Line {
                    centre: c,
                    fwhm,
                    scale: 1.0,
                };
                let e = quadrature_error(|nm| line.at(nm));
                assert!(e < 0.01, "line at {c} nm, FWHM {fwhm}: {e}");
            }
        }
    }

    /// A line far narrower than a bin (issue 34: FWHM 0.001 nm read as 8467 or 0 by where its
    /// centre fell) is read as the light it holds: its colour through the camera's bins is a
    /// 2 nm line's by the 1 nm CIE sum, at 0.37 nm steps over 420-740 nm, within 12% of the
    /// brightest such line's channel; and a 40 nm line bin by bin as its values at the bins'
    /// centres, to 1% of its peak (a bin's width against the line's curvature: 0.6% at most).
    #[test]
    fn narrow_lines_are_read_as_the_light_they_hold() {
        use super::super::{Sampled, Spectrum};
        let line = |c: f64, fwhm: f64| Spectrum::Line {
            centre: c,
            fwhm,
            scale: 1.0,
        };
        let centres: Vec<f64> = (0..865).map(|i| 420.0 + 0.37 * i as f64).collect();
        let want: Vec<DVec3> = centres
            .iter()
            .map(|&c| reference_rgb_of(|nm| line(c, 2.0).at(nm)))
            .collect();
        let peak = want
            .iter()
            .map(|w| w.abs().max_element())
            .fold(0.0, f64::max);
        for fwhm in [0.001, 0.1, 1.0] {
            for (&c, w) in centres.iter().zip(&want) {
                let got = rgb(&Sampled::of(&line(c, fwhm), 1.0));
                let err = (got - *w).abs().max_element();
                assert!(err < 0.12 * peak, "{fwhm} nm at {c} nm: {got} against {w}");
                // Read in a frame of wavelengths 1.5 times the camera's, the line 1.5 times as
                // long and wide: the same bins, each 1.5 times as wide (per nm, 1/1.5 of it).
                let shifted = rgb(&Sampled::of(&line(c * 1.5, fwhm * 1.5), 1.5)) * 1.5;
                assert!(
                    (shifted - got).abs().max_element() < 1e-9 * peak,
                    "{c} shifted"
                );
            }
        }
        for c in [450.0, 550.0, 650.0] {
            let wide = line(c, 40.0);
            let top = wide.at(c);
            for nm in wavelengths() {
                let (m, v) = (wide.bin_mean(*nm), wide.at(*nm));
                assert!((m - v).abs() < 1e-2 * top, "{c}: {m} vs {v}");
            }
        }
    }

    /// The bins' weights hold the CMFs' integrals over the band (checked against the 1 nm
    /// sum over 380-780 nm).
    #[test]
    fn weights_integrate_the_cmfs() {
        let total: DVec3 = response().xyz.iter().sum();
        let start = (BAND.0 - CMF_START) as usize;
        let end = (BAND.1 - CMF_START) as usize;
        let table: DVec3 = (start..=end)
            .map(|k| {
                let w = if k == start || k == end { 0.5 } else { 1.0 };
                DVec3::from(CMF_1931[k]) * w
            })
            .sum();
        assert!((total - table).abs().max_element() < 1e-9 * table.max_element());
    }
}
