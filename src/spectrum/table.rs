//! A smooth spectrum tabulated on a logarithmic wavelength grid aligned with the camera's
//! wavelengths, so that reading it at the camera's wavelengths times any shift is two
//! contiguous rows and one interpolation: the camera's wavelengths are equally spaced in ln λ
//! ([`camera::ln_step`]), a shift moves them all by ln(shift), and the grid has [`PHASES`]
//! steps per camera bin, stored phase by phase, so the values one shift needs lie side by side.
//!
//! The grid spans the wavelengths that reach the camera's band from D = 1/64 to 64 (beyond, the
//! spectrum is evaluated exactly), in steps of 1/16 of a bin in ln λ (0.07%). Linear
//! interpolation there is within 1e-4 of the spectrum's peak for the smooth kinds it is made
//! for (RGB uplifts and blackbodies; D65's 5 nm table is itself linear, so the white is within
//! 1e-3 at its kinks).

use super::{camera, Sampled, Shift, Spectrum, SAMPLES};
use std::sync::OnceLock;

/// Grid steps per camera bin.
const PHASES: usize = 16;
/// The largest shift either way the table covers.
const REACH: f64 = 64.0;

#[derive(Debug)]
pub struct LogTable {
    /// Row p holds the grid values p, p + PHASES, p + 2·PHASES, …
    rows: Vec<f64>,
    row_len: usize,
}

/// The grid: its step in ln λ, how many steps lie below the camera's first wavelength, and
/// its length.
struct Grid {
    step: f64,
    below: usize,
    len: usize,
}

fn grid() -> &'static Grid {
    static G: OnceLock<Grid> = OnceLock::new();
    G.get_or_init(|| {
        let step = camera::ln_step() / PHASES as f64;
        let reach = (REACH.ln() / step).ceil() as usize;
        let span = (SAMPLES - 1) * PHASES;
        Grid {
            step,
            below: reach,
            len: 2 * reach + span + 2,
        }
    })
}

impl LogTable {
    pub fn new(spectrum: &Spectrum) -> LogTable {
        let g = grid();
        let l0 = camera::wavelengths()[0];
        let row_len = g.len.div_ceil(PHASES) + 1;
        let mut rows = vec![0.0; PHASES * row_len];
        for j in 0..row_len * PHASES {
            let nm = l0 * ((j as f64 - g.below as f64) * g.step).exp();
            rows[(j % PHASES) * row_len + j / PHASES] = spectrum.at(nm);
        }
        LogTable { rows, row_len }
    }

    /// The spectrum at the camera's wavelengths times `shift` (`exact` off the grid).
    pub fn sample(&self, shift: Shift, exact: &Spectrum) -> Sampled {
        let g = grid();
        let offset = shift.ln / g.step + g.below as f64;
        let q = offset.floor();
        // Grid position of wavelength i: q + i·PHASES + t.
        if q >= 0.0 && q + ((SAMPLES - 1) * PHASES + 1) as f64 <= (self.row_len * PHASES - 1) as f64
        {
            let (k, t) = (q as usize, offset - q);
            let (p, b) = (k % PHASES, k / PHASES);
            let lo = &self.rows[p * self.row_len + b..][..SAMPLES];
            let (p1, b1) = if p + 1 < PHASES {
                (p + 1, b)
            } else {
                (0, b + 1)
            };
            let hi = &self.rows[p1 * self.row_len + b1..][..SAMPLES];
            let mut out = Sampled::ZERO;
            super::kernels::lerp(lo, hi, t, &mut out.0);
            return out;
        }
        Sampled::of(exact, shift.factor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::{Colour, Role, Shift};
    use glam::DVec3;

    /// Within 1e-4 of the spectrum's peak (1e-3 for the white, whose D65 table has kinks) at
    /// every shift, on the grid and off it. (Relative to a value far down Wien's tail, where a
    /// blackbody is e^-25 of its peak and less, the interpolation is off by more.)
    #[test]
    fn the_table_reads_the_spectrum() {
        let cases = [
            (
                Spectrum::Blackbody {
                    kelvin: 5800.0,
                    scale: 1.0,
                },
                1e-4,
            ),
            (
                Spectrum::Blackbody {
                    kelvin: 2000.0,
                    scale: 1.0,
                },
                1e-4,
            ),
            (
                Colour::rgb(DVec3::new(0.9, 0.3, 0.1), Role::Reflectance).spectrum,
                1e-4,
            ),
            (
                Colour::rgb(DVec3::new(0.2, 0.9, 0.5), Role::Emitter).spectrum,
                1e-3,
            ),
        ];
        for (s, tol) in cases {
            let table = LogTable::new(&s);
            for shift in [
                0.01, 0.0626, 0.07, 0.5, 0.98, 1.0, 1.7, 9.0, 15.9, 16.1, 40.0,
            ] {
                let got = table.sample(Shift::new(shift), &s);
                let want = Sampled::of(&s, shift);
                let peak = want
                    .0
                    .iter()
                    .chain(&Sampled::of(&s, 1.0).0)
                    .cloned()
                    .fold(0.0, f64::max);
                for i in 0..SAMPLES {
                    assert!(
                        (got.0[i] - want.0[i]).abs() <= tol * peak.max(1e-300),
                        "{s:?} shift {shift} at {i}: {} vs {}",
                        got.0[i],
                        want.0[i]
                    );
                }
            }
        }
    }
}
