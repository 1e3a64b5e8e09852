//! The star field as one frame's camera sees it: each star's light, put into the pixel its
//! aberrated direction falls in, as that pixel's mean radiance (docs/physics.md §5.5).
//!
//! A star's solid angle is far below a pixel's, so the pixel's mean radiance is the star's
//! irradiance over the pixel's solid angle, and the image holds the star's true light at any
//! size. The camera sees the star's direction aberrated, its wavelengths shifted by D and its
//! irradiance scaled as a point source's (D³ in all, with the Doppler shift and the searchlight
//! on). A pixel sample that meets nothing adds the light of its pixel's stars; samples that
//! meet an object hide them, so a star half behind an edge is half seen.
//!
//! Rays that leave after a bounce have no pixel of their own: they find the stars in the cone
//! of their bundle's solid angle ([`StarCones`]).

use super::band::Seen;
use super::camera::CameraRays;
use crate::scene::Sky;
use crate::spacetime::Boost;
use crate::spectrum::{camera, Sampled, Spectrum};
use glam::DVec3;
use hashbrown::HashMap;
use rayon::prelude::*;

/// The stars' light per pixel (linear sRGB mean radiance), for the pixels that hold any.
#[derive(Default)]
pub struct StarPixels {
    light: HashMap<(u32, u32), DVec3>,
}

impl StarPixels {
    /// The stars of `sky` as `cam` sees them, followed at the camera's wavelengths where
    /// `spectral` (else as their RGB at rest), with changes of frame doing what `seen` says;
    /// None without stars.
    pub fn new(sky: &Sky, cam: &CameraRays, seen: Seen, spectral: bool) -> Option<StarPixels> {
        let field = sky.stars.as_ref()?;
        let from_sky = Boost::from_rest(&sky.velocity);
        let to_sky = Boost::to_rest(&sky.velocity);
        let placed: Vec<((u32, u32), DVec3)> = field
            .stars
            .par_iter()
            .filter_map(|star| {
                let world = from_sky.view_dir(sky.rotation * star.dir).0;
                let (pixel, omega) = cam.pixel_toward(cam.to_camera_dir(world))?;
                // D = ν_camera / ν_sky along the ray: the ratio of the two lookback factors.
                let d = cam.lookback_factor(world) / to_sky.null_dir(world).1;
                let (shift, k) = seen.irradiance(d, 1.0);
                let rgb = star_rgb(star.kelvin, star.irradiance, shift, spectral);
                Some((pixel, rgb * (k / omega)))
            })
            .collect();
        let mut light = HashMap::with_capacity(placed.len());
        for (pixel, rgb) in placed {
            *light.entry(pixel).or_insert(DVec3::ZERO) += rgb;
        }
        Some(StarPixels { light })
    }

    /// The stars' light in pixel (x, y) of the full image (zero where it holds none).
    #[inline]
    pub fn at(&self, x: u32, y: u32) -> DVec3 {
        self.light.get(&(x, y)).copied().unwrap_or(DVec3::ZERO)
    }
}

/// What the camera records (linear sRGB) of a star at `kelvin` whose light at rest has
/// luminance `irradiance` (the Y of linear sRGB), seen from a frame whose wavelengths are
/// `shift` times the star's (`spectral`), or its RGB at rest (not `spectral`).
pub(crate) fn star_rgb(kelvin: f64, irradiance: f64, shift: f64, spectral: bool) -> DVec3 {
    let (spectrum, rest) = star_spectrum(kelvin, irradiance);
    if spectral {
        camera::rgb(&Sampled::of(&spectrum, shift))
    } else {
        rest
    }
}

/// The luminance (CIE Y) of linear sRGB.
pub fn luminance(rgb: DVec3) -> f64 {
    rgb.dot(DVec3::new(0.2126, 0.7152, 0.0722))
}

/// The stars by where they are on the sky (in the sky's frame), for the rays that leave the
/// scene after a reflection or refraction: a ray stands for a bundle of a pixel's solid angle,
/// carried from frame to frame, and sees the stars in the cone of that solid angle about it,
/// each as its irradiance over the cone. Exact for a flat mirror (a star lands in one pixel's
/// cone or, where cones of neighbouring pixels overlap or leave gaps, in as many as its share
/// of the sky makes on average); for a curved one, whose true cones are wider or narrower, right
/// on average (a star is found in proportionally fewer or more pixels).
pub struct StarCones {
    /// The stars' directions (sky frame, turned by the sky's `rotate`), spectra and RGB at
    /// rest ([`star_spectrum`], made once here, not per ray), by cell.
    stars: Vec<(DVec3, Spectrum, DVec3)>,
    /// Where each cell's stars start in `stars` (cells: `bands` in z, `sectors` in longitude).
    starts: Vec<u32>,
    bands: usize,
    sectors: usize,
}

impl StarCones {
    pub fn new(sky: &Sky) -> Option<StarCones> {
        let field = sky.stars.as_ref()?;
        let n = field.stars.len().max(1);
        // About four stars a cell; cells of equal area (uniform in z).
        let bands = ((n as f64 / 4.0 / 2.0).sqrt().ceil() as usize).clamp(1, 2048);
        let sectors = 2 * bands;
        let cell = |d: DVec3| {
            let b = (((d.z + 1.0) * 0.5 * bands as f64) as usize).min(bands - 1);
            let phi = d.y.atan2(d.x) + std::f64::consts::PI;
            let s = ((phi / std::f64::consts::TAU * sectors as f64) as usize).min(sectors - 1);
            b * sectors + s
        };
        let mut placed: Vec<(usize, (DVec3, Spectrum, DVec3))> = field
            .stars
            .par_iter()
            .map(|s| {
                let d = (sky.rotation * s.dir).normalize();
                let (spectrum, rest) = star_spectrum(s.kelvin, s.irradiance);
                (cell(d), (d, spectrum, rest))
            })
            .collect();
        placed.par_sort_by_key(|p| p.0);
        let mut starts = vec![0u32; bands * sectors + 1];
        for (c, _) in &placed {
            starts[c + 1] += 1;
        }
        for i in 0..bands * sectors {
            starts[i + 1] += starts[i];
        }
        Some(StarCones {
            stars: placed.into_iter().map(|p| p.1).collect(),
            starts,
            bands,
            sectors,
        })
    }

    /// Every star within the cone of solid angle `omega` about sky-frame direction `d` (unit):
    /// `visit(spectrum, rgb at rest)`.
    pub fn in_cone(&self, d: DVec3, omega: f64, mut visit: impl FnMut(&Spectrum, DVec3)) {
        if omega.is_nan() || omega <= 0.0 {
            return;
        }
        // The cone's half-angle: Ω = 2π (1 − cos θ).
        let cos_t = (1.0 - omega / std::f64::consts::TAU).clamp(-1.0, 1.0);
        let theta = cos_t.acos();
        let polar = d.z.clamp(-1.0, 1.0).acos();
        let z_lo = (polar + theta).min(std::f64::consts::PI).cos();
        let z_hi = (polar - theta).max(0.0).cos();
        let band = |z: f64| (((z + 1.0) * 0.5 * self.bands as f64) as usize).min(self.bands - 1);
        // The longitudes it spans, unless it holds a pole.
        let sin_p = polar.sin();
        let all =
            polar - theta <= 0.0 || polar + theta >= std::f64::consts::PI || theta.sin() >= sin_p;
        let phi = d.y.atan2(d.x) + std::f64::consts::PI;
        let half = if all {
            std::f64::consts::PI
        } else {
            (theta.sin() / sin_p).asin()
        };
        let per = std::f64::consts::TAU / self.sectors as f64;
        let (s_lo, s_hi) = if all {
            (0, self.sectors as i64 - 1)
        } else {
            (
                ((phi - half) / per).floor() as i64,
                ((phi + half) / per).floor() as i64,
            )
        };
        for b in band(z_lo)..=band(z_hi) {
            for s in s_lo..=s_hi.min(s_lo + self.sectors as i64 - 1) {
                let c = b * self.sectors + s.rem_euclid(self.sectors as i64) as usize;
                let (a, e) = (self.starts[c] as usize, self.starts[c + 1] as usize);
                for (dir, spectrum, rest) in &self.stars[a..e] {
                    if dir.dot(d) >= cos_t {
                        visit(spectrum, *rest);
                    }
                }
            }
        }
    }
}

/// The spectrum of a star at `kelvin` whose light at rest has luminance `irradiance`, and its
/// RGB at rest.
pub(crate) fn star_spectrum(kelvin: f64, irradiance: f64) -> (Spectrum, DVec3) {
    let unit = Spectrum::Blackbody { kelvin, scale: 1.0 };
    let rest = camera::rgb(&Sampled::of(&unit, 1.0));
    let scale = irradiance / luminance(rest);
    (Spectrum::Blackbody { kelvin, scale }, rest * scale)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::stars::StarField;

    /// The cells find exactly the stars a search of every star finds: cones about the poles,
    /// across the seam of longitude (-x), from a thousandth of a pixel's to a hemisphere's.
    #[test]
    fn a_cone_finds_the_stars_a_full_search_finds() {
        let sky = Sky {
            map: None,
            rotation: glam::DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7),
            intensity: 1.0,
            stars: Some(StarField::new(5000, 3, [0.0, 6.0], 1.0, [3000.0, 30000.0])),
            velocity: crate::spacetime::Velocity::ZERO,
        };
        let cones = StarCones::new(&sky).unwrap();
        let all: Vec<(DVec3, f64)> = sky
            .stars
            .as_ref()
            .unwrap()
            .stars
            .iter()
            .map(|s| ((sky.rotation * s.dir).normalize(), s.kelvin))
            .collect();
        let mut rng = crate::rng::Rng(9);
        let mut dirs = vec![DVec3::Z, -DVec3::Z, -DVec3::X, DVec3::new(-1.0, 1e-9, 0.3)];
        dirs.extend((0..200).map(|_| rng.unit()));
        let mut found_any = 0;
        for d in dirs {
            let d = d.normalize();
            for omega in [1e-9, 1e-5, 1e-3, 0.05, 0.5, 3.0, 6.0] {
                let cos_t = 1.0 - omega / std::f64::consts::TAU;
                let mut want: Vec<u64> = all
                    .iter()
                    .filter(|(s, _)| s.dot(d) >= cos_t)
                    .map(|(_, k)| k.to_bits())
                    .collect();
                let mut got = Vec::new();
                cones.in_cone(d, omega, |spectrum, _| {
                    if let Spectrum::Blackbody { kelvin, .. } = spectrum {
                        got.push(kelvin.to_bits());
                    }
                });
                want.sort_unstable();
                got.sort_unstable();
                assert_eq!(got, want, "about {d} with {omega} sr");
                found_any += got.len();
            }
        }
        assert!(found_any > 10_000, "{found_any}");
    }
}
