//! The `[camera]` table (its place, view, motion or worldline, shutter and flash) and the
//! `[film]` table read into the scene's camera and film.

use super::lights::flash;
use super::model::*;
use super::reader::{SceneResult, Table};
use super::segments;
use super::speed::velocity;
use super::worldline::Worldline;
use crate::spacetime::{Boost, Event, Velocity};
use glam::DVec3;

/// The camera, and the light riding with it where it has a `flash`.
pub(super) fn camera(
    t: &Table,
    from_file: Option<&super::gltf_file::CameraView>,
) -> SceneResult<(Camera, Option<Light>)> {
    // A table without a position takes the glTF file's camera: its place, view, up and field
    // of view, each unless the table gives it.
    let from_file = from_file.filter(|_| !t.has("position"));
    let position = match from_file {
        Some(c) => c.position,
        None => t.req_vec3("position")?,
    };
    let forward = match (t.vec3("look_at")?, t.vec3("direction")?) {
        (Some(_), Some(_)) => {
            return Err(t.error("direction", "give either look_at or direction, not both"))
        }
        (Some(p), None) => p - position,
        (None, Some(d)) => d,
        (None, None) if from_file.is_some() => from_file.expect("matched").forward,
        (None, None) => {
            return Err(t.error(
                "look_at",
                "missing: give look_at = [x, y, z] or direction = [x, y, z]",
            ))
        }
    };
    if forward.length() == 0.0 {
        let k = if t.has("look_at") {
            "look_at"
        } else {
            "direction"
        };
        return Err(t.error(
            k,
            "the view direction has zero length (look_at equals position?)",
        ));
    }
    let forward = forward.normalize();
    let up_in = t
        .vec3("up")?
        .or(from_file.map(|c| c.up))
        .unwrap_or(DVec3::Z);
    let right = forward.cross(up_in);
    if right.length() < 1e-9 * up_in.length().max(1e-300) || up_in.length() == 0.0 {
        return Err(t.error(
            "up",
            "`up` must not be zero or parallel to the view direction",
        ));
    }
    let right = right.normalize();
    let up = right.cross(forward);
    // Both projections' keys are read whichever is chosen, so a scene can switch projection
    // with --set and keep its file valid.
    let fov_y = t.f64_where(
        "fov_y",
        Some(from_file.map_or(40.0, |c| c.fov_y.to_degrees())),
        |v| (super::envelope::MIN_FOV_DEG..180.0).contains(&v),
        "at least 1e-6 and below 180 degrees",
    )?;
    let view_height = t.f64("view_height")?;
    if let Some(h) = view_height.filter(|&h| h <= 0.0) {
        return Err(t.error("view_height", format!("must be greater than 0 (got {h:?})")));
    }
    let projection = match t.string("projection")?.unwrap_or("pinhole") {
        "pinhole" | "perspective" => Projection::Pinhole {
            fov_y: fov_y.to_radians(),
        },
        "orthographic" => Projection::Orthographic {
            view_height: view_height.ok_or_else(|| {
                t.error(
                    "view_height",
                    "missing: an orthographic camera needs view_height (world units)",
                )
            })?,
        },
        "equirectangular" => Projection::Equirectangular,
        other => {
            let n = t.get("projection").expect("read above");
            return Err(t.error_at(
                n,
                "projection",
                format!("unknown projection `{other}` (pinhole, orthographic, equirectangular)"),
            ));
        }
    };
    let time = t.f64_or("time", 0.0)?;
    let worldline = segments::read(t, "velocity_direction", segments::Whose::Camera)?
        .map(|s| Worldline::new(Event::new(time, position), &s));
    let velocity = match &worldline {
        Some(w) => w.velocity(time),
        None => velocity(t, "velocity_direction")?.unwrap_or(Velocity::ZERO),
    };
    let shutter = t.f64_where(
        "shutter",
        Some(0.0),
        |s| s >= 0.0,
        "0 (an instant) or more: the exposure in the camera's proper time",
    )?;
    let flash = t.table("flash")?.map(|f| flash(&f)).transpose()?;
    t.finish(&[
        "position",
        "shutter",
        "flash",
        "worldline",
        "look_at",
        "direction",
        "up",
        "fov_y",
        "time",
        "velocity",
        "velocity_direction",
        "beta",
        "rapidity",
        "one_minus_beta",
        "projection",
        "view_height",
    ])?;
    let camera = Camera {
        position,
        time,
        forward,
        right,
        up,
        projection,
        velocity,
        shutter,
        worldline,
    };
    let flash = flash.map(|(radiance, inverse_square, timing)| {
        // At rest in the camera's frame, where the camera's worldline is. Its times are on the
        // camera's clock, which reads `time` at the imaging event; a light's are its frame's.
        let at_camera = Boost::to_rest(&velocity).event(camera.imaging_event());
        // On a worldline that changes velocity the flash rides along it, on its clock.
        let line = camera.worldline.clone().filter(|w| !w.is_uniform());
        Light {
            position: at_camera.x,
            radiance,
            velocity,
            inverse_square,
            timing: match line {
                Some(_) => timing,
                None => timing.delayed(at_camera.t - time),
            },
            worldline: line,
        }
    });
    Ok((camera, flash))
}

/// `[film]`: its view times, on world time or the camera's clock.
pub(super) fn film(t: &Table, camera: &Camera) -> SceneResult<Film> {
    let start = t.f64_or("start", camera.time)?;
    let end = t.f64_where("end", None, |_| true, "the last frame's view time")?;
    if end < start {
        return Err(t.error(
            "end",
            format!("must not be before start ({start:?}); got {end:?}"),
        ));
    }
    let positive = |v: f64| v > 0.0;
    let spacing = match (t.has("fps"), t.has("step")) {
        (true, true) => return Err(t.error("step", "give fps or step, not both")),
        (true, false) => FrameSpacing::Fps(t.f64_where("fps", None, positive, "more than 0")?),
        (false, true) => FrameSpacing::Step(t.f64_where("step", None, positive, "more than 0")?),
        (false, false) => return Err(t.error(
            "fps",
            "missing: give fps (frames per unit of world time) or step (world time between frames)",
        )),
    };
    let clock = match t.string("clock")?.unwrap_or("world") {
        "world" => Clock::World,
        "proper" => Clock::Proper,
        other => {
            let n = t.get("clock").expect("read above");
            return Err(t.error_at(
                n,
                "clock",
                format!("unknown clock `{other}` (world, proper)"),
            ));
        }
    };
    let f = Film {
        start,
        end,
        spacing,
        clock,
    };
    let n = ((end - start)
        * match spacing {
            FrameSpacing::Fps(x) => x,
            FrameSpacing::Step(x) => 1.0 / x,
        })
    .floor();
    if n >= MAX_FRAMES as f64 {
        let key = if t.has("fps") { "fps" } else { "step" };
        return Err(t.error(
            key,
            // Frames 0 ..= n: n + 1 of them.
            format!(
                "the film would have {:.0} frames; at most {MAX_FRAMES} are allowed",
                n + 1.0
            ),
        ));
    }
    t.finish(&["start", "end", "fps", "step", "clock"])?;
    Ok(f)
}
