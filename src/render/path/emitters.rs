//! Glowing objects as lights: every primitive whose material has `emission`, listed with the
//! probability of being chosen for next-event estimation (its area times its brightest
//! emitted value, in its rest frame), and how a point on it is drawn as seen from a receiver,
//! with the density of that draw per solid angle in the emitter's rest frame.

use super::draws::{sincos_turn, sphere_cone, sphere_point};
use crate::geometry::Primitive;
use crate::render::world::World;
use crate::scene::Scene;
use glam::DVec3;
use std::f64::consts::PI;

/// Parts of more emitting primitives than this (a glowing lattice of 10⁹ nodes) are not
/// listed: paths that meet them still see their light, by the BSDF's draws alone.
pub(crate) const MAX_LISTED: u64 = 1 << 22;

/// Every listed emitting primitive and how it is chosen.
#[derive(Default)]
pub struct Emitters {
    /// (world group, primitive) of each.
    items: Vec<(u32, u32)>,
    /// The cumulative probabilities of choosing them (the last is 1).
    cdf: Vec<f64>,
    /// Per world group, its listed runs: (first primitive, end, index of the first in `items`).
    runs: Vec<Vec<(u32, u32, u32)>>,
    /// Per world group, the material of each of its listed runs (as `runs`).
    materials: Vec<Vec<u32>>,
}

/// A point drawn on an emitter, in its rest frame.
pub struct EmitterPoint {
    pub point: DVec3,
}

impl Emitters {
    /// The emitters of the world's groups.
    pub fn new(scene: &Scene, world: &World) -> Emitters {
        let mut e = Emitters {
            runs: vec![Vec::new(); world.groups.len()],
            materials: vec![Vec::new(); world.groups.len()],
            ..Default::default()
        };
        let mut weights = Vec::new();
        for (gi, g) in world.groups.iter().enumerate() {
            for part in &g.geometry.parts {
                let mat = &scene.materials[part.material as usize];
                let Some(emission) = &mat.emission else {
                    continue;
                };
                let n = u64::from(part.end - part.start);
                if n == 0 || (e.items.len() as u64).saturating_add(n) > MAX_LISTED {
                    continue;
                }
                let bright = emission.rgb.max_element().max(0.0);
                if bright == 0.0 && mat.emission_texture.is_none() {
                    continue;
                }
                // A texture's brightness varies: its first colour stands for it.
                let bright = if bright > 0.0 { bright } else { 1.0 };
                e.runs[gi].push((part.start, part.end, e.items.len() as u32));
                e.materials[gi].push(part.material);
                for p in part.start..part.end {
                    e.items.push((gi as u32, p));
                    weights.push(area(&g.geometry.prim(p)) * bright);
                }
            }
        }
        let total: f64 = weights.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return Emitters::default();
        }
        let mut acc = 0.0;
        e.cdf = weights
            .iter()
            .map(|w| {
                acc += w / total;
                acc
            })
            .collect();
        if let Some(last) = e.cdf.last_mut() {
            *last = 1.0;
        }
        e
    }

    /// An emitter chosen by `u` in [0, 1): its group, primitive and probability.
    pub fn pick(&self, u: f64) -> Option<(usize, u32, f64)> {
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len().checked_sub(1)?);
        let (g, p) = self.items[i];
        Some((g as usize, p, self.prob(i)))
    }

    fn prob(&self, i: usize) -> f64 {
        self.cdf[i] - if i == 0 { 0.0 } else { self.cdf[i - 1] }
    }

    /// The material of listed emitter `prim` of group `group` (as [`Emitters::pick`] gives
    /// them).
    pub fn material_of(&self, group: usize, prim: u32) -> u32 {
        let runs = &self.runs[group];
        let i = runs.partition_point(|r| r.1 <= prim);
        self.materials[group][i]
    }

    /// The probability that [`Emitters::pick`] chooses primitive `prim` of group `group` (0
    /// where it is not listed).
    pub fn prob_of(&self, group: usize, prim: u32) -> f64 {
        let Some(runs) = self.runs.get(group) else {
            return 0.0;
        };
        let i = runs.partition_point(|r| r.1 <= prim);
        match runs.get(i) {
            Some(&(start, end, first)) if start <= prim && prim < end => {
                self.prob((first + prim - start) as usize)
            }
            _ => 0.0,
        }
    }
}

/// The surface area of a primitive.
pub fn area(p: &Primitive) -> f64 {
    match *p {
        Primitive::Sphere { radius, .. } => 4.0 * PI * radius * radius,
        Primitive::Capsule { a, b, radius } => {
            2.0 * PI * radius * (b - a).length() + 4.0 * PI * radius * radius
        }
        Primitive::Cuboid { min, max } => {
            let d = max - min;
            2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
        }
        Primitive::Triangle { v } => 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length(),
    }
}

/// Whether a sphere is drawn by the cone of directions it fills seen from `x` (outside it):
/// its centre, radius and 1 − cos θmax.
fn cone(p: &Primitive, x: DVec3) -> Option<(DVec3, f64, f64)> {
    let Primitive::Sphere { center, radius } = *p else {
        return None;
    };
    let (one_minus_cos, outside) = sphere_cone(center, radius, x);
    outside.then_some((center, radius, one_minus_cos))
}

/// A point drawn on `p` as seen from `x` (both in its rest frame), given three uniform numbers:
/// a sphere by the cone it fills, every other primitive uniformly by area.
pub(crate) fn sample_point(p: &Primitive, x: DVec3, u: [f64; 3]) -> Option<EmitterPoint> {
    if let Some((center, radius, omc)) = cone(p, x) {
        let point = sphere_point(center, radius, x, omc, [u[0], u[1]]);
        return Some(EmitterPoint { point });
    }
    let y = match *p {
        Primitive::Sphere { center, radius } => center + radius * sphere_dir(u[0], u[1]),
        Primitive::Capsule { a, b, radius } => {
            let axis = b - a;
            let len = axis.length();
            let side = 2.0 * PI * radius * len;
            let share = side / (side + 4.0 * PI * radius * radius);
            if u[0] < share && len > 0.0 {
                let basis = super::bsdf::Basis::new(axis / len);
                let (sp, cp) = sincos_turn(u[2]);
                a + u[1] * axis + radius * basis.to_world(DVec3::new(cp, sp, 0.0))
            } else {
                // A whole sphere's directions: the half toward b is b's cap, the rest a's.
                let d = sphere_dir(u[1], u[2]);
                (if d.dot(axis) >= 0.0 { b } else { a }) + radius * d
            }
        }
        Primitive::Cuboid { min, max } => {
            let d = max - min;
            let faces = [d.y * d.z, d.z * d.x, d.x * d.y];
            let total = faces[0] + faces[1] + faces[2];
            let mut k = 0;
            let mut pick = u[0] * total;
            while k < 2 && pick >= faces[k] {
                pick -= faces[k];
                k += 1;
            }
            // Which of the two faces of axis k, from what is left of the first number.
            let high = pick >= 0.5 * faces[k];
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let mut y = min;
            y[k] = if high { max[k] } else { min[k] };
            y[i] = min[i] + u[1] * d[i];
            y[j] = min[j] + u[2] * d[j];
            y
        }
        Primitive::Triangle { v } => {
            let su = u[0].sqrt();
            let (b0, b1) = (1.0 - su, u[1] * su);
            b0 * v[0] + b1 * v[1] + (1.0 - b0 - b1) * v[2]
        }
    };
    Some(EmitterPoint { point: y })
}

/// The density per solid angle (emitter's frame) with which [`sample_point`] draws point `y`
/// of `p` seen from `x`.
pub(crate) fn pdf_point(p: &Primitive, x: DVec3, y: DVec3) -> f64 {
    if let Some((_, _, omc)) = cone(p, x) {
        return 1.0 / (2.0 * PI * omc);
    }
    let d = y - x;
    let dist2 = d.length_squared();
    let cos = p.normal(y).dot(d).abs() / dist2.sqrt();
    let a = area(p);
    if cos <= 0.0 || a <= 0.0 || !cos.is_finite() {
        return 0.0;
    }
    dist2 / (a * cos)
}

/// A uniform direction on the sphere.
fn sphere_dir(u1: f64, u2: f64) -> DVec3 {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sp, cp) = sincos_turn(u2);
    DVec3::new(r * cp, r * sp, z)
}
