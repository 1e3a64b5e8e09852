//! The validity envelope: the values rest-embree renders correctly on every backend, enforced
//! when a scene loads (docs/scene-format.md, "Valid scenes").
//!
//! - Every number is at most [`MAX_MAGNITUDE`] in size, and every group's geometry lies within
//!   that of the origin. Squares and products of such numbers stay far from f64's range (and
//!   Embree's f32 sees only coordinates rebased near each group), so no intermediate becomes
//!   infinite: Embree aborted on spheres 4e18 apart, whose squared distances overflow f32.
//! - Speeds up to rapidity [`MAX_RAPIDITY`] (1 − β ≈ 1e-17; γ ≈ 2.4e8): the boosts stay exact
//!   in light-cone form, and a rest-frame position γ·[`MAX_MAGNITUDE`] stays finite in the f32
//!   passes.
//! - The vertical field of view at least [`MIN_FOV_DEG`]: below it every pixel of a 16k image
//!   would look along the same f64 direction.
//!
//! Physics is invariant under scaling all lengths and times together, so the envelope is one
//! of magnitude, not of units; detail finer than about 1e-9 of a coordinate's size is lost to
//! f64 rounding like in any renderer. Radiance beyond f32's range saturates at its largest
//! finite value in the image (a searchlight at γ = 1e8 multiplies radiance by up to 1e42).

/// The largest magnitude of any number in a scene.
pub(crate) const MAX_MAGNITUDE: f64 = 1e15;
/// The largest rapidity of any velocity (camera, light, group).
pub(crate) const MAX_RAPIDITY: f64 = 20.0;
/// The smallest vertical field of view, degrees.
pub(crate) const MIN_FOV_DEG: f64 = 1e-6;

/// The message for a number beyond [`MAX_MAGNITUDE`].
pub(crate) fn too_large(v: f64) -> String {
    format!(
        "{v:?} is beyond the values rest-embree renders correctly: numbers up to {MAX_MAGNITUDE:e} in size (scale the scene's units instead; see \"Valid scenes\" in docs/scene-format.md)"
    )
}

/// The message for an object that reaches beyond [`MAX_MAGNITUDE`] from the origin.
pub(crate) fn reaches_too_far(kind: &str, reach: f64) -> String {
    format!(
        "the {kind} reaches {reach:e} from the origin, beyond the {MAX_MAGNITUDE:e} rest-embree renders correctly (scale the scene's units instead; see \"Valid scenes\" in docs/scene-format.md)"
    )
}

/// The message for a velocity beyond [`MAX_RAPIDITY`], or None.
pub(crate) fn too_fast(rapidity: f64) -> Option<String> {
    (rapidity > MAX_RAPIDITY).then(|| {
        format!(
            "rapidity {rapidity:?} is beyond the speeds rest-embree renders correctly: rapidity up to {MAX_RAPIDITY:?} (1 - beta down to about 1e-17)"
        )
    })
}
