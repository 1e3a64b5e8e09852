//! Where along a ray a primitive of a turning part can lie: the stretches where its height and
//! distance from the axis (which the turning leaves alone) are within its shell's, and the
//! angles about the axis the turned-back point sweeps, against the shell's arc.

use super::TurningPart;
use glam::DVec3;

/// The angles about the axis that the turned-back point takes along a stretch of the ray:
/// within `half` of `mid` (in [0, 2π], where `rem_euclid` may round up to 2π itself).
pub(super) struct Turn {
    pub(super) mid: f64,
    pub(super) half: f64,
    /// Rounding's reach in the angles, which grows with the turn since the epoch.
    slack: f64,
}

impl Turn {
    /// Whether the shell's arc lies wholly outside these angles (never for a shell all
    /// around the axis). A hair of slack keeps rounding from parting an arc and a point on
    /// its edge.
    pub(super) fn misses(&self, sh: &[f64; 6]) -> bool {
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
pub(super) struct Along {
    /// Height along the axis where t = 0, and its change per unit t.
    z0: f64,
    dz: f64,
    /// The squared distance from the axis, qa (t − tv)² + m2: least, m2, at tv. In this form
    /// (not expanded in powers of t) a ray from far away keeps its distances to the axis: the
    /// expanded one loses the square of its distance from the axis to rounding.
    qa: f64,
    pub(super) tv: f64,
    m2: f64,
}

impl Along {
    /// Along `origin + t dir`: its height z0 + t dz, and w0 + t dw across the axis.
    pub(super) fn new((z0, dz): (f64, f64), (w0, dw): (DVec3, DVec3)) -> Along {
        let qa = dw.length_squared();
        let tv = if qa > 0.0 { -w0.dot(dw) / qa } else { 0.0 };
        let m2 = (w0 + tv * dw).length_squared();
        Along { z0, dz, qa, tv, m2 }
    }

    /// The squared distance from the axis at t.
    pub(super) fn rho2(&self, t: f64) -> f64 {
        let d = t - self.tv;
        self.qa * d * d + self.m2
    }

    /// Where the ray lies nearer the axis than `rho`, if it crosses that cylinder.
    pub(super) fn within(&self, rho: f64) -> Option<(f64, f64)> {
        let over = rho * rho - self.m2;
        (self.qa > 0.0 && over > 0.0).then(|| {
            let h = (over / self.qa).sqrt();
            (self.tv - h, self.tv + h)
        })
    }

    /// Whether the ray never lies within `rho` of the axis (taking one that only touches the
    /// cylinder as missing it).
    pub(super) fn outside(&self, rho: f64) -> bool {
        self.within(rho).is_none() && (self.qa > 0.0 || self.m2 > rho * rho)
    }

    /// The pieces of (a, b) where the point lies within the shell's ranges of height and of
    /// distance from the axis, widened by `tol`; at most two (the second where a shell round
    /// the axis parts the stretch in two).
    pub(super) fn pieces(
        &self,
        sh: &[f64; 6],
        (mut a, mut b): (f64, f64),
        tol: f64,
    ) -> [(f64, f64); 2] {
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

/// The angles about the axis the turned-back point takes along (a, b): those the ray's own
/// point sweeps (monotonic along a line that misses the axis, by less than π) widened by the
/// turn over that stretch of lookback. None where the ray passes the axis or starts or ends
/// on it, whose angles are any.
pub(super) fn turned_angles(
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
