//! Reading an EXR file's channels: for image textures and skies (`scene`), and to check and
//! join tiles (`output`). Below both, so neither reaches up into the other.

use crate::Error;
use exr::prelude::*;
use std::collections::HashMap;
use std::path::Path;

/// Width, height and every channel by name (f32, row-major) of an EXR file's first layer.
pub type Channels = (usize, usize, HashMap<String, Vec<f32>>);

/// The first layer of an EXR file with every channel and attribute, as stored.
pub(crate) fn read_layer(
    path: &Path,
) -> exr::error::Result<Image<Layer<AnyChannels<FlatSamples>>>> {
    read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
}

/// Every channel of the first layer of an EXR file.
pub fn read_channels(path: &Path) -> crate::Result<Channels> {
    let image = read_layer(path).map_err(|e| {
        let message = format!("cannot read `{}`: {e}", path.display());
        Error::image(path, message, Some(std::sync::Arc::new(e)))
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
