use super::file::cause;
use crate::render::{Frame, CHANNELS};
use crate::{Cause, Error};
use exr::prelude::*;
use smallvec::SmallVec;
use std::collections::HashMap;
use std::path::Path;

pub fn write(frame: &Frame, path: &Path) -> std::result::Result<(), Cause> {
    let size = (frame.width as usize, frame.height as usize);
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = CHANNELS
        .iter()
        .map(|&name| {
            AnyChannel::new(
                name,
                FlatSamples::F32(frame.channel(name).expect("known channel")),
            )
        })
        .collect();
    let attrs = LayerAttributes {
        software_name: Some(Text::from("rest-embree")),
        ..Default::default()
    };
    // Blocks in increasing order: compressed in parallel, they are otherwise written as they
    // finish, and the same image would make a different file from run to run.
    let encoding = Encoding {
        line_order: LineOrder::Increasing,
        ..Encoding::FAST_LOSSLESS
    };
    let layer = Layer::new(size, attrs, encoding, AnyChannels::sort(list));
    let mut image = Image::from_layer(layer);
    // R, G, B are linear sRGB / Rec. 709 (the camera's CIE XYZ through IEC 61966-2-1's matrix).
    let [r, g, b, w] = crate::spectrum::camera::SRGB_CHROMATICITIES.map(|[x, y]| Vec2(x, y));
    image.attributes.chromaticities = Some(attribute::Chromaticities {
        red: r,
        green: g,
        blue: b,
        white: w,
    });
    image.write().to_file(path).map_err(cause)
}

/// Width, height and every channel by name (f32, row-major) of an EXR file's first layer.
pub type Channels = (usize, usize, HashMap<String, Vec<f32>>);

/// Every channel of the first layer of an EXR file.
pub fn read_channels(path: &Path) -> crate::Result<Channels> {
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| {
            let message = format!("cannot read `{}`: {e}", path.display());
            Error::image(path, message, Some(cause(e)))
        })?;
    let layer = &image.layer_data;
    let map = layer
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
        .collect();
    Ok((layer.size.width(), layer.size.height(), map))
}
