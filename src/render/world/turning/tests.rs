use super::along::{turned_angles, Along};
use super::shells::{bands, beyond, cylindrical, shell};
use super::*;
use crate::geometry::Spin;

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
