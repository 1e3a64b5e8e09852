//! A world whose every group is small and at rest in the world frame traces its rays against
//! all groups at once, straight from the world rays (`direct::AtRest`). Its closest hits and
//! shadow answers must be the group-by-group ones to the bit: which group and primitive, the
//! lookback, the point, the direction and the lookback factor.

use super::common::*;
use crate::render::{World, WorldOptions};
use crate::spacetime::{Event, NullRay};
use glam::DVec3;

/// Groups at rest of boxes, spheres and rods, the first box of each group repeated in the
/// next (a tie the earlier group must win), and a floor that closes the view.
fn groups_at_rest(groups: usize, velocity: &str) -> String {
    let mut r = Rng(11);
    let mut s = String::from(
        "[camera]\nposition = [0, -30, 0]\nlook_at = [0, 0, 0]\n[image]\nwidth = 8\nheight = 8\n",
    );
    let mut shared = String::new();
    for g in 0..groups {
        s += &format!("[[group]]\nname = \"g{g}\"\n");
        if g == 0 {
            s += velocity;
        }
        s += &shared;
        for k in 0..6 {
            let c = [r.range(-8.0, 8.0), r.range(-8.0, 8.0), r.range(-8.0, 8.0)];
            let object = match k % 3 {
                0 => format!(
                    "[[group.object]]\ntype = \"box\"\nmin = [{:?}, {:?}, {:?}]\nmax = [{:?}, {:?}, {:?}]\n",
                    c[0] - 1.0, c[1] - 0.5, c[2] - 0.8, c[0] + 1.0, c[1] + 0.5, c[2] + 0.8
                ),
                1 => format!(
                    "[[group.object]]\ntype = \"sphere\"\ncenter = [{:?}, {:?}, {:?}]\nradius = {:?}\n",
                    c[0], c[1], c[2], r.range(0.3, 1.5)
                ),
                _ => format!(
                    "[[group.object]]\ntype = \"rod\"\nfrom = [{:?}, {:?}, {:?}]\nto = [{:?}, {:?}, {:?}]\nradius = 0.3\n",
                    c[0], c[1], c[2], c[0] + 2.0, c[1] - 1.0, c[2] + 1.5
                ),
            };
            if k == 0 {
                shared = object.clone();
            }
            s += &object;
        }
    }
    s + "[[group.object]]\ntype = \"box\"\nmin = [-20, -20, -10]\nmax = [20, 20, -9]\n"
}

/// Rays from anywhere near the objects (some inside them), toward them or anywhere, among
/// them rays along the axes (zero components).
fn rays(n: usize) -> Vec<NullRay> {
    let mut r = Rng(9);
    let mut rays: Vec<NullRay> = (0..n)
        .map(|k| {
            let x = DVec3::new(
                r.range(-12.0, 12.0),
                r.range(-12.0, 12.0),
                r.range(-12.0, 12.0),
            );
            let dir = match k % 3 {
                0 => r.unit(),
                _ => {
                    let target =
                        DVec3::new(r.range(-8.0, 8.0), r.range(-8.0, 8.0), r.range(-8.0, 8.0));
                    (target - x).normalize()
                }
            };
            NullRay::new(Event::new(r.range(-3.0, 3.0), x), dir)
        })
        .collect();
    for d in [DVec3::X, DVec3::NEG_Y, DVec3::Z, DVec3::NEG_Z] {
        rays.push(NullRay::new(Event::new(0.0, DVec3::new(0.0, 0.5, -0.0)), d));
    }
    rays
}

/// Both ways of tracing `s`'s world, with the options given.
fn both(s: &crate::scene::Scene, options: WorldOptions) -> (World, World) {
    let backend = crate::accel::backend_by_name("bvh").unwrap();
    let at_rest = World::build_with(s, backend.as_ref(), options).unwrap();
    let by_group = World::build_with(s, backend.as_ref(), options)
        .unwrap()
        .group_by_group();
    (at_rest, by_group)
}

#[test]
fn all_groups_at_once_is_group_by_group_to_the_bit() {
    for (groups, simd) in [(1, true), (4, true), (4, false)] {
        let s = scene(&groups_at_rest(groups, ""));
        // Several groups stay apart without the bounds cull (which clips their rays) and
        // without merging (which makes one group of them).
        let options = WorldOptions {
            bounds_cull: false,
            merge_equal_velocities: false,
            simd,
            ..Default::default()
        };
        let (at_rest, by_group) = both(&s, options);
        assert!(at_rest.traces_at_rest() && !by_group.traces_at_rest());
        let what = format!("{groups} groups, simd {simd}");
        let rays = rays(4000);
        for tmin in [0.0, 0.5] {
            let mut a = vec![None; rays.len()];
            let mut b = vec![None; rays.len()];
            at_rest.closest_hits(&rays, tmin, &mut a);
            by_group.closest_hits(&rays, tmin, &mut b);
            let met = b.iter().flatten().count();
            let others = b.iter().flatten().filter(|h| h.group > 0).count();
            // The box group g shares with group g + 1 (its first object; the first of group
            // g + 1): every hit on it is a tie, which group g keeps.
            let ties = b
                .iter()
                .flatten()
                .filter(|h| h.group + 1 < groups && h.prim == u32::from(h.group > 0))
                .count();
            assert!(met > rays.len() / 3, "{what}: rays meet something ({met})");
            assert!(
                groups == 1 || others > 300,
                "{what}: rays meet later groups ({others})"
            );
            assert!(
                groups == 1 || ties > 20,
                "{what}: rays meet shared boxes ({ties})"
            );
            for (k, (x, y)) in a.iter().zip(&b).enumerate() {
                // Debug prints every bit that matters: -0 apart from 0, NaN as NaN.
                assert_eq!(format!("{x:?}"), format!("{y:?}"), "{what}, ray {k}");
            }
        }
        let mut r = Rng(3);
        let tmax: Vec<f64> = (0..rays.len())
            .map(|k| match k % 7 {
                0 => f64::INFINITY,
                1 => 0.0,
                2 => -1.0,
                3 => f64::NAN,
                _ => r.range(0.5, 30.0),
            })
            .collect();
        let mut a = vec![false; rays.len()];
        let mut b = vec![true; rays.len()];
        at_rest.occluded_scattered(&rays, &tmax, &mut a);
        by_group.occluded_scattered(&rays, &tmax, &mut b);
        // Among the rays whose intervals are not empty (ends 0, -1 and NaN leave them lit).
        let open = || {
            b.iter()
                .enumerate()
                .filter(|(k, _)| !(1..=3).contains(&(k % 7)))
        };
        let blocked = open().filter(|&(_, &x)| x).count();
        let lit = open().count() - blocked;
        assert!(
            blocked > 300 && lit > 300,
            "{what}: a mix of shadowed ({blocked}) and lit ({lit}) rays"
        );
        for (k, (x, y)) in a.iter().zip(&b).enumerate() {
            assert_eq!(x, y, "{what}: the shadow ray {k}");
        }
    }
}

/// A group that moves, a spinning sphere, a worldline's segments, a camera far off
/// (whose rays are clipped) and the bounds cull of several groups keep the group-by-group way.
#[test]
fn only_worlds_wholly_at_rest_are_traced_at_once() {
    let backend = crate::accel::backend_by_name("bvh").unwrap();
    let world = |text: &str, options| World::build_with(&scene(text), backend.as_ref(), options);
    let apart = WorldOptions {
        bounds_cull: false,
        merge_equal_velocities: false,
        ..Default::default()
    };
    assert!(world(&groups_at_rest(3, ""), apart)
        .unwrap()
        .traces_at_rest());
    let moving = groups_at_rest(3, "velocity = [0.5, 0, 0]\n");
    assert!(!world(&moving, apart).unwrap().traces_at_rest());
    // One small group at rest seen from close by is traced at once, but for what it holds.
    let one = |object: &str, motion: &str, camera: &str| {
        let text = format!(
            "[camera]\nposition = {camera}\nlook_at = [0, 0, 0]\n[image]\nwidth = 8\n\
             height = 8\n[[group]]\nname = \"g\"\n{motion}[[group.object]]\n{object}"
        );
        world(&text, WorldOptions::default())
            .unwrap()
            .traces_at_rest()
    };
    let ball = "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n";
    let near = "[0, -10, 0]";
    assert!(one(ball, "", near));
    let spinning = format!("{ball}spin = {{ axis = [0, 0, 1], omega = 0.45 }}\n");
    assert!(!one(&spinning, "", near), "a spinning sphere");
    // A segment at rest and one moving (two at rest are one group, without a window).
    let segments =
        "worldline = [{ until = 0, velocity = [0, 0, 0] }, { velocity = [0.5, 0, 0] }]\n";
    assert!(!one(ball, segments, near), "a worldline's segments");
    assert!(!one(ball, "", "[0, -1000, 0]"), "a camera far off");
    let culled = WorldOptions {
        merge_equal_velocities: false,
        ..Default::default()
    };
    assert!(!world(&groups_at_rest(3, ""), culled)
        .unwrap()
        .traces_at_rest());
    // Merged, they are one group at rest, seen from close by: small enough for two groups'
    // worth, not for three.
    let merged = |groups| {
        world(&groups_at_rest(groups, ""), WorldOptions::default())
            .unwrap()
            .traces_at_rest()
    };
    assert!(merged(2) && !merged(3));
}
