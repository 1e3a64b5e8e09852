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
}

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
pub const EXTENSIONS: [&str; 3] = ["obj", "ply", "stl"];

/// Bytes of memory reading takes per byte of file, at most (text to positions, indices and the
/// readers' own tables), for the check against the memory limit before reading.
pub const BYTES_PER_FILE_BYTE: u64 = 24;

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

fn read_obj(path: &Path) -> Result<MeshData, MeshError> {
    let file =
        std::fs::File::open(path).map_err(|e| MeshError::new(format!("cannot read it: {e}")))?;
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // Materials (`mtllib`) are not read: objects take the scene's materials.
    let loaded = tobj::load_obj_buf(&mut std::io::BufReader::new(file), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    });
    let models = match loaded {
        Ok((models, _materials)) => models,
        Err(e) => return Err(obj_error(path, &e)),
    };
    let mut mesh = MeshData::default();
    let every = |f: &dyn Fn(&tobj::Mesh) -> bool| models.iter().all(|m| f(&m.mesh));
    let with_normals =
        every(&|m| !m.normals.is_empty() && m.normal_indices.len() == m.indices.len());
    let with_uvs =
        every(&|m| !m.texcoords.is_empty() && m.texcoord_indices.len() == m.indices.len());
    let (mut normals, mut uvs) = (Vec::new(), Vec::new());
    for m in &models {
        let corner = |list: &[f64], at: u32, n: usize| -> Option<Vec<f64>> {
            list.get(at as usize * n..at as usize * n + n)
                .map(<[f64]>::to_vec)
        };
        if with_normals {
            for t in m.mesh.normal_indices.chunks_exact(3) {
                let c = [t[0], t[1], t[2]]
                    .map(|i| corner(&m.mesh.normals, i, 3).map(|v| DVec3::new(v[0], v[1], v[2])));
                let [Some(a), Some(b), Some(c)] = c else {
                    return Err(MeshError::new("a normal index is out of range"));
                };
                normals.push([a, b, c].map(|n| n.normalize_or_zero()));
            }
        }
        if with_uvs {
            for t in m.mesh.texcoord_indices.chunks_exact(3) {
                let c = [t[0], t[1], t[2]]
                    .map(|i| corner(&m.mesh.texcoords, i, 2).map(|v| [v[0], v[1]]));
                let [Some(a), Some(b), Some(c)] = c else {
                    return Err(MeshError::new("a texture coordinate index is out of range"));
                };
                uvs.push([a, b, c]);
            }
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
    }
    mesh.normals = with_normals.then_some(normals);
    mesh.uvs = with_uvs.then_some(uvs);
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
            return MeshError::at(n + 1, format!("{what}: `{line}`"));
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
    })
}

fn read_ply(path: &Path) -> Result<MeshData, MeshError> {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Property};
    let file =
        std::fs::File::open(path).map_err(|e| MeshError::new(format!("cannot read it: {e}")))?;
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut std::io::BufReader::new(file))
        .map_err(|e| MeshError {
            line: e.line(),
            message: format!("not a readable PLY file: {e}"),
        })?;
    let number = |p: &Property| -> Option<f64> {
        Some(match *p {
            Property::Char(v) => v.into(),
            Property::UChar(v) => v.into(),
            Property::Short(v) => v.into(),
            Property::UShort(v) => v.into(),
            Property::Int(v) => v.into(),
            Property::UInt(v) => v.into(),
            Property::Float(v) => v.into(),
            Property::Double(v) => v,
            _ => return None,
        })
    };
    let indices = |p: &Property| -> Option<Vec<i64>> {
        Some(match p {
            Property::ListChar(v) => v.iter().map(|&i| i.into()).collect(),
            Property::ListUChar(v) => v.iter().map(|&i| i.into()).collect(),
            Property::ListShort(v) => v.iter().map(|&i| i.into()).collect(),
            Property::ListUShort(v) => v.iter().map(|&i| i.into()).collect(),
            Property::ListInt(v) => v.iter().map(|&i| i.into()).collect(),
            Property::ListUInt(v) => v.iter().map(|&i| i.into()).collect(),
            _ => return None,
        })
    };
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| MeshError::new("it has no `vertex` element"))?;
    let mut mesh = MeshData::default();
    let (mut vertex_normals, mut vertex_uvs) = (Vec::new(), Vec::new());
    let uv_names = [["u", "v"], ["s", "t"], ["texture_u", "texture_v"]];
    for (i, v) in vertices.iter().enumerate() {
        let coordinate = |k: &str| {
            v.get(k)
                .and_then(number)
                .ok_or_else(|| MeshError::new(format!("vertex {i} has no number `{k}`")))
        };
        mesh.positions.push(DVec3::new(
            coordinate("x")?,
            coordinate("y")?,
            coordinate("z")?,
        ));
        let get = |k: &str| v.get(k).and_then(number);
        if let (Some(x), Some(y), Some(z)) = (get("nx"), get("ny"), get("nz")) {
            vertex_normals.push(DVec3::new(x, y, z).normalize_or_zero());
        }
        if let Some(uv) = uv_names.iter().find_map(|[a, b]| Some([get(a)?, get(b)?])) {
            vertex_uvs.push(uv);
        }
    }
    let n_all = vertex_normals.len() == mesh.positions.len();
    let uv_all = vertex_uvs.len() == mesh.positions.len();
    let faces = ply
        .payload
        .get("face")
        .ok_or_else(|| MeshError::new("it has no `face` element"))?;
    let n = mesh.positions.len() as i64;
    for (f, face) in faces.iter().enumerate() {
        let list = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .and_then(indices)
            .ok_or_else(|| {
                MeshError::new(format!(
                    "face {f} has no integer list `vertex_indices` (or `vertex_index`)"
                ))
            })?;
        if list.len() < 3 {
            return Err(MeshError::new(format!(
                "face {f} has {} corners; a face needs 3 or more",
                list.len()
            )));
        }
        if let Some(bad) = list.iter().find(|&&i| i < 0 || i >= n) {
            return Err(MeshError::new(format!(
                "face {f} names vertex {bad}; the file has {n} (counted from 0)"
            )));
        }
        for k in 1..list.len() - 1 {
            mesh.triangles
                .push([list[0] as u32, list[k] as u32, list[k + 1] as u32]);
        }
    }
    let corners = |t: &[u32; 3]| t.map(|i| i as usize);
    if n_all {
        mesh.normals = Some(
            mesh.triangles
                .iter()
                .map(|t| corners(t).map(|i| vertex_normals[i]))
                .collect(),
        );
    }
    if uv_all {
        mesh.uvs = Some(
            mesh.triangles
                .iter()
                .map(|t| corners(t).map(|i| vertex_uvs[i]))
                .collect(),
        );
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
    }
}
