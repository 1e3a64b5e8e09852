//! Point lights as a shader sees them: each with the boosts into and out of its rest frame, and
//! the way from a surface to the emission event on its worldline (docs/physics.md §5.3).

use crate::render::world::WorldGroup;
use crate::scene::Light;
use crate::spacetime::{Boost, Event};
use glam::DVec3;

/// A point light with the boosts into and out of its rest frame.
pub(in crate::render) struct LightRt<'a> {
    pub light: &'a Light,
    pub(super) to_light: Boost,
    pub(super) from_light: Boost,
}

impl LightRt<'_> {
    /// Toward this light from world event `from`, seen in group `g`'s frame: the emission
    /// event on the light's worldline that lies on `from`'s past light cone, found in the
    /// light's rest frame, where the light is static. None where `from` is at the light.
    pub(in crate::render) fn toward(&self, from: Event, g: &WorldGroup) -> Option<ToLight> {
        let at_light = self.to_light.event(from);
        let delta = self.light.position - at_light.x;
        let dist = delta.length();
        if dist == 0.0 {
            return None;
        }
        let (dir_w, k) = self.from_light.view_dir(delta / dist);
        let (to_light, s_surface) = g.boost.view_dir(dir_w);
        Some(ToLight {
            dir_w,
            k,
            to_light,
            s_surface,
            dist,
        })
    }
}

/// The way from a surface to a point light (see [`LightRt::toward`]).
pub(in crate::render) struct ToLight {
    /// The world-frame looking direction toward the light.
    pub dir_w: DVec3,
    /// ν_world / ν_light along it.
    pub k: f64,
    /// The unit direction toward the light in the surface's frame.
    pub to_light: DVec3,
    /// ν_surface / ν_world along it.
    pub s_surface: f64,
    /// The distance in the light's frame (its lookback time there).
    pub dist: f64,
}
