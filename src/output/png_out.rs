use super::file::cause;
use super::srgb_encode;
use crate::render::Frame;
use crate::Cause;
use std::io::BufWriter;
use std::path::Path;

pub fn write(frame: &Frame, path: &Path) -> std::result::Result<(), Cause> {
    let file = std::fs::File::create(path).map_err(cause)?;
    let mut enc = png::Encoder::new(BufWriter::new(file), frame.width, frame.height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let data: Vec<u8> = frame
        .pixels
        .iter()
        .flat_map(|p| p.color.map(|c| (srgb_encode(c) * 255.0 + 0.5) as u8))
        .collect();
    let mut w = enc.write_header().map_err(cause)?;
    w.write_image_data(&data).map_err(cause)?;
    w.finish().map_err(cause)
}
