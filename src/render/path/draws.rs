//! The draws the path integrator makes at every vertex, written once as straight-line f64 code
//! without branches or library calls, so that the same function serves one path at a time and,
//! inlined into a loop over the paths of a tile, lanes of them (`lanes.rs`): the compiler turns
//! such a loop into vector instructions, and each lane's numbers are the scalar call's to the bit
//! (Rust never fuses a multiply and an add on its own, and the square root and the four
//! operations are correctly rounded at every width).

use glam::DVec3;
use std::f64::consts::PI;

/// An orthonormal frame about a unit normal (Duff et al. 2017, without branches but the sign).
pub struct Basis {
    t: DVec3,
    b: DVec3,
    n: DVec3,
}

impl Basis {
    pub fn new(n: DVec3) -> Basis {
        let sign = 1f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        Basis {
            t: DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
            b: DVec3::new(b, sign + n.y * n.y * a, -n.y),
            n,
        }
    }

    pub fn to_local(&self, v: DVec3) -> DVec3 {
        DVec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }

    pub fn to_world(&self, v: DVec3) -> DVec3 {
        v.x * self.t + v.y * self.b + v.z * self.n
    }
}

/// sin and cos of 2π u, for u in [0, 1) (any finite u works: whole turns drop out), without a
/// call into libm: the turn is cut into quarters exactly (4u and its nearest whole number are
/// exact in f64), and the quarter's remainder, at most π/4 either way, goes through the Taylor
/// series of sine and cosine to the terms below 1e-19. Good to about an ulp.
#[inline(always)]
pub(crate) fn sincos_turn(u: f64) -> (f64, f64) {
    // Quarters of a turn: y = 4u = q + r, q whole, |r| ≤ ½ (exact: u has 53 bits).
    let y = 4.0 * (u - u.floor());
    let q = y.round_ties_even();
    let a = (y - q) * (0.5 * PI);
    let a2 = a * a;
    // sin a = a (1 − a²/3! + a⁴/5! − …), cos a = 1 − a²/2! + a⁴/4! − …, |a| ≤ π/4.
    let s = a
        * (1.0
            + a2 * (-1.0 / 6.0
                + a2 * (1.0 / 120.0
                    + a2 * (-1.0 / 5040.0
                        + a2 * (1.0 / 362_880.0
                            + a2 * (-1.0 / 39_916_800.0
                                + a2 * (1.0 / 6_227_020_800.0
                                    + a2 * (-1.0 / 1_307_674_368_000.0))))))));
    let c = 1.0
        + a2 * (-0.5
            + a2 * (1.0 / 24.0
                + a2 * (-1.0 / 720.0
                    + a2 * (1.0 / 40_320.0
                        + a2 * (-1.0 / 3_628_800.0
                            + a2 * (1.0 / 479_001_600.0
                                + a2 * (-1.0 / 87_178_291_200.0
                                    + a2 * (1.0 / 20_922_789_888_000.0))))))));
    // Turn (s, c) on by q quarters (q in 0..=4; 4 is a whole turn): (s, c), (c, −s), (−s, −c),
    // (−c, s). Compared as numbers, so that lanes of them stay in vector registers.
    let odd = q == 1.0 || q == 3.0;
    let (s1, c1) = if odd { (c, -s) } else { (s, c) };
    let flip = q == 2.0 || q == 3.0;
    if flip {
        (-s1, -c1)
    } else {
        (s1, c1)
    }
}

/// A direction drawn with density cos θ / π on the hemisphere about +z (local), from two
/// uniform numbers.
#[inline(always)]
pub(crate) fn cosine_dir(u1: f64, u2: f64) -> DVec3 {
    let r = u1.sqrt();
    let (s, c) = sincos_turn(u2);
    DVec3::new(r * c, r * s, (1.0 - u1).max(0.0).sqrt())
}

/// A unit direction in the cone about unit `axis` whose half-angle has 1 − cos θmax = `omc`,
/// drawn uniformly by solid angle from two uniform numbers.
#[inline(always)]
pub(crate) fn cone_dir(axis: DVec3, omc: f64, u1: f64, u2: f64) -> DVec3 {
    let basis = Basis::new(axis);
    let a = u1 * omc;
    let cos = 1.0 - a;
    let sin = (a * (2.0 - a)).max(0.0).sqrt();
    let (sp, cp) = sincos_turn(u2);
    basis.to_world(DVec3::new(sin * cp, sin * sp, cos))
}

/// 1 − cos θmax of the cone a sphere (`center`, `radius`) fills seen from `x`, without
/// cancellation for a far sphere, and whether `x` is outside it (else the cone is no use).
#[inline(always)]
pub(crate) fn sphere_cone(center: DVec3, radius: f64, x: DVec3) -> (f64, bool) {
    let d2 = (center - x).length_squared();
    let sin2 = radius * radius / d2;
    let one_minus_cos = sin2 / (1.0 + (1.0 - sin2).sqrt());
    (one_minus_cos, sin2 < 1.0 && one_minus_cos > 0.0)
}

/// A point on a sphere seen from `x` outside it, drawn uniformly in the cone it fills (its 1 −
/// cos θmax `omc`) from two uniform numbers: where the drawn direction first meets it (the
/// tangent point where rounding misses it).
#[inline(always)]
pub(crate) fn sphere_point(center: DVec3, radius: f64, x: DVec3, omc: f64, u: [f64; 2]) -> DVec3 {
    let w = center - x;
    let dc = w.length();
    let dir = cone_dir(w / dc, omc, u[0], u[1]);
    let b = dir.dot(w);
    let closest = (w - b * dir).length_squared();
    let t = b - (radius * radius - closest).max(0.0).sqrt();
    x + t * dir
}

/// The density per solid angle with which [`cosine_dir`] draws local `wi` (0 below).
#[inline(always)]
pub(crate) fn cosine_pdf(wi_z: f64) -> f64 {
    if wi_z > 0.0 {
        wi_z / PI
    } else {
        0.0
    }
}

/// The power heuristic's weight for a strategy of density `a` against one of density `b`.
#[inline(always)]
pub(crate) fn power(a: f64, b: f64) -> f64 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 {
        a2 / (a2 + b2)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against libm over many turns, the quarter points exactly.
    #[test]
    fn sincos_turn_is_libms_to_an_ulp_or_two() {
        let mut worst = 0.0f64;
        for k in 0..=1_000_000u64 {
            let u = k as f64 / 1_000_000.0;
            let (s, c) = sincos_turn(u);
            let (ws, wc) = (2.0 * PI * u).sin_cos();
            worst = worst.max((s - ws).abs()).max((c - wc).abs());
        }
        // libm's own argument 2πu is rounded: 2π · 1 carries 2.4e-16 of error.
        assert!(worst < 1e-15, "worst {worst:e}");
        assert_eq!(sincos_turn(0.0), (0.0, 1.0));
        assert_eq!(sincos_turn(0.25), (1.0, 0.0));
        assert_eq!(sincos_turn(0.5), (0.0, -1.0));
        assert_eq!(sincos_turn(0.75), (-1.0, -0.0));
        for u in [0.1, 0.3, 0.6, 0.9, 0.999_999] {
            let (s, c) = sincos_turn(u);
            assert!((s * s + c * c - 1.0).abs() < 4e-16, "{u}");
        }
    }

    /// The cone's points lie on the sphere, on the side facing `x`, and inside the cone.
    #[test]
    fn sphere_points_lie_on_the_near_side() {
        let (c, r) = (DVec3::new(0.3, 4.0, -1.0), 0.6);
        let x = DVec3::new(-2.0, -1.0, 0.5);
        let (omc, outside) = sphere_cone(c, r, x);
        assert!(outside);
        let mut rng = crate::rng::Rng(5);
        for _ in 0..10_000 {
            let p = sphere_point(c, r, x, omc, [rng.f(), rng.f()]);
            assert!(((p - c).length() - r).abs() < 1e-12);
            assert!((p - c).dot(x - c) >= -1e-9, "the near side");
        }
        assert!(!sphere_cone(c, r, c + DVec3::X * 0.1).1, "inside");
    }
}
