//! An object's placement in its group's rest frame: `scale` (a number, or one per axis), then
//! `rotate` (`{ axis = [x, y, z], degrees = a }`, or a list of them applied in order, each
//! counter-clockwise about its axis seen from its tip), then `translate` ([x, y, z]), all about
//! the group's rest-frame origin.

use super::reader::{SceneResult, Table};
use glam::{DMat3, DVec3};

/// The keys a transform reads.
pub const KEYS: [&str; 3] = ["translate", "rotate", "scale"];

/// Scale, then rotation, then translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub scale: DVec3,
    pub rotation: DMat3,
    pub translate: DVec3,
}

impl Transform {
    /// The transform `t` gives, or None where it gives none of [`KEYS`].
    pub fn read(t: &Table) -> SceneResult<Option<Transform>> {
        if !KEYS.iter().any(|k| t.has(k)) {
            return Ok(None);
        }
        let scale = match t.get("scale") {
            None => DVec3::ONE,
            Some(n) => {
                let s = if let super::doc::Val::Array(_) = n.val {
                    t.vec3_of(n, "scale")?
                } else {
                    DVec3::splat(t.f64_or("scale", 1.0)?)
                };
                if s.cmple(DVec3::ZERO).any() {
                    return Err(t.error_at(
                        n,
                        "scale",
                        format!(
                            "every factor must be greater than 0 (got {s}): a mirrored placement is not taken"
                        ),
                    ));
                }
                s
            }
        };
        let rotation = Transform::read_rotation(t)?.unwrap_or(DMat3::IDENTITY);
        let translate = t.vec3("translate")?.unwrap_or(DVec3::ZERO);
        Ok(Some(Transform {
            scale,
            rotation,
            translate,
        }))
    }

    /// The `rotate` key of `t`: a turn `{ axis, degrees }` or a list of them, in order.
    pub fn read_rotation(t: &Table) -> SceneResult<Option<DMat3>> {
        let Some(n) = t.get("rotate") else {
            return Ok(None);
        };
        let turns = match &n.val {
            super::doc::Val::Array(_) => t.tables("rotate")?,
            _ => vec![t.table("rotate")?.expect("present")],
        };
        let mut rotation = DMat3::IDENTITY;
        for r in turns {
            let axis = r.req_vec3("axis")?;
            if axis.length_squared() == 0.0 {
                return Err(r.error("axis", "the axis must not be zero"));
            }
            let degrees = r
                .f64("degrees")?
                .ok_or_else(|| r.error("degrees", "missing: give the angle in degrees"))?;
            r.finish(&["axis", "degrees"])?;
            rotation = DMat3::from_axis_angle(axis.normalize(), degrees.to_radians()) * rotation;
        }
        Ok(Some(rotation))
    }

    /// Where the transform takes point `p`.
    pub fn point(&self, p: DVec3) -> DVec3 {
        self.rotation * (self.scale * p) + self.translate
    }

    /// Whether every axis is scaled alike.
    pub fn is_uniform(&self) -> bool {
        self.scale.x == self.scale.y && self.scale.y == self.scale.z
    }

    /// The rotation as a signed permutation of the axes, if it is one (within rounding of the
    /// angle: 90° turns give cosines of about 6e-17): it keeps an axis-aligned box one.
    pub fn axis_permutation(&self) -> Option<DMat3> {
        let m = self.rotation;
        let snapped = DMat3::from_cols_array(&m.to_cols_array().map(|x| {
            if (x.abs() - 1.0).abs() < 1e-12 {
                x.signum()
            } else if x.abs() < 1e-12 {
                0.0
            } else {
                f64::NAN
            }
        }));
        snapped.is_finite().then_some(snapped)
    }
}
