//! An EXR block's bytes made straight from a strip's pixels: each of the file's channels knows
//! where its value lies in a pixel (a pass, or a rank of a Cryptomatte layer), and a block is
//! written line by line, 16 pixels at a time (their values made once, then stored column by
//! column), without first making a column of every channel. Blocks are independent, so the
//! strip's blocks are made (and compressed) in parallel.

use super::cryptomatte::{self, MatteNames};
use crate::render::{Frame, Mattes, CHANNELS, MATTE_RANKS};
use exr::block::{BlockIndex, UncompressedBlock};
use exr::meta::attribute::{ChannelList, SampleType};
use exr::prelude::*;
use smallvec::SmallVec;

/// What makes a block's bytes: a strip of the image whose first row is the image's `y0`.
pub(super) trait BlockSource: Sync {
    /// The uncompressed bytes of `block` of an image whose channels are `channels` and whose
    /// lines are `width` samples long.
    fn block(
        &self,
        channels: &ChannelList,
        block: BlockIndex,
        y0: usize,
        width: usize,
    ) -> UncompressedBlock;

    /// The same bytes handed to `each` a line at a time, top to bottom (a source that can
    /// make a line alone never makes the block's bytes whole).
    fn each_line(
        &self,
        channels: &ChannelList,
        block: BlockIndex,
        y0: usize,
        width: usize,
        each: &mut dyn FnMut(&[u8]),
    ) {
        let data = self.block(channels, block, y0, width).data;
        let lines = block.pixel_size.height().max(1);
        data.chunks(data.len().div_ceil(lines).max(1))
            .for_each(each);
    }
}

/// Columns of samples, as the file orders its channels (what a tile being joined holds).
impl BlockSource for AnyChannels<FlatSamples> {
    fn block(
        &self,
        channels: &ChannelList,
        block: BlockIndex,
        y0: usize,
        width: usize,
    ) -> UncompressedBlock {
        UncompressedBlock::from_lines(channels, block, |line| {
            let at = (line.location.position.y() - y0) * width + line.location.position.x();
            let n = line.location.sample_count;
            let done = match &self.list[line.location.channel].sample_data {
                FlatSamples::F16(v) => line.write_samples_from_slice(&v[at..at + n]),
                FlatSamples::F32(v) => line.write_samples_from_slice(&v[at..at + n]),
                FlatSamples::U32(v) => line.write_samples_from_slice(&v[at..at + n]),
            };
            done.expect("a line of the block's own size");
        })
    }
}

/// Where one channel's value lies in a pixel.
#[derive(Clone, Copy)]
enum Source {
    /// A pass of the pixel's value: which of [`crate::render::PixelValue::values`].
    Pass(usize),
    /// A value of the pixel's mattes: which of [`Layout::matte_values`].
    Matte(usize),
}

/// How many values a pixel's mattes give: per kind (objects, materials) and rank, an id and a
/// share.
const MATTE_VALUES: usize = 2 * 2 * MATTE_RANKS;

/// The file's channels, in its order, each with where its values lie and how it is stored.
pub(super) struct Layout {
    columns: Vec<(Source, SampleType)>,
    /// The Cryptomatte ids of the objects and of the materials, by index + 1 (0 for none).
    ids: [Vec<f32>; 2],
}

impl Layout {
    /// The layout of a file whose channels are `channels`, named as the render names its
    /// passes (see [`crate::render::CHANNELS`]) and Cryptomatte layers; the mattes' ids from
    /// `names`. None if a channel is neither.
    pub(super) fn new(channels: &ChannelList, names: Option<&MatteNames>) -> Option<Layout> {
        let columns = channels
            .list
            .iter()
            .map(|c| Some((source(&c.name.to_string(), names.is_some())?, c.sample_type)))
            .collect::<Option<_>>()?;
        let ids = names.map_or_else(Default::default, |n| {
            n.made().each_ref().map(|m| m.ids.clone())
        });
        Some(Layout { columns, ids })
    }

    /// A strip of the image, as a source of blocks.
    pub(super) fn strip<'a>(&'a self, strip: &'a Frame) -> Strip<'a> {
        Strip {
            layout: self,
            frame: strip,
        }
    }

    /// A pixel's mattes as the values of the Cryptomatte channels: for the objects, then the
    /// materials, rank by rank, the id and the share.
    #[inline]
    fn matte_values(&self, m: &Mattes) -> [f32; MATTE_VALUES] {
        let mut v = [0.0; MATTE_VALUES];
        for (kind, ranks) in [&m.object, &m.material].into_iter().enumerate() {
            for (rank, &(index, share)) in ranks.iter().enumerate() {
                let at = 2 * (kind * MATTE_RANKS + rank);
                v[at] = self.ids[kind][index as usize];
                v[at + 1] = share;
            }
        }
        v
    }
}

/// A channel's source from its name: a pass, or (where the file has `mattes`) a column of a
/// Cryptomatte layer, named as [`cryptomatte::channel_name`] names it (column c holds rank
/// c / 2's id or share, value `c` of the layer's kind in [`Layout::matte_values`]).
fn source(name: &str, mattes: bool) -> Option<Source> {
    if let Some(pass) = crate::render::pass(name) {
        return Some(Source::Pass(pass));
    }
    if !mattes {
        return None;
    }
    let columns = 2 * MATTE_RANKS;
    (0..cryptomatte::LAYERS.len() * columns)
        .find(|&v| cryptomatte::channel_name(cryptomatte::LAYERS[v / columns], v % columns) == name)
        .map(Source::Matte)
}

/// A strip of pixels with the layout of the file it goes to.
pub(super) struct Strip<'a> {
    layout: &'a Layout,
    frame: &'a Frame,
}

/// Pixels whose values are made together, then stored column by column.
const RUN: usize = 16;

/// A line's columns by the kind of value each holds (which value, its first byte in the line,
/// its sample type): the passes' and the mattes'.
type Columns = SmallVec<[(usize, usize, SampleType); 32]>;

impl Strip<'_> {
    /// The columns of a line `n` pixels long, and the line's bytes.
    fn columns(&self, n: usize) -> (Columns, Columns, usize) {
        let (mut passes, mut mattes) = (Columns::new(), Columns::new());
        let mut line_bytes = 0;
        for &(source, t) in &self.layout.columns {
            match source {
                Source::Pass(i) => passes.push((i, line_bytes, t)),
                Source::Matte(i) => mattes.push((i, line_bytes, t)),
            }
            line_bytes += n * t.bytes_per_sample();
        }
        (passes, mattes, line_bytes)
    }

    /// The bytes of the line of `n` pixels from pixel `at` of the strip, every byte of `out`
    /// written.
    fn line(&self, (passes, mattes): (&Columns, &Columns), at: usize, n: usize, out: &mut [u8]) {
        // RUN pixels at a time: their values made once, then each column's RUN samples
        // stored together (one pixel's values spread over every column).
        let pixels = &self.frame.pixels[at..at + n];
        let mut values = [[0.0; CHANNELS.len()]; RUN];
        for (run, chunk) in pixels.chunks(RUN).enumerate() {
            for (v, p) in values.iter_mut().zip(chunk) {
                *v = p.values();
            }
            store_run(out, run, passes, &values[..chunk.len()]);
        }
        if mattes.is_empty() {
            return;
        }
        // A strip without mattes leaves their channels zero.
        let Some(pixel_mattes) = self.frame.mattes.get(at..at + n) else {
            for &(_, column, t) in mattes {
                out[column..column + n * t.bytes_per_sample()].fill(0);
            }
            return;
        };
        let mut values = [[0.0; MATTE_VALUES]; RUN];
        for (run, chunk) in pixel_mattes.chunks(RUN).enumerate() {
            for (v, m) in values.iter_mut().zip(chunk) {
                *v = self.layout.matte_values(m);
            }
            store_run(out, run, mattes, &values[..chunk.len()]);
        }
    }
}

impl BlockSource for Strip<'_> {
    fn block(
        &self,
        _: &ChannelList,
        block: BlockIndex,
        y0: usize,
        width: usize,
    ) -> UncompressedBlock {
        let lines = block.pixel_size.height();
        let (x0, n) = (block.pixel_position.x(), block.pixel_size.width());
        let (passes, mattes, line_bytes) = self.columns(n);
        let mut data = vec![0; line_bytes * lines];
        for (line, out) in data.chunks_exact_mut(line_bytes.max(1)).enumerate() {
            let at = (block.pixel_position.y() + line - y0) * width + x0;
            self.line((&passes, &mattes), at, n, out);
        }
        UncompressedBlock { index: block, data }
    }

    /// Each line made in a buffer the thread keeps, and handed on.
    fn each_line(
        &self,
        _: &ChannelList,
        block: BlockIndex,
        y0: usize,
        width: usize,
        each: &mut dyn FnMut(&[u8]),
    ) {
        thread_local! {
            static LINE: std::cell::RefCell<Vec<u8>> = Default::default();
        }
        let (x0, n) = (block.pixel_position.x(), block.pixel_size.width());
        let (passes, mattes, line_bytes) = self.columns(n);
        LINE.with_borrow_mut(|out| {
            // Every byte is written by `line`.
            out.resize(line_bytes, 0);
            for line in 0..block.pixel_size.height() {
                let at = (block.pixel_position.y() + line - y0) * width + x0;
                self.line((&passes, &mattes), at, n, out);
                each(out);
            }
        });
    }
}

/// Store run `run` of a line's pixels, whose values are `values`, in each of `columns` (which
/// value, the column's first byte in the line, its sample type).
#[inline(always)]
fn store_run<const N: usize>(
    line: &mut [u8],
    run: usize,
    columns: &[(usize, usize, SampleType)],
    values: &[[f32; N]],
) {
    for &(i, column, t) in columns {
        let size = t.bytes_per_sample();
        let at = column + size * RUN * run;
        let samples = line[at..at + size * values.len()].chunks_exact_mut(size);
        for (sample, v) in samples.zip(values) {
            store(sample, t, v[i]);
        }
    }
}

/// `v` as a half float, saturated at half's largest finite value (65504) rather than made
/// infinite: a bright glow stays the brightest a half holds, not `inf` in a compositor.
pub(super) fn half_of(v: f32) -> f16 {
    f16::from_f32(v.clamp(-65504.0, 65504.0))
}

/// Store `v` as a `t` in `sample` (its size).
#[inline(always)]
fn store(sample: &mut [u8], t: SampleType, v: f32) {
    match t {
        SampleType::F16 => sample.copy_from_slice(&half_of(v).to_ne_bytes()),
        SampleType::F32 => sample.copy_from_slice(&v.to_ne_bytes()),
        SampleType::U32 => sample.copy_from_slice(&(v as u32).to_ne_bytes()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use exr::meta::attribute::ChannelDescription;

    /// Every block made from a strip's pixels holds the bytes the same block made from columns
    /// of its channels holds (each column made on its own, from `Frame::channel` and
    /// `cryptomatte::layer`): every pass and both Cryptomatte layers, full and half floats,
    /// blocks of 1, 16 and 32 lines, including a last block cut short.
    #[test]
    fn blocks_from_pixels_are_blocks_from_columns() {
        let (w, h) = (13usize, 45usize);
        let mut rng = crate::rng::Rng(5);
        let mut frame = Frame::new(w as u32, h as u32);
        let mut f = || (rng.next_u64() % 10_000) as f32 / 77.0 - 50.0;
        for p in &mut frame.pixels {
            p.color = [f(), f(), f()];
            p.alpha = f();
            p.lookback = f();
            p.doppler = f();
            p.depth = f();
            p.normal = [f(), f(), f()];
            p.position = [f(), f(), f()];
            p.rest_position = [f(), f(), f()];
            p.camera_position = [f(), f(), f()];
            p.object_id = f().abs() as u32;
            p.material_id = f().abs() as u32;
            p.primitive_id = f().abs() as u32;
        }
        let names = MatteNames::new(
            (0..5).map(|i| format!("object {i}")).collect(),
            vec!["white".into(), "red".into()],
        );
        frame.mattes = (0..w * h)
            .map(|i| Mattes {
                object: std::array::from_fn(|r| ((i + r) as u32 % 6, r as f32 / 7.0)),
                material: std::array::from_fn(|r| ((i * r) as u32 % 3, 1.0 - r as f32 / 9.0)),
            })
            .collect();
        for half in [false, true] {
            let options = super::super::ExrOptions {
                half,
                mattes: Some(names.clone()),
                ..Default::default()
            };
            let (cols, _) = super::super::exr_out::channels(&frame, true, &options);
            let list: ChannelList = ChannelList::new(
                cols.list
                    .iter()
                    .map(|c| {
                        let t = match c.sample_data {
                            FlatSamples::F16(_) => SampleType::F16,
                            FlatSamples::F32(_) => SampleType::F32,
                            FlatSamples::U32(_) => SampleType::U32,
                        };
                        ChannelDescription::named(c.name.clone(), t)
                    })
                    .collect(),
            );
            assert_eq!(list.list.len(), CHANNELS.len() + 4 * MATTE_RANKS);
            let layout = Layout::new(&list, Some(&names)).expect("every channel known");
            // Cryptomatte channels without the names their ids come from have no layout.
            assert!(Layout::new(&list, None).is_none());
            let strip = layout.strip(&frame);
            for lines in [1usize, 16, 32] {
                for y in (0..h).step_by(lines) {
                    let block = BlockIndex {
                        layer: 0,
                        pixel_position: Vec2(0, y),
                        pixel_size: Vec2(w, lines.min(h - y)),
                        level: Vec2(0, 0),
                    };
                    let want = cols.block(&list, block, 0, w).data;
                    let got = strip.block(&list, block, 0, w).data;
                    assert_eq!(got, want, "half {half}, {lines} lines, at {y}");
                    // The same bytes a line at a time (how ZIP blocks are made).
                    let mut joined = Vec::new();
                    strip.each_line(&list, block, 0, w, &mut |l| {
                        assert_eq!(l.len(), want.len() / block.pixel_size.height());
                        joined.extend_from_slice(l)
                    });
                    assert_eq!(joined, want, "half {half}, {lines} lines at a time, at {y}");
                }
            }
            // A strip without mattes, its lines made on this thread right after those with:
            // the line buffer's Cryptomatte columns are zero again, as a whole block's are.
            let bare = Frame {
                mattes: Vec::new(),
                ..frame.clone()
            };
            let strip = layout.strip(&bare);
            let block = BlockIndex {
                layer: 0,
                pixel_position: Vec2(0, 0),
                pixel_size: Vec2(w, 16),
                level: Vec2(0, 0),
            };
            let want = strip.block(&list, block, 0, w).data;
            let mut joined = Vec::new();
            strip.each_line(&list, block, 0, w, &mut |l| joined.extend_from_slice(l));
            assert_eq!(joined, want, "half {half}, without mattes");
            assert!(want.iter().any(|&b| b != 0) && joined.len() == want.len());
        }
        // A channel the render does not name has no layout.
        let odd = ChannelList::new(smallvec::smallvec![ChannelDescription::named(
            "Q",
            SampleType::F32
        )]);
        assert!(Layout::new(&odd, Some(&names)).is_none());
    }
}
