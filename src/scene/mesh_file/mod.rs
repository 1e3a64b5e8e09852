//! Triangle meshes read from files: Wavefront OBJ (through the `tobj` crate, obj.rs), PLY,
//! ASCII or binary (through `ply-rs-bw`, ply.rs), and STL, ASCII or binary (through `stl_io`,
//! here). Polygons are split into fans of triangles. What goes wrong is said with the file
//! and, where there is one, its line.

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
    super::inputs::note(path);
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

mod obj;
mod ply;

use obj::read_obj;
use ply::read_ply;

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
