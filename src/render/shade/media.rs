//! Light in matter, for both integrators: the way through a glass object in its own frame,
//! at c/n (docs/physics.md §9.1), and media: Beer-Lambert along a way, shadow rays across the
//! boundaries of media, the invisible boundary of a fog bank, and the fog everywhere (§9.3).

use super::{Lit, Shader, Spread};
use crate::render::band::Band;
use crate::render::ray_budget::Budget;
use crate::render::world::SurfaceHit;
use crate::spacetime::{Event, NullRay};
use glam::DVec3;

/// A medium a ray is in: its world group and its material.
pub(in crate::render) type Medium = Option<(usize, u32)>;

/// One stretch of a null ray's way across the boundaries of media: in medium `within` from
/// lookback `from` to `hit` (None: nothing ahead), which is either a medium's invisible
/// boundary (`boundary`: the way goes on past it) or a surface (the way ends there).
pub(in crate::render) struct Stretch {
    pub within: Medium,
    pub from: f64,
    pub hit: Option<SurfaceHit>,
    pub boundary: bool,
}

/// The way of a null ray across the boundaries of media, stretch by stretch: the one walk
/// both the path integrator's legs and the shadow rays of both integrators take.
pub(in crate::render) struct MediaWalk {
    within: Medium,
    t: f64,
    known: Option<SurfaceHit>,
}

impl MediaWalk {
    /// A walk that starts in `within` (outside every object: the fog, if the scene has one),
    /// its first hit `first` where known.
    pub fn new<B: Band>(sh: &Shader<B>, within: Medium, first: Option<SurfaceHit>) -> Self {
        MediaWalk {
            within: within.or(sh.fog),
            t: 0.0,
            known: first,
        }
    }

    /// The next stretch along `ray`; past a boundary, the walk goes on in the medium beyond.
    pub fn next<B: Band>(&mut self, sh: &Shader<B>, ray: &NullRay) -> Stretch {
        let world = sh.world;
        let hit = self.known.take().or_else(|| world.closest_hit(ray, self.t));
        let (mut within, from) = (self.within, self.t);
        // Only the boundaries of media are invisible: without any, every hit is a surface.
        let boundary = hit.filter(|_| sh.has_invisible()).and_then(|h| {
            let material = world.groups[h.group].geometry.part_of(h.prim).material;
            sh.scene.materials[material as usize]
                .is_invisible()
                .then_some((h, material))
        });
        if let Some((h, material)) = boundary {
            let g = &world.groups[h.group];
            let exiting = g.geometry.prim(h.prim).normal(h.point).dot(h.dir) > 0.0;
            // Leaving a medium not entered on the way: the ray started in it (media are
            // closed and not nested).
            if exiting && within != Some((h.group, material)) {
                within = Some((h.group, material));
            }
            self.within = if exiting {
                sh.fog
            } else {
                Some((h.group, material))
            };
            // Past the boundary, by its group's ε (rest frame) in world lookback.
            self.t = h.lambda + g.epsilon / h.s;
        }
        Stretch {
            within,
            from,
            hit,
            boundary: boundary.is_some(),
        }
    }
}

impl<B: Band> Shader<'_, B> {
    /// The share of light the scene's fog lets through over lookback `lambda` (world frame)
    /// along world direction `dir`, seen by a receiver with lookback factor `receiver_s` and
    /// wavelengths `shift` times the camera's (None: no fog).
    pub(in crate::render) fn fog_over(
        &self,
        dir: DVec3,
        receiver_s: f64,
        shift: f64,
        lambda: f64,
    ) -> Option<B> {
        let (g, m) = self.fog?;
        let gs = self.world.groups[g].boost.null_dir(dir).1;
        let shift_f = self
            .arriving(receiver_s, self.lookback_factor(g, dir), shift)
            .0;
        self.attenuation(m, shift_f, gs * lambda)
    }

    /// The light a ray that leaves a hit into the inside of its object (rest-frame direction
    /// `dir`, starting ε off the surface along `side`) meets first: light inside a material
    /// of index `ior` travels at c/ior in the material's rest frame (docs/physics.md §9), so the
    /// event it left is found in that frame, `ior` times the distance back in time, and only
    /// the object's own group is searched. The hit (its direction the unit rest-frame one, its
    /// lookback factor 1: no change of frame on the way) and the event; None where the ray
    /// meets nothing of its group (an object that is not closed), and leaves as a null ray.
    /// The hit's lookback is 0: the caller accounts for the way (`dist`, the third value).
    pub(crate) fn inside_hit(
        &self,
        group: usize,
        event: Event,
        side: DVec3,
        dir: DVec3,
        ior: f64,
    ) -> Option<(SurfaceHit, Event, f64)> {
        let g = &self.world.groups[group];
        let from = g.boost.event(self.pushed_off(group, event, side));
        let (prim, t) = self.world.hit_in_group(group, from.x, dir)?;
        let point = from.x + t * dir;
        // The delay from the surface point itself (not the pushed-off start): exact.
        let entry = g.boost.event(event);
        let dist = (point - entry.x).length();
        let at_rest = Event::new(entry.t - ior * dist, point);
        let at = g.boost.inverse().event(at_rest);
        let hit = SurfaceHit {
            group,
            prim,
            lambda: 0.0,
            point: at_rest.x,
            dir,
            s: 1.0,
        };
        Some((hit, at, dist))
    }

    /// The attenuation coefficient σ_a + σ_s of a material's medium at wavelengths `shift` times
    /// the camera's (None: it has none).
    pub(in crate::render) fn sigma_t(&self, material: u32, shift: f64) -> Option<B> {
        let m = self.scene.materials[material as usize].medium.as_ref()?;
        let at = B::at(shift);
        let mut t = B::of(&m.sigma_a, at);
        t.add(&B::of(&m.sigma_s, at));
        Some(t)
    }

    /// The share of light that crosses a length `d` (its rest frame) of a material's medium, at
    /// wavelengths `shift` times the camera's (Beer-Lambert; None: no medium, all of it).
    pub(super) fn attenuation(&self, material: u32, shift: f64, d: f64) -> Option<B> {
        self.sigma_t(material, shift).map(|s| s.exp_neg(d))
    }

    /// Whether some object's surface is only the boundary of a medium (then shadow rays cross
    /// such surfaces, attenuated, instead of stopping at them).
    pub(in crate::render) fn has_invisible(&self) -> bool {
        self.invisible
    }

    /// The share of light that reaches the start of a shadow ray from lookback `tmax` along it,
    /// crossing the boundaries of media (attenuated in each, in its own frame) and stopped by
    /// any other surface (None). `within`: the medium the ray starts in (world group and
    /// material); `shift`: the wavelengths of the ray's start, `s` its frame's lookback factor
    /// for the ray (the medium's own wavelengths follow from the two frames).
    pub(in crate::render) fn transmittance(
        &self,
        ray: &NullRay,
        tmax: f64,
        within: Medium,
        shift: f64,
        s: f64,
    ) -> Option<B> {
        let mut share: Option<B> = None;
        let mut cross = |within: Medium, from: f64, to: f64| {
            let Some((g, m)) = within else {
                return;
            };
            let gs = self.world.groups[g].boost.null_dir(ray.dir).1;
            let shift_m = self.seen.radiance(s / gs, shift).0;
            // A boundary crossed within ε of the shadow ray's end can step past it: no length.
            if let Some(a) = self.attenuation(m, shift_m, gs * (to - from).max(0.0)) {
                match &mut share {
                    Some(t) => t.mul_by(&a),
                    None => share = Some(a),
                }
            }
        };
        let mut way = MediaWalk::new(self, within, None);
        loop {
            let stretch = way.next(self, ray);
            match stretch.hit.filter(|h| h.lambda < tmax) {
                None => {
                    cross(stretch.within, stretch.from, tmax);
                    return Some(share.unwrap_or(B::splat(1.0)));
                }
                Some(_) if !stretch.boundary => return None,
                Some(h) => cross(stretch.within, stretch.from, h.lambda),
            }
        }
    }

    /// What a ray that meets the invisible boundary of a medium (`lit`) sees beyond it: going
    /// in, the first surface of the object's group inside (its own far side, or an object in
    /// the medium), attenuated by the medium over the way (Beer-Lambert, rest frame), and
    /// through the far side what lies beyond; coming out, what lies beyond. The ray keeps its
    /// direction: the boundary bends nothing.
    pub(super) fn pass_through(&self, lit: &Lit, budget: Budget) -> (B, u64) {
        let outward = lit.v.dot(lit.n) > 0.0;
        let side = if outward { lit.n } else { -lit.n };
        let material = self.world.groups[lit.group]
            .geometry
            .part_of(lit.prim_id)
            .material;
        if !outward {
            if let Some((h, at, d)) = self.inside_hit(lit.group, lit.event, side, lit.v, 1.0) {
                let (mut light, spent) = self.shade_at(&h, at, lit.shift, budget, lit.spread);
                if let Some(a) = self.attenuation(material, lit.shift, d) {
                    light.mul_by(&a);
                }
                return (light, spent);
            }
        }
        let r = self.spawn(lit.group, lit.event, side, lit.v);
        let s = self.lookback_factor(lit.group, r.dir);
        let spread = match self.cones {
            Some(_) if lit.spread > 0.0 => Spread {
                sr: lit.spread,
                s: self.world.groups[lit.group].boost.null_dir(r.dir).1,
            },
            _ => Spread::NONE,
        };
        let (mut light, spent) = self.trace(&r, s, lit.shift, budget, spread);
        // Coming out of a medium the ray started in (a camera in a fog bank): its way in it.
        if outward && lit.reach > 0.0 {
            if let Some(a) = self.attenuation(material, lit.shift, lit.reach) {
                light.mul_by(&a);
            }
        }
        (light, spent)
    }
}
