//! The exact ray-primitive tests (used by the f64 BVH, by Embree's user geometry for rods and to
//! refine every Embree hit) against an independent answer: the first zero of the primitive's
//! signed distance along the ray, found by dense sampling and bisection.

use crate::common::Rng;
use glam::DVec3;
use rest_embree::geometry::Primitive;

fn capsule_distance(a: DVec3, b: DVec3, r: f64, p: DVec3) -> f64 {
    let ba = b - a;
    if ba == DVec3::ZERO {
        return (p - a).length() - r;
    }
    let s = ((p - a).dot(ba) / ba.length_squared()).clamp(0.0, 1.0);
    (p - (a + s * ba)).length() - r
}

/// The first t in (tmin, tmax) where the signed distance changes sign; None if it never does.
/// Also reports whether the ray only grazes (the distance comes within `graze` of zero without
/// a clear crossing), where either answer is acceptable.
fn first_crossing(
    dist: impl Fn(DVec3) -> f64,
    o: DVec3,
    d: DVec3,
    tmin: f64,
    tmax: f64,
) -> (Option<f64>, bool) {
    const N: usize = 40_000;
    let at = |t: f64| dist(o + t * d);
    let mut prev_t = tmin;
    let mut prev = at(tmin);
    let mut closest = prev.abs();
    for k in 1..=N {
        let t = tmin + (tmax - tmin) * k as f64 / N as f64;
        let v = at(t);
        closest = closest.min(v.abs());
        if (prev > 0.0) != (v > 0.0) {
            let (mut lo, mut hi) = (prev_t, t);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if (at(mid) > 0.0) == (prev > 0.0) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return (Some(0.5 * (lo + hi)), false);
        }
        prev_t = t;
        prev = v;
    }
    (None, closest < 1e-3)
}

#[test]
fn capsules_and_spheres_match_their_distance_functions() {
    let mut rng = Rng(7);
    let (mut checked, mut hits) = (0, 0);
    for case in 0..3000 {
        let a = DVec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        let b = if case % 10 == 0 {
            a // a degenerate capsule is a sphere
        } else if case % 3 == 1 {
            // Along x, y or z, either way (the lattices' rods).
            let mut e = DVec3::ZERO;
            e[(case / 3) % 3] = if case % 2 == 0 { 1.0 } else { -1.0 } * rng.range(0.1, 3.0);
            a + e
        } else {
            a + rng.unit() * rng.range(0.1, 3.0)
        };
        let r = rng.range(0.05, 0.8);
        let prim = if case % 7 == 0 {
            Primitive::Sphere {
                center: a,
                radius: r,
            }
        } else {
            Primitive::Capsule { a, b, radius: r }
        };
        let (o, d) = match case % 5 {
            // From inside (secondary rays leaving a transmissive rod).
            0 => (a + (b - a) * rng.f() + rng.unit() * r * 0.5, rng.unit()),
            // Exactly along the axis, from outside either end.
            1 if b != a => {
                let ax = (b - a).normalize();
                let off = if case % 2 == 0 { 0.0 } else { 0.3 * r };
                let side = ax.any_orthonormal_vector() * off;
                (a - ax * rng.range(1.0, 3.0) + side, ax)
            }
            _ => {
                let o = rng.unit() * rng.range(3.0, 6.0);
                let target = (a + b) * 0.5 + rng.unit() * rng.range(0.0, 1.5);
                (o, (target - o).normalize())
            }
        };
        // Directions of other lengths than 1, as the boosted rays have.
        let d = d * rng.range(0.2, 4.0);
        let (tmin, tmax) = (0.0, 12.0 / d.length());
        let dist = |p: DVec3| match prim {
            Primitive::Sphere { center, radius } => (p - center).length() - radius,
            Primitive::Capsule { a, b, radius } => capsule_distance(a, b, radius, p),
            _ => unreachable!(),
        };
        let (want, grazing) = first_crossing(dist, o, d, tmin, tmax);
        let got = prim.intersect(o, d, tmin, tmax);
        match (got, want) {
            (Some(g), Some(w)) => {
                assert!(
                    (g - w).abs() <= 1e-9 * w.abs().max(1.0),
                    "case {case}: {prim:?} ray {o} + t {d}: t = {g}, distance function says {w}"
                );
                hits += 1;
            }
            (None, None) => {}
            _ if grazing => continue,
            _ => panic!("case {case}: {prim:?} ray {o} + t {d}: got {got:?}, want {want:?}"),
        }
        checked += 1;
    }
    assert!(checked > 2900, "only {checked} cases decided");
    assert!(hits > 1000, "only {hits} hits: the rays should hit often");
}

/// Rods along each axis (either end first) and spheres, hit from 1e3 to 1e9 away (where the
/// boosted origins are near β → 1) with directions 1e-3 to 1e3 long (the boost's Doppler
/// factor): the entry is where the geometry puts it, t = (D − √(r² − p²)) / |d| for a ray
/// across the axis at distance D and offset p, to rounding of the origin's coordinates.
#[test]
fn far_rays_enter_where_the_geometry_says() {
    let (c, r) = (DVec3::new(0.3, -0.2, 0.1), 0.25_f64);
    let mut checked = 0;
    for k in 0..3 {
        let (mut e, mut n, mut m) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        e[k] = 1.0;
        n[(k + 1) % 3] = 1.0;
        m[(k + 2) % 3] = 1.0;
        for far in [1e3, 1e6, 1e9] {
            for scale in [1e-3, 1.0, 1e3] {
                for p in [0.0, 0.6 * r] {
                    let want = (far - (r * r - p * p).sqrt()) / scale;
                    let tol = 1e-15 * far / scale + 1e-13 / scale;
                    let prims = [
                        (
                            Primitive::Capsule {
                                a: c - 1.5 * e,
                                b: c + 1.5 * e,
                                radius: r,
                            },
                            0.4,
                        ),
                        (
                            Primitive::Capsule {
                                a: c + 1.5 * e,
                                b: c - 1.5 * e,
                                radius: r,
                            },
                            -0.7,
                        ),
                        (
                            Primitive::Sphere {
                                center: c,
                                radius: r,
                            },
                            0.0,
                        ),
                    ];
                    for (prim, along) in prims {
                        let o = c + far * n + p * m + along * e;
                        let got = prim.intersect(o, -scale * n, 0.0, f64::INFINITY);
                        let got = got.unwrap_or_else(|| panic!("{prim:?} from {o}: no hit"));
                        assert!(
                            (got - want).abs() <= tol,
                            "{prim:?} from {o} along {}: t = {got}, want {want}",
                            -scale * n
                        );
                        checked += 1;
                    }
                }
            }
        }
    }
    assert_eq!(checked, 3 * 3 * 3 * 2 * 3);
}
