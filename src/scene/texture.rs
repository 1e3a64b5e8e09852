//! Textures: a colour that varies over a surface, named by a material's `color` or `emission`
//! (`[[texture]]`). A checker alternates two colours in cubes laid out in the rest frame of the
//! object's group, so the pattern moves and deforms with the object exactly as its geometry does.

use crate::geometry::Primitive;
use crate::spectrum::{camera, Colour, Role, Shift};
use glam::{DMat3, DVec3};
use std::f64::consts::PI;

/// A colour that varies over a surface.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub enum Texture {
    /// Boxes of `size` (0 along an axis: no change along it) alternating between two colours,
    /// in the group's rest frame; the box from the origin toward +x, +y, +z has the first.
    Checker {
        /// The boxes' sides along x, y and z (0: no change along that axis).
        size: DVec3,
        /// The colour of the box at the origin, and the other.
        colors: [Colour; 2],
    },
    /// An image (PNG, sRGB-decoded to linear, or EXR, linear), mapped onto spheres, boxes and
    /// rods by [`uv`].
    Image(ImageTexture),
}

/// What a texture gives at a point: one of its colours, or an image's linear RGB with the
/// image (whose basis turns it into a spectrum).
pub enum Sample<'a> {
    /// A colour of the texture's own.
    Colour(&'a Colour),
    /// Linear RGB from an image.
    Rgb(DVec3, &'a ImageTexture),
}

/// An image's texels, and how one becomes a spectrum: `rgb` is written `c = to_basis · rgb` on
/// the three basis colours (the uplifts of pure red, green and blue), so that at rest, under
/// white light, the texel's colour is its RGB exactly, and shifted, each texel shifts as a
/// spectrum, the same three spectra for every texel (uplifted once, not per texel).
#[derive(Clone, PartialEq)]
pub struct ImageTexture {
    /// Where it came from (errors and the render id name it).
    pub path: String,
    /// Size in texels.
    pub width: usize,
    /// Size in texels.
    pub height: usize,
    /// Linear RGB, row by row from the top (shared by the texture's roles: a reflectance's and
    /// an emitter's uplift of the same image hold one copy).
    pub texels: std::sync::Arc<[[f32; 3]]>,
    /// Pure red, green and blue, uplifted in the texture's role.
    pub basis: [Colour; 3],
    /// From RGB to the coefficients on `basis`.
    pub to_basis: DMat3,
    /// The digest of `texels`, made on first use (a texture is not changed once made).
    digest: crate::geometry::digest::Memo,
}

impl ImageTexture {
    /// A digest of its texels' bits, read once for the texture's life.
    fn texel_digest(&self) -> u64 {
        self.digest.get_or(|| {
            let mut d = crate::geometry::digest::Digest::new();
            for t in self.texels.iter() {
                for c in t {
                    d.bytes(&c.to_bits().to_le_bytes());
                }
            }
            d.finish()
        })
    }
}

/// Its path, size and a digest of its texels: what messages show.
impl std::fmt::Debug for ImageTexture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "ImageTexture({}, {}x{}, {:016x})",
            self.path,
            self.width,
            self.height,
            self.texel_digest()
        )
    }
}

/// As its path, size and the digest of its texels: the render id hashes these, not millions of
/// numbers.
impl serde::Serialize for ImageTexture {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        (&self.path, self.width, self.height, self.texel_digest()).serialize(s)
    }
}

/// The three colours a texture of `role` writes its texels on (the uplifts of pure red, green
/// and blue) and the matrix from a texel's RGB to their weights: the same for every texture
/// of a role, so made once (with their spectral tables) for all of them.
fn basis_of(role: Role) -> &'static ([Colour; 3], DMat3) {
    static BASES: [std::sync::OnceLock<([Colour; 3], DMat3)>; 2] =
        [std::sync::OnceLock::new(), std::sync::OnceLock::new()];
    let slot = match role {
        Role::Reflectance => &BASES[0],
        Role::Emitter => &BASES[1],
    };
    slot.get_or_init(|| {
        let basis = [DVec3::X, DVec3::Y, DVec3::Z].map(|e| Colour::rgb(e, role));
        // The basis's colours as the camera records them: an emitter's own, a reflectance's
        // under white light (each of the nine numbers a camera response, so the matrix holds
        // the uplift's small departures from pure primaries).
        let seen = |c: &Colour| match role {
            Role::Emitter => camera::rgb(&c.sampled(Shift::new(1.0))),
            _ => {
                let white = Colour::rgb(DVec3::ONE, Role::Emitter).sampled(Shift::new(1.0));
                let mut s = c.sampled(Shift::new(1.0));
                for (a, b) in s.0.iter_mut().zip(white.0) {
                    *a *= b;
                }
                camera::rgb(&s)
            }
        };
        let m = DMat3::from_cols(seen(&basis[0]), seen(&basis[1]), seen(&basis[2]));
        (basis, m.inverse())
    })
}

impl ImageTexture {
    /// An image texture of `texels` for colours of `role`.
    pub fn new(
        path: String,
        width: usize,
        height: usize,
        texels: std::sync::Arc<[[f32; 3]]>,
        role: Role,
    ) -> ImageTexture {
        let (basis, to_basis) = basis_of(role).clone();
        ImageTexture {
            path,
            width,
            height,
            texels,
            basis,
            to_basis,
            digest: Default::default(),
        }
    }

    /// Bilinear: `u` wraps around, `v` (0 at the top row) is held at the edges.
    pub fn bilinear(&self, u: f64, v: f64) -> DVec3 {
        let (w, h) = (self.width as f64, self.height as f64);
        let x = u.rem_euclid(1.0) * w - 0.5;
        let y = (v.clamp(0.0, 1.0) * h - 0.5).clamp(0.0, h - 1.0);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let col = |i: f64| (i as i64).rem_euclid(self.width as i64) as usize;
        let row = |j: f64| (j as i64).clamp(0, self.height as i64 - 1) as usize;
        let t = |i: f64, j: f64| {
            let [r, g, b] = self.texels[row(j) * self.width + col(i)];
            DVec3::new(r.into(), g.into(), b.into())
        };
        let top = t(x0, y0) * (1.0 - fx) + t(x0 + 1.0, y0) * fx;
        let bottom = t(x0, y0 + 1.0) * (1.0 - fx) + t(x0 + 1.0, y0 + 1.0) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

/// Where a point of a primitive lies on an image, `(u, v)` in [0, 1] with v = 0 at the top:
/// - a sphere: longitude and latitude about its centre, z up (the poles at v = 0 and 1), u = 0.5
///   toward +x, increasing toward +y (east, seen from outside with north up);
/// - a rod: around its axis (u, from the direction most nearly +z, or +x for a rod along z) and
///   along it (v = 0 at `from`);
/// - a box: each face holds the whole image, seen from outside: on the ±x faces u runs along y,
///   on the ±y faces along x, on the ±z faces along x, and v downward along z (along y on ±z);
/// - a triangle: none of its own (a mesh's texture coordinates come from its file): None.
pub fn uv(prim: &Primitive, p: DVec3, outward: DVec3) -> Option<(f64, f64)> {
    match *prim {
        Primitive::Sphere { center, .. } => {
            let d = (p - center).normalize_or(DVec3::Z);
            Some((
                0.5 + d.y.atan2(d.x) / (2.0 * PI),
                d.z.clamp(-1.0, 1.0).acos() / PI,
            ))
        }
        Primitive::Capsule { a, b, .. } => {
            let axis = b - a;
            let len2 = axis.length_squared().max(f64::MIN_POSITIVE);
            let t = ((p - a).dot(axis) / len2).clamp(0.0, 1.0);
            let k = axis / len2.sqrt();
            let reference = if k.z.abs() > 0.9 { DVec3::X } else { DVec3::Z };
            let e1 = (reference - k * reference.dot(k)).normalize();
            let e2 = k.cross(e1);
            let r = p - a - k * (p - a).dot(k);
            Some((0.5 + r.dot(e2).atan2(r.dot(e1)) / (2.0 * PI), t))
        }
        Primitive::Cuboid { min, max } => {
            let size = max - min;
            let f = (p - min) / size;
            let n = outward.abs();
            Some(if n.x >= n.y && n.x >= n.z {
                (f.y, 1.0 - f.z)
            } else if n.y >= n.z {
                (f.x, 1.0 - f.z)
            } else {
                (f.x, 1.0 - f.y)
            })
        }
        Primitive::Triangle { .. } => None,
    }
}

impl Texture {
    /// What the texture gives at rest-frame point `p` of `prim`, whose outward normal there is
    /// `outward`. A checker is read just inside the surface (by a billionth of its smallest
    /// square): a face lying on a boundary between squares, as a box's faces do on a grid of
    /// its own size, takes the colour of the square behind it, not the one rounding picks.
    /// A mesh's texture coordinates there, `corner_uv` (v up from the bottom, as mesh files
    /// have it), take the place of the primitive's own mapping.
    #[inline]
    pub fn at(
        &self,
        prim: &Primitive,
        p: DVec3,
        outward: DVec3,
        corner_uv: Option<[f64; 2]>,
    ) -> Sample<'_> {
        match self {
            Texture::Image(img) => {
                let (u, v) = match corner_uv {
                    Some([u, v]) => (u, 1.0 - v),
                    None => uv(prim, p, outward).unwrap_or((0.5, 0.5)),
                };
                Sample::Rgb(img.bilinear(u, v), img)
            }
            Texture::Checker { size, colors } => {
                let smallest = [size.x, size.y, size.z]
                    .into_iter()
                    .filter(|&s| s > 0.0)
                    .fold(f64::INFINITY, f64::min);
                let inside = p - outward * (1e-9 * smallest);
                Sample::Colour(&colors[checker_cell(*size, inside)])
            }
        }
    }

    /// Every colour the texture may give (an image: its basis).
    pub fn colours(&self) -> impl Iterator<Item = &Colour> {
        match self {
            Texture::Checker { colors, .. } => colors.iter(),
            Texture::Image(img) => img.basis.iter(),
        }
    }
}

/// Which of a checker's two colours lies at `p`: the parity of the sum of its cell indices
/// along the axes whose size is not 0.
#[inline]
fn checker_cell(size: DVec3, p: DVec3) -> usize {
    let mut sum = 0i64;
    for k in 0..3 {
        if size[k] > 0.0 {
            sum += (p[k] / size[k]).floor() as i64;
        }
    }
    sum.rem_euclid(2) as usize
}

/// The largest value a texel keeps (an EXR's larger ones, infinity included, are clamped to
/// it, its negative ones to 0): a colour's own limit.
pub(crate) const MAX_TEXEL: f32 = 1e15;

/// The most texels an image texture may have (a 16384 x 16384 image).
pub(crate) const MAX_TEXELS: u64 = 1 << 28;

/// A texture's texels, shared by its roles.
pub(crate) type Texels = std::sync::Arc<[[f32; 3]]>;

/// Whether an image of `w` x `h` texels may be read: at most `MAX_TEXELS`, and its peak while
/// read (`per_texel` bytes a texel: the decoder's buffer and the texels made from it) within
/// the memory limit. Checked from the file's header, before its texels are read.
fn fits(path: &std::path::Path, w: usize, h: usize, per_texel: u64) -> crate::Result<()> {
    let bad = |m: String| crate::Error::image(path, m, None);
    let n = w as u64 * h as u64;
    if n == 0 || n > MAX_TEXELS {
        return Err(bad(format!(
            "it is {w}x{h}; a texture has 1 to 2^28 texels"
        )));
    }
    let what = format!("a {w}x{h} texture");
    match crate::memory::too_much(n.saturating_mul(per_texel), &what) {
        Some(why) => Err(bad(why)),
        None => Ok(()),
    }
}

/// An image file's linear RGB texels, row by row from the top: a PNG (8 or 16 bits, grey,
/// RGB, with or without alpha, palette; sRGB-decoded; alpha ignored) or an EXR (its R, G, B
/// channels, or Y as grey). Made straight into the shared buffer a texture holds (no copy of
/// them at any time); the size the header claims is checked before anything is decoded. Why
/// not, in words.
pub(crate) fn read_image(path: &std::path::Path) -> crate::Result<(usize, usize, Texels)> {
    let bad = |m: String| crate::Error::image(path, m, None);
    super::inputs::note(path);
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let meta = std::fs::metadata(path).map_err(|e| bad(format!("cannot read it: {e}")))?;
    if !meta.is_file() {
        return Err(bad("it is not a regular file".into()));
    }
    // 12 bytes a texel stay (three f32); the decoders' own buffers come on top.
    const TEXEL: u64 = 12;
    match ext.as_deref() {
        Some("png") => {
            let file =
                std::fs::File::open(path).map_err(|e| bad(format!("cannot read it: {e}")))?;
            read_png(std::io::BufReader::new(file), path)
        }
        Some("exr") => {
            // The header first: its data window says how large the image claims to be.
            let header = exr::meta::MetaData::read_from_file(path, false)
                .map_err(|e| bad(format!("not a readable EXR: {e}")))?;
            let first = header
                .headers
                .first()
                .ok_or_else(|| bad("it has no layer".into()))?;
            let (w, h) = (first.layer_size.width(), first.layer_size.height());
            // As decoded (each channel as stored), each channel as f32 again, and the texels.
            let stored: u64 = first
                .channels
                .list
                .iter()
                .map(|c| c.sample_type.bytes_per_sample() as u64 + 4)
                .sum();
            fits(path, w, h, TEXEL + stored)?;
            let (w, h, ch) =
                crate::exr_read::read_channels(path).map_err(|e| bad(e.to_string()))?;
            let pick =
                |names: [&str; 3]| names.iter().map(|n| ch.get(*n)).collect::<Option<Vec<_>>>();
            let planes = pick(["R", "G", "B"])
                .or_else(|| pick(["Y", "Y", "Y"]))
                .ok_or_else(|| bad("it has neither R, G, B nor Y channels".into()))?;
            if let Some(p) = (0..w * h).find(|&p| planes.iter().any(|c| c[p].is_nan())) {
                return Err(bad(format!(
                    "texel ({}, {}) (column, row from the top) is not a number",
                    p % w,
                    p / w
                )));
            }
            // As a colour may be: 0 to MAX_TEXEL. Negative texels (a filter's ringing in an HDR
            // map) would give negative light, infinite ones infinite light.
            let clamp = |v: f32| v.clamp(0.0, MAX_TEXEL);
            Ok((
                w,
                h,
                (0..w * h)
                    .map(|p| {
                        [
                            clamp(planes[0][p]),
                            clamp(planes[1][p]),
                            clamp(planes[2][p]),
                        ]
                    })
                    .collect(),
            ))
        }
        _ => Err(bad(
            "cannot tell its format: the name must end in .png or .exr".into(),
        )),
    }
}

/// `srgb_to_linear` of each 8-bit code (the same numbers, one `powf` per code instead of one
/// per texel and channel).
fn srgb8_to_linear() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|b| srgb_to_linear(b as f32 / 255.0)))
}

/// sRGB's decoding to linear.
fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// A sky, seen by every ray that meets nothing (`[sky]`), at rest in the world frame unless
/// it is given a velocity: an equirectangular map in the convention of the `equirectangular`
/// camera (a camera at rest with that projection looking along +x with up +z renders the map
/// back pixel for pixel), turned by `rotation` and scaled by `intensity`, and a star field
/// (where neither is given, the image's background).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Sky {
    /// The map, its texels radiances (emitter role).
    pub map: Option<std::sync::Arc<ImageTexture>>,
    /// Turns the sky (map and stars): the map's +x goes to `rotation * x`.
    pub rotation: DMat3,
    /// Multiplies the map's radiance.
    pub intensity: f64,
    /// The stars.
    pub stars: Option<super::stars::StarField>,
    /// The sky's velocity in the world frame.
    pub velocity: crate::spacetime::Velocity,
}

impl Sky {
    /// The linear RGB the map shows along sky-frame direction `d` (toward where the light
    /// comes from); None without a map.
    pub fn rgb(&self, d: DVec3) -> Option<DVec3> {
        let map = self.map.as_ref()?;
        let d = (self.rotation.transpose() * d).normalize_or(DVec3::X);
        // The camera's: longitude from +x toward its right (-y), latitude up toward +z.
        let lon = (-d.y).atan2(d.x);
        let lat = d.z.clamp(-1.0, 1.0).asin();
        let (u, v) = (lon / (2.0 * PI) + 0.5, 0.5 - lat / PI);
        Some(map.bilinear(u, v) * self.intensity)
    }
}

/// A PNG's linear RGB texels (see [`read_image`]) from `r`, its bytes; `path` names it in
/// errors (a file, or a glTF file's image).
pub(crate) fn read_png(
    mut r: impl std::io::Read,
    path: &std::path::Path,
) -> crate::Result<(usize, usize, Texels)> {
    use std::io::Read;
    let bad = |m: String| crate::Error::image(path, m, None);
    const TEXEL: u64 = 12;
    // The signature and the header's size, kept: where the decoder's own limits refuse the
    // header ("limits are exceeded"), the size it claims is said instead.
    let mut head = Vec::with_capacity(24);
    (&mut r)
        .take(24)
        .read_to_end(&mut head)
        .map_err(|e| bad(format!("not a readable PNG: {e}")))?;
    let mut decoder = png::Decoder::new(std::io::Cursor::new(head.clone()).chain(r));
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(|e| {
        let claimed = (head.len() == 24 && &head[12..16] == b"IHDR").then(|| {
            let word = |at: usize| {
                u32::from_be_bytes([head[at], head[at + 1], head[at + 2], head[at + 3]])
            };
            (word(16) as usize, word(20) as usize)
        });
        match (e, claimed) {
            (png::DecodingError::LimitsExceeded, Some((w, h))) => {
                fits(path, w, h, TEXEL).err().unwrap_or_else(|| {
                    bad(format!(
                        "not a readable PNG: {w}x{h} is beyond its decoder's limits"
                    ))
                })
            }
            (e, _) => bad(format!("not a readable PNG: {e}")),
        }
    })?;
    let (w, h) = (reader.info().width as usize, reader.info().height as usize);
    let n = (w as u64 * h as u64).max(1);
    fits(path, w, h, TEXEL + reader.output_buffer_size() as u64 / n)?;
    let mut buf = vec![0; reader.output_buffer_size()];
    let frame = reader
        .next_frame(&mut buf)
        .map_err(|e| bad(format!("not a readable PNG: {e}")))?;
    let channels = frame.color_type.samples();
    let wide = frame.bit_depth == png::BitDepth::Sixteen;
    let value = |i: usize| -> f32 {
        if wide {
            srgb_to_linear(f32::from(u16::from_be_bytes([buf[2 * i], buf[2 * i + 1]])) / 65535.0)
        } else {
            srgb8_to_linear()[usize::from(buf[i])]
        }
    };
    let texels = (0..w * h)
        .map(|p| {
            let at = p * channels;
            match channels {
                1 | 2 => [value(at); 3],
                _ => [value(at), value(at + 1), value(at + 2)],
            }
        })
        .collect();
    Ok((w, h, texels))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 8-bit table holds each code's decoding, as decoded one by one.
    #[test]
    fn the_srgb8_table_is_the_decoding() {
        for b in 0..=255u8 {
            let want = srgb_to_linear(f32::from(b) / 255.0);
            assert_eq!(srgb8_to_linear()[usize::from(b)].to_bits(), want.to_bits());
        }
    }

    #[test]
    fn checker_cells_alternate() {
        let s = DVec3::new(0.5, 0.5, 0.0);
        assert_eq!(checker_cell(s, DVec3::new(0.1, 0.1, 7.0)), 0);
        assert_eq!(checker_cell(s, DVec3::new(0.6, 0.1, -3.0)), 1);
        assert_eq!(checker_cell(s, DVec3::new(0.6, 0.6, 0.0)), 0);
        assert_eq!(checker_cell(s, DVec3::new(-0.1, 0.1, 0.0)), 1);
        assert_eq!(checker_cell(s, DVec3::new(-0.1, -0.1, 0.0)), 0);
        assert_eq!(
            checker_cell(DVec3::splat(1.0), DVec3::new(0.5, 0.5, 1.5)),
            1
        );
    }
}
