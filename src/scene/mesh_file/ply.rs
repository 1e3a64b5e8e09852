//! PLY, ASCII or binary, through `ply-rs-bw`: typed vertices and faces (a scanned mesh has
//! millions), its header's counts checked against the file's size before anything is read.

use super::{MeshData, MeshError};
use glam::DVec3;
use std::path::Path;

/// A PLY vertex as read: x, y, z, nx, ny, nz, u, v (or s, t, or texture_u, texture_v), with
/// a bit for each one the file gave. Typed, not a map of names per element: a scanned mesh
/// has millions of vertices.
#[derive(Clone, Copy, Default)]
struct PlyVertex {
    values: [f64; 8],
    given: u8,
}

impl PlyVertex {
    fn put(&mut self, name: &str, v: f64) -> ply_rs_bw::ply::PropertyAccessResult {
        use ply_rs_bw::ply::PropertyAccessResult::{Ignored, Set};
        let k = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            "nx" => 3,
            "ny" => 4,
            "nz" => 5,
            "u" | "s" | "texture_u" => 6,
            "v" | "t" | "texture_v" => 7,
            _ => return Ignored,
        };
        self.values[k] = v;
        self.given |= 1 << k;
        Set
    }

    fn has(&self, bits: u8) -> bool {
        self.given & bits == bits
    }
}

/// A PLY face as read: its vertex indices (`vertex_indices` or `vertex_index`), or the first
/// that is out of u32's range.
#[derive(Clone, Default)]
struct PlyFace {
    indices: smallvec::SmallVec<[u32; 4]>,
    out_of_range: Option<i64>,
    given: bool,
}

impl PlyFace {
    fn put<T: Copy + Into<i64>>(
        &mut self,
        name: &str,
        list: &[T],
    ) -> ply_rs_bw::ply::PropertyAccessResult {
        use ply_rs_bw::ply::PropertyAccessResult::{Ignored, Set};
        if name != "vertex_indices" && name != "vertex_index" {
            return Ignored;
        }
        self.given = true;
        self.indices.clear();
        for &i in list {
            let i: i64 = i.into();
            match u32::try_from(i) {
                Ok(u) => self.indices.push(u),
                Err(_) => {
                    self.out_of_range.get_or_insert(i);
                }
            }
        }
        Set
    }
}

/// An element the renderer does not use (edges, materials, ...), read past.
struct PlySkip;

macro_rules! scalar_setters {
    ($($f:ident: $t:ty),*) => {
        $(fn $f(&mut self, name: &str, v: $t) -> ply_rs_bw::ply::PropertyAccessResult {
            self.put(name, f64::from(v))
        })*
    };
}

macro_rules! list_setters {
    ($($f:ident: $t:ty),*) => {
        $(fn $f(&mut self, name: &str, v: Vec<$t>) -> ply_rs_bw::ply::PropertyAccessResult {
            self.put(name, &v)
        })*
    };
}

impl ply_rs_bw::ply::PropertyAccess for PlyVertex {
    fn new() -> Self {
        Self::default()
    }
    scalar_setters!(set_char: i8, set_uchar: u8, set_short: i16, set_ushort: u16, set_int: i32,
        set_uint: u32, set_float: f32, set_double: f64);
}

impl ply_rs_bw::ply::PropertyAccess for PlyFace {
    fn new() -> Self {
        Self::default()
    }
    list_setters!(set_list_char: i8, set_list_uchar: u8, set_list_short: i16,
        set_list_ushort: u16, set_list_int: i32, set_list_uint: u32);
}

impl ply_rs_bw::ply::PropertyAccess for PlySkip {
    fn new() -> Self {
        PlySkip
    }
}

/// A PLY file's vertices as they are read: positions, and normals and texture coordinates
/// for as long as every vertex has them.
struct Vertices {
    positions: Vec<DVec3>,
    normals: Option<Vec<DVec3>>,
    uvs: Option<Vec<[f64; 2]>>,
}

impl Vertices {
    fn with_capacity(n: usize) -> Vertices {
        Vertices {
            positions: Vec::with_capacity(n),
            normals: None,
            uvs: None,
        }
    }

    /// Keep vertex `i`, or say what is wrong with it.
    fn push(&mut self, i: usize, v: PlyVertex) -> Result<(), MeshError> {
        if let Some(k) = (0..3).find(|&k| !v.has(1 << k)) {
            return Err(MeshError::new(format!(
                "vertex {i} has no number `{}`",
                ["x", "y", "z"][k]
            )));
        }
        for (k, name) in ["x", "y", "z", "nx", "ny", "nz", "u", "v"]
            .iter()
            .enumerate()
        {
            if v.has(1 << k) && !v.values[k].is_finite() {
                return Err(MeshError::new(format!(
                    "vertex {i} (counted from 0) has {name} = {}, not a finite number",
                    v.values[k]
                )));
            }
        }
        let (first, capacity) = (self.positions.is_empty(), self.positions.capacity());
        self.positions
            .push(DVec3::new(v.values[0], v.values[1], v.values[2]));
        let normal = v
            .has(0b111_000)
            .then(|| DVec3::new(v.values[3], v.values[4], v.values[5]).normalize_or_zero());
        keep(&mut self.normals, normal, first, capacity);
        let uv = v.has(0b1100_0000).then(|| [v.values[6], v.values[7]]);
        keep(&mut self.uvs, uv, first, capacity);
        Ok(())
    }
}

/// Keep a vertex's `value` in `list` for as long as every vertex has one: the `first` vertex's
/// starts it (room for `capacity`), a vertex without one ends it.
fn keep<T>(list: &mut Option<Vec<T>>, value: Option<T>, first: bool, capacity: usize) {
    if first {
        *list = value.is_some().then(|| Vec::with_capacity(capacity));
    }
    match (list.as_mut(), value) {
        (Some(l), Some(x)) => l.push(x),
        _ => *list = None,
    }
}

/// A PLY file's faces as they are read, each polygon split into a fan of triangles.
#[derive(Default)]
struct Faces {
    triangles: Vec<[u32; 3]>,
    /// Where the faces come before the vertices, what is checked once the vertices are
    /// counted: the faces whose largest index is larger than every earlier face's (number,
    /// that index, line), among which is the first face naming a vertex the file does not
    /// have; and the first face that is wrong otherwise, from which on nothing is kept.
    records: Vec<(usize, u32, Option<usize>)>,
    wrong: Option<MeshError>,
}

impl Faces {
    /// Keep face `f` (on `line`, in an ASCII file), or say what is wrong with it; `vertices`,
    /// how many the file has, where they were read before the faces.
    fn push(
        &mut self,
        f: usize,
        face: PlyFace,
        vertices: Option<usize>,
        line: Option<usize>,
    ) -> Result<(), MeshError> {
        if self.wrong.is_some() {
            return Ok(());
        }
        let list = &face.indices;
        let missing = vertices.and_then(|n| list.iter().find(|&&i| i as usize >= n));
        let wrong = if !face.given {
            Some(MeshError::new(format!(
                "face {f} has no integer list `vertex_indices` (or `vertex_index`)"
            )))
        } else if let Some(bad) = face.out_of_range {
            Some(no_vertex(f, bad))
        } else if let (Some(&bad), Some(n)) = (missing, vertices) {
            Some(missing_vertex(f, bad, n))
        } else if list.len() < 3 {
            Some(MeshError::new(format!(
                "face {f} has {} corners; a face needs 3 or more",
                list.len()
            )))
        } else {
            None
        };
        if let Some(e) = wrong {
            let e = MeshError { line, ..e };
            if vertices.is_some() {
                return Err(e);
            }
            // An earlier face may name a vertex the file lacks: which comes first is known
            // once the vertices are counted.
            self.wrong = Some(e);
            return Ok(());
        }
        if vertices.is_none() {
            let largest = list.iter().copied().max().unwrap_or(0);
            if self.records.last().is_none_or(|&(_, r, _)| largest > r) {
                self.records.push((f, largest, line));
            }
        }
        for k in 1..list.len() - 1 {
            self.triangles.push([list[0], list[k], list[k + 1]]);
        }
        Ok(())
    }

    /// Once the vertices are counted: the first face that names a vertex the file does not
    /// have, or is wrong otherwise, if any (every face recorded came before the wrong one).
    fn check(&mut self, vertices: usize) -> Result<(), MeshError> {
        let missing = self
            .records
            .iter()
            .find(|&&(_, i, _)| i as usize >= vertices)
            .map(|&(f, i, line)| MeshError {
                line,
                ..missing_vertex(f, i, vertices)
            });
        match missing.or_else(|| self.wrong.take()) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

/// Face `f` names vertex `bad` of a file of `vertices`.
fn missing_vertex(f: usize, bad: u32, vertices: usize) -> MeshError {
    MeshError::new(format!(
        "face {f} names vertex {bad}; the file has {vertices} (counted from 0)"
    ))
}

/// Face `f` names `bad`, which is no vertex's number in any file (negative, or past u32).
fn no_vertex(f: usize, bad: i64) -> MeshError {
    MeshError::new(format!(
        "face {f} names vertex {bad}, not a vertex's number (counted from 0)"
    ))
}

/// Read element `def`'s entries one by one, handing each to `each` with its number and, in an
/// ASCII file, its line: nothing of the element is held but what `each` keeps (a scanned mesh
/// has millions of entries). `line` is the line the next entry starts on; a binary file's
/// entries have none, and its errors name none.
fn each_entry<E: ply_rs_bw::ply::PropertyAccess, R: std::io::BufRead>(
    reader: &mut R,
    header: &ply_rs_bw::ply::Header,
    def: &ply_rs_bw::ply::ElementDef,
    line: &mut usize,
    mut each: impl FnMut(usize, E, Option<usize>) -> Result<(), MeshError>,
) -> Result<(), MeshError> {
    use ply_rs_bw::ply::Encoding;
    let parser = ply_rs_bw::parser::Parser::<E>::new();
    let ascii = matches!(header.encoding, Encoding::Ascii);
    let mut text = String::new();
    for i in 0..def.count {
        let at = ascii.then_some(*line);
        let ended = || MeshError {
            line: at,
            message: format!(
                "not a readable PLY file: it ends in element `{}` after {i} of its {} entries",
                crate::text::shown(&def.name),
                def.count
            ),
        };
        let entry = match header.encoding {
            Encoding::Ascii => {
                text.clear();
                let read = reader.read_line(&mut text).map_err(|e| MeshError {
                    line: at,
                    message: format!("cannot read it: {e}"),
                })?;
                if read == 0 {
                    return Err(ended());
                }
                parser.read_ascii_element(&text, def)
            }
            Encoding::BinaryLittleEndian => parser.read_little_endian_element(reader, def),
            Encoding::BinaryBigEndian => parser.read_big_endian_element(reader, def),
        };
        let entry = match entry {
            Ok(entry) => entry,
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Err(ended()),
            Err(e) => {
                let mut message = ply_message(&e);
                // Not every parser error quotes its line (a number out of its type's range).
                if ascii && !message.contains(LINE_READS) {
                    message.push_str(&line_reads(&text));
                }
                return Err(MeshError { line: at, message });
            }
        };
        each(i, entry, at).map_err(|e| MeshError {
            line: e.line.or(at),
            ..e
        })?;
        *line += 1;
    }
    Ok(())
}

/// A PLY parser's error in this project's words: its message's first line, and the line of
/// the file it read (once, cut short, its control characters escaped), without the parser's
/// own dump of its state.
fn ply_message(e: &ply_rs_bw::parser::ParseError) -> String {
    let text = e.to_string();
    let mut parts = text.split("\n\t");
    let first = parts.next().unwrap_or_default();
    // "Line N: " is the parser's; the line number goes into the error's place instead.
    let first = match first.split_once(": ") {
        Some((l, rest)) if l.starts_with("Line ") => rest,
        _ => first,
    };
    let mut message = format!("not a readable PLY file: {}", crate::text::shown(first));
    if let Some(line) = parts.find_map(|p| p.strip_prefix("String: ")) {
        message.push_str(&line_reads(line.trim_matches('\'')));
    }
    message
}

/// How an error quotes the line of the file it read.
const LINE_READS: &str = " (the line reads `";

/// `LINE_READS` with `line` (cut short, its control characters escaped, as `text::shown`).
fn line_reads(line: &str) -> String {
    format!("{LINE_READS}{}`)", crate::text::shown(line.trim_end()))
}

/// Refuse a PLY header whose elements the file cannot hold: an element without properties
/// (nothing to read, any count), or more entries than the bytes after the header could hold at
/// the fewest bytes an entry takes (a property's bytes in a binary file; a number and a
/// separator, two bytes, in ASCII). Checked before anything is read or allocated: a header of
/// 130 bytes claiming four billion vertices would otherwise grow until the machine refuses.
fn check_counts(header: &ply_rs_bw::ply::Header, size: u64) -> Result<(), MeshError> {
    use ply_rs_bw::ply::{Encoding, PropertyType, ScalarType};
    let bytes = |t: &ScalarType| match t {
        ScalarType::Char | ScalarType::UChar => 1u64,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    };
    let ascii = matches!(header.encoding, Encoding::Ascii);
    for (name, def) in &header.elements {
        let name = crate::text::shown(name);
        if def.properties.is_empty() {
            if def.count > 0 {
                return Err(MeshError::new(format!(
                    "element `{name}` has {} entries and no properties: there is nothing to read in it",
                    def.count
                )));
            }
            continue;
        }
        let least: u64 = def
            .properties
            .values()
            .map(|p| match (&p.data_type, ascii) {
                (_, true) => 2,
                (PropertyType::Scalar(t), false) => bytes(t),
                (PropertyType::List(index, _), false) => bytes(index),
            })
            .sum();
        let need = (def.count as u64).saturating_mul(least);
        if need > size {
            return Err(MeshError::new(format!(
                "element `{name}` claims {} entries of at least {least} bytes each, more than the file's {size} bytes hold",
                def.count
            )));
        }
    }
    Ok(())
}

pub(super) fn read_ply(path: &Path) -> Result<MeshData, MeshError> {
    use ply_rs_bw::parser::{Parser, Reader};
    let file =
        std::fs::File::open(path).map_err(|e| MeshError::new(format!("cannot read it: {e}")))?;
    let size = file.metadata().map(|m| m.len()).unwrap_or(0);
    let unreadable = |e: ply_rs_bw::parser::ParseError| MeshError {
        line: e.line(),
        message: ply_message(&e),
    };
    let mut reader = Reader::new(std::io::BufReader::with_capacity(1 << 20, file));
    let header = Parser::<PlySkip>::new()
        .read_header(&mut reader)
        .map_err(unreadable)?;
    check_counts(&header, size)?;
    // The line of the first entry (the parser counts the one after the header's last).
    let mut line = reader.line();
    let mut reader = reader.into_inner();
    let (mut vertices, mut faces) = (None::<Vertices>, None::<Faces>);
    // Elements are read in the header's order, each entry straight into the buffers it ends
    // in: the entries as read are never held.
    for (name, def) in &header.elements {
        match name.as_str() {
            "vertex" => {
                let mut v = Vertices::with_capacity(def.count);
                each_entry(&mut reader, &header, def, &mut line, |i, e, _| v.push(i, e))?;
                vertices = Some(v);
            }
            "face" => {
                let mut f = Faces::default();
                f.triangles.reserve(def.count);
                let n = vertices.as_ref().map(|v| v.positions.len());
                each_entry(&mut reader, &header, def, &mut line, |i, e, at| {
                    f.push(i, e, n, at)
                })?;
                faces = Some(f);
            }
            _ => each_entry(&mut reader, &header, def, &mut line, |_, PlySkip, _| Ok(()))?,
        }
    }
    let vertices = vertices.ok_or_else(|| MeshError::new("it has no `vertex` element"))?;
    let mut faces = faces.ok_or_else(|| MeshError::new("it has no `face` element"))?;
    faces.check(vertices.positions.len())?;
    let mut mesh = MeshData {
        positions: vertices.positions,
        triangles: faces.triangles,
        ..Default::default()
    };
    if let Some(n) = vertices.normals {
        let at = |t: &[u32; 3]| t.map(|i| n[i as usize]);
        mesh.normals = Some(mesh.triangles.iter().map(at).collect());
    }
    if let Some(uv) = vertices.uvs {
        let at = |t: &[u32; 3]| t.map(|i| uv[i as usize]);
        mesh.uvs = Some(mesh.triangles.iter().map(at).collect());
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::super::{read, MeshData, MeshError};
    use glam::DVec3;

    /// `bytes` written as a PLY file and read.
    fn read_bytes(name: &str, bytes: &[u8]) -> Result<MeshData, MeshError> {
        let dir =
            std::env::temp_dir().join(format!("rest-embree-ply-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("t.ply");
        std::fs::write(&p, bytes).unwrap();
        let m = read(&p);
        std::fs::remove_dir_all(&dir).unwrap();
        m
    }

    /// Why `text`, written as a PLY file, is refused.
    fn refused(name: &str, text: &str) -> MeshError {
        read_bytes(name, text.as_bytes()).unwrap_err()
    }

    /// Nine lines: the first vertex is line 10, the first face line 14.
    const HEADER: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
    const VERTICES: &str = "0 0 0\n1 0 0\n0 1 0\n1 1 0\n";

    /// Each entry is read into the mesh as it comes: polygons split into fans, normals kept
    /// where every vertex has them, and what is wrong named with its entry's line.
    #[test]
    fn ply_entries_are_read_one_by_one() {
        let m = read_bytes(
            "fan",
            format!("{HEADER}{VERTICES}4 0 1 3 2\n3 1 3 2\n").as_bytes(),
        )
        .unwrap();
        assert_eq!(m.triangles, [[0, 1, 3], [0, 3, 2], [1, 3, 2]]);
        assert_eq!(m.positions[3], DVec3::new(1.0, 1.0, 0.0));
        assert_eq!((m.normals, m.uvs), (None, None));

        let bad = format!("{HEADER}0 0 0\n1 x 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3 2\n");
        let e = refused("number", &bad);
        assert_eq!(e.line, Some(11), "{}", e.message);
        assert!(e.message.contains("`1 x 0`"), "{}", e.message);
        let e = refused("range", &format!("{HEADER}{VERTICES}3 0 1 2\n3 1 7 2\n"));
        assert_eq!(e.line, Some(15));
        assert_eq!(
            e.message,
            "face 1 names vertex 7; the file has 4 (counted from 0)"
        );
        let e = refused(
            "negative",
            &format!("{HEADER}{VERTICES}3 0 1 2\n3 1 -3 2\n"),
        );
        assert_eq!(
            e.message,
            "face 1 names vertex -3, not a vertex's number (counted from 0)"
        );
        // A number its type does not hold: the line is quoted all the same.
        let uint = HEADER.replace("uchar int", "uchar uint");
        let e = refused("uint", &format!("{uint}{VERTICES}3 0 1 2\n3 0 -1 2\n"));
        assert_eq!(e.line, Some(15));
        assert!(
            e.message.contains("(the line reads `3 0 -1 2`)"),
            "{}",
            e.message
        );
        let e = refused("short", &format!("{HEADER}0 0 0\n1 0 0\n"));
        assert_eq!(e.line, Some(12));
        assert!(
            e.message
                .contains("ends in element `vertex` after 2 of its 4 entries"),
            "{}",
            e.message
        );

        // Faces before the vertices: checked once the vertices are counted, naming the first
        // face that names a vertex the file does not have.
        let faces_first = "ply\nformat ascii 1.0\nelement face 3\nproperty list uchar int vertex_indices\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
        let missing = "face 1 names vertex 5; the file has 4 (counted from 0)";
        for (name, faces, why) in [
            ("first", "3 0 1 3\n3 1 5 2\n3 0 9 2\n", missing),
            // A face of two corners after it: face 1 is still the one named.
            ("first-two", "3 0 1 3\n3 1 5 2\n2 0 1\n", missing),
            // And the two corners named where no face before names a missing vertex.
            (
                "first-two-only",
                "3 0 1 3\n2 0 1\n3 1 5 2\n",
                "face 1 has 2 corners; a face needs 3 or more",
            ),
            (
                "first-negative",
                "3 0 1 3\n3 1 -1 2\n3 0 1 2\n",
                "face 1 names vertex -1, not a vertex's number (counted from 0)",
            ),
        ] {
            let e = refused(name, &format!("{faces_first}{faces}{VERTICES}"));
            assert_eq!((e.line, e.message.as_str()), (Some(11), why), "{name}");
        }
        let m = read_bytes(
            "first-ok",
            format!("{faces_first}3 0 1 3\n3 1 3 2\n4 0 1 3 2\n{VERTICES}").as_bytes(),
        )
        .unwrap();
        assert_eq!(m.triangles.len(), 4);

        let normals = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0 2\n1 0 0 0 0 1\n0 1 0 1 0 0\n3 0 1 2\n";
        let m = read_bytes("normals", normals.as_bytes()).unwrap();
        assert_eq!(m.normals, Some(vec![[DVec3::Z, DVec3::Z, DVec3::X]]));

        // Binary, whole and cut short.
        let mut bin = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n".to_vec();
        for x in [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.5] {
            bin.extend_from_slice(&x.to_le_bytes());
        }
        bin.push(3);
        for i in [0i32, 1, 2] {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        let m = read_bytes("binary", &bin).unwrap();
        assert_eq!(m.triangles, [[0, 1, 2]]);
        assert_eq!(m.positions[2], DVec3::new(0.0, 1.0, 0.5));
        let e = read_bytes("cut", &bin[..bin.len() - 5]).unwrap_err();
        assert_eq!(e.line, None, "a binary file has no lines");
        assert!(
            e.message
                .contains("ends in element `face` after 0 of its 1 entries"),
            "{}",
            e.message
        );
    }
}
