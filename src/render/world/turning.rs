//! Spinning bodies that are not of revolution about their axis (a bar, a spoked wheel): their
//! shape in the group's frame turns, so a ray meets the body where the point it reaches, turned
//! back by ω T to the shape at time 0, lies inside it (docs/physics.md §12.6). Found by sphere
//! tracing along the ray: the shape's signed distance at the turned-back point changes by at
//! most s (1 + |ω| R) per unit of lookback (s the ray's lookback factor, R the body's reach from
//! its centre), so a step of the distance over that never passes a surface.
//!
//! The rays reaching here start on the group's hyperplane of time T₀ (the imaging event's,
//! `World::rest_ray`), so the group's time is T = T₀ − |d| t along `origin + t dir`.

use crate::accel::{Hit, Ray};
use crate::geometry::{Geometry, Primitive, Spin};
use glam::DVec3;

/// The most steps a ray takes through one turning body; a ray that grazes it so closely that
/// it needs more is taken to miss it.
const MAX_STEPS: usize = 20_000;

/// A run of primitives turning together, how far they reach from its centre, and where each
/// lies about the axis: its ranges of distance from the axis, of height along it, and of angle
/// about it (in the shape at time 0), which bound its distance from below without computing it.
#[derive(Clone, Debug, PartialEq)]
pub struct TurningPart {
    pub start: u32,
    pub end: u32,
    pub spin: Spin,
    pub reach: f64,
    /// Per primitive from `start`: (ρ_lo, ρ_hi, z_lo, z_hi, angle centre, angular half-width),
    /// the half-width π where it surrounds the axis.
    pub shells: Vec<[f64; 6]>,
    /// Two directions across the axis, for the angle.
    pub across: (DVec3, DVec3),
    /// The heights along the axis and the farthest distance from it, over all its primitives.
    pub z_range: (f64, f64),
    pub rho_max: f64,
}

/// Cylindrical coordinates about the spin's axis: (ρ, z, φ) of `q`.
fn cylindrical(sp: &Spin, across: (DVec3, DVec3), q: DVec3) -> (f64, f64, f64) {
    let r = q - sp.centre;
    let z = r.dot(sp.axis);
    let (x, y) = (r.dot(across.0), r.dot(across.1));
    ((x * x + y * y).sqrt(), z, y.atan2(x))
}

/// Where primitive `p` lies about the axis (see [`TurningPart::shells`]).
fn shell(sp: &Spin, across: (DVec3, DVec3), p: &Primitive) -> [f64; 6] {
    use std::f64::consts::PI;
    let cyl = |q: DVec3| cylindrical(sp, across, q);
    // The centre line's ends (a sphere's centre twice) and the radius about it; a box by its
    // corners, all around.
    let (a, b, r) = match *p {
        Primitive::Sphere { center, radius } => (center, center, radius),
        Primitive::Capsule { a, b, radius } => (a, b, radius),
        other => {
            let c = other.bounds().corners().map(cyl);
            let (lo, hi) = c
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), q| {
                    (l.min(q.1), h.max(q.1))
                });
            let rho = c.iter().map(|q| q.0).fold(0.0, f64::max);
            return [0.0, rho, lo, hi, 0.0, PI];
        }
    };
    let ((ra, za, pa), (rb, zb, pb)) = (cyl(a), cyl(b));
    // The least distance of the segment a-b from the axis: |w(t)|² is quadratic in t.
    let across_axis = |q: DVec3| (q - sp.centre) - (q - sp.centre).dot(sp.axis) * sp.axis;
    let (wa, wb) = (across_axis(a), across_axis(b));
    let dw = wb - wa;
    let t = if dw.length_squared() > 0.0 {
        (-wa.dot(dw) / dw.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let closest = (wa + t * dw).length();
    let (rho_lo, rho_hi) = ((closest - r).max(0.0), ra.max(rb) + r);
    let (z_lo, z_hi) = (za.min(zb) - r, za.max(zb) + r);
    if closest <= r {
        return [rho_lo, rho_hi, z_lo, z_hi, 0.0, PI];
    }
    // The segment does not pass the axis: it subtends the shorter arc between its ends,
    // widened by the angle its radius takes at its closest.
    let mut gap = pb - pa;
    if gap > PI {
        gap -= 2.0 * PI;
    } else if gap < -PI {
        gap += 2.0 * PI;
    }
    let half = 0.5 * gap.abs() + (r / closest).min(1.0).asin();
    [rho_lo, rho_hi, z_lo, z_hi, pa + 0.5 * gap, half.min(PI)]
}

/// Whether all that lies within `sh` is at least `best` from the point at (ρ, z, φ), by a
/// lower bound on the distance: the greatest of how far the point lies outside the shell's
/// ranges of distance from the axis and of height, and ρ sin(its angle outside the shell's
/// arc). Each step of the march asks it of every primitive, so the sine is taken only where
/// the other bounds leave the answer open and ρ times the angle (at least ρ sin, rounding
/// being monotone) reaches `best`: the same answers as with the sine always taken.
#[inline]
fn beyond(sh: &[f64; 6], (rho, z, phi): (f64, f64, f64), best: f64) -> bool {
    use std::f64::consts::{PI, TAU};
    let lb = (sh[0] - rho).max(rho - sh[1]).max(sh[2] - z).max(z - sh[3]);
    if lb >= best {
        return true;
    }
    if sh[5] >= PI {
        return false;
    }
    // φ and the arc's centre lie within 1.5π of 0, so `off` is below 4π, where taking 2π
    // off once is exact (Sterbenz) and gives the remainder `%` would.
    let mut off = (phi - sh[4]).abs();
    if off >= TAU {
        off -= TAU;
    }
    if off > PI {
        off = TAU - off;
    }
    let outside = (off - sh[5]).clamp(0.0, 0.5 * PI);
    rho * outside >= best && rho * outside.sin() >= best
}

/// The turning parts of a geometry (empty if nothing turns).
pub(crate) fn turning_parts(geometry: &Geometry) -> Vec<TurningPart> {
    geometry
        .parts
        .iter()
        .filter_map(|part| {
            let spin = part.spin.filter(|s| s.turning)?;
            let reach = geometry.reach(part, spin.centre);
            let u = spin.axis.any_orthonormal_vector();
            let across = (u, spin.axis.cross(u));
            let shells: Vec<[f64; 6]> = (part.start..part.end)
                .map(|i| shell(&spin, across, &geometry.prim(i)))
                .collect();
            let z_range = shells
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |r, sh| {
                    (r.0.min(sh[2]), r.1.max(sh[3]))
                });
            let rho_max = shells.iter().map(|sh| sh[1]).fold(0.0, f64::max);
            Some(TurningPart {
                start: part.start,
                end: part.end,
                spin,
                reach,
                shells,
                across,
                z_range,
                rho_max,
            })
        })
        .collect()
}

/// The first primitive on the ray: the still ones by their own tests, each turning part by
/// sphere tracing.
pub(super) fn intersect(
    geometry: &Geometry,
    parts: &[TurningPart],
    ray: &Ray,
    t0: f64,
) -> Option<Hit> {
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
        if let Some(h) = march(geometry, p, ray, tmax, t0) {
            best = Some(h);
        }
    }
    best
}

/// The signed distance of the part's shape at time 0 from `q`, and the primitive nearest.
/// Primitives whose shell lies farther than the nearest found so far are not asked.
fn distance(geometry: &Geometry, part: &TurningPart, q: DVec3) -> (f64, u32) {
    let at = cylindrical(&part.spin, part.across, q);
    let mut best = (f64::INFINITY, part.start);
    for (k, sh) in part.shells.iter().enumerate() {
        if beyond(sh, at, best.0) {
            continue;
        }
        let i = part.start + k as u32;
        let d = geometry.prim(i).distance(q).unwrap_or(f64::INFINITY);
        if d < best.0 {
            best = (d, i);
        }
    }
    best
}

/// Sphere tracing through one turning part, within the ball it sweeps.
fn march(geometry: &Geometry, part: &TurningPart, ray: &Ray, tmax: f64, t0: f64) -> Option<Hit> {
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
    let (qa, qb, qc) = (
        dw.length_squared(),
        w0.dot(dw),
        w0.length_squared() - part.rho_max * part.rho_max,
    );
    if qa > 0.0 {
        let disc = qb * qb - qa * qc;
        if disc < 0.0 {
            return None;
        }
        let root = disc.sqrt();
        t = t.max((-qb - root) / qa);
        end = end.min((-qb + root) / qa);
    } else if qc > 0.0 {
        return None;
    }
    if t >= end {
        return None;
    }
    let lipschitz = s * (1.0 + sp.omega.abs() * part.reach);
    let tol = 1e-10 * part.reach.max(1e-300);
    for _ in 0..MAX_STEPS {
        let p = ray.origin + t * ray.dir;
        let q = sp.unturned(p, t0 - s * t);
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

    /// `beyond` answers as the lower bound with its sine always taken, compared with `best`
    /// (the bound as first written): over shells and points about the axis at every angle,
    /// with bests around the bound itself, ties included.
    #[test]
    fn beyond_answers_as_the_whole_bound_does() {
        use std::f64::consts::PI;
        let whole = |sh: &[f64; 6], (rho, z, phi): (f64, f64, f64)| {
            let mut lb = (sh[0] - rho).max(rho - sh[1]).max(sh[2] - z).max(z - sh[3]);
            if sh[5] < PI {
                let mut off = (phi - sh[4]).abs() % (2.0 * PI);
                if off > PI {
                    off = 2.0 * PI - off;
                }
                let outside = (off - sh[5]).clamp(0.0, 0.5 * PI);
                lb = lb.max(rho * outside.sin());
            }
            lb
        };
        let mut rng = crate::rng::Rng(11);
        let (mut asked, mut skipped) = (0, 0);
        for _ in 0..200_000 {
            let mut u = |a: f64, b: f64| a + (b - a) * rng.f();
            let (r0, z0) = (u(0.0, 2.0), u(-1.0, 1.0));
            let (pa, gap) = (u(-PI, PI), u(-PI, PI));
            let sh = [
                r0,
                r0 + u(0.0, 1.0),
                z0,
                z0 + u(0.0, 0.5),
                pa + 0.5 * gap,
                u(0.0, 1.2 * PI),
            ];
            let at = (u(0.0, 3.0), u(-1.5, 1.5), u(-PI, PI));
            let lb = whole(&sh, at);
            for best in [
                lb,
                u(0.0, 2.0),
                lb * (1.0 + 1e-12),
                lb * (1.0 - 1e-12),
                f64::INFINITY,
            ] {
                let want = lb >= best;
                assert_eq!(beyond(&sh, at, best), want, "{sh:?} {at:?} {best}");
                asked += 1;
                skipped += usize::from(want);
            }
        }
        assert!(
            skipped > asked / 10 && skipped < asked * 9 / 10,
            "{skipped} of {asked}"
        );
    }

    /// A bar turning about z: every hit found lies on the bar's surface turned by ω T, and
    /// no point the ray passes before it lies inside.
    #[test]
    fn hits_lie_on_the_turned_shape_and_none_before() {
        let spin = Spin {
            centre: DVec3::ZERO,
            axis: DVec3::Z,
            omega: 0.4,
            turning: true,
            epoch: 0.0,
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
            let Some(h) = intersect(&g, &parts, &ray, 0.0) else {
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
