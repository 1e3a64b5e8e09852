//! The star field as one frame's camera sees it: each star's light, put into the pixel its
//! aberrated direction falls in, as that pixel's mean radiance (docs/physics.md §5.5).
//!
//! A star's solid angle is far below a pixel's, so the pixel's mean radiance is the star's
//! irradiance over the pixel's solid angle, and the image holds the star's true light at any
//! size. The camera sees the star's direction aberrated, its wavelengths shifted by D and its
//! irradiance scaled as a point source's (D³ in all, with the Doppler shift and the searchlight
//! on). A pixel sample that meets nothing adds the light of its pixel's stars; samples that
//! meet an object hide them, so a star half behind an edge is half seen.

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
/// `shift` times the star's (`spectral`), or its RGB at rest (not `spectral`). Its spectrum is
/// Planck's law read at the shifted wavelengths, scaled to that luminance.
pub fn star_rgb(kelvin: f64, irradiance: f64, shift: f64, spectral: bool) -> DVec3 {
    let unit = Spectrum::Blackbody { kelvin, scale: 1.0 };
    let rest = camera::rgb(&Sampled::of(&unit, 1.0));
    let scale = irradiance / luminance(rest);
    if spectral {
        camera::rgb(&Sampled::of(&unit, shift)) * scale
    } else {
        rest * scale
    }
}

/// The luminance (CIE Y) of linear sRGB.
pub fn luminance(rgb: DVec3) -> f64 {
    rgb.dot(DVec3::new(0.2126, 0.7152, 0.0722))
}
