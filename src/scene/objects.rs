//! Objects of a velocity group: boxes, spheres, rods, meshes and the procedural lattice and bars,
//! read into rest-frame primitives within the scene's limits.

use super::procedural::{BarArray, Lattice};
use super::reader::{SceneResult, Table};
use crate::geometry::{Blocks, Implicit};
use crate::geometry::{Geometry, Primitive};
use glam::DVec3;
use std::collections::HashMap;

/// The most primitives one scene may hold (a guard against typos like `counts = [1000000, ...]`).
pub const MAX_PRIMITIVES: u64 = 200_000_000;

pub(super) const OBJECT_KEYS: &[&str] = &[
    "type",
    "name",
    "material",
    "min",
    "max",
    "center",
    "radius",
    "from",
    "to",
    "vertices",
    "indices",
    "counts",
    "spacing",
    "origin",
    "rod_radius",
    "sphere_radius",
    "rod_material",
    "sphere_material",
    "bar_size",
    "length",
    "axis",
];

fn material_ref(
    t: &Table,
    key: &str,
    ids: &HashMap<String, u32>,
    default: u32,
) -> SceneResult<u32> {
    match t.string(key)? {
        None => Ok(default),
        Some(name) => ids.get(name).copied().ok_or_else(|| {
            let mut known: Vec<&str> = ids.keys().map(String::as_str).collect();
            known.sort();
            let n = t.get(key).expect("read above");
            t.error_at(
                n,
                key,
                format!(
                    "no material named `{name}` (materials: {})",
                    if known.is_empty() {
                        "none defined".into()
                    } else {
                        known.join(", ")
                    }
                ),
            )
        }),
    }
}

fn budget(t: &Table, key: &str, total: &mut u64, add: u64) -> SceneResult<()> {
    *total = total.saturating_add(add);
    if *total > MAX_PRIMITIVES {
        return Err(t.error(
            key,
            format!(
                "the scene would hold {} primitives, more than the limit of {MAX_PRIMITIVES}",
                *total
            ),
        ));
    }
    let what = format!("a scene of {} primitives", *total);
    let need = total.saturating_mul(crate::memory::BYTES_PER_PRIMITIVE);
    if let Some(why) = crate::memory::too_much(need, &what) {
        return Err(t.error(key, why));
    }
    Ok(())
}

/// A lattice or bar array is held as itself, whatever its size: rendered, one of more than
/// [`INSTANCE_OVER`](crate::render::INSTANCE_OVER) primitives is built from one block of them
/// (`Blocks`), costing the block's primitives and one placement per block; a smaller one is
/// listed primitive by primitive, counting against the scene's limit as any object does.
fn implicit_budget(t: &Table, total: &mut u64, shape: &Implicit) -> SceneResult<()> {
    if shape.len() <= crate::render::INSTANCE_OVER {
        return budget(t, "counts", total, shape.len());
    }
    let what = format!(
        "an object of {} primitives in {} blocks",
        shape.len(),
        Blocks::of(shape.grid()).count()
    );
    if let Some(why) = crate::memory::too_much(crate::memory::implicit_bytes(shape), &what) {
        return Err(at_value(t, "counts", why));
    }
    Ok(())
}

/// An error about the value of `key` (on its line), or the table's where it has none.
fn at_value(t: &Table, key: &str, why: impl Into<String>) -> super::SceneError {
    match t.get(key) {
        Some(n) => t.error_at(n, key, why),
        None => t.error(key, why),
    }
}

pub(super) fn add_object(
    t: &Table,
    id: u32,
    mats: &HashMap<String, u32>,
    geo: &mut Geometry,
    total: &mut u64,
) -> SceneResult<String> {
    let kind = t.req_string("type")?;
    let mat = material_ref(t, "material", mats, 0)?;
    match kind {
        "box" => {
            let (min, max) = (t.req_vec3("min")?, t.req_vec3("max")?);
            if min.cmpge(max).any() {
                return Err(t.error("max", "every coordinate of max must exceed min"));
            }
            budget(t, "type", total, 1)?;
            geo.push_part(id, mat, [Primitive::Cuboid { min, max }]);
        }
        "sphere" => {
            let center = t.req_vec3("center")?;
            let radius = t.f64_where("radius", None, |v| v > 0.0, "greater than 0")?;
            budget(t, "type", total, 1)?;
            geo.push_part(id, mat, [Primitive::Sphere { center, radius }]);
        }
        "rod" => {
            let (a, b) = (t.req_vec3("from")?, t.req_vec3("to")?);
            let radius = t.f64_where("radius", None, |v| v > 0.0, "greater than 0")?;
            budget(t, "type", total, 1)?;
            geo.push_part(id, mat, [Primitive::Capsule { a, b, radius }]);
        }
        "mesh" => {
            let vn = t
                .get("vertices")
                .ok_or_else(|| t.error("vertices", "missing: give [[x, y, z], ...]"))?;
            let verts = match &vn.val {
                super::doc::Val::Array(items) => items
                    .iter()
                    .map(|e| {
                        t.numbers_of(e, "vertices", Some(3))
                            .map(|v| DVec3::new(v[0], v[1], v[2]))
                    })
                    .collect::<SceneResult<Vec<_>>>()?,
                _ => return Err(t.error_at(vn, "vertices", "expected an array of [x, y, z]")),
            };
            let inn = t
                .get("indices")
                .ok_or_else(|| t.error("indices", "missing: give [[i, j, k], ...]"))?;
            let tris = match &inn.val {
                super::doc::Val::Array(items) => items
                    .iter()
                    .map(|e| {
                        let v = t.numbers_of(e, "indices", Some(3))?;
                        let mut idx = [0usize; 3];
                        for (k, x) in v.iter().enumerate() {
                            if x.fract() != 0.0 || *x < 0.0 || *x as usize >= verts.len() {
                                return Err(t.error_at(
                                    e,
                                    "indices",
                                    format!(
                                        "index {x} is not a vertex (there are {})",
                                        verts.len()
                                    ),
                                ));
                            }
                            idx[k] = *x as usize;
                        }
                        Ok(Primitive::Triangle {
                            v: idx.map(|i| verts[i]),
                        })
                    })
                    .collect::<SceneResult<Vec<_>>>()?,
                _ => return Err(t.error_at(inn, "indices", "expected an array of [i, j, k]")),
            };
            if tris.is_empty() {
                return Err(t.error_at(inn, "indices", "the mesh has no triangles"));
            }
            budget(t, "type", total, tris.len() as u64)?;
            geo.push_part(id, mat, tris);
        }
        "lattice" => {
            let counts = t
                .uints("counts", 3, 1, 1_000_000)?
                .ok_or_else(|| t.error("counts", "missing: give the node counts [nx, ny, nz]"))?;
            let spacing = t.positive_scalar_or_array("spacing", 3, Some(1.0))?;
            let l = Lattice {
                counts: [counts[0] as u32, counts[1] as u32, counts[2] as u32],
                spacing: DVec3::from_slice(&spacing),
                origin: t.vec3("origin")?.unwrap_or(DVec3::ZERO),
                rod_radius: t.f64_where("rod_radius", Some(0.05), |v| v >= 0.0, "0 or more")?,
                sphere_radius: t.f64_where(
                    "sphere_radius",
                    Some(0.15),
                    |v| v >= 0.0,
                    "0 or more",
                )?,
            };
            if l.rod_radius == 0.0 && l.sphere_radius == 0.0 {
                return Err(t.error(
                    "rod_radius",
                    "rod_radius and sphere_radius are both 0: the lattice would be empty",
                ));
            }
            let sm = material_ref(t, "sphere_material", mats, mat)?;
            let rm = material_ref(t, "rod_material", mats, mat)?;
            let runs = [(l.sphere_count(), sm), (l.rod_count(), rm)];
            let shape = Implicit::Lattice(l);
            implicit_budget(t, total, &shape)?;
            geo.push_implicit(id, &runs, shape)
                .map_err(|why| at_value(t, "counts", why))?;
        }
        "bar_array" => {
            let counts = t
                .uints("counts", 2, 1, 100_000)?
                .ok_or_else(|| t.error("counts", "missing: give the bar counts [n1, n2]"))?;
            let spacing = t.positive_scalar_or_array("spacing", 2, Some(2.0))?;
            let bar_size = t.positive_scalar_or_array("bar_size", 2, Some(0.5))?;
            let axis = match t.string("axis")?.unwrap_or("z") {
                "x" => 0,
                "y" => 1,
                "z" => 2,
                other => {
                    let n = t.get("axis").expect("read above");
                    return Err(t.error_at(
                        n,
                        "axis",
                        format!("unknown axis `{other}` (x, y or z)"),
                    ));
                }
            };
            let b = BarArray {
                counts: [counts[0] as u32, counts[1] as u32],
                spacing: [spacing[0], spacing[1]],
                bar_size: [bar_size[0], bar_size[1]],
                length: t.f64_where("length", Some(2.0), |v| v > 0.0, "greater than 0")?,
                axis,
                center: t.vec3("center")?.unwrap_or(DVec3::ZERO),
            };
            let runs = [(b.len(), mat)];
            let shape = Implicit::Bars(b);
            implicit_budget(t, total, &shape)?;
            geo.push_implicit(id, &runs, shape)
                .map_err(|why| at_value(t, "counts", why))?;
        }
        other => {
            let n = t.get("type").expect("read above");
            return Err(t.error_at(
                n,
                "type",
                format!(
                    "unknown object type `{other}` (box, sphere, rod, mesh, lattice, bar_array)"
                ),
            ));
        }
    }
    Ok(kind.to_string())
}
