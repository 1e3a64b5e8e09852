//! A tile of pixels: its primary rays (in 4 × 4 blocks, so a 16-wide packet is a square of
//! neighbouring pixels), traced together through every group, then shaded one by one.

use super::camera::CameraRays;
use super::frame::PixelValue;
use super::sampler::sample_offset;
use super::shade::Shader;
use super::world::{SurfaceHit, World};
use super::TILE;
use crate::scene::Scene;
use crate::spacetime::NullRay;
use glam::DVec3;

/// The pixels of the tile at (x0, y0), clipped to the image, in 4 × 4 blocks.
pub fn tile_pixels(x0: u32, y0: u32, w: u32, h: u32) -> Vec<(u32, u32)> {
    let mut v = Vec::with_capacity((TILE * TILE) as usize);
    for by in (y0..(y0 + TILE).min(h)).step_by(4) {
        for bx in (x0..(x0 + TILE).min(w)).step_by(4) {
            for y in by..(by + 4).min(h).min(y0 + TILE) {
                for x in bx..(bx + 4).min(w).min(x0 + TILE) {
                    v.push((x, y));
                }
            }
        }
    }
    v
}

/// The primary rays of `coords` (frame pixels; `offset` places the frame in the full image):
/// sample `(s, n)` of each pixel, or the pixel centre for None.
pub fn primary_rays(
    cam: &CameraRays,
    coords: &[(u32, u32)],
    offset: (u32, u32),
    sample: Option<(u32, u32)>,
    rays: &mut Vec<NullRay>,
) {
    rays.clear();
    for &(fx, fy) in coords {
        let (x, y) = (fx + offset.0, fy + offset.1);
        let (ox, oy) = match sample {
            Some((s, n)) => sample_offset(x, y, s, n),
            None => (0.5, 0.5),
        };
        rays.push(cam.ray(x as f64 + ox, y as f64 + oy));
    }
}

/// Trace (without shading) every sample's primary rays of one tile; returns rays and hits.
pub fn trace_tile(scene: &Scene, world: &World, cam: &CameraRays, x0: u32, y0: u32) -> (u64, u64) {
    let (w, h) = scene.image.frame_size();
    let coords = tile_pixels(x0, y0, w, h);
    let n = scene.image.samples;
    let mut rays = Vec::with_capacity(coords.len());
    let mut hits = vec![None; coords.len()];
    let mut found = 0;
    for s in 0..n {
        primary_rays(
            cam,
            &coords,
            scene.image.frame_offset(),
            Some((s, n)),
            &mut rays,
        );
        world.closest_hits(&rays, 0.0, &mut hits);
        found += hits.iter().filter(|h| h.is_some()).count() as u64;
    }
    (n as u64 * coords.len() as u64, found)
}

pub struct TilePixel {
    pub x: u32,
    pub y: u32,
    pub value: PixelValue,
}

pub struct TileResult {
    pub pixels: Vec<TilePixel>,
    pub primary_rays: u64,
    pub nonfinite: u64,
}

pub fn render_tile(scene: &Scene, world: &World, cam: &CameraRays, x0: u32, y0: u32) -> TileResult {
    let (w, h) = scene.image.frame_size();
    let coords = tile_pixels(x0, y0, w, h);
    let n = scene.image.samples;
    let shader = Shader::new(scene, world);
    let mut sum = vec![DVec3::ZERO; coords.len()];
    let mut covered = vec![0u32; coords.len()];
    let mut aov: Vec<Option<(NullRay, SurfaceHit)>> = vec![None; coords.len()];
    let mut rays = Vec::with_capacity(coords.len());
    let mut hits = vec![None; coords.len()];
    let mut primary = 0u64;
    // With one sample the pixel centre serves both colour and passes; with more, an extra
    // centre ray gives crisp passes (ids, lookback) that compositors expect.
    let aov_pass = n > 1;
    let aov_sample = if aov_pass { n } else { 0 };
    for s in 0..n + u32::from(aov_pass) {
        let centre = s == n;
        let sample = if centre { None } else { Some((s, n)) };
        primary_rays(cam, &coords, scene.image.frame_offset(), sample, &mut rays);
        primary += rays.len() as u64;
        world.closest_hits(&rays, 0.0, &mut hits);
        for (k, (r, hit)) in rays.iter().zip(&hits).enumerate() {
            if !centre {
                sum[k] += match hit {
                    Some(hh) => {
                        covered[k] += 1;
                        shader.shade(r, hh, 0)
                    }
                    None => scene.image.background,
                };
            }
            if s == aov_sample {
                aov[k] = hit.map(|hh| (*r, hh));
            }
        }
    }
    let mut nonfinite = 0;
    let pixels = coords
        .iter()
        .enumerate()
        .map(|(k, &(x, y))| {
            let mut c = sum[k] / n as f64;
            if !c.is_finite() {
                nonfinite += 1;
                c = DVec3::ZERO;
            }
            let mut value = PixelValue {
                color: [c.x as f32, c.y as f32, c.z as f32],
                alpha: covered[k] as f32 / n as f32,
                ..Default::default()
            };
            if let Some((r, hit)) = aov[k] {
                let g = &world.groups[hit.group];
                let prim = &g.geometry.prims[hit.prim as usize];
                let nrm = prim.normal(hit.point);
                value.lookback = hit.lambda as f32;
                value.doppler = (cam.lookback_factor(r.dir) / hit.s) as f32;
                value.object_id = g.geometry.part_of(hit.prim).object + 1;
                value.normal = [nrm.x as f32, nrm.y as f32, nrm.z as f32];
                let p = r.at(hit.lambda).x;
                value.position = [p.x as f32, p.y as f32, p.z as f32];
                let q = hit.point;
                value.rest_position = [q.x as f32, q.y as f32, q.z as f32];
            }
            TilePixel { x, y, value }
        })
        .collect();
    TileResult {
        pixels,
        primary_rays: primary,
        nonfinite,
    }
}
