//! Radiance (or a reflectance) at the camera's wavelengths, followed back along a path.

use super::{camera, Spectrum};
use std::ops::{Add, AddAssign, Mul};

/// How many wavelengths the camera reads (see [`camera`]).
pub const SAMPLES: usize = 48;

/// Values at the camera's wavelengths: in a frame whose wavelengths are `shift` times the
/// camera's, the i-th value belongs to wavelength `shift · camera::wavelengths()[i]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampled(pub [f64; SAMPLES]);

impl Sampled {
    pub const ZERO: Sampled = Sampled([0.0; SAMPLES]);

    /// `spectrum` read at the camera's wavelengths times `shift`.
    pub fn of(spectrum: &Spectrum, shift: f64) -> Sampled {
        if let Spectrum::Flat(v) = spectrum {
            return Sampled([*v; SAMPLES]);
        }
        let l = camera::wavelengths();
        Sampled(std::array::from_fn(|i| spectrum.at(shift * l[i])))
    }

    pub fn is_finite(&self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }
}

impl Add for Sampled {
    type Output = Sampled;
    fn add(self, o: Sampled) -> Sampled {
        Sampled(std::array::from_fn(|i| self.0[i] + o.0[i]))
    }
}

impl AddAssign for Sampled {
    fn add_assign(&mut self, o: Sampled) {
        for (a, b) in self.0.iter_mut().zip(o.0) {
            *a += b;
        }
    }
}

impl Mul for Sampled {
    type Output = Sampled;
    fn mul(self, o: Sampled) -> Sampled {
        Sampled(std::array::from_fn(|i| self.0[i] * o.0[i]))
    }
}

impl Mul<f64> for Sampled {
    type Output = Sampled;
    fn mul(self, k: f64) -> Sampled {
        Sampled(self.0.map(|v| v * k))
    }
}
