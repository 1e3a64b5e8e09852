//! The viewer's frames: a view rendered at a ladder of levels (a small frame of one sample a
//! pixel first, then the full size, then the scene's own samples: that last is the render of
//! the saved view), stopped between strips when a newer view supersedes it, and shown as one
//! pass in 8-bit colour.

use crate::accel::Backend;
use crate::render::{Frame, Passes, RestGroups, World, DEPTH_FAR};
use crate::scene::{ImageSettings, Scene};
use std::sync::atomic::{AtomicBool, Ordering};

/// The longest side of the first, coarse frame after a change.
pub(crate) const COARSE_SIDE: u32 = 256;

/// One rung of the ladder: the image size and samples a pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Level {
    pub width: u32,
    pub height: u32,
    pub samples: u32,
}

/// The levels a view is refined through, the last the scene's own image (the final frame).
/// The coarse one keeps the aspect ratio; a cropped image is refined at its own size only.
pub(crate) fn levels(image: &ImageSettings) -> Vec<Level> {
    let (w, h, s) = (image.width, image.height, image.samples);
    let full = Level {
        width: w,
        height: h,
        samples: s,
    };
    let mut out = Vec::new();
    if image.crop.is_none() {
        let side = w.max(h);
        if side > COARSE_SIDE {
            let scale =
                |x: u32| ((u64::from(x) * u64::from(COARSE_SIDE)) / u64::from(side)).max(1) as u32;
            out.push(Level {
                width: scale(w),
                height: scale(h),
                samples: 1,
            });
        }
        if s > 1 {
            out.push(Level { samples: 1, ..full });
        }
    }
    out.push(full);
    out
}

/// How a render ended early.
#[derive(Debug)]
pub(crate) enum Stopped {
    /// A newer view came.
    Superseded,
    /// The render failed.
    Failed(crate::Error),
}

impl From<crate::Error> for Stopped {
    fn from(e: crate::Error) -> Self {
        Stopped::Failed(e)
    }
}

/// Render `scene` (already at the level's size; `rest`: its world's groups) with every pass, strip by strip, stopping
/// between strips once `cancel` is set. The colour is what `rest-embree render` writes to a
/// PNG: the background composited where nothing is hit.
pub(crate) fn render(
    scene: &mut Scene,
    rest: &RestGroups,
    backend: &dyn Backend,
    cancel: &AtomicBool,
) -> Result<Frame, Stopped> {
    scene.image.transparent.get_or_insert(false);
    scene.film = None;
    let world = World::aim(scene, rest, backend)?;
    let (w, h) = scene.image.frame_size();
    let mut frame = Frame::new(w, h);
    frame.pixels.clear();
    frame.mattes.clear();
    // Small strips: a superseded render stops within one.
    let strip = u64::from(w) * u64::from(crate::render::TILE);
    crate::render::render_world_in_strips(scene, &world, Passes::All, strip, None, |s| {
        if cancel.load(Ordering::Relaxed) {
            return Err(Stopped::Superseded);
        }
        frame.pixels.extend_from_slice(&s.pixels);
        frame.mattes.extend_from_slice(&s.mattes);
        Ok(())
    })?;
    // A fault the backend recorded fails the frame, as it fails `rest-embree render`.
    world.check()?;
    Ok(frame)
}

/// The passes the page can show.
pub(crate) const PASSES: [&str; 5] = ["colour", "lookback", "doppler", "depth", "object_id"];

/// One pass of a frame as 8-bit RGB: colour as the PNG writer writes it; lookback and depth
/// in grey, near bright (scaled to the frame's range); the Doppler factor from red (D = 1/4 or
/// less, redshift) through white (1) to blue (4 or more); object ids in colours of their own.
/// Background black but in colour.
pub(crate) fn pass_rgb(frame: &Frame, pass: &str) -> Option<Vec<u8>> {
    let px = &frame.pixels;
    let hit = |p: &crate::render::PixelValue| p.object_id != 0;
    let grey = |v: f32| {
        let c = crate::output::srgb8(v.clamp(0.0, 1.0));
        [c, c, c]
    };
    let rgb: Vec<[u8; 3]> = match pass {
        "colour" => return Some(crate::output::png_out::srgb_bytes(px, false)),
        "lookback" | "depth" => {
            let value = |p: &crate::render::PixelValue| {
                if pass == "lookback" {
                    p.lookback
                } else {
                    p.depth
                }
            };
            let (lo, hi) = px
                .iter()
                .filter(|p| hit(p) && value(p) < DEPTH_FAR && value(p).is_finite())
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
                    (lo.min(value(p)), hi.max(value(p)))
                });
            let span = (hi - lo).max(f32::MIN_POSITIVE);
            px.iter()
                .map(|p| match hit(p) {
                    true => grey(0.15 + 0.85 * (1.0 - (value(p) - lo) / span)),
                    false => [0, 0, 0],
                })
                .collect()
        }
        "doppler" => px
            .iter()
            .map(|p| match hit(p) && p.doppler > 0.0 {
                true => {
                    let l = (p.doppler.log2() / 2.0).clamp(-1.0, 1.0);
                    let (r, g, b) = if l < 0.0 {
                        (1.0, 1.0 + l, 1.0 + l)
                    } else {
                        (1.0 - l, 1.0 - l, 1.0)
                    };
                    [r, g, b].map(|c: f32| crate::output::srgb8(c))
                }
                false => [0, 0, 0],
            })
            .collect(),
        "object_id" => px
            .iter()
            .map(|p| match p.object_id {
                0 => [0, 0, 0],
                id => {
                    // A colour per id, bright enough to see: the bytes of a multiplicative hash.
                    let h = id.wrapping_mul(0x9E37_79B1).rotate_left(7);
                    [
                        h as u8 | 0x40,
                        (h >> 8) as u8 | 0x40,
                        (h >> 16) as u8 | 0x40,
                    ]
                }
            })
            .collect(),
        _ => return None,
    };
    Some(rgb.into_iter().flatten().collect())
}

/// One pass of a frame as PNG bytes; an error names an unknown pass. The colour of a
/// transparent scene is RGBA with straight alpha, as `rest-embree render` writes it.
pub(crate) fn png(frame: &Frame, pass: &str, transparent: bool) -> crate::Result<Vec<u8>> {
    let encoded = if pass == "colour" && transparent {
        let rgba = crate::output::png_out::srgb_bytes(&frame.pixels, true);
        crate::output::png_out::rgba_png(frame.width, frame.height, &rgba)
    } else {
        let rgb = pass_rgb(frame, pass)
            .ok_or_else(|| crate::Error::invalid(format!("no pass `{pass}`")))?;
        crate::output::png_out::rgb_png(frame.width, frame.height, &rgb)
    };
    encoded.map_err(|e| crate::Error::invalid(format!("encoding the frame: {e}")))
}

/// What a pixel shows, for the page's click: the object, its emission event, lookback,
/// Doppler factor and the point on the object in its rest frame.
pub(crate) fn probe(shown: &super::Shown, x: u32, y: u32) -> serde_json::Value {
    use serde_json::json;
    let frame = &shown.frame;
    let i = y as usize * frame.width as usize + x as usize;
    let Some(p) = frame.pixels.get(i) else {
        return json!({ "hit": false });
    };
    if p.object_id == 0 {
        return json!({ "hit": false, "pixel": [x, y] });
    }
    let object = shown.objects.get(p.object_id as usize - 1);
    let group = object.and_then(|o| shown.groups.get(o.group));
    json!({
        "hit": true,
        "pixel": [x, y],
        "object": object.and_then(|o| o.name.clone()),
        "kind": object.map(|o| o.kind.clone()),
        "group": group,
        "object_id": p.object_id,
        "emission": {
            "t": shown.time - f64::from(p.lookback),
            "x": p.position,
        },
        "lookback": p.lookback,
        "doppler": p.doppler,
        "depth": p.depth,
        "rest_position": p.rest_position,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = "[camera]\nposition = [0, 0, 0]\ndirection = [1, 0, 0]\n[[group]]\nname = \"a\"\nvelocity = [0, 0, 0]\n[[group.object]]\ntype = \"sphere\"\ncenter = [3, 0, 0]\nradius = 1\n";

    #[test]
    fn the_ladder_ends_at_the_scenes_own_image() {
        let image = |width, height, samples| ImageSettings {
            width,
            height,
            samples,
            ..crate::scene::load_str("t.toml", SCENE, &[]).unwrap().image
        };
        let l = levels(&image(512, 384, 4));
        assert_eq!(
            l,
            vec![
                Level {
                    width: 256,
                    height: 192,
                    samples: 1
                },
                Level {
                    width: 512,
                    height: 384,
                    samples: 1
                },
                Level {
                    width: 512,
                    height: 384,
                    samples: 4
                },
            ]
        );
        assert_eq!(
            levels(&image(200, 100, 1)),
            vec![Level {
                width: 200,
                height: 100,
                samples: 1
            }]
        );
        assert_eq!(
            levels(&image(4000, 10, 1))[0],
            Level {
                width: 256,
                height: 1,
                samples: 1
            }
        );
    }
}
