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

/// A PLY file's vertices: positions, and normals and texture coordinates where every vertex
/// has them.
type VertexData = (Vec<DVec3>, Option<Vec<DVec3>>, Option<Vec<[f64; 2]>>);

fn vertex_data(vertices: Vec<PlyVertex>) -> Result<VertexData, MeshError> {
    let mut positions = Vec::with_capacity(vertices.len());
    for (i, v) in vertices.iter().enumerate() {
        if let Some(k) = (0..3).find(|&k| !v.has(1 << k)) {
            return Err(MeshError::new(format!(
                "vertex {i} has no number `{}`",
                ["x", "y", "z"][k]
            )));
        }
        positions.push(DVec3::new(v.values[0], v.values[1], v.values[2]));
    }
    let any = !vertices.is_empty();
    for (i, v) in vertices.iter().enumerate() {
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
    }
    let normals = (any && vertices.iter().all(|v| v.has(0b111_000))).then(|| {
        let n = |v: &PlyVertex| DVec3::new(v.values[3], v.values[4], v.values[5]);
        vertices.iter().map(|v| n(v).normalize_or_zero()).collect()
    });
    let uvs = (any && vertices.iter().all(|v| v.has(0b1100_0000))).then(|| {
        vertices
            .iter()
            .map(|v| [v.values[6], v.values[7]])
            .collect()
    });
    Ok((positions, normals, uvs))
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
        let line = line.trim_matches('\'').trim_end();
        message.push_str(&format!(" (the line reads `{}`)", crate::text::shown(line)));
    }
    message
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
    let (mut vertices, mut faces) = (None, None);
    // Elements are read in the header's order, each by the type that keeps what it needs.
    for (name, def) in &header.elements {
        match name.as_str() {
            // Made into positions (and normals, texture coordinates) at once, so that the
            // elements as read are freed before the faces are read.
            "vertex" => {
                vertices = Some(vertex_data(
                    Parser::<PlyVertex>::new()
                        .read_payload_for_element(&mut reader, def, &header)
                        .map_err(unreadable)?,
                )?)
            }
            "face" => {
                faces = Some(
                    Parser::<PlyFace>::new()
                        .read_payload_for_element(&mut reader, def, &header)
                        .map_err(unreadable)?,
                )
            }
            _ => {
                Parser::<PlySkip>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(unreadable)?;
            }
        }
    }
    let (positions, vertex_normals, vertex_uvs) =
        vertices.ok_or_else(|| MeshError::new("it has no `vertex` element"))?;
    let mut mesh = MeshData {
        positions,
        ..Default::default()
    };
    let faces = faces.ok_or_else(|| MeshError::new("it has no `face` element"))?;
    let n = mesh.positions.len() as i64;
    mesh.triangles.reserve(faces.len());
    for (f, face) in faces.iter().enumerate() {
        if !face.given {
            return Err(MeshError::new(format!(
                "face {f} has no integer list `vertex_indices` (or `vertex_index`)"
            )));
        }
        let list = &face.indices;
        if let Some(bad) = face.out_of_range.or_else(|| {
            list.iter()
                .find(|&&i| i64::from(i) >= n)
                .map(|&i| i64::from(i))
        }) {
            return Err(MeshError::new(format!(
                "face {f} names vertex {bad}; the file has {n} (counted from 0)"
            )));
        }
        if list.len() < 3 {
            return Err(MeshError::new(format!(
                "face {f} has {} corners; a face needs 3 or more",
                list.len()
            )));
        }
        for k in 1..list.len() - 1 {
            mesh.triangles.push([list[0], list[k], list[k + 1]]);
        }
    }
    drop(faces);
    if let Some(n) = vertex_normals {
        let at = |t: &[u32; 3]| t.map(|i| n[i as usize]);
        mesh.normals = Some(mesh.triangles.iter().map(at).collect());
    }
    if let Some(uv) = vertex_uvs {
        let at = |t: &[u32; 3]| t.map(|i| uv[i as usize]);
        mesh.uvs = Some(mesh.triangles.iter().map(at).collect());
    }
    Ok(mesh)
}
