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
    /// Whether the band holds spectra (else RGB, where colours are their RGB exactly).
    const SPECTRAL: bool;
    /// The frame whose wavelengths are `shift` times the camera's.
    fn at(shift: f64) -> Self::At;
    /// The colour `c` in that frame.
    fn of(c: &Colour, at: Self::At) -> Self;
    /// A spectrum read in a frame whose wavelengths are `shift` times the camera's (in RGB:
    /// `rest_rgb`, its RGB at rest).
    fn of_spectrum(s: &crate::spectrum::Spectrum, rest_rgb: DVec3, shift: f64) -> Self;
    /// The same value at every wavelength (or in every channel).
    fn splat(v: f64) -> Self;
    /// Its largest value over the wavelengths (or channels).
    fn max_value(&self) -> f64;
    /// Its mean over the wavelengths (or channels).
    fn mean_value(&self) -> f64;
    /// e^(−v d) of each value v: the transmittance of a path of length d through a medium of
    /// these attenuation coefficients.
    fn exp_neg(&self, d: f64) -> Self;
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
    const SPECTRAL: bool = false;
    type At = ();
    fn at(_shift: f64) {}
    fn of(c: &Colour, _: ()) -> Self {
        c.rgb
    }
    fn of_spectrum(_: &crate::spectrum::Spectrum, rest_rgb: DVec3, _: f64) -> Self {
        rest_rgb
    }
    fn splat(v: f64) -> Self {
        DVec3::splat(v)
    }
    fn max_value(&self) -> f64 {
        self.max_element()
    }
    fn mean_value(&self) -> f64 {
        self.element_sum() / 3.0
    }
    fn exp_neg(&self, d: f64) -> Self {
        DVec3::new(exp_neg(self.x, d), exp_neg(self.y, d), exp_neg(self.z, d))
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
    const SPECTRAL: bool = true;
    type At = Shift;
    fn at(shift: f64) -> Shift {
        Shift::new(shift)
    }
    fn of(c: &Colour, at: Shift) -> Self {
        c.sampled(at)
    }
    fn of_spectrum(s: &crate::spectrum::Spectrum, _: DVec3, shift: f64) -> Self {
        Sampled::of(s, shift)
    }
    fn splat(v: f64) -> Self {
        Sampled([v; crate::spectrum::SAMPLES])
    }
    fn max_value(&self) -> f64 {
        self.0.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }
    fn mean_value(&self) -> f64 {
        self.0.iter().sum::<f64>() / self.0.len() as f64
    }
    fn exp_neg(&self, d: f64) -> Self {
        Sampled(self.0.map(|v| exp_neg(v, d)))
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

/// e^(−v d), with a medium that does not attenuate (v = 0) letting all through however far
/// (0 · ∞ would be NaN).
fn exp_neg(v: f64, d: f64) -> f64 {
    if v == 0.0 {
        1.0
    } else {
        (-v * d).exp()
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
    colours.extend(
        scene
            .sky
            .iter()
            .flat_map(|s| s.map.iter().flat_map(|m| m.basis.iter())),
    );
    // Stars are blackbodies.
    if scene.sky.as_ref().is_some_and(|s| s.stars.is_some()) {
        return true;
    }
    for m in &scene.materials {
        colours.extend(m.colours());
    }
    colours.extend(scene.lights.iter().map(|l| &l.radiance));
    if colours.iter().any(|c| !c.from_rgb) {
        return true;
    }
    // Points that move within their group's frame (accelerated segments, spin) are shaded in
    // frames of their own.
    if scene
        .groups
        .iter()
        .any(|g| g.accelerated.is_some() || g.geometry.spins())
        || scene.lights.iter().any(|l| l.worldline.is_some())
        || (scene.camera.shutter > 0.0
            && scene
                .camera
                .worldline
                .as_ref()
                .is_some_and(|w| !w.is_uniform()))
    {
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
    if let Some(sky) = &scene.sky {
        frames.push(sky.velocity.identity_key());
    }
    frames.iter().any(|f| *f != frames[0])
}

/// The Doppler factor from which on most of the camera's 380-780 nm left a source beyond one
/// end of the band: 580 D > 780 (beyond the red end), or 580 D < 380 (beyond the violet end).
const MOSTLY_OUTSIDE: (f64, f64) = (380.0 / 580.0, 780.0 / 580.0);

/// A warning where a scene's colours given as RGB (not grey) may be seen so far shifted that
/// most of what the camera sees of them comes from outside 380-780 nm, where an RGB colour says
/// nothing and its uplifted spectrum is held at its end values (docs/physics.md §6.1): the
/// largest Doppler factor between the camera and a group or the background, from their
/// relative rapidity, against [`MOSTLY_OUTSIDE`]. A bound: a group seen only sideways may
/// never show it.
pub(crate) fn extrapolation_warning(scene: &Scene) -> Option<String> {
    use crate::spacetime::Velocity;
    if !scene.render.doppler || !scene.render.rgb_shift_warning {
        return None;
    }
    let coloured = |c: &crate::spectrum::Colour| {
        c.from_rgb && !c.is_black() && !(c.rgb.x == c.rgb.y && c.rgb.y == c.rgb.z)
    };
    let materials = scene.materials.iter().any(|m| m.colours().any(coloured));
    let cam = &scene.camera.velocity;
    // The rapidity between two velocities: cosh φ = γ_u γ_v (1 − u·v).
    let between = |v: &Velocity| {
        let c = cam.gamma() * v.gamma() * (1.0 - cam.beta_vec().dot(v.beta_vec()));
        c.max(1.0).acosh()
    };
    let mut worst: Option<(f64, String)> = None;
    let mut consider = |phi: f64, what: String| {
        if worst.as_ref().is_none_or(|(w, _)| phi > *w) {
            worst = Some((phi, what));
        }
    };
    if coloured(&scene.image.background) {
        consider(between(&Velocity::ZERO), "the background".to_string());
    }
    if materials {
        for g in scene.groups.iter().filter(|g| !g.geometry.is_empty()) {
            consider(between(&g.velocity), format!("group `{}`", g.name));
        }
    }
    let (phi, what) = worst?;
    let d = phi.exp();
    (d > MOSTLY_OUTSIDE.1).then(|| {
        format!(
            "warning: {what} moves at {:.2}c relative to the camera: its colours given as RGB may be seen shifted by up to D = {d:.2}, from light outside 380-780 nm, where RGB says nothing (docs/physics.md 6.1).\n  Give them as spectra to say what they are there; `[render] rgb_shift_warning = false` (or --quiet) silences this.",
            phi.tanh(),
        )
    })
}
