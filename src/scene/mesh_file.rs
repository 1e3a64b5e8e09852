//! Triangle meshes read from files: Wavefront OBJ (through the `tobj` crate), PLY, ASCII or
//! binary (through `ply-rs-bw`), and STL, ASCII or binary (through `stl_io`). Polygons are split into fans of triangles. What goes wrong is
//! said with the file and, where there is one, its line.

use glam::DVec3;
use std::path::Path;

/// A mesh as read: its vertices, and its triangles as indices into them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions, in the file's coordinates.
    pub positions: Vec<DVec3>,
    /// Triangles, counter-clockwise seen from the front as the file gives them.
    pub triangles: Vec<[u32; 3]>,
    /// Each triangle's corner normals, where the file gives normals for every corner.
    pub normals: Option<Vec<[DVec3; 3]>>,
    /// Each triangle's corner texture coordinates, where the file gives them for every corner.
    pub uvs: Option<Vec<[[f64; 2]; 3]>>,
    /// The material names the file uses (OBJ's `usemtl`), in the order first used.
    pub materials: Vec<String>,
    /// Each triangle's material (an index into `materials`, or [`NO_MATERIAL`]); empty where
    /// the file names none.
    pub material_of: Vec<u32>,
}

/// A triangle's material where the file gives it none.
pub(crate) const NO_MATERIAL: u32 = u32::MAX;

/// The name under which the names of an OBJ's `usemtl` statements are handed to tobj as a
/// material library of their own (see `read_obj`).
const USEMTL_NAMES: &str = "rest-embree-usemtl-names.mtl";

/// Why a mesh file could not be read: the message, and the 1-based line it concerns, if any.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshError {
    pub line: Option<usize>,
    pub message: String,
}

impl MeshError {
    fn new(message: impl Into<String>) -> MeshError {
        MeshError {
            line: None,
            message: message.into(),
        }
    }

    fn at(line: usize, message: impl Into<String>) -> MeshError {
        MeshError {
            line: Some(line),
            message: message.into(),
        }
    }
}

/// The formats, by extension.
pub(crate) const EXTENSIONS: [&str; 3] = ["obj", "ply", "stl"];

/// Bytes of memory reading takes per byte of file, at most (text to positions, indices and the
/// readers' own tables), for the check against the memory limit before reading.
pub(crate) const BYTES_PER_FILE_BYTE: u64 = 24;

/// Read the mesh at `path`, by its extension.
pub fn read(path: &Path) -> Result<MeshData, MeshError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let meta =
        std::fs::metadata(path).map_err(|e| MeshError::new(format!("cannot read it: {e}")))?;
    if !meta.is_file() {
        return Err(MeshError::new("it is not a regular file"));
    }
    let mesh = match ext.as_deref() {
        Some("obj") => read_obj(path)?,
        Some("ply") => read_ply(path)?,
        Some("stl") => read_stl(path)?,
        _ => {
            return Err(MeshError::new(format!(
                "cannot tell its format: the name must end in {}",
                EXTENSIONS.map(|e| format!(".{e}")).join(", ")
            )))
        }
    };
    if mesh.triangles.is_empty() {
        return Err(MeshError::new("it has no triangles"));
    }
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(MeshError::new(format!(
            "vertex {} is not finite ({})",
            i + 1,
            mesh.positions[i]
        )));
    }
    Ok(mesh)
}

/// The numbers of an OBJ statement's rest (`v x y z`), where each parses: Some(values).
fn obj_numbers(rest: &str) -> Option<Vec<f64>> {
    rest.split_whitespace().map(|x| x.parse().ok()).collect()
}

/// What tobj accepts of an OBJ file but this renderer must not, found line by line with the
/// line named: numbers that are not finite in `v`, `vn` and `vt`; a face's index 0 (OBJ
/// counts from 1) or an index past the positions, normals or texture coordinates given before
/// it.
fn check_obj_lines(text: &str) -> Result<(), MeshError> {
    let (mut v, mut vn, mut vt) = (0i64, 0i64, 0i64);
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        let (head, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        let shown = || crate::text::shown(line);
        match head {
            "v" | "vn" | "vt" => {
                if let Some(x) =
                    obj_numbers(rest).and_then(|xs| xs.into_iter().find(|x| !x.is_finite()))
                {
                    return Err(MeshError::at(
                        n + 1,
                        format!("`{}`: {x} is not a finite number", shown()),
                    ));
                }
                match head {
                    "v" => v += 1,
                    "vn" => vn += 1,
                    _ => vt += 1,
                }
            }
            "f" => {
                for corner in rest.split_whitespace() {
                    for (k, (what, count)) in
                        [("vertex", v), ("texture coordinate", vt), ("normal", vn)]
                            .into_iter()
                            .enumerate()
                    {
                        let Some(i) = corner.split('/').nth(k).filter(|x| !x.is_empty()) else {
                            continue;
                        };
                        let Ok(i) = i.parse::<i64>() else {
                            continue;
                        };
                        if i == 0 {
                            return Err(MeshError::at(
                                n + 1,
                                format!("`{}`: {what} index 0 (OBJ counts from 1)", shown()),
                            ));
                        }
                        if i > count || -i > count {
                            return Err(MeshError::at(
                                n + 1,
                                format!(
                                    "`{}` names {what} {i}; the file gives {count} before this line",
                                    shown()
                                ),
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

fn read_obj(path: &Path) -> Result<MeshData, MeshError> {
    let mut bytes =
        std::fs::read(path).map_err(|e| MeshError::new(format!("cannot read it: {e}")))?;
    // A byte-order mark before the first statement is no part of it.
    if bytes.starts_with("\u{feff}".as_bytes()) {
        bytes.drain(..3);
    }
    check_obj_lines(&String::from_utf8_lossy(&bytes))?;
    // tobj keeps a triangle's `usemtl` only where a material library defines that name, and
    // the scene maps names to its own materials without reading the file's library: the
    // names used are collected first and given to tobj as a library of their own.
    let mut names: Vec<String> = Vec::new();
    // Which triangles' corners carry a normal and texture coordinates of their own: where a
    // file has normals, tobj gives a face without them its neighbour's, which would shade it
    // wrongly. A face of k corners is k - 2 triangles, in the file's order.
    let mut given: Vec<(bool, bool)> = Vec::new();
    for line in bytes.split(|&b| b == b'\n') {
        let line = String::from_utf8_lossy(line);
        match line.trim().split_once(char::is_whitespace) {
            // The name as tobj reads it: after the line's first space, trimmed.
            Some(("usemtl", _)) => {
                let name = line.split_once(' ').map_or("", |x| x.1).trim().to_string();
                if !name.is_empty() && !names.contains(&name) {
                    names.push(name);
                }
            }
            Some(("f", rest)) => {
                let corners: Vec<&str> = rest.split_whitespace().collect();
                let part = |c: &str, k: usize| c.split('/').nth(k).is_some_and(|x| !x.is_empty());
                let flags = (
                    corners.iter().all(|c| part(c, 2)),
                    corners.iter().all(|c| part(c, 1)),
                );
                given.extend(std::iter::repeat_n(flags, corners.len().saturating_sub(2)));
            }
            _ => {}
        }
    }
    use std::io::Read;
    let mut source = std::io::Cursor::new(format!("mtllib {USEMTL_NAMES}\n").into_bytes())
        .chain(std::io::Cursor::new(bytes));
    let library = || {
        let materials: Vec<tobj::Material> = names
            .iter()
            .map(|n| tobj::Material {
                name: n.clone(),
                ..Default::default()
            })
            .collect();
        let map = names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.clone(), i))
            .collect();
        Ok((materials, map))
    };
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // The file's own libraries (`mtllib`) are not read: objects take the scene's materials.
    let loaded = tobj::load_obj_buf(&mut std::io::BufReader::new(&mut source), &options, |p| {
        if p.file_name().and_then(|n| n.to_str()) == Some(USEMTL_NAMES) {
            library()
        } else {
            Err(tobj::LoadError::OpenFileFailed)
        }
    });
    let models = match loaded {
        Ok((models, _materials)) => models,
        Err(e) => return Err(obj_error(path, &e)),
    };
    let mut mesh = MeshData::default();
    // Normals and texture coordinates where some model gives them for every corner; a model
    // without them gets its flat face normals (the shading of a mesh without normals) and
    // texture coordinates (0, 0).
    let complete = |list: &[f64], idx: &[u32], m: &tobj::Mesh| {
        !list.is_empty() && idx.len() == m.indices.len()
    };
    let with_normals = models
        .iter()
        .any(|m| complete(&m.mesh.normals, &m.mesh.normal_indices, &m.mesh));
    let with_uvs = models
        .iter()
        .any(|m| complete(&m.mesh.texcoords, &m.mesh.texcoord_indices, &m.mesh));
    let (mut normals, mut uvs) = (Vec::new(), Vec::new());
    for m in &models {
        let corner = |list: &[f64], at: u32, n: usize| -> Option<Vec<f64>> {
            list.get(at as usize * n..at as usize * n + n)
                .map(<[f64]>::to_vec)
        };
        let position = |i: u32| {
            corner(&m.mesh.positions, i, 3).map_or(DVec3::ZERO, |v| DVec3::new(v[0], v[1], v[2]))
        };
        if with_normals && complete(&m.mesh.normals, &m.mesh.normal_indices, &m.mesh) {
            for t in m.mesh.normal_indices.chunks_exact(3) {
                let c = [t[0], t[1], t[2]]
                    .map(|i| corner(&m.mesh.normals, i, 3).map(|v| DVec3::new(v[0], v[1], v[2])));
                let [Some(a), Some(b), Some(c)] = c else {
                    return Err(MeshError::new("a normal index is out of range"));
                };
                normals.push([a, b, c].map(|n| n.normalize_or_zero()));
            }
        } else if with_normals {
            for t in m.mesh.indices.chunks_exact(3) {
                let [a, b, c] = [t[0], t[1], t[2]].map(position);
                normals.push([(b - a).cross(c - a).normalize_or_zero(); 3]);
            }
        }
        if with_uvs && complete(&m.mesh.texcoords, &m.mesh.texcoord_indices, &m.mesh) {
            for t in m.mesh.texcoord_indices.chunks_exact(3) {
                let c = [t[0], t[1], t[2]]
                    .map(|i| corner(&m.mesh.texcoords, i, 2).map(|v| [v[0], v[1]]));
                let [Some(a), Some(b), Some(c)] = c else {
                    return Err(MeshError::new("a texture coordinate index is out of range"));
                };
                uvs.push([a, b, c]);
            }
        } else if with_uvs {
            uvs.extend(m.mesh.indices.chunks_exact(3).map(|_| [[0.0; 2]; 3]));
        }
    }
    for m in models {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(
            m.mesh
                .positions
                .chunks_exact(3)
                .map(|p| DVec3::new(p[0], p[1], p[2])),
        );
        mesh.triangles.extend(
            m.mesh
                .indices
                .chunks_exact(3)
                .map(|t| [base + t[0], base + t[1], base + t[2]]),
        );
        if !names.is_empty() {
            let id = m.mesh.material_id.map_or(NO_MATERIAL, |i| i as u32);
            mesh.material_of.resize(mesh.triangles.len(), id);
        }
    }
    if given.len() == mesh.triangles.len() {
        for (k, &(has_normals, has_uvs)) in given.iter().enumerate() {
            if with_normals && !has_normals {
                let [a, b, c] = mesh.triangles[k].map(|i| mesh.positions[i as usize]);
                normals[k] = [(b - a).cross(c - a).normalize_or_zero(); 3];
            }
            if with_uvs && !has_uvs {
                uvs[k] = [[0.0; 2]; 3];
            }
        }
    }
    mesh.normals = with_normals.then_some(normals);
    mesh.uvs = with_uvs.then_some(uvs);
    mesh.materials = names;
    Ok(mesh)
}

/// tobj's error, with the line it concerns: tobj does not say, so the file is read again for
/// the first statement of the kind that failed that does not hold.
fn obj_error(path: &Path, e: &tobj::LoadError) -> MeshError {
    use tobj::LoadError as E;
    let what = e.to_string();
    let Ok(text) = std::fs::read_to_string(path) else {
        return MeshError::new(what);
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let floats = |rest: &str, counts: &[usize]| {
        let v: Vec<&str> = rest.split_whitespace().collect();
        counts.contains(&v.len()) && v.iter().all(|x| x.parse::<f64>().is_ok())
    };
    let mut vertices = 0i64;
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        let (head, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        let bad = match (head, e) {
            ("v", E::PositionParseError) => !floats(rest, &[3, 4, 6, 7]),
            ("vn", E::NormalParseError) => !floats(rest, &[3]),
            ("vt", E::TexcoordParseError) => !floats(rest, &[1, 2, 3]),
            ("f", E::FaceParseError | E::InvalidPolygon) => {
                let corners: Vec<&str> = rest.split_whitespace().collect();
                corners.len() < 3
                    || corners.iter().any(|c| {
                        c.split('/')
                            .next()
                            .is_none_or(|i| i.parse::<i64>().map_or(true, |i| i == 0))
                    })
            }
            ("f", E::FaceVertexOutOfBounds) => rest.split_whitespace().any(|c| {
                c.split('/')
                    .next()
                    .and_then(|i| i.parse::<i64>().ok())
                    .is_some_and(|i| i > vertices || -i > vertices)
            }),
            _ => false,
        };
        if head == "v" {
            vertices += 1;
        }
        if bad {
            return MeshError::at(n + 1, format!("{what}: `{}`", crate::text::shown(line)));
        }
    }
    MeshError::new(what)
}

/// An STL file (its facets' own normals are not used: STL's are per facet, which the
/// triangle's winding already gives).
fn read_stl(path: &Path) -> Result<MeshData, MeshError> {
    let file =
        std::fs::File::open(path).map_err(|e| MeshError::new(format!("cannot read it: {e}")))?;
    let stl = stl_io::read_stl(&mut std::io::BufReader::new(file))
        .map_err(|e| MeshError::new(format!("not a readable STL file: {e}")))?;
    let n = stl.vertices.len();
    let triangles = stl
        .faces
        .iter()
        .map(|f| {
            if f.vertices.iter().any(|&i| i >= n) {
                return Err(MeshError::new("a facet names a vertex it does not have"));
            }
            Ok(f.vertices.map(|i| i as u32))
        })
        .collect::<Result<_, _>>()?;
    Ok(MeshData {
        positions: stl
            .vertices
            .iter()
            .map(|v| DVec3::new(v[0].into(), v[1].into(), v[2].into()))
            .collect(),
        triangles,
        normals: None,
        uvs: None,
        ..Default::default()
    })
}

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

fn read_ply(path: &Path) -> Result<MeshData, MeshError> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_normals_and_uvs_reach_the_corners() {
        let dir = std::env::temp_dir().join(format!("rest-embree-objn-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("t.obj");
        std::fs::write(&p, "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 2\nvn 1 0 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1/1 2/2/2 3/3/3\n").unwrap();
        let m = read(&p).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(m.normals, Some(vec![[DVec3::Z, DVec3::Z, DVec3::X]]));
        assert_eq!(m.uvs, Some(vec![[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]]));
        // Normals without texture coordinates, on a quad.
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(&p, "v 0 0 0\nvn 0 0 1\nv 1 0 0\nvn 0 0 1\nv 1 1 0\nvn 0 0 1\nv 0 1 0\nvn 1 0 0\nf 1//1 2//2 3//3 4//4\n").unwrap();
        let m = read(&p).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(m.triangles.len(), 2);
        assert_eq!(m.uvs, None);
        assert_eq!(m.normals.map(|n| n.len()), Some(2));
        // A part with normals and texture coordinates beside one without (another usemtl):
        // the second gets its flat face normal and (0, 0), the first keeps its own.
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(&p, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 1 0 0\nvt 0.5 0.5\nusemtl a\nf 1/1/1 2/1/1 3/1/1\nusemtl b\nf 1 4 2\n").unwrap();
        let m = read(&p).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(
            m.normals,
            Some(vec![[DVec3::X; 3], [DVec3::Y; 3]]),
            "the flat normal of (0,0,0) (0,0,1) (1,0,0) is +y"
        );
        assert_eq!(m.uvs, Some(vec![[[0.5, 0.5]; 3], [[0.0, 0.0]; 3]]));
        assert_eq!(m.materials, ["a", "b"]);
        assert_eq!(m.material_of, [0, 1]);
    }
}
