//! What a tile's samples gathered, pixel by pixel, and the pixels it makes of it: the mean
//! colour, the alpha of the samples that met a surface, the passes of the centre ray's hit
//! (lookback, Doppler factor, ids, normal, positions, depth) and the mattes' ranked ids.

use super::super::camera::CameraRays;
use super::super::frame::{Mattes, PixelValue, MATTE_RANKS};
use super::super::world::{SurfaceHit, World};
use crate::scene::Scene;
use crate::spacetime::NullRay;
use glam::DVec3;

/// A pixel of a tile: where it is in the frame, its values, and its mattes.
pub struct TilePixel {
    pub x: u32,
    pub y: u32,
    pub value: PixelValue,
    /// Default where the passes are not rendered.
    pub mattes: Mattes,
}

/// What a tile's samples gathered, pixel by pixel (in `tile_pixels` order).
pub(super) struct Gathered {
    /// The colours' sum over the samples.
    pub sum: Vec<DVec3>,
    /// How many samples met a surface.
    pub covered: Vec<u32>,
    /// The centre ray's hit, for the passes.
    pub aov: Vec<Option<(NullRay, SurfaceHit)>>,
    /// How many samples saw each object and each material (with the passes).
    pub seen: Vec<[Counts; 2]>,
    /// Whether the passes are rendered.
    pub passes: bool,
}

impl Gathered {
    /// The tile's pixels, and how many came out NaN or infinite (made black).
    pub fn pixels(
        mut self,
        coords: &[(u32, u32)],
        n: u32,
        scene: &Scene,
        world: &World,
        cam: &CameraRays,
    ) -> (Vec<TilePixel>, u64) {
        let transparent = scene.image.is_transparent();
        let mut nonfinite = 0;
        // Depth is measured in the camera's rest frame, from the imaging event.
        let (to_camera, eye) = (
            crate::spacetime::Boost::to_rest(&scene.camera.velocity),
            scene.camera.imaging_event(),
        );
        let pixels = coords
            .iter()
            .enumerate()
            .map(|(k, &(x, y))| {
                let mut c = self.sum[k] / n as f64;
                if !c.is_finite() {
                    nonfinite += 1;
                    c = DVec3::ZERO;
                }
                let mut value = PixelValue {
                    color: c.to_array().map(to_f32),
                    alpha: if transparent {
                        self.covered[k] as f32 / n as f32
                    } else {
                        1.0
                    },
                    ..Default::default()
                };
                if let Some((r, hit)) = &self.aov[k] {
                    fill_passes(&mut value, r, hit, world, cam, (scene, &to_camera, eye));
                } else if self.passes {
                    value.depth = super::super::DEPTH_FAR;
                }
                let mattes =
                    self.seen
                        .get_mut(k)
                        .map_or(Mattes::default(), |[objects, materials]| Mattes {
                            object: ranked(objects, n),
                            material: ranked(materials, n),
                        });
                TilePixel {
                    x,
                    y,
                    value,
                    mattes,
                }
            })
            .collect();
        (pixels, nonfinite)
    }
}

/// The passes of a pixel whose centre ray `r` met `hit`: lookback, Doppler factor, ids, normal,
/// positions (world, rest frame, and the camera's frame: into it by `to_camera`, from the
/// imaging event `eye`) and depth.
fn fill_passes(
    value: &mut PixelValue,
    r: &NullRay,
    hit: &SurfaceHit,
    world: &World,
    cam: &CameraRays,
    (scene, to_camera, eye): (&Scene, &crate::spacetime::Boost, crate::spacetime::Event),
) {
    let g = &world.groups[hit.group];
    let nrm = crate::render::world::surface_normal(g, hit, r.at(hit.lambda));
    value.lookback = to_f32(hit.lambda);
    value.doppler = to_f32(cam.lookback_factor_of(r) / hit.s);
    let part = g.geometry.part_of(hit.prim);
    value.object_id = part.object + 1;
    value.material_id = part.material + 1;
    value.primitive_id = g.geometry.index_in_object(hit.prim) + 1;
    value.normal = [nrm.x as f32, nrm.y as f32, nrm.z as f32];
    let p = r.at(hit.lambda).x;
    value.position = p.to_array().map(to_f32);
    let q = hit.point;
    value.rest_position = q.to_array().map(to_f32);
    let seen_at = to_camera.event(r.at(hit.lambda) - eye).x;
    let c = &scene.camera;
    let on_axes = [c.right, c.up, c.forward].map(|a| to_f32(seen_at.dot(a)));
    value.camera_position = on_axes;
    value.depth = on_axes[2];
}

/// An f64 value as f32, saturating at f32's largest finite values (radiance under a strong
/// searchlight can exceed f32's range; an image holds no infinity).
fn to_f32(v: f64) -> f32 {
    v.clamp(-f64::from(f32::MAX), f64::from(f32::MAX)) as f32
}

/// How many samples saw each id (index + 1), in the order first seen.
pub(super) type Counts = smallvec::SmallVec<[(u32, u32); 4]>;

pub(super) fn count(counts: &mut Counts, id: u32) {
    match counts.iter_mut().find(|(i, _)| *i == id) {
        Some((_, c)) => *c += 1,
        None => counts.push((id, 1)),
    }
}

/// The ids with the most samples, most first (ties by id, so the order is the same on every
/// run), as (id, share of the `n` samples).
fn ranked(counts: &mut Counts, n: u32) -> [(u32, f32); MATTE_RANKS] {
    counts.sort_unstable_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let mut out = [(0, 0.0); MATTE_RANKS];
    for (slot, &(id, c)) in out.iter_mut().zip(counts.iter()) {
        *slot = (id, c as f32 / n as f32);
    }
    out
}
