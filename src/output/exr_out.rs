use super::exr_block::{BlockSource, Layout};
use super::exr_zip::zip_lines;
use super::file::cause;
use super::{cryptomatte, Attribute, ExrOptions};
use crate::render::{Frame, CHANNELS};
use crate::scene::Pass;
use crate::Cause;
use exr::prelude::*;
use smallvec::SmallVec;
use std::path::Path;

/// Channels that may be stored as half floats (`--half`): colour, coverage, normals and the
/// Doppler factor. Positions, depth, lookback and ids keep full precision.
const MAY_BE_HALF: [&str; 8] = ["R", "G", "B", "A", "N.X", "N.Y", "N.Z", "doppler.V"];

/// The pass a channel of [`CHANNELS`] belongs to (named for what Nuke and Blender make of
/// it: docs/output-passes.md); None for colour and alpha, which are always written.
fn pass_of(channel: &str) -> Option<Pass> {
    let layer = channel.split('.').next().unwrap_or(channel);
    Some(match layer {
        "R" | "G" | "B" | "A" => return None,
        "Z" => Pass::Depth,
        "lookback" => Pass::Lookback,
        "doppler" => Pass::Doppler,
        "object_id" => Pass::ObjectId,
        "material_id" => Pass::MaterialId,
        "primitive_id" => Pass::PrimitiveId,
        "N" => Pass::Normal,
        "P" => Pass::Position,
        "Pref" => Pass::RestPosition,
        "Pcam" => Pass::CameraPosition,
        _ => unreachable!("a channel of CHANNELS: {channel}"),
    })
}

/// Strips of rows, top to bottom, handed to a sink that encodes them.
pub type Strips<'a> = dyn FnMut(&Frame) -> std::result::Result<(), Cause> + 'a;

/// Write a whole frame (see [`write_strips`]).
pub fn write(frame: &Frame, path: &Path, options: &ExrOptions) -> std::result::Result<(), Cause> {
    let mattes = !frame.mattes.is_empty();
    write_strips(path, (frame.width, frame.height), mattes, options, |put| {
        put(frame)
    })
}

/// The channels of `frame` as columns, as the file holds them, sorted by name (every pass,
/// and the Cryptomatte layers when `mattes`), with the Cryptomatte attributes: the header's
/// template (from a frame of one pixel), and what the blocks made straight from a strip's
/// pixels (`exr_block.rs`) are tested against.
pub(super) fn channels(
    frame: &Frame,
    mattes: bool,
    options: &ExrOptions,
) -> (AnyChannels<FlatSamples>, Vec<(String, Attribute)>) {
    let channels: Vec<AnyChannel<FlatSamples>> = CHANNELS
        .iter()
        .filter(|name| pass_of(name).is_none_or(|p| options.passes.has(p)))
        .map(|&name| {
            let values = frame.channel(name).expect("known channel");
            let samples = if options.half && MAY_BE_HALF.contains(&name) {
                FlatSamples::F16(values.into_iter().map(super::exr_block::half_of).collect())
            } else {
                FlatSamples::F32(values)
            };
            AnyChannel::new(name, samples)
        })
        .collect();
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels.into_iter().collect();
    let mut extra = Vec::new();
    let mattes = mattes && options.passes.has(Pass::Cryptomatte);
    if let (Some(names), true) = (&options.mattes, mattes) {
        let picks: [cryptomatte::Pick; 2] = [|m| &m.object, |m| &m.material];
        for (pick, made) in picks.into_iter().zip(names.made()) {
            let (channels, attributes) = cryptomatte::layer(&frame.mattes, pick, made);
            // Ids are bit patterns: always full float.
            list.extend(
                channels
                    .into_iter()
                    .map(|(name, values)| AnyChannel::new(name.as_str(), FlatSamples::F32(values))),
            );
            extra.extend(attributes);
        }
    }
    (AnyChannels::sort(list), extra)
}

/// A header string as OpenEXR stores it: its UTF-8 bytes (the exr crate's `Text::from`
/// panics on characters beyond Latin-1: a scene named `雪.toml`, an object named `雪`).
fn text(s: &str) -> Text {
    Text::from_slice_unchecked(s.as_bytes())
}

/// The file's header, for an image of `size` whose channels are those of `template` (its
/// samples unused) and whose extra attributes are `extra`.
fn headers(
    size: (u32, u32),
    template: AnyChannels<FlatSamples>,
    extra: &[(String, Attribute)],
    options: &ExrOptions,
) -> exr::meta::Headers {
    let mut attrs = LayerAttributes {
        software_name: Some(Text::from(concat!(
            "rest-embree ",
            env!("CARGO_PKG_VERSION")
        ))),
        ..Default::default()
    };
    for (name, value) in options.attributes.iter().chain(extra) {
        // The standard attributes the exr crate keeps in fields of their own.
        match (name.as_str(), value) {
            ("worldToCamera", Attribute::Matrix(m)) => {
                attrs.world_to_camera = Some(*m);
                continue;
            }
            ("worldToNDC", Attribute::Matrix(m)) => {
                attrs.world_to_normalized_device = Some(*m);
                continue;
            }
            _ => {}
        }
        let value = match value {
            Attribute::Text(t) => AttributeValue::Text(text(t)),
            Attribute::Texts(ts) => {
                AttributeValue::TextVector(ts.iter().map(|t| text(t)).collect())
            }
            Attribute::Number(x) => AttributeValue::F64(*x),
            Attribute::Int(i) => AttributeValue::I32(*i),
            Attribute::Vector(v) => AttributeValue::FloatVec3((v[0], v[1], v[2])),
            Attribute::Matrix(m) => AttributeValue::Matrix4x4(*m),
        };
        attrs.other.insert(text(name), value);
    }
    // Scanlines, which compositors stream, in increasing order.
    let encoding = Encoding {
        compression: options.compression.exr(),
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    if let Some(p) = options.placement {
        attrs.layer_position = Vec2(p.origin.0 as i32, p.origin.1 as i32);
    }
    let layer = Layer::new(
        (size.0 as usize, size.1 as usize),
        attrs,
        encoding,
        template,
    );
    let mut image = Image::from_layer(layer);
    if let Some(p) = options.placement {
        image.attributes.display_window =
            IntegerBounds::new((0, 0), (p.full.0 as usize, p.full.1 as usize));
    }
    // R, G, B are linear sRGB / Rec. 709 (the camera's CIE XYZ through IEC 61966-2-1's matrix).
    let [r, g, b, w] = crate::spectrum::camera::SRGB_CHROMATICITIES.map(|[x, y]| Vec2(x, y));
    image.attributes.chromaticities = Some(attribute::Chromaticities {
        red: r,
        green: g,
        blue: b,
        white: w,
    });
    image.write().infer_meta_data()
}

/// Write a `width` × `height` EXR whose rows `fill` hands to its sink in strips, top to
/// bottom (every strip but the last a whole number of 32-row blocks): each strip's blocks are
/// compressed in parallel and written as it comes, so the image is never held whole. `mattes`:
/// whether the strips carry Cryptomatte mattes (and the file their layers).
pub(crate) fn write_strips(
    path: &Path,
    (width, height): (u32, u32),
    mattes: bool,
    options: &ExrOptions,
    fill: impl FnOnce(&mut Strips) -> std::result::Result<(), Cause>,
) -> std::result::Result<(), Cause> {
    // The header from the channels of an empty frame: the same names and sample types.
    let empty = Frame {
        mattes: if mattes {
            vec![Default::default()]
        } else {
            Vec::new()
        },
        ..Frame::new(1, 1)
    };
    let (template, extra) = channels(&empty, mattes, options);
    let headers = headers((width, height), template, &extra, options);
    let layout = Layout::new(&headers[0].channels, options.mattes.as_ref())
        .expect("the channels of a render");
    write_blocks(path, headers, |put| {
        fill(&mut |strip: &Frame| {
            if strip.width != width {
                return Err(cause(std::io::Error::other("a strip of another width")));
            }
            put(&layout.strip(strip), strip.height as usize)
        })
    })
}

/// Rows of the image, as a source of the file's blocks, and how many rows they hold.
pub(super) type Rows<'a> =
    dyn FnMut(&dyn BlockSource, usize) -> std::result::Result<(), Cause> + 'a;

/// Write a single-part scanline EXR with `headers` whose rows `fill` hands on in runs, top to
/// bottom (each but the last a whole number of blocks): each run's blocks are compressed in
/// parallel and written in increasing order; then the header's attributes are sorted.
pub(super) fn write_blocks(
    path: &Path,
    headers: exr::meta::Headers,
    fill: impl FnOnce(&mut Rows) -> std::result::Result<(), Cause>,
) -> std::result::Result<(), Cause> {
    use exr::block::{enumerate_ordered_header_block_indices, writer::ChunksWriter};
    use rayon::prelude::*;
    let file = std::io::BufWriter::new(std::fs::File::create(path).map_err(cause)?);
    let mut failed: Option<Cause> = None;
    let written = exr::block::write(file, headers, true, |meta, writer| {
        let blocks: Vec<_> = enumerate_ordered_header_block_indices(&meta.headers).collect();
        let header = &meta.headers[0];
        let width = header.layer_size.width();
        let (mut next, mut y0) = (0usize, 0usize);
        std::thread::scope(|scope| {
            // A run's chunks are written, in order, by a thread of their own while the next
            // run renders (one run waits at most); the renderer's threads never wait on the
            // file.
            let (tx, rx) =
                std::sync::mpsc::sync_channel::<Vec<(usize, exr::block::chunk::Chunk)>>(1);
            let writing = scope.spawn(move || -> exr::error::Result<()> {
                for chunks in rx {
                    for (index, chunk) in chunks {
                        writer.write_chunk(index, chunk)?;
                    }
                }
                Ok(())
            });
            let result = fill(&mut |channels, rows| {
                let y1 = y0 + rows;
                let mine = blocks[next..]
                    .iter()
                    .take_while(|(_, b)| b.pixel_position.y() + b.pixel_size.height() <= y1)
                    .count();
                let chunks = blocks[next..next + mine]
                    .par_iter()
                    .map(|&(index, block)| {
                        compress(&meta.headers, block, (channels, y0, width)).map(|c| (index, c))
                    })
                    .collect::<exr::error::Result<Vec<_>>>()
                    .map_err(cause)?;
                // A writer that stopped has its error, given below.
                let sent = tx.send(chunks);
                next += mine;
                y0 = y1;
                sent.map_err(|_| cause(std::io::Error::other("the file's writer stopped")))
            });
            drop(tx);
            let wrote = writing
                .join()
                .unwrap_or_else(|p| std::panic::resume_unwind(p));
            if let Err(e) = wrote {
                failed = Some(cause(e));
                return Err(exr::error::Error::Aborted);
            }
            if let Err(e) = result {
                failed = Some(e);
                return Err(exr::error::Error::Aborted);
            }
            if next != blocks.len() {
                failed = Some(cause(std::io::Error::other(format!(
                    "{y0} rows of {} were written",
                    header.layer_size.height()
                ))));
                return Err(exr::error::Error::Aborted);
            }
            Ok(())
        })
    });
    if let Some(e) = failed {
        return Err(e);
    }
    written.map_err(cause)?;
    sort_header_attributes(path).map_err(cause)
}

/// A block, from `source` (whose first row is the image's `y0`, its lines `width` long),
/// compressed into its chunk. ZIP (16 lines or 1) is done here, line by line as the source
/// makes them (`zip_lines`), the rest by the exr crate.
fn compress(
    headers: &[exr::meta::header::Header],
    block: exr::block::BlockIndex,
    (source, y0, width): (&dyn BlockSource, usize, usize),
) -> exr::error::Result<exr::block::chunk::Chunk> {
    use exr::block::chunk::{Chunk, CompressedBlock, CompressedScanLineBlock};
    let header = &headers[block.layer];
    let zip = matches!(header.compression, Compression::ZIP16 | Compression::ZIP1);
    // The block's bytes are the file's (little-endian) bytes only on a little-endian machine.
    if !zip || cfg!(target_endian = "big") {
        return source
            .block(&header.channels, block, y0, width)
            .compress_to_chunk(headers);
    }
    let size = header.channels.bytes_per_pixel * block.pixel_size.area();
    let zipped = zip_lines(size, |each| {
        source.each_line(&header.channels, block, y0, width, each)
    });
    // A block that does not get smaller is stored as it is, as OpenEXR reads it (its bytes
    // made again, whole: rare, as noise is).
    let pixels = match zipped.filter(|z| z.len() < size) {
        Some(z) => z,
        None => source.block(&header.channels, block, y0, width).data,
    };
    Ok(Chunk {
        layer_index: block.layer,
        compressed_block: CompressedBlock::ScanLine(CompressedScanLineBlock {
            y_coordinate: block.pixel_position.y() as i32
                + header.own_attributes.layer_position.y(),
            compressed_pixels_le: pixels,
        }),
    })
}

/// Put the header's attributes in the order of their names. The exr crate keeps custom
/// attributes in a `HashMap`, whose order changes from process to process, and the same render
/// would make a different file. The header keeps its length, so the offsets after it hold.
pub(super) fn sort_header_attributes(path: &Path) -> std::io::Result<()> {
    use std::io::{Read, Seek, SeekFrom, Write};
    let mut file = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(path)?;
    let mut header = Vec::new();
    let spans = loop {
        let mut chunk = vec![0; 1 << 16];
        let n = file.read(&mut chunk)?;
        header.extend_from_slice(&chunk[..n]);
        if let Some(spans) = attribute_spans(&header) {
            break spans;
        }
        if n == 0 {
            return Err(std::io::Error::other("an EXR header without its end"));
        }
    };
    let (Some(first), Some(last)) = (spans.first(), spans.last()) else {
        return Ok(());
    };
    let (start, end) = (first.start, last.end);
    let mut sorted = spans.clone();
    sorted.sort_by(|a, b| name_of(&header, a).cmp(name_of(&header, b)));
    let bytes: Vec<u8> = sorted
        .iter()
        .flat_map(|s| header[s.clone()].to_vec())
        .collect();
    debug_assert_eq!(bytes.len(), end - start);
    file.seek(SeekFrom::Start(start as u64))?;
    file.write_all(&bytes)?;
    Ok(())
}

/// The byte ranges of a single-part EXR header's attributes (after the magic number and the
/// version), or None if `bytes` ends before the header does.
fn attribute_spans(bytes: &[u8]) -> Option<Vec<std::ops::Range<usize>>> {
    let mut spans = Vec::new();
    let mut at = 8;
    loop {
        if *bytes.get(at)? == 0 {
            return Some(spans);
        }
        let name_end = at + bytes[at..].iter().position(|&b| b == 0)?;
        let type_end = name_end + 1 + bytes[name_end + 1..].iter().position(|&b| b == 0)?;
        let size = bytes.get(type_end + 1..type_end + 5)?;
        let size = u32::from_le_bytes(size.try_into().ok()?) as usize;
        let end = type_end + 5 + size;
        if end > bytes.len() {
            return None;
        }
        spans.push(at..end);
        at = end;
    }
}

fn name_of<'a>(header: &'a [u8], span: &std::ops::Range<usize>) -> &'a [u8] {
    let s = &header[span.clone()];
    &s[..s.iter().position(|&b| b == 0).unwrap_or(s.len())]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exr_read::read_channels;
    use crate::output::Compression as Packing;

    /// Every channel reads back bit for bit through the exr crate, for the ZIPs done here (on
    /// smooth values, which compress, and on noise, whose blocks are stored raw) and for a
    /// compression the crate does, in one strip and in several.
    #[test]
    fn written_blocks_read_back_exactly() {
        let (w, h) = (37, 70);
        let mut rng = crate::rng::Rng(11);
        for noise in [false, true] {
            let mut frame = Frame::new(w, h);
            for (i, p) in frame.pixels.iter_mut().enumerate() {
                let r = if noise {
                    f32::from_bits((rng.next_u64() as u32) & 0x7f7f_ffff)
                } else {
                    i as f32 / 100.0
                };
                p.color = [r, r * 0.5, 1.0 - r];
                p.alpha = 1.0;
                p.depth = r;
                p.object_id = i as u32 % 7;
                p.position = [r, -r, 2.0 * r];
            }
            for compression in [Packing::Zip, Packing::Zips, Packing::Piz, Packing::None] {
                let options = ExrOptions {
                    compression,
                    ..Default::default()
                };
                let dir = std::env::temp_dir();
                let path = dir.join(format!("rest-embree-blocks-{}.exr", std::process::id()));
                // Two strips of 32 rows and the rest, as a render hands them on.
                write_strips(&path, (w, h), false, &options, |put| {
                    for y in (0..h).step_by(32) {
                        let rows = (y..(y + 32).min(h)).collect::<Vec<_>>();
                        let strip = Frame {
                            width: w,
                            height: rows.len() as u32,
                            pixels: frame.pixels
                                [(y * w) as usize..((y + rows.len() as u32) * w) as usize]
                                .to_vec(),
                            mattes: Vec::new(),
                        };
                        put(&strip)?;
                    }
                    Ok(())
                })
                .unwrap();
                let (rw, rh, channels) = read_channels(&path).unwrap();
                assert_eq!((rw, rh), (w as usize, h as usize));
                for name in ["R", "G", "B", "Z", "object_id.V", "P.Z"] {
                    let want = frame.channel(name).unwrap();
                    let got = &channels[name];
                    let same = want
                        .iter()
                        .zip(got)
                        .all(|(a, b)| a.to_bits() == b.to_bits());
                    assert!(same, "{name}, {compression:?}, noise {noise}");
                }
                let _ = std::fs::remove_file(&path);
            }
        }
    }

    /// A file whose writes fail part way (a full device) ends the render with the device's
    /// error, as the thread that writes the chunks met it: not a panic, and not the word of
    /// the renderer's side that the writer stopped.
    #[test]
    fn a_failed_write_is_the_devices_error() {
        let full = Path::new("/dev/full");
        if !full.exists() {
            return;
        }
        let (w, h) = (256, 256);
        let mut rng = crate::rng::Rng(5);
        let mut frame = Frame::new(w, h);
        for p in frame.pixels.iter_mut() {
            // Noise, which does not compress: every strip's chunks exceed the write buffer.
            let r = f32::from_bits((rng.next_u64() as u32) & 0x3f7f_ffff);
            p.color = [r, r, r];
            p.position = [r, r, r];
        }
        let mut strips = 0;
        let err = write_strips(full, (w, h), false, &ExrOptions::default(), |put| {
            for y in (0..h).step_by(32) {
                let strip = Frame {
                    width: w,
                    height: 32,
                    pixels: frame.pixels[(y * w) as usize..((y + 32) * w) as usize].to_vec(),
                    mattes: Vec::new(),
                };
                strips += 1;
                put(&strip)?;
            }
            Ok(())
        })
        .expect_err("a full device fails the write");
        let said = err.to_string();
        assert!(said.contains("No space left"), "{said}");
        assert!(strips >= 1, "{strips}");
    }
}
