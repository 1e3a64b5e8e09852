//! Where a worldline's segments are groups, closest hits visit the groups last to first (the
//! latest segment's window first). The order must not change a hit: the closest is the
//! closest whichever group is asked first.

use super::common::*;
use super::EIGHT_SEGMENTS;
use crate::render::World;
use crate::spacetime::{Event, NullRay};
use glam::DVec3;

/// A lattice on the bench's eight segments, seen from the imaging event and from events
/// closer by, whose rays meet the later segments.
#[test]
fn segments_visited_latest_first_meet_what_first_to_last_meets() {
    let text = format!(
        "[camera]\nposition = [0, -30, 0]\nlook_at = [0, 0, 0]\ntime = 3\n\
         [image]\nwidth = 8\nheight = 8\n[[group]]\nname = \"lattice\"\nworldline = {EIGHT_SEGMENTS}\n\
         [[group.object]]\ntype = \"lattice\"\norigin = [-6, -6, -6]\nspacing = 2.0\n\
         counts = [7, 7, 7]\nrod_radius = 0.1\nsphere_radius = 0.3\n"
    );
    same_hits_either_way(&text, 4, 1);
}

/// Two lattices, each on a worldline of its own, one a little behind the other, their
/// segments' ends interleaved in time: once a ray has met one worldline's later segment, the
/// other's segments visited after it may still hold a later emission (the groups left are
/// passed over only where none can).
#[test]
fn interleaved_worldlines_visited_latest_first_meet_what_first_to_last_meets() {
    let lattice = |name: &str, line: &str, x: f64| {
        format!(
            "[[group]]\nname = \"{name}\"\nworldline = {line}\n\
             [[group.object]]\ntype = \"lattice\"\norigin = [{x}, -6, -6]\nspacing = 2.0\n\
             counts = [7, 7, 7]\nrod_radius = 0.1\nsphere_radius = 0.3\n"
        )
    };
    let a = "[{until=-20, velocity=[-0.5,0,0]}, {until=-6, velocity=[-0.45,0,0]}, \
             {until=-1.5, velocity=[-0.5,0,0]}, {until=0.25, velocity=[-0.45,0,0]}, \
             {velocity=[-0.5,0,0]}]";
    let b = "[{until=-12, velocity=[-0.5,0,0.02]}, {until=-4, velocity=[-0.45,0,0.02]}, \
             {until=-0.5, velocity=[-0.5,0,0.02]}, {until=1, velocity=[-0.45,0,0.02]}, \
             {velocity=[-0.5,0,0.02]}]";
    let text = format!(
        "[camera]\nposition = [0, -30, 0]\nlook_at = [0, 0, 0]\ntime = 3\n\
         [image]\nwidth = 8\nheight = 8\n{}{}",
        lattice("a", a, -6.0),
        lattice("b", b, -5.0)
    );
    same_hits_either_way(&text, 4, 8);
}

/// The hits on rays from the scene's imaging event and from events closer by are the same in
/// every printed bit visited latest first and first to last, in packets and one ray at a
/// time, on each backend; the rays meet at least `segments` of the groups. The rays come in
/// bundles of `bundle` from one event, their targets a hair apart: a packet's rays then meet
/// things together, and the groups left can be passed over once all have.
fn same_hits_either_way(text: &str, segments: usize, bundle: usize) {
    let s = scene(text);
    for name in backends() {
        let backend = crate::accel::backend_by_name(name).unwrap();
        let latest = World::build(&s, backend.as_ref()).unwrap();
        let first = World::build(&s, backend.as_ref()).unwrap().first_to_last();
        assert!(latest.visits_latest_first() && !first.visits_latest_first());
        let mut r = Rng(4);
        let mut rays: Vec<NullRay> = Vec::with_capacity(3000);
        let (mut from, mut target) = (Event::new(0.0, DVec3::ZERO), DVec3::ZERO);
        for k in 0..3000 {
            if k % bundle == 0 {
                from = match (k / bundle) % 2 {
                    0 => Event::new(3.0, DVec3::new(0.0, -30.0, 0.0)),
                    // Close by, so that light left late: the later segments.
                    _ => Event::new(
                        r.range(-15.0, 5.0),
                        DVec3::new(
                            r.range(-40.0, 40.0),
                            r.range(-12.0, -8.0),
                            r.range(-8.0, 8.0),
                        ),
                    ),
                };
                target = DVec3::new(r.range(-40.0, 40.0), 0.0, r.range(-8.0, 8.0));
            }
            let near = target + DVec3::new(1e-3, 0.0, 2e-3) * (k % bundle) as f64;
            rays.push(NullRay::new(from, (near - from.x).normalize()));
        }
        let mut a = vec![None; rays.len()];
        let mut b = vec![None; rays.len()];
        latest.closest_hits(&rays, 0.0, &mut a);
        first.closest_hits(&rays, 0.0, &mut b);
        let met: std::collections::BTreeSet<usize> = b.iter().flatten().map(|h| h.group).collect();
        assert!(
            met.len() >= segments,
            "{name}: rays meet several segments ({met:?})"
        );
        for (k, (x, y)) in a.iter().zip(&b).enumerate() {
            assert_eq!(format!("{x:?}"), format!("{y:?}"), "{name}, ray {k}");
            let one = latest.closest_hit(&rays[k], 0.0);
            assert_eq!(
                format!("{one:?}"),
                format!("{y:?}"),
                "{name}, ray {k} alone"
            );
        }
    }
}

/// The groups left are passed over only where none can hold a later emission for any ray of
/// the packet. Two rays at rest-frame distance: ray 0 meets sphere B (worldline b's last
/// segment) 4.4 away, and behind it nothing; in front of B, 4.1 away, lies sphere A, seen in
/// worldline a's first segment (emissions before t = −4). Ray 1 meets A's twin 3.5 away in
/// a's last segment. Visited b's segments first, then a's last: every ray has a hit, but ray
/// 0's (emitted at −4.4) is earlier than a's first segment can still show (up to −4), so that
/// segment must be visited, and it gives ray 0 sphere A.
#[test]
fn a_segment_that_can_still_show_a_later_emission_is_visited() {
    let text = "[camera]\nposition = [0, 0, 0]\nlook_at = [0, 1, 0]\ntime = 0\n\
         [image]\nwidth = 8\nheight = 8\n\
         [[group]]\nname = \"a\"\n\
         worldline = [{until=-4, velocity=[0,0,0.001]}, {velocity=[0,0,0.002]}]\n\
         [[group.object]]\ntype = \"sphere\"\ncenter = [0, 4.2, 0]\nradius = 0.1\n\
         [[group.object]]\ntype = \"sphere\"\ncenter = [2, 3, 0]\nradius = 0.1\n\
         [[group]]\nname = \"b\"\n\
         worldline = [{until=-100, velocity=[0,0,0.001]}, {velocity=[0,0,0.002]}]\n\
         [[group.object]]\ntype = \"sphere\"\ncenter = [0, 4.5, 0]\nradius = 0.1\n";
    let s = scene(text);
    let event = Event::new(0.0, DVec3::ZERO);
    let rays = [
        NullRay::new(event, DVec3::Y),
        NullRay::new(event, DVec3::new(2.0, 3.0, 0.0).normalize()),
    ];
    for name in backends() {
        let backend = crate::accel::backend_by_name(name).unwrap();
        let world = World::build(&s, backend.as_ref()).unwrap();
        assert!(world.visits_latest_first());
        let mut hits = [None; 2];
        world.closest_hits(&rays, 0.0, &mut hits);
        let [Some(h0), Some(h1)] = hits else {
            panic!("{name}: both rays meet a sphere: {hits:?}");
        };
        // Groups in file order: a's two segments, then b's.
        assert_eq!(
            h0.group, 0,
            "{name}: ray 0 meets A in a's first segment: {h0:?}"
        );
        assert_eq!(
            h1.group, 1,
            "{name}: ray 1 meets A's twin in a's last: {h1:?}"
        );
        // Emitted at about −4.1 and −3.5 (the spheres creep across the rays).
        assert!((h0.lambda - 4.1).abs() < 0.05, "{name}: {h0:?}");
        assert!(h1.lambda < 4.0, "{name}: {h1:?}");
    }
}
