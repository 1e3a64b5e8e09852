//! Worldlines of segments, each uniform or of constant proper acceleration (hyperbolic), moving
//! continuously: where a body is, how fast, its proper time, the event on a given event's past
//! light cone, and each piece's window of emission events (docs/physics.md §12.4, §12.5, §12.7,
//! §12.8). Reading the segments and making a group's groups of them: `segments.rs`.

use crate::spacetime::{Boost, Event, Hyperbola, Slice, Velocity, Window};
use glam::{DMat3, DVec3};

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

/// A piece of a resolved worldline.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub(super) enum Piece {
    /// Uniform motion at `velocity` through the event `at`.
    Uniform { velocity: Velocity, at: Event },
    /// Hyperbolic motion from its start.
    Accelerated(Hyperbola),
}

impl Piece {
    pub(super) fn event_at(&self, t: f64) -> Event {
        match self {
            Piece::Uniform { velocity, at } => {
                Event::new(t, at.x + velocity.beta_vec() * (t - at.t))
            }
            Piece::Accelerated(h) => h.event(h.theta_at(t)),
        }
    }

    pub(super) fn velocity_at(&self, t: f64) -> Velocity {
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

/// A resolved worldline: its pieces, their world-time spans, and the turn of each piece's axes
/// (see [`Worldline::turns`]).
type Resolved = (Vec<Piece>, Vec<(f64, f64)>, Vec<DMat3>);

/// Resolve segments into pieces through `anchor`, with their world-time spans: velocities
/// chained (an accelerated segment starts at the velocity before it, a coasting one keeps the
/// velocity reached), positions continuous, neighbouring uniform pieces of one velocity (and
/// turn) merged (so that they render as one, to the bit), and after an accelerated last
/// segment a coast at the velocity reached. The axes turn across an acceleration by the
/// Thomas-Wigner rotation of its start velocity and the velocity it adds; a coast keeps them,
/// and a segment that gives its velocity starts again from the plain boost's.
fn resolve(anchor: Event, segments: &[Segment]) -> Resolved {
    let mut pieces: Vec<Piece> = Vec::with_capacity(segments.len() + 1);
    let mut spans: Vec<(f64, f64)> = Vec::with_capacity(segments.len() + 1);
    let mut turns: Vec<DMat3> = Vec::with_capacity(segments.len() + 1);
    // Positions first relative to an arbitrary origin, then moved through the anchor.
    let mut start = f64::NEG_INFINITY;
    let mut here = Event::ORIGIN;
    let mut turn = DMat3::IDENTITY;
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
            Motion::Uniform(v) => {
                turn = DMat3::IDENTITY;
                Piece::Uniform {
                    velocity: v,
                    at: here,
                }
            }
            Motion::Coast => Piece::Uniform {
                velocity: last_v,
                at: here,
            },
            Motion::Accelerated(a) => {
                Piece::Accelerated(Hyperbola::new(here, last_v, a).expect("checked on reading"))
            }
        };
        // Neighbouring uniform pieces of one velocity and turn are one.
        match (pieces.last(), &piece) {
            (Some(Piece::Uniform { velocity: v1, .. }), Piece::Uniform { velocity: v2, .. })
                if v1 == v2 && turns.last() == Some(&turn) =>
            {
                spans.last_mut().expect("a piece").1 = end;
            }
            _ => {
                pieces.push(piece);
                spans.push((start, end));
                turns.push(turn);
            }
        }
        if let Piece::Accelerated(h) = piece {
            turn *= h.wigner(h.theta_at(end));
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
            turns.push(turn);
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
    (pieces, spans, turns)
}

/// A worldline of segments through the event `anchor`: continuous, each segment's motion held
/// through its span of world time.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Worldline {
    anchor: Event,
    pub(super) pieces: Vec<Piece>,
    pub(super) spans: Vec<(f64, f64)>,
    /// Each piece's axes (at its start, for an accelerated one) as the rotation from those of
    /// the plain boost to its velocity: the identity but after an acceleration across the
    /// motion (docs/physics.md §12.7). A body's; a camera or light keeps the plain axes.
    pub(super) turns: Vec<DMat3>,
}

impl Worldline {
    /// Through `anchor`, with `segments` in time order.
    pub(crate) fn new(anchor: Event, segments: &[Segment]) -> Worldline {
        let (pieces, spans, turns) = resolve(anchor, segments);
        Worldline {
            anchor,
            pieces,
            spans,
            turns,
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
            turns: self.turns.clone(),
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
    pub(super) fn window(&self, k: usize) -> Window {
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
        let (p, spans, _) = resolve(
            Event::ORIGIN,
            &[seg(Some(1.0), 0.5), seg(Some(4.0), 0.5), seg(None, 0.1)],
        );
        assert_eq!(p.len(), 2);
        assert_eq!(spans, vec![(f64::NEG_INFINITY, 4.0), (4.0, f64::INFINITY)]);
        let (p, spans, _) = resolve(Event::ORIGIN, &[seg(Some(1.0), 0.5), seg(Some(2.0), 0.5)]);
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

    /// Axes turn across an acceleration across the motion (by the Thomas-Wigner rotation of
    /// the start velocity and the velocity added), not along it; a coast keeps the turn and a
    /// given velocity starts from the plain boost's axes again.
    #[test]
    fn axes_turn_across_an_acceleration_across_the_motion() {
        let v0 = Velocity::from_beta_vec(DVec3::new(0.0, 0.8, 0.0)).unwrap();
        let coast = Segment {
            until: Some(12.0),
            motion: Motion::Coast,
        };
        let line = Worldline::new(
            Event::ORIGIN,
            &[
                Segment {
                    until: Some(0.0),
                    motion: Motion::Uniform(v0),
                },
                accel(6.0, 0.3),
                coast,
                seg(None, 0.5),
            ],
        );
        assert_eq!(line.pieces.len(), 4);
        let Piece::Accelerated(h) = line.pieces[1] else {
            panic!("accelerated")
        };
        let want = crate::spacetime::wigner_rotation(
            &v0,
            &Velocity::from_rapidity(DVec3::X, h.theta_at(6.0)).unwrap(),
        );
        assert_eq!(line.turns[0], DMat3::IDENTITY);
        assert_eq!(line.turns[1], DMat3::IDENTITY);
        assert_eq!(line.turns[2], want);
        assert!(
            (want * DVec3::X).dot(DVec3::X) < 0.99,
            "a turn of some degrees"
        );
        assert_eq!(line.turns[3], DMat3::IDENTITY);
        // Along the motion nothing turns.
        let line = Worldline::new(Event::ORIGIN, &[seg(Some(0.0), 0.5), accel(3.0, 0.2)]);
        assert!(line.turns.iter().all(|&r| r == DMat3::IDENTITY));
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
