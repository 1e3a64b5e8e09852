//! RGB to a smooth spectrum (Jakob & Hanika, "A Low-Dimensional Function Space for Efficient
//! Spectral Upsampling", Computer Graphics Forum 38(2), 2019): a reflectance is the sigmoid of
//! a quadratic in wavelength, bounded in (0, 1) everywhere, fitted so that under the camera's
//! white it has the RGB given. Where they tabulate the fit over the RGB cube, a scene has a
//! handful of colours, so each is fitted when the scene loads (Gauss-Newton on the CIELAB
//! difference, walked out from grey, as in their paper), against the camera's own quadrature:
//! at rest the renderer gives back the RGB to the fit's tolerance.

use super::camera::{self, XYZ_TO_SRGB};
use super::{sigmoid_poly, Spectrum, SAMPLES};
use glam::DVec3;

/// A reflectance with linear sRGB `rgb` under the white: exactly flat for a grey.
pub fn reflectance(rgb: DVec3) -> Spectrum {
    if rgb.x == rgb.y && rgb.y == rgb.z {
        return Spectrum::Flat(rgb.x);
    }
    // Above 1 no bounded reflectance has the colour: fit its shape and scale it.
    let scale = rgb.max_element().max(1.0);
    Spectrum::Sigmoid {
        coeffs: fit(rgb / scale),
        scale,
    }
}

/// An emitter with linear sRGB `rgb`: `2m · σ(…) · white` with m the largest channel, so its
/// sigmoid stays in the fit's easy middle, and a grey k is exactly k times the white.
pub fn emitter(rgb: DVec3) -> Spectrum {
    let m = rgb.max_element();
    if m == 0.0 {
        return Spectrum::Flat(0.0);
    }
    let coeffs = if rgb.x == rgb.y && rgb.y == rgb.z {
        [0.0; 3]
    } else {
        fit(rgb / (2.0 * m))
    };
    Spectrum::Illuminant {
        coeffs,
        scale: 2.0 * m,
    }
}

/// CIELAB's f.
fn lab_f(t: f64) -> f64 {
    const D: f64 = 6.0 / 29.0;
    if t > D * D * D {
        t.cbrt()
    } else {
        t / (3.0 * D * D) + 4.0 / 29.0
    }
}

fn lab(xyz: DVec3, white: DVec3) -> DVec3 {
    let f = (xyz / white).to_array().map(lab_f);
    DVec3::new(
        116.0 * f[1] - 16.0,
        500.0 * (f[0] - f[1]),
        200.0 * (f[1] - f[2]),
    )
}

struct Model {
    white: [f64; SAMPLES],
    lambda: [f64; SAMPLES],
    white_xyz: DVec3,
}

impl Model {
    fn new() -> Model {
        let lambda = *camera::wavelengths();
        let white = lambda.map(camera::white);
        let white_xyz = camera::xyz(&super::Sampled(white));
        Model {
            white,
            lambda,
            white_xyz,
        }
    }

    /// XYZ of the sigmoid reflectance `c` under the white.
    fn xyz(&self, c: &[f64; 3]) -> DVec3 {
        let s = super::Sampled(std::array::from_fn(|i| {
            self.white[i] * sigmoid_poly(c, self.lambda[i])
        }));
        camera::xyz(&s)
    }

    fn residual(&self, c: &[f64; 3], target_lab: DVec3) -> DVec3 {
        lab(self.xyz(c), self.white_xyz) - target_lab
    }
}

/// Sigmoid-polynomial coefficients whose reflectance has linear sRGB `rgb` (in [0, 1]) under
/// the white.
/// Each fit is kept (by the colour's bits) for the process's later loads: a fit is thousands of
/// evaluations of the model, and a scene read again (the viewer after each edit, a farm's
/// tiles, a film's frames) has the same colours. The fit is a function of the colour alone, so
/// a kept one is the one a new fit would give.
fn fit(rgb: DVec3) -> [f64; 3] {
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};
    /// Colours kept at most (then forgotten, all at once).
    const KEPT: usize = 4096;
    static FITS: OnceLock<Mutex<HashMap<[u64; 3], [f64; 3]>>> = OnceLock::new();
    let fits = FITS.get_or_init(Default::default);
    let key = rgb.to_array().map(f64::to_bits);
    if let Some(c) = fits.lock().ok().and_then(|f| f.get(&key).copied()) {
        return c;
    }
    let c = fit_anew(rgb);
    if let Ok(mut f) = fits.lock() {
        if f.len() >= KEPT {
            f.clear();
        }
        f.insert(key, c);
    }
    c
}

/// The fit itself, made anew (what `fit` keeps).
fn fit_anew(rgb: DVec3) -> [f64; 3] {
    let model = Model::new();
    let to_xyz = XYZ_TO_SRGB.inverse();
    let grey = DVec3::splat(0.5);
    let mut c = [0.0; 3];
    const STEPS: u32 = 16;
    for k in 1..=STEPS {
        let t = grey.lerp(rgb, f64::from(k) / f64::from(STEPS));
        let target = lab(to_xyz * t, model.white_xyz);
        let iterations = if k == STEPS { 60 } else { 12 };
        c = gauss_newton(&model, c, target, iterations);
    }
    c
}

fn gauss_newton(model: &Model, mut c: [f64; 3], target: DVec3, iterations: u32) -> [f64; 3] {
    let mut r = model.residual(&c, target);
    for _ in 0..iterations {
        if r.length() < 1e-6 {
            break;
        }
        let mut cols = [DVec3::ZERO; 3];
        for (j, col) in cols.iter_mut().enumerate() {
            let h = 1e-6 * (1.0 + c[j].abs());
            let mut cj = c;
            cj[j] += h;
            *col = (model.residual(&cj, target) - r) / h;
        }
        let jac = glam::DMat3::from_cols(cols[0], cols[1], cols[2]);
        if jac.determinant().abs() < 1e-300 {
            break;
        }
        let step = jac.inverse() * -r;
        // Halve the step until it helps (the sigmoid's tails make full steps overshoot).
        let mut scale = 1.0;
        let mut improved = false;
        for _ in 0..30 {
            let trial = [
                c[0] + scale * step.x,
                c[1] + scale * step.y,
                c[2] + scale * step.z,
            ];
            let rt = model.residual(&trial, target);
            if rt.length() < r.length() {
                c = trial;
                r = rt;
                improved = true;
                break;
            }
            scale *= 0.5;
        }
        if !improved {
            break;
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::{camera, Colour, Role};

    /// At rest, under the white, every uplifted reflectance gives back its RGB within 1% of
    /// its largest channel (the cube's corners and edges included), and stays within [0, 1]
    /// at every wavelength, inside the band and far outside it.
    #[test]
    fn reflectances_give_back_their_rgb() {
        let levels = [0.0, 0.02, 0.2, 0.5, 0.8, 1.0];
        for &r in &levels {
            for &g in &levels {
                for &b in &levels {
                    let rgb = DVec3::new(r, g, b);
                    let c = Colour::rgb(rgb, Role::Reflectance);
                    let back = camera::rgb_of(|nm| c.spectrum.at(nm) * camera::white(nm));
                    let err = (back - rgb).abs().max_element();
                    assert!(
                        err <= 0.01 * rgb.max_element().max(0.02),
                        "{rgb} gives back {back}"
                    );
                    for nm in [1.0, 200.0, 380.0, 500.0, 780.0, 5000.0, 1e7] {
                        let v = c.spectrum.at(nm);
                        assert!((0.0..=1.0).contains(&v), "{rgb} at {nm}: {v}");
                    }
                }
            }
        }
    }

    /// A kept fit is the fit itself, bit for bit, and a colour fitted before is found again.
    #[test]
    fn a_kept_fit_is_a_new_fit() {
        for rgb in [DVec3::new(0.7, 0.2, 0.1), DVec3::new(0.05, 0.6, 0.3)] {
            let first = fit(rgb);
            assert_eq!(first, fit_anew(rgb));
            assert_eq!(fit(rgb), first);
        }
    }

    /// An RGB grey is exactly the flat spectrum of that value; an emitter grey is exactly that
    /// many times the white.
    #[test]
    fn greys_are_exact() {
        for v in [0.0, 0.18, 0.5, 1.0, 3.0] {
            assert_eq!(reflectance(DVec3::splat(v)), Spectrum::Flat(v));
            let e = Colour::grey(v, Role::Emitter).spectrum;
            for nm in [300.0, 555.0, 900.0] {
                assert_eq!(e.at(nm), v * camera::white(nm), "{v} at {nm}");
            }
        }
    }

    /// Emitters of any brightness give back their RGB at rest.
    #[test]
    fn emitters_give_back_their_rgb() {
        for rgb in [
            DVec3::new(1.0, 0.5, 0.2),
            DVec3::new(20.0, 0.0, 3.0),
            DVec3::new(0.01, 0.02, 0.03),
            DVec3::new(0.0, 1.0, 0.0),
        ] {
            let c = Colour::rgb(rgb, Role::Emitter);
            let back = camera::rgb_of(|nm| c.spectrum.at(nm));
            let err = (back - rgb).abs().max_element();
            assert!(err <= 0.01 * rgb.max_element(), "{rgb} gives back {back}");
        }
    }
}
