//! Worldlines of uniform segments (`worldline = [{ until, velocity }, ...]` on a group or the
//! camera): the motion changes velocity at given world times, moving continuously. A group's
//! segments become groups of their own, at rest in the segment's frame and seen only at
//! emission events within the segment's world times; the camera sees, at each imaging event,
//! with its velocity there (docs/physics.md §12.4-§12.5).

use super::reader::{SceneResult, Table};
use super::speed::velocity;
use super::Group;
use crate::geometry::Geometry;
use crate::spacetime::{Boost, Event, Velocity};
use glam::DVec3;
use std::sync::Arc;

/// The most segments a worldline may have.
pub(crate) const MAX_SEGMENTS: usize = 4096;

/// One uniform segment: the velocity until world time `until` (None: for ever).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Segment {
    pub until: Option<f64>,
    pub velocity: Velocity,
}

/// The segments of a table's `worldline`, in time order; None if it has none. `dir_key` is the
/// table's key for a velocity's direction, which a worldline replaces.
pub(crate) fn read(t: &Table, dir_key: &str) -> SceneResult<Option<Vec<Segment>>> {
    if !t.has("worldline") {
        return Ok(None);
    }
    for k in ["velocity", dir_key, "beta", "rapidity", "one_minus_beta"] {
        if t.has(k) {
            return Err(t.error(
                k,
                "give the motion either as a velocity or as a worldline, not both",
            ));
        }
    }
    let tables = t.tables("worldline")?;
    if tables.len() > MAX_SEGMENTS {
        return Err(t.error(
            "worldline",
            format!(
                "{} segments: at most {MAX_SEGMENTS} (each segment of a group is a copy of its geometry)",
                tables.len()
            ),
        ));
    }
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

/// A worldline of uniform segments through the event `anchor`: continuous, each segment's
/// velocity held through its span of world time.
#[derive(Clone, Debug, PartialEq)]
pub struct Worldline {
    anchor: Event,
    segments: Vec<Segment>,
    spans: Vec<(f64, f64)>,
}

impl Worldline {
    /// Through `anchor`, with `segments` in time order (neighbours of one velocity merged).
    pub(crate) fn new(anchor: Event, segments: &[Segment]) -> Worldline {
        let segments = merged(segments);
        let spans = spans(&segments);
        Worldline {
            anchor,
            segments,
            spans,
        }
    }

    /// The world time of the event it was given through.
    pub fn anchor_time(&self) -> f64 {
        self.anchor.t
    }

    /// Whether it is one uniform motion.
    pub fn is_uniform(&self) -> bool {
        self.segments.len() == 1
    }

    /// `f(velocity, dt)` summed over the segments, dt the share of each segment's span in the
    /// world times from the anchor to `t` (negative before the anchor).
    fn along<T: std::iter::Sum<T> + std::ops::Neg<Output = T>>(
        &self,
        t: f64,
        f: impl Fn(&Velocity, f64) -> T,
    ) -> T {
        let t0 = self.anchor.t;
        let (lo, hi) = if t >= t0 { (t0, t) } else { (t, t0) };
        let sum: T = self
            .segments
            .iter()
            .zip(&self.spans)
            .map(|(s, &(a, b))| f(&s.velocity, (b.min(hi) - a.max(lo)).max(0.0)))
            .sum();
        if t >= t0 {
            sum
        } else {
            -sum
        }
    }

    /// Where it is at world time `t`.
    pub fn position(&self, t: f64) -> DVec3 {
        self.anchor.x + self.along(t, |v, dt| v.beta_vec() * dt)
    }

    /// Its velocity at world time `t` (a segment's own from its start, up to its end).
    pub fn velocity(&self, t: f64) -> Velocity {
        let k = self.spans.partition_point(|&(_, end)| end <= t);
        self.segments[k.min(self.segments.len() - 1)].velocity
    }

    /// The proper time from the anchor to world time `t` (negative before it).
    pub fn proper_time(&self, t: f64) -> f64 {
        self.along(t, |v, dt| dt / v.gamma())
    }

    /// The world time at which the proper time from the anchor is `tau`.
    pub fn world_time(&self, tau: f64) -> f64 {
        // Segment by segment from the anchor, forward or backward in time.
        let t0 = self.anchor.t;
        let k0 = self.spans.partition_point(|&(_, end)| end <= t0);
        let k0 = k0.min(self.segments.len() - 1);
        let (mut t, mut left) = (t0, tau);
        if tau >= 0.0 {
            for k in k0..self.segments.len() {
                let g = self.segments[k].velocity.gamma();
                let end = self.spans[k].1;
                if left <= (end - t) / g || k + 1 == self.segments.len() {
                    return t + left * g;
                }
                left -= (end - t) / g;
                t = end;
            }
        } else {
            for k in (0..=k0).rev() {
                let g = self.segments[k].velocity.gamma();
                let start = self.spans[k].0;
                if -left <= (t - start) / g || k == 0 {
                    return t + left * g;
                }
                left += (t - start) / g;
                t = start;
            }
        }
        t
    }

    /// The same worldline moved by the spacetime translation `shift`.
    pub fn translated(&self, shift: Event) -> Worldline {
        let mut w = self.clone();
        w.anchor = w.anchor + shift;
        for s in &mut w.segments {
            s.until = s.until.map(|u| u + shift.t);
        }
        for sp in &mut w.spans {
            *sp = (sp.0 + shift.t, sp.1 + shift.t);
        }
        w
    }
}

/// How many groups `segments` make (neighbours of one velocity are one).
pub(crate) fn group_count(segments: &[Segment]) -> usize {
    merged(segments).len()
}

/// The groups a worldline makes of one group's geometry: one per segment (neighbours of one
/// velocity merged), each with the geometry placed where the group's origin rests in that
/// segment's frame and seen only at emission events in the segment's world times. One segment
/// is the uniform group itself.
pub(crate) fn groups(
    t: &Table,
    name: &str,
    geometry: Arc<Geometry>,
    segments: &[Segment],
) -> SceneResult<Vec<Group>> {
    let line = Worldline::new(Event::new(0.0, DVec3::ZERO), segments);
    let (segments, spans) = (&line.segments, &line.spans);
    if let [one] = segments.as_slice() {
        return Ok(vec![Group {
            name: name.to_string(),
            velocity: one.velocity,
            geometry,
            window: None,
        }]);
    }
    segments
        .iter()
        .zip(spans)
        .map(|(s, &(a, b))| {
            // An event of the origin's worldline within the span (the one nearest world time 0),
            // and where that puts the origin, at rest, in the segment's frame.
            let when = 0.0f64.clamp(a, b);
            let on_line = Event::new(when, line.position(when));
            let rest = Boost::to_rest(&s.velocity).event(on_line).x;
            let reach = rest.abs().max_element() + geometry.bounds().max_abs();
            if reach > super::envelope::MAX_MAGNITUDE {
                return Err(t.error(
                    "worldline",
                    format!(
                        "a segment puts the group {reach:e} from the origin of its frame: {}",
                        super::envelope::too_large(reach)
                    ),
                ));
            }
            let geometry = if rest == DVec3::ZERO {
                geometry.clone()
            } else {
                Arc::new(geometry.translated(rest))
            };
            Ok(Group {
                name: name.to_string(),
                velocity: s.velocity,
                geometry,
                window: Some(crate::spacetime::Window::world(a, b)),
            })
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
        let line = Worldline::new(Event::new(0.0, DVec3::ZERO), &s);
        let x = |t: f64| line.position(t).x;
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

    #[test]
    fn proper_time_and_world_time_are_inverse() {
        // The twin: out at 0.8c until 10, back at 0.8c; anchored at (0, 3).
        let line = Worldline::new(
            Event::new(0.0, DVec3::new(3.0, 0.0, 0.0)),
            &[seg(Some(10.0), 0.8), seg(None, -0.8)],
        );
        assert!((line.proper_time(20.0) - 12.0).abs() < 1e-12);
        assert!((line.proper_time(-5.0) + 3.0).abs() < 1e-12);
        for tau in [-7.0, -1.0, 0.0, 2.0, 6.0, 8.0, 12.0, 30.0] {
            let t = line.world_time(tau);
            assert!((line.proper_time(t) - tau).abs() < 1e-12, "{tau}: {t}");
        }
        assert!((line.position(20.0).x - 3.0).abs() < 1e-12);
        assert_eq!(line.velocity(9.0).beta_vec().x, 0.8);
        assert!(line.velocity(10.0).beta_vec().x < 0.0);
    }
}
