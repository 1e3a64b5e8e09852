//! Light as spectra: what the scene's colours mean at any wavelength, and what the camera makes
//! of them.
//!
//! A colour in the scene is a [`Spectrum`] (a function of wavelength in nm, defined at every
//! wavelength, since a Doppler shift can bring light from far outside the visible band into
//! view) together with the RGB it has at rest ([`Colour`]). The renderer follows a fixed set of
//! camera-frame wavelengths ([`camera::wavelengths`]) back along each path: in a frame whose
//! wavelengths are `shift` times the camera's, a spectrum is read at `shift · λ_i`
//! (`Sampled::of`). The camera turns the radiance at its wavelengths into CIE XYZ and linear
//! sRGB ([`camera`]). See docs/physics.md, "Light and colour".

pub mod camera;
mod cie_data;
pub(crate) mod kernels;
mod sampled;
mod table;
mod uplift;

pub(crate) use sampled::{Sampled, SAMPLES};

use glam::DVec3;
use std::sync::{Arc, OnceLock};

/// Planck's first radiation constant for spectral radiance, 2hc² (W·m²·sr⁻¹; CODATA 2018, exact).
const C1L: f64 = 1.191_042_972_397_188_4e-16;
/// Planck's second radiation constant hc/k (m·K; CODATA 2018, exact).
const C2: f64 = 1.438_776_877_503_933_8e-2;

/// A frame's wavelengths over the camera's, with its logarithm (what a log-wavelength table
/// needs), computed once for all the colours read in that frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Shift {
    pub factor: f64,
    pub ln: f64,
}

impl Shift {
    pub fn new(factor: f64) -> Shift {
        Shift {
            factor,
            ln: factor.ln(),
        }
    }
}

/// A spectrum: a non-negative function of wavelength (nm), defined at every wavelength.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub enum Spectrum {
    /// The same value at every wavelength (an RGB grey reflectance, or zero).
    Flat(f64),
    /// `scale · σ(c₀x² + c₁x + c₂)`, x = (λ − 380)/400 held in [0, 1] (constant outside the
    /// visible band): a smooth reflectance uplifted from RGB (Jakob & Hanika 2019).
    Sigmoid {
        /// c₀, c₁, c₂.
        coeffs: [f64; 3],
        /// The scale (1 for RGB in [0, 1]).
        scale: f64,
    },
    /// `scale · σ(…) · W(λ)`: an RGB emitter, the sigmoid times the camera's white
    /// ([`camera::white`]), so that RGB (1, 1, 1) is exactly the white.
    Illuminant {
        /// c₀, c₁, c₂.
        coeffs: [f64; 3],
        /// The scale.
        scale: f64,
    },
    /// Planck's law at `kelvin`, in W·sr⁻¹·m⁻²·nm⁻¹, times `scale`.
    Blackbody {
        /// The temperature, K.
        kelvin: f64,
        /// The scale.
        scale: f64,
    },
    /// A Gaussian line at `centre` nm with full width at half maximum `fwhm` nm whose integral
    /// over wavelength is `scale`.
    Line {
        /// The centre wavelength, nm.
        centre: f64,
        /// The full width at half maximum, nm.
        fwhm: f64,
        /// The integral over wavelength.
        scale: f64,
    },
    /// Linear interpolation in a table (wavelengths strictly increasing), held at the end
    /// values beyond the first and last wavelength.
    Tabulated {
        /// The wavelengths, nm, strictly increasing.
        wavelengths: Arc<[f64]>,
        /// The values at those wavelengths.
        values: Arc<[f64]>,
    },
}

/// Jakob & Hanika's sigmoid, 1/2 + x / (2√(1 + x²)): smooth, in (0, 1), no exponential.
pub(crate) fn sigmoid(x: f64) -> f64 {
    if x.is_infinite() {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + 0.5 * x / (1.0 + x * x).sqrt()
}

/// The sigmoid polynomial at wavelength `nm`.
pub(crate) fn sigmoid_poly(c: &[f64; 3], nm: f64) -> f64 {
    let x = ((nm - 380.0) / 400.0).clamp(0.0, 1.0);
    sigmoid((c[0] * x + c[1]) * x + c[2])
}

/// Planck's spectral radiance B_λ(λ, T) in W·sr⁻¹·m⁻²·nm⁻¹ at `nm` nanometres.
pub fn planck(nm: f64, kelvin: f64) -> f64 {
    let m = nm * 1e-9;
    let x = C2 / (m * kelvin);
    // Per metre of wavelength, then per nanometre. exp_m1 keeps the Rayleigh-Jeans tail exact.
    let per_m = C1L / (m.powi(5) * x.exp_m1());
    if per_m.is_finite() {
        per_m * 1e-9
    } else {
        0.0
    }
}

impl Spectrum {
    /// The spectrum's mean over the camera bin centred at `nm` (edges nm·e^{∓h},
    /// [`camera::bin_half_ln`]): the value at `nm` for every kind but a line, which is
    /// integrated over the bin (erf) and divided by its width, so that a line far narrower than
    /// a bin is read as the light it holds wherever its centre falls, not as its peak or as
    /// nothing. For lines as wide as a bin or wider it is the value at `nm` to within the
    /// quadrature's own error.
    pub fn bin_mean(&self, nm: f64) -> f64 {
        match self {
            Spectrum::Line {
                centre,
                fwhm,
                scale,
            } => {
                let h = camera::bin_half_ln();
                let (a, b) = (nm * (-h).exp(), nm * h.exp());
                let sigma = fwhm / (2.0 * (2.0 * std::f64::consts::LN_2).sqrt());
                let below =
                    |x: f64| 0.5 * libm::erfc(-(x - centre) / (sigma * std::f64::consts::SQRT_2));
                scale * (below(b) - below(a)) / (b - a)
            }
            _ => self.at(nm),
        }
    }

    /// The value at wavelength `nm` (nanometres, > 0).
    pub fn at(&self, nm: f64) -> f64 {
        match self {
            Spectrum::Flat(v) => *v,
            Spectrum::Sigmoid { coeffs, scale } => scale * sigmoid_poly(coeffs, nm),
            Spectrum::Illuminant { coeffs, scale } => {
                scale * sigmoid_poly(coeffs, nm) * camera::white(nm)
            }
            Spectrum::Blackbody { kelvin, scale } => scale * planck(nm, *kelvin),
            Spectrum::Line {
                centre,
                fwhm,
                scale,
            } => {
                let sigma = fwhm / (2.0 * (2.0 * std::f64::consts::LN_2).sqrt());
                let z = (nm - centre) / sigma;
                scale / (sigma * (2.0 * std::f64::consts::PI).sqrt()) * (-0.5 * z * z).exp()
            }
            Spectrum::Tabulated {
                wavelengths,
                values,
            } => {
                let k = wavelengths.partition_point(|&w| w <= nm);
                if k == 0 {
                    return values[0];
                }
                if k == wavelengths.len() {
                    return values[k - 1];
                }
                let (l0, l1) = (wavelengths[k - 1], wavelengths[k]);
                let t = (nm - l0) / (l1 - l0);
                values[k - 1] + t * (values[k] - values[k - 1])
            }
        }
    }
}

/// How a colour is used: reflectances are bounded by 1 where they come from RGB in [0, 1],
/// and an RGB emitter is a multiple of the camera's white.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// A reflectance (diffuse or specular colour): RGB in [0, 1] gives a spectrum in [0, 1].
    Reflectance,
    /// An emitter (emission, light, background, ambient): RGB gives a multiple of the white.
    Emitter,
}

/// A colour of the scene: its spectrum, and the linear sRGB it has at rest (what the RGB
/// renderer uses, and exactly the RGB given where the colour was given as RGB).
#[derive(Clone, serde::Serialize)]
pub struct Colour {
    /// Linear sRGB at rest.
    pub rgb: DVec3,
    /// The spectrum.
    pub spectrum: Spectrum,
    /// Whether it was given as RGB (a scene of RGB colours only, all at rest relative to each
    /// other, needs no spectral rendering).
    pub from_rgb: bool,
    /// The spectrum on a logarithmic grid, for the smooth kinds (see [`table`]): made the
    /// first time the colour is read at a frame's wavelengths (some thirteen thousand
    /// evaluations of the spectrum), so that a scene rendered in RGB, or a colour never seen
    /// shifted, costs none; shared by the colour's clones. Made from the spectrum, so the
    /// render id, which hashes the spectrum, leaves it out.
    #[serde(skip)]
    table: Option<Arc<OnceLock<table::LogTable>>>,
    /// Black at every wavelength (asked per hit, so kept).
    black: bool,
}

/// Without its table, which is made from the spectrum (printing a colour makes none).
impl std::fmt::Debug for Colour {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Colour")
            .field("rgb", &self.rgb)
            .field("spectrum", &self.spectrum)
            .field("from_rgb", &self.from_rgb)
            .field("black", &self.black)
            .finish()
    }
}

impl PartialEq for Colour {
    fn eq(&self, o: &Colour) -> bool {
        self.rgb == o.rgb && self.spectrum == o.spectrum && self.from_rgb == o.from_rgb
    }
}

impl Colour {
    fn new(rgb: DVec3, spectrum: Spectrum, from_rgb: bool) -> Colour {
        let smooth = matches!(
            spectrum,
            Spectrum::Sigmoid { .. } | Spectrum::Illuminant { .. } | Spectrum::Blackbody { .. }
        );
        let table = smooth.then(|| Arc::new(OnceLock::new()));
        let black = spectrum == Spectrum::Flat(0.0) || rgb == DVec3::ZERO && from_rgb;
        Colour {
            rgb,
            spectrum,
            from_rgb,
            table,
            black,
        }
    }

    /// Its table, made on first use.
    fn table_in<'t>(&self, t: &'t OnceLock<table::LogTable>) -> &'t table::LogTable {
        t.get_or_init(|| table::LogTable::new(&self.spectrum))
    }

    /// The colour at the camera's wavelengths times `shift`.
    pub(crate) fn sampled(&self, shift: Shift) -> Sampled {
        match &self.table {
            Some(t) => self.table_in(t).sample(shift, &self.spectrum),
            None => Sampled::of(&self.spectrum, shift.factor),
        }
    }

    /// An RGB colour (linear sRGB, every channel ≥ 0), uplifted to a smooth spectrum.
    pub fn rgb(rgb: DVec3, role: Role) -> Colour {
        let spectrum = match role {
            Role::Reflectance => uplift::reflectance(rgb),
            Role::Emitter => uplift::emitter(rgb),
        };
        Colour::new(rgb, spectrum, true)
    }

    /// A grey: the flat spectrum of `v` as a reflectance, `v` times the white as an emitter.
    pub fn grey(v: f64, role: Role) -> Colour {
        Colour::rgb(DVec3::splat(v), role)
    }

    /// A colour given as a spectrum; its RGB is what the camera sees of it at rest (as an
    /// emitter), or under the white (as a reflectance).
    pub fn spectral(spectrum: Spectrum, role: Role) -> Colour {
        let rgb = match role {
            Role::Emitter => camera::rgb_of(|nm| spectrum.bin_mean(nm)),
            Role::Reflectance => camera::rgb_of(|nm| spectrum.at(nm) * camera::white(nm)),
        };
        Colour::new(rgb, spectrum, false)
    }

    /// This colour times `k` (a light's intensity).
    pub fn scaled(&self, k: f64) -> Colour {
        let spectrum = match &self.spectrum {
            Spectrum::Flat(v) => Spectrum::Flat(v * k),
            Spectrum::Sigmoid { coeffs, scale } => Spectrum::Sigmoid {
                coeffs: *coeffs,
                scale: scale * k,
            },
            Spectrum::Illuminant { coeffs, scale } => Spectrum::Illuminant {
                coeffs: *coeffs,
                scale: scale * k,
            },
            Spectrum::Blackbody { kelvin, scale } => Spectrum::Blackbody {
                kelvin: *kelvin,
                scale: scale * k,
            },
            Spectrum::Line {
                centre,
                fwhm,
                scale,
            } => Spectrum::Line {
                centre: *centre,
                fwhm: *fwhm,
                scale: scale * k,
            },
            Spectrum::Tabulated {
                wavelengths,
                values,
            } => Spectrum::Tabulated {
                wavelengths: wavelengths.clone(),
                values: values.iter().map(|v| v * k).collect(),
            },
        };
        Colour::new(self.rgb * k, spectrum, self.from_rgb)
    }

    /// Whether it is black at every wavelength.
    pub fn is_black(&self) -> bool {
        self.black
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// §6 of docs/physics.md: D⁵ B_λ(Dλ, T) = B_λ(λ, DT) at every wavelength.
    #[test]
    fn a_shifted_blackbody_is_a_blackbody_at_d_t() {
        for d in [0.1f64, 0.25, 0.5, 2.0, 4.0, 10.0, 1e3] {
            for nm in [100.0, 380.0, 550.0, 780.0, 5000.0] {
                let (a, b) = (d.powi(5) * planck(d * nm, 5800.0), planck(nm, 5800.0 * d));
                assert!(
                    (a - b).abs() <= 1e-12 * b.max(1e-300),
                    "D {d} at {nm}: {a} vs {b}"
                );
            }
        }
    }

    /// Planck's law at 6500 K, 500 nm, by hand: 2hc²/λ⁵ / (e^{hc/λkT} − 1).
    #[test]
    fn planck_by_hand() {
        let (h, c, k): (f64, f64, f64) = (6.626_070_15e-34, 299_792_458.0, 1.380_649e-23);
        let l: f64 = 500e-9;
        let want = 2.0 * h * c * c / l.powi(5) / ((h * c / (l * k * 6500.0)).exp() - 1.0) * 1e-9;
        let got = planck(500.0, 6500.0);
        assert!((got / want - 1.0).abs() < 1e-12, "{got} vs {want}");
        assert_eq!(planck(1e-3, 300.0), 0.0);
        assert!(planck(1e9, 300.0) > 0.0);
    }

    /// A line's integral is its scale, and its FWHM is its width.
    #[test]
    fn line_integral_and_width() {
        let s = Spectrum::Line {
            centre: 500.0,
            fwhm: 20.0,
            scale: 3.0,
        };
        let sum: f64 = (0..20000)
            .map(|i| s.at(300.0 + 0.02 * i as f64) * 0.02)
            .sum();
        assert!((sum - 3.0).abs() < 1e-9, "{sum}");
        let half = s.at(510.0) / s.at(500.0);
        assert!((half - 0.5).abs() < 1e-12, "{half}");
    }

    #[test]
    fn tabulated_interpolates_and_holds_its_ends() {
        let s = Spectrum::Tabulated {
            wavelengths: vec![400.0, 500.0, 700.0].into(),
            values: vec![0.2, 0.4, 1.0].into(),
        };
        assert_eq!(s.at(300.0), 0.2);
        assert_eq!(s.at(400.0), 0.2);
        assert!((s.at(450.0) - 0.3).abs() < 1e-15);
        assert!((s.at(600.0) - 0.7).abs() < 1e-15);
        assert_eq!(s.at(700.0), 1.0);
        assert_eq!(s.at(1e6), 1.0);
    }
}
