//! The path integrator over a round of a tile's paths at once (a wavefront): every path
//! advances a bounce, then the next, the paths' state kept in arrays in the worker's scratch.
//! At each bounce a path's leg is followed to what it reaches (`walk`), and what it reaches
//! is shaded: the sky, a point in a medium, or a surface. A surface is resolved once
//! (`meet_surface`: its material, normal, colours and lobes); the commonest kind, a Lambert
//! surface in a frame at rest in the world frame, then goes to the lanes (`lanes.rs`), which
//! draw the next direction and next-event estimation's point on a glowing sphere for all
//! such vertices of the bounce at once, and their shadow rays are traced together; every
//! other surface is shaded on its own (`scatter_surface`). The paths that end leave the
//! arrays of the next bounce, so its lanes are full again (docs/architecture.md, "The path
//! integrator's lanes").
//!
//! Each path keeps its own random numbers and draws them in the same order as alone, and each
//! lane's arithmetic is the scalar code's, so the picture is the same whether the lanes run
//! in vector registers, one by one, or not at all (`WorldOptions::lanes`).

use super::bsdf::{Basis, Lobes};
use super::lanes::{DiffuseIn, DiffuseLanes};
use super::nee::Gather;
use super::{Came, Leg, Path, PathTracer, Reached};
use crate::geometry::Primitive;
use crate::render::band::Band;
use crate::render::shade::Spread;
use crate::render::world::SurfaceHit;
use crate::rng::Rng;
use crate::spacetime::{Event, NullRay};
use glam::DVec3;

/// Where a path starts: a camera ray that met `hit`, the camera's lookback factor for it (as
/// the switches have it), the bundle it stands for and its random numbers.
pub(crate) struct Start {
    pub ray: NullRay,
    pub hit: SurfaceHit,
    pub camera_s: f64,
    pub spread: Spread,
    pub rng: Rng,
}

/// A diffuse vertex in the lanes: what the scalar code needs after them, beside the lanes'
/// own columns (`DiffuseLanes`).
struct Queued<B> {
    /// The path's slot.
    slot: u32,
    group: usize,
    event: Event,
    /// The frame's wavelengths over the camera's.
    shift: f64,
    within: Option<(usize, u32)>,
    diffuse: B,
    /// The glowing sphere drawn for next-event estimation (group, primitive, probability) and
    /// the numbers of the point on it, where the lanes draw it.
    emitter: Option<((usize, u32, f64), [f64; 3])>,
}

impl<B> Queued<B> {
    /// Where next-event estimation gathers light for it (its shading normal `nf`).
    fn gather(&self, nf: DVec3) -> Gather {
        Gather {
            group: self.group,
            event: self.event,
            shift: self.shift,
            nf: Some(nf),
            within: self.within,
        }
    }
}

/// A Lambert vertex as the lanes need it: its group and event, the shading normal toward the
/// viewer and the direction the path looked along, the frame's wavelengths over the camera's,
/// and its colour in that frame.
struct Lambert<B> {
    group: usize,
    event: Event,
    nf: DVec3,
    v: DVec3,
    shift: f64,
    diffuse: B,
}

/// What [`PathTracer::plain_lambert`] found.
enum Plain<B> {
    /// Not a plain Lambert surface (resolve it whole).
    No,
    /// A plain Lambert surface where the path ends (past the last bounce, or black).
    Ends,
    Lambert(Lambert<B>),
}

/// The light a shadow ray brings if nothing is in its way.
struct Shadow<B> {
    slot: u32,
    ray: NullRay,
    tmax: f64,
    light: B,
}

/// What a round's paths keep from bounce to bounce, refilled round after round and tile after
/// tile by the worker (so a bounce allocates nothing once they have grown).
pub(crate) struct WaveScratch<B> {
    paths: Vec<Path<B>>,
    rngs: Vec<Rng>,
    outs: Vec<B>,
    legs: Vec<Leg>,
    /// The camera rays' hits, each path's first.
    first: Vec<SurfaceHit>,
    active: Vec<u32>,
    next: Vec<u32>,
    lanes: DiffuseLanes,
    queued: Vec<Queued<B>>,
    shadows: Vec<Shadow<B>>,
    rays: Vec<NullRay>,
    hits: Vec<Option<SurfaceHit>>,
    tmax: Vec<f64>,
    blocked: Vec<bool>,
}

impl<B> Default for WaveScratch<B> {
    fn default() -> Self {
        Self {
            paths: Vec::new(),
            rngs: Vec::new(),
            outs: Vec::new(),
            legs: Vec::new(),
            first: Vec::new(),
            active: Vec::new(),
            next: Vec::new(),
            lanes: DiffuseLanes::default(),
            queued: Vec::new(),
            shadows: Vec::new(),
            rays: Vec::new(),
            hits: Vec::new(),
            tmax: Vec::new(),
            blocked: Vec::new(),
        }
    }
}

impl<B: Band> WaveScratch<B> {
    /// The light each path of the last round brought to the camera, in the order of its starts.
    pub fn light(&self) -> &[B] {
        &self.outs
    }
}

impl<'a, B: Band> PathTracer<'_, 'a, B> {
    /// Follow a path from each start to its end, all together bounce by bounce; their light is
    /// then in `w.light()`, at the camera's wavelengths.
    pub(crate) fn trace_paths(&self, starts: impl Iterator<Item = Start>, w: &mut WaveScratch<B>) {
        w.paths.clear();
        w.rngs.clear();
        w.outs.clear();
        w.legs.clear();
        w.first.clear();
        w.active.clear();
        for (k, st) in starts.enumerate() {
            w.paths.push(Path {
                beta: B::splat(1.0),
                shift: 1.0,
                came: None,
                spread: st.spread,
            });
            w.rngs.push(st.rng);
            w.outs.push(B::splat(0.0));
            w.legs.push(Leg::Null {
                ray: st.ray,
                receiver_s: st.camera_s,
                within: None,
            });
            w.first.push(st.hit);
            w.active.push(k as u32);
        }
        for depth in 0.. {
            if w.active.is_empty() {
                break;
            }
            self.bounce(depth, w);
            std::mem::swap(&mut w.active, &mut w.next);
        }
    }

    /// Every active path's next leg followed and shaded; the paths that go on, with their next
    /// legs, into `w.next`.
    fn bounce(&self, depth: u32, w: &mut WaveScratch<B>) {
        w.next.clear();
        w.lanes.clear();
        w.queued.clear();
        // The plain legs' closest hits, traced together (the camera rays' are known).
        w.rays.clear();
        if depth > 0 {
            for &slot in &w.active {
                let leg = &w.legs[slot as usize];
                if let (Leg::Null { ray, .. }, true) = (leg, self.is_plain(leg)) {
                    w.rays.push(*ray);
                }
            }
        }
        // Every entry is written by the trace: the ones kept from the last bounce are not
        // cleared first.
        w.hits.truncate(w.rays.len());
        w.hits.resize(w.rays.len(), None);
        self.shader
            .world
            .closest_hits_scattered(&w.rays, &mut w.hits);
        let mut traced = w.hits.iter();
        for &slot in &w.active {
            let k = slot as usize;
            let (path, rng, out) = (&mut w.paths[k], &mut w.rngs[k], &mut w.outs[k]);
            let first = (depth == 0).then(|| w.first[k]);
            let lanes = (&mut w.lanes, &mut w.queued);
            let next = match &w.legs[k] {
                // A plain leg reaches its closest hit (`reach`, without a `Reached` made).
                &Leg::Null {
                    ray, receiver_s, ..
                } if self.is_plain(&w.legs[k]) => {
                    let hit = match first {
                        Some(h) => Some(h),
                        None => *traced.next().expect("a hit per plain leg"),
                    };
                    match hit {
                        None => {
                            out.add(&self.sky_light(ray.dir, receiver_s, path));
                            None
                        }
                        Some(h) => {
                            let (shift_h, k) = self.shader.arriving(receiver_s, h.s, path.shift);
                            path.beta = path.beta * k;
                            path.shift = shift_h;
                            let event = ray.at(h.lambda);
                            let at = (path, rng, out);
                            self.surface_in_wave(&h, event, None, depth, slot, at, lanes)
                        }
                    }
                }
                leg => {
                    let reached = match *leg {
                        Leg::Null {
                            ray,
                            receiver_s,
                            within,
                        } => self.walk(&ray, receiver_s, within, first, path, rng),
                        Leg::Slow(inside) => self.walk_inside(&inside, path, rng),
                    };
                    match reached {
                        Reached::Sky { dir, receiver_s } => {
                            out.add(&self.sky_light(dir, receiver_s, path));
                            None
                        }
                        Reached::Surface { hit, event, within } => {
                            let at = (path, rng, out);
                            self.surface_in_wave(&hit, event, within, depth, slot, at, lanes)
                        }
                        Reached::Scatter(at) => self.in_medium(&at, depth, path, rng, out),
                        Reached::Lost => None,
                    }
                }
            };
            if let Some(leg) = next {
                w.legs[k] = leg;
                w.next.push(slot);
            }
        }
        if w.lanes.len() > 0 {
            self.finish_lanes(depth, w);
        }
    }

    /// A surface met at a bounce: resolved, and either queued for the lanes (a Lambert surface
    /// at rest in the world frame, its random numbers drawn now in the order the scalar path
    /// draws them) or shaded here. The next leg, where it is decided here.
    #[allow(clippy::too_many_arguments)]
    fn surface_in_wave(
        &self,
        hit: &SurfaceHit,
        event: Event,
        within: Option<(usize, u32)>,
        depth: u32,
        slot: u32,
        (path, rng, out): (&mut Path<B>, &mut Rng, &mut B),
        lanes: (&mut DiffuseLanes, &mut Vec<Queued<B>>),
    ) -> Option<Leg> {
        let v = match self.plain_lambert(hit, event, depth, path) {
            Plain::Ends => return None,
            Plain::Lambert(v) => v,
            Plain::No => {
                let s = self.meet_surface(hit, event, depth, path, out)?;
                let sh = self.shader;
                let identity = sh.world.groups[s.lit.group].boost.is_identity();
                if !(self.lanes && s.lobes.lambert_only() && identity && !sh.has_invisible()) {
                    return self.scatter_surface(&s, hit, within, depth, path, rng, out);
                }
                let lit = &s.lit;
                Lambert {
                    group: lit.group,
                    event: lit.event,
                    nf: lit.nf,
                    v: lit.v,
                    shift: lit.shift,
                    diffuse: s.lobes.diffuse(),
                }
            }
        };
        self.queue_lambert(&v, within, slot, (path, rng, out), lanes);
        None
    }

    /// A surface met at a bounce as the lanes take it, resolved without the rest of the hit
    /// where that is all there is to it: a material of one Lambert lobe and no texture, on a
    /// part without corner data or spin, in a group at rest in the world frame, in a scene
    /// without media. The same numbers as `meet_surface` (the normal turned to the viewer,
    /// the colour in the frame's band).
    fn plain_lambert(
        &self,
        hit: &SurfaceHit,
        event: Event,
        depth: u32,
        path: &Path<B>,
    ) -> Plain<B> {
        let sh = self.shader;
        let g = &sh.world.groups[hit.group];
        if !self.lanes || !g.boost.is_identity() || sh.has_invisible() {
            return Plain::No;
        }
        let part = g.part_of(hit.prim);
        if !self.plain[part.material as usize] || part.corners.is_some() || part.spin.is_some() {
            return Plain::No;
        }
        // Past the last bounce a vertex only says what light it sends: none.
        if depth > self.max_depth {
            return Plain::Ends;
        }
        let mat = &sh.scene.materials[part.material as usize];
        let diffuse = B::of(&mat.color, B::at(path.shift));
        // Black (or NaN) scatters nothing, as `Lobes::is_black` says.
        if diffuse.max_value().max(0.0) <= 0.0 {
            return Plain::Ends;
        }
        let n = g.with_prim(hit.prim, |p| p.normal(hit.point));
        // hit.s is 1 in a frame at rest, where x / 1 is x.
        let v = if hit.s == 1.0 {
            hit.dir
        } else {
            hit.dir / hit.s
        };
        let nf = if n.dot(v) > 0.0 { -n } else { n };
        Plain::Lambert(Lambert {
            group: hit.group,
            event,
            nf,
            v,
            shift: path.shift,
            diffuse,
        })
    }

    /// A Lambert vertex into the lanes: the point lights it gathers (here), its draws, and what
    /// the scalar code needs after the lanes.
    fn queue_lambert(
        &self,
        l: &Lambert<B>,
        within: Option<(usize, u32)>,
        slot: u32,
        (path, rng, out): (&mut Path<B>, &mut Rng, &mut B),
        (lanes, queued): (&mut DiffuseLanes, &mut Vec<Queued<B>>),
    ) {
        let sh = self.shader;
        let here = Gather {
            group: l.group,
            event: l.event,
            shift: l.shift,
            nf: Some(l.nf),
            within,
        };
        // What the surface scatters toward a light, for the lights the lanes do not take.
        let scatter = |wi: DVec3| {
            let basis = Basis::new(l.nf);
            let w = basis.to_local(wi);
            let (f, pdf) = Lobes::lambert(l.diffuse).eval(basis.to_local(-l.v), w);
            (f * w.z.abs(), pdf)
        };
        if !sh.lights.is_empty() {
            self.point_lights(&here, &scatter, &path.beta, out);
        }
        // Next-event estimation's draws (`emitter_light`): a glowing sphere at rest goes to
        // the lanes; any other emitter is done here.
        let mut emitter = None;
        let mut sphere = (DVec3::ZERO, 0.0, 0.0);
        if let Some(pick) = self.emitters.pick(rng.f()) {
            let u = [rng.f(), rng.f(), rng.f()];
            match self.sphere_in_lanes(pick) {
                Some((center, radius)) => {
                    emitter = Some((pick, u));
                    sphere = (center, radius, pick.2);
                }
                None => self.emitter_light_drawn(&here, &scatter, &path.beta, pick, u, out),
            }
        }
        // The BSDF's draw: four numbers, of which a Lambert surface uses the second and third.
        let u = [rng.f(), rng.f(), rng.f(), rng.f()];
        let ue = emitter.map_or([0.0; 3], |(_, u)| u);
        lanes.push(&DiffuseIn {
            nf: l.nf,
            v: l.v,
            x: l.event.x,
            epsilon: sh.world.groups[l.group].epsilon,
            u: [u[1], u[2]],
            sphere: (sphere.0, sphere.1),
            p_pick: sphere.2,
            ue: [ue[0], ue[1]],
        });
        queued.push(Queued {
            slot,
            group: l.group,
            event: l.event,
            shift: l.shift,
            within,
            diffuse: l.diffuse,
            emitter,
        });
    }

    /// The centre and radius of the emitter `pick` where the lanes can draw a point on it: a
    /// sphere, in a frame at rest in the world frame, seen at every time (whether the vertex
    /// is outside it, the lanes find).
    fn sphere_in_lanes(&self, (eg, prim, _): (usize, u32, f64)) -> Option<(DVec3, f64)> {
        let ge = &self.shader.world.groups[eg];
        if !ge.boost.is_identity() || ge.window.is_some() {
            return None;
        }
        ge.with_prim(prim, |p| match *p {
            Primitive::Sphere { center, radius } => Some((center, radius)),
            _ => None,
        })
    }

    /// The lanes of a bounce run, their shadow rays traced together, and each of their paths
    /// given its light and its next leg (what `emitter_light_drawn` and `scatter_surface` do
    /// for the vertices the lanes took).
    fn finish_lanes(&self, depth: u32, w: &mut WaveScratch<B>) {
        let sh = self.shader;
        w.lanes.run(self.simd);
        w.shadows.clear();
        let lanes = &w.lanes;
        // Next-event estimation, before the BSDF's draw changes the paths' throughput.
        for (i, q) in w.queued.iter().enumerate() {
            let o = lanes.out(i);
            let Some((pick, u)) = q.emitter else {
                continue;
            };
            let k = q.slot as usize;
            let beta = &w.paths[k].beta;
            if !o.coned {
                // The vertex or the shadow ray's start is inside the sphere: no cone to draw
                // from or to weigh the draw by; alone, from the same numbers.
                let lobes = Lobes::lambert(q.diffuse);
                let (nf, v) = lanes.normal_and_look(i);
                let basis = Basis::new(nf);
                let wo = basis.to_local(-v);
                let scatter = |wi: DVec3| {
                    let l = basis.to_local(wi);
                    let (f, pdf) = lobes.eval(wo, l);
                    (f * l.z.abs(), pdf)
                };
                let here = q.gather(nf);
                let out = &mut w.outs[k];
                self.emitter_light_drawn(&here, &scatter, beta, pick, u, out);
                continue;
            }
            if !o.lit {
                continue;
            }
            let f = Lobes::lambert_f(&q.diffuse, o.cos);
            if f.max_value() <= 0.0 {
                continue;
            }
            // Both frames are the world's: no shift, no factor (D = 1).
            let (shift_e, k_e) = sh.seen.radiance(1.0, q.shift);
            let (eg, prim, _) = pick;
            let (look, point) = (o.look, o.point);
            let Some(mut c) = self.emitted((eg, prim), point, look, q.event, shift_e) else {
                continue;
            };
            c.mul_by(&f);
            c.mul_by(beta);
            w.shadows.push(Shadow {
                slot: q.slot,
                ray: NullRay::new(Event::new(q.event.t, o.from), look),
                tmax: o.tmax,
                light: c * (k_e * o.factor),
            });
        }
        self.trace_shadows(w);
        // The BSDF's draw, roulette and the next leg.
        let lanes = &w.lanes;
        for (i, q) in w.queued.iter().enumerate() {
            let o = lanes.out(i);
            if !o.drawn {
                continue;
            }
            let k = q.slot as usize;
            let path = &mut w.paths[k];
            path.beta.mul_by(&Lobes::lambert_f(&q.diffuse, o.weight));
            if self.roulette(depth, path, &mut w.rngs[k]).is_none() {
                continue;
            }
            // `leg_after` in a frame at rest: the ray starts ε off the surface, its direction
            // and lookback factors the world frame's; a diffuse bounce keeps no bundle.
            let origin = Event::new(q.event.t + 0.0, o.next);
            path.came = Some(Came {
                pdf: o.pdf,
                from: origin,
                s: 1.0,
            });
            path.spread = Spread { sr: 0.0, s: 1.0 };
            w.legs[k] = Leg::Null {
                ray: NullRay::new(origin, o.wi),
                receiver_s: 1.0,
                within: q.within,
            };
            w.next.push(q.slot);
        }
    }

    /// The shadow rays of a bounce's lanes: those that reach their light add it to their paths.
    fn trace_shadows(&self, w: &mut WaveScratch<B>) {
        w.rays.clear();
        w.tmax.clear();
        w.rays.extend(w.shadows.iter().map(|s| s.ray));
        w.tmax.extend(w.shadows.iter().map(|s| s.tmax));
        w.blocked.clear();
        w.blocked.resize(w.rays.len(), false);
        self.shader
            .world
            .occluded_scattered(&w.rays, &w.tmax, &mut w.blocked);
        for (s, &b) in w.shadows.iter().zip(&w.blocked) {
            if !b {
                w.outs[s.slot as usize].add(&s.light);
            }
        }
    }
}
