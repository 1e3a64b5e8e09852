//! Groups on a segment of constant proper acceleration, intersected exactly (docs/physics.md
//! §12.7). In the frame S' the segment starts at rest in, with the origin's start event at
//! (0, 0) and â the acceleration's direction, a point of the body with shape coordinates
//! (ξ, y) (ξ along â, y across) is at `x = (1/a + ξ) cosh θ − 1/a`, `T = (1/a + ξ) sinh θ` at
//! the origin's rapidity θ: the body is still in Rindler coordinates (ρ = 1/a + ξ, θ, y).
//! Along a past-directed null ray `x∥² − T² + |y|²` is linear in the lookback (the null
//! condition cancels its square), so a sphere's or a plane's equation in (ξ, y), with
//! `a ξ² + 2 ξ = 2 x∥ + a (x∥² − T²)` tying ξ to the ray, is a quadratic in the lookback:
//! a closed form, written so that a → 0 gives the static one.
//!
//! The rays reaching here start on the segment's start hyperplane (T = 0, `World::rest_ray`
//! moves them there), so T = −|d| t along `origin + t dir`.

use crate::accel::{Hit, Ray};
use crate::geometry::{Aabb, Geometry, Primitive};
use crate::scene::Accelerated;
use crate::spacetime::{cosh_m1, Boost, Velocity};
use glam::DVec3;

/// The box in S' that holds the body through the segment: its shape at the start, and moved
/// along â by as much as its farthest point goes, `(1/a + ξ_max)(cosh θ_end − 1)`.
pub(crate) fn swept_bounds(acc: &Accelerated, shape: Aabb) -> Aabb {
    let start = Aabb::new(shape.min + acc.start.x, shape.max + acc.start.x);
    let reach = (1.0 / acc.a + shape.support(acc.axis)) * cosh_m1(acc.theta_end);
    let end = Aabb::new(start.min + reach * acc.axis, start.max + reach * acc.axis);
    start.union(&end)
}

/// The roots of `A t² + B t + C` in ascending order (a linear equation where A is 0), by the
/// form that loses nothing when A is small.
fn roots(a: f64, b: f64, c: f64) -> [f64; 2] {
    const NONE: [f64; 2] = [f64::NAN, f64::NAN];
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 || !disc.is_finite() {
        return NONE;
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    if q == 0.0 {
        return if a == 0.0 { NONE } else { [0.0, 0.0] };
    }
    let (r0, r1) = (c / q, if a == 0.0 { f64::NAN } else { q / a });
    if r1 < r0 {
        [r1, r0]
    } else {
        [r0, r1]
    }
}

/// One ray in the segment's terms: relative to the origin's start, split along and across â.
struct Local {
    a: f64,
    axis: DVec3,
    /// Start along â, and across.
    x0: f64,
    w0: DVec3,
    /// Direction along â, and across; s = |dir|.
    dx: f64,
    dw: DVec3,
    s: f64,
    /// The origin's rapidity at the segment's end: along the ray within the segment, the
    /// point in shape space moves at most s (1 + e^θ_end) per unit of lookback.
    theta_end: f64,
}

impl Local {
    fn new(acc: &Accelerated, ray: &Ray) -> Local {
        let p0 = ray.origin - acc.start.x;
        let x0 = p0.dot(acc.axis);
        let dx = ray.dir.dot(acc.axis);
        Local {
            a: acc.a,
            axis: acc.axis,
            x0,
            w0: p0 - x0 * acc.axis,
            dx,
            dw: ray.dir - dx * acc.axis,
            s: ray.len,
            theta_end: acc.theta_end,
        }
    }

    /// 2x∥ + a(x∥² − T²) at t, whose root ξ is the shape coordinate along â; and x∥, T.
    fn k(&self, t: f64) -> (f64, f64, f64) {
        let x = self.x0 + t * self.dx;
        let time = -self.s * t;
        (2.0 * x + self.a * (x - time) * (x + time), x, time)
    }

    /// Whether the event at t lies in the right wedge (ahead of the horizon, at |T| < 1/a + x),
    /// and there the body's point: its shape coordinates.
    fn shape_point(&self, t: f64) -> Option<DVec3> {
        let (k, x, time) = self.k(t);
        let ahead = 1.0 + self.a * x;
        if ahead <= self.a * time.abs() {
            return None;
        }
        let xi = k / (1.0 + (1.0 + self.a * k).max(0.0).sqrt());
        Some(xi * self.axis + self.w0 + t * self.dw)
    }

    /// The origin's rapidity at the event at t (T / (1/a + x) = tanh θ).
    fn theta(&self, t: f64) -> f64 {
        let (_, x, time) = self.k(t);
        (self.a * time / (1.0 + self.a * x)).atanh()
    }

    /// The first lookback in (from, to) where the ray's point in shape space reaches the solid
    /// primitive `prim` (of size `size`), by sphere tracing: across the segment (θ in
    /// [0, θ_end]) the point moves at most s (1 + e^θ_end) per unit of lookback (|ξ′| =
    /// s |d∥X + sT|/ρ ≤ s e^|θ|, |y′| ≤ s), so steps of the distance over that pass no surface.
    /// A ray that needs more than 20,000 steps (grazing it) is taken to miss.
    fn march(&self, prim: &Primitive, from: f64, to: f64, size: f64) -> Option<f64> {
        let lipschitz = self.s * (1.0 + self.theta_end.exp());
        let tol = 1e-10 * size.max(1e-300);
        let mut t = from;
        for _ in 0..20_000 {
            if t >= to {
                return None;
            }
            let d = prim.distance(self.shape_point(t)?)?;
            if d < tol {
                return Some(t);
            }
            t += d / lipschitz;
        }
        None
    }

    /// The sphere of shape centre c, radius r: the lookbacks where the ray meets it.
    fn sphere(&self, c: DVec3, r: f64) -> [f64; 2] {
        let a = self.a;
        let cx = c.dot(self.axis);
        let w0 = self.w0 - (c - cx * self.axis);
        let (x0, dx, dw) = (self.x0, self.dx, self.dw);
        let m0 = x0 * x0 + w0.length_squared() + cx * cx - r * r;
        let m1 = 2.0 * (x0 * dx + w0.dot(dw));
        let den = 1.0 + a * cx;
        let p = (2.0 * x0 + a * m0) / (2.0 * den);
        let q = (2.0 * dx + a * m1) / (2.0 * den);
        let qa = q * q + dw.length_squared();
        let qb = 2.0 * p * q + (2.0 * w0.dot(dw) - 2.0 * cx * dx - 2.0 * a * cx * x0 * dx) / den;
        let qc = p * p
            + (w0.length_squared() + cx * cx - r * r - 2.0 * cx * x0 - a * cx * x0 * x0) / den;
        let mut rs = roots(qa, qb, qc);
        // A root of the squared equation is the sphere's where ρ = 1/a + ξ is positive.
        for t in &mut rs {
            if 1.0 + a * (p + q * *t) <= 0.0 {
                *t = f64::NAN;
            }
        }
        rs
    }

    /// The plane n·P = h of shape space (n unit): the lookbacks where the ray meets it.
    fn plane(&self, n: DVec3, h: f64) -> [f64; 2] {
        let a = self.a;
        let nx = n.dot(self.axis);
        let nw = n - nx * self.axis;
        // n∥ ξ = u(t) = h − n⊥·y(t); with a ξ² + 2ξ = K(t), times n∥²: a u² + 2 n∥ u − n∥² K = 0.
        let (u0, u1) = (h - nw.dot(self.w0), -nw.dot(self.dw));
        if nx == 0.0 {
            // A plane along â: y alone decides, and y is linear along the ray.
            return [-u0 / u1, f64::NAN];
        }
        let (x0, dx) = (self.x0, self.dx);
        let dw2 = self.dw.length_squared();
        // K = 2x + a(x² − T²) = k0 + k1 t + k2 t², k2 = −a|d⊥|² (null: dx² − s² = −|d⊥|²).
        let (k0, k1, k2) = (
            2.0 * x0 + a * x0 * x0,
            2.0 * dx + 2.0 * a * x0 * dx,
            -a * dw2,
        );
        let n2 = nx * nx;
        let qa = a * u1 * u1 - n2 * k2;
        let qb = 2.0 * a * u0 * u1 + 2.0 * nx * u1 - n2 * k1;
        let qc = a * u0 * u0 + 2.0 * nx * u0 - n2 * k0;
        let mut rs = roots(qa, qb, qc);
        for t in &mut rs {
            // The root on the far branch ξ < −1/a (behind the horizon) is not the body's.
            if (nx + a * (u0 + u1 * *t)) * nx < 0.0 {
                *t = f64::NAN;
                continue;
            }
            // Where n∥ is small the squared equation's roots crowd together and lose digits:
            // two Newton steps on u(t) − n∥ ξ(t), with ξ' = K'/(2(1 + a ξ)), restore them.
            for _ in 0..2 {
                let (k, x, _) = self.k(*t);
                let xi = k / (1.0 + (1.0 + a * k).max(0.0).sqrt());
                let dk = 2.0 * dx + 2.0 * a * (x * dx - self.s * self.s * *t);
                let f = u0 + u1 * *t - nx * xi;
                let df = u1 - nx * dk / (2.0 * (1.0 + a * xi));
                if df != 0.0 && f.is_finite() {
                    *t -= f / df;
                }
            }
        }
        rs
    }
}

/// Whether `p` lies in triangle v (on its plane, to rounding).
fn in_triangle(v: &[DVec3; 3], p: DVec3) -> bool {
    let n = (v[1] - v[0]).cross(v[2] - v[0]);
    let edge = |i: usize| (v[(i + 1) % 3] - v[i]).cross(p - v[i]).dot(n) >= 0.0;
    edge(0) && edge(1) && edge(2)
}

/// The lookbacks in (tmin, tmax) where the ray meets primitive `prim`, and the point there.
fn crossings(l: &Local, prim: &Primitive, tmin: f64, tmax: f64, mut found: impl FnMut(f64)) {
    let mut keep = |t: f64, inside: &dyn Fn(DVec3) -> bool| {
        if t > tmin && t < tmax {
            if let Some(p) = l.shape_point(t) {
                if inside(p) {
                    found(t);
                }
            }
        }
    };
    match *prim {
        Primitive::Sphere { center, radius } => {
            for t in l.sphere(center, radius) {
                keep(t, &|_| true);
            }
        }
        Primitive::Triangle { v } => {
            let n = (v[1] - v[0]).cross(v[2] - v[0]);
            let len = n.length();
            if len == 0.0 {
                return;
            }
            let n = n / len;
            for t in l.plane(n, n.dot(v[0])) {
                keep(t, &|p| in_triangle(&v, p));
            }
        }
        Primitive::Cuboid { min, max } => {
            let tol = 1e-9 * (max - min).max_element().max(f64::MIN_POSITIVE);
            for k in 0..3 {
                let mut n = DVec3::ZERO;
                n[k] = 1.0;
                for h in [min[k], max[k]] {
                    for t in l.plane(n, h) {
                        keep(t, &|p| {
                            (0..3).all(|j| j == k || (p[j] >= min[j] - tol && p[j] <= max[j] + tol))
                        });
                    }
                }
            }
        }
        // A rod's surface meets the ray's path through shape space in a quartic: marched,
        // within the ball about the rod where the closed form puts the path.
        Primitive::Capsule { a, b, radius } => {
            let half = 0.5 * (b - a).length() + radius;
            let [t0, t1] = l.sphere(0.5 * (a + b), half);
            if !(t0.is_finite() && t1.is_finite()) {
                return;
            }
            if let Some(t) = l.march(prim, t0.max(tmin), t1.min(tmax), half) {
                keep(t, &|_| true);
            }
        }
    }
}

/// The first primitive of `geometry` on the ray (the smallest lookback: the latest emission).
pub(super) fn intersect(acc: &Accelerated, geometry: &Geometry, ray: &Ray) -> Option<Hit> {
    if !ray.is_active() {
        return None;
    }
    let l = Local::new(acc, ray);
    let mut best: Option<Hit> = None;
    for i in 0..geometry.len() {
        let tmax = best.map_or(ray.tmax, |h| h.t);
        crossings(&l, &geometry.prim(i), ray.tmin, tmax, |t| {
            if best.is_none_or(|h| t < h.t) {
                best = Some(Hit { t, prim: i });
            }
        });
    }
    best
}

/// Whether anything of `geometry` lies on the ray.
pub(super) fn occluded(acc: &Accelerated, geometry: &Geometry, ray: &Ray) -> bool {
    if !ray.is_active() {
        return false;
    }
    let l = Local::new(acc, ray);
    let mut any = false;
    for i in 0..geometry.len() {
        crossings(&l, &geometry.prim(i), ray.tmin, ray.tmax, |_| any = true);
        if any {
            return true;
        }
    }
    false
}

/// A hit at t on the ray, seen in its point's frame: the shape point, the boost from S' into
/// the frame moving with the point (rapidity θ along â), and the ray's direction there with
/// its length the lookback factor, as `World::spun` gives a spinning point's.
pub(super) fn point_frame(acc: &Accelerated, ray: &Ray, t: f64) -> (DVec3, Boost, DVec3, f64) {
    let l = Local::new(acc, ray);
    let point = l
        .shape_point(t)
        .unwrap_or(ray.origin + t * ray.dir - acc.start.x);
    let boost = boost_at(acc, l.theta(t));
    let (d, s) = boost.null_dir(ray.dir / ray.len);
    (point, boost, d * ray.len, s * ray.len)
}

/// The boost from S' into the frame moving with the body at the origin's rapidity θ.
pub(crate) fn boost_at(acc: &Accelerated, theta: f64) -> Boost {
    match Velocity::from_rapidity(acc.axis, theta.abs()) {
        Ok(v) if theta >= 0.0 => Boost::to_rest(&v),
        Ok(v) => Boost::to_rest(&v.reversed()),
        Err(_) => Boost::IDENTITY,
    }
}

/// The boost from S' into the frame moving with the body at event `e` (given in S'): the
/// origin's rapidity there is artanh(a T / (1 + a x∥)).
pub(crate) fn point_boost(acc: &Accelerated, e: crate::spacetime::Event) -> Boost {
    let rel = e - acc.start;
    boost_at(
        acc,
        (acc.a * rel.t / (1.0 + acc.a * rel.x.dot(acc.axis))).atanh(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spacetime::Event;

    fn acc(a: f64) -> Accelerated {
        Accelerated {
            start: Event::new(0.0, DVec3::new(1.0, -2.0, 0.5)),
            a,
            axis: DVec3::new(0.6, 0.0, 0.8),
            theta_end: 2.0,
        }
    }

    /// A ray from a hyperplane T = 0 event, looking along `look` (unit).
    fn ray(acc: &Accelerated, from: DVec3, look: DVec3) -> Ray {
        Ray::new(acc.start.x + from, look, -1e3, 1e3)
    }

    /// Every root found is on the body's point: that point's Rindler event is the ray's.
    #[test]
    fn hits_lie_on_the_shape_at_the_rays_event() {
        let acc = acc(0.3);
        let geo = {
            let mut g = Geometry::default();
            g.push_part(
                0,
                0,
                [Primitive::Sphere {
                    center: DVec3::new(0.5, 0.2, 1.0),
                    radius: 0.7,
                }],
            );
            g.push_part(
                1,
                0,
                [Primitive::Cuboid {
                    min: DVec3::new(-2.0, 1.0, -1.0),
                    max: DVec3::new(-1.0, 2.0, 0.0),
                }],
            );
            g
        };
        let mut hits = 0;
        for i in 0..400 {
            let u = i as f64 * 0.618_033_988_75;
            let look = DVec3::new(
                u.cos() * (0.3 * u).sin(),
                u.sin() * (0.3 * u).sin(),
                (0.3 * u).cos(),
            );
            let from = DVec3::new(0.2, 0.1, 0.3) - 6.0 * look;
            let r = ray(&acc, from, look);
            let Some(h) = intersect(&acc, &geo, &r) else {
                continue;
            };
            hits += 1;
            let (p, ..) = point_frame(&acc, &r, h.t);
            // The point's event, from its shape coordinates and θ, is the ray's.
            let theta = Local::new(&acc, &r).theta(h.t);
            let xi = p.dot(acc.axis);
            let rho = 1.0 / acc.a + xi;
            let across = p - xi * acc.axis;
            let e_x = (rho * theta.cosh() - 1.0 / acc.a) * acc.axis + across;
            let e_t = rho * theta.sinh();
            let on_ray = r.origin + h.t * r.dir - acc.start.x;
            assert!((e_x - on_ray).length() < 1e-9, "{e_x} against {on_ray}");
            assert!((e_t + h.t).abs() < 1e-9, "{e_t} against {}", -h.t);
            // And on the primitive's surface.
            let prim = geo.prim(h.prim);
            let d = match prim {
                Primitive::Sphere { center, radius } => ((p - center).length() - radius).abs(),
                Primitive::Cuboid { min, max } => {
                    let q = (p - min).min(max - p);
                    q.min_element().abs()
                }
                _ => unreachable!(),
            };
            assert!(
                d < 1e-9,
                "off the surface by {d}: {prim:?} at {p}, t {}",
                h.t
            );
        }
        assert!(hits > 15, "{hits}");
    }

    /// As a → 0 the roots are the static ones.
    #[test]
    fn tiny_accelerations_meet_the_static_shapes() {
        for a in [1e-4, 1e-7, 1e-10] {
            let acc = acc(a);
            let l_look = DVec3::new(0.1, 0.2, -0.9).normalize();
            let r = ray(&acc, DVec3::new(0.0, 0.0, 5.0), l_look);
            let l = Local::new(&acc, &r);
            let c = DVec3::new(0.3, 0.1, 0.2);
            let prim = Primitive::Sphere {
                center: c,
                radius: 1.0,
            };
            let want = prim
                .intersect(r.origin - acc.start.x, r.dir, -1e3, 1e3)
                .unwrap();
            let got = l.sphere(c, 1.0)[0];
            assert!((got - want).abs() < 1e3 * a, "a {a}: {got} against {want}");
            let n = DVec3::new(0.0, 0.6, 0.8);
            let got = l.plane(n, 0.3).into_iter().find(|t| t.is_finite()).unwrap();
            let p0 = r.origin - acc.start.x;
            let want = (0.3 - n.dot(p0)) / n.dot(r.dir);
            assert!((got - want).abs() < 1e3 * a, "a {a}: {got} against {want}");
        }
    }
}
