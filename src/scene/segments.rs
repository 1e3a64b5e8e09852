//! A `worldline = [{ until, velocity }, { until, acceleration }, ...]` as the scene file gives
//! it (on a group, the camera or a light), and the groups a group's worldline makes: one per
//! piece, each at rest in its piece's (starting) frame and seen only at emission events in the
//! piece's window (docs/physics.md §12.4, §12.7). The motion itself: `worldline.rs`.

use super::reader::{SceneResult, Table};
use super::speed::velocity;
pub(crate) use super::worldline::{Motion, Segment};
use super::worldline::{Piece, Worldline};
use super::Group;
use crate::geometry::Geometry;
use crate::spacetime::{Boost, Event};
use glam::{DMat3, DVec3};
use std::sync::Arc;

/// The most segments a worldline may have.
pub(crate) const MAX_SEGMENTS: usize = 4096;

/// The most primitives a group with an accelerated segment or a turning spinning body may
/// have: each ray tries them all (render/world/accelerated.rs, render/world/turning/).
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

/// Whose worldline a table's is (its messages say so).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Whose {
    Group,
    Camera,
    Light,
}

/// The segments of a table's `worldline`, in time order; None if it has none. `dir_key` is the
/// table's key for a velocity's direction, which a worldline replaces.
pub(crate) fn read(t: &Table, dir_key: &str, whose: Whose) -> SceneResult<Option<Vec<Segment>>> {
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
        let why = match whose {
            Whose::Group => {
                "a group's worldline: each segment holds a copy of the group's geometry"
            }
            Whose::Camera => "the camera's worldline",
            Whose::Light => "a light's worldline",
        };
        return Err(t.error(
            "worldline",
            format!("{} segments: at most {MAX_SEGMENTS} in {why}", tables.len()),
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
    // The last segment lasts for ever, unless it accelerates (then a coast follows it at the
    // velocity reached): an `until` on a uniform last segment would say nothing.
    if let (
        Some(Segment {
            until: Some(u),
            motion: Motion::Uniform(_) | Motion::Coast,
        }),
        Some(s),
    ) = (segments.last(), tables.last())
    {
        let n = s.get("until").expect("read above");
        return Err(s.error_at(
            n,
            "until",
            format!(
                "the last segment lasts for ever, so it has no end at {u}: leave `until` out, or add the segment that follows it (a group at rest after it: {{ velocity = [0, 0, 0] }})"
            ),
        ));
    }
    // An acceleration ends at the velocity it reached, which must be one the renderer keeps
    // exact, as a velocity given is.
    let line = Worldline::new(Event::ORIGIN, &segments);
    for (i, (segment, s)) in segments.iter().zip(&tables).enumerate() {
        if let (Motion::Accelerated(_), Some(u)) = (segment.motion, segment.until) {
            // The accelerated piece's own velocity at its end (at `u` the worldline is already
            // in the next piece, which may give a velocity of its own).
            let rapidity = line
                .pieces
                .iter()
                .zip(&line.spans)
                .find(|(p, span)| matches!(p, Piece::Accelerated(_)) && span.1 == u)
                .map_or_else(|| line.velocity(u), |(p, _)| p.velocity_at(u))
                .rapidity();
            if rapidity.is_nan() || rapidity > super::envelope::MAX_RAPIDITY {
                return Err(s.error(
                    "acceleration",
                    format!(
                        "segment {} reaches rapidity {rapidity:?} by its end (world time {u}), beyond the speeds rest-embree renders correctly: rapidity up to {:?} (1 - beta down to about 1e-17); accelerate less, or end it sooner",
                        i + 1,
                        super::envelope::MAX_RAPIDITY
                    ),
                ));
            }
        }
    }
    Ok(Some(segments))
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
            turn: None,
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
            let window = Some(Box::new(line.window(k)));
            // The piece's axes, turned by the accelerations across the motion before it.
            let r = line.turns[k];
            let turn = (r != DMat3::IDENTITY).then_some(r);
            match piece {
                Piece::Uniform { velocity, .. } => {
                    // An event of the origin's worldline within the span (the one nearest
                    // world time 0), and where that puts the origin, at rest, in the frame.
                    let when = 0.0f64.clamp(a, b);
                    let on_line = piece.event_at(when);
                    let rest = Boost::to_rest(velocity).turned(r).event(on_line).x;
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
                        turn,
                    })
                }
                Piece::Accelerated(h) => {
                    // The motion in the piece's own axes: those of S' turned by r, in which
                    // the geometry is given.
                    let axis = r * h.axis;
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
                    let start = h.to_start_frame().turned(r).event(h.start);
                    let sweep = (1.0 / h.a + geometry.bounds().support(axis))
                        * crate::spacetime::cosh_m1(h.theta_at(b));
                    let reach = start.x.abs().max_element() + geometry.bounds().max_abs() + sweep;
                    if reach > super::envelope::MAX_MAGNITUDE {
                        return Err(too_far(reach));
                    }
                    // Every point must stay ahead of the horizon, 1/a behind the origin.
                    let behind = geometry.bounds().support(-axis);
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
                            axis,
                            theta_end: h.theta_at(b),
                        }),
                        turn,
                    })
                }
            }
        })
        .collect()
}
