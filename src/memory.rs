//! The memory a render needs, estimated before anything large is allocated, against a limit:
//! the machine's available memory (Linux: `MemAvailable`), or what `--max-memory` says. A
//! render that would not fit is refused with the estimate and the limit, instead of aborting
//! on a failed allocation halfway.
//!
//! The estimates are upper bounds from the sizes of the structures: per pixel the frame's
//! [`PixelValue`](crate::render::PixelValue) (92 bytes) and, for an EXR, its mattes and the
//! encoder's blocks in flight (images are rendered and written a strip at a time,
//! [`STRIP_PIXELS`] or more, so only a strip counts); per primitive the f64 primitive, its
//! share of the accelerator and the build's buffers (the bench's 100³ lattice, 4 million
//! primitives, peaks near 270 bytes each).

use std::sync::atomic::{AtomicU64, Ordering};

/// Bytes per primitive: the scene's copy, the accelerator and its build.
pub(crate) const BYTES_PER_PRIMITIVE: u64 = 320;
/// Bytes per block of an instanced lattice: an Embree instance (or the f64 BVH's leaf) and its
/// share of the tree over the blocks.
pub(crate) const BYTES_PER_BLOCK: u64 = 1024;
/// Bytes of memory per byte of a scene file's text while it is read: the text itself and the
/// tokens of its longest expression (the tree's values are `BYTES_PER_SCENE_VALUE`).
pub(crate) const BYTES_PER_SCENE_BYTE: u64 = 8;
/// Bytes of memory per value of a scene file's tree at most: its node and its share of the
/// growth of the array or table it is in. Measured (peak resident memory over the file's
/// values): 10 million numbers in one array 85 bytes each, 5 million one-number arrays 150
/// bytes per value, a table of a million keys 150.
pub(crate) const BYTES_PER_SCENE_VALUE: u64 = 192;

/// What reading `text` as a scene costs at most: its bytes, and a value for each `,`, `[`, `{`
/// and `=` (every value of TOML follows one; comments and strings only make it more).
pub(crate) fn scene_bytes(text: &[u8]) -> u64 {
    // In chunks whose counts fit a u32, a form the compiler turns into vector compares (a
    // 26 MB scene took 55 ms byte by byte).
    let values: u64 = text
        .chunks(1 << 16)
        .map(|c| {
            let n: u32 = c
                .iter()
                .map(|&b| u32::from(matches!(b, b',' | b'[' | b'{' | b'=')))
                .sum();
            u64::from(n)
        })
        .sum();
    (text.len() as u64)
        .saturating_mul(BYTES_PER_SCENE_BYTE)
        .saturating_add(values.saturating_mul(BYTES_PER_SCENE_VALUE))
}
/// Bytes per pixel of a PNG render's strip: the frame's rows, and their 8-bit encoding.
pub(crate) const BYTES_PER_PIXEL_PNG: u64 = 96;
/// Pixels a render to a file holds at a time, at least (whole pairs of rows of tiles,
/// [`STRIP_TILE_ROWS_PER_THREAD`] per thread or more): a PNG or EXR is written strip by strip
/// as it is rendered, an EXR strip's blocks compressed in parallel. Smaller strips hold less
/// (on a big mesh, the strip is most of what a render adds to the scene's memory) at the cost
/// of a wait for the slowest tile at each strip's end.
pub(crate) const STRIP_PIXELS: u64 = 1 << 16;
/// Rows of tiles a strip has per thread at least, so that every thread has work to the strip's
/// end.
pub(crate) const STRIP_TILE_ROWS_PER_THREAD: u64 = 2;
/// Bytes per pixel of an EXR render's strip, at most: the frame (92), its mattes (96), each
/// thread's block in flight (ZIP's predicted bytes, or another compression's block: at most
/// the thread's share of the strip, 32 rows of 46 channels of 4 bytes, 184 bytes a pixel, as a
/// strip has at least 32 rows per thread), and compressed chunks as large as the raw blocks at
/// worst (no compression, or noise): the strip's own and the two earlier strips' the writer
/// may still hold (`exr_out::write_blocks`), 3 × 184.
pub(crate) const BYTES_PER_PIXEL_EXR: u64 = 92 + 96 + 184 + 3 * 184;

/// What a triangle of a mesh held as itself costs rendered, its corner data aside: its share of
/// the shared vertices and of its indices, and of the backend's structure and its build (the
/// f64 BVH's build holds an 80-byte item a triangle, and the whole process peaked at 159 bytes
/// a triangle on the bench's 10-million-triangle PLY; Embree's compact structure, far less).
pub(crate) const BYTES_PER_HELD_TRIANGLE: u64 = 160;

/// A mesh triangle's corner normals: three, in f64.
pub(crate) const BYTES_PER_CORNER_NORMALS: u64 = 72;
/// What one placement of a shared mesh costs (`Implicit::Instance`): its placement, its run
/// and parts, and its instance in a backend (Embree's instance geometry, the BVH's entry).
pub(crate) const BYTES_PER_INSTANCE: u64 = 4096;

/// A mesh triangle's corner texture coordinates: three pairs, in f64.
pub(crate) const BYTES_PER_CORNER_UVS: u64 = 48;

/// What a star of `[sky] stars` costs: itself (40 bytes), its entry in the grid that rays after
/// a bounce search (88: direction, spectrum, RGB), and in a frame its place in a pixel (about
/// 80).
pub(crate) const BYTES_PER_STAR: u64 = 210;

/// The memory an object held as itself (a lattice, a bar array) costs rendered: its
/// primitives', listed, or when it is instanced (more than
/// [`INSTANCE_OVER`](crate::geometry::INSTANCE_OVER) of them) one block's and a placement per
/// block; a mesh's, its vertices and indices.
pub(crate) fn implicit_bytes(shape: &crate::geometry::Implicit) -> u64 {
    if let crate::geometry::Implicit::Instance(_) = shape {
        // The mesh is counted once, where it is read; a placement costs its own.
        return BYTES_PER_INSTANCE;
    }
    if shape.len() <= crate::geometry::INSTANCE_OVER {
        return shape.len().saturating_mul(BYTES_PER_PRIMITIVE);
    }
    if let crate::geometry::Implicit::Mesh(m) = shape {
        return m.len().saturating_mul(BYTES_PER_HELD_TRIANGLE);
    }
    let blocks = crate::geometry::Blocks::of(shape.grid());
    shape.member_count(&blocks) * BYTES_PER_PRIMITIVE + blocks.count() * BYTES_PER_BLOCK
}

/// The limit set by [`set_limit`]; 0 for the machine's available memory.
static LIMIT: AtomicU64 = AtomicU64::new(0);

/// Limit what a render may use to `bytes` (None: the machine's available memory).
pub(crate) fn set_limit(bytes: Option<u64>) {
    LIMIT.store(bytes.unwrap_or(0), Ordering::Relaxed);
}

/// The limit, and where it comes from; None where it cannot be known (no limit set, and not
/// Linux), when nothing is checked.
pub fn limit() -> Option<(u64, &'static str)> {
    match LIMIT.load(Ordering::Relaxed) {
        0 => available().map(|b| (b, "available")),
        b => Some((b, "allowed by --max-memory")),
    }
}

/// The machine's available memory (Linux), in bytes: read at most once a second (a scene of
/// 100,000 objects asks for each, and /proc/meminfo took 20 µs a read: 2 s of its loading).
fn available() -> Option<u64> {
    use std::sync::Mutex;
    use std::time::{Duration, Instant};
    static READ: Mutex<Option<(Instant, Option<u64>)>> = Mutex::new(None);
    let mut read = READ.lock().unwrap_or_else(|e| e.into_inner());
    match *read {
        Some((at, bytes)) if at.elapsed() < Duration::from_secs(1) => bytes,
        _ => {
            let bytes = read_available();
            *read = Some((Instant::now(), bytes));
            bytes
        }
    }
}

/// The machine's available memory now, from /proc/meminfo.
fn read_available() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Why `need` bytes (for `what`) will not fit, or None when they do or nothing can be known.
pub(crate) fn too_much(need: u64, what: &str) -> Option<String> {
    exceeds(need, what, limit())
}

fn exceeds(need: u64, what: &str, limit: Option<(u64, &str)>) -> Option<String> {
    let (limit, source) = limit?;
    (need > limit).then(|| {
        format!(
            "{what} needs about {} of memory, more than the {} {source}",
            human(need),
            human(limit)
        )
    })
}

/// A size for people: GiB, MiB, KiB or bytes (never "0 MiB" for a size that is not 0).
pub(crate) fn human(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= f64::from(1u32 << 30) {
        format!("{:.1} GiB", b / f64::from(1u32 << 30))
    } else if b >= f64::from(1u32 << 20) {
        format!("{:.0} MiB", b / f64::from(1u32 << 20))
    } else if b >= 1024.0 {
        format!("{:.0} KiB", b / 1024.0)
    } else {
        format!("{bytes} bytes")
    }
}

/// A size as people write it: `8G`, `512M`, `64k` or bytes.
pub(crate) fn parse_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let (number, unit) = t
        .find(|c: char| c.is_ascii_alphabetic())
        .map_or((t, ""), |i| t.split_at(i));
    let factor: u64 = match unit.to_ascii_lowercase().as_str() {
        "" | "b" => 1,
        "k" | "kb" | "kib" => 1 << 10,
        "m" | "mb" | "mib" => 1 << 20,
        "g" | "gb" | "gib" => 1 << 30,
        "t" | "tb" | "tib" => 1 << 40,
        _ => return Err(format!("`{text}`: the unit must be k, M, G or T")),
    };
    let n: f64 = number
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a size such as 8G or 512M"))?;
    let bytes = n * factor as f64;
    if !(bytes.is_finite() && bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!("`{text}` is not a size such as 8G or 512M"));
    }
    Ok(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_as_people_write_them() {
        assert_eq!(parse_size("8G"), Ok(8 << 30));
        assert_eq!(parse_size("512M"), Ok(512 << 20));
        assert_eq!(parse_size("1.5 GiB"), Ok(3 << 29));
        assert_eq!(parse_size("4096"), Ok(4096));
        for bad in ["", "G", "-1G", "8X", "nanG", "0"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
        assert_eq!(human(3 << 29), "1.5 GiB");
        assert_eq!(human(200 << 20), "200 MiB");
        assert_eq!(human(1 << 10), "1 KiB");
        assert_eq!(human(5), "5 bytes");
        // Values by their separators: 3 in `a = [1, 2]` ('=', '[' and ',').
        assert_eq!(scene_bytes(b"a = [1, 2]"), 10 * 8 + 3 * 192);
    }

    #[test]
    fn a_limit_refuses_what_exceeds_it() {
        let limit = Some((1 << 30, "allowed by --max-memory"));
        assert!(exceeds(1 << 29, "x", limit).is_none());
        let why = exceeds(3 << 30, "this render", limit).unwrap();
        assert!(why.contains("3.0 GiB") && why.contains("1.0 GiB allowed by --max-memory"));
        assert!(
            exceeds(u64::MAX, "x", None).is_none(),
            "nothing known, nothing refused"
        );
    }
}
