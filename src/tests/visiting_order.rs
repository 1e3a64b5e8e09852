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
    let s = scene(&text);
    for name in backends() {
        let backend = crate::accel::backend_by_name(name).unwrap();
        let latest = World::build(&s, backend.as_ref()).unwrap();
        let first = World::build(&s, backend.as_ref()).unwrap().first_to_last();
        assert!(latest.visits_latest_first() && !first.visits_latest_first());
        let mut r = Rng(4);
        let rays: Vec<NullRay> = (0..3000)
            .map(|k| {
                let from = match k % 2 {
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
                let target = DVec3::new(r.range(-40.0, 40.0), 0.0, r.range(-8.0, 8.0));
                NullRay::new(from, (target - from.x).normalize())
            })
            .collect();
        let mut a = vec![None; rays.len()];
        let mut b = vec![None; rays.len()];
        latest.closest_hits(&rays, 0.0, &mut a);
        first.closest_hits(&rays, 0.0, &mut b);
        let segments: std::collections::BTreeSet<usize> =
            b.iter().flatten().map(|h| h.group).collect();
        assert!(
            segments.len() >= 4,
            "{name}: rays meet several segments ({segments:?})"
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
