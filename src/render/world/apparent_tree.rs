//! Culling for primary rays among many groups: every primary ray starts at the imaging event
//! E0, and from there a group is seen exactly where its apparent (retarded) shape is. That shape
//! lies in a box computed from the retarded-position map of docs/physics.md §2.1 (see
//! [`apparent_box`]). A static BVH over those boxes, traversed by the spatial ray x0 + λa (λ
//! is the lookback, so it doubles as the distance), finds the groups a primary ray can meet.

use super::group_tree::world_box;
use crate::accel::{BoxCuller, CullerFactory};
use crate::geometry::Aabb;
use crate::spacetime::{Event, NullRay, Velocity};
use glam::DVec3;

pub struct ApparentTree {
    event: Event,
    /// The backend's culling structure over the apparent boxes.
    tree: Box<dyn BoxCuller>,
}

/// x_app = γ(X − β·sqrt(X² + ρ²)) (docs/physics.md §2.1), without cancellation for X > 0.
fn x_app(g: f64, b: f64, x: f64, rho: f64) -> f64 {
    let s = (x * x + rho * rho).sqrt();
    if x <= 0.0 {
        g * (x - b * s)
    } else {
        (x * x / g - g * b * b * rho * rho) / (x + b * s)
    }
}

/// The box holding every apparent position, as seen from `event`, of a group with rest-frame
/// bounds `rest` moving at `v`. By §2.1 the offsets perpendicular to v are unchanged and the
/// offset along v is x_app(X, ρ), increasing in the rest-frame offset X and decreasing in the
/// distance ρ from the line of motion through the camera; so the apparent shape lies in the
/// prism "the box's perpendicular section × [x_app(X_min, ρ_max), x_app(X_max, ρ_min)]".
pub(crate) fn apparent_box(rest: &Aabb, v: &Velocity, event: Event) -> Aabb {
    apparent_box_of(&world_box(rest, v, event.t), v, event.x)
}

/// As [`apparent_box`], for whatever moves at `v` and lies within `now` (world frame) at the
/// time of the viewing event at `eye`: the bound holds point by point, so for any set in that box.
pub(crate) fn apparent_box_of(now: &Aabb, v: &Velocity, eye: DVec3) -> Aabb {
    if v.is_zero() {
        return *now;
    }
    apparent_box_along(now, v.direction(), v.beta(), v.gamma(), eye)
}

/// [`apparent_box_of`] for a motion given as its direction `u`, speed β > 0 and γ.
pub(crate) fn apparent_box_along(now: &Aabb, u: DVec3, beta: f64, gamma: f64, eye: DVec3) -> Aabb {
    // The box about the eye: centre c and half-widths h.
    let c = now.centroid() - eye;
    let h = 0.5 * now.extent();
    // Offsets along v (a = x·u) and perpendicular to it (p = x − (x·u)u) are linear in x, so
    // over the box they range over the centre's value ± the half-widths through |u| and |I − uuᵀ|.
    let a_mid = c.dot(u);
    let a_half = h.dot(u.abs());
    let (a_min, a_max) = (a_mid - a_half, a_mid + a_half);
    let cp = c - a_mid * u;
    let row = |k: usize| {
        let m = DVec3::new(-u[k] * u.x, -u[k] * u.y, -u[k] * u.z);
        let mut m = m.abs();
        m[k] = (1.0 - u[k] * u[k]).abs();
        m.dot(h)
    };
    let ph = DVec3::new(row(0), row(1), row(2));
    // |p|² is convex: largest at a corner c + s. There p = cp + s⊥ (cp ⊥ u, so cp·s⊥ = cp·s),
    // |p|² = |cp|² + 2 cp·s + |s⊥|², and the corners ±s share |s⊥|²: the largest of four
    // pairs, 2|cp·s| + |s⊥|². (Corner by corner this was a frame's costliest function among
    // many groups: ~900k of these boxes each.)
    let w = cp * h;
    let hu = h * u;
    let mut rho2_max = 0.0f64;
    for (sy, sz) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
        let cps = w.x + sy * w.y + sz * w.z;
        let su = hu.x + sy * hu.y + sz * hu.z;
        let s_perp2 = h.length_squared() - su * su;
        rho2_max = rho2_max.max(cp.length_squared() + 2.0 * cps.abs() + s_perp2);
    }
    // Lab-simultaneous offsets along v, and their rest-frame values X = γ x∥.
    let (x_min, x_max) = (gamma * a_min, gamma * a_max);
    let rho_max = rho2_max.sqrt();
    // |r⊥| is convex: bounded below by its supporting plane at the box centre.
    let cp_len = cp.length();
    let rho_min = if cp_len > 0.0 {
        // The gradient cp / |cp| dotted with h, with one division instead of three.
        (cp_len - cp.abs().dot(h) / cp_len).max(0.0)
    } else {
        0.0
    };
    let (lo, hi) = (
        x_app(gamma, beta, x_min, rho_max),
        x_app(gamma, beta, x_max, rho_min),
    );
    // The prism {perpendicular offset of a point + x u, lo ≤ x ≤ hi}: its box is the
    // perpendicular offsets' box plus the segment's.
    let (s0, s1) = (lo * u, hi * u);
    let b = Aabb::new(eye + cp - ph + s0.min(s1), eye + cp + ph + s0.max(s1));
    // A little slack for rounding.
    let pad = DVec3::splat(1e-9 * (b.max_abs() + 1.0));
    Aabb::new(b.min - pad, b.max + pad)
}

impl ApparentTree {
    /// Over the groups' apparent boxes (see [`apparent_box`]) seen from `event`, in the
    /// backend's culling structure (Embree's BVH, or the f64 box tree).
    pub fn build(
        apparent: &[Aabb],
        event: Event,
        cullers: &CullerFactory,
    ) -> crate::Result<ApparentTree> {
        Ok(ApparentTree {
            event,
            tree: cullers(apparent)?,
        })
    }

    /// Whether this tree serves the ray (it starts at the imaging event).
    pub fn serves(&self, ray: &NullRay) -> bool {
        ray.origin == self.event
    }

    /// One ray (starting at the imaging event): `visit(group, tmax)` returns its new tmax.
    pub fn traverse(
        &self,
        ray: &NullRay,
        tmin: f64,
        tmax: f64,
        mut visit: impl FnMut(u32, f64) -> f64,
    ) {
        let mut t = [tmax];
        self.tree.traverse_packet(
            self.event.x,
            &[ray.dir],
            &[tmin],
            &mut t,
            &mut |g, _, tm| visit(g, tm),
        );
    }

    /// Traverse with a packet of up to [`crate::geometry::PACKET`] primary rays (all starting at
    /// the imaging event): `visit(group, ray, tmax)` returns the ray's new tmax (best hit so
    /// far).
    pub fn traverse_packet(
        &self,
        dirs: &[glam::DVec3],
        tmin: f64,
        tmax: &mut [f64],
        mut visit: impl FnMut(u32, usize, f64) -> f64,
    ) {
        let tmins = [tmin; crate::geometry::PACKET];
        self.tree
            .traverse_packet(self.event.x, dirs, &tmins, tmax, &mut visit);
    }
}
