//! One conformance suite that every intersection backend must pass (after svenstaro/bvh's
//! testbase): analytic hits of each primitive kind, tmin/tmax and masking rules, batches of any
//! size, and agreement with brute force on random scenes.

use super::Rng;
use glam::DVec3;
use rest_embree::accel::{Accelerator, Backend, Hit, Ray};
use rest_embree::geometry::{Geometry, Primitive};
use std::sync::Arc;

/// How exact a backend must be: relative error in t, and the share of random rays allowed to
/// disagree with brute force on hit/miss (grazing rays, f32 backends).
pub struct Tolerance {
    pub t_rel: f64,
    pub mismatch: f64,
}

fn build(backend: &dyn Backend, prims: Vec<Primitive>) -> Box<dyn Accelerator> {
    let mut g = Geometry::default();
    g.push_part(0, 0, prims);
    backend.build(Arc::new(g)).expect("backend builds")
}

fn ray(o: DVec3, d: DVec3) -> Ray {
    Ray::new(o, d, 0.0, f64::INFINITY)
}

fn one(a: &dyn Accelerator, r: Ray) -> Option<Hit> {
    let mut h = [None];
    a.intersect(&[r], &mut h);
    h[0]
}

fn occ(a: &dyn Accelerator, r: Ray) -> bool {
    let mut o = [false];
    a.occluded(&[r], &mut o);
    o[0]
}

fn expect_t(a: &dyn Accelerator, r: Ray, t: f64, tol: &Tolerance, what: &str) {
    let h = one(a, r).unwrap_or_else(|| panic!("{what}: expected a hit at t = {t}, got none"));
    assert!(
        (h.t - t).abs() <= tol.t_rel * t.abs().max(1.0),
        "{what}: t = {}, expected {t}",
        h.t
    );
}

pub fn analytic_hits(backend: &dyn Backend, tol: &Tolerance) {
    let sphere = build(
        backend,
        vec![Primitive::Sphere {
            center: DVec3::new(0.0, 0.0, 10.0),
            radius: 1.0,
        }],
    );
    expect_t(
        &*sphere,
        ray(DVec3::ZERO, DVec3::Z),
        9.0,
        tol,
        "sphere, unit direction",
    );
    // Unnormalised directions: t is in units of the direction's length (lookback time).
    expect_t(
        &*sphere,
        ray(DVec3::ZERO, 2.0 * DVec3::Z),
        4.5,
        tol,
        "sphere, direction of length 2",
    );
    expect_t(
        &*sphere,
        ray(DVec3::new(0.0, 0.0, 10.0), DVec3::Z),
        1.0,
        tol,
        "sphere from inside",
    );
    assert!(
        one(&*sphere, ray(DVec3::new(1.01, 0.0, 0.0), DVec3::Z)).is_none(),
        "sphere: ray passing by"
    );
    assert!(
        one(&*sphere, ray(DVec3::ZERO, -DVec3::Z)).is_none(),
        "sphere behind the ray"
    );

    let rod = build(
        backend,
        vec![Primitive::Capsule {
            a: DVec3::new(-1.0, 0.0, 5.0),
            b: DVec3::new(1.0, 0.0, 5.0),
            radius: 0.5,
        }],
    );
    expect_t(&*rod, ray(DVec3::ZERO, DVec3::Z), 4.5, tol, "rod side");
    let cap = 5.0 - (0.25f64 - 0.04).sqrt();
    expect_t(
        &*rod,
        ray(DVec3::new(1.2, 0.0, 0.0), DVec3::Z),
        cap,
        tol,
        "rod round cap",
    );
    assert!(
        one(&*rod, ray(DVec3::new(1.6, 0.0, 0.0), DVec3::Z)).is_none(),
        "rod: beyond the cap"
    );
    expect_t(
        &*rod,
        ray(DVec3::new(0.2, 0.0, 5.0), DVec3::Z),
        0.5,
        tol,
        "rod from inside",
    );

    let cube = build(
        backend,
        vec![Primitive::Cuboid {
            min: DVec3::new(-1.0, -1.0, 4.0),
            max: DVec3::new(1.0, 1.0, 6.0),
        }],
    );
    expect_t(
        &*cube,
        ray(DVec3::new(0.3, -0.2, 0.0), DVec3::Z),
        4.0,
        tol,
        "box front face",
    );
    expect_t(
        &*cube,
        ray(DVec3::new(5.0, 0.5, 5.0), -DVec3::X),
        4.0,
        tol,
        "box side face",
    );
    expect_t(
        &*cube,
        ray(DVec3::new(0.0, 0.0, 5.0), DVec3::Z),
        1.0,
        tol,
        "box from inside",
    );

    let tri = build(
        backend,
        vec![Primitive::Triangle {
            v: [
                DVec3::new(-1.0, -1.0, 3.0),
                DVec3::new(1.0, -1.0, 3.0),
                DVec3::new(0.0, 1.0, 3.0),
            ],
        }],
    );
    expect_t(&*tri, ray(DVec3::ZERO, DVec3::Z), 3.0, tol, "triangle");
    expect_t(
        &*tri,
        ray(DVec3::new(0.0, 0.0, 6.0), -DVec3::Z),
        3.0,
        tol,
        "triangle, back side",
    );
    assert!(
        one(&*tri, ray(DVec3::new(0.9, 0.9, 0.0), DVec3::Z)).is_none(),
        "triangle: outside the edge"
    );
}

pub fn interval_and_mask_rules(backend: &dyn Backend, _tol: &Tolerance) {
    let a = build(
        backend,
        vec![Primitive::Cuboid {
            min: DVec3::new(-1.0, -1.0, 4.0),
            max: DVec3::new(1.0, 1.0, 6.0),
        }],
    );
    let base = ray(DVec3::ZERO, DVec3::Z);
    assert!(
        one(&*a, Ray { tmax: 3.9, ..base }).is_none(),
        "tmax before the hit"
    );
    assert!(
        !occ(&*a, Ray { tmax: 3.9, ..base }),
        "occlusion: tmax before the hit"
    );
    assert!(
        occ(&*a, Ray { tmax: 4.1, ..base }),
        "occlusion: tmax past the hit"
    );
    let far = one(&*a, Ray { tmin: 4.5, ..base }).expect("tmin past the entry finds the exit");
    assert!((far.t - 6.0).abs() < 1e-3, "exit at 6, got {}", far.t);
    assert!(
        one(&*a, Ray { tmin: 7.0, ..base }).is_none(),
        "tmin past everything"
    );
    // A masked ray (tmin > tmax) is skipped and reported as no hit, even next to active ones.
    let rays = [
        Ray {
            tmin: 1.0,
            tmax: 0.0,
            ..base
        },
        base,
        Ray {
            tmin: 1.0,
            tmax: 0.0,
            ..base
        },
    ];
    let mut hits = [Some(Hit { t: -1.0, prim: 99 }); 3];
    a.intersect(&rays, &mut hits);
    assert!(
        hits[0].is_none() && hits[2].is_none() && hits[1].is_some(),
        "{hits:?}"
    );
    let mut o = [true; 3];
    a.occluded(&rays, &mut o);
    assert_eq!(o, [false, true, false]);
}

fn random_scene(r: &mut Rng, n: usize) -> Vec<Primitive> {
    (0..n)
        .map(|i| {
            let c = DVec3::new(
                r.range(-10.0, 10.0),
                r.range(-10.0, 10.0),
                r.range(-10.0, 10.0),
            );
            match i % 4 {
                0 => Primitive::Sphere {
                    center: c,
                    radius: r.range(0.05, 0.6),
                },
                1 => Primitive::Capsule {
                    a: c,
                    b: c + r.unit() * r.range(0.2, 2.0),
                    radius: r.range(0.03, 0.3),
                },
                2 => {
                    let h = DVec3::new(r.range(0.05, 0.5), r.range(0.05, 0.5), r.range(0.05, 0.5));
                    Primitive::Cuboid {
                        min: c - h,
                        max: c + h,
                    }
                }
                _ => Primitive::Triangle {
                    v: [
                        c,
                        c + r.unit() * r.range(0.3, 1.5),
                        c + r.unit() * r.range(0.3, 1.5),
                    ],
                },
            }
        })
        .collect()
}

fn brute(prims: &[Primitive], r: &Ray) -> Option<(f64, u32)> {
    let mut best: Option<(f64, u32)> = None;
    for (i, p) in prims.iter().enumerate() {
        let tmax = best.map_or(r.tmax, |b| b.0);
        if let Some(t) = p.intersect(r.origin, r.dir, r.tmin, tmax) {
            best = Some((t, i as u32));
        }
    }
    best
}

pub fn agrees_with_brute_force(backend: &dyn Backend, tol: &Tolerance) {
    let mut r = Rng(42);
    let prims = random_scene(&mut r, 2000);
    let a = build(backend, prims.clone());
    let rays: Vec<Ray> = (0..4000)
        .map(|_| {
            let o = DVec3::new(
                r.range(-20.0, 20.0),
                r.range(-20.0, 20.0),
                r.range(-20.0, 20.0),
            );
            let target = DVec3::new(r.range(-8.0, 8.0), r.range(-8.0, 8.0), r.range(-8.0, 8.0));
            // Lengths other than 1, as the boosted rays have.
            ray(o, (target - o).normalize() * r.range(0.1, 5.0))
        })
        .collect();
    let mut hits = vec![None; rays.len()];
    a.intersect(&rays, &mut hits);
    let mut occluded = vec![false; rays.len()];
    a.occluded(&rays, &mut occluded);
    let mut mismatches = 0;
    let mut hit_count = 0;
    for (k, rr) in rays.iter().enumerate() {
        let want = brute(&prims, rr);
        hit_count += usize::from(want.is_some());
        match (hits[k], want) {
            (Some(h), Some((t, p))) => {
                if (h.t - t).abs() > tol.t_rel * t.abs().max(1.0) {
                    // A different primitive at nearly the same t is a tie, not an error.
                    let other =
                        prims[h.prim as usize].intersect(rr.origin, rr.dir, 0.0, f64::INFINITY);
                    assert!(
                        other.is_some_and(|o| (o - h.t).abs() <= tol.t_rel * t.max(1.0)),
                        "ray {k}: t = {} on prim {}, brute force t = {t} on prim {p}",
                        h.t,
                        h.prim
                    );
                    mismatches += 1;
                }
            }
            (None, None) => {}
            _ => mismatches += 1,
        }
        if occluded[k] != want.is_some() {
            mismatches += 1;
        }
    }
    assert!(
        hit_count > 1000,
        "the random scene must be hit often enough to test anything ({hit_count})"
    );
    let share = mismatches as f64 / rays.len() as f64;
    assert!(
        share <= tol.mismatch,
        "{mismatches} of {} rays disagree with brute force",
        rays.len()
    );
}

pub fn batches_match_single_rays(backend: &dyn Backend, _tol: &Tolerance) {
    let mut r = Rng(7);
    let prims = random_scene(&mut r, 300);
    let a = build(backend, prims);
    let rays: Vec<Ray> = (0..67)
        .map(|_| {
            let o = DVec3::new(r.range(-20.0, 20.0), -25.0, r.range(-20.0, 20.0));
            ray(o, DVec3::new(r.range(-0.3, 0.3), 1.0, r.range(-0.3, 0.3)))
        })
        .collect();
    for size in [1usize, 7, 8, 16, 17, 33, 67] {
        let mut batch = vec![None; size];
        a.intersect(&rays[..size], &mut batch);
        for (k, rr) in rays[..size].iter().enumerate() {
            assert_eq!(batch[k], one(&*a, *rr), "batch of {size}, ray {k}");
        }
    }
}

/// Rays from afar that graze boxes' edges and corners (just inside and just outside, by less
/// than to a few times f32's rounding of their coordinates), in packets of every width: each
/// hit a ray finds alone, it finds (or a closer one) in a packet too. A backend that drops lanes before exact
/// tests (Embree's packets, lane_cull.rs) must keep every lane whose ray meets a primitive.
pub fn grazing_batches_match_single_rays(backend: &dyn Backend, _tol: &Tolerance) {
    let mut r = Rng(11);
    let boxes: Vec<(DVec3, DVec3)> = (0..40)
        .map(|_| {
            let c = DVec3::new(
                r.range(-30.0, 30.0),
                r.range(-30.0, 30.0),
                r.range(-30.0, 30.0),
            );
            let h = DVec3::new(r.range(0.2, 3.0), r.range(0.2, 3.0), r.range(0.2, 3.0));
            (c - h, c + h)
        })
        .collect();
    let prims = boxes
        .iter()
        .map(|&(min, max)| Primitive::Cuboid { min, max })
        .collect();
    let a = build(backend, prims);
    let mut rays = Vec::new();
    for _ in 0..6000 {
        let (min, max) = boxes[(r.next_u64() % boxes.len() as u64) as usize];
        // A point on an edge (two coordinates at a face), or a corner.
        let pick = |r: &mut Rng, k: usize| -> f64 {
            match r.next_u64() % 3 {
                0 => min[k],
                1 => max[k],
                _ => r.range(min[k], max[k]),
            }
        };
        let mut p = DVec3::new(pick(&mut r, 0), pick(&mut r, 1), pick(&mut r, 2));
        let shift = (p - (min + max) * 0.5) * r.range(-3e-6, 3e-6);
        p += shift;
        // From 1,000 to 100,000 away: f32 rounds the origin by 6e-5 to 4e-3.
        let o = p + r.unit() * 10f64.powf(r.range(3.0, 5.0));
        rays.push(ray(o, (p - o).normalize() * r.range(0.5, 2.0)));
    }
    let single: Vec<Option<Hit>> = rays.iter().map(|rr| one(a.as_ref(), *rr)).collect();
    let single_occ: Vec<bool> = rays.iter().map(|rr| occ(a.as_ref(), *rr)).collect();
    let hits = single.iter().filter(|h| h.is_some()).count();
    // Both kinds, so neither check is empty.
    assert!(
        hits > rays.len() / 2 && hits < rays.len() * 19 / 20,
        "{hits} of {} rays hit",
        rays.len()
    );
    for size in [8usize, 16] {
        for (k0, chunk) in rays.chunks(size).enumerate() {
            let mut batch = vec![None; chunk.len()];
            a.intersect(chunk, &mut batch);
            let mut blocked = vec![false; chunk.len()];
            a.occluded(chunk, &mut blocked);
            for (k, h) in batch.iter().enumerate() {
                let i = k0 * size + k;
                // Embree's single-ray traversal (f32 boxes) may itself miss a box that a ray
                // grazes by less than f32 rounding, which its packets find: so a packet finds
                // a hit at least as close, not necessarily the same one.
                if let Some(alone) = single[i] {
                    let t = h.map(|h| h.t);
                    assert!(
                        t.is_some_and(|t| t <= alone.t),
                        "batch of {size}, ray {i}: {h:?}, alone {alone:?}"
                    );
                }
                if single_occ[i] {
                    assert!(blocked[k], "occlusion batch of {size}, ray {i}");
                }
            }
        }
    }
}

pub fn empty_geometry(backend: &dyn Backend, _tol: &Tolerance) {
    let a = backend
        .build(Arc::new(Geometry::default()))
        .expect("empty geometry builds");
    assert!(one(&*a, ray(DVec3::ZERO, DVec3::Z)).is_none());
    assert!(!occ(&*a, ray(DVec3::ZERO, DVec3::Z)));
}

/// One #[test] per check for a backend.
#[macro_export]
macro_rules! conformance_suite {
    ($modname:ident, $backend:expr, $tol:expr) => {
        mod $modname {
            use $crate::common::conformance::*;
            #[test]
            fn analytic_hits_of_each_primitive() {
                analytic_hits(&*$backend, &$tol);
            }
            #[test]
            fn tmin_tmax_and_mask() {
                interval_and_mask_rules(&*$backend, &$tol);
            }
            #[test]
            fn random_scene_matches_brute_force() {
                agrees_with_brute_force(&*$backend, &$tol);
            }
            #[test]
            fn batches_equal_single_rays() {
                batches_match_single_rays(&*$backend, &$tol);
            }
            #[test]
            fn grazing_batches_equal_single_rays() {
                grazing_batches_match_single_rays(&*$backend, &$tol);
            }
            #[test]
            fn empty_geometry_never_hits() {
                empty_geometry(&*$backend, &$tol);
            }
        }
    };
}
