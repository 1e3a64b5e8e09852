//! Whitted shading in the rest frame of the surface hit: Phong with shadow rays to point lights
//! on their own worldlines, mirror reflection, and refraction with Fresnel. Every secondary ray
//! is again a past-directed null ray, spawned in the surface's frame and boosted back.

use super::camera::CameraRays;
use super::frame::PixelValue;
use super::sampler::sample_offset;
use super::world::{SurfaceHit, World};
use super::TILE;
use crate::scene::{Light, Scene};
use crate::spacetime::{Boost, Event, NullRay};
use glam::DVec3;

pub struct TilePixel {
    pub x: u32,
    pub y: u32,
    pub value: PixelValue,
}

pub struct TileResult {
    pub pixels: Vec<TilePixel>,
    pub primary_rays: u64,
    pub nonfinite: u64,
}

pub fn render_tile(scene: &Scene, world: &World, cam: &CameraRays, x0: u32, y0: u32) -> TileResult {
    let (w, h) = (scene.image.width, scene.image.height);
    let xs = x0..(x0 + TILE).min(w);
    let ys = y0..(y0 + TILE).min(h);
    let coords: Vec<(u32, u32)> = ys.flat_map(|y| xs.clone().map(move |x| (x, y))).collect();
    let n = scene.image.samples;
    let shader = Shader::new(scene, world);
    let mut sum = vec![DVec3::ZERO; coords.len()];
    let mut covered = vec![0u32; coords.len()];
    let mut aov: Vec<Option<(NullRay, SurfaceHit)>> = vec![None; coords.len()];
    let mut rays = Vec::with_capacity(coords.len());
    let mut hits = vec![None; coords.len()];
    let mut primary = 0u64;
    // With one sample the pixel centre serves both colour and passes; with more, an extra
    // centre ray gives crisp passes (ids, lookback) that compositors expect.
    let aov_pass = n > 1;
    let aov_sample = if aov_pass { n } else { 0 };
    for s in 0..n + u32::from(aov_pass) {
        let centre = s == n;
        rays.clear();
        for &(x, y) in &coords {
            let (ox, oy) = if centre {
                (0.5, 0.5)
            } else {
                sample_offset(x, y, s, n)
            };
            rays.push(cam.ray(x as f64 + ox, y as f64 + oy));
        }
        primary += rays.len() as u64;
        world.closest_hits(&rays, 0.0, &mut hits);
        for (k, (r, hit)) in rays.iter().zip(&hits).enumerate() {
            if !centre {
                sum[k] += match hit {
                    Some(hh) => {
                        covered[k] += 1;
                        shader.shade(r, hh, 0)
                    }
                    None => scene.image.background,
                };
            }
            if s == aov_sample {
                aov[k] = hit.map(|hh| (*r, hh));
            }
        }
    }
    let mut nonfinite = 0;
    let pixels = coords
        .iter()
        .enumerate()
        .map(|(k, &(x, y))| {
            let mut c = sum[k] / n as f64;
            if !c.is_finite() {
                nonfinite += 1;
                c = DVec3::ZERO;
            }
            let mut value = PixelValue {
                color: [c.x as f32, c.y as f32, c.z as f32],
                alpha: covered[k] as f32 / n as f32,
                ..Default::default()
            };
            if let Some((r, hit)) = aov[k] {
                let g = &scene.groups[hit.group];
                let prim = &g.geometry.prims[hit.prim as usize];
                let nrm = prim.normal(hit.point);
                value.lookback = hit.lambda as f32;
                value.doppler = (cam.lookback_factor(r.dir) / hit.s) as f32;
                value.object_id = g.geometry.part_of(hit.prim).object + 1;
                value.normal = [nrm.x as f32, nrm.y as f32, nrm.z as f32];
            }
            TilePixel { x, y, value }
        })
        .collect();
    TileResult {
        pixels,
        primary_rays: primary,
        nonfinite,
    }
}

struct LightRt<'a> {
    light: &'a Light,
    to_light: Boost,
    from_light: Boost,
}

pub struct Shader<'a> {
    scene: &'a Scene,
    world: &'a World,
    lights: Vec<LightRt<'a>>,
}

fn reflect(v: DVec3, n: DVec3) -> DVec3 {
    v - 2.0 * v.dot(n) * n
}

/// Unpolarised Fresnel reflectance for a ray with cos_i going from index n1 into n2, and the
/// refracted direction, or None on total internal reflection.
fn fresnel_refract(v: DVec3, n: DVec3, eta: f64) -> (f64, Option<DVec3>) {
    let cos_i = (-v.dot(n)).clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return (1.0, None);
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let t = (eta * v + (eta * cos_i - cos_t) * n).normalize();
    (0.5 * (rs * rs + rp * rp), Some(t))
}

impl<'a> Shader<'a> {
    pub fn new(scene: &'a Scene, world: &'a World) -> Self {
        let lights = scene
            .lights
            .iter()
            .map(|l| LightRt {
                light: l,
                to_light: Boost::to_rest(&l.velocity),
                from_light: Boost::from_rest(&l.velocity),
            })
            .collect();
        Self {
            scene,
            world,
            lights,
        }
    }

    /// The colour arriving along a world-frame null ray.
    fn trace(&self, ray: &NullRay, depth: u32) -> DVec3 {
        match self.world.closest_hit(ray, 0.0) {
            Some(h) => self.shade(ray, &h, depth),
            None => self.scene.image.background,
        }
    }

    /// Spawn a secondary ray at a hit: rest-frame direction `dir`, origin pushed off the
    /// surface by ε along `side` (rest frame), both boosted back to the world frame.
    fn spawn(&self, group: usize, hit_event: Event, side: DVec3, dir: DVec3) -> NullRay {
        let g = &self.world.groups[group];
        let offset = g.unboost.event(Event::new(0.0, g.epsilon * side));
        let (dir_w, _) = g.unboost.view_dir(dir);
        NullRay::new(hit_event + offset, dir_w)
    }

    pub fn shade(&self, ray: &NullRay, hit: &SurfaceHit, depth: u32) -> DVec3 {
        let scene = self.scene;
        let group = &scene.groups[hit.group];
        let g = &self.world.groups[hit.group];
        let prim = &group.geometry.prims[hit.prim as usize];
        let mat = &scene.materials[group.geometry.part_of(hit.prim).material as usize];
        if let Some(e) = mat.emission {
            return e;
        }
        let v = hit.dir / hit.s;
        let n = prim.normal(hit.point);
        let inside = n.dot(v) > 0.0;
        let nf = if inside { -n } else { n };
        let event = ray.at(hit.lambda);
        let mut color = scene.render.ambient * mat.color;
        for l in &self.lights {
            let from = self.spawn(hit.group, event, nf, nf).origin;
            // The emission event on the light's worldline that lies on `from`'s past light
            // cone, found in the light's rest frame, where the light is static.
            let at_light = l.to_light.event(from);
            let delta = l.light.position - at_light.x;
            let dist = delta.length();
            if dist == 0.0 {
                continue;
            }
            let (dir_w, k) = l.from_light.view_dir(delta / dist);
            let to_light = g.boost.view_dir(dir_w).0;
            let ndl = nf.dot(to_light);
            if ndl <= 0.0 {
                continue;
            }
            let shadow = NullRay::new(from, dir_w);
            if self.world.occluded(&shadow, 0.0, dist * k * (1.0 - 1e-9)) {
                continue;
            }
            let atten = if l.light.inverse_square {
                1.0 / (dist * dist)
            } else {
                1.0
            };
            let mut term = mat.color * ndl;
            if mat.specular != DVec3::ZERO {
                let r = reflect(-to_light, nf);
                term += mat.specular * r.dot(-v).max(0.0).powf(mat.shininess);
            }
            color += l.light.radiance * atten * term;
        }
        if depth >= scene.render.max_depth {
            return color;
        }
        let (mut kr, mut kt) = (mat.reflect, mat.transmit);
        let mut refracted = None;
        if kt > 0.0 {
            let eta = if inside { mat.ior } else { 1.0 / mat.ior };
            let (f, t) = fresnel_refract(v, nf, eta);
            match t {
                Some(t) => {
                    kr += kt * f;
                    kt *= 1.0 - f;
                    refracted = Some(t);
                }
                None => {
                    kr += kt;
                    kt = 0.0;
                }
            }
        }
        if kr > 0.0 {
            let r = self.spawn(hit.group, event, nf, reflect(v, nf));
            color += kr * self.trace(&r, depth + 1);
        }
        if let (Some(t), true) = (refracted, kt > 0.0) {
            let r = self.spawn(hit.group, event, -nf, t);
            color += kt * self.trace(&r, depth + 1);
        }
        color
    }
}
