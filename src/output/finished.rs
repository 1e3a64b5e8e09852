//! Whether a file is a finished image of a render, for a film's `--resume`: a regular file that
//! reads to its end as the format says (every EXR block its offset table promises, each
//! decompressed; every PNG row), of the frame's size, that names the same render (`header::render_id`, an EXR
//! attribute and a PNG text chunk). A file that is empty, cut short, garbage, a directory, the
//! wrong size or another render's is not, whatever its name.

use super::header::RENDER_ID;
use super::Format;
use std::io::BufReader;
use std::path::Path;

/// Ok if `path` is a finished `format` image of `size` (the frame's) from render `id`; else
/// an error that says why not.
/// `storage`: for an EXR, the compression and whether colour is in half floats, as this
/// render would write them (a film resumed with `--half` or another `--compression` renders
/// its frames again rather than mix two kinds of file).
pub fn finished(
    path: &Path,
    format: Format,
    size: (u32, u32),
    id: &str,
    storage: (super::Compression, bool),
) -> crate::Result<()> {
    let meta = std::fs::metadata(path).map_err(|e| not(path, e))?;
    if !meta.is_file() {
        return Err(not(path, "not a regular file"));
    }
    if meta.len() == 0 {
        return Err(not(path, "empty"));
    }
    match format {
        Format::Png => png(path, size, id),
        Format::Exr => exr(path, size, id, storage),
    }
}

/// Why `path` is not a finished image.
fn not(path: &Path, why: impl std::fmt::Display) -> crate::Error {
    crate::Error::image(path, why.to_string(), None)
}

fn png(path: &Path, size: (u32, u32), id: &str) -> crate::Result<()> {
    let file = std::fs::File::open(path).map_err(|e| not(path, e))?;
    let mut reader = png::Decoder::new(BufReader::new(file))
        .read_info()
        .map_err(|e| not(path, format!("not a readable PNG ({e})")))?;
    let info = reader.info();
    if (info.width, info.height) != size {
        return Err(not(
            path,
            format!(
                "{}x{}, not the frame's {}x{}",
                info.width, info.height, size.0, size.1
            ),
        ));
    }
    let said = info
        .uncompressed_latin1_text
        .iter()
        .find(|t| t.keyword == RENDER_ID)
        .map(|t| t.text.clone());
    if said.as_deref() != Some(id) {
        return Err(not(path, "from another render (or none said)"));
    }
    let mut rows = 0;
    while let Some(_row) = reader
        .next_row()
        .map_err(|e| not(path, format!("cut short or damaged ({e})")))?
    {
        rows += 1;
    }
    if rows != size.1 {
        return Err(not(path, format!("{rows} rows of {}", size.1)));
    }
    Ok(())
}

fn exr(
    path: &Path,
    size: (u32, u32),
    id: &str,
    (compression, half): (super::Compression, bool),
) -> crate::Result<()> {
    use exr::meta::attribute::AttributeValue;
    let file = std::fs::File::open(path).map_err(|e| not(path, e))?;
    let reader = exr::block::read(BufReader::new(file), false)
        .map_err(|e| not(path, format!("not a readable EXR ({e})")))?;
    let headers = reader.headers();
    if headers.len() != 1 {
        return Err(not(path, format!("{} layers, not one", headers.len())));
    }
    let header = &headers[0];
    let window = header.layer_size;
    if (window.0 as u32, window.1 as u32) != size {
        return Err(not(
            path,
            format!(
                "{}x{}, not the frame's {}x{}",
                window.0, window.1, size.0, size.1
            ),
        ));
    }
    if header.compression != compression.exr() {
        return Err(not(
            path,
            format!(
                "compressed as {}, not {}",
                header.compression,
                compression.exr()
            ),
        ));
    }
    let red = header
        .channels
        .list
        .iter()
        .find(|c| c.name.to_string() == "R");
    let in_half = red.is_some_and(|c| c.sample_type == exr::meta::attribute::SampleType::F16);
    if red.is_some() && in_half != half {
        return Err(not(
            path,
            match half {
                true => "colour in full floats, not half (--half)",
                false => "colour in half floats (--half), not full",
            },
        ));
    }
    let said = header
        .own_attributes
        .other
        .iter()
        .find(|(name, _)| *name == RENDER_ID)
        .and_then(|(_, v)| match v {
            AttributeValue::Text(t) => Some(t.to_string()),
            _ => None,
        });
    if said.as_deref() != Some(id) {
        return Err(not(path, "from another render (or none said)"));
    }
    // Every block read and decompressed (in parallel): a byte flipped in the middle of a
    // compressed block, or zeros where its last bytes were, fails here. (A file written
    // without compression holds no check of its own: a flipped byte there is a wrong pixel.)
    use exr::block::reader::ChunksReader;
    let expected = header.chunk_count;
    let mut blocks = 0;
    reader
        .all_chunks(false)
        .map_err(|e| not(path, format!("cut short or damaged ({e})")))?
        .decompress_parallel(false, |_, _| {
            blocks += 1;
            Ok(())
        })
        .map_err(|e| not(path, format!("cut short or damaged ({e})")))?;
    if blocks != expected {
        return Err(not(path, format!("{blocks} of its {expected} blocks")));
    }
    Ok(())
}
