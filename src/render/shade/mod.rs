//! Whitted shading in the rest frame of the surface hit: Phong with shadow rays to point lights
//! on their own worldlines, mirror reflection, and refraction with Fresnel. Every secondary ray
//! is again a past-directed null ray, spawned in the surface's frame and boosted back.
//!
//! Shading works at the surface's rest-frame wavelengths, `shift` times the camera's. Light
//! crossing into the surface's frame (from a light, or from another surface along a reflected
//! or refracted ray) is shifted by the frequency ratio of the two frames along that ray, which
//! the boosts give for free: a frame's lookback factor `s` for a world-frame direction is the
//! photon's frequency there over its world-frame frequency ([`Boost::null_dir`]).

mod lights;
mod media;

use super::band::{Band, Seen};
use super::optics::{fresnel, phong, reflect, refract};
use super::ray_budget::{Branch, Budget};
use super::star_pixels::StarCones;
use super::world::{SurfaceHit, World};
use crate::scene::Scene;
use crate::spacetime::{Boost, Event, NullRay};
use glam::DVec3;
pub(super) use lights::{LightRt, ToLight};
pub(super) use media::MediaWalk;
use std::marker::PhantomData;

/// The sky, with the boost into its rest frame where it moves.
struct SkyRt<'a> {
    sky: &'a crate::scene::Sky,
    to_sky: Option<Boost>,
}

pub struct Shader<'a, B> {
    pub(super) scene: &'a Scene,
    pub(super) world: &'a World,
    pub(super) lights: Vec<LightRt<'a>>,
    sky: Option<SkyRt<'a>>,
    /// The stars by direction, for rays that leave after a bounce (None: no stars, or no
    /// material that reflects or transmits).
    cones: Option<&'a StarCones>,
    pub(super) seen: Seen,
    /// Whether some material is only the boundary of a medium.
    invisible: bool,
    /// The scene's fog: the world group whose frame it rests in, and its material.
    pub(super) fog: Option<(usize, u32)>,
    band: PhantomData<B>,
}

impl<'a, B: Band> Shader<'a, B> {
    /// A shader whose changes of frame do what `seen` says (use [`Seen::NONE`] for RGB).
    pub fn new(scene: &'a Scene, world: &'a World, seen: Seen) -> Self {
        let lights = scene
            .lights
            .iter()
            .map(|l| LightRt {
                light: l,
                to_light: Boost::to_rest(&l.velocity),
                from_light: Boost::from_rest(&l.velocity),
            })
            .collect();
        let sky = scene.sky.as_ref().map(|sky| SkyRt {
            sky,
            to_sky: (!sky.velocity.is_zero()).then(|| Boost::to_rest(&sky.velocity)),
        });
        Self {
            scene,
            world,
            lights,
            sky,
            cones: None,
            seen,
            invisible: scene.materials.iter().any(|m| m.is_invisible()),
            fog: scene.fog.as_ref().map(|f| {
                let key = scene.groups[f.group].velocity.identity_key();
                let g = world
                    .groups
                    .iter()
                    .position(|g| g.velocity.identity_key() == key)
                    .expect("a fog's group holds objects, so the world has its frame");
                (g, f.material)
            }),
            band: PhantomData,
        }
    }

    /// This shader, finding stars for the rays that leave after a bounce in `cones`.
    pub fn with_star_cones(mut self, cones: Option<&'a StarCones>) -> Self {
        self.cones = cones;
        self
    }

    /// Whether rays leaving after a bounce look for stars (so primary hits should say what
    /// bundle their ray stands for).
    pub fn finds_star_cones(&self) -> bool {
        self.cones.is_some()
    }

    /// The light arriving along a world-frame null ray at a receiver whose lookback factor
    /// for the ray's direction is `receiver_s` and whose wavelengths are `shift` times the
    /// camera's, in the receiver's frame; and the secondary rays spent below its hit. `spread`:
    /// the bundle the ray stands for (stars are found in it where it leaves the scene).
    pub fn trace(
        &self,
        ray: &NullRay,
        receiver_s: f64,
        shift: f64,
        budget: Budget,
        spread: Spread,
    ) -> (B, u64) {
        let hit = self.world.closest_hit(ray, 0.0);
        let (mut light, spent) = match hit {
            Some(h) => {
                let (shift_h, k) = self.arriving(receiver_s, h.s, shift);
                let sr = spread.into_frame(h.s);
                let (light, spent) = self.shade(ray, &h, shift_h, budget, sr);
                (light * k, spent)
            }
            None => {
                let mut light = self.background_along(ray.dir, receiver_s, shift);
                if let Some(stars) = self.stars_along(ray.dir, receiver_s, shift, spread) {
                    light.add(&stars);
                }
                (light, 0)
            }
        };
        let way = hit.map_or(f64::INFINITY, |h| h.lambda);
        if let Some(t) = self.fog_over(ray.dir, receiver_s, shift, way) {
            light.mul_by(&t);
        }
        (light, spent)
    }

    /// The stars a ray leaving the scene after a bounce sees, as radiance in its receiver's
    /// frame: those in the cone of the ray's bundle about it (in the sky's frame), each as its
    /// irradiance, carried into the receiver's frame as a point source's (docs/physics.md
    /// §5.5), over the bundle's solid angle there. None where there are none to find.
    pub(super) fn stars_along(
        &self,
        dir: DVec3,
        receiver_s: f64,
        shift: f64,
        spread: Spread,
    ) -> Option<B> {
        let (cones, sky) = (self.cones?, self.sky.as_ref()?);
        if spread.sr.is_nan() || spread.sr <= 0.0 {
            return None;
        }
        let (dir_sky, s_sky) = match &sky.to_sky {
            Some(b) => b.view_dir(dir),
            None => (dir, 1.0),
        };
        let (star_shift, k) = self.seen.irradiance(receiver_s / s_sky, shift);
        let mut sum: Option<B> = None;
        cones.in_cone(dir_sky, spread.into_frame(s_sky), |spectrum, rgb| {
            let v = B::of_spectrum(spectrum, rgb, star_shift);
            match &mut sum {
                Some(s) => s.add(&v),
                None => sum = Some(v),
            }
        });
        sum.map(|s| s * (k / spread.sr))
    }

    /// The background (at rest in the world frame, lookback factor 1) as a receiver with
    /// lookback factor `receiver_s` and wavelengths `shift` times the camera's sees it: the
    /// image's background colour (the same in every direction; see
    /// [`Shader::background_along`] for a sky).
    pub fn background(&self, receiver_s: f64, shift: f64) -> B {
        let (shift, k) = self.arriving(receiver_s, 1.0, shift);
        B::of(&self.scene.image.background, B::at(shift)) * k
    }

    /// The background along world-frame direction `dir` (toward where the light comes from):
    /// the sky's there where the scene has one, its texel a spectrum on the map's basis as an
    /// image texture's is, else the background colour.
    pub fn background_along(&self, dir: DVec3, receiver_s: f64, shift: f64) -> B {
        let Some(sky) = &self.sky else {
            return self.background(receiver_s, shift);
        };
        let Some(map) = &sky.sky.map else {
            return self.background(receiver_s, shift);
        };
        let (dir, sky_s) = match &sky.to_sky {
            Some(b) => b.view_dir(dir),
            None => (dir, 1.0),
        };
        let (shift, k) = self.arriving(receiver_s, sky_s, shift);
        let rgb = sky.sky.rgb(dir).expect("it has a map");
        texel::<B>(map, rgb, B::at(shift)) * k
    }

    /// Radiance from a sender with lookback factor `sender_s` reaching a receiver with
    /// `receiver_s` (both for the ray's world-frame direction; D = ν_receiver / ν_sender is
    /// their ratio): the sender's wavelength shift, and the factor on its radiance.
    pub fn arriving(&self, receiver_s: f64, sender_s: f64, shift: f64) -> (f64, f64) {
        self.seen.radiance(receiver_s / sender_s, shift)
    }

    /// A group's lookback factor for a world-frame direction (1 where no change of frame
    /// alters light, so it need not be computed).
    pub(super) fn lookback_factor(&self, group: usize, dir_w: DVec3) -> f64 {
        if !self.seen.any() {
            return 1.0;
        }
        self.world.groups[group].boost.null_dir(dir_w).1
    }

    /// Spawn a secondary ray at a hit: rest-frame direction `dir`, origin pushed off the
    /// surface by ε along `side` (rest frame), both boosted back to the world frame.
    pub(super) fn spawn(&self, group: usize, hit_event: Event, side: DVec3, dir: DVec3) -> NullRay {
        let (dir_w, _) = self.world.groups[group].boost.inverse().view_dir(dir);
        NullRay::new(self.pushed_off(group, hit_event, side), dir_w)
    }

    /// The world-frame event ε off the surface at a hit, along rest-frame `side`: where a
    /// secondary ray of the hit starts.
    pub(super) fn pushed_off(&self, group: usize, hit_event: Event, side: DVec3) -> Event {
        let g = &self.world.groups[group];
        if g.boost.is_identity() {
            return hit_event + Event::new(0.0, g.epsilon * side);
        }
        hit_event + g.boost.inverse().event(Event::new(0.0, g.epsilon * side))
    }

    /// The light leaving a hit toward the ray's origin, in the surface's frame at wavelengths
    /// `shift` times the camera's: its light from each light not in shadow, and what it
    /// reflects and transmits.
    /// `spread`: the solid angle, in the surface's frame, of the bundle the ray stands for.
    pub fn shade(
        &self,
        ray: &NullRay,
        hit: &SurfaceHit,
        shift: f64,
        budget: Budget,
        spread: f64,
    ) -> (B, u64) {
        self.shade_at(hit, ray.at(hit.lambda), shift, budget, spread)
    }

    /// [`Shader::shade`] of a hit at world event `event`.
    fn shade_at(
        &self,
        hit: &SurfaceHit,
        event: Event,
        shift: f64,
        budget: Budget,
        spread: f64,
    ) -> (B, u64) {
        // On the stack for a few lights: a secondary hit allocates nothing.
        let mut shadows = smallvec::SmallVec::<[Option<ShadowQuery>; 4]>::new();
        let lit = self
            .prepare_at(hit, event, shift, &mut shadows)
            .with_spread(spread);
        self.finish(
            &lit,
            &shadows,
            |light, q| !self.world.shadowed(light, &q.ray, q.tmax),
            budget,
        )
    }

    /// Whether changes of frame alter light (else every receiver's lookback factor may be 1).
    pub fn follows_frames(&self) -> bool {
        self.seen.any()
    }

    /// Whether primary rays that meet nothing add nothing: a transparent image, or a black
    /// background.
    pub fn primary_misses_add_nothing(&self) -> bool {
        let black = self.scene.sky.is_none() && self.scene.image.background.is_black();
        black || self.scene.image.is_transparent()
    }

    /// What the ray tree below a primary hit may spend.
    pub fn primary_budget(&self) -> Budget {
        Budget::primary(self.scene.render.max_rays)
    }

    pub fn light_count(&self) -> usize {
        self.lights.len()
    }

    /// Everything about a hit's shading that does not depend on other rays: the ambient and
    /// emitted light, and (appended to `shadows`, one entry per light, None where the light
    /// cannot reach the surface) each light's contribution and the shadow ray that decides it.
    /// `shift`: the surface frame's wavelengths over the camera's.
    pub fn prepare(
        &self,
        ray: &NullRay,
        hit: &SurfaceHit,
        shift: f64,
        shadows: &mut impl Extend<Option<ShadowQuery>>,
    ) -> Lit<'a> {
        self.prepare_at(hit, ray.at(hit.lambda), shift, shadows)
    }

    /// [`Shader::prepare`] of a hit at world event `event`.
    fn prepare_at(
        &self,
        hit: &SurfaceHit,
        event: Event,
        shift: f64,
        shadows: &mut impl Extend<Option<ShadowQuery>>,
    ) -> Lit<'a> {
        let lit = self.lit_at(hit, event, shift);
        let (g, mat, nf, event, v) = (
            &self.world.groups[hit.group],
            lit.mat,
            lit.nf,
            lit.event,
            lit.v,
        );
        if mat.emission.is_some() || mat.is_invisible() {
            shadows.extend(self.lights.iter().map(|_| None));
            return lit;
        }
        if self.lights.is_empty() {
            return lit;
        }
        let glints = !mat.specular.is_black();
        let from = self.pushed_off(hit.group, event, nf);
        shadows.extend(self.lights.iter().map(|l| {
            let ToLight {
                dir_w,
                k,
                to_light,
                s_surface,
                dist,
                atten,
            } = l.toward(from, event, g, lit.own_frame.as_ref())?;
            let ndl = nf.dot(to_light);
            if ndl <= 0.0 {
                return None;
            }
            let highlight = glints.then(|| {
                let r = reflect(to_light, nf);
                phong(r.dot(-v).max(0.0), mat.shininess)
            });
            // D_in = ν_surface / ν_light: k is ν_world / ν_light, s_surface ν_surface / ν_world.
            let (light_shift, k_in) = self.seen.irradiance(k * s_surface, shift);
            Some(ShadowQuery {
                ray: NullRay::new(from, dir_w),
                tmax: dist * k * (1.0 - 1e-9),
                s: s_surface,
                term: LightTerm {
                    shift: light_shift,
                    atten,
                    ndl,
                    highlight,
                    k: k_in,
                },
            })
        }));
        lit
    }

    /// A hit at world event `event`, seen at wavelengths `shift` times the camera's: its
    /// material, the normal turned toward the ray, and where its textures are read.
    pub(super) fn lit_at(&self, hit: &SurfaceHit, event: Event, shift: f64) -> Lit<'a> {
        let g = &self.world.groups[hit.group];
        let prim = g.geometry.prim(hit.prim);
        let part = g.geometry.part_of(hit.prim);
        let mat = &self.scene.materials[part.material as usize];
        let v = hit.dir / hit.s;
        let n = crate::render::world::surface_normal_of(g, &prim, part, hit, event);
        let inside = n.dot(v) > 0.0;
        let faced = if inside { -n } else { n };
        // A mesh's vertex normals shade it smoothly, turned to the side the ray sees.
        let (smooth, corner_uv) =
            crate::geometry::Geometry::corners_of(part, &prim, hit.prim, hit.point);
        let nf = smooth.map_or(faced, |s| if s.dot(faced) < 0.0 { -s } else { s });
        // Textures are laid out in the object's own coordinates, on its shape before any
        // transform placed it.
        // A spinning body's textures turn with it: read where its point was at time 0.
        let (painted, painted_n) = match &part.spin {
            Some(sp) => {
                let t = g.boost.event(event).t;
                let p = sp.unturned(hit.point, t);
                (p, sp.unturned(sp.centre + n, t) - sp.centre)
            }
            None => (hit.point, n),
        };
        let (point, outward, prim) = match &part.placement {
            Some(pl) => (
                pl.to_object(painted),
                pl.normal_to_object(painted_n),
                pl.shape.unwrap_or(prim),
            ),
            None => (painted, painted_n, prim),
        };
        Lit {
            mat,
            point,
            outward,
            corner_uv,
            prim,
            group: hit.group,
            prim_id: hit.prim,
            reach: hit.s * hit.lambda,
            event,
            v,
            nf,
            n,
            inside,
            shift,
            spread: 0.0,
            own_frame: match &g.accelerated {
                Some(acc) => Some(crate::render::world::point_boost(acc, g.boost.event(event))),
                None => part.spin.and_then(|sp| sp.boost_at(hit.point)),
            },
        }
    }

    /// The colour of a prepared hit, given its shadow rays and `reaches(light, query)`: whether
    /// that light's shadow ray reaches it.
    pub fn finish(
        &self,
        lit: &Lit,
        shadows: &[Option<ShadowQuery>],
        reaches: impl Fn(usize, &ShadowQuery) -> bool,
        budget: Budget,
    ) -> (B, u64) {
        let (mat, at) = (lit.mat, B::at(lit.shift));
        if mat.is_invisible() {
            return self.pass_through(lit, budget);
        }
        if let Some(e) = &mat.emission {
            return (
                surface_colour(e, mat.emission_texture.as_deref(), lit, at),
                0,
            );
        }
        let diffuse = surface_colour(&mat.color, mat.color_texture.as_deref(), lit, at);
        let mut color = B::of(&self.scene.render.ambient, at);
        color.mul_by(&diffuse);
        let specular = (!mat.specular.is_black()).then(|| B::of(&mat.specular, at));
        for (l, q) in shadows.iter().enumerate() {
            let Some(q) = q else {
                continue;
            };
            // Through media the light arrives attenuated; otherwise it arrives or it does not.
            let through = match self.invisible {
                true => match self.transmittance(&q.ray, q.tmax, None, lit.shift, q.s) {
                    Some(t) => Some(t),
                    None => continue,
                },
                false if reaches(l, q) => None,
                false => continue,
            };
            {
                let t = &q.term;
                let mut light = B::of(&self.lights[l].light.radiance, B::at(t.shift));
                if let Some(through) = &through {
                    light.mul_by(through);
                }
                let glint = specular.as_ref().zip(t.highlight);
                color.add_lit(&light, t.atten, &diffuse, t.ndl, glint, t.k);
            }
        }
        let max_depth = self.scene.render.max_depth;
        if budget.depth >= max_depth {
            return (color, 0);
        }
        let (v, nf, event) = (lit.v, lit.nf, lit.event);
        let (mut kr, mut kt) = (mat.reflect, mat.transmit);
        let mut refracted = None;
        if kt > 0.0 {
            let eta = if lit.inside { 1.0 / mat.ior } else { mat.ior };
            let cos_i = (-v.dot(nf)).clamp(0.0, 1.0);
            match refract(-v, nf, eta) {
                Some(t) => {
                    let f = fresnel(cos_i, eta);
                    kr += kt * f;
                    kt *= 1.0 - f;
                    refracted = Some(t.normalize());
                }
                None => {
                    kr += kt;
                    kt = 0.0;
                }
            }
        }
        let refracted = refracted.filter(|_| kt > 0.0);
        let (mut seen_r, mut seen_t) = (None, None);
        let spent = budget.follow(
            max_depth,
            (kr > 0.0).then_some(kr),
            refracted.map(|_| kt),
            |branch, b| {
                let (side, dir, seen) = match branch {
                    Branch::Reflected => (nf, reflect(-v, nf), &mut seen_r),
                    Branch::Refracted => (-nf, refracted.expect("a refracted ray"), &mut seen_t),
                };
                // Into a glass object, light is slower (`inside_hit`) and never changes frame.
                if mat.transmit > 0.0 && dir.dot(lit.n) < 0.0 {
                    if let Some((h, at, d)) = self.inside_hit(lit.group, event, side, dir, mat.ior)
                    {
                        let sr = lit.spread;
                        let (mut light, spent) = self.shade_at(&h, at, lit.shift, b, sr);
                        let material = self.world.groups[lit.group].geometry.part_of(lit.prim_id);
                        if let Some(a) = self.attenuation(material.material, lit.shift, d) {
                            light.mul_by(&a);
                        }
                        *seen = Some(light);
                        return 1 + spent;
                    }
                }
                // A spinning or accelerated point's directions are in its own frame: into the
                // group's first.
                let (dir, spun) = match &lit.own_frame {
                    Some(b) => {
                        let (d, _) = b.inverse().view_dir(dir);
                        (d, b.null_dir(d).1)
                    }
                    None => (dir, 1.0),
                };
                let r = self.spawn(lit.group, event, side, dir);
                let s = self.lookback_factor(lit.group, r.dir) * spun;
                // The bundle keeps its solid angle in the surface's frame (a flat surface).
                let spread = match self.cones {
                    Some(_) if lit.spread > 0.0 => Spread {
                        sr: lit.spread,
                        s: self.world.groups[lit.group].boost.null_dir(r.dir).1 * spun,
                    },
                    _ => Spread::NONE,
                };
                let (light, spent) = self.trace(&r, s, lit.shift, b, spread);
                *seen = Some(light);
                1 + spent
            },
        );
        // Added in this order whichever was traced first (the sum is the same to the bit).
        if let Some(light) = seen_r {
            color.add(&(light * kr));
        }
        if let Some(light) = seen_t {
            color.add(&(light * kt));
        }
        (color, spent)
    }
}

/// A material's colour at a hit, or its texture's there, in the band. An image's RGB becomes a
/// spectrum on its basis (`ImageTexture`): in RGB the texel itself.
pub(super) fn surface_colour<B: Band>(
    colour: &crate::spectrum::Colour,
    texture: Option<&crate::scene::Texture>,
    lit: &Lit,
    at: B::At,
) -> B {
    use crate::scene::TextureSample as S;
    match texture.map(|t| t.at(&lit.prim, lit.point, lit.outward, lit.corner_uv)) {
        None => B::of(colour, at),
        Some(S::Colour(c)) => B::of(c, at),
        Some(S::Rgb(rgb, img)) => texel(img, rgb, at),
    }
}

/// An image's linear RGB as light in the band: on its basis (`ImageTexture`), in RGB itself.
fn texel<B: Band>(img: &crate::scene::ImageTexture, rgb: DVec3, at: B::At) -> B {
    let c = if B::SPECTRAL { img.to_basis * rgb } else { rgb };
    let mut out = B::of(&img.basis[0], at) * c.x;
    out.add(&(B::of(&img.basis[1], at) * c.y));
    out.add(&(B::of(&img.basis[2], at) * c.z));
    out
}

/// A shadow ray to one light, and what decides the light it brings if nothing is in the way.
pub struct ShadowQuery {
    pub ray: NullRay,
    pub tmax: f64,
    /// The surface frame's lookback factor for the ray (ν_surface / ν_world).
    s: f64,
    term: LightTerm,
}

/// A light's term at a hit, but for the spectra (evaluated only if the light is seen):
/// `light(shift) · atten · (diffuse · ndl + specular · highlight) · k`.
struct LightTerm {
    /// The light's wavelengths over the camera's.
    shift: f64,
    atten: f64,
    ndl: f64,
    highlight: Option<f64>,
    /// What the change of frame from the light's to the surface's does to its irradiance.
    k: f64,
}

/// A hit prepared for shading: see [`Shader::prepare`].
pub struct Lit<'a> {
    pub(super) mat: &'a crate::scene::Material,
    /// The hit in its object's own coordinates (its group's rest frame, undone by the
    /// object's transform, if it has one; textures are laid out there), and the surface's
    /// outward normal there.
    point: DVec3,
    outward: DVec3,
    /// The primitive hit as the object was before its transform (where an image is mapped
    /// from), and a mesh's texture coordinates there.
    prim: crate::geometry::Primitive,
    corner_uv: Option<[f64; 2]>,
    pub(super) group: usize,
    /// The primitive hit (its index in its group).
    pub(super) prim_id: u32,
    /// How far the ray came to the hit in the surface's frame (0 for a ray inside an object,
    /// whose way the caller accounts for).
    pub(super) reach: f64,
    pub(super) event: Event,
    pub(super) v: DVec3,
    pub(super) nf: DVec3,
    /// The surface's outward normal (rest frame).
    pub(super) n: DVec3,
    pub(super) inside: bool,
    /// The surface frame's wavelengths over the camera's.
    pub(super) shift: f64,
    /// The solid angle, in the surface's frame, of the bundle the ray that hit stands for (0:
    /// none is followed).
    spread: f64,
    /// Where the point moves in its group's frame (a spinning object, a group on an
    /// accelerated segment): the boost from the group's frame into the point's own, where it
    /// is shaded (its hit's direction and factor are there already, `World::spun`,
    /// `World::surface_hit`).
    pub(super) own_frame: Option<Boost>,
}

impl Lit<'_> {
    /// The hit, its ray standing for a bundle of solid angle `sr` in the surface's frame.
    pub fn with_spread(mut self, sr: f64) -> Self {
        self.spread = sr;
        self
    }
}

/// The bundle of rays a ray stands for (a pixel's, carried along): its solid angle in its
/// receiver's frame, and the receiver's lookback factor for its direction (whatever the
/// switches say: solid angles follow the geometry).
#[derive(Clone, Copy, Debug)]
pub struct Spread {
    pub sr: f64,
    pub s: f64,
}

impl Spread {
    /// No bundle followed.
    pub const NONE: Spread = Spread { sr: 0.0, s: 1.0 };

    /// Its solid angle in a frame whose lookback factor for its direction is `s_to`: solid
    /// angles scale as the inverse square of frequency, Ω_to = Ω (ν_from / ν_to)²
    /// (docs/physics.md §5.5).
    pub fn into_frame(self, s_to: f64) -> f64 {
        self.sr * (self.s / s_to).powi(2)
    }
}
