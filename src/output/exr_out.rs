use super::file::cause;
use super::{cryptomatte, Attribute, ExrOptions};
use crate::render::{Frame, CHANNELS};
use crate::{Cause, Error};
use exr::prelude::*;
use smallvec::SmallVec;
use std::collections::HashMap;
use std::path::Path;

/// Channels that may be stored as half floats (`--half`): colour, coverage, normals and the
/// Doppler factor. Positions, depth, lookback and ids keep full precision.
const MAY_BE_HALF: [&str; 8] = [
    "R",
    "G",
    "B",
    "A",
    "N.X",
    "N.Y",
    "N.Z",
    "relativity.doppler",
];

/// Strips of rows, top to bottom, handed to a sink that encodes them.
pub type Strips<'a> = dyn FnMut(&Frame) -> std::result::Result<(), Cause> + 'a;

/// Write a whole frame (see [`write_strips`]).
pub fn write(frame: &Frame, path: &Path, options: &ExrOptions) -> std::result::Result<(), Cause> {
    let mattes = !frame.mattes.is_empty();
    write_strips(path, (frame.width, frame.height), mattes, options, |put| {
        put(frame)
    })
}

/// The channels of `frame` as the file holds them, sorted by name (every pass, and the
/// Cryptomatte layers when `mattes`), made in parallel, with the Cryptomatte attributes.
fn channels(
    frame: &Frame,
    mattes: bool,
    options: &ExrOptions,
) -> (AnyChannels<FlatSamples>, Vec<(String, Attribute)>) {
    use rayon::prelude::*;
    let channels: Vec<AnyChannel<FlatSamples>> = CHANNELS
        .par_iter()
        .map(|&name| {
            let values = frame.channel(name).expect("known channel");
            let samples = if options.half && MAY_BE_HALF.contains(&name) {
                FlatSamples::F16(values.into_iter().map(f16::from_f32).collect())
            } else {
                FlatSamples::F32(values)
            };
            AnyChannel::new(name, samples)
        })
        .collect();
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels.into_iter().collect();
    let mut extra = Vec::new();
    if let (Some(names), true) = (&options.mattes, mattes) {
        let kinds: [(&str, cryptomatte::Pick, &[String]); 2] = [
            ("CryptoObject", |m| &m.object, &names.objects),
            ("CryptoMaterial", |m| &m.material, &names.materials),
        ];
        for (layer, pick, names) in kinds {
            let (channels, attributes) = cryptomatte::layer(layer, &frame.mattes, pick, names);
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
            Attribute::Text(t) => AttributeValue::Text(Text::from(t.as_str())),
            Attribute::Texts(ts) => {
                AttributeValue::TextVector(ts.iter().map(|t| Text::from(t.as_str())).collect())
            }
            Attribute::Number(x) => AttributeValue::F64(*x),
            Attribute::Int(i) => AttributeValue::I32(*i),
            Attribute::Vector(v) => AttributeValue::FloatVec3((v[0], v[1], v[2])),
            Attribute::Matrix(m) => AttributeValue::Matrix4x4(*m),
        };
        attrs.other.insert(Text::from(name.as_str()), value);
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
pub fn write_strips(
    path: &Path,
    (width, height): (u32, u32),
    mattes: bool,
    options: &ExrOptions,
    fill: impl FnOnce(&mut Strips) -> std::result::Result<(), Cause>,
) -> std::result::Result<(), Cause> {
    use exr::block::{
        enumerate_ordered_header_block_indices, writer::ChunksWriter, UncompressedBlock,
    };
    use rayon::prelude::*;
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
    let file = std::io::BufWriter::new(std::fs::File::create(path).map_err(cause)?);
    let mut failed: Option<Cause> = None;
    let written = exr::block::write(file, headers, true, |meta, writer| {
        let blocks: Vec<_> = enumerate_ordered_header_block_indices(&meta.headers).collect();
        let list = &meta.headers[0].channels;
        let (mut next, mut y0) = (0usize, 0usize);
        let result = fill(&mut |strip: &Frame| {
            if strip.width != width {
                return Err(cause(std::io::Error::other("a strip of another width")));
            }
            let (channels, _) = channels(strip, mattes, options);
            let y1 = y0 + strip.height as usize;
            let mine = blocks[next..]
                .iter()
                .take_while(|(_, b)| b.pixel_position.y() + b.pixel_size.height() <= y1)
                .count();
            let w = width as usize;
            let chunks: Vec<_> = blocks[next..next + mine]
                .par_iter()
                .map(|&(index, block)| {
                    let data = UncompressedBlock::from_lines(list, block, |line| {
                        let at = (line.location.position.y() - y0) * w + line.location.position.x();
                        let n = line.location.sample_count;
                        let samples = &channels.list[line.location.channel].sample_data;
                        let done = match samples {
                            FlatSamples::F16(v) => line.write_samples_from_slice(&v[at..at + n]),
                            FlatSamples::F32(v) => line.write_samples_from_slice(&v[at..at + n]),
                            FlatSamples::U32(v) => line.write_samples_from_slice(&v[at..at + n]),
                        };
                        done.expect("a line of the block's own size");
                    });
                    data.compress_to_chunk(&meta.headers).map(|c| (index, c))
                })
                .collect();
            for chunk in chunks {
                let (index, chunk) = chunk.map_err(cause)?;
                writer.write_chunk(index, chunk).map_err(cause)?;
            }
            next += mine;
            y0 = y1;
            Ok(())
        });
        if let Err(e) = result {
            failed = Some(e);
            return Err(exr::error::Error::Aborted);
        }
        if next != blocks.len() {
            failed = Some(cause(std::io::Error::other(format!(
                "{y0} rows of {height} were rendered"
            ))));
            return Err(exr::error::Error::Aborted);
        }
        Ok(())
    });
    if let Some(e) = failed {
        return Err(e);
    }
    written.map_err(cause)?;
    sort_header_attributes(path).map_err(cause)
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
