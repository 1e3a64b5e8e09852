//! Writing a rendered frame: EXR (linear float, with the extra passes) or PNG (tone-mapped
//! sRGB), chosen by the file extension. Files are written whole or not at all.

mod exr_out;
pub mod file;
mod png_out;

use crate::render::Frame;
use crate::{Cause, Error};
use std::path::Path;

/// An image format, chosen by the output file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// OpenEXR: every pass, linear, 32-bit float.
    Exr,
    /// PNG: colour and alpha, sRGB-encoded, 8 bits.
    Png,
}

impl Format {
    /// The format for an output path, from its extension.
    pub fn for_path(path: &Path) -> crate::Result<Format> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("exr") => Ok(Format::Exr),
            Some("png") => Ok(Format::Png),
            _ => Err(Error::image(
                path,
                format!(
                    "cannot tell the image format of `{}`: the name must end in .exr or .png",
                    path.display()
                ),
                None,
            )),
        }
    }
}

/// Write the frame; the file appears only when it is complete (see [`file`]).
pub fn write(frame: &Frame, path: &Path) -> crate::Result<()> {
    let format = Format::for_path(path)?;
    file::write_whole(path, |tmp| match format {
        Format::Exr => exr_out::write(frame, tmp),
        Format::Png => png_out::write(frame, tmp),
    })
}

/// Write a PNG of `width` × `height` whose rows `fill` hands on in bands, top to bottom, as it
/// renders them (see [`crate::render`]'s banded rendering): the image is never held whole.
pub(crate) fn write_png_in_bands(
    path: &Path,
    width: u32,
    height: u32,
    fill: impl FnOnce(&mut png_out::Bands) -> Result<(), Cause>,
) -> crate::Result<()> {
    file::write_whole(path, |tmp| png_out::write_bands(tmp, width, height, fill))
}

/// Linear to sRGB-encoded, after clamping to [0, 1].
pub fn srgb_encode(linear: f32) -> f32 {
    let c = if linear.is_finite() {
        linear.clamp(0.0, 1.0)
    } else {
        0.0
    };
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

pub use exr_out::read_channels as read_exr_channels;
