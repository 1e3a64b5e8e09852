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
    /// light's rest frame, where the light is static. `lit` is the event the light falls on
    /// (a hit; `from` is a shadow ray's start, ε off it): the light shines with its timing at
    /// the emission event on `lit`'s past light cone, its time in the light's frame being its
    /// proper time. None where `from` is at the light, or where the light is off then.
    pub(in crate::render) fn toward(
        &self,
        from: Event,
        lit: Event,
        g: &WorldGroup,
        own_frame: Option<&Boost>,
    ) -> Option<ToLight> {
        if let Some(line) = &self.light.worldline {
            return self.toward_on(line, from, lit, g, own_frame);
        }
        let at_light = self.to_light.event(from);
        let delta = self.light.position - at_light.x;
        let dist = delta.length();
        if dist == 0.0 {
            return None;
        }
        let strength = if self.light.timing.is_steady() {
            1.0
        } else {
            let at = self.to_light.event(lit);
            let emitted = at.t - (self.light.position - at.x).length();
            self.light.timing.factor(emitted)
        };
        if strength <= 0.0 {
            return None;
        }
        let atten = if self.light.inverse_square {
            strength / (dist * dist)
        } else {
            strength
        };
        let (dir_w, k) = self.from_light.view_dir(delta / dist);
        Some(Self::seen_from(g, own_frame, dir_w, k, dist, atten))
    }

    /// [`LightRt::toward`] a light on a worldline whose velocity changes: the emission event
    /// on `from`'s past light cone found on the worldline (`Worldline::retarded`), and the
    /// light there seen in the frame it moves with at that event (docs/physics.md §12.7).
    fn toward_on(
        &self,
        line: &crate::scene::Worldline,
        from: Event,
        lit: Event,
        g: &WorldGroup,
        own_frame: Option<&Boost>,
    ) -> Option<ToLight> {
        let t_e = line.retarded(from);
        let v = line.velocity(t_e);
        let (to, out) = (Boost::to_rest(&v), Boost::from_rest(&v));
        let at_light = to.event(from);
        let delta = to.event(Event::new(t_e, line.position(t_e))).x - at_light.x;
        let dist = delta.length();
        if dist == 0.0 || !dist.is_finite() {
            return None;
        }
        let strength = if self.light.timing.is_steady() {
            1.0
        } else {
            // Its clock reads the anchor's time at the anchor and runs at its proper rate.
            let t_lit = line.retarded(lit);
            let tau = line.anchor_time() + line.proper_time(t_lit);
            self.light.timing.factor(tau)
        };
        if strength <= 0.0 {
            return None;
        }
        let atten = if self.light.inverse_square {
            strength / (dist * dist)
        } else {
            strength
        };
        let (dir_w, k) = out.view_dir(delta / dist);
        Some(Self::seen_from(g, own_frame, dir_w, k, dist, atten))
    }

    /// The way toward a light along world direction `dir_w` (ν_world / ν_light = k, at `dist`
    /// in the light's frame), as the surface in group `g` (and its point's own frame) sees it.
    fn seen_from(
        g: &WorldGroup,
        own_frame: Option<&Boost>,
        dir_w: DVec3,
        k: f64,
        dist: f64,
        atten: f64,
    ) -> ToLight {
        let (mut to_light, mut s_surface) = g.boost.view_dir(dir_w);
        // A spinning or accelerated point is lit in its own frame.
        if let Some(b) = own_frame {
            let (d, s) = b.view_dir(to_light);
            (to_light, s_surface) = (d, s_surface * s);
        }
        ToLight {
            dir_w,
            k,
            to_light,
            s_surface,
            dist,
            atten,
        }
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
    /// What the light's intensity is multiplied by on the way: its timing's factor at the
    /// emission event, over the distance squared where it falls off.
    pub atten: f64,
}
