//! The scene's `[image]` and `[render]` tables: the picture's size, samples, background, crop,
//! transparency and passes; the effects and the integrator.

use super::load::FrameSize;
use super::model::*;
use super::reader::{SceneResult, Table};
use super::PassSet;
use crate::spectrum::{Colour, Role};

/// The scene's `[image]` table (`frame`: the size a film's frame or a command line gave).
pub(super) fn image(t: &Table, frame: FrameSize) -> SceneResult<ImageSettings> {
    let width = t.uint("width", Some(512), 1, 1 << 20)? as u32;
    let height = t.uint("height", Some(512), 1, 1 << 20)? as u32;
    let crop = t
        .uints("crop", 4, 0, 1 << 20)?
        .map(|c| [c[0] as u32, c[1] as u32, c[2] as u32, c[3] as u32]);
    if let Some([x, y, w, h]) = crop {
        if w == 0 || h == 0 || x + w > width || y + h > height {
            let n = t.get("crop").expect("read above");
            return Err(t.error_at(
                n,
                "crop",
                format!("the window [{x}, {y}, {w}, {h}] must be non-empty and inside the {width}x{height} image"),
            ));
        }
    }
    let s = ImageSettings {
        width,
        height,
        samples: t.uint("samples", Some(1), 1, 4096)? as u32,
        background: t
            .colour("background", Role::Emitter)?
            .unwrap_or_else(|| Colour::grey(0.0, Role::Emitter)),
        crop,
        transparent: match t.get("transparent") {
            Some(_) => Some(t.bool_or("transparent", true)?),
            None => None,
        },
        passes: match t.strings("passes")? {
            Some((n, names)) if names.len() > 1 && names.contains(&"none") => {
                return Err(t.error_at(
                    n,
                    "passes",
                    "`none` (colour and alpha alone) cannot stand with other passes",
                ))
            }
            Some((n, names)) => PassSet::from_names(names).map_err(|bad| {
                t.error_at(
                    n,
                    "passes",
                    format!(
                        "`{bad}` is not a pass; the passes are {} (colour and alpha are always written)",
                        PassSet::accepted()
                    ),
                )
            })?,
            None => PassSet::ALL,
        },
    };
    let (fw, fh) = s.frame_size();
    let whole = s.crop.is_none() && frame == FrameSize::InTiles;
    if fw as u64 * fh as u64 > MAX_FRAME_PIXELS && !whole {
        let (key, n) = ["width", "height", "crop"]
            .into_iter()
            .find_map(|k| t.get(k).map(|n| (k, n)))
            .expect("a frame this large was set by one of these");
        return Err(t.error_at(
            n,
            key,
            format!(
                "a {fw}x{fh} frame is too large (at most 2^28 pixels; render it in tiles, \
                 `--tiles NxM`, or crops)"
            ),
        ));
    }
    t.finish(&[
        "width",
        "height",
        "samples",
        "background",
        "crop",
        "transparent",
        "passes",
    ])?;
    Ok(s)
}

/// The scene's `[render]` table.
pub(super) fn render_settings(t: &Table) -> SceneResult<RenderSettings> {
    let d = RenderSettings::default();
    let s = RenderSettings {
        max_depth: t.uint("max_depth", Some(d.max_depth.into()), 0, 64)? as u32,
        max_rays: t.uint("max_rays", Some(d.max_rays.into()), 0, MAX_RAYS.into())? as u32,
        ambient: t.colour("ambient", Role::Emitter)?.unwrap_or(d.ambient),
        doppler: t.bool_or("doppler", d.doppler)?,
        searchlight: t.bool_or("searchlight", d.searchlight)?,
        integrator: match t.string("integrator")?.unwrap_or("whitted") {
            "whitted" => Integrator::Whitted,
            "path" => Integrator::Path,
            other => {
                return Err(t.error(
                    "integrator",
                    format!("unknown integrator `{other}` (whitted, path)"),
                ))
            }
        },
        seed: t.uint("seed", Some(0), 0, i64::MAX as u64)?,
        rgb_shift_warning: t.bool_or("rgb_shift_warning", d.rgb_shift_warning)?,
    };
    t.finish(&[
        "max_depth",
        "max_rays",
        "ambient",
        "doppler",
        "searchlight",
        "integrator",
        "seed",
        "rgb_shift_warning",
    ])?;
    Ok(s)
}
