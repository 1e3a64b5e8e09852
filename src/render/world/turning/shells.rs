//! What a turning part is for the march: each primitive's shell about the spin's axis (its
//! ranges of distance from the axis, of height along it and of angle about it), narrower
//! bands for rods from the hub, and the union's distance bounded from below by the shells.

use crate::geometry::{Geometry, Primitive, Spin};
use glam::DVec3;

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
pub(super) fn cylindrical(sp: &Spin, across: (DVec3, DVec3), q: DVec3) -> (f64, f64, f64) {
    let r = q - sp.centre;
    let z = r.dot(sp.axis);
    let (x, y) = (r.dot(across.0), r.dot(across.1));
    ((x * x + y * y).sqrt(), z, y.atan2(x))
}

/// Where primitive `p` lies about the axis (see [`TurningPart::shells`]).
pub(super) fn shell(sp: &Spin, across: (DVec3, DVec3), p: &Primitive) -> [f64; 6] {
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
pub(super) fn bands(
    sp: &Spin,
    across: (DVec3, DVec3),
    p: &Primitive,
    sh: [f64; 6],
) -> Vec<[f64; 6]> {
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
pub(super) fn beyond(sh: &[f64; 6], (rho, z, phi): (f64, f64, f64), best: f64) -> bool {
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

/// The signed distance of the part's shape at time 0 from `q`, and the primitive nearest.
/// Primitives whose shell lies farther than the nearest found so far are not asked.
pub(super) fn distance(geometry: &Geometry, part: &TurningPart, q: DVec3) -> (f64, u32) {
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
