use crate::render::{Frame, CHANNELS};
use exr::prelude::*;
use smallvec::SmallVec;
use std::collections::HashMap;
use std::path::Path;

pub fn write(frame: &Frame, path: &Path) -> std::result::Result<(), String> {
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
    let mut attrs = LayerAttributes::default();
    attrs.software_name = Some(Text::from("rest-embree"));
    let layer = Layer::new(
        size,
        attrs,
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(list),
    );
    Image::from_layer(layer)
        .write()
        .to_file(path)
        .map_err(|e| e.to_string())
}

/// Every channel of the first layer of an EXR file, by name, as f32 in row-major order.
pub fn read_channels(
    path: &Path,
) -> std::result::Result<(usize, usize, HashMap<String, Vec<f32>>), String> {
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| e.to_string())?;
    let layer = &image.layer_data;
    let map = layer
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
        .collect();
    Ok((layer.size.width(), layer.size.height(), map))
}
