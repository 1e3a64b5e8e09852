//! Spinning bodies that are not of revolution about their axis (a bar, a spoked wheel): their
//! shape in the group's frame turns, so a ray meets the body where the point it reaches, turned
//! back by ω T to the shape at time 0, lies inside it (docs/physics.md §12.6). Found by sphere
//! tracing along the ray: the shape's signed distance at the turned-back point changes by at
//! most s (1 + |ω| R) per unit of lookback (s the ray's lookback factor, R the body's reach from
//! its centre), so a step of the distance over that never passes a surface.
//!
//! The rays reaching here start on the group's hyperplane of time 0 (`World::rest_ray`), so the
//! group's time is T = −|d| t along `origin + t dir`.

use crate::accel::{Hit, Ray};
use crate::geometry::{Geometry, Spin};
use glam::DVec3;

/// The most steps a ray takes through one turning body; a ray that grazes it so closely that
/// it needs more is taken to miss it.
const MAX_STEPS: usize = 20_000;

/// A run of primitives turning together, and how far they reach from its centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TurningPart {
    pub start: u32,
    pub end: u32,
    pub spin: Spin,
    pub reach: f64,
}

/// The turning parts of a geometry (empty if nothing turns).
pub(crate) fn turning_parts(geometry: &Geometry) -> Vec<TurningPart> {
    geometry
        .parts
        .iter()
        .filter_map(|part| {
            let spin = part.spin.filter(|s| s.turning)?;
            let reach = (part.start..part.end)
                .map(|i| {
                    let b = geometry.prim(i).bounds();
                    b.corners()
                        .iter()
                        .map(|c| (*c - spin.centre).length())
                        .fold(0.0, f64::max)
                })
                .fold(0.0, f64::max);
            Some(TurningPart {
                start: part.start,
                end: part.end,
                spin,
                reach,
            })
        })
        .collect()
}

/// The first primitive on the ray: the still ones by their own tests, each turning part by
/// sphere tracing.
pub(super) fn intersect(geometry: &Geometry, parts: &[TurningPart], ray: &Ray) -> Option<Hit> {
    if !ray.is_active() {
        return None;
    }
    let mut best: Option<Hit> = None;
    let turning = |i: u32| parts.iter().any(|p| (p.start..p.end).contains(&i));
    for i in 0..geometry.len() {
        if turning(i) {
            continue;
        }
        let tmax = best.map_or(ray.tmax, |h| h.t);
        if let Some(t) = geometry
            .prim(i)
            .intersect(ray.origin, ray.dir, ray.tmin, tmax)
        {
            best = Some(Hit { t, prim: i });
        }
    }
    for p in parts {
        let tmax = best.map_or(ray.tmax, |h| h.t);
        if let Some(h) = march(geometry, p, ray, tmax) {
            best = Some(h);
        }
    }
    best
}

/// The signed distance of the part's shape at time 0 from `q`, and the primitive nearest.
fn distance(geometry: &Geometry, part: &TurningPart, q: DVec3) -> (f64, u32) {
    (part.start..part.end)
        .map(|i| (geometry.prim(i).distance(q).unwrap_or(f64::INFINITY), i))
        .fold(
            (f64::INFINITY, part.start),
            |a, b| if b.0 < a.0 { b } else { a },
        )
}

/// Sphere tracing through one turning part, within the ball it sweeps.
fn march(geometry: &Geometry, part: &TurningPart, ray: &Ray, tmax: f64) -> Option<Hit> {
    let sp = &part.spin;
    let s = ray.len;
    // The ball about the centre that holds the part at every turn.
    let oc = ray.origin - sp.centre;
    let (a, b, c) = (
        ray.dir.length_squared(),
        oc.dot(ray.dir),
        oc.length_squared() - part.reach * part.reach,
    );
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let (enter, leave) = ((-b - root) / a, (-b + root) / a);
    let (mut t, end) = (enter.max(ray.tmin), leave.min(tmax));
    if t >= end {
        return None;
    }
    let lipschitz = s * (1.0 + sp.omega.abs() * part.reach);
    let tol = 1e-10 * part.reach.max(1e-300);
    for _ in 0..MAX_STEPS {
        let p = ray.origin + t * ray.dir;
        let q = sp.unturned(p, -s * t);
        let (d, prim) = distance(geometry, part, q);
        if d < tol {
            return (t > ray.tmin).then_some(Hit { t, prim });
        }
        t += d / lipschitz;
        if t >= end {
            return None;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Primitive;

    /// A bar turning about z: every hit found lies on the bar's surface turned by ω T, and
    /// no point the ray passes before it lies inside.
    #[test]
    fn hits_lie_on_the_turned_shape_and_none_before() {
        let spin = Spin {
            centre: DVec3::ZERO,
            axis: DVec3::Z,
            omega: 0.4,
            turning: true,
        };
        let mut g = Geometry::default();
        g.push_part(
            0,
            0,
            [Primitive::Cuboid {
                min: DVec3::new(-2.0, -0.2, -0.3),
                max: DVec3::new(2.0, 0.2, 0.3),
            }],
        );
        g.set_spin(0, spin);
        let parts = turning_parts(&g);
        assert_eq!(parts.len(), 1);
        let mut hits = 0;
        for i in 0..300 {
            let x = -3.0 + 0.02 * i as f64;
            let look = DVec3::new(0.0, 1.0, 0.05).normalize();
            let ray = Ray::new(DVec3::new(x, -5.0, 0.0), look, 0.0, 50.0);
            let Some(h) = intersect(&g, &parts, &ray) else {
                continue;
            };
            hits += 1;
            let at = |t: f64| spin.unturned(ray.origin + t * ray.dir, -ray.len * t);
            let prim = g.prim(h.prim);
            assert!(prim.distance(at(h.t)).unwrap().abs() < 1e-9);
            for k in 1..200 {
                let t = h.t * k as f64 / 200.0;
                assert!(
                    prim.distance(at(t)).unwrap() > -1e-12,
                    "inside before the hit"
                );
            }
        }
        assert!(hits > 50, "{hits}");
    }
}
