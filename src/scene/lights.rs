//! Point lights as the scene file gives them: `[[light]]` tables and the camera's `flash`,
//! with what they emit and how it varies in time.

use super::model::*;
use super::reader::{SceneResult, Table};
use super::speed::velocity;
use super::timing::{self, Timing, TIMING_KEYS};
use crate::spacetime::Velocity;
use crate::spectrum::{Colour, Role};

/// What a light emits: its colour times its intensity, whether it falls off as 1/r², and how
/// it varies in its proper time.
pub(super) type Emitting = (Colour, bool, Timing);

/// A light's `intensity`, `color`, `falloff` and timing (`pulse`, `on` or `table`).
fn emitting(t: &Table) -> SceneResult<Emitting> {
    let intensity = t.f64_where("intensity", Some(1.0), |v| v >= 0.0, "0 or more")?;
    let color = t
        .colour("color", Role::Emitter)?
        .unwrap_or_else(|| Colour::grey(1.0, Role::Emitter));
    let inverse_square = match t.string("falloff")?.unwrap_or("none") {
        "none" => false,
        "inverse_square" => true,
        other => {
            let n = t.get("falloff").expect("read above");
            return Err(t.error_at(
                n,
                "falloff",
                format!("unknown falloff `{other}` (none, inverse_square)"),
            ));
        }
    };
    Ok((color.scaled(intensity), inverse_square, timing::read(t)?))
}

/// `[camera] flash`: a point light riding with the camera (the radar world).
pub(super) fn flash(t: &Table) -> SceneResult<Emitting> {
    let e = emitting(t)?;
    let keys = ["intensity", "color", "falloff"];
    t.finish(&[&keys[..], &TIMING_KEYS[..]].concat())?;
    Ok(e)
}

/// A `[[light]]`: a point light at rest in the world's frame, a group's, or its own.
pub(super) fn light(t: &Table, groups: &[Group]) -> SceneResult<Light> {
    let position = t.req_vec3("position")?;
    let (radiance, inverse_square, timing) = emitting(t)?;
    let own = velocity(t, "velocity_direction")?;
    let velocity = match (t.string("group")?, own) {
        (Some(_), Some(_)) => {
            return Err(t.error("group", "give either `group` or a velocity, not both"))
        }
        (Some(g), None) => match groups.iter().find(|x| x.name == g) {
            Some(x) if x.window.is_some() => {
                return Err(t.error(
                    "group",
                    format!("group `{g}` has a worldline of several segments: a light resting in it is not built yet (give the light its own velocity)"),
                ))
            }
            Some(x) => x.velocity,
            None => {
                let names: Vec<&str> = groups.iter().map(|x| x.name.as_str()).collect();
                let n = t.get("group").expect("read above");
                return Err(t.error_at(
                    n,
                    "group",
                    format!("no group named `{g}` (groups: {})", names.join(", ")),
                ));
            }
        },
        (None, v) => v.unwrap_or(Velocity::ZERO),
    };
    // A worldline through `position` at world time 0, whose clock reads 0 there.
    let segments = super::segments::read(t, "velocity_direction", super::segments::Whose::Light)?;
    if segments.is_some() && t.has("group") {
        return Err(t.error("group", "give either `group` or a worldline, not both"));
    }
    // Kept even when it is one uniform motion: `position` is then still where the light is
    // at world time 0, not in its rest frame.
    let worldline =
        segments.map(|s| super::Worldline::new(crate::spacetime::Event::new(0.0, position), &s));
    let velocity = match &worldline {
        Some(w) => w.velocity(0.0),
        None => velocity,
    };
    t.string("name")?;
    let keys = [
        "position",
        "intensity",
        "color",
        "group",
        "falloff",
        "velocity",
        "velocity_direction",
        "beta",
        "rapidity",
        "one_minus_beta",
        "name",
        "worldline",
    ];
    t.finish(&[&keys[..], &TIMING_KEYS[..]].concat())?;
    Ok(Light {
        position,
        radiance,
        velocity,
        inverse_square,
        timing,
        worldline,
    })
}
