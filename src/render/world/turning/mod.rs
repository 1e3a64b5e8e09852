//! Spinning bodies that are not of revolution about their axis (a bar, a spoked wheel): their
//! shape in the group's frame turns, so a ray meets the body where the point it reaches, turned
//! back by ω T to the shape at time 0, lies inside it (docs/physics.md §12.6). Found by sphere
//! tracing along the ray, a primitive at a time and only over the stretches of the ray where
//! its heights, distances from the axis and angles about it allow: a primitive's signed
//! distance at the turned-back point changes by at most s (1 + |ω| ρ) per unit of lookback (s
//! the ray's lookback factor, ρ the farthest the stretch lies from the axis), so a step of the
//! distance over that never passes a surface; for spheres and rods a step up to the first root
//! of a quadratic lower bound on the distance goes farther, and closes on a surface at
//! Newton's rate.
//!
//! The rays reaching here start on the group's hyperplane of time T₀ (the imaging event's,
//! `World::rest_ray`), so the group's time is T = T₀ − |d| t along `origin + t dir`.

mod along;
mod shells;
#[cfg(test)]
mod tests;

use crate::accel::{Hit, Ray};
use crate::geometry::{Geometry, Primitive};
use along::{turned_angles, Along};
use glam::DVec3;
use shells::distance;
pub(crate) use shells::{turning_parts, TurningPart};

/// The most steps a ray's march takes along one primitive's stretch; where it grazes the
/// primitive so closely that it needs more, it is taken to miss it there.
const MAX_STEPS: usize = 20_000;

/// The first primitive on the ray: the still ones by their own tests, each turning part by
/// sphere tracing.
pub(super) fn intersect(
    geometry: &Geometry,
    parts: &[TurningPart],
    ray: &Ray,
    t0: f64,
) -> Option<Hit> {
    first(geometry, parts, ray, t0, false)
}

/// Whether any primitive lies on the ray: [`intersect`]'s answer, found without looking for
/// the first once one is found.
pub(super) fn occluded(geometry: &Geometry, parts: &[TurningPart], ray: &Ray, t0: f64) -> bool {
    first(geometry, parts, ray, t0, true).is_some()
}

/// [`intersect`], or with `any` a hit that need not be the first.
fn first(geometry: &Geometry, parts: &[TurningPart], ray: &Ray, t0: f64, any: bool) -> Option<Hit> {
    if !ray.is_active() {
        return None;
    }
    let mut best: Option<Hit> = None;
    let mut i = 0;
    while i < geometry.len() {
        // Over a turning part at once.
        if let Some(p) = parts.iter().find(|p| (p.start..p.end).contains(&i)) {
            i = p.end;
            continue;
        }
        let tmax = best.map_or(ray.tmax, |h| h.t);
        if let Some(t) = geometry
            .prim(i)
            .intersect(ray.origin, ray.dir, ray.tmin, tmax)
        {
            best = Some(Hit { t, prim: i });
            if any {
                return best;
            }
        }
        i += 1;
    }
    for p in parts {
        let tmax = best.map_or(ray.tmax, |h| h.t);
        if let Some(h) = march(geometry, p, ray, tmax, t0, any) {
            best = Some(h);
            if any {
                return best;
            }
        }
    }
    best
}

/// Where the ray is within the ball about the spin's centre that holds the part at every
/// turn: between the roots of a quadratic in t, or None.
fn swept_ball(part: &TurningPart, ray: &Ray) -> Option<(f64, f64)> {
    let oc = ray.origin - part.spin.centre;
    let (a, b, c) = (
        ray.dir.length_squared(),
        oc.dot(ray.dir),
        oc.length_squared() - part.reach * part.reach,
    );
    let disc = b * b - a * c;
    // Also where a NaN in the ray leaves nothing to march.
    if disc < 0.0 || disc.is_nan() {
        return None;
    }
    let root = disc.sqrt();
    Some(((-b - root) / a, (-b + root) / a))
}

/// Sphere tracing through one turning part, within the ball it sweeps, a primitive at a time:
/// each where the ray's height, distance from the axis and turned-back angle can reach it,
/// stepping by its own distance over a bound on how fast that distance changes there.
fn march(
    geometry: &Geometry,
    part: &TurningPart,
    ray: &Ray,
    tmax: f64,
    t0: f64,
    any: bool,
) -> Option<Hit> {
    let sp = &part.spin;
    let s = ray.len;
    let oc = ray.origin - sp.centre;
    let (enter, leave) = swept_ball(part, ray)?;
    let (mut t, mut end) = (enter.max(ray.tmin), leave.min(tmax));
    // Height along the axis and distance from it do not change as the body turns: along the
    // ray the first is linear and the second's square quadratic, so the march is kept to
    // where both are within the part's ranges (a wheel's thin slab, a bar's cylinder).
    let (z0, dz) = (oc.dot(sp.axis), ray.dir.dot(sp.axis));
    if dz != 0.0 {
        let (ta, tb) = ((part.z_range.0 - z0) / dz, (part.z_range.1 - z0) / dz);
        t = t.max(ta.min(tb));
        end = end.min(ta.max(tb));
    } else if z0 < part.z_range.0 || z0 > part.z_range.1 {
        return None;
    }
    let (w0, dw) = (oc - z0 * sp.axis, ray.dir - dz * sp.axis);
    let along = Along::new((z0, dz), (w0, dw));
    if along.outside(part.rho_max) {
        return None;
    }
    if let Some((lo, hi)) = along.within(part.rho_max) {
        t = t.max(lo);
        end = end.min(hi);
    }
    if t >= end || t.is_nan() || end.is_nan() {
        return None;
    }
    let tol = 1e-10 * part.reach.max(1e-300);
    // The turned-back point (`Spin::unturned` of the ray's point at its group time) and its
    // velocity: the ray's direction turned back, and the turn's own sweep of the point at
    // rate ω s about the axis.
    let moving = |t: f64| {
        let back = sp.back(t0 - s * t);
        let q = sp.centre + back * (ray.origin + t * ray.dir - sp.centre);
        let velocity = back * ray.dir + sp.omega * s * sp.axis.cross(q - sp.centre);
        (q, velocity)
    };
    // A ray that starts within the part's shape, where the march begins at its open lower
    // end, is taken to meet none of it (as by the march through the whole part).
    if t <= ray.tmin && distance(geometry, part, moving(t).0).0 < tol {
        return None;
    }
    let turn = turned_angles(part, (w0, dw), s, t0, (t, end));
    // The ray's least and greatest distance from the axis over (t, end): its square is least
    // at the vertex (or the end nearer it), greatest at an end.
    let rho_lo = along.rho2(along.tv.clamp(t, end)).sqrt() - tol;
    let rho_hi = along.rho2(t).max(along.rho2(end)).sqrt() + tol;
    let mut stretches: smallvec::SmallVec<[(f64, f64, u32, f64); 32]> = smallvec::SmallVec::new();
    for (sh, k) in &part.bands {
        if sh[0] > rho_hi {
            break;
        }
        if sh[1] < rho_lo || turn.as_ref().is_some_and(|r| r.misses(sh)) {
            continue;
        }
        for (lo, hi) in along.pieces(sh, (t, end), tol) {
            if lo < hi {
                stretches.push((lo, hi, *k, sh[1]));
            }
        }
    }
    stretches.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.2.cmp(&y.2)));
    let mut best: Option<Hit> = None;
    for (lo, hi, k, rho_hi) in stretches {
        // In order of where they start: none after the best hit so far can hold a nearer one.
        if best.is_some_and(|h: Hit| lo >= h.t) {
            break;
        }
        let limit = best.map_or(hi, |h: Hit| h.t.min(hi));
        let i = part.start + k;
        // Within the stretch the point lies no farther than its band's ρ_hi from the axis,
        // so it moves at most s (1 + |ω| ρ_hi) per unit of lookback, and its velocity turns
        // at most 2 |ω| s² + ω² s² ρ_hi.
        let (w, rho) = (sp.omega.abs(), rho_hi + tol);
        let step = s * (1.0 + w * rho);
        let bend = s * s * w * (2.0 + w * rho);
        if let Some(th) = march_one(&geometry.prim(i), &moving, (lo, limit), (step, bend), tol) {
            if th > ray.tmin {
                best = Some(Hit { t: th, prim: i });
                if any {
                    return best;
                }
            }
        }
    }
    best
}

/// A primitive's signed distance from `q` and its gradient there, with a bound on the
/// gradient's rate of change outside the primitive (the inverse of its radius): for spheres
/// and rods. None for others, whose march takes plain steps.
fn distance_and_slope(prim: &Primitive, q: DVec3) -> Option<(f64, DVec3, f64)> {
    let (off, radius) = prim.core_offset(q)?;
    let len = off.length();
    (radius > 0.0 && len > 0.0).then(|| (len - radius, off / len, 1.0 / radius))
}

/// The first step of a sphere trace through (lo, end) where the primitive lies within `tol`
/// of the turned-back point. `step` bounds how fast the point moves (so how fast its distance
/// changes), `bend` how fast the point's velocity changes.
///
/// A step is never shorter than the distance allows at that speed. For a sphere or a rod it
/// may be longer, up to the first root of a lower bound on the distance along the ray:
/// f(t + h) ≥ f + f′ h − K h² / 2, with f′ the distance's rate of change, found from its
/// gradient and the point's velocity, and K = κ step² + bend bounding f″ wherever the point
/// lies outside (κ bounding how fast the gradient turns there). Near a surface the ray meets,
/// that step is Newton's, so the march closes on it at Newton's rate without passing it.
fn march_one(
    prim: &Primitive,
    moving: &impl Fn(f64) -> (DVec3, DVec3),
    (mut t, end): (f64, f64),
    (step, bend): (f64, f64),
    tol: f64,
) -> Option<f64> {
    for _ in 0..MAX_STEPS {
        let (q, velocity) = moving(t);
        let (d, h) = match distance_and_slope(prim, q) {
            Some((d, grad, kappa)) => {
                let plain = d / step;
                let k = kappa * step * step + bend;
                let rate = grad.dot(velocity);
                let root = (rate * rate + 2.0 * k * d.max(0.0)).sqrt();
                // The positive root of f + f′ h − K h² / 2, in the form free of cancellation.
                let bounded = if rate <= 0.0 {
                    2.0 * d / (root - rate)
                } else {
                    (rate + root) / k
                };
                (d, plain.max(bounded))
            }
            None => {
                let d = prim.distance(q).unwrap_or(f64::INFINITY);
                (d, d / step)
            }
        };
        if d < tol {
            return Some(t);
        }
        t += h;
        if t >= end || t.is_nan() {
            return None;
        }
    }
    None
}
