//! Mesh files the scene places more than once, read and held once.
//!
//! A first pass over the scene (`SharedMeshes::scan`) counts the entries that place each mesh
//! file: `type = "mesh"` entries naming it by `file`, and `type = "instance"` entries naming
//! such an object by `of`. A file placed once is read and placed as it always was (its vertices
//! copied to their places); a file placed several times is read once, held in its own
//! coordinates, and each entry is a placement of it (`Implicit::Instance`): a thousand
//! placements of a mesh cost one mesh and a thousand placements, not a thousand meshes.
//!
//! So too a glTF file that several `type = "gltf"` entries place: it is read once, every mesh
//! in it held once (`Shared`), and each entry places those meshes where the file's nodes put
//! them; what each entry takes for itself (its materials, lights, cameras, and the copies a
//! node that is a group of its own holds) is cloned from the one reading.

use super::gltf_file::{GltfData, GltfError};
use super::reader::{SceneResult, Table};
use super::transform::Transform;
use crate::geometry::{Affine, Corners, Geometry, Implicit, IndexedMesh, MeshInstance};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The mesh files of a scene, and those read so far that are placed more than once.
#[derive(Default)]
pub(super) struct SharedMeshes {
    /// How many entries place each mesh file.
    uses: HashMap<PathBuf, usize>,
    /// The files of named mesh objects, by name (each file once): what an instance's `of`
    /// names. Names need not be unique across groups; an `of` naming meshes of two files is
    /// refused.
    named: HashMap<String, Vec<PathBuf>>,
    /// The names of meshes given inline, which an instance cannot place.
    inline: std::collections::HashSet<String>,
    /// Files placed more than once, read.
    read: HashMap<PathBuf, Arc<Shared>>,
    /// How many entries place each glTF file with each grouping (whether each top-level node
    /// is a group of its own), and how many of them are still to be read.
    gltf_uses: HashMap<(PathBuf, bool), (usize, usize)>,
    /// glTF files several entries place, read and kept for the entries still to come: the file
    /// with its meshes held once taken out.
    gltf_read: HashMap<(PathBuf, bool), (GltfData, Held)>,
    /// The meshes held once counted against the scene's limit so far (each once), kept alive
    /// here so that no later mesh can take the address one of them had.
    counted: HashMap<*const Shared, Arc<Shared>>,
}

/// A glTF file's meshes held once, by the file's mesh index.
pub(super) type Held = HashMap<usize, Arc<Shared>>;

/// A mesh file held once: its triangles in its own coordinates and, by runs of one of the
/// file's materials, its corner data, each shared by every placement.
pub(super) struct Shared {
    mesh: Arc<IndexedMesh>,
    /// (triangles, the file's material or `NO_MATERIAL`, corner data) of each run.
    runs: Vec<(u64, u32, Option<Arc<Corners>>)>,
    /// The material names the file uses.
    materials: Vec<String>,
}

/// The key a mesh file is known by: its path made absolute where it exists, so that
/// `rock.ply` and `./rock.ply` are one file.
fn key(path: PathBuf) -> PathBuf {
    std::fs::canonicalize(&path).unwrap_or(path)
}

impl SharedMeshes {
    /// Count the entries of `groups` that place each mesh file.
    pub fn scan(groups: &[Table]) -> SceneResult<SharedMeshes> {
        let mut s = SharedMeshes::default();
        let mut instances = Vec::new();
        for g in groups {
            for o in g.tables("object")? {
                match o.string("type")? {
                    Some("mesh") => {
                        let Some(file) = o.string("file")? else {
                            if let Some(name) = o.string("name")? {
                                s.inline.insert(name.to_string());
                            }
                            continue;
                        };
                        let path = key(o.path_beside(file));
                        *s.uses.entry(path.clone()).or_default() += 1;
                        if let Some(name) = o.string("name")? {
                            let files = s.named.entry(name.to_string()).or_default();
                            if !files.contains(&path) {
                                files.push(path);
                            }
                        }
                    }
                    Some("gltf") => {
                        if let Some(file) = o.string("file")? {
                            let split = o.string("groups")? == Some("nodes");
                            let slot = (key(o.path_beside(file)), split);
                            let uses = s.gltf_uses.entry(slot).or_default();
                            *uses = (uses.0 + 1, uses.1 + 1);
                        }
                    }
                    Some("instance") => {
                        if let Some(of) = o.string("of")? {
                            instances.push(of.to_string());
                        }
                    }
                    _ => {}
                }
            }
        }
        for of in instances {
            if let Some([path]) = s.named.get(&of).map(Vec::as_slice) {
                *s.uses.entry(path.clone()).or_default() += 1;
            }
        }
        Ok(s)
    }

    /// Whether the file `t`'s `file` names is placed more than once.
    pub fn is_shared(&self, t: &Table) -> SceneResult<bool> {
        let file = t.req_string("file")?;
        Ok(self
            .uses
            .get(&key(t.path_beside(file)))
            .is_some_and(|&n| n > 1))
    }

    /// The file the instance entry `t` places (its `of`: a named mesh object read from a file).
    pub fn file_of_instance(&self, t: &Table) -> SceneResult<PathBuf> {
        let of = t.req_string("of")?;
        let at = t.get("of").expect("read above");
        match self.named.get(of).map(Vec::as_slice) {
            Some([path]) => return Ok(path.clone()),
            Some(paths) => {
                let files: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
                return Err(t.error_at(
                    at,
                    "of",
                    format!("mesh objects of several files are named `{of}` ({}): give them names of their own", files.join(", ")),
                ));
            }
            None if self.inline.contains(of) => {
                return Err(t.error_at(
                    at,
                    "of",
                    format!("the mesh `{of}` is given inline (vertices, indices): an instance places a mesh read from a file"),
                ));
            }
            None => {}
        }
        Err({
            let mut known: Vec<&str> = self.named.keys().map(String::as_str).collect();
            known.sort_unstable();
            let known = if known.is_empty() {
                "the scene names none".to_string()
            } else {
                format!("named ones: {}", known.join(", "))
            };
            t.error_at(
                at,
                "of",
                format!("no mesh object is named `{of}`: an instance places a mesh read from a file (type = \"mesh\", file = ..., name = \"{of}\"); {known}"),
            )
        })
    }

    /// The mesh file at `path` as held once, read on first use by `read` (which checks it
    /// against the scene's limits); its triangles counted against the scene's once.
    pub fn get(
        &mut self,
        path: PathBuf,
        read: impl FnOnce() -> SceneResult<super::mesh_file::MeshData>,
    ) -> SceneResult<Arc<Shared>> {
        let path = key(path);
        if let Some(s) = self.read.get(&path) {
            return Ok(s.clone());
        }
        let shared = Arc::new(Shared::of(read()?));
        self.read.insert(path, shared.clone());
        Ok(shared)
    }
}

impl SharedMeshes {
    /// The glTF file at `path` as an entry takes it (`split_all`: each top-level node a group
    /// of its own), and its meshes that are held once: read here for a file one entry places;
    /// for one several entries place (with the same grouping), read on first use with every
    /// mesh held once, the same meshes given to every entry, and the reading kept until the
    /// last of them takes it.
    pub fn gltf(&mut self, path: &Path, split_all: bool) -> Result<(GltfData, Held), GltfError> {
        let slot = (key(path.to_path_buf()), split_all);
        let (several, left) = match self.gltf_uses.get_mut(&slot) {
            Some((all, left)) => {
                *left = left.saturating_sub(1);
                (*all > 1, *left)
            }
            None => (false, 0),
        };
        let hold = |mut data: GltfData| {
            let names: Vec<String> = data.materials.iter().map(|m| m.name.clone()).collect();
            let held: Held = std::mem::take(&mut data.shared)
                .into_iter()
                .map(|(k, mut m)| {
                    m.materials = names.clone();
                    (k, Arc::new(Shared::of(m)))
                })
                .collect();
            (data, held)
        };
        if !several {
            return Ok(hold(super::gltf_file::read(path, split_all, false)?));
        }
        let read = match self.gltf_read.remove(&slot) {
            Some(read) => read,
            None => hold(super::gltf_file::read(path, split_all, true)?),
        };
        if left > 0 {
            self.gltf_read
                .insert(slot, (read.0.clone(), read.1.clone()));
        }
        Ok(read)
    }

    /// Whether the held mesh `s` is counted against the scene's limit for the first time
    /// (it is then counted, once, however many entries and groups place it).
    pub fn first_count(&mut self, s: &Arc<Shared>) -> bool {
        self.counted.insert(Arc::as_ptr(s), s.clone()).is_none()
    }
}

impl Shared {
    /// The mesh `m` (in its own coordinates) held once.
    pub fn of(m: super::mesh_file::MeshData) -> Shared {
        use super::mesh_file::NO_MATERIAL;
        let n = m.triangles.len();
        let material_of = |i: usize| m.material_of.get(i).copied().unwrap_or(NO_MATERIAL);
        let mut runs = Vec::new();
        let mut start = 0;
        while start < n {
            let k = material_of(start);
            let end = (start + 1..n).find(|&i| material_of(i) != k).unwrap_or(n);
            let corners = (m.normals.is_some() || m.uvs.is_some()).then(|| {
                Arc::new(Corners {
                    normals: m.normals.as_ref().map(|v| v[start..end].to_vec()),
                    uvs: m.uvs.as_ref().map(|v| v[start..end].to_vec()),
                })
            });
            runs.push(((end - start) as u64, k, corners));
            start = end;
        }
        Shared {
            mesh: Arc::new(IndexedMesh::new(m.positions, m.triangles)),
            runs,
            materials: m.materials,
        }
    }

    /// How many triangles.
    pub fn len(&self) -> u64 {
        self.mesh.len()
    }

    /// The material names the file uses.
    pub fn materials(&self) -> &[String] {
        &self.materials
    }

    /// Place it in `geo` as object `id` by `transform` (none: as the file has it), the file's
    /// materials `chosen` (by index), those it names none `mat`.
    pub fn place(
        &self,
        id: u32,
        mat: u32,
        transform: Option<Transform>,
        chosen: &[u32],
        geo: &mut Geometry,
    ) -> crate::Result<()> {
        let place = match transform {
            Some(x) => Affine::rigid(x.scale, x.rotation, x.translate),
            None => Affine::IDENTITY,
        };
        self.place_at(id, mat, place, chosen, geo)
    }

    /// Place it in `geo` as object `id` by `place`, its materials as [`place`](Self::place)
    /// has them.
    pub fn place_at(
        &self,
        id: u32,
        mat: u32,
        place: Affine,
        chosen: &[u32],
        geo: &mut Geometry,
    ) -> crate::Result<()> {
        let runs: Vec<_> = self
            .runs
            .iter()
            .map(|(n, k, c)| {
                (
                    *n,
                    chosen.get(*k as usize).copied().unwrap_or(mat),
                    c.clone(),
                )
            })
            .collect();
        let shape = Implicit::Instance(Arc::new(MeshInstance::new(self.mesh.clone(), place)));
        geo.push_implicit_with(id, &runs, shape)
    }
}
