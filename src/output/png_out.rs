use super::file::cause;
use super::srgb8;
use crate::render::Frame;
use crate::Cause;
use rayon::prelude::*;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Strips of rows, top to bottom, handed to a sink that encodes them.
pub type Strips<'a> = dyn FnMut(&Frame) -> Result<(), Cause> + 'a;

/// Write a whole frame: RGB where every pixel is opaque, RGBA (straight alpha) where some are
/// not, so that a transparent render keeps its coverage instead of going black (see
/// [`write_strips`]).
pub fn write(frame: &Frame, path: &Path) -> std::result::Result<(), Cause> {
    let alpha = frame.pixels.iter().any(|p| p.alpha != 1.0);
    write_strips(path, frame.width, frame.height, alpha, None, |put| {
        put(frame)
    })
}

/// Write a `width` × `height` image whose rows `fill` hands to its sink in strips, top to
/// bottom: the rows are encoded as they come, so the image is never held whole.
/// With `alpha`, RGBA: PNG's alpha is straight, so the premultiplied colour is divided by it.
/// sRGB, with gAMA and cHRM for readers that ignore the sRGB chunk, and a Software chunk.
pub(crate) fn write_strips(
    path: &Path,
    width: u32,
    height: u32,
    alpha: bool,
    render_id: Option<&str>,
    fill: impl FnOnce(&mut Strips) -> Result<(), Cause>,
) -> std::result::Result<(), Cause> {
    let file = std::fs::File::create(path).map_err(cause)?;
    let mut enc = png::Encoder::new(BufWriter::new(file), width, height);
    enc.set_color(if alpha {
        png::ColorType::Rgba
    } else {
        png::ColorType::Rgb
    });
    enc.set_depth(png::BitDepth::Eight);
    // The sRGB chunk, and the gAMA and cHRM values the PNG specification gives for it.
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    enc.set_source_gamma(png::ScaledFloat::from_scaled(45455));
    let [r, g, b, w] = crate::spectrum::camera::SRGB_CHROMATICITIES
        .map(|[x, y]| (png::ScaledFloat::new(x), png::ScaledFloat::new(y)));
    enc.set_source_chromaticities(png::SourceChromaticities::new(
        (w.0.into_value(), w.1.into_value()),
        (r.0.into_value(), r.1.into_value()),
        (g.0.into_value(), g.1.into_value()),
        (b.0.into_value(), b.1.into_value()),
    ));
    let software = concat!("rest-embree ", env!("CARGO_PKG_VERSION"));
    enc.add_text_chunk("Software".into(), software.into())
        .map_err(cause)?;
    if let Some(id) = render_id {
        enc.add_text_chunk(super::header::RENDER_ID.into(), id.into())
            .map_err(cause)?;
    }
    let mut w = enc.write_header().map_err(cause)?;
    let mut stream = w.stream_writer().map_err(cause)?;
    let mut rows = 0u64;
    fill(&mut |strip: &Frame| {
        debug_assert_eq!(strip.width, width);
        let data = srgb_bytes(&strip.pixels, alpha);
        rows += u64::from(strip.height);
        stream.write_all(&data).map_err(cause)
    })?;
    if rows != u64::from(height) {
        let e = std::io::Error::other(format!("{rows} rows of {height} were rendered"));
        return Err(cause(e));
    }
    stream.finish().map_err(cause)?;
    w.finish().map_err(cause)
}

/// The 8-bit sRGB bytes of pixels as a PNG holds them: RGB, or RGBA with straight alpha (the
/// premultiplied colour divided by it). Encoded in parallel: the deflate after it is the only
/// serial part.
pub(crate) fn srgb_bytes(pixels: &[crate::render::PixelValue], alpha: bool) -> Vec<u8> {
    let channels = if alpha { 4 } else { 3 };
    let mut data = vec![0u8; pixels.len() * channels];
    data.par_chunks_mut(channels * 1024)
        .zip(pixels.par_chunks(1024))
        .for_each(|(out, pixels)| {
            for (o, p) in out.chunks_exact_mut(channels).zip(pixels) {
                if alpha {
                    let a = p.alpha;
                    let straight = p.color.map(|c| if a > 0.0 { c / a } else { 0.0 });
                    o[..3].copy_from_slice(&straight.map(srgb8));
                    o[3] = (a.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
                } else {
                    o.copy_from_slice(&p.color.map(srgb8));
                }
            }
        });
    data
}

/// An 8-bit RGB image as PNG bytes in memory (fast compression: for a screen, not a file).
pub(crate) fn rgb_png(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>, Cause> {
    png_bytes(width, height, png::ColorType::Rgb, rgb)
}

/// An 8-bit RGBA image (straight alpha) as PNG bytes in memory.
pub(crate) fn rgba_png(width: u32, height: u32, rgba: &[u8]) -> Result<Vec<u8>, Cause> {
    png_bytes(width, height, png::ColorType::Rgba, rgba)
}

fn png_bytes(
    width: u32,
    height: u32,
    colour: png::ColorType,
    data: &[u8],
) -> Result<Vec<u8>, Cause> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width, height);
    enc.set_color(colour);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::Fast);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut w = enc.write_header().map_err(cause)?;
    w.write_image_data(data).map_err(cause)?;
    w.finish().map_err(cause)?;
    Ok(out)
}
