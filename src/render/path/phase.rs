//! How a medium scatters light: the Henyey-Greenstein phase function (1941), in the medium's
//! rest frame. `wo` points toward where the light goes on to (the viewer), `wi` toward where
//! it came from; the scattering angle θ is between the light's way in (−wi) and out (wo), and
//! g = ⟨cos θ⟩ (forward scattering for g > 0).

use glam::DVec3;
use std::f64::consts::PI;

#[derive(Clone, Copy, Debug)]
pub struct Hg {
    g: f64,
}

impl Hg {
    pub fn new(g: f64) -> Hg {
        Hg { g }
    }

    /// p(θ) = (1 − g²) / (4π (1 + g² − 2g cos θ)^(3/2)), per steradian.
    fn p(&self, cos: f64) -> f64 {
        let g = self.g;
        let denom = 1.0 + g * g - 2.0 * g * cos;
        (1.0 - g * g) / (4.0 * PI * denom * denom.sqrt())
    }

    /// The phase function for light from `wi` scattered toward `wo` (also the density of
    /// [`Hg::sample`]).
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> f64 {
        self.p((-wi).dot(wo))
    }

    /// A direction for the light to come from, drawn with density `eval`, and the density.
    pub fn sample(&self, wo: DVec3, u1: f64, u2: f64) -> (DVec3, f64) {
        let g = self.g;
        let cos = if g.abs() < 1e-3 {
            1.0 - 2.0 * u1
        } else {
            let k = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1);
            ((1.0 + g * g - k * k) / (2.0 * g)).clamp(-1.0, 1.0)
        };
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let (sp, cp) = super::draws::sincos_turn(u2);
        let way_in = super::bsdf::Basis::new(wo).to_world(DVec3::new(sin * cp, sin * sp, cos));
        let wi = -way_in;
        (wi, self.eval(wo, wi))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// The phase function integrates to 1, its mean cosine is g, and draws have its density
    /// (their mean cosine is g too).
    #[test]
    fn normalised_with_mean_cosine_g() {
        for g in [-0.7, -0.2, 0.0, 0.3, 0.85] {
            let hg = Hg::new(g);
            let wo = DVec3::new(0.3, -0.5, 0.8).normalize();
            let n = 2000;
            let (mut total, mut mean) = (0.0, 0.0);
            for i in 0..n {
                let theta = (i as f64 + 0.5) * PI / n as f64;
                for j in 0..n {
                    let phi = (j as f64 + 0.5) * 2.0 * PI / n as f64;
                    let d = super::super::bsdf::Basis::new(wo).to_world(DVec3::new(
                        theta.sin() * phi.cos(),
                        theta.sin() * phi.sin(),
                        theta.cos(),
                    ));
                    let w = hg.eval(wo, -d) * theta.sin() * (PI / n as f64) * (2.0 * PI / n as f64);
                    total += w;
                    mean += w * theta.cos();
                }
            }
            assert!((total - 1.0).abs() < 1e-3, "g = {g}: ∫ p = {total}");
            assert!((mean - g).abs() < 2e-3, "g = {g}: <cos> = {mean}");
            let mut rng = Rng(5);
            let draws = 200_000;
            let mut drawn = 0.0;
            for _ in 0..draws {
                let (wi, pdf) = hg.sample(wo, rng.f(), rng.f());
                assert!((pdf - hg.eval(wo, wi)).abs() < 1e-12 * pdf.max(1.0));
                drawn += (-wi).dot(wo);
            }
            let drawn = drawn / draws as f64;
            assert!((drawn - g).abs() < 0.01, "g = {g}: drawn <cos> = {drawn}");
        }
    }
}
