//! Tiles (EXRs that are crops of one image, each with its data window inside the same display
//! window) joined into the one EXR of the whole image: every channel, sample type, attribute
//! and the compression of the tiles, the pixels copied bit for bit.
//!
//! Every tile's header is read and checked before any pixel: one scanline part, a lossless
//! compression, the same full image (display window, within the size a render may have), the
//! same channels and render (`renderId`), its data window inside the full image; together the
//! tiles must cover the image exactly once. Then the image is written in bands of rows, top to
//! bottom, each band's rows made from the lines the tiles decode as they are reached: what is
//! held is a band and a block per tile, never the image, and the estimate of it is checked
//! against the memory limit first.

use super::exr_block::BlockSource;
use super::file::cause;
use crate::Cause;
use exr::block::reader::ChunksReader;
use exr::block::{BlockIndex, UncompressedBlock};
use exr::meta::attribute::{ChannelList, SampleType};
use exr::meta::header::Header;
use exr::meta::{BlockDescription, Headers};
use exr::prelude::*;
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

/// The largest full image joined: as large as a scene's image may be, per side.
const MAX_SIDE: usize = 1 << 20;

/// Rows written at a time: a whole number of blocks of every compression (1, 16 or 32 lines).
const BAND_ALIGN: usize = 32;

/// About how many bytes of rows a band holds (more rows give more blocks to compress in
/// parallel), at least [`BAND_ALIGN`] rows whatever the width.
const BAND_BYTES: usize = 64 << 20;

fn bad(path: &Path, why: impl Into<String>) -> crate::Error {
    let why = why.into();
    crate::Error::image(path, format!("tile {}: {why}", path.display()), None)
}

/// A tile's header, checked to be one a render writes: one scanline part, flat, losslessly
/// compressed, its data window inside its display window.
struct TileHeader {
    path: PathBuf,
    header: Header,
    /// Its place in the full image: the data window's top left, from the display window's.
    origin: (usize, usize),
    size: (usize, usize),
}

impl TileHeader {
    fn read(path: &Path) -> crate::Result<TileHeader> {
        let meta = Self::read_meta(path)?;
        let n = meta.headers.len();
        let Some(header) = meta.headers.into_iter().next().filter(|_| n == 1) else {
            return Err(bad(
                path,
                format!(
                    "it has {n} parts; assemble joins single-part EXRs as `render` writes them"
                ),
            ));
        };
        Self::joinable(path, &header)?;
        Self::placed(path, header)
    }

    /// The file's headers: a regular file (a FIFO or a device would be read forever) whose
    /// headers the EXR reader reads and a writer would write again.
    fn read_meta(path: &Path) -> crate::Result<exr::meta::MetaData> {
        // Only a regular file: a FIFO or a device would be read forever.
        match std::fs::metadata(path) {
            Err(e) => return Err(bad(path, format!("cannot read it: {e}"))),
            Ok(m) if m.is_dir() => return Err(bad(path, "it is a directory, not an EXR")),
            Ok(m) if !m.is_file() => {
                let kind = super::file::kind_of(&m);
                return Err(bad(path, format!("it is {kind}, not an EXR file")));
            }
            Ok(_) => {}
        }
        let read = std::panic::catch_unwind(|| exr::meta::MetaData::read_from_file(path, true));
        let meta = match read {
            Ok(Ok(m)) => m,
            Ok(Err(e)) => return Err(bad(path, format!("it is not a readable EXR: {e}"))),
            Err(_) => {
                return Err(bad(
                    path,
                    "it is not a readable EXR: its header is malformed",
                ))
            }
        };
        // What the reader lets pass but a writer refuses (a standard attribute of the wrong
        // type, kept as a custom one), since the first tile's header is written again.
        if let Err(e) = exr::meta::MetaData::validate(&meta.headers, true) {
            return Err(bad(path, format!("its header is not valid: {e}")));
        }
        // Names and type names are NUL-terminated in the file: one the reader took with a NUL
        // inside would be written as another header.
        let printable =
            |t: &Text| !t.bytes().is_empty() && t.bytes().iter().all(|b| (0x20..0x7f).contains(b));
        for h in &meta.headers {
            for (name, value) in h
                .own_attributes
                .other
                .iter()
                .chain(&h.shared_attributes.other)
            {
                let kind_ok = match value {
                    AttributeValue::Custom { kind, bytes } => {
                        printable(kind) && standard_size_holds(kind, bytes.len())
                    }
                    _ => true,
                };
                if !printable(name) || !kind_ok {
                    return Err(bad(
                        path,
                        format!(
                            "its header has a malformed attribute ({:?})",
                            name.to_string()
                        ),
                    ));
                }
            }
        }
        Ok(meta)
    }

    /// Refuse what assemble cannot join bit for bit: deep data, tiled or mipmapped storage,
    /// lossy compression, subsampled channels.
    fn joinable(path: &Path, header: &Header) -> crate::Result<()> {
        if header.deep {
            return Err(bad(path, "it holds deep data; assemble joins flat images"));
        }
        if let BlockDescription::Tiles(t) = header.blocks {
            let mip = match t.level_mode {
                exr::meta::attribute::LevelMode::Singular => "",
                _ => " with mipmap or ripmap levels",
            };
            return Err(bad(
                path,
                format!(
                    "it is stored in tiles{mip}; assemble joins scanline EXRs as `render` writes them"
                ),
            ));
        }
        use exr::compression::Compression as C;
        if !matches!(
            header.compression,
            C::Uncompressed | C::RLE | C::ZIP1 | C::ZIP16 | C::PIZ
        ) {
            return Err(bad(
                path,
                format!(
                    "it is compressed with {}, which is lossy: assemble copies pixels bit for bit \
                     and writes the tiles' compression; render the tiles with zip, zips, piz, rle \
                     or none (`--compression`)",
                    header.compression
                ),
            ));
        }
        if let Some(c) = header
            .channels
            .list
            .iter()
            .find(|c| c.sampling != Vec2(1, 1))
        {
            return Err(bad(
                path,
                format!(
                    "channel {} is subsampled; assemble joins full-resolution channels",
                    c.name
                ),
            ));
        }
        Ok(())
    }

    /// The tile's place in the full image (its display window), which must hold it.
    fn placed(path: &Path, header: Header) -> crate::Result<TileHeader> {
        let display = header.shared_attributes.display_window;
        let (w, h) = (display.size.0, display.size.1);
        if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
            return Err(bad(
                path,
                format!(
                    "its full image (display window) is {w}x{h}; assemble joins images of 1 to \
                     {MAX_SIDE} pixels a side"
                ),
            ));
        }
        let position = header.own_attributes.layer_position;
        let (ox, oy) = (
            i64::from(position.0) - i64::from(display.position.0),
            i64::from(position.1) - i64::from(display.position.1),
        );
        let (tw, th) = (header.layer_size.0, header.layer_size.1);
        if ox < 0 || oy < 0 || ox as usize + tw > w || oy as usize + th > h {
            return Err(bad(
                path,
                format!(
                    "its pixels ({tw}x{th} at ({ox}, {oy})) lie outside the {w}x{h} full image"
                ),
            ));
        }
        Ok(TileHeader {
            path: path.to_path_buf(),
            origin: (ox as usize, oy as usize),
            size: (tw, th),
            header,
        })
    }

    /// The render the tile says it is of (`header::render_id`), if it says.
    fn render_id(&self) -> Option<String> {
        let h = &self.header;
        h.own_attributes
            .other
            .iter()
            .chain(h.shared_attributes.other.iter())
            .find(|(name, _)| **name == *super::header::RENDER_ID)
            .and_then(|(_, v)| match v {
                AttributeValue::Text(t) => Some(t.to_string()),
                _ => None,
            })
    }

    /// Whether `other` has the same channels (names and sample types) as this tile.
    fn same_channels(&self, other: &ChannelList) -> bool {
        let mine = &self.header.channels.list;
        mine.len() == other.list.len()
            && mine
                .iter()
                .zip(&other.list)
                .all(|(a, b)| a.name == b.name && a.sample_type == b.sample_type)
    }
}

/// Whether an attribute the exr crate keeps as raw bytes has the size its type has, where the
/// type is one of OpenEXR's own of fixed size (the crate reads the others itself): a tile whose
/// `m44d` holds 64 bytes would be copied into a file OpenEXR rejects.
fn standard_size_holds(kind: &Text, len: usize) -> bool {
    let size = match kind.bytes() {
        b"m33d" => 72,
        b"m44d" => 128,
        b"v2d" => 16,
        b"v3d" => 24,
        b"floatvector" => return len.is_multiple_of(4),
        _ => return true,
    };
    len == size
}

/// Check the tiles against the first: the same full image, channels and render.
fn check_alike(tiles: &[TileHeader]) -> crate::Result<()> {
    let first = &tiles[0];
    let display = first.header.shared_attributes.display_window;
    for t in &tiles[1..] {
        if t.header.shared_attributes.display_window != display {
            return Err(bad(
                &t.path,
                format!(
                    "its full image (display window) differs from that of the first tile, {}",
                    first.path.display()
                ),
            ));
        }
        if !first.same_channels(&t.header.channels) {
            return Err(bad(
                &t.path,
                format!(
                    "its channels (names or sample types) differ from those of the first tile, {}",
                    first.path.display()
                ),
            ));
        }
        // Tiles of one render share its id (another view time, β or backend has another).
        if t.render_id() != first.render_id() {
            return Err(bad(
                &t.path,
                format!(
                    "it is of another render than {} (renderId {} against {})",
                    first.path.display(),
                    t.render_id().unwrap_or_else(|| "none".into()),
                    first.render_id().unwrap_or_else(|| "none".into())
                ),
            ));
        }
    }
    Ok(())
}

/// Check that the tiles cover the `w` × `h` image exactly once, from their rectangles alone:
/// between consecutive top and bottom edges the same tiles cross every row, and in x order
/// they must meet end to end from 0 to `w`.
fn check_cover(tiles: &[TileHeader], (w, h): (usize, usize)) -> crate::Result<()> {
    let mut edges: Vec<usize> = tiles
        .iter()
        .flat_map(|t| [t.origin.1, t.origin.1 + t.size.1])
        .chain([0, h])
        .collect();
    edges.sort_unstable();
    edges.dedup();
    // A gap is reported only when no tile overlaps another (a doubled tile also leaves one).
    let mut gap = None;
    for band in edges.windows(2) {
        let y = band[0];
        let mut crossing: Vec<&TileHeader> = tiles
            .iter()
            .filter(|t| t.origin.1 <= y && y < t.origin.1 + t.size.1)
            .collect();
        crossing.sort_by_key(|t| t.origin.0);
        let mut x = 0;
        for t in crossing {
            if t.origin.0 < x {
                return Err(bad(
                    &t.path,
                    format!("it overlaps another tile at pixel ({}, {y})", t.origin.0),
                ));
            }
            if t.origin.0 > x {
                gap = gap.or(Some((x, y)));
            }
            x = t.origin.0 + t.size.0;
        }
        if x < w {
            gap = gap.or(Some((x, y)));
        }
    }
    match gap {
        Some((x, y)) => Err(crate::Error::flag(
            "assemble",
            format!(
                "the tiles leave pixel ({x}, {y}) of the {w}x{h} image uncovered: is a tile missing?"
            ),
        )),
        None => Ok(()),
    }
}

/// Bytes of one sample of each channel, in the file's (sorted) channel order.
fn sample_bytes(channels: &ChannelList) -> Vec<usize> {
    channels
        .list
        .iter()
        .map(|c| match c.sample_type {
            SampleType::F16 => 2,
            SampleType::F32 | SampleType::U32 => 4,
        })
        .collect()
}

/// A tile's lines, decoded block by block as they are asked for, top to bottom.
struct TileLines {
    path: PathBuf,
    width: usize,
    blocks: Box<dyn Iterator<Item = exr::error::Result<UncompressedBlock>>>,
    /// The block being read, and its first line (the tile's own row).
    block: Option<(usize, UncompressedBlock)>,
    line_bytes: usize,
}

impl TileLines {
    fn open(tile: &TileHeader, line_bytes: usize) -> crate::Result<TileLines> {
        let path = tile.path.clone();
        let file = File::open(&path).map_err(|e| bad(&path, format!("cannot open it: {e}")))?;
        let chunks = exr::block::read(BufReader::new(file), true)
            .and_then(|r| r.all_chunks(true))
            .map_err(|e| bad(&path, format!("cannot read it: {e}")))?;
        Ok(TileLines {
            path,
            width: tile.size.0,
            blocks: Box::new(chunks.sequential_decompressor(true)),
            block: None,
            line_bytes,
        })
    }

    /// The tile's row `y` (its own numbering): every channel's samples, one after another.
    /// Rows must be asked for in increasing order.
    fn line(&mut self, y: usize) -> crate::Result<&[u8]> {
        loop {
            if let Some((first, b)) = &self.block {
                let n = b.index.pixel_size.height();
                if y >= *first && y < first + n {
                    let at = (y - first) * self.line_bytes;
                    return Ok(
                        &self.block.as_ref().expect("just seen").1.data[at..at + self.line_bytes]
                    );
                }
            }
            let path = &self.path;
            let next =
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| self.blocks.next()))
                    .map_err(|_| bad(path, "a block of it is malformed"))?;
            let block = match next {
                Some(Ok(b)) => b,
                Some(Err(e)) => {
                    return Err(bad(
                        path,
                        format!("a block of its pixels cannot be read: {e}"),
                    ))
                }
                None => return Err(bad(path, format!("it ends before its row {y}"))),
            };
            let first = block.index.pixel_position.y();
            let fits = block.index.pixel_position.x() == 0
                && block.index.pixel_size.width() == self.width
                && block.data.len() == block.index.pixel_size.height() * self.line_bytes;
            if !fits || first > y {
                return Err(bad(
                    path,
                    format!(
                        "its blocks are not stored top to bottom (a block of row {first} came \
                         where row {y} was next): assemble reads increasing line order"
                    ),
                ));
            }
            self.block = Some((first, block));
        }
    }
}

/// A tile on its way into the image: where each channel's samples start in its lines, and
/// its lines while the bands cross it.
struct Source {
    tile: TileHeader,
    offsets: Vec<usize>,
    lines: Option<TileLines>,
}

/// Rows of the full image, `width` wide, whose first is the image's row `y0`: as a source of
/// the file's blocks.
struct Band {
    bytes: Vec<u8>,
    line_bytes: usize,
}

impl BlockSource for Band {
    fn block(&self, _: &ChannelList, block: BlockIndex, y0: usize, _: usize) -> UncompressedBlock {
        let first = block.pixel_position.y() - y0;
        let n = block.pixel_size.height();
        UncompressedBlock {
            index: block,
            data: self.bytes[first * self.line_bytes..(first + n) * self.line_bytes].to_vec(),
        }
    }

    /// The block's lines straight from the band, without the block's copy.
    fn each_line(
        &self,
        _: &ChannelList,
        block: BlockIndex,
        y0: usize,
        _: usize,
        each: &mut dyn FnMut(&[u8]),
    ) {
        let first = block.pixel_position.y() - y0;
        let n = block.pixel_size.height();
        self.bytes[first * self.line_bytes..(first + n) * self.line_bytes]
            .chunks(self.line_bytes.max(1))
            .for_each(each);
    }
}

/// What joining the tiles holds at most, an upper bound: a band of rows four times over (the
/// rows, each block's copy, its compressed chunk, and slack for the writer's buffers), the
/// decoded and compressed blocks of the tiles the band crosses (they cover the width once per
/// row of tiles, and a band may cross two rows of tiles), and the program itself.
fn held_bytes(band_rows: usize, pixel_bytes: usize, w: usize) -> u64 {
    let row = (w * pixel_bytes) as u64;
    4 * band_rows as u64 * row + 4 * BAND_ALIGN as u64 * row + PROGRAM_BYTES
}

/// The program beside the image's bytes (code, libraries, threads' stacks), generously.
const PROGRAM_BYTES: u64 = 64 << 20;

/// Join `tiles` into `output`.
pub fn assemble(tiles: &[PathBuf], output: &Path) -> crate::Result<()> {
    if tiles.is_empty() {
        return Err(crate::Error::flag("assemble", "no tiles given"));
    }
    let headers: Vec<TileHeader> = tiles
        .iter()
        .map(|p| TileHeader::read(p))
        .collect::<crate::Result<_>>()?;
    check_alike(&headers)?;
    let first = &headers[0].header;
    let display = first.shared_attributes.display_window;
    let (w, h) = (display.size.0, display.size.1);
    check_cover(&headers, (w, h))?;

    let sizes = sample_bytes(&first.channels);
    let pixel_bytes: usize = sizes.iter().sum();
    let band_rows = (BAND_BYTES / (w * pixel_bytes).max(1) / BAND_ALIGN).max(1) * BAND_ALIGN;
    let need = held_bytes(band_rows, pixel_bytes, w);
    let what = format!(
        "joining {} tiles into a {w}x{h} image of {} channels",
        headers.len(),
        sizes.len()
    );
    if let Some(why) = crate::memory::too_much(need, &what) {
        return Err(crate::Error::flag("assemble", why));
    }
    let out_headers = image_headers(first, (w, h));
    let layout = Layout::new(sizes, w);
    // A tile is opened when the band reaches its first row and closed after its last, so
    // that only a row of tiles is open at a time.
    let mut sources: Vec<Source> = headers
        .into_iter()
        .map(|tile| Source {
            offsets: layout.offsets(tile.size.0),
            tile,
            lines: None,
        })
        .collect();
    sources.sort_by_key(|s| (s.tile.origin.1, s.tile.origin.0));
    let mut failed: Option<crate::Error> = None;
    let written = super::file::write_whole(output, |tmp| {
        super::exr_out::write_blocks(tmp, out_headers, |put| {
            let mut y0 = 0;
            while y0 < h {
                let rows = band_rows.min(h - y0);
                let mut band = Band {
                    bytes: vec![0; rows * layout.line_bytes],
                    line_bytes: layout.line_bytes,
                };
                if let Err(e) = layout.fill(&mut band, y0, &mut sources) {
                    failed = Some(e);
                    return Err(cause(std::io::Error::other("a tile failed")));
                }
                put(&band, rows)?;
                y0 += rows;
            }
            Ok::<(), Cause>(())
        })
    });
    match (failed, written) {
        (Some(e), _) => Err(e),
        (None, w) => w,
    }
}

/// The whole image's headers: the first tile's, over the display window (`size`), in scan
/// lines.
fn image_headers(first: &Header, size: (usize, usize)) -> Headers {
    let display = first.shared_attributes.display_window;
    let mut attributes = first.own_attributes.clone();
    attributes.layer_position = Vec2(display.position.0, display.position.1);
    let template = AnyChannels {
        list: first
            .channels
            .list
            .iter()
            .map(|c| AnyChannel {
                name: c.name.clone(),
                sample_data: match c.sample_type {
                    SampleType::F16 => FlatSamples::F16(Vec::new()),
                    SampleType::F32 => FlatSamples::F32(Vec::new()),
                    SampleType::U32 => FlatSamples::U32(Vec::new()),
                },
                quantize_linearly: c.quantize_linearly,
                sampling: c.sampling,
            })
            .collect(),
    };
    let encoding = Encoding {
        compression: first.compression,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(size, attributes, encoding, template);
    let mut image = Image::from_layer(layer);
    image.attributes = first.shared_attributes.clone();
    image.write().infer_meta_data()
}

/// How the image's lines are laid out: each channel's samples together (`sizes`: each
/// channel's bytes a sample), channel after channel, over the image's width.
struct Layout {
    sizes: Vec<usize>,
    /// Where each channel's samples start in an image line.
    image_offsets: Vec<usize>,
    line_bytes: usize,
}

impl Layout {
    fn new(sizes: Vec<usize>, width: usize) -> Layout {
        let line_bytes = width * sizes.iter().sum::<usize>();
        let mut layout = Layout {
            sizes,
            image_offsets: Vec::new(),
            line_bytes,
        };
        layout.image_offsets = layout.offsets(width);
        layout
    }

    /// Where each channel's samples start in a line `width` wide.
    fn offsets(&self, width: usize) -> Vec<usize> {
        self.sizes
            .iter()
            .scan(0, |at, s| {
                let here = *at;
                *at += s * width;
                Some(here)
            })
            .collect()
    }

    /// The band of image rows from `y0`: each tile's part of them, copied channel by channel
    /// into place; a tile is opened at its first row and closed after its last.
    fn fill(&self, band: &mut Band, y0: usize, sources: &mut [Source]) -> crate::Result<()> {
        let rows = band.bytes.len() / self.line_bytes.max(1);
        let pixel_bytes: usize = self.sizes.iter().sum();
        for source in sources.iter_mut() {
            let (ox, oy) = source.tile.origin;
            let (tw, th) = source.tile.size;
            let (from, to) = (y0.max(oy), (y0 + rows).min(oy + th));
            if from >= to {
                continue;
            }
            let lines = match &mut source.lines {
                Some(l) => l,
                None => source
                    .lines
                    .insert(TileLines::open(&source.tile, tw * pixel_bytes)?),
            };
            for y in from..to {
                let line = lines.line(y - oy)?;
                let row = &mut band.bytes[(y - y0) * self.line_bytes..][..self.line_bytes];
                for ((&size, &src), &dst) in self
                    .sizes
                    .iter()
                    .zip(&source.offsets)
                    .zip(&self.image_offsets)
                {
                    let n = tw * size;
                    row[dst + ox * size..][..n].copy_from_slice(&line[src..src + n]);
                }
            }
            if to == oy + th {
                source.lines = None;
            }
        }
        Ok(())
    }
}
