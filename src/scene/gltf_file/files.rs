//! A glTF file's bytes: the file itself, its buffers (the binary chunk, files beside it, data
//! URIs) and its images (PNG in a buffer view or a URI, EXR beside it), each a regular file
//! checked against the memory limit before it is read.

use super::{GltfError, Image, BYTES_PER_FILE_BYTE};
use std::path::{Path, PathBuf};

/// A file's bytes, if it is a regular file within the memory limit.
pub(super) fn read_file(path: &Path) -> Result<Vec<u8>, GltfError> {
    crate::scene::inputs::note(path);
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot read it: {e}"))?;
    if !meta.is_file() {
        return Err("it is not a regular file".into());
    }
    let need = meta.len().saturating_mul(BYTES_PER_FILE_BYTE);
    let what = format!(
        "reading {} ({})",
        path.display(),
        crate::memory::human(meta.len())
    );
    if let Some(why) = crate::memory::too_much(need, &what) {
        return Err(why.into());
    }
    std::fs::read(path).map_err(|e| format!("cannot read it: {e}").into())
}

/// The bytes a URI names: a data URI (base64), or a file relative to `base`.
pub(super) fn uri_bytes(uri: &str, base: &Path) -> Result<(Vec<u8>, String), GltfError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or("a data URI that is not base64")?;
        let need = (data.len() as u64 / 4 * 3).saturating_mul(BYTES_PER_FILE_BYTE);
        if let Some(why) = crate::memory::too_much(need, "a data URI") {
            return Err(why.into());
        }
        use base64::Engine;
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(data.trim_end())
            .map_err(|e| format!("a data URI that is not base64: {e}"))?;
        return Ok((bytes, "a data URI".into()));
    }
    if uri.contains("://") {
        return Err(format!("`{}` is not a file beside it", crate::text::shown(uri)).into());
    }
    let path: PathBuf = base.join(percent_decoded(uri));
    let bytes = read_file(&path).map_err(|why| format!("{}: {why}", path.display()))?;
    Ok((bytes, path.display().to_string()))
}

/// A relative URI's path with its %XX escapes decoded.
pub(super) fn percent_decoded(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        match (
            b[i],
            b.get(i + 1).and_then(|&c| hex(c)),
            b.get(i + 2).and_then(|&c| hex(c)),
        ) {
            (b'%', Some(h), Some(l)) => {
                out.push((h * 16 + l) as u8);
                i += 3;
            }
            (c, _, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Every buffer's bytes, each at least as long as the file says it is.
pub(super) fn buffers(gltf: &gltf::Gltf, base: &Path) -> Result<Vec<Vec<u8>>, GltfError> {
    gltf.buffers()
        .map(|b| {
            let bytes = match b.source() {
                gltf::buffer::Source::Bin => gltf.blob.clone().ok_or_else(|| {
                    format!("buffer {} is the binary chunk, which it lacks", b.index())
                })?,
                gltf::buffer::Source::Uri(uri) => {
                    uri_bytes(uri, base)
                        .map_err(|why| format!("buffer {}: {why}", b.index()))?
                        .0
                }
            };
            if bytes.len() < b.length() {
                return Err(format!(
                    "buffer {} holds {} bytes, less than the {} it claims",
                    b.index(),
                    bytes.len(),
                    b.length()
                )
                .into());
            }
            Ok(bytes)
        })
        .collect()
}

/// An image's texels: a PNG in a buffer view, a data URI or a file beside the glTF file (PNG
/// or EXR).
pub(super) fn image(
    img: &gltf::Image,
    buffers: &[Vec<u8>],
    base: &Path,
) -> Result<Image, GltfError> {
    let (bytes, shown, mime) = match img.source() {
        gltf::image::Source::View { view, mime_type } => {
            let data = &buffers[view.buffer().index()];
            let range = view.offset()..view.offset() + view.length();
            let bytes = data
                .get(range)
                .ok_or_else(|| format!("image {}'s buffer view is past its buffer", img.index()))?;
            (
                bytes.to_vec(),
                format!("image {}", img.index()),
                Some(mime_type.to_string()),
            )
        }
        gltf::image::Source::Uri { uri, mime_type } => {
            if !uri.starts_with("data:") && uri.to_ascii_lowercase().ends_with(".exr") {
                let path = base.join(percent_decoded(uri));
                let (w, h, texels) =
                    crate::scene::texture::read_image(&path).map_err(|e| e.to_string())?;
                return Ok(Image {
                    shown: path.display().to_string(),
                    width: w,
                    height: h,
                    texels,
                });
            }
            let (bytes, shown) = uri_bytes(uri, base)?;
            (bytes, shown, mime_type.map(str::to_string))
        }
    };
    if !bytes.starts_with(b"\x89PNG") {
        return Err(format!(
            "{shown} ({}) is not a PNG: only PNG (and EXR) textures are read; export with PNG images",
            mime.as_deref().unwrap_or("no type given")
        ).into());
    }
    let (w, h, texels) =
        crate::scene::texture::read_png(std::io::Cursor::new(bytes), Path::new(&shown))
            .map_err(|e| e.to_string())?;
    Ok(Image {
        shown,
        width: w,
        height: h,
        texels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_lose_their_escapes() {
        assert_eq!(percent_decoded("my%20mesh.bin"), "my mesh.bin");
        assert_eq!(percent_decoded("100%"), "100%");
        assert_eq!(percent_decoded("a%zz"), "a%zz");
    }
}
