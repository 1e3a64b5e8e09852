//! Tiles (EXRs that are crops of one image, each with its data window inside the same display
//! window) joined into the one EXR of the whole image: every channel, sample type, attribute
//! and the compression of the tiles, the pixels copied bit for bit.

use exr::prelude::*;
use std::path::{Path, PathBuf};

type Tile = Image<Layer<AnyChannels<FlatSamples>>>;

fn read_tile(path: &Path) -> crate::Result<Tile> {
    super::exr_out::read_layer(path).map_err(|e| bad(path, format!("cannot read the tile: {e}")))
}

fn bad(path: &Path, why: impl Into<String>) -> crate::Error {
    let why = why.into();
    crate::Error::image(path, format!("tile {}: {why}", path.display()), None)
}

/// The render a tile says it is of (`header::render_id`), if it says.
fn render_id(tile: &Tile) -> Option<String> {
    tile.layer_data
        .attributes
        .other
        .iter()
        .chain(tile.attributes.other.iter())
        .find(|(name, _)| **name == *super::header::RENDER_ID)
        .and_then(|(_, v)| match v {
            AttributeValue::Text(t) => Some(t.to_string()),
            _ => None,
        })
}

/// Join `tiles` into `output`.
pub fn assemble(tiles: &[PathBuf], output: &Path) -> crate::Result<()> {
    let Some(first_path) = tiles.first() else {
        return Err(crate::Error::flag("assemble", "no tiles given"));
    };
    let first = read_tile(first_path)?;
    let display = first.attributes.display_window;
    let (w, h) = (display.size.0, display.size.1);
    let names: Vec<Text> = first
        .layer_data
        .channel_data
        .list
        .iter()
        .map(|c| c.name.clone())
        .collect();
    let mut covered = vec![false; w * h];
    let mut channels: Vec<AnyChannel<FlatSamples>> = first
        .layer_data
        .channel_data
        .list
        .iter()
        .map(|c| {
            let samples = match &c.sample_data {
                FlatSamples::F16(_) => FlatSamples::F16(vec![f16::ZERO; w * h]),
                FlatSamples::F32(_) => FlatSamples::F32(vec![0.0; w * h]),
                FlatSamples::U32(_) => FlatSamples::U32(vec![0; w * h]),
            };
            AnyChannel {
                sample_data: samples,
                ..c.clone()
            }
        })
        .collect();
    for path in tiles {
        let tile = if path == first_path {
            first.clone()
        } else {
            read_tile(path)?
        };
        if tile.attributes.display_window != display {
            return Err(bad(
                path,
                "its full image (display window) differs from the first tile's",
            ));
        }
        // Tiles of one render share its id (another view time, β or backend has another).
        if render_id(&tile) != render_id(&first) {
            return Err(bad(
                path,
                format!(
                    "it is of another render than {} (renderId {} against {})",
                    first_path.display(),
                    render_id(&tile).unwrap_or_else(|| "none".into()),
                    render_id(&first).unwrap_or_else(|| "none".into())
                ),
            ));
        }
        let layer = &tile.layer_data;
        let list = &layer.channel_data.list;
        if list.len() != names.len() || list.iter().zip(&names).any(|(c, n)| c.name != *n) {
            return Err(bad(path, "its channels differ from the first tile's"));
        }
        let (tw, th) = (layer.size.0, layer.size.1);
        let origin = layer.attributes.layer_position;
        let (ox, oy) = (origin.0 - display.position.0, origin.1 - display.position.1);
        if ox < 0 || oy < 0 || ox as usize + tw > w || oy as usize + th > h {
            return Err(bad(path, "it lies outside the full image"));
        }
        let (ox, oy) = (ox as usize, oy as usize);
        for y in 0..th {
            for x in 0..tw {
                let seen = &mut covered[(oy + y) * w + ox + x];
                if *seen {
                    return Err(bad(
                        path,
                        format!("it overlaps another tile at pixel ({}, {})", ox + x, oy + y),
                    ));
                }
                *seen = true;
            }
        }
        for (dst, src) in channels.iter_mut().zip(list) {
            let rows = (0..th).map(|y| ((oy + y) * w + ox, y * tw));
            match (&mut dst.sample_data, &src.sample_data) {
                (FlatSamples::F16(d), FlatSamples::F16(s)) => {
                    rows.for_each(|(a, b)| d[a..a + tw].copy_from_slice(&s[b..b + tw]))
                }
                (FlatSamples::F32(d), FlatSamples::F32(s)) => {
                    rows.for_each(|(a, b)| d[a..a + tw].copy_from_slice(&s[b..b + tw]))
                }
                (FlatSamples::U32(d), FlatSamples::U32(s)) => {
                    rows.for_each(|(a, b)| d[a..a + tw].copy_from_slice(&s[b..b + tw]))
                }
                _ => {
                    return Err(bad(
                        path,
                        format!(
                            "channel {} has another sample type than in the first tile",
                            src.name
                        ),
                    ))
                }
            }
        }
    }
    if let Some(gap) = covered.iter().position(|&c| !c) {
        return Err(crate::Error::flag(
            "assemble",
            format!(
                "the tiles leave pixel ({}, {}) of the {w}x{h} image uncovered: is a tile missing?",
                gap % w,
                gap / w
            ),
        ));
    }
    let mut attributes = first.layer_data.attributes.clone();
    attributes.layer_position = Vec2(display.position.0, display.position.1);
    // The header from the channels' names and types alone; the samples go through the same
    // block writer as a render's, so the file is the whole render's.
    let channels = AnyChannels::sort(channels.into_iter().collect());
    let template = AnyChannels {
        list: channels
            .list
            .iter()
            .map(|c| AnyChannel {
                name: c.name.clone(),
                sample_data: match &c.sample_data {
                    FlatSamples::F16(_) => FlatSamples::F16(Vec::new()),
                    FlatSamples::F32(_) => FlatSamples::F32(Vec::new()),
                    FlatSamples::U32(_) => FlatSamples::U32(Vec::new()),
                },
                quantize_linearly: c.quantize_linearly,
                sampling: c.sampling,
            })
            .collect(),
    };
    let layer = Layer::new((w, h), attributes, first.layer_data.encoding, template);
    let mut image = Image::from_layer(layer);
    image.attributes = first.attributes.clone();
    let headers = image.write().infer_meta_data();
    super::file::write_whole(output, |tmp| {
        super::exr_out::write_blocks(tmp, headers, |put| put(&channels, h))
    })
}
