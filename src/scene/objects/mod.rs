//! Objects of a velocity group: boxes, spheres, rods, meshes and the procedural lattice and bars,
//! read into rest-frame primitives within the scene's limits.

mod meshes;

pub(super) use meshes::{add_mesh_data, file_materials};

use super::procedural::{BarArray, Lattice};
use super::reader::{SceneResult, Table};
use super::shared_meshes::SharedMeshes;
use super::transform::{Transform, KEYS};
use crate::geometry::{Blocks, Implicit};
use crate::geometry::{Geometry, Primitive};
use glam::DVec3;
use std::collections::HashMap;

/// The most primitives one scene may hold (a guard against typos like `counts = [1000000, ...]`).
pub(crate) const MAX_PRIMITIVES: u64 = 200_000_000;

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
    "file",
    "materials",
    "translate",
    "rotate",
    "scale",
    "spin",
    "spokes",
    "rim_segments",
    "hub_radius",
    "groups",
    "time_scale",
    "camera",
    "of",
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

/// Whether a scene of `total` primitives passes [`budget`]'s checks.
pub(crate) fn within_budget(total: u64) -> bool {
    let need = total.saturating_mul(crate::memory::BYTES_PER_PRIMITIVE);
    total <= MAX_PRIMITIVES && crate::memory::too_much(need, "").is_none()
}

pub(super) fn budget(t: &Table, key: &str, total: &mut u64, add: u64) -> SceneResult<()> {
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
/// [`INSTANCE_OVER`](crate::geometry::INSTANCE_OVER) primitives is built from one block of them
/// (`Blocks`), costing the block's primitives and one placement per block; a smaller one is
/// listed primitive by primitive, counting against the scene's limit as any object does.
fn implicit_budget(t: &Table, total: &mut u64, shape: &Implicit) -> SceneResult<()> {
    if shape.len() <= crate::geometry::INSTANCE_OVER {
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

/// An error about the first transform key `t` gives (on its line): an object placed by keys
/// of its own.
fn at_transform(t: &Table, why: impl Into<String>) -> super::SceneError {
    let key = KEYS
        .into_iter()
        .find(|k| t.has(k))
        .expect("a transform has a key");
    at_value(t, key, why)
}

/// An error about the value of `key` (on its line), or the table's where it has none.
fn at_value(t: &Table, key: &str, why: impl Into<String>) -> super::SceneError {
    match t.get(key) {
        Some(n) => t.error_at(n, key, why),
        None => t.error(key, why),
    }
}

/// The twelve triangles of the box from `min` to `max`, two per face, counter-clockwise seen
/// from outside.
fn box_triangles(min: DVec3, max: DVec3) -> [[DVec3; 3]; 12] {
    let c = |i: usize| {
        DVec3::new(
            if i & 1 == 0 { min.x } else { max.x },
            if i & 2 == 0 { min.y } else { max.y },
            if i & 4 == 0 { min.z } else { max.z },
        )
    };
    // Each face's corners in order around it, seen from outside.
    let faces = [
        [0, 2, 3, 1], // z = min
        [4, 5, 7, 6], // z = max
        [0, 1, 5, 4], // y = min
        [2, 6, 7, 3], // y = max
        [0, 4, 6, 2], // x = min
        [1, 3, 7, 5], // x = max
    ];
    let mut out = [[DVec3::ZERO; 3]; 12];
    for (f, q) in faces.iter().enumerate() {
        out[2 * f] = [c(q[0]), c(q[1]), c(q[2])];
        out[2 * f + 1] = [c(q[0]), c(q[2]), c(q[3])];
    }
    out
}

pub(super) fn add_object(
    t: &Table,
    id: u32,
    mats: &HashMap<String, u32>,
    geo: &mut Geometry,
    total: &mut u64,
    meshes: &mut SharedMeshes,
) -> SceneResult<String> {
    let kind = t.req_string("type")?;
    let mat = material_ref(t, "material", mats, 0)?;
    let transform = Transform::read(t)?;
    let mut adding = Adding {
        t,
        id,
        mat,
        transform,
        geo,
        total,
    };
    // The shape before its transform, where it is a box, sphere or rod.
    let original = match kind {
        "box" => Some(adding.add_box()?),
        "sphere" => Some(adding.add_sphere()?),
        "rod" => Some(adding.add_rod()?),
        "mesh" if t.has("file") && meshes.is_shared(t)? => {
            let path = t.path_beside(t.req_string("file")?);
            adding.add_shared_mesh(mats, meshes, "file", path)?;
            None
        }
        "mesh" if t.has("file") => adding.add_mesh_file(mats).map(|_| None)?,
        "instance" => {
            if let Some(k) = ["file", "vertices", "indices"]
                .into_iter()
                .find(|k| t.has(k))
            {
                return Err(at_value(
                    t,
                    k,
                    "an instance places the mesh of the object its `of` names; give the file there",
                ));
            }
            let path = meshes.file_of_instance(t)?;
            adding.add_shared_mesh(mats, meshes, "of", path)?;
            None
        }
        "mesh" => adding.add_inline_mesh().map(|_| None)?,
        "lattice" | "bar_array" if transform.is_some() => {
            return Err(at_transform(
                t,
                format!(
                    "transforms apply to boxes, spheres, rods and meshes; a {kind} is placed by its own keys (origin, center, spacing, axis)"
                ),
            ));
        }
        "lattice" => adding.add_lattice(mats).map(|_| None)?,
        "wheel" if transform.is_some() => {
            return Err(at_transform(
                t,
                "a wheel is placed by its own keys (center, axis, radius)",
            ));
        }
        "wheel" => Some(adding.add_wheel()?),
        "bar_array" => adding.add_bar_array().map(|_| None)?,
        other => {
            let n = t.get("type").expect("read above");
            return Err(t.error_at(
                n,
                "type",
                format!(
                    "unknown object type `{other}` (box, sphere, rod, mesh, instance, gltf, lattice, bar_array, wheel)"
                ),
            ));
        }
    };
    if let Some(spin) = t.table("spin")? {
        let prims: Vec<Primitive> = adding
            .geo
            .parts
            .iter()
            .filter(|p| p.object == id)
            .flat_map(|p| p.start..p.end)
            .filter(|&i| (i as usize) < adding.geo.prims.len())
            .map(|i| adding.geo.prims[i as usize])
            .collect();
        let spin = super::spin_keys::read_spin(&spin, kind, &prims)?;
        adding.geo.set_spin(id, spin);
    }
    // Textures turn and move with the object (a box turned by quarter turns as exactly as its
    // corners were).
    if let Some(x) = transform {
        adding.geo.set_placement(
            id,
            std::sync::Arc::new(crate::geometry::Placement {
                scale: x.scale,
                rotation: x.axis_permutation().unwrap_or(x.rotation),
                translate: x.translate,
                shape: original,
            }),
        );
    }
    Ok(kind.to_string())
}

/// The factor of a uniform scale (1 without a transform): a sphere or rod stays one under a
/// uniform scale only.
fn uniform_scale(t: &Table, transform: Option<Transform>, what: &str) -> SceneResult<f64> {
    match transform {
        Some(x) if !x.is_uniform() => Err(at_value(
            t,
            "scale",
            format!(
                "a {what} scaled unevenly is no longer a {what}: give one factor, or use a mesh"
            ),
        )),
        _ => Ok(transform.map_or(1.0, |x| x.scale.x)),
    }
}

/// An object being added: its table, id, material and transform, the group's geometry it goes
/// into, and the scene's count of primitives so far.
struct Adding<'t, 'a> {
    t: &'t Table<'a>,
    id: u32,
    mat: u32,
    transform: Option<Transform>,
    geo: &'t mut Geometry,
    total: &'t mut u64,
}

impl Adding<'_, '_> {
    /// A box (`min`, `max`): itself, moved by quarter turns, or its twelve triangles turned any
    /// other way; returns the box as given.
    fn add_box(&mut self) -> SceneResult<Primitive> {
        let (t, id, mat, transform) = (self.t, self.id, self.mat, self.transform);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        let (min, max) = (t.req_vec3("min")?, t.req_vec3("max")?);
        if min.cmpge(max).any() {
            return Err(t.error("max", "every coordinate of max must exceed min"));
        }
        match transform {
            None => {
                budget(t, "type", total, 1)?;
                geo.push_part(id, mat, [Primitive::Cuboid { min, max }]);
            }
            // Turned by quarter turns: still a box, its corners moved.
            Some(x) if x.axis_permutation().is_some() => {
                let exact = Transform {
                    rotation: x.axis_permutation().expect("checked"),
                    ..x
                };
                let (a, b) = (exact.point(min), exact.point(max));
                budget(t, "type", total, 1)?;
                geo.push_part(
                    id,
                    mat,
                    [Primitive::Cuboid {
                        min: a.min(b),
                        max: a.max(b),
                    }],
                );
            }
            // Turned otherwise: its twelve triangles.
            Some(x) => {
                budget(t, "type", total, 12)?;
                geo.push_part(
                    id,
                    mat,
                    box_triangles(min, max).map(|v| Primitive::Triangle {
                        v: v.map(|p| x.point(p)),
                    }),
                );
            }
        }
        Ok(Primitive::Cuboid { min, max })
    }

    /// A sphere (`center`, `radius`); returns it as given.
    fn add_sphere(&mut self) -> SceneResult<Primitive> {
        let (t, id, mat, transform) = (self.t, self.id, self.mat, self.transform);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        let center = t.req_vec3("center")?;
        let radius = t.f64_where("radius", None, |v| v > 0.0, "greater than 0")?;
        let s = uniform_scale(t, transform, "sphere")?;
        let given = Primitive::Sphere { center, radius };
        let center = transform.map_or(center, |x| x.point(center));
        budget(t, "type", total, 1)?;
        geo.push_part(
            id,
            mat,
            [Primitive::Sphere {
                center,
                radius: radius * s,
            }],
        );
        Ok(given)
    }

    /// A spoked wheel (`center`, `axis` [0, 0, 1], `radius` of the rim's centre line,
    /// `spokes` 8, `rim_segments` 6 per spoke, `rod_radius` radius/25, `hub_radius` three rod
    /// radii): a hub sphere, then the spokes and the rim as rods; returns the hub.
    fn add_wheel(&mut self) -> SceneResult<Primitive> {
        let (t, id, mat) = (self.t, self.id, self.mat);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        let center = t.req_vec3("center")?;
        let axis = t.vec3("axis")?.unwrap_or(DVec3::Z);
        if !(axis.is_finite() && axis.length() > 0.0) {
            return Err(t.error("axis", "must be a direction, not zero"));
        }
        let axis = axis.normalize();
        let radius = t.f64_where("radius", None, |v| v > 0.0, "greater than 0")?;
        let spokes = t.uint("spokes", Some(8), 1, 1000)? as usize;
        let rim_segments = t.uint("rim_segments", Some(6 * spokes as u64), 3, 100_000)? as usize;
        let rod = t.f64_where(
            "rod_radius",
            Some(radius / 25.0),
            |v| v > 0.0,
            "greater than 0",
        )?;
        let hub = t.f64_where("hub_radius", Some(3.0 * rod), |v| v > 0.0, "greater than 0")?;
        // Two directions across the axis.
        let u = axis.any_orthonormal_vector();
        let v = axis.cross(u);
        let at = |k: usize, n: usize| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            center + radius * (a.cos() * u + a.sin() * v)
        };
        let hub_prim = Primitive::Sphere {
            center,
            radius: hub,
        };
        let mut prims = vec![hub_prim];
        prims.extend((0..spokes).map(|k| Primitive::Capsule {
            a: center,
            b: at(k, spokes),
            radius: rod,
        }));
        prims.extend((0..rim_segments).map(|k| Primitive::Capsule {
            a: at(k, rim_segments),
            b: at(k + 1, rim_segments),
            radius: rod,
        }));
        budget(t, "type", total, prims.len() as u64)?;
        geo.push_part(id, mat, prims);
        Ok(hub_prim)
    }

    /// A rod (`from`, `to`, `radius`), a capsule; returns it as given.
    fn add_rod(&mut self) -> SceneResult<Primitive> {
        let (t, id, mat, transform) = (self.t, self.id, self.mat, self.transform);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        let (a, b) = (t.req_vec3("from")?, t.req_vec3("to")?);
        let radius = t.f64_where("radius", None, |v| v > 0.0, "greater than 0")?;
        let s = uniform_scale(t, transform, "rod")?;
        let given = Primitive::Capsule { a, b, radius };
        let (a, b) = transform.map_or((a, b), |x| (x.point(a), x.point(b)));
        budget(t, "type", total, 1)?;
        geo.push_part(
            id,
            mat,
            [Primitive::Capsule {
                a,
                b,
                radius: radius * s,
            }],
        );
        Ok(given)
    }
}

/// The entry `t`'s `material` (for triangles its file gives none) and transform.
pub(super) fn material_and_transform(
    t: &Table,
    mats: &HashMap<String, u32>,
) -> SceneResult<(u32, Option<Transform>)> {
    Ok((material_ref(t, "material", mats, 0)?, Transform::read(t)?))
}

impl Adding<'_, '_> {
    /// A lattice (`counts`, `spacing`, `origin`, its radii and materials), held as itself.
    fn add_lattice(&mut self, mats: &HashMap<String, u32>) -> SceneResult<()> {
        let (t, id, mat) = (self.t, self.id, self.mat);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
        let counts = t
            .uints("counts", 3, 1, 1_000_000)?
            .ok_or_else(|| t.error("counts", "missing: give the node counts [nx, ny, nz]"))?;
        let spacing = t.positive_scalar_or_array("spacing", 3, Some(1.0))?;
        let l = Lattice {
            counts: [counts[0] as u32, counts[1] as u32, counts[2] as u32],
            spacing: DVec3::from_slice(&spacing),
            origin: t.vec3("origin")?.unwrap_or(DVec3::ZERO),
            rod_radius: t.f64_where("rod_radius", Some(0.05), |v| v >= 0.0, "0 or more")?,
            sphere_radius: t.f64_where("sphere_radius", Some(0.15), |v| v >= 0.0, "0 or more")?,
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
            .map_err(|why| at_value(t, "counts", why.to_string()))?;
        Ok(())
    }

    /// A bar array (`counts`, `spacing`, `bar_size`, `length`, `axis`, `center`), held as
    /// itself.
    fn add_bar_array(&mut self) -> SceneResult<()> {
        let (t, id, mat) = (self.t, self.id, self.mat);
        let (geo, total) = (&mut *self.geo, &mut *self.total);
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
                return Err(t.error_at(n, "axis", format!("unknown axis `{other}` (x, y or z)")));
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
            .map_err(|why| at_value(t, "counts", why.to_string()))?;
        Ok(())
    }
}
