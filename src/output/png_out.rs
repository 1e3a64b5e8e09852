use super::file::cause;
use super::srgb_encode;
use crate::render::Frame;
use crate::Cause;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Bands of rows, top to bottom, handed to a sink that encodes them.
pub type Bands<'a> = dyn FnMut(&Frame) -> Result<(), Cause> + 'a;

/// Write a whole frame.
pub fn write(frame: &Frame, path: &Path) -> std::result::Result<(), Cause> {
    write_bands(path, frame.width, frame.height, |put| put(frame))
}

/// Write a `width` × `height` image whose rows `fill` hands to its sink in bands, top to
/// bottom: the rows are encoded as they come, so the image is never held whole.
pub fn write_bands(
    path: &Path,
    width: u32,
    height: u32,
    fill: impl FnOnce(&mut Bands) -> Result<(), Cause>,
) -> std::result::Result<(), Cause> {
    let file = std::fs::File::create(path).map_err(cause)?;
    let mut enc = png::Encoder::new(BufWriter::new(file), width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut w = enc.write_header().map_err(cause)?;
    let mut stream = w.stream_writer().map_err(cause)?;
    let mut rows = 0u64;
    fill(&mut |band: &Frame| {
        debug_assert_eq!(band.width, width);
        let data: Vec<u8> = band
            .pixels
            .iter()
            .flat_map(|p| p.color.map(|c| (srgb_encode(c) * 255.0 + 0.5) as u8))
            .collect();
        rows += u64::from(band.height);
        stream.write_all(&data).map_err(cause)
    })?;
    if rows != u64::from(height) {
        let e = std::io::Error::other(format!("{rows} rows of {height} were rendered"));
        return Err(cause(e));
    }
    stream.finish().map_err(cause)?;
    w.finish().map_err(cause)
}
