//! Lattices and bar arrays held as themselves (instanced blocks in Embree, two levels in the
//! f64 BVH) against the same objects listed primitive by primitive: the same hits, primitive
//! and lookback time to the bit, for rays from outside and inside, in packets and alone, and
//! the same occlusion.

use crate::accel::{backend_by_name, Hit, Ray};
use crate::geometry::{Aabb, BarArray, Geometry, Implicit, Lattice, Primitive};
use crate::rng::Rng;
use glam::DVec3;
use std::sync::Arc;

/// Push a lattice as itself, spheres with material `sm`, rods with `rm`.
fn push_lattice(g: &mut Geometry, object: u32, sm: u32, rm: u32, l: Lattice) {
    let runs = [(l.sphere_count(), sm), (l.rod_count(), rm)];
    g.push_implicit(object, &runs, Implicit::Lattice(l))
        .unwrap();
}

/// A lattice whose blocks do not divide it (so the far blocks hold numbers it lacks), after a
/// box held as itself, a second lattice of spheres only, and a bar array.
fn geometry() -> Geometry {
    let mut g = Geometry::default();
    g.push_part(
        0,
        0,
        [Primitive::Cuboid {
            min: DVec3::new(-9.0, -9.0, -9.0),
            max: DVec3::new(-8.0, -8.0, 20.0),
        }],
    );
    let lattice = Lattice {
        counts: [23, 17, 11],
        spacing: DVec3::new(1.0, 0.8, 1.3),
        origin: DVec3::new(-4.0, -6.5, -3.0),
        rod_radius: 0.05,
        sphere_radius: 0.15,
    };
    push_lattice(&mut g, 1, 1, 2, lattice);
    let spheres = Lattice {
        counts: [5, 4, 3],
        spacing: DVec3::splat(2.0),
        origin: DVec3::new(30.0, 0.0, 0.0),
        rod_radius: 0.0,
        sphere_radius: 0.4,
    };
    push_lattice(&mut g, 2, 3, 3, spheres);
    let bars = BarArray {
        counts: [13, 7],
        spacing: [1.5, 2.0],
        bar_size: [0.5, 0.6],
        length: 9.0,
        axis: 1,
        center: DVec3::new(10.0, 2.0, 3.0),
    };
    g.push_implicit(3, &[(bars.len(), 4)], Implicit::Bars(bars))
        .unwrap();
    g
}

/// Rays from around and inside the geometry, aimed into it.
fn rays(rng: &mut Rng, n: usize) -> Vec<Ray> {
    super::rays_toward(
        rng,
        n,
        Aabb::new(DVec3::new(-4.0, -6.5, -3.0), DVec3::new(18.0, 6.5, 10.0)),
        40.0,
        Aabb::new(DVec3::new(-5.0, -8.0, -4.0), DVec3::new(40.0, 8.0, 12.0)),
        30.0,
    )
}

#[test]
fn held_lattices_hit_as_listed_ones() {
    let held = Arc::new(geometry());
    let listed = Arc::new(held.flattened());
    assert!(held.prims.len() == 1 && held.implicit.len() == 3 && listed.implicit.is_empty());
    assert_eq!(held.len(), listed.len());
    let mut rng = Rng(0x1a77_1ce0_5eed_0001);
    let rays = rays(&mut rng, 6000);
    for name in crate::accel::backend_names() {
        let backend = backend_by_name(name).unwrap();
        let a = backend.build(held.clone()).unwrap();
        let b = backend.build(listed.clone()).unwrap();
        for width in [1, 16] {
            let (ha, hb) = (
                super::hits(a.as_ref(), &rays, width),
                super::hits(b.as_ref(), &rays, width),
            );
            let hit = hb.iter().filter(|h| h.is_some()).count();
            assert!(hit > rays.len() / 3, "{name}: {hit} hits of {}", rays.len());
            // Where two primitives are met at the same t (two rods' round ends about one
            // node), either is the hit.
            let tie = |x: &Option<Hit>, y: &Option<Hit>| match (x, y) {
                (Some(x), Some(y)) => x.t == y.t,
                _ => false,
            };
            let differ: Vec<usize> = (0..rays.len())
                .filter(|&i| ha[i] != hb[i] && !tie(&ha[i], &hb[i]))
                .collect();
            assert!(
                differ.is_empty(),
                "{name}, {width} wide: {} of {} rays differ, first {:?}: {:?} against {:?}",
                differ.len(),
                rays.len(),
                differ.first(),
                differ.first().map(|&i| ha[i]),
                differ.first().map(|&i| hb[i]),
            );
            let (oa, ob) = (
                super::occluded(a.as_ref(), &rays, width),
                super::occluded(b.as_ref(), &rays, width),
            );
            assert_eq!(oa, ob, "{name}, {width} wide");
            for (h, o) in hb.iter().zip(&ob) {
                assert_eq!(h.is_some(), *o);
            }
        }
    }
}

/// The paper's lattice and bar array rendered instanced and listed: the same frame, every
/// pass, on each backend.
#[test]
fn the_paper_scenes_render_alike_instanced() {
    use crate::render::{render_world, World, WorldOptions};
    let sets = |list: &[&str]| -> Vec<String> {
        let mut all = vec![
            "image.width=64",
            "image.height=64",
            "image.samples=1",
            "render.doppler=true",
            "render.searchlight=true",
        ];
        all.extend_from_slice(list);
        all.iter().map(|s| s.to_string()).collect()
    };
    let scenes = [
        (
            "lattice",
            sets(&[
                "group.lattice.velocity=[-0.9, 0, 0]",
                "group.lattice.object.lattice.counts=[14, 13, 12]",
            ]),
        ),
        ("bar_array", sets(&["group.bars.velocity=[0.9, 0, 0]"])),
    ];
    for (paper, sets) in scenes {
        let scene = crate::scene::paper::paper(paper, &sets).unwrap();
        for name in crate::accel::backend_names() {
            let backend = backend_by_name(name).unwrap();
            let build = |instance_over| {
                let options = WorldOptions {
                    instance_over,
                    ..WorldOptions::default()
                };
                World::build_with(&scene, backend.as_ref(), options).unwrap()
            };
            let held = build(0);
            let listed = build(u64::MAX);
            assert!(!held.groups[0].geometry.implicit.is_empty(), "{paper}");
            assert!(listed.groups[0].geometry.implicit.is_empty());
            let a = render_world(&scene, &held).0;
            let b = render_world(&scene, &listed).0;
            assert!(a.pixels.iter().any(|p| p.object_id > 0), "{paper}: empty");
            let differ = super::differing_pixels(&a, &b);
            assert_eq!(differ, 0, "{paper}, {name}: {differ} pixels differ");
            assert!(a.mattes == b.mattes, "{paper}, {name}: the mattes differ");
        }
    }
}

/// Groups of one velocity merged (`Geometry::append`): every primitive keeps its shape and its
/// object, the held ones numbered before every lattice's, whatever order the groups came in.
#[test]
fn merged_geometries_keep_every_primitive() {
    let small = |origin: f64, object: u32, nx: u32| {
        let mut g = Geometry::default();
        push_lattice(
            &mut g,
            object,
            0,
            1,
            Lattice {
                counts: [nx, 2, 2],
                spacing: DVec3::ONE,
                origin: DVec3::splat(origin),
                rod_radius: 0.05,
                sphere_radius: 0.1,
            },
        );
        // Held after the lattice: numbered before it.
        g.push_part(
            object + 1,
            2,
            [Primitive::Sphere {
                center: DVec3::splat(origin - 5.0),
                radius: 1.0,
            }],
        );
        g
    };
    // 32 and 44 primitives.
    let (a, b) = (small(0.0, 0, 3), small(20.0, 10, 4));
    let mut merged = a.clone();
    merged.append(&b);
    assert_eq!(merged.len(), a.len() + b.len());
    assert_eq!(merged.prims.len(), 2);
    let flat = merged.flattened();
    // Each primitive with its object, material and index among its object's primitives.
    let of = |g: &Geometry, i: u32| {
        let part = g.part_of(i);
        (g.prim(i), part.object, part.material, g.index_in_object(i))
    };
    let mut from: Vec<_> = Vec::new();
    for g in [&a, &b] {
        from.extend((0..g.len()).map(|i| of(g, i)));
    }
    let mut got: Vec<_> = (0..merged.len())
        .map(|i| {
            assert_eq!(merged.prim(i), flat.prims[i as usize]);
            of(&merged, i)
        })
        .collect();
    let key = |p: &(Primitive, u32, u32, u32)| format!("{p:?}");
    from.sort_by_key(key);
    got.sort_by_key(key);
    assert_eq!(got, from);
    // Listing the smaller lattice only: the same primitives, objects and indices.
    let mixed = merged.listing(40);
    assert_eq!((mixed.prims.len(), mixed.implicit.len()), (2 + 32, 1));
    let mut got: Vec<_> = (0..mixed.len()).map(|i| of(&mixed, i)).collect();
    got.sort_by_key(key);
    assert_eq!(got, from);
}
