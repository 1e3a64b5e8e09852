//! How a surface scatters light in the path integrator, in the surface's rest frame: a
//! mixture of Lambert (`color`), a normalised Phong lobe (`specular`, `shininess`), a conductor
//! (`reflect`) and a Fresnel dielectric (`transmit`, `ior`), the last two smooth or rough (GGX
//! microfacets, `roughness`; Walter et al. 2007, sampled by visible normals after Heitz 2018).
//! Directions are local: z is the normal on the side the light leaves toward (the viewer's),
//! and both `wo` (toward the viewer) and `wi` (toward where the light comes from) point away
//! from the surface (docs/physics.md §10).

pub use super::draws::Basis;
use super::draws::{cosine_dir, cosine_pdf, sincos_turn};
use crate::render::band::Band;
use crate::render::optics::{fresnel, phong, reflect, refract};
use glam::DVec3;
use std::f64::consts::PI;

/// The GGX (Trowbridge-Reitz) distribution of normals with roughness α.
#[derive(Clone, Copy, Debug)]
pub struct Ggx {
    alpha: f64,
}

impl Ggx {
    /// D(h): the density of microfacet normals h (local, h.z > 0) per solid angle, projected.
    pub fn d(&self, h: DVec3) -> f64 {
        let a2 = self.alpha * self.alpha;
        let k = h.z * h.z * (a2 - 1.0) + 1.0;
        a2 / (PI * k * k)
    }

    /// Smith's Λ(w).
    fn lambda(&self, w: DVec3) -> f64 {
        let c2 = w.z * w.z;
        if c2 >= 1.0 {
            return 0.0;
        }
        let tan2 = (1.0 - c2) / c2;
        0.5 * ((1.0 + self.alpha * self.alpha * tan2).sqrt() - 1.0)
    }

    /// The masking of one direction, G1.
    pub fn g1(&self, w: DVec3) -> f64 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Masking and shadowing together, height-correlated (G2).
    pub fn g2(&self, wo: DVec3, wi: DVec3) -> f64 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// The density of the visible normal h seen from `wo` (wo.z > 0): G1(wo) max(0, wo·h) D(h)
    /// / wo.z.
    pub fn visible_pdf(&self, wo: DVec3, h: DVec3) -> f64 {
        self.g1(wo) * wo.dot(h).max(0.0) * self.d(h) / wo.z
    }

    /// A normal drawn from the visible normals seen from `wo` (Heitz 2018).
    pub fn sample_visible(&self, wo: DVec3, u1: f64, u2: f64) -> DVec3 {
        let a = self.alpha;
        let vh = DVec3::new(a * wo.x, a * wo.y, wo.z).normalize();
        let len2 = vh.x * vh.x + vh.y * vh.y;
        let t1 = if len2 > 0.0 {
            DVec3::new(-vh.y, vh.x, 0.0) / len2.sqrt()
        } else {
            DVec3::X
        };
        let t2 = vh.cross(t1);
        let r = u1.sqrt();
        let (sin, cos) = sincos_turn(u2);
        let (p1, mut p2) = (r * cos, r * sin);
        let s = 0.5 * (1.0 + vh.z);
        p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
        let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
        DVec3::new(a * nh.x, a * nh.y, nh.z.max(0.0)).normalize()
    }
}

/// The surface's lobes, and the probability of drawing each.
pub struct Lobes<B> {
    diffuse: B,
    phong: Option<(B, f64)>,
    conductor: f64,
    dielectric: f64,
    /// The index beyond the surface over the index on the viewer's side.
    eta: f64,
    /// None: smooth (a mirror, clear glass).
    ggx: Option<Ggx>,
    /// The probabilities of drawing the diffuse, Phong, conductor and dielectric lobes.
    pick: [f64; 4],
}

/// A direction drawn from the lobes.
pub struct Sample<B> {
    /// Local, toward where the light comes from.
    pub wi: DVec3,
    /// f |cos θ_i| / pdf: what the light arriving along `wi` is multiplied by.
    pub weight: B,
    /// The density it was drawn with, per solid angle (0 for a smooth lobe).
    pub pdf: f64,
    /// Whether it came from a smooth (delta) lobe.
    pub delta: bool,
}

/// Below this roughness a lobe is smooth (its α = roughness² would be under 1e-6).
const SMOOTH: f64 = 1e-3;

impl<B: Band> Lobes<B> {
    /// A surface of diffuse reflectance `diffuse`, Phong lobe `phong` (reflectance and
    /// exponent), shares `conductor` and `dielectric` of mirror and glass of `roughness`, the
    /// far side's index over the viewer's `eta`.
    pub fn new(
        diffuse: B,
        phong: Option<(B, f64)>,
        conductor: f64,
        dielectric: f64,
        roughness: f64,
        eta: f64,
    ) -> Lobes<B> {
        let w = [
            diffuse.max_value().max(0.0),
            phong.as_ref().map_or(0.0, |(k, _)| k.max_value().max(0.0)),
            conductor,
            dielectric,
        ];
        let total: f64 = w.iter().sum();
        let pick = if total > 0.0 {
            w.map(|x| x / total)
        } else {
            [0.0; 4]
        };
        Lobes {
            diffuse,
            phong,
            conductor,
            dielectric,
            eta,
            ggx: (roughness >= SMOOTH).then_some(Ggx {
                alpha: roughness * roughness,
            }),
            pick,
        }
    }

    /// A Lambert surface of reflectance `diffuse` and nothing else.
    pub fn lambert(diffuse: B) -> Lobes<B> {
        Lobes::new(diffuse, None, 0.0, 0.0, 0.0, 1.0)
    }

    /// Whether it is a Lambert surface and nothing else.
    pub fn lambert_only(&self) -> bool {
        self.pick == [1.0, 0.0, 0.0, 0.0] && self.phong.is_none()
    }

    /// Its diffuse reflectance.
    pub fn diffuse(&self) -> B {
        self.diffuse
    }

    /// A Lambert lobe's f = ρ / π times `x`, as [`Lobes::eval`] and [`Lobes::sample`] make it
    /// (for the lanes, which find the factor `x`).
    pub fn lambert_f(diffuse: &B, x: f64) -> B {
        let mut f = B::splat(0.0);
        f.add(&(*diffuse * (1.0 / PI)));
        f * x
    }

    /// Whether it scatters no light.
    pub fn is_black(&self) -> bool {
        self.pick == [0.0; 4]
    }

    /// Whether some lobe is not a delta (so light from a given direction can be reflected:
    /// next-event estimation is worth doing).
    pub fn has_glossy(&self) -> bool {
        self.pick[0] > 0.0
            || self.pick[1] > 0.0
            || (self.ggx.is_some() && self.pick[2..] != [0.0; 2])
    }

    /// The BSDF f(wo, wi) of the lobes that are not deltas, and the density with which
    /// [`Lobes::sample`] draws `wi`.
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> (B, f64) {
        let mut f = B::splat(0.0);
        let mut pdf = 0.0;
        if wo.z <= 0.0 {
            return (f, 0.0);
        }
        if wi.z > 0.0 {
            if self.pick[0] > 0.0 {
                f.add(&(self.diffuse * (1.0 / PI)));
                pdf += self.pick[0] * cosine_pdf(wi.z);
            }
            if let Some((ks, n)) = &self.phong {
                let r = DVec3::new(-wo.x, -wo.y, wo.z);
                let c = r.dot(wi).max(0.0);
                let l = phong(c, *n);
                f.add(&(*ks * ((n + 2.0) / (2.0 * PI) * l)));
                pdf += self.pick[1] * (n + 1.0) / (2.0 * PI) * l;
            }
        }
        let Some(ggx) = self.ggx else {
            return (f, pdf);
        };
        if wi.z > 0.0 && (self.conductor > 0.0 || self.dielectric > 0.0) {
            let h = (wo + wi).normalize();
            let common = ggx.d(h) * ggx.g2(wo, wi) / (4.0 * wo.z * wi.z);
            let per_h = ggx.visible_pdf(wo, h) / (4.0 * wo.dot(h));
            if self.conductor > 0.0 {
                f.add(&B::splat(self.conductor * common));
                pdf += self.pick[2] * per_h;
            }
            if self.dielectric > 0.0 {
                let fr = fresnel(wo.dot(h), self.eta);
                f.add(&B::splat(self.dielectric * fr * common));
                pdf += self.pick[3] * fr * per_h;
            }
        } else if wi.z < 0.0 && self.dielectric > 0.0 {
            let mut h = (wo + self.eta * wi).normalize();
            if h.z < 0.0 {
                h = -h;
            }
            let (oh, ih) = (wo.dot(h), wi.dot(h));
            if oh > 0.0 && ih < 0.0 && h.is_finite() {
                let fr = fresnel(oh, self.eta);
                let denom = (oh + self.eta * ih).powi(2);
                let jacobian = self.eta * self.eta * ih.abs() / denom;
                let ft = (1.0 - fr) * ggx.d(h) * ggx.g2(wo, wi) * oh * jacobian / (wo.z * -wi.z);
                f.add(&B::splat(self.dielectric * ft));
                pdf += self.pick[3] * (1.0 - fr) * ggx.visible_pdf(wo, h) * jacobian;
            }
        }
        (f, pdf)
    }

    /// A direction drawn for the light to come from, given four uniform numbers in [0, 1);
    /// None where the draw leaves no light (below the surface, or a black surface).
    pub fn sample(&self, wo: DVec3, u: [f64; 4]) -> Option<Sample<B>> {
        if wo.z <= 0.0 || self.is_black() {
            return None;
        }
        let mut lobe = 0;
        let mut acc = self.pick[0];
        while lobe < 3 && u[0] >= acc {
            lobe += 1;
            acc += self.pick[lobe];
        }
        let (u1, u2, u3) = (u[1], u[2], u[3]);
        let wi = match lobe {
            // Cosine-weighted on the hemisphere.
            0 => cosine_dir(u1, u2),
            1 => {
                let (_, n) = self.phong.as_ref().expect("drawn only with a Phong lobe");
                let r = DVec3::new(-wo.x, -wo.y, wo.z);
                let cos = u1.powf(1.0 / (n + 1.0));
                let sin = (1.0 - cos * cos).max(0.0).sqrt();
                let (sp, cp) = sincos_turn(u2);
                Basis::new(r).to_world(DVec3::new(sin * cp, sin * sp, cos))
            }
            2 => match self.ggx {
                None => {
                    let w = self.conductor / self.pick[2];
                    return Some(self.delta(DVec3::new(-wo.x, -wo.y, wo.z), w));
                }
                Some(g) => Some(reflect(wo, g.sample_visible(wo, u1, u2))).filter(|w| w.z > 0.0)?,
            },
            _ => {
                let h = match self.ggx {
                    None => DVec3::Z,
                    Some(g) => g.sample_visible(wo, u1, u2),
                };
                let fr = fresnel(wo.dot(h), self.eta);
                // A microfacet may send light to the wrong side of the surface: no light.
                let wi = if u3 < fr {
                    Some(reflect(wo, h)).filter(|w| w.z > 0.0)?
                } else {
                    refract(wo, h, self.eta).filter(|w| w.z < 0.0)?
                };
                if self.ggx.is_none() {
                    return Some(self.delta(wi, self.dielectric / self.pick[3]));
                }
                wi
            }
        };
        if wi.z == 0.0 || !wi.is_finite() {
            return None;
        }
        let (f, pdf) = self.eval(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        Some(Sample {
            wi,
            weight: f * (wi.z.abs() / pdf),
            pdf,
            delta: false,
        })
    }

    fn delta(&self, wi: DVec3, weight: f64) -> Sample<B> {
        Sample {
            wi,
            weight: B::splat(weight),
            pdf: 0.0,
            delta: true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// Surfaces with a lobe of every kind, alone and mixed (RGB, so f is three numbers).
    fn surfaces() -> Vec<(&'static str, Lobes<DVec3>)> {
        let grey = |v: f64| DVec3::splat(v);
        vec![
            ("lambert", Lobes::new(grey(0.7), None, 0.0, 0.0, 0.0, 1.5)),
            (
                "phong",
                Lobes::new(grey(0.0), Some((grey(0.5), 20.0)), 0.0, 0.0, 0.0, 1.5),
            ),
            (
                "rough metal",
                Lobes::new(grey(0.0), None, 0.9, 0.0, 0.4, 1.5),
            ),
            (
                "rough glass in",
                Lobes::new(grey(0.0), None, 0.0, 1.0, 0.4, 1.5),
            ),
            (
                "rough glass out",
                Lobes::new(grey(0.0), None, 0.0, 1.0, 0.4, 1.0 / 1.5),
            ),
            (
                "mixed",
                Lobes::new(grey(0.2), Some((grey(0.1), 8.0)), 0.3, 0.4, 0.5, 1.33),
            ),
        ]
    }

    fn directions() -> [DVec3; 3] {
        [
            DVec3::Z,
            DVec3::new(0.5, 0.2, 0.8).normalize(),
            DVec3::new(0.9, -0.1, 0.2).normalize(),
        ]
    }

    /// ∫ g(ω) dω over the sphere, by the midpoint rule on an n × n grid even in θ and φ
    /// (deterministic, and fine near the poles, where lobes at normal incidence peak).
    fn over_sphere(n: usize, mut g: impl FnMut(DVec3) -> f64) -> f64 {
        let (dt, dp) = (PI / n as f64, 2.0 * PI / n as f64);
        let mut sum = 0.0;
        for i in 0..n {
            let theta = (i as f64 + 0.5) * dt;
            let (st, ct) = theta.sin_cos();
            for j in 0..n {
                let phi = (j as f64 + 0.5) * dp;
                sum += g(DVec3::new(st * phi.cos(), st * phi.sin(), ct)) * st;
            }
        }
        sum * dt * dp
    }

    /// The density `eval` gives is the density `sample` draws with: its integral over the
    /// sphere is the share of draws that give a direction, and the mean weight of the draws is
    /// ∫ f |cos θ| dω. A wrong Jacobian, a missing G1 or a density for the wrong lobe fails by
    /// far more than the 1.5% allowed.
    #[test]
    fn sample_and_eval_agree() {
        let n = 400_000;
        for (name, lobes) in surfaces() {
            for wo in directions() {
                let mut rng = Rng(17);
                let pdf_integral = over_sphere(1000, |wi| lobes.eval(wo, wi).1);
                let albedo = over_sphere(1000, |wi| lobes.eval(wo, wi).0.x * wi.z.abs());
                let (mut drawn, mut weight) = (0, 0.0);
                for _ in 0..n {
                    let u = [rng.f(), rng.f(), rng.f(), rng.f()];
                    if let Some(s) = lobes.sample(wo, u) {
                        assert!(!s.delta, "{name}: rough lobes only");
                        let (f, pdf) = lobes.eval(wo, s.wi);
                        assert!(
                            (pdf - s.pdf).abs() <= 1e-12 * pdf,
                            "{name}: the draw's density"
                        );
                        assert!((f.x * s.wi.z.abs() / pdf - s.weight.x).abs() <= 1e-9);
                        drawn += 1;
                        weight += s.weight.x;
                    }
                }
                let share = drawn as f64 / n as f64;
                let mean = weight / n as f64;
                let what = format!("{name}, wo = {wo:?}");
                assert!(
                    (pdf_integral - share).abs() <= 0.015 * share.max(0.05),
                    "{what}: ∫ pdf = {pdf_integral}, share of draws {share}"
                );
                assert!(
                    (albedo - mean).abs() <= 0.015 * albedo.max(0.05),
                    "{what}: ∫ f cos = {albedo}, mean weight {mean}"
                );
                assert!(albedo <= 1.0 + 0.02, "{what}: no energy made ({albedo})");
            }
        }
    }

    /// Smooth lobes are deltas: a mirror sends back `reflect` along the mirror direction, and
    /// clear glass splits by Fresnel (reflected share R at normal incidence, ((n−1)/(n+1))²),
    /// each draw's weight the lobe's share over its chance of being drawn.
    #[test]
    fn smooth_lobes_are_deltas() {
        let mirror = Lobes::new(DVec3::ZERO, None, 0.8, 0.0, 0.0, 1.5);
        let wo = DVec3::new(0.3, 0.4, 0.866).normalize();
        let s = mirror.sample(wo, [0.5, 0.1, 0.2, 0.3]).unwrap();
        assert!(s.delta);
        assert!((s.wi - DVec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-15);
        assert!((s.weight.x - 0.8).abs() < 1e-15);
        assert_eq!(mirror.eval(wo, s.wi).0, DVec3::ZERO);
        let glass = Lobes::new(DVec3::ZERO, None, 0.0, 1.0, 0.0, 1.5);
        let mut rng = Rng(3);
        let (mut reflected, n) = (0, 200_000);
        for _ in 0..n {
            let s = glass
                .sample(DVec3::Z, [rng.f(), rng.f(), rng.f(), rng.f()])
                .unwrap();
            assert!(s.delta && (s.weight.x - 1.0).abs() < 1e-15);
            if s.wi.z > 0.0 {
                reflected += 1;
            } else {
                assert!((s.wi + DVec3::Z).length() < 1e-12, "straight through");
            }
        }
        let r = reflected as f64 / n as f64;
        assert!((r - 0.04).abs() < 0.002, "reflected share {r}");
    }
}
