//! Writing a rendered frame: EXR (linear float, with the extra passes) or PNG (tone-mapped
//! sRGB), chosen by the file extension. Files are written whole or not at all.

mod assemble;
pub mod cryptomatte;
mod exr_block;
mod exr_out;
mod exr_zip;
pub mod file;
mod finished;
pub use finished::finished;
pub mod header;
pub(crate) mod png_out;
mod srgb8;
pub(crate) use srgb8::srgb8;

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

/// Write the frame; the file appears only when it is complete (see [`mod@file`]). An EXR is
/// written with [`ExrOptions::default`].
pub fn write(frame: &Frame, path: &Path) -> crate::Result<()> {
    write_with(frame, path, &ExrOptions::default())
}

/// Write `frame`, rendered from `scene` (loaded from `scene_file` with the overrides shown as
/// `overrides`) on `backend`, as `rest-embree render` writes it: an EXR with its header's
/// attributes and Cryptomatte layers, a PNG with its render id and alpha only for a
/// transparent scene. The same render makes the same bytes as the command's file.
pub fn write_render(
    frame: &Frame,
    path: &Path,
    scene: &crate::scene::Scene,
    backend: &str,
    scene_file: &str,
    overrides: &[String],
) -> crate::Result<()> {
    let size = (frame.width, frame.height);
    match Format::for_path(path)? {
        Format::Exr => {
            let exr = ExrOptions::for_render(scene, backend, scene_file, overrides);
            let mattes = !frame.mattes.is_empty();
            write_exr_in_strips(path, size, mattes, &exr, |put| put(frame))
        }
        Format::Png => {
            let id = header::render_id(scene, backend, overrides);
            let alpha = scene.image.is_transparent();
            write_png_in_strips(path, size, alpha, Some(&id), |put| put(frame))
        }
    }
}

/// As [`write()`], an EXR with `exr`'s compression, precision and header attributes.
pub(crate) fn write_with(frame: &Frame, path: &Path, exr: &ExrOptions) -> crate::Result<()> {
    let format = Format::for_path(path)?;
    file::write_whole(path, |tmp| match format {
        Format::Exr => exr_out::write(frame, tmp, exr),
        Format::Png => png_out::write(frame, tmp),
    })
}

/// How an EXR is written besides its pixels.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExrOptions {
    /// The compression of its scanlines.
    pub compression: Compression,
    /// Colour, alpha, normals and the Doppler factor as half floats (positions, depth,
    /// lookback and ids stay full floats).
    pub half: bool,
    /// Attributes of the header beside the standard ones, by name.
    pub attributes: Vec<(String, Attribute)>,
    /// The names for Cryptomatte layers (`CryptoObject`, `CryptoMaterial`) of a frame that
    /// has mattes; None: no such layers.
    pub mattes: Option<cryptomatte::MatteNames>,
    /// Where a cropped frame sits in the full image; None: the frame is the full image.
    pub placement: Option<Placement>,
    /// The passes beside colour and alpha.
    pub passes: crate::scene::PassSet,
}

impl ExrOptions {
    /// The EXR of a render of `scene` on `backend` from `scene_file` with the command line's
    /// `overrides`: the header's camera, scene and render attributes, the Cryptomatte names, the
    /// crop's place; the default compression, full floats.
    pub fn for_render(
        scene: &crate::scene::Scene,
        backend: &str,
        scene_file: &str,
        overrides: &[String],
    ) -> ExrOptions {
        let names = header::matte_names(scene);
        // The mattes' ids and manifests now, where a render makes its header beside its build.
        if scene.image.passes.has(crate::scene::Pass::Cryptomatte) {
            names.made();
        }
        ExrOptions {
            attributes: header::attributes(scene, backend, scene_file, overrides),
            mattes: Some(names),
            placement: Placement::of(&scene.image),
            passes: scene.image.passes,
            ..Default::default()
        }
    }
}

/// A crop's place: the full image's size (OpenEXR's display window) and the frame's top left
/// pixel in it (the origin of the data window), so compositors put it where it belongs and
/// `rest-embree assemble` can join tiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    /// Width and height of the full image.
    pub full: (u32, u32),
    /// The frame's top left pixel in the full image.
    pub origin: (u32, u32),
}

impl Placement {
    /// The placement of a frame rendered with `image`'s settings (None without a crop).
    pub fn of(image: &crate::scene::ImageSettings) -> Option<Placement> {
        image.crop.map(|_| Placement {
            full: (image.width, image.height),
            origin: image.frame_offset(),
        })
    }
}

/// An EXR's lossless compressions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Compression {
    /// zlib over blocks of 16 scanlines: small, and what compositors read fastest.
    #[default]
    Zip,
    /// zlib per scanline.
    Zips,
    /// Wavelets and Huffman: smallest for grainy images.
    Piz,
    /// Run lengths: fastest to write, largest.
    Rle,
    /// None.
    None,
}

impl Compression {
    /// The names `--compression` takes.
    pub const NAMES: [&'static str; 5] = ["zip", "zips", "piz", "rle", "none"];

    /// The compression of a name in [`Compression::NAMES`].
    pub fn by_name(name: &str) -> Option<Compression> {
        let all = [Self::Zip, Self::Zips, Self::Piz, Self::Rle, Self::None];
        Self::NAMES.iter().position(|n| *n == name).map(|i| all[i])
    }

    pub(crate) fn exr(self) -> exr::prelude::Compression {
        use exr::prelude::Compression as C;
        match self {
            Self::Zip => C::ZIP16,
            Self::Zips => C::ZIP1,
            Self::Piz => C::PIZ,
            Self::Rle => C::RLE,
            Self::None => C::Uncompressed,
        }
    }
}

/// A header attribute's value.
#[derive(Clone, Debug, PartialEq)]
pub enum Attribute {
    /// A string.
    Text(String),
    /// Strings.
    Texts(Vec<String>),
    /// A double.
    Number(f64),
    /// An integer.
    Int(i32),
    /// A vector of three floats.
    Vector([f32; 3]),
    /// A 4 × 4 matrix, row-major.
    Matrix([f32; 16]),
}

/// Write a PNG of `width` × `height` whose rows `fill` hands on in strips, top to bottom, as
/// it renders them: the image is never held whole.
/// `render_id` (`header::render_id`), if given, goes into a text chunk.
pub(crate) fn write_png_in_strips(
    path: &Path,
    (width, height): (u32, u32),
    alpha: bool,
    render_id: Option<&str>,
    fill: impl FnOnce(&mut png_out::Strips) -> Result<(), Cause>,
) -> crate::Result<()> {
    file::write_whole(path, |tmp| {
        png_out::write_strips(tmp, width, height, alpha, render_id, fill)
    })
}

/// Write an EXR of `width` × `height` whose rows `fill` hands on in strips, top to bottom (each
/// but the last a whole number of 32-row blocks), as it renders them: the image is never held
/// whole. `mattes`: whether the strips carry Cryptomatte mattes.
impl ExrOptions {
    /// The same, its header saying `samples` were taken per pixel (`renderSamples`).
    pub(crate) fn with_samples(mut self, samples: u32) -> ExrOptions {
        for (name, value) in &mut self.attributes {
            if name == "renderSamples" {
                *value = Attribute::Int(samples as i32);
            }
        }
        self
    }
}

pub(crate) fn write_exr_in_strips(
    path: &Path,
    size: (u32, u32),
    mattes: bool,
    exr: &ExrOptions,
    fill: impl FnOnce(&mut exr_out::Strips) -> Result<(), Cause>,
) -> crate::Result<()> {
    file::write_whole(path, |tmp| {
        exr_out::write_strips(tmp, size, mattes, exr, fill)
    })
}

/// Linear to sRGB-encoded, after clamping to [0, 1].
pub(crate) fn srgb_encode(linear: f32) -> f32 {
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

pub use crate::exr_read::read_channels as read_exr_channels;
pub use assemble::assemble;
