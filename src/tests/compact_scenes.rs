//! Scenes of many triangles are built compact (`EmbreeBackend::compact_from`,
//! `COMPACT_FROM_TRIANGLES`): Embree's leaves name their triangles' vertices by index instead
//! of holding copies, about half the memory. Both run Embree's robust test on the same f32
//! vertices, so rays at random find the same hits, and rays at shared edges the same points.
//! Traced: a mesh held as itself, listed triangles and a shared mesh's placements (its own
//! scene compact or not), one ray at a time and in packets, under every instruction set the
//! CPU has.

#![cfg(feature = "embree")]

use crate::accel::{EmbreeBackend, Isa};
use crate::geometry::{Aabb, Affine, Geometry, Implicit, IndexedMesh, MeshInstance, Primitive};
use crate::rng::Rng;
use glam::{DMat3, DVec3};
use std::sync::Arc;

/// A rough height field of `n` x `n` squares (two triangles each) over [-4, 4]², its heights
/// random, so that many rays meet its triangles' shared edges and corners at grazing angles.
fn terrain(n: u32) -> IndexedMesh {
    let mut rng = Rng(0xc0c0_a5e5_0000_0052);
    let mut positions = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            let (x, y) = (
                8.0 * f64::from(i) / f64::from(n) - 4.0,
                8.0 * f64::from(j) / f64::from(n) - 4.0,
            );
            positions.push(DVec3::new(x, y, 0.3 * (x * y).sin() + rng.range(0.0, 0.05)));
        }
    }
    let at = |i: u32, j: u32| i * (n + 1) + j;
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..n {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    IndexedMesh::new(positions, triangles)
}

/// The terrain held as itself, a few listed triangles standing on it, and a small terrain
/// placed three times (a shared mesh: an Embree scene of its own, instanced).
fn geometry() -> Geometry {
    let big = Arc::new(terrain(90));
    let small = Arc::new(terrain(12));
    let mut g = Geometry::default();
    g.push_implicit_with(0, &[(big.len(), 0, None)], Implicit::Mesh(big))
        .unwrap();
    let walls = (0..6).map(|k| {
        let x = f64::from(k) - 2.5;
        Primitive::Triangle {
            v: [
                DVec3::new(x, -3.0, -0.5),
                DVec3::new(x + 0.7, -3.0, 1.5),
                DVec3::new(x, 3.0, 1.0),
            ],
        }
    });
    g.push_part(1, 1, walls);
    for k in 0..3 {
        let place = Affine::rigid(
            DVec3::splat(0.3),
            DMat3::from_rotation_x(0.5 * f64::from(k)),
            DVec3::new(2.5 * f64::from(k) - 2.5, 1.0, 1.2),
        );
        let inst = MeshInstance::new(small.clone(), place);
        g.push_implicit_with(
            2 + k,
            &[(small.len(), 2, None)],
            Implicit::Instance(Arc::new(inst)),
        )
        .unwrap();
    }
    g
}

#[test]
fn compact_scenes_hit_as_the_others_do() {
    let geometry = Arc::new(geometry());
    let mut rays = super::rays_toward(
        &mut Rng(0xc0c0_a5e5_0000_0053),
        6000,
        Aabb::new(DVec3::new(-4.0, -4.0, 0.6), DVec3::new(4.0, 4.0, 2.0)),
        12.0,
        Aabb::new(DVec3::new(-4.0, -4.0, -0.5), DVec3::new(4.0, 4.0, 1.5)),
        20.0,
    );
    // And rays at points of the big terrain's shared edges, where which of two triangles is
    // met is decided by f32 rounding: the same decision in both kinds of scene.
    let random = rays.len();
    let big = terrain(90);
    let mut rng = Rng(0xc0c0_a5e5_0000_0054);
    // Each edge ray's edge, by its vertices.
    let mut edges = Vec::new();
    for _ in 0..6000 {
        // An inner square's triangle: its edges are shared.
        let (i, j) = (1 + rng.next_u64() % 88, 1 + rng.next_u64() % 88);
        let t = big.triangles()[(i * 180 + 2 * j + rng.next_u64() % 2) as usize];
        let k = (rng.next_u64() % 3) as usize;
        let (p, q) = (t[k], t[(k + 1) % 3]);
        edges.push((p, q));
        let (a, b) = (big.position(p), big.position(q));
        let aim = a.lerp(b, rng.range(0.0, 1.0));
        let origin = DVec3::new(
            rng.range(-6.0, 6.0),
            rng.range(-6.0, 6.0),
            rng.range(0.5, 6.0),
        );
        rays.push(crate::accel::Ray::new(
            origin,
            aim - origin,
            1e-6,
            f64::INFINITY,
        ));
    }
    // The group's scene counts the big terrain's triangles and the listed ones; the placed
    // terrain is counted in its own scene.
    let triangles = 2 * 90 * 90 + 6;
    let on = |isa: Isa| EmbreeBackend::new().on_isa(isa).unwrap();
    for isa in Isa::on_cpu() {
        let usual_backend = on(isa);
        let usual = usual_backend.accelerator(geometry.clone()).unwrap();
        assert!(!usual.is_compact(), "{isa:?}: a small scene is not compact");
        assert_eq!(usual_backend.shared_scenes_compact(), [false], "{isa:?}");
        // Compact from as many triangles as the group has, and not from one more.
        let compact = on(isa)
            .compact_from(triangles)
            .accelerator(geometry.clone())
            .unwrap();
        assert!(compact.is_compact(), "{isa:?}");
        let just_under = on(isa).compact_from(triangles + 1);
        assert!(!just_under
            .accelerator(geometry.clone())
            .unwrap()
            .is_compact());
        // And compact from the placed terrain's size: its own scene too.
        let everything = on(isa).compact_from(2 * 12 * 12);
        let all = everything.accelerator(geometry.clone()).unwrap();
        assert_eq!(everything.shared_scenes_compact(), [true], "{isa:?}");
        // The usual scene's hits and occlusions, traced once for both compact ones.
        let widths = [1, 4, 16];
        let expected = widths.map(|width| {
            (
                super::hits(&usual, &rays, width),
                super::occluded(&usual, &rays[..random], width),
            )
        });
        for (compact, (width, (a, oa))) in [&compact, &all]
            .into_iter()
            .flat_map(|c| widths.iter().zip(&expected).map(move |e| (c, e)))
        {
            let width = *width;
            let b = super::hits(compact, &rays, width);
            let met = a.iter().filter(|h| h.is_some()).count();
            assert!(met > rays.len() / 3, "{isa:?}: {met} hits");
            let kinds: std::collections::BTreeSet<u32> = a
                .iter()
                .flatten()
                .map(|h| geometry.part_of(h.prim).object)
                .collect();
            assert_eq!(
                kinds.len(),
                5,
                "{isa:?}: the hits meet every object: {kinds:?}"
            );
            // Rays at random: the same hits, to the bit, and the same occlusions.
            for (i, (x, y)) in a.iter().zip(&b).enumerate().take(random) {
                let same = match (x, y) {
                    (Some(x), Some(y)) => x.prim == y.prim && x.t.to_bits() == y.t.to_bits(),
                    (None, None) => true,
                    _ => false,
                };
                assert!(same, "{isa:?}, {width} wide, ray {i}: {x:?} against {y:?}");
            }
            let ob = super::occluded(compact, &rays[..random], width);
            assert_eq!(*oa, ob, "{isa:?}, {width} wide");
            // Rays at shared edges: Embree runs each kind's test as compiled for its own
            // instruction set (the compact one's single rays without FMA on AVX2), so where
            // two triangles meet, rounding may offer the other one. Either way a hit at the
            // edge is where the ray was aimed, t = 1, refined in f64: on the triangle, or
            // where the ray crosses its plane when the f64 test finds it just outside (Embree's
            // f32 t is a millionth off there). A hit on the edge: on one of the big terrain's
            // (object 0's) triangles that hold both its vertices.
            let on_edge = |prim: u32, (p, q): (u32, u32)| {
                let part = geometry.part_of(prim);
                let tri = || big.triangles()[(prim - part.start) as usize];
                part.object == 0 && tri().contains(&p) && tri().contains(&q)
            };
            for (kind, hits) in [("usual", a.as_slice()), ("compact", b.as_slice())] {
                for (i, (h, &edge)) in hits[random..].iter().zip(&edges).enumerate() {
                    if let Some(h) = h.filter(|h| on_edge(h.prim, edge)) {
                        let off = (h.t - 1.0).abs();
                        assert!(
                            off < 1e-12,
                            "{isa:?}, {width} wide, {kind}, edge ray {i}: t - 1 = {off:e}"
                        );
                    }
                }
            }
            // Rarely (a few in ten thousand, in the usual scene as in the compact one)
            // Embree's robust test offers neither triangle of the edge, and the ray goes on
            // through it (a limit of Embree's own test: docs/architecture.md).
            let mut elsewhere = 0;
            for (x, y) in a.iter().zip(&b).skip(random) {
                match (x, y) {
                    (Some(x), Some(y)) if (x.t - y.t).abs() <= 1e-12 * x.t => {}
                    (None, None) => {}
                    _ => elsewhere += 1,
                }
            }
            assert!(
                elsewhere <= (rays.len() - random) / 500,
                "{isa:?}, {width} wide: {elsewhere} rays at edges meet another point"
            );
        }
    }
}
