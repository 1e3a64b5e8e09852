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

use crate::accel::{Hit, Ray};
use crate::geometry::{Geometry, Primitive, Spin};
use glam::DVec3;

/// The most steps a ray's march takes along one primitive's stretch; where it grazes the
/// primitive so closely that it needs more, it is taken to miss it there.
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
    /// The same, narrower, for the march: a shell per primitive but for rods that reach round
    /// the axis (a spoke from the hub), which get one per band of distance from it
    /// ([`bands`]); each with its primitive's index from `start`, in order of their least
    /// distance from the axis.
    pub bands: Vec<([f64; 6], u32)>,
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

/// Shells for a rod's march that are narrower than its one [`shell`] where that wraps much of
/// the way round the axis (a spoke from the hub): all round up to 3r from the axis (r its
/// radius), then bands of distance R to 2R, each with the arc of the rod's centre line where
/// it lies R − r or more from the axis, widened by asin(r / (R − r)). A point of the rod at
/// distance R or more lies within r of a point of that line at R − r or more, so within that
/// angle of it. Other primitives keep their one shell.
fn bands(sp: &Spin, across: (DVec3, DVec3), p: &Primitive, sh: [f64; 6]) -> Vec<[f64; 6]> {
    use std::f64::consts::{FRAC_PI_4, PI};
    let Primitive::Capsule { a, b, radius: r } = *p else {
        return vec![sh];
    };
    if sh[5] <= FRAC_PI_4 || sh[1] <= 6.0 * r || r <= 0.0 {
        return vec![sh];
    }
    let across_axis = |q: DVec3| (q - sp.centre) - (q - sp.centre).dot(sp.axis) * sp.axis;
    let (wa, wb) = (across_axis(a), across_axis(b));
    let dw = wb - wa;
    let angle = |w: DVec3| w.dot(across.1).atan2(w.dot(across.0));
    let mut out = Vec::new();
    if sh[0] < 3.0 * r {
        out.push([sh[0], 3.0 * r, sh[2], sh[3], 0.0, PI]);
    }
    let mut band = 3.0 * r;
    while band < sh[1] {
        let next = (2.0 * band).min(sh[1]);
        // A band wholly nearer the axis than the rod holds nothing.
        if next <= sh[0] {
            band = next;
            continue;
        }
        let from = band.max(sh[0]);
        let inner = from - r;
        // The centre line lies nearer the axis than `inner` between two roots of a
        // quadratic in its parameter; the rest of [0, 1] is in one or two pieces.
        let (qa, qb, qc) = (
            dw.length_squared(),
            wa.dot(dw),
            wa.length_squared() - inner * inner,
        );
        let disc = qb * qb - qa * qc;
        let pieces: [(f64, f64); 2] = if qa > 0.0 && disc > 0.0 {
            let root = disc.sqrt();
            [
                (0.0, ((-qb - root) / qa).min(1.0)),
                (((-qb + root) / qa).max(0.0), 1.0),
            ]
        } else if qc >= 0.0 {
            [(0.0, 1.0), (1.0, 0.0)]
        } else {
            [(1.0, 0.0); 2]
        };
        let widen = (r / inner).min(1.0).asin();
        for (lo, hi) in pieces {
            if lo > hi {
                continue;
            }
            let (pa, pb) = (angle(wa + lo * dw), angle(wa + hi * dw));
            let mut gap = pb - pa;
            if gap > PI {
                gap -= 2.0 * PI;
            } else if gap < -PI {
                gap += 2.0 * PI;
            }
            let half = (0.5 * gap.abs() + widen).min(PI);
            out.push([from, next, sh[2], sh[3], pa + 0.5 * gap, half]);
        }
        band = next;
    }
    out
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
            let mut bands: Vec<([f64; 6], u32)> = (part.start..part.end)
                .zip(&shells)
                .flat_map(|(i, sh)| {
                    let k = i - part.start;
                    bands(&spin, across, &geometry.prim(i), *sh)
                        .into_iter()
                        .map(move |b| (b, k))
                })
                .collect();
            bands.sort_by(|x, y| x.0[0].total_cmp(&y.0[0]).then(x.1.cmp(&y.1)));
            Some(TurningPart {
                start: part.start,
                end: part.end,
                spin,
                reach,
                shells,
                bands,
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

/// The angles about the axis that the turned-back point takes along a stretch of the ray:
/// within `half` of `mid` (in [0, 2π], where `rem_euclid` may round up to 2π itself).
struct Turn {
    mid: f64,
    half: f64,
    /// Rounding's reach in the angles, which grows with the turn since the epoch.
    slack: f64,
}

impl Turn {
    /// Whether the shell's arc lies wholly outside these angles (never for a shell all
    /// around the axis). A hair of slack keeps rounding from parting an arc and a point on
    /// its edge.
    fn misses(&self, sh: &[f64; 6]) -> bool {
        use std::f64::consts::{PI, TAU};
        if sh[5] >= PI {
            return false;
        }
        // `mid` lies in [0, 2π] and the arc's centre within 1.5π of 0 (see `beyond`).
        let mut off = (self.mid - sh[4]).abs();
        if off >= TAU {
            off -= TAU;
        }
        if off > PI {
            off = TAU - off;
        }
        off > self.half + sh[5] + self.slack
    }
}

/// The ray's stretch where a primitive may lie: its height within the shell's, and its
/// distance from the axis (unchanged by the turning) too; empty pieces are not pushed.
struct Along {
    /// Height along the axis where t = 0, and its change per unit t.
    z0: f64,
    dz: f64,
    /// The squared distance from the axis, qa (t − tv)² + m2: least, m2, at tv. In this form
    /// (not expanded in powers of t) a ray from far away keeps its distances to the axis: the
    /// expanded one loses the square of its distance from the axis to rounding.
    qa: f64,
    tv: f64,
    m2: f64,
}

impl Along {
    /// Along `origin + t dir`: its height z0 + t dz, and w0 + t dw across the axis.
    fn new((z0, dz): (f64, f64), (w0, dw): (DVec3, DVec3)) -> Along {
        let qa = dw.length_squared();
        let tv = if qa > 0.0 { -w0.dot(dw) / qa } else { 0.0 };
        let m2 = (w0 + tv * dw).length_squared();
        Along { z0, dz, qa, tv, m2 }
    }

    /// The squared distance from the axis at t.
    fn rho2(&self, t: f64) -> f64 {
        let d = t - self.tv;
        self.qa * d * d + self.m2
    }

    /// Where the ray lies nearer the axis than `rho`, if it crosses that cylinder.
    fn within(&self, rho: f64) -> Option<(f64, f64)> {
        let over = rho * rho - self.m2;
        (self.qa > 0.0 && over > 0.0).then(|| {
            let h = (over / self.qa).sqrt();
            (self.tv - h, self.tv + h)
        })
    }

    /// Whether the ray never lies within `rho` of the axis (taking one that only touches the
    /// cylinder as missing it).
    fn outside(&self, rho: f64) -> bool {
        self.within(rho).is_none() && (self.qa > 0.0 || self.m2 > rho * rho)
    }

    /// The pieces of (a, b) where the point lies within the shell's ranges of height and of
    /// distance from the axis, widened by `tol`; at most two (the second where a shell round
    /// the axis parts the stretch in two).
    fn pieces(&self, sh: &[f64; 6], (mut a, mut b): (f64, f64), tol: f64) -> [(f64, f64); 2] {
        const NONE: [(f64, f64); 2] = [(0.0, 0.0); 2];
        let (z_lo, z_hi) = (sh[2] - tol, sh[3] + tol);
        if self.dz != 0.0 {
            let (ta, tb) = ((z_lo - self.z0) / self.dz, (z_hi - self.z0) / self.dz);
            a = a.max(ta.min(tb));
            b = b.min(ta.max(tb));
        } else if self.z0 < z_lo || self.z0 > z_hi {
            return NONE;
        }
        if a >= b {
            return NONE;
        }
        // Within ρ_hi: between the roots; outside ρ_lo: not between them.
        let rho_hi = sh[1] + tol;
        if self.outside(rho_hi) {
            return NONE;
        }
        if let Some((lo, hi)) = self.within(rho_hi) {
            a = a.max(lo);
            b = b.min(hi);
        }
        if a >= b {
            return NONE;
        }
        let rho_lo = sh[0] - tol;
        if rho_lo <= 0.0 {
            return [(a, b), (0.0, 0.0)];
        }
        match self.within(rho_lo) {
            Some((lo, hi)) => [(a, b.min(lo)), (a.max(hi), b)],
            None if self.qa == 0.0 && self.m2 < rho_lo * rho_lo => NONE,
            None => [(a, b), (0.0, 0.0)],
        }
    }
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
    let at = |t: f64| sp.unturned(ray.origin + t * ray.dir, t0 - s * t);
    // The turned-back point and its velocity: the ray's direction turned back, and the turn's
    // own sweep of the point at rate ω s about the axis.
    let moving = |t: f64| {
        let back = sp.back(t0 - s * t);
        let q = sp.centre + back * (ray.origin + t * ray.dir - sp.centre);
        let velocity = back * ray.dir + sp.omega * s * sp.axis.cross(q - sp.centre);
        (q, velocity)
    };
    // A ray that starts within the part's shape, where the march begins at its open lower
    // end, is taken to meet none of it (as by the march through the whole part).
    if t <= ray.tmin && distance(geometry, part, at(t)).0 < tol {
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
    // The same arithmetic as `Primitive::distance`, so the same distances.
    let (off, radius) = match *prim {
        Primitive::Sphere { center, radius } => (q - center, radius),
        Primitive::Capsule { a, b, radius } => {
            let ab = b - a;
            let h = ((q - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
            (q - (a + h * ab), radius)
        }
        _ => return None,
    };
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

/// The angles about the axis the turned-back point takes along (a, b): those the ray's own
/// point sweeps (monotonic along a line that misses the axis, by less than π) widened by the
/// turn over that stretch of lookback. None where the ray passes the axis or starts or ends
/// on it, whose angles are any.
fn turned_angles(
    part: &TurningPart,
    (w0, dw): (DVec3, DVec3),
    s: f64,
    t0: f64,
    (a, b): (f64, f64),
) -> Option<Turn> {
    use std::f64::consts::{PI, TAU};
    let sp = &part.spin;
    let (u, v) = part.across;
    let flat = |t: f64| {
        let w = w0 + t * dw;
        (w.dot(u), w.dot(v))
    };
    let ((xa, ya), (xb, yb)) = (flat(a), flat(b));
    let near = 1e-9 * part.reach;
    if xa.hypot(ya) < near || xb.hypot(yb) < near {
        return None;
    }
    let swept = (xa * yb - ya * xb).atan2(xa * xb + ya * yb);
    if swept.abs() > PI - 1e-6 {
        return None;
    }
    // φ of the turned-back point: φ of the ray's point less ω (T − epoch), T = t0 − s t.
    let start = ya.atan2(xa) - sp.omega * (t0 - s * a - sp.epoch);
    let turned = sp.omega * s * (b - a);
    let (lo, hi) = (
        start + swept.min(0.0) + turned.min(0.0),
        start + swept.max(0.0) + turned.max(0.0),
    );
    let half = 0.5 * (hi - lo);
    // Rounding: of the angles at the ends (relative to the ray's reach across the axis over
    // its distance from it there), of the group times the march turns back by (which grow
    // with t0 and the epoch however small the turn between them), and of `start` itself.
    let eps = f64::EPSILON;
    let times = sp.omega.abs() * (t0.abs() + (s * b).abs() + sp.epoch.abs());
    let ends = (w0.length() + dw.length() * a.abs().max(b.abs())) / xa.hypot(ya).min(xb.hypot(yb));
    (half < PI).then(|| Turn {
        mid: (0.5 * (lo + hi)).rem_euclid(TAU),
        half,
        slack: 1e-9 * (1.0 + start.abs()) + 8.0 * eps * (times + ends),
    })
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

    /// The march through the whole part as it was before a primitive at a time: every step
    /// the union's distance over its Lipschitz bound for the whole reach. Slow and plain,
    /// so the reference the per-primitive march must agree with.
    fn union_march(g: &Geometry, part: &TurningPart, ray: &Ray, t0: f64) -> Option<Hit> {
        let (sp, s) = (&part.spin, ray.len);
        let (enter, leave) = swept_ball(part, ray)?;
        let (mut t, end) = (enter.max(ray.tmin), leave.min(ray.tmax));
        let lipschitz = s * (1.0 + sp.omega.abs() * part.reach);
        let tol = 1e-10 * part.reach;
        while t < end {
            let (d, prim) = distance(g, part, sp.unturned(ray.origin + t * ray.dir, t0 - s * t));
            if d < tol {
                return (t > ray.tmin).then_some(Hit { t, prim });
            }
            t += d / lipschitz;
        }
        None
    }

    /// A wheel of rods and a hub in the plane z = 0, spokes from its centre, and a rod across
    /// it, turning about `axis` through `centre` at `speed` (the fraction of c its farthest
    /// point moves at, negative to turn the other way).
    fn fast_wheel(speed: f64, centre: DVec3, axis: DVec3) -> Geometry {
        let mut prims = vec![Primitive::Sphere {
            center: DVec3::ZERO,
            radius: 0.2,
        }];
        let rim = |k: usize| {
            let a = std::f64::consts::TAU * k as f64 / 24.0;
            DVec3::new(2.0 * a.cos(), 2.0 * a.sin(), 0.0)
        };
        for k in 0..24 {
            prims.push(Primitive::Capsule {
                a: rim(k),
                b: rim(k + 1),
                radius: 0.06,
            });
        }
        for k in (0..24).step_by(3) {
            prims.push(Primitive::Capsule {
                a: 0.1 * rim(k),
                b: rim(k),
                radius: 0.05,
            });
        }
        prims.push(Primitive::Capsule {
            a: DVec3::new(-1.2, 0.7, 0.1),
            b: DVec3::new(1.3, -0.6, -0.1),
            radius: 0.04,
        });
        let mut g = Geometry::default();
        g.push_part(0, 0, prims);
        let reach = g.reach(&g.parts[0], centre);
        g.set_spin(
            0,
            Spin {
                centre,
                axis: axis.normalize(),
                omega: speed / reach,
                turning: true,
                epoch: 0.3,
            },
        );
        g
    }

    /// The wheels the tests march through: about its own axis and a tilted one off its
    /// centre, still and at rims up to 0.98c either way.
    fn wheels() -> Vec<Geometry> {
        let tilted = (DVec3::new(0.3, -0.2, 0.1), DVec3::new(0.2, 0.3, 1.0));
        let mut out = Vec::new();
        for speed in [0.0, 0.4, -0.9, 0.98] {
            out.push(fast_wheel(speed, DVec3::ZERO, DVec3::Z));
        }
        for speed in [0.6, -0.98] {
            out.push(fast_wheel(speed, tilted.0, tilted.1));
        }
        out
    }

    /// A ray at the wheel from all about it; some lie in a plane across the spin's axis (no
    /// change of height), some along it, some start a little along (tmin > 0); the group
    /// time at its start near 0 or a million.
    fn ray_at(rng: &mut crate::rng::Rng, axis: DVec3, k: usize) -> (Ray, f64) {
        let mut u = |a: f64, b: f64| a + (b - a) * rng.f();
        let from = DVec3::new(u(-4.0, 4.0), u(-4.0, 4.0), u(-3.0, 3.0));
        let to = DVec3::new(u(-2.2, 2.2), u(-2.2, 2.2), u(-0.1, 0.1));
        let mut dir = (to - from).normalize();
        match k % 8 {
            // Across the axis: no change of height along it.
            0 => dir = (dir - dir.dot(axis) * axis).normalize(),
            // Along the axis.
            1 => dir = -axis,
            _ => {}
        }
        let dir = dir * u(0.5, 2.0);
        let tmin = if k.is_multiple_of(5) {
            u(0.0, 1.0)
        } else {
            0.0
        };
        let t0 = if k.is_multiple_of(7) {
            1e6 + u(-1.0, 1.0)
        } else {
            u(-20.0, 20.0)
        };
        (Ray::new(from, dir, tmin, 100.0), t0)
    }

    /// The per-primitive march, with its bands, angles and longer steps near rods and spheres,
    /// finds the hits the plain march through the whole part finds: the same primitive's
    /// surface at a lookback within 1e-6 (the two stop at different points within the
    /// tolerance of a surface a glancing ray reaches over a longer stretch), or, where one
    /// finds a hit the other does not, a ray passing within the tolerance of a surface; and
    /// no point before a hit inside. Occlusion answers as the intersection does.
    #[test]
    fn the_march_by_primitive_finds_what_the_whole_march_finds() {
        let mut rng = crate::rng::Rng(7);
        let (mut hits, mut rays) = (0, 0);
        for g in wheels() {
            let parts = turning_parts(&g);
            let part = &parts[0];
            for k in 0..3000 {
                let (ray, t0) = ray_at(&mut rng, part.spin.axis, k);
                rays += 1;
                let want = union_march(&g, part, &ray, t0);
                let got = intersect(&g, &parts, &ray, t0);
                assert_eq!(
                    occluded(&g, &parts, &ray, t0),
                    got.is_some(),
                    "{ray:?} {t0}"
                );
                let at = |t: f64| {
                    part.spin
                        .unturned(ray.origin + t * ray.dir, t0 - ray.len * t)
                };
                match (want, got) {
                    (None, None) => {}
                    (Some(w), Some(h)) => {
                        hits += 1;
                        assert!((w.t - h.t).abs() < 1e-6, "{w:?} {h:?} {ray:?} {t0}");
                        assert!(g.prim(h.prim).distance(at(h.t)).unwrap() < 1e-9, "{h:?}");
                        for k in 0..64 {
                            let t = ray.tmin + (h.t - ray.tmin) * k as f64 / 64.0;
                            assert!(distance(&g, part, at(t)).0 > -1e-12, "inside before {h:?}");
                        }
                    }
                    _ => {
                        let h = want.or(got).unwrap();
                        let (d, _) = distance(&g, part, at(h.t));
                        assert!(d.abs() < 1e-9, "{want:?} {got:?} {ray:?} {t0}");
                    }
                }
            }
        }
        assert!(hits > rays / 10 && hits < rays * 9 / 10, "{hits} of {rays}");
    }

    /// A ray that starts inside the body meets none of it, as the plain march has it; one
    /// that starts on its surface and leaves meets what lies beyond.
    #[test]
    fn rays_from_inside_and_from_the_surface() {
        let g = fast_wheel(0.9, DVec3::ZERO, DVec3::Z);
        let parts = turning_parts(&g);
        // From the hub's centre, out through the rim's far side: inside at the start.
        let ray = Ray::new(DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0), 0.0, 100.0);
        assert_eq!(intersect(&g, &parts, &ray, 0.0), None);
        assert_eq!(union_march(&g, &parts[0], &ray, 0.0), None);
        // Pushed just off the hub's surface as a shadow ray is (t0 the epoch: the wheel as
        // built): up out of the plane, nothing; out between two spokes, the rim or a spoke
        // turned into its way, where the plain march finds it.
        let up = Ray::new(DVec3::new(0.0, 0.0, 0.2 + 1e-7), DVec3::Z, 0.0, 100.0);
        assert_eq!(intersect(&g, &parts, &up, 0.3), None);
        let between = DVec3::new(22.5f64.to_radians().cos(), 22.5f64.to_radians().sin(), 0.0);
        let out = Ray::new((0.2 + 1e-7) * between, between, 0.0, 100.0);
        let (want, got) = (
            union_march(&g, &parts[0], &out, 0.3),
            intersect(&g, &parts, &out, 0.3),
        );
        let (w, h) = (
            want.expect("the plain march meets it"),
            got.expect("meets it"),
        );
        assert!((w.t - h.t).abs() < 1e-9, "{w:?} {h:?}");
    }

    /// The angles `turned_angles` gives hold the turned-back point's angle all along the
    /// stretch, and the pieces `Along::pieces` gives hold every point of it within a band's
    /// heights and distances from the axis: sampled densely, over the rays above (those
    /// across and along the axis among them). And they cull: most bands are passed over.
    #[test]
    fn the_culls_hold_every_point_they_must() {
        use std::f64::consts::{PI, TAU};
        let mut rng = crate::rng::Rng(5);
        let (mut asked, mut passed) = (0usize, 0usize);
        for g in wheels() {
            let part = &turning_parts(&g)[0];
            let sp = &part.spin;
            for k in 0..400 {
                let (ray, t0) = ray_at(&mut rng, sp.axis, k);
                let s = ray.len;
                let Some((enter, leave)) = swept_ball(part, &ray) else {
                    continue;
                };
                let (a, b) = (enter.max(ray.tmin), leave.min(ray.tmax));
                if a >= b {
                    continue;
                }
                let oc = ray.origin - sp.centre;
                let (z0, dz) = (oc.dot(sp.axis), ray.dir.dot(sp.axis));
                let (w0, dw) = (oc - z0 * sp.axis, ray.dir - dz * sp.axis);
                let along = Along::new((z0, dz), (w0, dw));
                let turn = turned_angles(part, (w0, dw), s, t0, (a, b));
                let samples: Vec<f64> = (0..=200).map(|i| a + (b - a) * i as f64 / 200.0).collect();
                for &t in &samples {
                    let q = sp.unturned(ray.origin + t * ray.dir, t0 - s * t);
                    let (rho, z, phi) = cylindrical(sp, part.across, q);
                    if let Some(turn) = &turn {
                        let mut off = (phi - turn.mid).rem_euclid(TAU);
                        if off > PI {
                            off = TAU - off;
                        }
                        assert!(
                            off <= turn.half + 1e-9,
                            "{t} of {a}..{b}: {off} > {}",
                            turn.half
                        );
                    }
                    for (sh, _) in &part.bands {
                        let inside = rho >= sh[0] && rho <= sh[1] && z >= sh[2] && z <= sh[3];
                        if inside {
                            let ps = along.pieces(sh, (a, b), 0.0);
                            let slack = 1e-9 * (1.0 + t.abs());
                            assert!(
                                ps.iter()
                                    .any(|&(lo, hi)| lo - slack <= t && t <= hi + slack),
                                "{t} in {sh:?} outside {ps:?}"
                            );
                        }
                    }
                }
                for (sh, _) in &part.bands {
                    asked += 1;
                    let misses = turn.as_ref().is_some_and(|r| r.misses(sh));
                    let empty = along.pieces(sh, (a, b), 0.0).iter().all(|p| p.0 >= p.1);
                    passed += usize::from(!misses && !empty);
                }
            }
        }
        assert!(passed * 4 < asked, "{passed} of {asked} bands marched");
    }

    /// Every point of a rod lies within one of its bands: its distance from the axis in the
    /// band's range and its angle within the band's arc, for rods from, near and across the
    /// axis, sampled through their volume.
    #[test]
    fn a_rod_lies_within_its_bands() {
        use std::f64::consts::{PI, TAU};
        let spin = Spin {
            centre: DVec3::new(0.1, -0.2, 0.0),
            axis: DVec3::new(0.2, 0.1, 1.0).normalize(),
            omega: 1.0,
            turning: true,
            epoch: 0.0,
        };
        let u0 = spin.axis.any_orthonormal_vector();
        let across = (u0, spin.axis.cross(u0));
        let mut rng = crate::rng::Rng(3);
        let mut banded = 0;
        for _ in 0..300 {
            let mut u = |a: f64, b: f64| a + (b - a) * rng.f();
            let a = DVec3::new(u(-0.3, 0.3), u(-0.3, 0.3), u(-0.2, 0.2));
            let b = DVec3::new(u(-3.0, 3.0), u(-3.0, 3.0), u(-0.5, 0.5));
            let r = u(0.01, 0.1);
            let p = Primitive::Capsule { a, b, radius: r };
            let sh = shell(&spin, across, &p);
            let bs = bands(&spin, across, &p, sh);
            banded += usize::from(bs.len() > 1);
            for _ in 0..400 {
                let e = DVec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0));
                let x = a + u(0.0, 1.0) * (b - a) + r * e / e.length().max(1.0);
                let (rho, z, phi) = cylindrical(&spin, across, x);
                let inside = bs.iter().any(|bd| {
                    let mut off = (phi - bd[4]).rem_euclid(TAU);
                    if off > PI {
                        off = TAU - off;
                    }
                    rho >= bd[0] - 1e-12
                        && rho <= bd[1] + 1e-12
                        && z >= bd[2] - 1e-12
                        && z <= bd[3] + 1e-12
                        && off <= bd[5] + 1e-12
                });
                assert!(inside, "{x:?} of {p:?} in none of {bs:?}");
            }
        }
        assert!(banded > 100, "{banded}");
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
