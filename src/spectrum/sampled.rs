//! Radiance (or a reflectance) at the camera's wavelengths, followed back along a path.

use super::{camera, Spectrum};
use std::ops::Mul;

/// How many wavelengths the camera reads (see [`camera`]).
pub(crate) const SAMPLES: usize = 64;

/// Values at the camera's wavelengths: in a frame whose wavelengths are `shift` times the
/// camera's, the i-th value belongs to wavelength `shift · camera::wavelengths()[i]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampled(pub [f64; SAMPLES]);

impl Sampled {
    pub const ZERO: Sampled = Sampled([0.0; SAMPLES]);

    /// `spectrum` read at the camera's wavelengths times `shift`.
    pub fn of(spectrum: &Spectrum, shift: f64) -> Sampled {
        let l = camera::wavelengths();
        // One loop per kind, so each is a tight loop the compiler can vectorise.
        match spectrum {
            Spectrum::Flat(v) => Sampled([*v; SAMPLES]),
            Spectrum::Sigmoid { coeffs, scale } => Sampled(std::array::from_fn(|i| {
                scale * super::sigmoid_poly(coeffs, shift * l[i])
            })),
            Spectrum::Illuminant { coeffs, scale } => {
                Sampled(camera::illuminant(coeffs, *scale, shift))
            }
            Spectrum::Blackbody { kelvin, scale } => Sampled(std::array::from_fn(|i| {
                scale * super::planck(shift * l[i], *kelvin)
            })),
            // Lines as their mean over each bin (`Spectrum::bin_mean`), tables as sampled.
            _ => Sampled(std::array::from_fn(|i| spectrum.bin_mean(shift * l[i]))),
        }
    }
}

// Scaling is the loop of `kernels`, vectorised (the rest is in `render::band`, by reference).
impl Mul<f64> for Sampled {
    type Output = Sampled;
    fn mul(mut self, k: f64) -> Sampled {
        super::kernels::scale(&mut self.0, k);
        self
    }
}
