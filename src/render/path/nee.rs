//! Next-event estimation: at a vertex (a surface's hit, or a point in a medium), the light of
//! every point light and of one glowing primitive drawn in its own rest frame, each through a
//! shadow ray (attenuated through media), weighed against the vertex's own draws by the power
//! heuristic (docs/physics.md §10.3).

use super::draws::power;
use super::emitters;
use super::{Came, PathTracer};
use crate::render::band::Band;
use crate::render::shade::surface_colour;
use crate::render::world::SurfaceHit;
use crate::rng::Rng;
use crate::spacetime::{Event, NullRay};
use glam::DVec3;
use std::f64::consts::PI;

/// Where next-event estimation gathers light.
pub(super) struct Gather {
    pub group: usize,
    pub event: Event,
    /// The frame's wavelengths over the camera's.
    pub shift: f64,
    /// A surface's normal toward the side the path came from (None: a point in a medium).
    pub nf: Option<DVec3>,
    /// The medium the point is in.
    pub within: Option<(usize, u32)>,
}

impl<B: Band> PathTracer<'_, '_, B> {
    /// The weight of an emitter a BSDF draw met (power heuristic against next-event
    /// estimation's density for the same point, in the receiver's frame).
    pub(super) fn mis_met(&self, came: &Came, hit: &SurfaceHit) -> f64 {
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

    /// Whether the way from `here` back along a shadow ray (`ray`, to lookback `tmax`) is clear,
    /// and what share of the light crosses it: media attenuate it (where the scene has any
    /// whose surface is invisible), any other surface stops it (None).
    fn reaches(
        &self,
        here: &Gather,
        ray: &NullRay,
        tmax: f64,
        light: Option<usize>,
    ) -> Option<Option<B>> {
        let sh = self.shader;
        if sh.has_invisible() {
            let s = sh.world.groups[here.group].boost.null_dir(ray.dir).1;
            return sh
                .transmittance(ray, tmax, here.within, here.shift, s)
                .map(Some);
        }
        let blocked = match light {
            None => sh.world.occluded(ray, 0.0, tmax),
            Some(l) => sh.world.shadowed(l, ray, tmax),
        };
        (!blocked).then_some(None)
    }

    /// `beta` times the light `here` gathers from every point light and one glowing primitive
    /// (next-event estimation), to `out`. `scatter(wi)`: for light arriving from rest-frame
    /// direction `wi`, the factor on its radiance (BSDF times cosine, or the phase function)
    /// and the density with which the vertex's own draw would have chosen `wi`.
    pub(super) fn gather(
        &self,
        here: &Gather,
        scatter: &dyn Fn(DVec3) -> (B, f64),
        beta: &B,
        rng: &mut Rng,
        out: &mut B,
    ) {
        self.point_lights(here, scatter, beta, out);
        self.emitter_light(here, scatter, beta, rng, out);
    }

    /// The start of a shadow ray toward rest-frame direction `toward`: ε off the surface on
    /// that side (a point in a medium starts where it is).
    fn shadow_start(&self, here: &Gather, toward: DVec3) -> Event {
        match here.nf {
            Some(nf) => {
                let side = if toward.dot(nf) > 0.0 { nf } else { -nf };
                self.shader.pushed_off(here.group, here.event, side)
            }
            None => here.event,
        }
    }

    pub(super) fn point_lights(
        &self,
        here: &Gather,
        scatter: &dyn Fn(DVec3) -> (B, f64),
        beta: &B,
        out: &mut B,
    ) {
        let sh = self.shader;
        let g = &sh.world.groups[here.group];
        for (i, l) in sh.lights.iter().enumerate() {
            let Some(first) = l.toward(here.event, here.event, g, None) else {
                continue;
            };
            let from = self.shadow_start(here, first.to_light);
            let Some(to) = l.toward(from, here.event, g, None) else {
                continue;
            };
            let (f, _) = scatter(to.to_light);
            if f.max_value() <= 0.0 {
                continue;
            }
            let ray = NullRay::new(from, to.dir_w);
            let Some(through) = self.reaches(here, &ray, to.dist * to.k * (1.0 - 1e-9), Some(i))
            else {
                continue;
            };
            let atten = to.atten;
            let (light_shift, k) = sh.seen.irradiance(to.k * to.s_surface, here.shift);
            // A point light's `intensity` is Whitted's: a white Lambert surface facing it at
            // distance 1 shows that radiance, so its irradiance there is π times it.
            let mut c = B::of(&l.light.radiance, B::at(light_shift));
            c.mul_by(&f);
            c.mul_by(beta);
            if let Some(t) = &through {
                c.mul_by(t);
            }
            out.add(&(c * (PI * atten * k)));
        }
    }

    /// `beta` times the light of one glowing primitive, drawn on its area in its rest frame,
    /// weighed against the vertex's own draws, to `out`.
    fn emitter_light(
        &self,
        here: &Gather,
        scatter: &dyn Fn(DVec3) -> (B, f64),
        beta: &B,
        rng: &mut Rng,
        out: &mut B,
    ) {
        let Some(pick) = self.emitters.pick(rng.f()) else {
            return;
        };
        let u = [rng.f(), rng.f(), rng.f()];
        self.emitter_light_drawn(here, scatter, beta, pick, u, out);
    }

    /// [`PathTracer::emitter_light`] with its random numbers drawn: the emitter `pick` (its
    /// group, primitive and probability), and the three numbers of the point on it.
    pub(super) fn emitter_light_drawn(
        &self,
        here: &Gather,
        scatter: &dyn Fn(DVec3) -> (B, f64),
        beta: &B,
        (eg, prim, p_pick): (usize, u32, f64),
        u: [f64; 3],
        out: &mut B,
    ) {
        let sh = self.shader;
        let world = sh.world;
        let ge = &world.groups[eg];
        let prim_e = ge.geometry.prim(prim);
        // The vertex in the emitter's frame, where the emitter is static: the event on its
        // surface on the vertex's past light cone is `dist` before, at the drawn point.
        let x = ge.boost.event(here.event).x;
        let Some(pt) = emitters::sample_point(&prim_e, x, u) else {
            return;
        };
        // The shadow ray starts ε off the surface, on the side the light comes from; the
        // distance and the density are taken from there (as a BSDF draw's are, `mis_met`).
        let toward_w = ge.boost.inverse().view_dir(pt.point - x).0;
        let toward = world.groups[here.group].boost.view_dir(toward_w).0;
        let from = self.shadow_start(here, toward);
        let x = ge.boost.event(from).x;
        let delta = pt.point - x;
        let dist = delta.length();
        if dist == 0.0 || !dist.is_finite() {
            return;
        }
        let look_e = delta / dist;
        // ν_world / ν_emitter, then ν_vertex / ν_world, along the ray.
        let (dir_w, k_world) = ge.boost.inverse().view_dir(look_e);
        let (look, s_vertex) = world.groups[here.group].boost.view_dir(dir_w);
        let d = k_world * s_vertex;
        let (f, pdf_own) = scatter(look);
        if f.max_value() <= 0.0 {
            return;
        }
        let ray = NullRay::new(from, dir_w);
        // A worldline's segment shines only at its own times (as `World::rest_ray` sees it).
        if !ge.shows_at(ray.at(dist * k_world)) {
            return;
        }
        let tmax = dist * k_world * (1.0 - 1e-6);
        let Some(through) = self.reaches(here, &ray, tmax, None) else {
            return;
        };
        let pdf_e = emitters::pdf_point(&prim_e, x, pt.point);
        let p_light = p_pick * pdf_e * d * d;
        let (shift_e, k) = sh.seen.radiance(d, here.shift);
        let Some(mut c) = self.emitted((eg, prim), pt.point, look_e, here.event, shift_e) else {
            return;
        };
        c.mul_by(&f);
        c.mul_by(beta);
        if let Some(t) = &through {
            c.mul_by(t);
        }
        let w = power(p_light, pdf_own);
        out.add(&(c * (k * w / p_light)));
    }

    /// The light emitter `prim` of group `eg` sends from rest-frame point `point` (looked at
    /// along `look`, from `event`), at wavelengths `shift` times the camera's; None where its
    /// material does not glow.
    pub(super) fn emitted(
        &self,
        (eg, prim): (usize, u32),
        point: DVec3,
        look: DVec3,
        event: Event,
        shift: f64,
    ) -> Option<B> {
        let sh = self.shader;
        let at = B::at(shift);
        let mat = &sh.scene.materials[self.emitters.material_of(eg, prim) as usize];
        let e = mat.emission.as_ref()?;
        // A texture is read where the point lies on the object; a colour is the same all over.
        Some(match mat.emission_texture.as_deref() {
            None => B::of(e, at),
            Some(texture) => {
                let on = SurfaceHit {
                    group: eg,
                    prim,
                    lambda: 0.0,
                    point,
                    dir: look,
                    s: 1.0,
                };
                let elit = sh.lit_at(&on, event, shift);
                surface_colour::<B>(e, Some(texture), &elit, at)
            }
        })
    }
}
