use super::real::Real;
use super::Aabb;
use glam::{DVec3, Vec3Swizzles};

/// One rest-frame primitive. Boxes are axis-aligned; rods are capsules (a cylinder with round
/// caps).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum Primitive {
    /// A sphere.
    Sphere {
        /// Its centre.
        center: DVec3,
        /// Its radius.
        radius: f64,
    },
    /// A rod: the points within `radius` of the segment from `a` to `b`.
    Capsule {
        /// One end of the axis.
        a: DVec3,
        /// The other end of the axis.
        b: DVec3,
        /// The radius.
        radius: f64,
    },
    /// An axis-aligned box.
    Cuboid {
        /// The least corner.
        min: DVec3,
        /// The greatest corner.
        max: DVec3,
    },
    /// A triangle (two-sided).
    Triangle {
        /// Its corners, counter-clockwise seen from the front.
        v: [DVec3; 3],
    },
}

/// Where the ray `oc + t d` (relative to a centre) is at distance r from it, ascending: a
/// sphere, or with the components along an axis removed from both, an infinite cylinder.
/// The discriminant is a²(r² − l²) with l the closest approach, computed from a·l = a·oc − b·d
/// (nothing lost when the ray passes close by) and tested before any division or root.
fn round_roots(oc: DVec3, d: DVec3, r: f64) -> Option<(f64, f64)> {
    if d.length_squared() == 0.0 {
        return None;
    }
    let (h, t0, t1) = ball_crossings(oc.to_array(), d.to_array(), r);
    (h >= 0.0).then_some((t0, t1))
}

/// The line oc + t d (oc relative to the ball's centre, d ≠ 0) against the ball of radius r:
/// (h, t0, t1), crossings t0 ≤ t1 where h ≥ 0, none where h < 0. Without branches, so the
/// Embree backend runs it on four rays at once (`lane_hits`).
#[inline(always)]
pub(crate) fn ball_crossings<T: Real>(oc: [T; 3], d: [T; 3], r: T) -> (T, T, T) {
    let dot = |u: [T; 3], v: [T; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let a = dot(d, d);
    let b = dot(oc, d);
    // The closest approach scaled by a (no large-number cancellation for distant origins).
    let l = [
        a * oc[0] - b * d[0],
        a * oc[1] - b * d[1],
        a * oc[2] - b * d[2],
    ];
    let h = r * r * a * a - dot(l, l);
    let inv = T::splat(1.0) / a;
    let q = -(b + b.signum() * (h * inv).sqrt());
    let cc = dot(oc, oc) - r * r;
    // cc/q where q ≠ 0, else q/a again, as one division of selected operands.
    let m = q.ne_zero();
    let (t0, t1) = (
        q * inv,
        T::select(m, cc, q * inv) / T::select(m, q, T::splat(1.0)),
    );
    (h, t0.min(t1), t0.max(t1))
}

fn sphere_hit(c: DVec3, r: f64, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<f64> {
    let (t0, t1) = round_roots(o - c, d, r)?;
    [t0, t1].into_iter().find(|&t| t > tmin && t < tmax)
}

impl Primitive {
    /// The same primitive moved by `d`.
    pub fn translated(&self, d: DVec3) -> Primitive {
        match *self {
            Primitive::Sphere { center, radius } => Primitive::Sphere {
                center: center + d,
                radius,
            },
            Primitive::Capsule { a, b, radius } => Primitive::Capsule {
                a: a + d,
                b: b + d,
                radius,
            },
            Primitive::Cuboid { min, max } => Primitive::Cuboid {
                min: min + d,
                max: max + d,
            },
            Primitive::Triangle { v } => Primitive::Triangle {
                v: v.map(|p| p + d),
            },
        }
    }

    /// Its bounding box.
    pub fn bounds(&self) -> Aabb {
        match *self {
            Primitive::Sphere { center, radius } => {
                Aabb::new(center - DVec3::splat(radius), center + DVec3::splat(radius))
            }
            Primitive::Capsule { a, b, radius } => {
                let r = DVec3::splat(radius);
                Aabb::new(a.min(b) - r, a.max(b) + r)
            }
            Primitive::Cuboid { min, max } => Aabb::new(min, max),
            Primitive::Triangle { v } => {
                Aabb::new(v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]))
            }
        }
    }

    /// The first intersection of `o + t d` with `tmin < t < tmax`.
    pub fn intersect(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<f64> {
        match *self {
            Primitive::Sphere { center, radius } => sphere_hit(center, radius, o, d, tmin, tmax),
            Primitive::Capsule { a, b, radius } => capsule_hit(a, b, radius, o, d, tmin, tmax),
            Primitive::Cuboid { min, max } => cuboid_hit(min, max, o, d, tmin, tmax),
            Primitive::Triangle { v } => triangle_hit(v, o, d, tmin, tmax),
        }
    }

    /// Where `o + t d` crosses a triangle's plane, with `tmin < t < tmax`; None for the other
    /// primitives and for a ray along the plane. For a hit another test found on the triangle
    /// that [`intersect`](Self::intersect) finds just outside it: a ray at an edge the triangle
    /// shares, which meets the neighbour at that point of the plane.
    pub fn plane_crossing(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<f64> {
        let Primitive::Triangle { v } = *self else {
            return None;
        };
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        let t = (v[0] - o).dot(n) / d.dot(n);
        (t > tmin && t < tmax).then_some(t)
    }

    /// The signed distance from `p` to a solid primitive (negative inside); None for a
    /// triangle, which bounds nothing. It changes by at most |Δp| as p moves.
    pub fn distance(&self, p: DVec3) -> Option<f64> {
        Some(match *self {
            Primitive::Sphere { .. } | Primitive::Capsule { .. } => {
                let (off, radius) = self.core_offset(p)?;
                off.length() - radius
            }
            Primitive::Cuboid { min, max } => {
                let (c, h) = (0.5 * (min + max), 0.5 * (max - min));
                let q = (p - c).abs() - h;
                q.max(DVec3::ZERO).length() + q.max_element().min(0.0)
            }
            Primitive::Triangle { .. } => return None,
        })
    }

    /// For a sphere or a rod: `p`'s offset from the nearest point of its centre (a rod's
    /// centre segment), and its radius; its signed distance is the offset's length less the
    /// radius, and the offset's direction the distance's gradient. None for other primitives.
    pub fn core_offset(&self, p: DVec3) -> Option<(DVec3, f64)> {
        match *self {
            Primitive::Sphere { center, radius } => Some((p - center, radius)),
            Primitive::Capsule { a, b, radius } => {
                let ab = b - a;
                let h =
                    ((p - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
                Some((p - (a + h * ab), radius))
            }
            _ => None,
        }
    }

    /// The outward geometric normal at a point on the surface (unit).
    pub fn normal(&self, p: DVec3) -> DVec3 {
        match *self {
            Primitive::Sphere { center, .. } => (p - center).normalize_or(DVec3::Z),
            Primitive::Capsule { a, b, .. } => {
                // From the segment's nearest point: along a rod on an axis, p clamped to the
                // segment's box (no division). Off the axis lo and hi agree, so that is the
                // rod's own coordinate there; written whole, not as one component set by a
                // run-time index, whose store stalled the read of the vector after it.
                let nearest = match AxisRod::of(a, b) {
                    Some(rod) => p.max(rod.lo).min(rod.hi),
                    None => {
                        let ab = b - a;
                        let s = ((p - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE))
                            .clamp(0.0, 1.0);
                        a + s * ab
                    }
                };
                (p - nearest).normalize_or(DVec3::Z)
            }
            Primitive::Cuboid { min, max } => {
                let c = 0.5 * (min + max);
                let h = (0.5 * (max - min)).max(DVec3::splat(f64::MIN_POSITIVE));
                let q = (p - c) / h;
                let aq = q.abs();
                // The face whose axis the point is farthest along (x before y before z on a
                // tie), chosen without branches: which face a ray meets is a coin toss to a
                // branch predictor.
                let x = aq.x >= aq.y && aq.x >= aq.z;
                let y = !x && aq.y >= aq.z;
                let z = !x && !y;
                DVec3::new(
                    if x { q.x.signum() } else { 0.0 },
                    if y { q.y.signum() } else { 0.0 },
                    if z { q.z.signum() } else { 0.0 },
                )
            }
            Primitive::Triangle { v } => (v[1] - v[0]).cross(v[2] - v[0]).normalize_or(DVec3::Z),
        }
    }
}

/// The capsule (points within r of the segment ab) is convex, so the ray meets it on one
/// interval: it enters where it enters the infinite cylinder if that point lies beside the
/// segment, else where it enters the end ball on that side; likewise for the exit.
///
/// A rod along x, y or z (every rod of a lattice) takes [`aligned_capsule_hit`]: the same
/// arithmetic with the axis's components known to be zero. It is here because the Embree
/// backend tests such rods four rays at a time with the same [`cylinder_crossings`], and the
/// two must agree to the bit.
#[inline]
pub(crate) fn capsule_hit(
    a: DVec3,
    b: DVec3,
    r: f64,
    o: DVec3,
    d: DVec3,
    tmin: f64,
    tmax: f64,
) -> Option<f64> {
    match AxisRod::of(a, b) {
        Some(rod) => aligned_capsule_hit(&rod, r, o, d, tmin, tmax),
        None => any_capsule_hit(a, b, r, o, d, tmin, tmax),
    }
}

/// A rod's segment along a coordinate axis: a and b differ in component `k` alone. Its ends
/// in order along the axis (a capsule is symmetric in its two), `len = hi[k] − lo[k] > 0`.
/// The scalar test and the Embree backend's four-ray test both start from here, so they
/// start from the same numbers.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AxisRod {
    pub k: usize,
    pub lo: DVec3,
    pub hi: DVec3,
    pub len: f64,
}

impl AxisRod {
    #[inline(always)]
    pub fn of(a: DVec3, b: DVec3) -> Option<AxisRod> {
        let ba = b - a;
        let k = match (ba.x != 0.0, ba.y != 0.0, ba.z != 0.0) {
            (true, false, false) => 0,
            (false, true, false) => 1,
            (false, false, true) => 2,
            _ => return None,
        };
        let (lo, hi) = if a[k] < b[k] { (a, b) } else { (b, a) };
        Some(AxisRod {
            k,
            lo,
            hi,
            len: hi[k] - lo[k],
        })
    }
}

/// [`capsule_hit`] for a rod along a coordinate axis. It is the general test with ba = L e_k: there dp = L² d⊥, op = L² o⊥ and every quantity carries
/// a power of L that cancels in the roots, so the values are the same up to rounding.
#[inline(always)]
fn aligned_capsule_hit(
    rod: &AxisRod,
    r: f64,
    o: DVec3,
    d: DVec3,
    tmin: f64,
    tmax: f64,
) -> Option<f64> {
    // Components rotated so the axis is x (swizzles stay in registers; indexing by k would not).
    let (lo, hi, ro, dr) = match rod.k {
        0 => (rod.lo, rod.hi, o, d),
        1 => (rod.lo.yzx(), rod.hi.yzx(), o.yzx(), d.yzx()),
        _ => (rod.lo.zxy(), rod.hi.zxy(), o.zxy(), d.zxy()),
    };
    let oa = ro - lo;
    let rr = r * r;
    if dr.y * dr.y + dr.z * dr.z == 0.0 {
        // Along the axis (the capsule is the same with its ends either way round).
        return any_capsule_hit(rod.lo, rod.hi, r, o, d, tmin, tmax);
    }
    let (h, c0, c1) = cylinder_crossings(oa.y, oa.z, dr.y, dr.z, rr);
    if h < 0.0 {
        return None;
    }
    let ends = (ro - lo, ro - hi);
    beside_or_ends(
        c0,
        c1,
        |t| oa.x + t * dr.x,
        rod.len,
        ends,
        dr,
        r,
        tmin,
        tmax,
    )
}

/// A capsule's first crossing in (tmin, tmax) from its infinite cylinder's crossings c0 ≤ c1:
/// where a crossing's position along the axis, `axial(t)`, lies beyond the segment (0, end), the
/// end ball on that side decides instead (`ends`: the ray's origin from the lower end's centre
/// and from the upper's).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn beside_or_ends(
    c0: f64,
    c1: f64,
    axial: impl Fn(f64) -> f64,
    end: f64,
    ends: (DVec3, DVec3),
    d: DVec3,
    r: f64,
    tmin: f64,
    tmax: f64,
) -> Option<f64> {
    let ball = |t: f64| {
        let y = axial(t);
        (y <= 0.0 || y >= end).then(|| round_roots(if y <= 0.0 { ends.0 } else { ends.1 }, d, r))
    };
    let t_in = match ball(c0) {
        None => c0,
        Some(roots) => roots?.0,
    };
    if t_in > tmin {
        return (t_in < tmax).then_some(t_in);
    }
    let t_out = match ball(c1) {
        None => c1,
        Some(roots) => roots?.1,
    };
    [t_in, t_out].into_iter().find(|&t| t > tmin && t < tmax)
}

/// The line (ou, ov) + t (du, dv) in the plane across a rod's axis (relative to the axis,
/// (du, dv) ≠ 0) against the circle of radius² rr, that is the line against the rod's infinite
/// cylinder: (h, c0, c1), crossings c0 ≤ c1 where h ≥ 0, none where h < 0. Without branches,
/// so the Embree backend runs it on several rays at once (`lane_hits`).
#[inline(always)]
pub(crate) fn cylinder_crossings<T: Real>(ou: T, ov: T, du: T, dv: T, rr: T) -> (T, T, T) {
    let qa = du * du + dv * dv;
    let qb = ou * du + ov * dv;
    // The closest approach scaled by qa; its discriminant qa·(rr − distance²) comes first.
    let (lu, lv) = (qa * ou - qb * du, qa * ov - qb * dv);
    let h = rr * qa * qa - (lu * lu + lv * lv);
    // The roots q/qa and c/q with q = -(qb ± sqrt(h/qa)), here multiplied through by sqrt(qa)
    // so the square roots come first and one division follows them (not division, root,
    // division in a chain).
    let s = qa.sqrt();
    let qs = -(qb * s + qb.signum() * h.sqrt());
    let t0 = qs / (qa * s);
    // c/q where q ≠ 0, else t0 again; as one division of selected operands (a select between
    // two divisions would be compiled as a branch).
    let m = qs.ne_zero();
    let t1 = T::select(m, (ou * ou + ov * ov - rr) * s, qs) / T::select(m, qs, qa * s);
    (h, t0.min(t1), t0.max(t1))
}

/// [`capsule_hit`] for a rod in any direction.
#[inline(always)]
fn any_capsule_hit(
    a: DVec3,
    b: DVec3,
    r: f64,
    o: DVec3,
    d: DVec3,
    tmin: f64,
    tmax: f64,
) -> Option<f64> {
    let ba = b - a;
    let oa = o - a;
    let baba = ba.length_squared();
    if baba == 0.0 {
        return sphere_hit(a, r, o, d, tmin, tmax);
    }
    let bard = ba.dot(d);
    let baoa = ba.dot(oa);
    // Perpendicular to the axis and scaled by |ba|² (no division, no large-number cancellation).
    let dp = baba * d - bard * ba;
    let op = baba * oa - baoa * ba;
    let rr = r * r * baba * baba;
    let qa = dp.length_squared();
    if qa == 0.0 {
        // Along the axis: in through one end ball, out through the other.
        if op.length_squared() > rr {
            return None;
        }
        let (first, last) = if bard > 0.0 { (a, b) } else { (b, a) };
        let (t_in, t_out) = (
            round_roots(o - first, d, r)?.0,
            round_roots(o - last, d, r)?.1,
        );
        return [t_in, t_out].into_iter().find(|&t| t > tmin && t < tmax);
    }
    // The infinite cylinder: qa·t² + 2qb·t + |op|² − rr = 0. Its discriminant, qa·(rr − l²)
    // with l the closest approach, is tested before any division or root.
    let qb = op.dot(dp);
    let l = qa * op - qb * dp;
    let h = rr * qa * qa - l.length_squared();
    if h < 0.0 {
        return None;
    }
    let inv = 1.0 / qa;
    let q = -(qb + qb.signum() * (h * inv).sqrt());
    let (u, v) = (
        q * inv,
        if q != 0.0 {
            (op.length_squared() - rr) / q
        } else {
            q * inv
        },
    );
    let (c0, c1) = (u.min(v), u.max(v));
    beside_or_ends(
        c0,
        c1,
        |t| baoa + t * bard,
        baba,
        (o - a, o - b),
        d,
        r,
        tmin,
        tmax,
    )
}

/// The first crossing of an axis-aligned box's surface (entry, or exit from inside).
pub(crate) fn cuboid_hit(
    min: DVec3,
    max: DVec3,
    o: DVec3,
    d: DVec3,
    tmin: f64,
    tmax: f64,
) -> Option<f64> {
    let inv = d.recip();
    let a = (min - o) * inv;
    let bb = (max - o) * inv;
    let lo = a.min(bb);
    let hi = a.max(bb);
    let t0 = lo.x.max(lo.y).max(lo.z);
    let t1 = hi.x.min(hi.y).min(hi.z);
    if t0 > t1 {
        return None;
    }
    [t0, t1].into_iter().find(|&t| t > tmin && t < tmax)
}

fn triangle_hit(v: [DVec3; 3], o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<f64> {
    let e1 = v[1] - v[0];
    let e2 = v[2] - v[0];
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - v[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let w = d.dot(q) * inv;
    if w < 0.0 || u + w > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > tmin && t < tmax).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::Primitive;
    use glam::DVec3;

    /// A triangle's plane crossing: where `intersect` meets it, the same t; beside it, where
    /// the ray crosses the plane; along the plane, behind the interval and for a solid, none.
    #[test]
    fn plane_crossings() {
        let tri = Primitive::Triangle {
            v: [
                DVec3::new(0.0, 0.0, 1.0),
                DVec3::new(1.0, 0.0, 2.0),
                DVec3::new(0.0, 1.0, 1.0),
            ],
        };
        let o = DVec3::new(0.2, 0.3, -3.0);
        let d = DVec3::new(0.0, 0.0, 2.0);
        let inside = tri.intersect(o, d, 0.0, 10.0).unwrap();
        assert_eq!(tri.plane_crossing(o, d, 0.0, 10.0), Some(inside));
        // z = 1 + x on the plane: from (1.5, 0.3, -3) along +z it is crossed at z = 2.5.
        let beside = DVec3::new(1.5, 0.3, -3.0);
        assert_eq!(tri.intersect(beside, d, 0.0, 10.0), None);
        assert_eq!(tri.plane_crossing(beside, d, 0.0, 10.0), Some(2.75));
        assert_eq!(tri.plane_crossing(beside, d, 0.0, 2.5), None);
        assert_eq!(
            tri.plane_crossing(o, DVec3::new(1.0, 0.0, 1.0), 0.0, 10.0),
            None
        );
        let ball = Primitive::Sphere {
            center: DVec3::ZERO,
            radius: 1.0,
        };
        assert_eq!(ball.plane_crossing(o, d, 0.0, 10.0), None);
    }

    /// A capsule's normal at points of its surface: across the axis beside the segment, and
    /// from the end ball's centre beyond either end; for rods along each axis (either end first)
    /// and one along no axis.
    #[test]
    fn capsule_normals() {
        let a = DVec3::new(0.3, -1.2, 2.5);
        let r = 0.25;
        let along = [
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, -3.0, 0.0),
            DVec3::new(0.0, 0.0, 1.5),
            DVec3::new(1.0, 2.0, -2.0),
        ];
        for ab in along {
            for (a, b) in [(a, a + ab), (a + ab, a)] {
                let rod = Primitive::Capsule { a, b, radius: r };
                let axis = (b - a).normalize();
                let across = axis.any_orthonormal_vector();
                for (s, side) in [(0.3, across), (0.9, -across), (0.5, axis.cross(across))] {
                    let p = a + s * (b - a) + r * side;
                    assert!((rod.normal(p) - side).length() < 1e-12, "{a} {b} at {p}");
                }
                // Beyond the ends: from the end ball's centre.
                let out = (across - axis).normalize();
                assert!((rod.normal(a + r * out) - out).length() < 1e-12);
                let out = (across + axis).normalize();
                assert!((rod.normal(b + r * out) - out).length() < 1e-12);
            }
        }
    }
}
