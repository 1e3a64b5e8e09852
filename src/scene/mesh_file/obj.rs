//! Wavefront OBJ, through the `tobj` crate: its statements checked line by line first (so an
//! error names its line), then its vertices, normals, texture coordinates and `usemtl` parts.

use super::{MeshData, MeshError, NO_MATERIAL};
use glam::DVec3;
use std::path::Path;

/// The name under which the names of an OBJ's `usemtl` statements are handed to tobj as a
/// material library of their own (see `read_obj`).
const USEMTL_NAMES: &str = "rest-embree-usemtl-names.mtl";

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

pub(super) fn read_obj(path: &Path) -> Result<MeshData, MeshError> {
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

#[cfg(test)]
mod tests {
    use super::super::read;
    use glam::DVec3;

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
