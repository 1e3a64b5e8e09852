//! What a ray carries back to the camera, and what a change of frame does to it.
//!
//! The shader is written once for any [`Band`]: RGB (`DVec3`), where no change of frame alters
//! the light and every factor is exactly 1 (so the RGB render is today's to the bit), or
//! radiance at the camera's wavelengths ([`Sampled`]), where each change of frame along a path
//! shifts the wavelengths and scales the radiance (docs/physics.md, "Light and colour").

use crate::scene::Scene;
use crate::spectrum::{camera, kernels, Colour, Sampled, Shift};
use glam::DVec3;
use std::ops::Mul;

/// Light along a ray: in a frame whose wavelengths are `shift` times the camera's. Large bands
/// are combined in place and by reference (a spectrum is 64 numbers).
pub(crate) trait Band: Copy + Mul<f64, Output = Self> {
    /// A frame's shift as this band reads colours with it (prepared once per frame).
    type At: Copy;
    /// The frame whose wavelengths are `shift` times the camera's.
    fn at(shift: f64) -> Self::At;
    /// The colour `c` in that frame.
    fn of(c: &Colour, at: Self::At) -> Self;
    /// What the camera records of it (linear sRGB).
    fn to_rgb(&self) -> DVec3;
    /// `self *= o`, wavelength by wavelength.
    fn mul_by(&mut self, o: &Self);
    /// `self += o`.
    fn add(&mut self, o: &Self);
    /// `self +=` the light a point light sends off a surface: `light · atten · (diffuse · ndl +
    /// specular · highlight) · k`, where `glint` is the specular reflectance and highlight.
    fn add_lit(
        &mut self,
        light: &Self,
        atten: f64,
        diffuse: &Self,
        ndl: f64,
        glint: Option<(&Self, f64)>,
        k: f64,
    );
}

impl Band for DVec3 {
    type At = ();
    fn at(_shift: f64) {}
    fn of(c: &Colour, _: ()) -> Self {
        c.rgb
    }
    fn to_rgb(&self) -> DVec3 {
        *self
    }
    fn mul_by(&mut self, o: &Self) {
        *self *= *o;
    }
    fn add(&mut self, o: &Self) {
        *self += *o;
    }
    /// In the order of operations the RGB render has always used.
    fn add_lit(
        &mut self,
        light: &Self,
        atten: f64,
        diffuse: &Self,
        ndl: f64,
        glint: Option<(&Self, f64)>,
        k: f64,
    ) {
        let mut term = *diffuse * ndl;
        if let Some((spec, h)) = glint {
            term += *spec * h;
        }
        *self += *light * atten * term * k;
    }
}

impl Band for Sampled {
    type At = Shift;
    fn at(shift: f64) -> Shift {
        Shift::new(shift)
    }
    fn of(c: &Colour, at: Shift) -> Self {
        c.sampled(at)
    }
    fn to_rgb(&self) -> DVec3 {
        camera::rgb(self)
    }
    fn mul_by(&mut self, o: &Self) {
        kernels::mul(&mut self.0, &o.0);
    }
    fn add(&mut self, o: &Self) {
        kernels::add(&mut self.0, &o.0);
    }
    /// One pass over the wavelengths.
    fn add_lit(
        &mut self,
        light: &Self,
        atten: f64,
        diffuse: &Self,
        ndl: f64,
        glint: Option<(&Self, f64)>,
        k: f64,
    ) {
        let glint = glint.map(|(s, h)| (&s.0, h));
        kernels::add_lit(&mut self.0, &light.0, &diffuse.0, ndl, glint, atten * k);
    }
}

/// What a change of frame does to light: with `doppler`, the sender's wavelengths are D times
/// the receiver's (D = ν_receiver / ν_sender) and radiance per unit wavelength gains the
/// Jacobian D; with `searchlight`, radiance gains D⁴ and a point light's irradiance D². Both
/// together are the exact transformation (D⁵ and D³); neither is the RGB render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Seen {
    pub doppler: bool,
    pub searchlight: bool,
}

impl Seen {
    pub const NONE: Seen = Seen {
        doppler: false,
        searchlight: false,
    };

    /// The scene's switches.
    pub fn of(scene: &Scene) -> Seen {
        Seen {
            doppler: scene.render.doppler,
            searchlight: scene.render.searchlight,
        }
    }

    /// Whether a change of frame alters anything (else D need not be computed).
    pub fn any(&self) -> bool {
        self.doppler || self.searchlight
    }

    fn shifted(&self, d: f64, shift: f64, searchlight_power: i32) -> (f64, f64) {
        if !self.any() {
            return (shift, 1.0);
        }
        let (mut sender_shift, mut k) = (shift, 1.0);
        if self.doppler {
            sender_shift = d * shift;
            k = d;
        }
        if self.searchlight {
            let d2 = d * d;
            k *= if searchlight_power == 4 { d2 * d2 } else { d2 };
        }
        (sender_shift, k)
    }

    /// Radiance seen across a change of frame with frequency ratio `d` = ν_receiver/ν_sender,
    /// by a receiver whose wavelengths are `shift` times the camera's: the sender's shift, and
    /// the factor on the sender's radiance (`(shift, 1)` exactly for [`Seen::NONE`]).
    pub fn radiance(&self, d: f64, shift: f64) -> (f64, f64) {
        self.shifted(d, shift, 4)
    }

    /// As [`Seen::radiance`], for the irradiance a point light sends (D³ in all).
    pub fn irradiance(&self, d: f64, shift: f64) -> (f64, f64) {
        self.shifted(d, shift, 2)
    }
}

/// Whether the scene needs its light followed at every wavelength: a switch is on, and some
/// colour is a spectrum or something moves relative to something else (camera, lights, groups,
/// and the world frame where the background is not black). Otherwise the RGB render is exact.
pub fn needs_spectra(scene: &Scene) -> bool {
    if !scene.render.shifts_light() {
        return false;
    }
    let mut colours = vec![&scene.image.background, &scene.render.ambient];
    for m in &scene.materials {
        colours.extend([&m.color, &m.specular]);
        colours.extend(m.emission.as_ref());
    }
    colours.extend(scene.lights.iter().map(|l| &l.radiance));
    if colours.iter().any(|c| !c.from_rgb) {
        return true;
    }
    let mut frames = vec![scene.camera.velocity.identity_key()];
    frames.extend(scene.lights.iter().map(|l| l.velocity.identity_key()));
    frames.extend(
        scene
            .groups
            .iter()
            .filter(|g| !g.geometry.is_empty())
            .map(|g| g.velocity.identity_key()),
    );
    if !scene.image.background.is_black() {
        frames.push(crate::spacetime::Velocity::ZERO.identity_key());
    }
    frames.iter().any(|f| *f != frames[0])
}
