//! Primary rays alone, without shading: the bench's measure of intersection throughput, and
//! the rays of its bare-Embree baseline. They reach into the tile's buffers as the renderer
//! fills them, so the rays and their order are the renderer's.

use crate::render::{image_points, tiles, CameraRays, ScreenCull, TileScratch, World};
use crate::scene::Scene;
use rayon::prelude::*;

/// Trace every primary ray of the image through the world without shading; returns (rays,
/// hits).
pub(crate) fn trace_primary(scene: &Scene, world: &World) -> (u64, u64) {
    let cam = CameraRays::new(&scene.camera, scene.image.width, scene.image.height);
    let cull = ScreenCull::new(world, &cam).filter(|_| !cam.has_shutter());
    tiles(scene)
        .par_iter()
        .map_init(TileScratch::default, |scratch, &xy| {
            trace_tile(scene, world, &cam, cull.as_ref(), xy, scratch)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}

/// Trace (without shading) every sample's primary rays of one tile; returns the primary rays
/// resolved (culled ones as background included) and the hits.
fn trace_tile(
    scene: &Scene,
    world: &World,
    cam: &CameraRays,
    cull: Option<&ScreenCull>,
    (x0, y0): (u32, u32),
    scratch: &mut TileScratch,
) -> (u64, u64) {
    let (t, px, primary, _) = scratch.tile(scene, cam, cull, (x0, y0));
    let n = scene.image.samples;
    let mut found = 0;
    for s in 0..n {
        image_points(
            &t.live_coords,
            t.offset,
            (Some((s, n)), 0, cam.has_shutter()),
            px,
        );
        world.primary_hits(cam, px, primary);
        found += primary.hit_count() as u64;
    }
    (n as u64 * t.total as u64, found)
}

/// Every pixel-centre primary ray, tile by tile in the order the renderer traces them.
#[cfg(feature = "embree")]
pub(crate) fn primary_rays_by_tile(scene: &Scene) -> Vec<Vec<crate::spacetime::NullRay>> {
    let cam = CameraRays::new(&scene.camera, scene.image.width, scene.image.height);
    let (w, h) = scene.image.frame_size();
    tiles(scene)
        .iter()
        .map(|&(x0, y0)| {
            let mut rays = Vec::new();
            crate::render::primary_rays(
                &cam,
                &crate::render::tile_pixels(x0, y0, w, h),
                scene.image.frame_offset(),
                None,
                &mut rays,
            );
            rays
        })
        .collect()
}
