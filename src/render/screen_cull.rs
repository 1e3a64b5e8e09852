//! Primary rays that cannot meet any group go straight to the background without being made.
//!
//! In a group's rest frame the group is static and every primary ray starts at one point, the
//! imaging event's rest-frame position; from there the group's bounds are seen within a cone of
//! looking directions (the cap holding the directions to its eight corners). A Lorentz
//! transformation acts on directions as a Möbius map of the celestial sphere, which takes
//! circles to circles, so that cone, carried into the world frame and on into the camera's rest
//! frame (the aberration of docs/physics.md §1.1 each time), is again a cone, found exactly from
//! three of its boundary directions. A 4 × 4 block of pixels (one ray packet) whose directions
//! all lie outside every group's cone is background, with no camera ray, boost or bounds test
//! spent on it: one dot product per block and group, and first one per tile and group (a tile
//! no group's cone reaches is background without its blocks tested). Pinhole cameras only (image points L
//! pixels apart then look at most L / focal radians apart, which bounds a block's spread of
//! directions); at most `MAX_GROUPS` groups (with more, the group tree culls).

use super::camera::CameraRays;
use super::world::World;
use super::TILE;
use glam::DVec3;
use std::f64::consts::PI;

const MAX_GROUPS: usize = 64;

/// A cone of looking directions in the camera's rest frame.
#[derive(Clone, Copy, Debug)]
struct Cone {
    axis: DVec3,
    half_angle: f64,
}

pub struct ScreenCull {
    /// Per group: the cone's axis and the cosine of its half-angle widened by a block's
    /// angular radius (a block is visible when its centre direction is within that).
    cones: Vec<(DVec3, f64)>,
    /// The same widened by a tile's angular radius instead, for a tile's test.
    tile_cones: Vec<(DVec3, f64)>,
}

/// The angle between two unit vectors, accurate for small angles too (acos is not near 1).
fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// The circle through three unit vectors, as a cone (axis toward them).
fn cone_through(p: [DVec3; 3]) -> Option<Cone> {
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let len = n.length();
    if len.is_nan() || len <= 0.0 {
        return None;
    }
    let mut axis = n / len;
    if axis.dot(p[0]) < 0.0 {
        axis = -axis;
    }
    let half_angle = p.iter().map(|q| angle(axis, *q)).fold(0.0, f64::max);
    Some(Cone { axis, half_angle })
}

impl ScreenCull {
    /// None when this cull does not apply: bounds culling switched off, a camera that is not a
    /// pinhole, more than `MAX_GROUPS` groups, or a group whose bounds hold the imaging event or
    /// fill nearly a hemisphere of its view.
    pub fn new(world: &World, cam: &CameraRays) -> Option<ScreenCull> {
        if !world.options.bounds_cull || world.groups.len() > MAX_GROUPS {
            return None;
        }
        cam.pinhole_toward(0.0, 0.0)?;
        // Image points L pixels apart look at most L / focal apart: a 4 x 4 block's directions
        // are within 2 sqrt(2) / focal of its centre's.
        let block_radius = 8f64.sqrt() / cam.focal_px();
        // A tile's: within TILE / sqrt(2) pixels of its centre (a block's centre within
        // 6 sqrt(2), so a block within the reach of a cone lies in a tile within it).
        let tile_radius = std::f64::consts::SQRT_2 * f64::from(TILE / 2) / cam.focal_px();
        let widened = |axis: DVec3, half_angle: f64, radius: f64| {
            // Slack for rounding in the maps (a pixel is ~1e-3 rad).
            let reach = half_angle + radius + 1e-6;
            (axis, if reach < PI { reach.cos() } else { -1.0 })
        };
        let mut cones = Vec::with_capacity(world.groups.len());
        let mut tile_cones = Vec::with_capacity(world.groups.len());
        for g in &world.groups {
            let out = g.boost.inverse();
            let b = &g.bounds;
            let e = g.event_rest;
            if e.cmpge(b.min).all() && e.cmple(b.max).all() {
                return None;
            }
            // The box's looking directions lie in the spherical hull of its corners', so in
            // the cap around the direction to its centre that holds all eight corners.
            let axis = (b.centroid() - g.event_rest).normalize();
            let theta = b
                .corners()
                .iter()
                .map(|&corner| angle(axis, (corner - g.event_rest).normalize()))
                .fold(0.0, f64::max);
            // A cap reaching to 90 degrees is of no use.
            if theta.is_nan() || theta >= std::f64::consts::FRAC_PI_2 - 1e-6 {
                return None;
            }
            let u = axis.any_orthonormal_vector();
            let v = axis.cross(u);
            // Three boundary directions, seen in the world frame, then by the camera.
            let seen = |side: DVec3| {
                let rest = theta.cos() * axis + theta.sin() * side;
                cam.to_camera_dir(out.view_dir(rest).0)
            };
            let c = cone_through([
                seen(u),
                seen(-0.5 * u + 0.866_025_403_784_438_6 * v),
                seen(-0.5 * u - 0.866_025_403_784_438_6 * v),
            ])?;
            // The image of the axis lies inside the image cone unless the map turned the cone
            // inside out (it then covers more than a hemisphere: no use).
            let centre = cam.to_camera_dir(out.view_dir(axis).0);
            if centre.dot(c.axis) < c.half_angle.cos() || c.half_angle > 1.4 {
                return None;
            }
            cones.push(widened(c.axis, c.half_angle, block_radius));
            tile_cones.push(widened(c.axis, c.half_angle, tile_radius));
        }
        // A cull that keeps every block is all cost (a test per block where a group fills the
        // view). A cone narrower than a hemisphere is convex on the sphere, and a
        // pinhole's image is the convex hull of its corners' directions (lines on the image
        // plane look along great circles), so a cone that holds the four corners holds the
        // centre of every block.
        let (w, h) = cam.image_size();
        let corners = [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)];
        let fills_view = |&cone: &(DVec3, f64)| {
            cone.1 > 0.0 && corners.iter().all(|&(x, y)| seen_from(&[cone], cam, x, y))
        };
        if cones.iter().any(fills_view) {
            return None;
        }
        Some(ScreenCull { cones, tile_cones })
    }

    /// Whether any group may be seen from the TILE × TILE pixels whose top-left pixel is
    /// (x, y) in full-image coordinates (where none can, no block of it need be tested).
    pub fn tile_visible(&self, cam: &CameraRays, x: u32, y: u32) -> bool {
        let half = f64::from(TILE / 2);
        seen_from(&self.tile_cones, cam, x as f64 + half, y as f64 + half)
    }

    /// Whether any group may be seen from the 4 × 4 block of pixels whose top-left pixel is
    /// (x, y) in full-image coordinates.
    pub fn block_visible(&self, cam: &CameraRays, x: u32, y: u32) -> bool {
        seen_from(&self.cones, cam, x as f64 + 2.0, y as f64 + 2.0)
    }
}

/// Whether the looking direction through image point (x, y) lies within any of `cones` (axis
/// and cosine of the reach).
fn seen_from(cones: &[(DVec3, f64)], cam: &CameraRays, x: f64, y: f64) -> bool {
    let Some(d) = cam.pinhole_toward(x, y) else {
        return true;
    };
    // axis · d ≥ cos_reach |d| without the square root: compare squares, minding signs.
    let d2 = d.length_squared();
    cones.iter().any(|&(axis, c)| {
        let a = axis.dot(d);
        let (a2, c2) = (a * a, c * c * d2);
        if c >= 0.0 {
            a >= 0.0 && a2 >= c2
        } else {
            a >= 0.0 || a2 <= c2
        }
    })
}
