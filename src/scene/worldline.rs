//! Worldlines of segments (`worldline = [{ until, velocity }, { until, acceleration }, ...]` on
//! a group or the camera): each segment uniform or of constant proper acceleration (hyperbolic),
//! moving continuously. A group's segments become groups of their own, at rest in the segment's
//! (starting) frame and seen only at emission events in the segment's window; the camera sees,
//! at each imaging event, with its velocity there (docs/physics.md §12.4, §12.5, §12.7).

use super::reader::{SceneResult, Table};
use super::speed::velocity;
use super::Group;
use crate::geometry::Geometry;
use crate::spacetime::{Boost, Event, Hyperbola, Slice, Velocity, Window};
use glam::DVec3;
use std::sync::Arc;

/// The most segments a worldline may have.
pub(crate) const MAX_SEGMENTS: usize = 4096;

/// The most primitives a group with an accelerated segment or a turning spinning body may
/// have: each ray tries them all (render/world/accelerated.rs, render/world/turning.rs).
pub(crate) const MAX_ACCELERATED_PRIMS: u32 = 4096;

/// Why a group's geometry cannot take an accelerated segment, if it cannot: too many
/// primitives, a rod (whose crossing with a null ray in Rindler coordinates is no quadratic),
/// or a spinning object.
pub(crate) fn accelerated_refusal(geometry: &Geometry) -> Option<String> {
    let n = geometry.len();
    if n > MAX_ACCELERATED_PRIMS {
        return Some(format!("the group has {n} primitives: a group with an accelerated segment is intersected primitive by primitive, at most {MAX_ACCELERATED_PRIMS}"));
    }
    if geometry.spins() {
        return Some(
            "spinning objects in a group with an accelerated segment are not built yet".into(),
        );
    }
    None
}

/// Whether any segment accelerates.
pub(crate) fn accelerates(segments: &[Segment]) -> bool {
    segments
        .iter()
        .any(|s| matches!(s.motion, Motion::Accelerated(_)))
}

/// How a segment moves, as the scene gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Motion {
    /// At this velocity.
    Uniform(Velocity),
    /// At the velocity the segment before it reached (a uniform segment without a velocity,
    /// after an accelerated one).
    Coast,
    /// With this proper acceleration (in the frame it starts at rest in).
    Accelerated(DVec3),
}

/// One segment: its motion until world time `until` (None: for ever).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Segment {
    pub until: Option<f64>,
    pub motion: Motion,
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
    let mut segments: Vec<Segment> = Vec::with_capacity(tables.len());
    let last = tables.len() - 1;
    for (i, s) in tables.iter().enumerate() {
        let until = s.f64("until")?;
        let after_acceleration = matches!(
            segments.last(),
            Some(p) if matches!(p.motion, Motion::Accelerated(_) | Motion::Coast)
        );
        let motion = match s.vec3("acceleration")? {
            Some(a) => {
                if let Some(k) = ["velocity", "direction", "beta", "rapidity", "one_minus_beta"]
                    .into_iter()
                    .find(|k| s.has(k))
                {
                    return Err(s.error(
                        k,
                        "an accelerated segment starts with the velocity the one before it ended with: give its acceleration alone",
                    ));
                }
                if i == 0 {
                    return Err(s.error(
                        "acceleration",
                        "the first segment cannot accelerate: give a uniform segment before it ({ until, velocity }), whose velocity it starts from",
                    ));
                }
                if until.is_none() {
                    return Err(s.error(
                        "acceleration",
                        format!("segment {} accelerates for ever: give the world time it ends at (`until`); after it the motion goes on at the velocity reached", i + 1),
                    ));
                }
                if !(a.is_finite() && a.length() > 0.0) {
                    return Err(s.error(
                        "acceleration",
                        "give a proper acceleration that is not zero (units of c² per unit length)",
                    ));
                }
                Motion::Accelerated(a)
            }
            None => match velocity(s, "direction")? {
                Some(v) => Motion::Uniform(v),
                None if after_acceleration => Motion::Coast,
                None => {
                    return Err(s.error(
                        "velocity",
                        "missing: a segment needs velocity = [...] (or direction and a speed), or an acceleration",
                    ))
                }
            },
        };
        if until.is_none() && i < last {
            return Err(s.error(
                "until",
                format!(
                    "missing: segment {} needs the world time it ends at (only the last lasts for ever)",
                    i + 1
                ),
            ));
        }
        if let (Some(prev), Some(u)) = (segments.last().and_then(|p| p.until), until) {
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
            "acceleration",
        ])?;
        segments.push(Segment { until, motion });
    }
    Ok(Some(segments))
}

/// A piece of a resolved worldline.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Piece {
    /// Uniform motion at `velocity` through the event `at`.
    Uniform { velocity: Velocity, at: Event },
    /// Hyperbolic motion from its start.
    Accelerated(Hyperbola),
}

impl Piece {
    fn event_at(&self, t: f64) -> Event {
        match self {
            Piece::Uniform { velocity, at } => {
                Event::new(t, at.x + velocity.beta_vec() * (t - at.t))
            }
            Piece::Accelerated(h) => h.event(h.theta_at(t)),
        }
    }

    fn velocity_at(&self, t: f64) -> Velocity {
        match self {
            Piece::Uniform { velocity, .. } => *velocity,
            Piece::Accelerated(h) => h.velocity(h.theta_at(t)),
        }
    }

    /// The proper time from world time `a` to `b` on it.
    fn proper_time(&self, a: f64, b: f64) -> f64 {
        match self {
            Piece::Uniform { velocity, .. } => (b - a) / velocity.gamma(),
            Piece::Accelerated(h) => (h.theta_at(b) - h.theta_at(a)) / h.a,
        }
    }

    /// The world time a proper time `tau` after world time `from` on it.
    fn world_time_after(&self, from: f64, tau: f64) -> f64 {
        match self {
            Piece::Uniform { velocity, .. } => from + tau * velocity.gamma(),
            Piece::Accelerated(h) => h.time(h.theta_at(from) + h.a * tau),
        }
    }

    fn translated(&self, shift: Event) -> Piece {
        match *self {
            Piece::Uniform { velocity, at } => Piece::Uniform {
                velocity,
                at: at + shift,
            },
            Piece::Accelerated(h) => Piece::Accelerated(Hyperbola {
                start: h.start + shift,
                ..h
            }),
        }
    }
}

/// Resolve segments into pieces through `anchor`, with their world-time spans: velocities
/// chained (an accelerated segment starts at the velocity before it, a coasting one keeps the
/// velocity reached), positions continuous, neighbouring uniform pieces of one velocity
/// merged (so that they render as one, to the bit), and after an accelerated last segment a
/// coast at the velocity reached.
fn resolve(anchor: Event, segments: &[Segment]) -> (Vec<Piece>, Vec<(f64, f64)>) {
    let mut pieces: Vec<Piece> = Vec::with_capacity(segments.len() + 1);
    let mut spans: Vec<(f64, f64)> = Vec::with_capacity(segments.len() + 1);
    // Positions first relative to an arbitrary origin, then moved through the anchor.
    let mut start = f64::NEG_INFINITY;
    let mut here = Event::ORIGIN;
    for s in segments {
        let end = s.until.unwrap_or(f64::INFINITY);
        let (last_v, last) = match pieces.last() {
            Some(p) => (p.velocity_at(start), Some(p)),
            None => (Velocity::ZERO, None),
        };
        if let Some(p) = last {
            here = p.event_at(start);
        }
        let piece = match s.motion {
            Motion::Uniform(v) if start == f64::NEG_INFINITY => Piece::Uniform {
                velocity: v,
                at: Event::new(if end.is_finite() { end } else { 0.0 }, DVec3::ZERO),
            },
            Motion::Uniform(v) => Piece::Uniform {
                velocity: v,
                at: here,
            },
            Motion::Coast => Piece::Uniform {
                velocity: last_v,
                at: here,
            },
            Motion::Accelerated(a) => {
                Piece::Accelerated(Hyperbola::new(here, last_v, a).expect("checked on reading"))
            }
        };
        // Neighbouring uniform pieces of one velocity are one.
        match (pieces.last(), &piece) {
            (Some(Piece::Uniform { velocity: v1, .. }), Piece::Uniform { velocity: v2, .. })
                if v1 == v2 =>
            {
                spans.last_mut().expect("a piece").1 = end;
            }
            _ => {
                pieces.push(piece);
                spans.push((start, end));
            }
        }
        start = end;
    }
    // After the last end the motion goes on as it was, or at the velocity reached.
    match pieces.last() {
        Some(Piece::Accelerated(h)) => {
            let end = spans.last().expect("a piece").1;
            let at = h.event(h.theta_at(end));
            pieces.push(Piece::Uniform {
                velocity: h.velocity(h.theta_at(end)),
                at,
            });
            spans.push((end, f64::INFINITY));
        }
        _ => spans.last_mut().expect("a piece").1 = f64::INFINITY,
    }
    // Through the anchor.
    let k = spans
        .partition_point(|&(_, end)| end <= anchor.t)
        .min(pieces.len() - 1);
    let off = anchor.x - pieces[k].event_at(anchor.t).x;
    let pieces = pieces
        .iter()
        .map(|p| p.translated(Event::new(0.0, off)))
        .collect();
    (pieces, spans)
}

/// A worldline of segments through the event `anchor`: continuous, each segment's motion held
/// through its span of world time.
#[derive(Clone, Debug, PartialEq)]
pub struct Worldline {
    anchor: Event,
    pieces: Vec<Piece>,
    spans: Vec<(f64, f64)>,
}

impl Worldline {
    /// Through `anchor`, with `segments` in time order.
    pub(crate) fn new(anchor: Event, segments: &[Segment]) -> Worldline {
        let (pieces, spans) = resolve(anchor, segments);
        Worldline {
            anchor,
            pieces,
            spans,
        }
    }

    /// The world time of the event it was given through.
    pub fn anchor_time(&self) -> f64 {
        self.anchor.t
    }

    /// Whether it is one uniform motion.
    pub fn is_uniform(&self) -> bool {
        self.pieces.len() == 1
    }

    /// The piece that holds world time `t` (a piece's own from its start, up to its end).
    fn piece(&self, t: f64) -> usize {
        self.spans
            .partition_point(|&(_, end)| end <= t)
            .min(self.pieces.len() - 1)
    }

    /// Where it is at world time `t`.
    pub fn position(&self, t: f64) -> DVec3 {
        self.pieces[self.piece(t)].event_at(t).x
    }

    /// Its velocity at world time `t`.
    pub fn velocity(&self, t: f64) -> Velocity {
        self.pieces[self.piece(t)].velocity_at(t)
    }

    /// The proper time from the anchor to world time `t` (negative before it).
    pub fn proper_time(&self, t: f64) -> f64 {
        let t0 = self.anchor.t;
        let (lo, hi, sign) = if t >= t0 { (t0, t, 1.0) } else { (t, t0, -1.0) };
        let sum: f64 = self
            .pieces
            .iter()
            .zip(&self.spans)
            .map(|(p, &(a, b))| {
                let (a, b) = (a.max(lo), b.min(hi));
                if b > a {
                    p.proper_time(a, b)
                } else {
                    0.0
                }
            })
            .sum();
        sign * sum
    }

    /// The world time at which the proper time from the anchor is `tau`.
    pub fn world_time(&self, tau: f64) -> f64 {
        // Piece by piece from the anchor, forward or backward in time.
        let k0 = self.piece(self.anchor.t);
        let (mut t, mut left) = (self.anchor.t, tau);
        let n = self.pieces.len();
        if tau >= 0.0 {
            for k in k0..n {
                let end = self.spans[k].1;
                let here = self.pieces[k].proper_time(t, end);
                if left <= here || k + 1 == n {
                    return self.pieces[k].world_time_after(t, left);
                }
                left -= here;
                t = end;
            }
        } else {
            for k in (0..=k0).rev() {
                let start = self.spans[k].0;
                let here = self.pieces[k].proper_time(start, t);
                if -left <= here || k == 0 {
                    return self.pieces[k].world_time_after(t, left);
                }
                left += here;
                t = start;
            }
        }
        t
    }

    /// The world time of the event on it that lies on the past light cone of `e`: the root
    /// of g(t) = (e.t − t) − |X(t) − e.x|, which falls at least 1 − |v| > 0 per unit of t (so
    /// the root is one), by Newton's steps kept within a bracket that halves when a step
    /// leaves it.
    pub fn retarded(&self, e: Event) -> f64 {
        let g = |t: f64| {
            let d = self.position(t) - e.x;
            let len = d.length();
            let slope = if len > 0.0 {
                -1.0 - d.dot(self.velocity(t).beta_vec()) / len
            } else {
                -1.0
            };
            ((e.t - t) - len, slope)
        };
        // g(e.t) ≤ 0; step back until g > 0.
        let mut hi = e.t;
        let mut back = 1.0 + (self.position(e.t) - e.x).length();
        let mut lo = e.t - back;
        while g(lo).0 <= 0.0 {
            back *= 2.0;
            lo = e.t - back;
            if !lo.is_finite() {
                return lo;
            }
        }
        let mut t = 0.5 * (lo + hi);
        for _ in 0..100 {
            let (v, slope) = g(t);
            if v > 0.0 {
                lo = t;
            } else {
                hi = t;
            }
            let newton = t - v / slope;
            let next = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            let done = (next - t).abs() <= 1e-15 * t.abs().max(1.0);
            t = next;
            if done || hi - lo <= 1e-15 * t.abs().max(1.0) {
                break;
            }
        }
        t
    }

    /// The same worldline moved by the spacetime translation `shift`.
    pub fn translated(&self, shift: Event) -> Worldline {
        Worldline {
            anchor: self.anchor + shift,
            pieces: self.pieces.iter().map(|p| p.translated(shift)).collect(),
            spans: self
                .spans
                .iter()
                .map(|sp| (sp.0 + shift.t, sp.1 + shift.t))
                .collect(),
        }
    }

    /// The hyperplane between piece k and the next: world time between uniform pieces; where
    /// either accelerates, the simultaneity of the frame moving with the accelerated one there.
    fn junction(&self, k: usize) -> Slice {
        let t = self.spans[k].1;
        let moving = match (&self.pieces[k], &self.pieces[k + 1]) {
            (Piece::Accelerated(_), _) => Some(self.pieces[k].velocity_at(t)),
            (_, Piece::Accelerated(h)) => Some(h.v0),
            _ => None,
        };
        match moving {
            None => Slice::world(t),
            Some(v) => {
                let e = self.pieces[k].event_at(t);
                Slice::of(v, Boost::to_rest(&v).event(e).t)
            }
        }
    }

    /// The window of piece k: from its junction with the one before to the one after.
    fn window(&self, k: usize) -> Window {
        let from = if k == 0 {
            Slice::world(f64::NEG_INFINITY)
        } else {
            self.junction(k - 1)
        };
        let to = if k + 1 == self.pieces.len() {
            Slice::world(f64::INFINITY)
        } else {
            self.junction(k)
        };
        Window { from, to }
    }
}

/// How many groups `segments` make (neighbours of one velocity are one).
pub(crate) fn group_count(segments: &[Segment]) -> usize {
    Worldline::new(Event::ORIGIN, segments).pieces.len()
}

/// The groups a worldline makes of one group's geometry: one per piece, each seen only at
/// emission events in the piece's window. A uniform piece has the geometry placed where the
/// group's origin rests in that piece's frame; an accelerated one has it as given, moving
/// Born-rigidly with the origin from the start (docs/physics.md §12.7). One piece is the
/// uniform group itself.
pub(crate) fn groups(
    t: &Table,
    name: &str,
    geometry: Arc<Geometry>,
    segments: &[Segment],
) -> SceneResult<Vec<Group>> {
    let line = Worldline::new(Event::ORIGIN, segments);
    if let [Piece::Uniform { velocity, .. }] = line.pieces.as_slice() {
        return Ok(vec![Group {
            name: name.to_string(),
            velocity: *velocity,
            geometry,
            window: None,
            accelerated: None,
        }]);
    }
    let too_far = |reach: f64| {
        t.error(
            "worldline",
            format!(
                "a segment puts the group {reach:e} from the origin of its frame: {}",
                super::envelope::too_large(reach)
            ),
        )
    };
    line.pieces
        .iter()
        .zip(&line.spans)
        .enumerate()
        .map(|(k, (piece, &(a, b)))| {
            let window = Some(line.window(k));
            match piece {
                Piece::Uniform { velocity, .. } => {
                    // An event of the origin's worldline within the span (the one nearest
                    // world time 0), and where that puts the origin, at rest, in the frame.
                    let when = 0.0f64.clamp(a, b);
                    let on_line = piece.event_at(when);
                    let rest = Boost::to_rest(velocity).event(on_line).x;
                    let reach = rest.abs().max_element() + geometry.bounds().max_abs();
                    if reach > super::envelope::MAX_MAGNITUDE {
                        return Err(too_far(reach));
                    }
                    let geometry = if rest == DVec3::ZERO {
                        geometry.clone()
                    } else {
                        Arc::new(geometry.translated(rest))
                    };
                    Ok(Group {
                        name: name.to_string(),
                        velocity: *velocity,
                        geometry,
                        window,
                        accelerated: None,
                    })
                }
                Piece::Accelerated(h) => {
                    // Accelerated across its motion, a body's frame at the end is the plain
                    // boost to its velocity turned by a Thomas-Wigner rotation, which the
                    // segments after it do not carry yet.
                    let across = h.v0.direction().cross(h.axis).length();
                    if !h.v0.is_zero() && across > 1e-9 {
                        return Err(t.error(
                            "worldline",
                            "a segment accelerates across the velocity it starts with: only along it (or from rest) is built yet (the body would come out of it turned by a Thomas-Wigner rotation)".to_string(),
                        ));
                    }
                    // A rod is marched with steps that shrink as e^-θ_end (accelerated.rs).
                    let theta_end = h.theta_at(b);
                    let rods = (0..geometry.len()).any(|i| {
                        matches!(geometry.prim(i), crate::geometry::Primitive::Capsule { .. })
                    });
                    if rods && theta_end > 5.0 {
                        return Err(t.error(
                            "worldline",
                            format!("a segment accelerates the group to rapidity {theta_end:.3} (more than 5, a speed of 0.99991c, relative to its start): its rods are marched with steps too fine to finish; give the group spheres, boxes or meshes, or a shorter segment"),
                        ));
                    }
                    let start = h.to_start_frame().event(h.start);
                    let sweep = (1.0 / h.a + geometry.bounds().support(h.axis))
                        * crate::spacetime::cosh_m1(h.theta_at(b));
                    let reach = start.x.abs().max_element() + geometry.bounds().max_abs() + sweep;
                    if reach > super::envelope::MAX_MAGNITUDE {
                        return Err(too_far(reach));
                    }
                    // Every point must stay ahead of the horizon, 1/a behind the origin.
                    let behind = geometry.bounds().support(-h.axis);
                    if behind * h.a >= 1.0 {
                        return Err(t.error(
                            "worldline",
                            format!(
                                "at acceleration {} the horizon lies {:e} behind the group's origin, and the group reaches {behind:e} behind it: a body moving Born-rigidly must lie ahead of its horizon (accelerate less, or move the origin back)",
                                h.a,
                                1.0 / h.a
                            ),
                        ));
                    }
                    Ok(Group {
                        name: name.to_string(),
                        velocity: h.v0,
                        geometry: geometry.clone(),
                        window,
                        accelerated: Some(super::Accelerated {
                            start,
                            a: h.a,
                            axis: h.axis,
                            theta_end: h.theta_at(b),
                        }),
                    })
                }
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
            motion: Motion::Uniform(Velocity::from_beta_vec(DVec3::new(bx, 0.0, 0.0)).unwrap()),
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
        let (p, spans) = resolve(
            Event::ORIGIN,
            &[seg(Some(1.0), 0.5), seg(Some(4.0), 0.5), seg(None, 0.1)],
        );
        assert_eq!(p.len(), 2);
        assert_eq!(spans, vec![(f64::NEG_INFINITY, 4.0), (4.0, f64::INFINITY)]);
        let (p, spans) = resolve(Event::ORIGIN, &[seg(Some(1.0), 0.5), seg(Some(2.0), 0.5)]);
        assert_eq!(p.len(), 1);
        assert_eq!(spans, vec![(f64::NEG_INFINITY, f64::INFINITY)]);
    }

    fn accel(until: f64, ax: f64) -> Segment {
        Segment {
            until: Some(until),
            motion: Motion::Accelerated(DVec3::new(ax, 0.0, 0.0)),
        }
    }

    /// A smooth turnaround: out at 0.8c, decelerating at a until back at −0.8c, then coasting.
    /// Rapidity ±φ, φ = artanh 0.8: the turn takes 2φ/a of proper time and 2 sinh φ / a of
    /// world time, and brings the traveller (cosh φ − 1)/a farther out.
    #[test]
    fn a_smooth_turnaround_has_the_closed_form_times() {
        let a = 0.5;
        let phi = 0.8f64.atanh();
        let turn = 2.0 * phi.sinh() / a;
        let line = Worldline::new(
            Event::ORIGIN,
            &[
                seg(Some(10.0), 0.8),
                accel(10.0 + turn, -a),
                Segment {
                    until: None,
                    motion: Motion::Coast,
                },
            ],
        );
        assert_eq!(line.pieces.len(), 3);
        let tau = line.proper_time(10.0 + turn);
        assert!((tau - (6.0 + 2.0 * phi / a)).abs() < 1e-12, "{tau}");
        let far = line.position(10.0 + turn / 2.0).x;
        assert!(
            (far - (8.0 + (phi.cosh() - 1.0) / a)).abs() < 1e-12,
            "{far}"
        );
        let v = line.velocity(10.0 + turn + 1.0).beta_vec();
        assert!((v.x + 0.8).abs() < 1e-12 && v.y == 0.0, "{v}");
        assert!((line.position(10.0 + turn).x - 8.0).abs() < 1e-12);
        // Home again at 20 + turn, symmetric.
        assert!(line.position(20.0 + turn).x.abs() < 1e-12);
        for tau in [-3.0, 1.0, 6.0, 7.0, 8.5, 14.0, 40.0] {
            let t = line.world_time(tau);
            assert!((line.proper_time(t) - tau).abs() < 1e-12, "{tau}: {t}");
        }
        // Continuous at the junctions, and each junction the moving frame's simultaneity.
        for t in [10.0, 10.0 + turn] {
            let (x0, x1) = (line.position(t - 1e-9).x, line.position(t + 1e-9).x);
            assert!((x1 - x0).abs() < 1e-8);
        }
        let w = line.window(1);
        assert_eq!(w.from.frame(), line.velocity(9.0));
        assert!((w.to.frame().beta_vec().x + 0.8).abs() < 1e-12);
        assert!(w.contains(Event::new(10.0 + turn / 2.0, DVec3::new(far, 0.0, 0.0))));
    }

    /// The retarded event lies on the past light cone of the event asked about.
    #[test]
    fn retarded_events_lie_on_the_past_light_cone() {
        let line = Worldline::new(
            Event::new(0.0, DVec3::new(1.0, 2.0, 0.0)),
            &[
                seg(Some(-3.0), 0.9),
                accel(2.0, -0.7),
                Segment {
                    until: None,
                    motion: Motion::Coast,
                },
            ],
        );
        for (t, x) in [
            (0.0, 5.0),
            (10.0, -3.0),
            (-20.0, 40.0),
            (3.0, 1.0),
            (100.0, 0.0),
        ] {
            let e = Event::new(t, DVec3::new(x, -1.0, 2.0));
            let te = line.retarded(e);
            let gap = (e.t - te) - (line.position(te) - e.x).length();
            assert!(
                te <= e.t && gap.abs() < 1e-12 * (1.0 + e.t.abs()),
                "{e:?}: {te}, {gap}"
            );
        }
    }

    /// A tiny acceleration moves as the uniform motion does, to its own small order.
    #[test]
    fn tiny_accelerations_converge_to_uniform_motion() {
        for a in [1e-3, 1e-6, 1e-9] {
            let line = Worldline::new(Event::ORIGIN, &[seg(Some(0.0), 0.6), accel(10.0, a)]);
            let x = line.position(10.0).x;
            // x = 6 + a t²/(2γ³) + O(a²).
            let g = 1.25f64;
            let want = 6.0 + a * 100.0 / (2.0 * g * g * g);
            assert!(
                (x - want).abs() < 1e3 * a * a + 1e-13,
                "a {a}: {x} against {want}"
            );
        }
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
