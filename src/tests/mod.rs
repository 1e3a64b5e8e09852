//! Tests of the renderer's internals: the group and light trees, the culls, the fans of primary
//! rays, batched shadow rays. The integration tests in tests/ use the public API alone; these
//! reach what the crate keeps to itself.

#[path = "../../tests/common/basics.rs"]
mod common;

mod allocations;
mod at_rest;
mod backend_names;
mod compact_scenes;
mod every_isa;
// It counts the bench's primary hits (src/bench/primary.rs).
#[cfg(feature = "cli")]
mod fused_primary;
mod instanced_lattice;
mod light_buffer;
mod many_groups;
mod mesh_instances;
mod progressive;
mod screen_cull;
mod shadow_batches;
mod slow_light;
mod strips;
mod toml_tree;
mod visiting_order;

/// A worldline of eight segments alternating between 0.9c and 0.88c along −x, their ends
/// spread over the emission times a view from t = 3 sees (the bench's "8 segments").
const EIGHT_SEGMENTS: &str =
    "[{until=-40, velocity=[-0.9,0,0]}, {until=-20, velocity=[-0.88,0,0]}, \
    {until=-10, velocity=[-0.9,0,0]}, {until=-5, velocity=[-0.88,0,0]}, \
    {until=-2, velocity=[-0.9,0,0]}, {until=0, velocity=[-0.88,0,0]}, \
    {until=1, velocity=[-0.9,0,0]}, {velocity=[-0.88,0,0]}]";

/// How many pixels of two frames of one size differ, in any pass.
fn differing_pixels(a: &crate::render::Frame, b: &crate::render::Frame) -> usize {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| p != q)
        .count()
}

/// Rays for comparing accelerators: a third from inside `inside`, the rest from a sphere of
/// radius `far` about the origin, each aimed at a point of `target`, with a direction as long
/// as a boost makes it (0.5 to 3), searched all the way or (every other one, as shadow rays
/// are) up to a lookback of 1 to `reach`.
fn rays_toward(
    rng: &mut crate::rng::Rng,
    n: usize,
    inside: crate::geometry::Aabb,
    far: f64,
    target: crate::geometry::Aabb,
    reach: f64,
) -> Vec<crate::accel::Ray> {
    let within = |rng: &mut crate::rng::Rng, b: &crate::geometry::Aabb| {
        glam::DVec3::new(
            rng.range(b.min.x, b.max.x),
            rng.range(b.min.y, b.max.y),
            rng.range(b.min.z, b.max.z),
        )
    };
    (0..n)
        .map(|i| {
            let origin = if i % 3 == 0 {
                within(rng, &inside)
            } else {
                rng.unit() * far
            };
            let aim = within(rng, &target);
            let dir = (aim - origin).normalize() * rng.range(0.5, 3.0);
            let tmax = if i % 2 == 0 {
                f64::INFINITY
            } else {
                rng.range(1.0, reach)
            };
            crate::accel::Ray::new(origin, dir, 1e-6, tmax)
        })
        .collect()
}

/// `accel`'s closest hits of `rays`, traced `width` at a time.
fn hits(
    accel: &dyn crate::accel::Accelerator,
    rays: &[crate::accel::Ray],
    width: usize,
) -> Vec<Option<crate::accel::Hit>> {
    let mut out = vec![None; rays.len()];
    for (r, h) in rays.chunks(width).zip(out.chunks_mut(width)) {
        accel.intersect(r, h);
    }
    out
}

/// Whether `accel` finds each of `rays` blocked, traced `width` at a time.
fn occluded(
    accel: &dyn crate::accel::Accelerator,
    rays: &[crate::accel::Ray],
    width: usize,
) -> Vec<bool> {
    let mut out = vec![false; rays.len()];
    for (r, o) in rays.chunks(width).zip(out.chunks_mut(width)) {
        accel.occluded(r, o);
    }
    out
}
