//! An object's `spin = { axis, omega }` (docs/physics.md §12.6): the axis through its centre,
//! whether its shape turns (not a body of revolution about the axis) and its rim slower than
//! light.

use super::reader::{SceneResult, Table};
use crate::geometry::Primitive;
use glam::DVec3;

/// An object's `spin = { axis, omega }`, about the axis through its centre, its rim slower
/// than light. A sphere, and a rod about its own axis, are bodies of revolution about it, whose
/// shape stays still; a box, a rod about another axis and a wheel turn (`Spin::turning`).
/// `prims`: the object's primitives as placed.
pub(super) fn read_spin(
    t: &Table,
    kind: &str,
    prims: &[Primitive],
) -> SceneResult<crate::geometry::Spin> {
    let axis = t.req_vec3("axis")?;
    if axis.length() == 0.0 {
        return Err(t.error("axis", "must not be zero"));
    }
    let axis = axis.normalize();
    // No default: a spin without its rate would be none, said nowhere.
    let omega = t.f64("omega")?.ok_or_else(|| {
        t.error(
            "omega",
            "missing: give the rate of turning (radians per unit of the group's time; 0 for none)",
        )
    })?;
    t.finish(&["axis", "omega"])?;
    let (centre, turning) = match (kind, prims) {
        ("sphere", [Primitive::Sphere { center, .. }]) => (*center, false),
        ("rod", [Primitive::Capsule { a, b, .. }]) => {
            let along = (*b - *a).normalize_or_zero();
            (0.5 * (*a + *b), along.cross(axis).length() > 1e-9)
        }
        ("box", [Primitive::Cuboid { min, max }]) => (0.5 * (*min + *max), true),
        // A wheel's first primitive is its hub, at its centre.
        ("wheel", [Primitive::Sphere { center, .. }, ..]) => (*center, true),
        ("box", _) => {
            return Err(t.error(
                "axis",
                "a box turned other than by quarter turns is a mesh, and a spinning mesh is not built yet",
            ))
        }
        _ => {
            return Err(t.error(
                "axis",
                format!("a spinning {kind} is not built yet: spheres, rods, boxes and wheels spin"),
            ))
        }
    };
    // The farthest any point of it lies from the axis.
    let off = |p: DVec3| (p - centre).cross(axis).length();
    let rim = prims
        .iter()
        .map(|p| match *p {
            Primitive::Sphere { center, radius } => off(center) + radius,
            Primitive::Capsule { a, b, radius } => off(a).max(off(b)) + radius,
            other => other
                .bounds()
                .corners()
                .iter()
                .map(|c| off(*c))
                .fold(0.0, f64::max),
        })
        .fold(0.0, f64::max);
    let speed = omega.abs() * rim;
    if speed >= 1.0 {
        let n = t.get("omega").expect("read above");
        return Err(t.error_at(
            n,
            "omega",
            format!("the rim would move at |omega| x radius = {speed}c: at or beyond the speed of light"),
        ));
    }
    Ok(crate::geometry::Spin {
        centre,
        axis,
        omega,
        turning,
        epoch: 0.0,
    })
}
