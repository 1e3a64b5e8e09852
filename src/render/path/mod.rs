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
mod draws;
mod emitters;
mod lanes;
mod nee;
mod phase;
mod wave;

pub(crate) use emitters::Emitters;
pub(crate) use wave::{Start, WaveScratch};

use super::band::Band;
use super::shade::{surface_colour, Lit, MediaWalk, Shader, Spread};
use super::world::SurfaceHit;
use crate::rng::{splitmix64 as splitmix, Rng};
use crate::spacetime::{Event, NullRay};
use bsdf::{Basis, Lobes};
use glam::DVec3;
use nee::Gather;

/// The bounce from which Russian roulette may end a path.
const ROULETTE_FROM: u32 = 5;

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
    /// Whether the commonest vertices go to the lanes (`wave.rs`), and whether those run in
    /// vector registers (`WorldOptions::lanes`, `WorldOptions::simd`).
    lanes: bool,
    simd: bool,
    /// Per material, whether it is one Lambert lobe and nothing else, untextured (such
    /// surfaces are resolved without the rest of the hit, `plain_lambert`).
    plain: Vec<bool>,
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
        let options = shader.world.options;
        Self {
            shader,
            emitters,
            max_depth: shader.scene.render.max_depth,
            lanes: options.lanes,
            simd: options.simd,
            plain: shader
                .scene
                .materials
                .iter()
                .map(|m| {
                    m.emission.is_none()
                        && m.medium.is_none()
                        && !m.is_invisible()
                        && m.color_texture.is_none()
                        && m.specular.is_black()
                        && m.reflect == 0.0
                        && m.transmit == 0.0
                })
                .collect(),
        }
    }

    /// The light of the sky (and of the stars, along a path of mirrors and clear glass that
    /// keeps its bundle) that a leg along world-frame `dir` brings to its receiver (lookback
    /// factor `receiver_s`), times the path's throughput.
    fn sky_light(&self, dir: DVec3, receiver_s: f64, path: &Path<B>) -> B {
        let sh = self.shader;
        let mut sky = sh.background_along(dir, receiver_s, path.shift);
        if let Some(stars) = sh.stars_along(dir, receiver_s, path.shift, path.spread) {
            sky.add(&stars);
        }
        sky.mul_by(&path.beta);
        sky
    }

    /// Follow a null ray from its receiver (lookback factor `receiver_s`, as the switches have
    /// it) until it meets a surface or scatters in a medium, crossing the boundaries of media
    /// as it goes (`within`: the medium it starts in). The throughput and the wavelengths are
    /// carried into the frame of what it reaches. `first`: its first hit, where known.
    fn walk(
        &self,
        ray: &NullRay,
        receiver_s: f64,
        within: Option<(usize, u32)>,
        first: Option<SurfaceHit>,
        path: &mut Path<B>,
        rng: &mut Rng,
    ) -> Reached {
        let (sh, world) = (self.shader, self.shader.world);
        let mut way = MediaWalk::new(sh, within, first);
        loop {
            let stretch = way.next(sh, ray);
            if let Some((g, m)) = stretch.within {
                // Free flight through the medium, in its frame.
                let gs = world.groups[g].boost.null_dir(ray.dir).1;
                // The medium's wavelengths, and what its light gains on the way to the receiver.
                let (shift_m, k) =
                    sh.arriving(receiver_s, sh.lookback_factor(g, ray.dir), path.shift);
                let end = stretch.hit.map_or(f64::INFINITY, |h| h.lambda);
                match self.fly(m, shift_m, gs * (end - stretch.from), path, rng) {
                    Some(ts) => {
                        let lambda = stretch.from + ts / gs;
                        path.beta = path.beta * k;
                        path.shift = shift_m;
                        return Reached::Scatter(Scatter {
                            group: g,
                            material: m,
                            event: ray.at(lambda),
                            look: world.groups[g].boost.view_dir(ray.dir).0,
                            slow: None,
                        });
                    }
                    None if stretch.hit.is_none() => return Reached::Lost,
                    None => {}
                }
            }
            if !stretch.boundary {
                return self.reach(ray, receiver_s, stretch.hit, stretch.within, path);
            }
        }
    }

    /// What a leg reaches where its last stretch (in medium `within`) ends at `hit`, a surface
    /// that is not a medium's boundary, or nowhere: the throughput and the wavelengths carried
    /// into the surface's frame.
    fn reach(
        &self,
        ray: &NullRay,
        receiver_s: f64,
        hit: Option<SurfaceHit>,
        within: Option<(usize, u32)>,
        path: &mut Path<B>,
    ) -> Reached {
        let Some(h) = hit else {
            return Reached::Sky {
                dir: ray.dir,
                receiver_s,
            };
        };
        let (shift_h, k) = self.shader.arriving(receiver_s, h.s, path.shift);
        path.beta = path.beta * k;
        path.shift = shift_h;
        Reached::Surface {
            hit: h,
            event: ray.at(h.lambda),
            within,
        }
    }

    /// Whether a leg is a plain null ray whose closest hit is what it reaches: it starts in no
    /// medium, and the scene has no fog and no medium's boundary.
    fn is_plain(&self, leg: &Leg) -> bool {
        let sh = self.shader;
        matches!(leg, Leg::Null { within: None, .. }) && sh.fog.is_none() && !sh.has_invisible()
    }

    /// Follow a ray inside a glass object (its group's frame, light at c/n, `Shader::inside_hit`)
    /// to its next surface, or to where it scatters in the object's medium.
    fn walk_inside(&self, leg: &Inside, path: &mut Path<B>, rng: &mut Rng) -> Reached {
        let Inside {
            group,
            event,
            side,
            dir,
            material,
            outside,
        } = *leg;
        let sh = self.shader;
        let ior = sh.scene.materials[material as usize].ior;
        let Some((h, at, d)) = sh.inside_hit(group, event, side, dir, ior) else {
            // Not closed: the ray leaves as a null ray.
            let r = sh.spawn(group, event, side, dir);
            let receiver_s = sh.lookback_factor(group, r.dir);
            return self.walk(&r, receiver_s, outside, None, path, rng);
        };
        // The way is in the object's frame: no change of wavelengths; the throughput changes
        // by the medium alone (`fly` sees to it).
        let from = sh.pushed_off(group, event, side);
        if sh.scene.materials[material as usize].medium.is_some() {
            if let Some(ts) = self.fly(material, path.shift, d, path, rng) {
                let g = &sh.world.groups[group];
                let start = g.boost.event(event);
                let point = g.boost.event(from).x + ts * dir;
                let at_rest = Event::new(start.t - ior * (point - start.x).length(), point);
                return Reached::Scatter(Scatter {
                    group,
                    material,
                    event: g.boost.inverse().event(at_rest),
                    look: dir,
                    slow: Some(outside),
                });
            }
        }
        Reached::Surface {
            hit: h,
            event: at,
            within: outside,
        }
    }

    /// Free flight over a rest-frame length `d` of material `m`'s medium (wavelengths `shift`
    /// times the camera's): a distance drawn with density σ̄ e^(−σ̄ t), σ̄ the mean attenuation
    /// over the band; Some(t) where it falls short of `d` (the light scattered there), the
    /// throughput weighed by σ_s e^(−σ_t t) / (σ̄ e^(−σ̄ t)); else by e^(−σ_t d) / e^(−σ̄ d).
    fn fly(&self, m: u32, shift: f64, d: f64, path: &mut Path<B>, rng: &mut Rng) -> Option<f64> {
        let sh = self.shader;
        let sigma_t = sh.sigma_t(m, shift)?;
        let mean = sigma_t.mean_value();
        if mean <= 0.0 {
            return None;
        }
        let medium = sh.scene.materials[m as usize]
            .medium
            .as_ref()
            .expect("a medium");
        let sigma_s = B::of(&medium.sigma_s, B::at(shift));
        // A medium that only absorbs: Beer-Lambert, no draw.
        if sigma_s.max_value() <= 0.0 {
            if d.is_finite() {
                path.beta.mul_by(&sigma_t.exp_neg(d));
            } else {
                path.beta = path.beta * 0.0;
            }
            return None;
        }
        let ts = -(1.0 - rng.f()).ln() / mean;
        if ts < d {
            let mut w = sigma_s;
            w.mul_by(&sigma_t.exp_neg(ts));
            path.beta.mul_by(&(w * (1.0 / (mean * (-mean * ts).exp()))));
            return Some(ts);
        }
        if d.is_finite() {
            path.beta.mul_by(&(sigma_t.exp_neg(d) * (mean * d).exp()));
        }
        None
    }

    /// A surface the path met, resolved once: its light if it glows (added to `out`, and the
    /// path ends: None), else its material's lobes in the surface's frame (None where they
    /// scatter nothing, or past the last bounce).
    fn meet_surface(
        &self,
        hit: &SurfaceHit,
        event: Event,
        depth: u32,
        path: &Path<B>,
        out: &mut B,
    ) -> Option<Surface<'a, B>> {
        let sh = self.shader;
        let lit = sh.lit_at(hit, event, path.shift);
        let (mat, at) = (lit.mat, B::at(path.shift));
        if let Some(e) = &mat.emission {
            let weight = path.came.as_ref().map_or(1.0, |c| self.mis_met(c, hit));
            let mut le = surface_colour::<B>(e, mat.emission_texture.as_deref(), &lit, at);
            le.mul_by(&path.beta);
            out.add(&(le * weight));
            return None;
        }
        // Past the last bounce a vertex only says what light it sends (above).
        if depth > self.max_depth {
            return None;
        }
        let diffuse = surface_colour::<B>(&mat.color, mat.color_texture.as_deref(), &lit, at);
        let phong = (!mat.specular.is_black()).then(|| (B::of(&mat.specular, at), mat.shininess));
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
            return None;
        }
        let basis = Basis::new(lit.nf);
        let wo = basis.to_local(-lit.v);
        Some(Surface {
            lit,
            lobes,
            basis,
            wo,
        })
    }

    /// The light a resolved surface gathers (to `out`), and the next leg its lobes draw.
    #[allow(clippy::too_many_arguments)]
    fn scatter_surface(
        &self,
        s: &Surface<'a, B>,
        hit: &SurfaceHit,
        within: Option<(usize, u32)>,
        depth: u32,
        path: &mut Path<B>,
        rng: &mut Rng,
        out: &mut B,
    ) -> Option<Leg> {
        let Surface {
            lit,
            lobes,
            basis,
            wo,
        } = s;
        let here = Gather {
            group: lit.group,
            event: lit.event,
            shift: lit.shift,
            nf: Some(lit.nf),
            within,
        };
        if lobes.has_glossy() {
            let scatter = |wi: DVec3| {
                let l = basis.to_local(wi);
                let (f, pdf) = lobes.eval(*wo, l);
                (f * l.z.abs(), pdf)
            };
            self.gather(&here, &scatter, &path.beta, rng, out);
        }
        let u = [rng.f(), rng.f(), rng.f(), rng.f()];
        let bs = lobes.sample(*wo, u)?;
        path.beta.mul_by(&bs.weight);
        self.roulette(depth, path, rng)?;
        let wi = basis.to_world(bs.wi);
        let glass = (lit.mat.transmit > 0.0).then(|| {
            let part = self.shader.world.groups[lit.group]
                .geometry
                .part_of(hit.prim);
            (lit.n, part.material)
        });
        let spot = Spot {
            group: lit.group,
            event: lit.event,
            nf: lit.nf,
            glass,
        };
        let pdf = (!bs.delta).then_some(bs.pdf);
        Some(self.leg_after(&spot, hit.s, within, wi, bs.wi.z > 0.0, pdf, path))
    }

    /// The next leg from a surface (`spot`, met by a ray whose lookback factor there was
    /// `hit_s`) along rest-frame direction `wi`, to the side the light left toward where
    /// `above`, drawn with density `pdf` (None: a smooth lobe's).
    #[allow(clippy::too_many_arguments)]
    fn leg_after(
        &self,
        spot: &Spot,
        hit_s: f64,
        within: Option<(usize, u32)>,
        wi: DVec3,
        above: bool,
        pdf: Option<f64>,
        path: &mut Path<B>,
    ) -> Leg {
        let sh = self.shader;
        let side = if above { spot.nf } else { -spot.nf };
        let from = sh.pushed_off(spot.group, spot.event, side);
        // A smooth bounce keeps the bundle's solid angle in the surface's frame (a flat
        // surface), as Whitted's rays do; any other ends it.
        let kept = match pdf.is_none() && path.spread.sr > 0.0 {
            true => path.spread.into_frame(hit_s),
            false => 0.0,
        };
        // Into a glass object: slower light, no change of frame, maybe a medium.
        if let Some((_, material)) = spot.glass.filter(|(n, _)| wi.dot(*n) < 0.0) {
            path.came = pdf.map(|pdf| Came { pdf, from, s: 1.0 });
            path.spread = Spread { sr: kept, s: 1.0 };
            return Leg::Slow(Inside {
                group: spot.group,
                event: spot.event,
                side,
                dir: wi,
                material,
                outside: within,
            });
        }
        let r = sh.spawn(spot.group, spot.event, side, wi);
        let s = sh.world.groups[spot.group].boost.null_dir(r.dir).1;
        path.came = pdf.map(|pdf| Came {
            pdf,
            from: r.origin,
            s,
        });
        path.spread = Spread { sr: kept, s };
        Leg::Null {
            ray: r,
            receiver_s: sh.lookback_factor(spot.group, r.dir),
            within,
        }
    }

    /// A point where the path's light scattered in a medium: the lights it gathers there, and
    /// the next leg, drawn from the medium's phase function.
    fn in_medium(
        &self,
        at: &Scatter,
        depth: u32,
        path: &mut Path<B>,
        rng: &mut Rng,
        out: &mut B,
    ) -> Option<Leg> {
        if depth > self.max_depth {
            return None;
        }
        let sh = self.shader;
        let medium = sh.scene.materials[at.material as usize].medium.as_ref()?;
        let phase = phase::Hg::new(medium.g);
        let wo = -at.look;
        let here = Gather {
            group: at.group,
            event: at.event,
            shift: path.shift,
            nf: None,
            within: Some((at.group, at.material)),
        };
        // Inside glass the shadow rays meet the glass: only light that refracts in arrives.
        if at.slow.is_none() {
            let scatter = |wi: DVec3| {
                let p = phase.eval(wo, wi);
                (B::splat(p), p)
            };
            self.gather(&here, &scatter, &path.beta, rng, out);
        }
        let (wi, pdf) = phase.sample(wo, rng.f(), rng.f());
        self.roulette(depth, path, rng)?;
        path.spread = Spread::NONE;
        let s = match at.slow {
            Some(_) => 1.0,
            None => {
                let dir_w = sh.world.groups[at.group].boost.inverse().view_dir(wi).0;
                sh.world.groups[at.group].boost.null_dir(dir_w).1
            }
        };
        path.came = Some(Came {
            pdf,
            from: at.event,
            s,
        });
        Some(match at.slow {
            Some(outside) => Leg::Slow(Inside {
                group: at.group,
                event: at.event,
                side: DVec3::ZERO,
                dir: wi,
                material: at.material,
                outside,
            }),
            None => {
                let r = sh.spawn(at.group, at.event, DVec3::ZERO, wi);
                Leg::Null {
                    ray: r,
                    receiver_s: sh.lookback_factor(at.group, r.dir),
                    within: Some((at.group, at.material)),
                }
            }
        })
    }

    /// Russian roulette from the third bounce: None where the path ends.
    fn roulette(&self, depth: u32, path: &mut Path<B>, rng: &mut Rng) -> Option<()> {
        if depth + 1 >= ROULETTE_FROM && depth < self.max_depth {
            let q = path.beta.max_value().min(ROULETTE_MAX);
            // A NaN q ends the path too.
            if q.is_nan() || q <= 0.0 || rng.f() >= q {
                return None;
            }
            path.beta = path.beta * (1.0 / q);
        }
        Some(())
    }
}

/// A surface a path met, resolved once for all that is done there: the hit as shading sees
/// it, the material's lobes, and the local frame about the shading normal with the direction
/// toward the viewer in it.
struct Surface<'a, B> {
    lit: Lit<'a>,
    lobes: Lobes<B>,
    basis: Basis,
    wo: DVec3,
}

/// Where a surface's next leg leaves from: its group, the hit's event and the shading normal
/// toward the side the path came from; for a surface that lets light into glass, its outward
/// normal and the glass's material.
#[derive(Clone, Copy)]
struct Spot {
    group: usize,
    event: Event,
    nf: DVec3,
    glass: Option<(DVec3, u32)>,
}

/// A path's state between vertices: its throughput, the wavelengths of the frame it is in,
/// and what its last draw was (for weighing an emitter it meets).
struct Path<B> {
    beta: B,
    shift: f64,
    came: Option<Came>,
    /// The bundle the path's leg stands for (none after a bounce that is not smooth).
    spread: Spread,
}

/// A leg of a path: a null ray (through the media whose boundaries it crosses), or a ray
/// inside a glass object, in its frame.
#[derive(Clone, Copy)]
enum Leg {
    Null {
        ray: NullRay,
        /// The lookback factor of the ray's receiver (as the switches have it).
        receiver_s: f64,
        /// The medium it starts in.
        within: Option<(usize, u32)>,
    },
    Slow(Inside),
}

/// A ray inside a glass object, in the object's frame.
#[derive(Clone, Copy)]
struct Inside {
    group: usize,
    /// Where it starts (on the surface, or at a point where it scattered).
    event: Event,
    /// Which way it starts off the surface (zero at a point in the medium).
    side: DVec3,
    dir: DVec3,
    /// The glass object's material (its `ior`, and its medium if it has one).
    material: u32,
    /// The medium outside the object, to go back into.
    outside: Option<(usize, u32)>,
}

/// What a leg reaches.
enum Reached {
    Sky {
        dir: DVec3,
        receiver_s: f64,
    },
    Surface {
        hit: SurfaceHit,
        event: Event,
        /// The medium the surface is in.
        within: Option<(usize, u32)>,
    },
    Scatter(Scatter),
    /// The path ends (a medium with no far side).
    Lost,
}

/// A point where light scattered in a medium.
struct Scatter {
    group: usize,
    material: u32,
    event: Event,
    /// The leg's looking direction there, in the medium's frame.
    look: DVec3,
    /// Inside a glass object: Some(the medium outside it).
    slow: Option<Option<(usize, u32)>>,
}
