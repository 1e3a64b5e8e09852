//! Worldlines of uniform segments (`worldline = [{ until, velocity }, ...]` on a group): the
//! group's motion changes velocity at given world times, its origin moving continuously. Each
//! segment becomes a group of its own, at rest in the segment's frame and seen only at emission
//! events within the segment's world times (docs/physics.md §12.4).

use super::reader::{SceneResult, Table};
use super::speed::velocity;
use super::Group;
use crate::geometry::Geometry;
use crate::spacetime::{Boost, Event, Velocity};
use glam::DVec3;
use std::sync::Arc;

/// One uniform segment: the velocity until world time `until` (None: for ever).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Segment {
    pub until: Option<f64>,
    pub velocity: Velocity,
}

/// The segments of a group's `worldline`, in time order; None if it has none.
pub(crate) fn read(t: &Table) -> SceneResult<Option<Vec<Segment>>> {
    if !t.has("worldline") {
        return Ok(None);
    }
    for k in [
        "velocity",
        "direction",
        "beta",
        "rapidity",
        "one_minus_beta",
    ] {
        if t.has(k) {
            return Err(t.error(
                k,
                "give the motion either as a velocity or as a worldline, not both",
            ));
        }
    }
    let tables = t.tables("worldline")?;
    if tables.is_empty() {
        return Err(t.error(
            "worldline",
            "give at least one segment: { velocity = [...] }",
        ));
    }
    let mut segments = Vec::with_capacity(tables.len());
    let last = tables.len() - 1;
    for (i, s) in tables.iter().enumerate() {
        if s.has("acceleration") {
            return Err(s.error(
                "acceleration",
                "segments of constant proper acceleration are not built yet: give the motion as uniform segments ({ until, velocity })",
            ));
        }
        let v = velocity(s, "direction")?.ok_or_else(|| {
            s.error(
                "velocity",
                "missing: a segment needs velocity = [...] (or direction and a speed)",
            )
        })?;
        let until = s.f64("until")?;
        if until.is_none() && i < last {
            return Err(s.error(
                "until",
                format!(
                    "missing: segment {} needs the world time it ends at (only the last lasts for ever)",
                    i + 1
                ),
            ));
        }
        if let (Some(prev), Some(u)) = (segments.last().and_then(|p: &Segment| p.until), until) {
            if u <= prev {
                let n = s.get("until").expect("read above");
                return Err(s.error_at(
                    n,
                    "until",
                    format!("segment {} ends at {u}, not after the segment before it ({prev}): segments are in time order and do not overlap", i + 1),
                ));
            }
        }
        s.finish(&[
            "until",
            "velocity",
            "direction",
            "beta",
            "rapidity",
            "one_minus_beta",
        ])?;
        segments.push(Segment { until, velocity: v });
    }
    Ok(Some(segments))
}

/// Neighbouring segments of the same velocity as one (so that they render as one, to the bit).
fn merged(segments: &[Segment]) -> Vec<Segment> {
    let mut out: Vec<Segment> = Vec::with_capacity(segments.len());
    for s in segments {
        match out.last_mut() {
            Some(p) if p.velocity == s.velocity => p.until = s.until,
            _ => out.push(*s),
        }
    }
    // After the last end the motion goes on as it was.
    if let Some(l) = out.last_mut() {
        l.until = None;
    }
    out
}

/// The world-time span of each segment: from the end of the one before (or −∞) to its own end
/// (or +∞).
fn spans(segments: &[Segment]) -> Vec<(f64, f64)> {
    let mut start = f64::NEG_INFINITY;
    segments
        .iter()
        .map(|s| {
            let end = s.until.unwrap_or(f64::INFINITY);
            let span = (start, end);
            start = end;
            span
        })
        .collect()
}

/// Where the group's origin is at world time `t`: it passes the world origin at world time 0
/// (every group's convention) and moves with each segment's velocity through its span.
fn origin_at(segments: &[Segment], spans: &[(f64, f64)], t: f64) -> DVec3 {
    let (lo, hi) = if t >= 0.0 { (0.0, t) } else { (t, 0.0) };
    let travelled: DVec3 = segments
        .iter()
        .zip(spans)
        .map(|(s, &(a, b))| {
            let overlap = (b.min(hi) - a.max(lo)).max(0.0);
            s.velocity.beta_vec() * overlap
        })
        .sum();
    if t >= 0.0 {
        travelled
    } else {
        -travelled
    }
}

/// The groups a worldline makes of one group's geometry: one per segment (neighbours of one
/// velocity merged), each with the geometry placed where the group's origin rests in that
/// segment's frame and seen only at emission events in the segment's world times. One segment
/// is the uniform group itself.
pub(crate) fn groups(name: &str, geometry: Arc<Geometry>, segments: &[Segment]) -> Vec<Group> {
    let segments = merged(segments);
    let spans = spans(&segments);
    if let [one] = segments.as_slice() {
        return vec![Group {
            name: name.to_string(),
            velocity: one.velocity,
            geometry,
            during: None,
        }];
    }
    segments
        .iter()
        .zip(&spans)
        .map(|(s, &(a, b))| {
            // An event of the origin's worldline within the span (the one nearest world time 0),
            // and where that puts the origin, at rest, in the segment's frame.
            let t = 0.0f64.clamp(a, b);
            let on_line = Event::new(t, origin_at(&segments, &spans, t));
            let rest = Boost::to_rest(&s.velocity).event(on_line).x;
            let geometry = if rest == DVec3::ZERO {
                geometry.clone()
            } else {
                Arc::new(geometry.translated(rest))
            };
            Group {
                name: name.to_string(),
                velocity: s.velocity,
                geometry,
                during: Some((a, b)),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(until: Option<f64>, bx: f64) -> Segment {
        Segment {
            until,
            velocity: Velocity::from_beta_vec(DVec3::new(bx, 0.0, 0.0)).unwrap(),
        }
    }

    #[test]
    fn origin_moves_continuously_through_the_segments() {
        let s = [seg(Some(-2.0), 0.5), seg(Some(3.0), -0.25), seg(None, 0.8)];
        let sp = spans(&s);
        let x = |t: f64| origin_at(&s, &sp, t).x;
        assert_eq!(x(0.0), 0.0);
        for (t, want) in [
            (2.0, -0.5),
            (5.0, -0.75 + 1.6),
            (-2.0, 0.5),
            (-4.0, 0.5 - 1.0),
        ] {
            assert!(
                (x(t) - want).abs() < 1e-15,
                "at {t}: {} against {want}",
                x(t)
            );
        }
    }

    #[test]
    fn equal_neighbours_merge_into_one() {
        let m = merged(&[seg(Some(1.0), 0.5), seg(Some(4.0), 0.5), seg(None, 0.1)]);
        assert_eq!(m, vec![seg(Some(4.0), 0.5), seg(None, 0.1)]);
        assert_eq!(
            merged(&[seg(Some(1.0), 0.5), seg(Some(2.0), 0.5)]),
            vec![seg(None, 0.5)]
        );
    }
}
