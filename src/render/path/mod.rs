//! The path integrator (`[render] integrator = "path"`): unbiased Monte Carlo light transport
//! across moving frames. Every vertex of a path is shaded in its surface's rest frame; every
//! leg between vertices is a null ray found on the past light cone of the vertex it arrives
//! at (inside glass, light at c/n in the glass's frame: `Shader::inside_hit`), and carries the
//! shift and D⁵ of its change of frame, as Whitted's rays do. At each vertex: next-event
//! estimation to every point light and to one glowing primitive (its area drawn in its own
//! rest frame), weighed against the BSDF's draws by multiple importance sampling (the power
//! heuristic, with densities carried into the receiver's frame as solid angles: Ω scales as
//! D⁻²); then a direction drawn from the BSDF, and Russian roulette (docs/physics.md §10).

mod bsdf;
mod emitters;

pub(crate) use emitters::Emitters;

use super::band::Band;
use super::sampler::splitmix;
use super::shade::{surface_colour, Lit, Shader};
use super::world::SurfaceHit;
use crate::rng::Rng;
use crate::spacetime::{Event, NullRay};
use bsdf::{Basis, Lobes};
use glam::DVec3;
use std::f64::consts::PI;

/// The bounce from which Russian roulette may end a path.
const ROULETTE_FROM: u32 = 3;

/// The most a path's survival probability may be under roulette (so every path ends).
const ROULETTE_MAX: f64 = 0.95;

/// A sample's own generator (the crate's splitmix64), seeded from a hash of the scene's
/// seed, the pixel and the sample's index, so the image is the same on any number of threads.
pub(crate) fn sample_rng(seed: u64, x: u32, y: u32, sample: u32) -> Rng {
    let pixel = (u64::from(x) << 32) | u64::from(y);
    let h = splitmix(pixel ^ splitmix(seed));
    Rng(splitmix(h ^ u64::from(sample)))
}

/// The path integrator over one shader (scene, world, lights, the band light is carried in).
pub(crate) struct PathTracer<'s, 'a, B> {
    shader: &'s Shader<'a, B>,
    emitters: &'s Emitters,
    max_depth: u32,
}

/// What a path remembers of the vertex a BSDF draw left, to weigh an emitter the draw meets
/// against next-event estimation from that vertex.
struct Came {
    /// The BSDF's density for the direction, per solid angle in that vertex's frame.
    pdf: f64,
    /// Where the ray started (world frame).
    from: Event,
    /// The frequency ratio ν_vertex / ν_world along the ray (its lookback factor there).
    s: f64,
}

impl<'s, 'a, B: Band> PathTracer<'s, 'a, B> {
    pub fn new(shader: &'s Shader<'a, B>, emitters: &'s Emitters) -> Self {
        Self {
            shader,
            emitters,
            max_depth: shader.scene.render.max_depth,
        }
    }

    /// The light leaving `hit` (met by `ray`) back along the ray, in the hit's frame at
    /// wavelengths `shift` times the camera's: one path's estimate.
    pub fn radiance(&self, ray: &NullRay, hit: &SurfaceHit, shift: f64, rng: &mut Rng) -> B {
        let sh = self.shader;
        let world = sh.world;
        let mut out = B::splat(0.0);
        let mut beta = B::splat(1.0);
        let (mut hit, mut event, mut shift) = (*hit, ray.at(hit.lambda), shift);
        let mut came: Option<Came> = None;
        for depth in 0.. {
            let lit = sh.lit_at(&hit, event, shift);
            let (mat, at) = (lit.mat, B::at(shift));
            if let Some(e) = &mat.emission {
                let weight = came.as_ref().map_or(1.0, |c| self.mis_met(c, &hit));
                let mut le = surface_colour::<B>(e, mat.emission_texture.as_deref(), &lit, at);
                le.mul_by(&beta);
                out.add(&(le * weight));
                break;
            }
            // Past the last bounce a vertex only says what light it sends (above).
            if depth > self.max_depth {
                break;
            }
            let diffuse = surface_colour::<B>(&mat.color, mat.color_texture.as_deref(), &lit, at);
            let phong =
                (!mat.specular.is_black()).then(|| (B::of(&mat.specular, at), mat.shininess));
            let eta = if lit.inside { 1.0 / mat.ior } else { mat.ior };
            let lobes = Lobes::new(
                diffuse,
                phong,
                mat.reflect,
                mat.transmit,
                mat.roughness,
                eta,
            );
            if lobes.is_black() {
                break;
            }
            let basis = Basis::new(lit.nf);
            let wo = basis.to_local(-lit.v);
            if lobes.has_glossy() {
                self.point_lights(&lit, &lobes, &basis, wo, &beta, &mut out);
                self.emitter_light(&lit, &lobes, &basis, wo, &beta, rng, &mut out);
            }
            let u = [rng.f(), rng.f(), rng.f(), rng.f()];
            let Some(bs) = lobes.sample(wo, u) else {
                break;
            };
            beta.mul_by(&bs.weight);
            if depth + 1 >= ROULETTE_FROM && depth < self.max_depth {
                let q = beta.max_value().min(ROULETTE_MAX);
                // A NaN q ends the path too.
                if q.is_nan() || q <= 0.0 || rng.f() >= q {
                    break;
                }
                beta = beta * (1.0 / q);
            }
            let wi = basis.to_world(bs.wi);
            let side = if bs.wi.z > 0.0 { lit.nf } else { -lit.nf };
            let pdf = (!bs.delta).then_some(bs.pdf);
            // Into a glass object: slower light, and no change of frame.
            if mat.transmit > 0.0 && wi.dot(lit.n) < 0.0 {
                if let Some((h, at_event)) = sh.inside_hit(lit.group, event, side, wi, mat.ior) {
                    let from = sh.pushed_off(lit.group, event, side);
                    came = pdf.map(|pdf| Came { pdf, from, s: 1.0 });
                    (hit, event) = (h, at_event);
                    continue;
                }
            }
            let r = sh.spawn(lit.group, event, side, wi);
            let receiver_s = sh.lookback_factor(lit.group, r.dir);
            let Some(h) = world.closest_hit(&r, 0.0) else {
                let mut sky = sh.background_along(r.dir, receiver_s, shift);
                sky.mul_by(&beta);
                out.add(&sky);
                break;
            };
            let (shift_h, k) = sh.arriving(receiver_s, h.s, shift);
            beta = beta * k;
            let s = world.groups[lit.group].boost.null_dir(r.dir).1;
            came = pdf.map(|pdf| Came {
                pdf,
                from: r.origin,
                s,
            });
            (hit, event, shift) = (h, r.at(h.lambda), shift_h);
        }
        out
    }

    /// The weight of an emitter a BSDF draw met (power heuristic against next-event
    /// estimation's density for the same point, in the receiver's frame).
    fn mis_met(&self, came: &Came, hit: &SurfaceHit) -> f64 {
        let p_pick = self.emitters.prob_of(hit.group, hit.prim);
        if p_pick == 0.0 {
            return 1.0;
        }
        let g = &self.shader.world.groups[hit.group];
        let x = g.boost.event(came.from).x;
        let pdf_e = emitters::pdf_point(&g.geometry.prim(hit.prim), x, hit.point);
        let d = came.s / hit.s;
        power(came.pdf, p_pick * pdf_e * d * d)
    }

    /// `beta` times the light of every point light that reaches the vertex, to `out`.
    fn point_lights(
        &self,
        lit: &Lit,
        lobes: &Lobes<B>,
        basis: &Basis,
        wo: DVec3,
        beta: &B,
        out: &mut B,
    ) {
        let sh = self.shader;
        let g = &sh.world.groups[lit.group];
        for (i, l) in sh.lights.iter().enumerate() {
            let mut from = sh.pushed_off(lit.group, lit.event, lit.nf);
            let Some(mut to) = l.toward(from, g) else {
                continue;
            };
            // Through a rough glass: the shadow ray leaves from the far side.
            if to.to_light.dot(lit.nf) < 0.0 {
                from = sh.pushed_off(lit.group, lit.event, -lit.nf);
                let Some(t) = l.toward(from, g) else {
                    continue;
                };
                to = t;
            }
            let wi = basis.to_local(to.to_light);
            let (f, _) = lobes.eval(wo, wi);
            if f.max_value() <= 0.0 {
                continue;
            }
            let ray = NullRay::new(from, to.dir_w);
            if sh.world.shadowed(i, &ray, to.dist * to.k * (1.0 - 1e-9)) {
                continue;
            }
            let atten = if l.light.inverse_square {
                1.0 / (to.dist * to.dist)
            } else {
                1.0
            };
            let (light_shift, k) = sh.seen.irradiance(to.k * to.s_surface, lit.shift);
            // A point light's `intensity` is Whitted's: a white Lambert surface facing it at
            // distance 1 shows that radiance, so its irradiance there is π times it.
            let mut c = B::of(&l.light.radiance, B::at(light_shift));
            c.mul_by(&f);
            c.mul_by(beta);
            out.add(&(c * (PI * atten * wi.z.abs() * k)));
        }
    }

    /// `beta` times the light of one glowing primitive, drawn on its area in its rest frame,
    /// weighed against the BSDF's draws, to `out`.
    #[allow(clippy::too_many_arguments)]
    fn emitter_light(
        &self,
        lit: &Lit,
        lobes: &Lobes<B>,
        basis: &Basis,
        wo: DVec3,
        beta: &B,
        rng: &mut Rng,
        out: &mut B,
    ) {
        let sh = self.shader;
        let world = sh.world;
        let Some((eg, prim, p_pick)) = self.emitters.pick(rng.f()) else {
            return;
        };
        let u = [rng.f(), rng.f(), rng.f()];
        let ge = &world.groups[eg];
        let prim_e = ge.geometry.prim(prim);
        // The vertex in the emitter's frame, where the emitter is static: the event on its
        // surface on the vertex's past light cone is `dist` before, at the drawn point.
        let x = ge.boost.event(lit.event).x;
        let Some(pt) = emitters::sample_point(&prim_e, x, u) else {
            return;
        };
        // The shadow ray starts ε off the surface, on the side the light comes from; the
        // distance and the density are taken from there (as a BSDF draw's are, `mis_met`).
        let n_e = ge.boost.inverse().view_dir(pt.point - x).0;
        let toward = world.groups[lit.group].boost.view_dir(n_e).0;
        let side = if toward.dot(lit.nf) > 0.0 {
            lit.nf
        } else {
            -lit.nf
        };
        let from = sh.pushed_off(lit.group, lit.event, side);
        let x = ge.boost.event(from).x;
        let delta = pt.point - x;
        let dist = delta.length();
        if dist == 0.0 || !dist.is_finite() {
            return;
        }
        let look_e = delta / dist;
        // ν_world / ν_emitter, then ν_vertex / ν_world, along the ray.
        let (dir_w, k_world) = ge.boost.inverse().view_dir(look_e);
        let (look, s_vertex) = world.groups[lit.group].boost.view_dir(dir_w);
        let d = k_world * s_vertex;
        let wi = basis.to_local(look);
        let (f, pdf_bsdf) = lobes.eval(wo, wi);
        if f.max_value() <= 0.0 {
            return;
        }
        let ray = NullRay::new(from, dir_w);
        if world.occluded(&ray, 0.0, dist * k_world * (1.0 - 1e-6)) {
            return;
        }
        let pdf_e = emitters::pdf_point(&prim_e, x, pt.point);
        let p_light = p_pick * pdf_e * d * d;
        let (shift_e, k) = sh.seen.radiance(d, lit.shift);
        let on = SurfaceHit {
            group: eg,
            prim,
            lambda: 0.0,
            point: pt.point,
            dir: look_e,
            s: 1.0,
        };
        let elit = sh.lit_at(&on, lit.event, shift_e);
        let Some(e) = &elit.mat.emission else {
            return;
        };
        let at = B::at(shift_e);
        let mut c = surface_colour::<B>(e, elit.mat.emission_texture.as_deref(), &elit, at);
        c.mul_by(&f);
        c.mul_by(beta);
        let w = power(p_light, pdf_bsdf);
        out.add(&(c * (k * wi.z.abs() * w / p_light)));
    }
}

/// The power heuristic's weight for a strategy of density `a` against one of density `b`.
fn power(a: f64, b: f64) -> f64 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 {
        a2 / (a2 + b2)
    } else {
        0.0
    }
}
