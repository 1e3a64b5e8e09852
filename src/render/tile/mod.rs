//! A tile of pixels: its primary rays (in 4 × 4 blocks, so a 16-wide packet is a square of
//! neighbouring pixels), traced together through every group, then shaded one by one; what its
//! samples gathered becomes its pixels in `gathered`.

mod gathered;

use super::band::{Band, Seen};
use super::camera::CameraRays;
use super::path::{sample_rng, Emitters, PathTracer, Start, WaveScratch};
use super::sampler::{sample_offset, shutter_offset};
use super::screen_cull::ScreenCull;
use super::shade::{Lit, Shader, ShadowQuery, Spread};
use super::star_pixels::{StarCones, StarPixels};
use super::world::{PrimaryHits, ShadowBuffers, SurfaceHit, World};
use super::{Passes, TILE};
use crate::scene::Scene;
use crate::spacetime::NullRay;
use gathered::{count, Counts, Gathered};
use glam::DVec3;

pub use gathered::TilePixel;

/// The 4 × 4 blocks of the tile at (x0, y0), clipped to the image, in packet order: each
/// block's top-left pixel and its width and height.
fn blocks(x0: u32, y0: u32, w: u32, h: u32) -> impl Iterator<Item = (u32, u32, u32, u32)> {
    let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
    (y0..y1).step_by(4).flat_map(move |by| {
        (x0..x1)
            .step_by(4)
            .map(move |bx| (bx, by, (bx + 4).min(x1) - bx, (by + 4).min(y1) - by))
    })
}

/// The pixels of the tile at (x0, y0), clipped to the image, in 4 × 4 blocks.
pub(crate) fn tile_pixels(x0: u32, y0: u32, w: u32, h: u32) -> Vec<(u32, u32)> {
    let mut v = Vec::with_capacity((TILE * TILE) as usize);
    for (bx, by, bw, bh) in blocks(x0, y0, w, h) {
        for y in by..by + bh {
            v.extend((bx..bx + bw).map(|x| (x, y)));
        }
    }
    v
}

/// A round's image points, in pixels from the image's top-left corner, and where the camera's
/// shutter is open, each one's place in the exposure (−½ to ½; empty for an instant, and for
/// the pixel centres, which see from the imaging event).
#[derive(Default)]
pub(crate) struct ImagePoints {
    pub px: Vec<(f64, f64)>,
    pub times: Vec<f64>,
}

/// The image points of `coords` (frame pixels; `offset` places the frame in the full image):
/// sample `(s, n)` of each pixel in the round of samples that starts at `base`
/// (`sample_offset`, and `shutter_offset` where `shutter`), or the pixel centre for None.
pub(crate) fn image_points(
    coords: &[(u32, u32)],
    offset: (u32, u32),
    (sample, base, shutter): (Option<(u32, u32)>, u32, bool),
    points: &mut ImagePoints,
) {
    let ImagePoints { px, times } = points;
    px.clear();
    times.clear();
    let (dx, dy) = (offset.0 as f64, offset.1 as f64);
    if let (true, Some((s, n))) = (shutter, sample) {
        times.extend(
            coords
                .iter()
                .map(|&(fx, fy)| shutter_offset(fx + offset.0, fy + offset.1, s, n, base)),
        );
    }
    match sample {
        Some((s, n)) if n > 1 || base > 0 => px.extend(coords.iter().map(|&(fx, fy)| {
            let (x, y) = (fx + offset.0, fy + offset.1);
            let (ox, oy) = sample_offset(x, y, s, n, base);
            (x as f64 + ox, y as f64 + oy)
        })),
        // One sample per pixel is its centre (`sample_offset`), in a loop without the test
        // per pixel, which the compiler vectorises.
        _ => px.extend(
            coords
                .iter()
                .map(|&(fx, fy)| (fx as f64 + dx + 0.5, fy as f64 + dy + 0.5)),
        ),
    }
}

/// The primary rays of `coords` (see `image_points`).
#[cfg(feature = "embree")]
pub fn primary_rays(
    cam: &CameraRays,
    coords: &[(u32, u32)],
    offset: (u32, u32),
    sample: Option<(u32, u32)>,
    rays: &mut Vec<NullRay>,
) {
    let mut points = ImagePoints::default();
    image_points(coords, offset, (sample, 0, false), &mut points);
    rays.clear();
    rays.extend(points.px.iter().map(|&(x, y)| cam.ray(x, y)));
}

/// A tile's pixels that the screen cull keeps (frame coordinates, and their indices among
/// all the tile's pixels in `tile_pixels` order), how many pixels it has, and where the frame
/// sits in the image. The others are background: their 4 × 4 block (aligned in the frame, as
/// the tile's packets are) misses every group's cone of directions.
#[derive(Default)]
pub(crate) struct TilePixels {
    /// How many pixels the tile has, culled or not.
    pub total: usize,
    /// Where the tile's frame lies in the full image.
    pub offset: (u32, u32),
    live: Vec<usize>,
    /// The pixels not culled (frame coordinates).
    pub live_coords: Vec<(u32, u32)>,
    /// A whole tile's pixels at (0, 0) (`tile_pixels`), made on first use.
    template: Vec<(u32, u32)>,
    /// Whether `live` is every index of a whole tile (kept from one whole tile to the next).
    all_live: bool,
}

impl TilePixels {
    /// The tile at (x0, y0), in the buffers already here.
    fn fill(
        &mut self,
        scene: &Scene,
        cam: &CameraRays,
        cull: Option<&ScreenCull>,
        x0: u32,
        y0: u32,
    ) {
        let (w, h) = scene.image.frame_size();
        self.offset = scene.image.frame_offset();
        let (ox, oy) = self.offset;
        if cull.is_none() && x0 + TILE <= w && y0 + TILE <= h {
            return self.fill_whole(x0, y0);
        }
        self.total = 0;
        self.live.clear();
        self.live_coords.clear();
        self.all_live = false;
        // Tiles start at multiples of TILE in the frame, so a tile's square is its pixels'.
        let tile = cull.is_none_or(|c| c.tile_visible(cam, x0 + ox, y0 + oy));
        for (bx, by, bw, bh) in blocks(x0, y0, w, h) {
            let n = (bw * bh) as usize;
            if tile && cull.is_none_or(|c| c.block_visible(cam, bx + ox, by + oy)) {
                self.live.extend(self.total..self.total + n);
                for y in by..by + bh {
                    self.live_coords.extend((bx..bx + bw).map(|x| (x, y)));
                }
            }
            self.total += n;
        }
    }

    /// A whole tile with every pixel kept (no cull): the first whole tile's pixels moved to
    /// (x0, y0), in one pass without the blocks' bookkeeping.
    fn fill_whole(&mut self, x0: u32, y0: u32) {
        const N: usize = (TILE * TILE) as usize;
        if !self.all_live {
            self.live.clear();
            self.live.extend(0..N);
            self.all_live = true;
        }
        if self.template.is_empty() {
            self.template = tile_pixels(0, 0, TILE, TILE);
        }
        self.total = N;
        self.live_coords.clear();
        let shifted = self.template.iter().map(|&(x, y)| (x + x0, y + y0));
        self.live_coords.extend(shifted);
    }
}

/// What tracing a tile needs besides the tile, kept from one tile to the next by each worker
/// so that a tile allocates nothing once the buffers have grown (a tile's allocations, per
/// 16 × 16 pixels, were a visible share of a primary ray's cost).
#[derive(Default)]
pub struct TileScratch {
    pixels: TilePixels,
    points: ImagePoints,
    primary: PrimaryHits,
    round: RoundBuffers,
    /// The path integrator's paths (a `WaveScratch` of the band it renders in).
    wave: Option<Box<dyn std::any::Any + Send>>,
}

/// The path integrator's scratch in `slot`, of band `B` (made on first use, and anew if the
/// worker renders in another band).
fn wave_of<B: Band + Send + 'static>(
    slot: &mut Option<Box<dyn std::any::Any + Send>>,
) -> &mut WaveScratch<B> {
    if !slot.as_ref().is_some_and(|w| w.is::<WaveScratch<B>>()) {
        *slot = Some(Box::new(WaveScratch::<B>::default()));
    }
    slot.as_mut()
        .and_then(|w| w.downcast_mut())
        .expect("made above")
}

impl TileScratch {
    /// The tile at (x0, y0): its pixels, and the buffers for its image points and hits.
    pub(crate) fn tile(
        &mut self,
        scene: &Scene,
        cam: &CameraRays,
        cull: Option<&ScreenCull>,
        (x0, y0): (u32, u32),
    ) -> (
        &TilePixels,
        &mut ImagePoints,
        &mut PrimaryHits,
        &mut RoundBuffers,
    ) {
        self.pixels.fill(scene, cam, cull, x0, y0);
        (
            &self.pixels,
            &mut self.points,
            &mut self.primary,
            &mut self.round,
        )
    }

    /// [`TileScratch::tile`], and the path integrator's scratch in band `B`.
    #[allow(clippy::type_complexity)]
    fn tile_with_wave<B: Band + Send + 'static>(
        &mut self,
        scene: &Scene,
        cam: &CameraRays,
        cull: Option<&ScreenCull>,
        (x0, y0): (u32, u32),
    ) -> (
        &TilePixels,
        &mut ImagePoints,
        &mut PrimaryHits,
        &mut RoundBuffers,
        &mut WaveScratch<B>,
    ) {
        self.pixels.fill(scene, cam, cull, x0, y0);
        (
            &self.pixels,
            &mut self.points,
            &mut self.primary,
            &mut self.round,
            wave_of(&mut self.wave),
        )
    }
}

/// The colours (linear sRGB) of primary hits (background where none), into `buf.colors`, with
/// the shadow rays of all of them traced together, light by light, so they go to the backends
/// in packets; `lits` and `buf` are refilled, not made.
#[allow(clippy::too_many_arguments)]
fn shade_hits<'a, B: Band>(
    shader: &Shader<'a, B>,
    world: &World,
    cam: &CameraRays,
    primary: &PrimaryHits,
    (coords, (ox, oy)): (&[(u32, u32)], (u32, u32)),
    stars: Option<&StarPixels>,
    lits: &mut Vec<Prepared<'a>>,
    buf: &mut RoundBuffers,
) {
    // Stars seen after a bounce are found in the bundle of the pixel's solid angle.
    let spreads = shader.finds_star_cones();
    // One entry per light and hit (None where there is no shadow ray), hit-major.
    let lights = shader.light_count();
    let budget = shader.primary_budget();
    let follows = shader.follows_frames();
    let black_sky = shader.primary_misses_add_nothing();
    let RoundBuffers {
        shadows,
        visible,
        which,
        shadow,
        tmax,
        blocked,
        trees,
        colors,
    } = buf;
    shadows.clear();
    // Each ray's hit prepared for shading with the factor its light gains on the way to the
    // camera, or the camera's lookback factor along a ray that meets nothing.
    lits.clear();
    lits.extend((0..primary.len()).map(|i| {
        let ray = primary.ray(i);
        let camera_s = if follows {
            cam.lookback_factor_of(&ray)
        } else {
            1.0
        };
        match primary.hit(i) {
            Some(h) => {
                let (shift, k) = shader.arriving(camera_s, h.s, 1.0);
                let lit = shader.prepare(&ray, &h, shift, shadows);
                let lit = if spreads {
                    let (x, y) = coords[i];
                    let omega = cam.pixel_solid_angle(x + ox, y + oy);
                    lit.with_spread(omega * (cam.lookback_factor_of(&ray) / h.s).powi(2))
                } else {
                    lit
                };
                Ok((lit, k))
            }
            None => {
                shadows.extend((0..lights).map(|_| None));
                Err((camera_s, ray.dir))
            }
        }
    }));
    visible.clear();
    visible.resize(shadows.len(), false);
    for light in 0..lights {
        which.clear();
        shadow.clear();
        tmax.clear();
        // Room for a ray per hit from the first round on: no later round grows them.
        which.reserve(lits.len());
        shadow.reserve(lits.len());
        tmax.reserve(lits.len());
        blocked.reserve(lits.len());
        for (at, q) in shadows.iter().enumerate().skip(light).step_by(lights) {
            if let Some(q) = q {
                which.push(at);
                shadow.push(q.ray);
                tmax.push(q.tmax);
            }
        }
        blocked.clear();
        blocked.resize(shadow.len(), false);
        world.shadowed_many(light, (shadow, tmax), blocked, trees);
        for (&at, &b) in which.iter().zip(blocked.iter()) {
            visible[at] = !b;
        }
    }
    colors.clear();
    colors.extend(lits.iter().enumerate().map(|(k, lit)| match lit {
        Ok((l, factor)) => {
            let mine = k * lights..(k + 1) * lights;
            let mut seen = shader
                .finish(
                    l,
                    &shadows[mine],
                    |light, _| visible[k * lights + light],
                    budget,
                )
                .0;
            // The way from the hit to the camera through the scene's fog.
            if let Some(h) = primary.hit(k) {
                let ray = primary.ray(k);
                let camera_s = if follows {
                    cam.lookback_factor_of(&ray)
                } else {
                    1.0
                };
                if let Some(t) = shader.fog_over(ray.dir, camera_s, 1.0, h.lambda) {
                    seen.mul_by(&t);
                }
            }
            // The camera leg's factor, on the RGB (linear, so as on every wavelength).
            seen.to_rgb() * *factor
        }
        Err(_) if black_sky => DVec3::ZERO,
        Err((camera_s, dir)) => {
            let (x, y) = coords[k];
            missed(shader, *camera_s, *dir, stars, (x + ox, y + oy))
        }
    }));
}

/// A primary hit prepared for shading and the factor its light gains on the way to the camera,
/// or, where the ray meets nothing, the camera's lookback factor and the ray's direction.
type Prepared<'a> = Result<(Lit<'a>, f64), (f64, DVec3)>;

/// The buffers of a round of samples of a tile (a sample of each pixel), kept by the worker
/// and refilled round after round and tile after tile, so a sample allocates nothing.
#[derive(Default)]
pub(crate) struct RoundBuffers {
    /// One entry per light and hit (None where there is no shadow ray), hit-major.
    shadows: Vec<Option<ShadowQuery>>,
    visible: Vec<bool>,
    /// One light's shadow rays: where each sits in `shadows`, the rays, their lookback limits,
    /// and whether each is blocked.
    which: Vec<usize>,
    shadow: Vec<NullRay>,
    tmax: Vec<f64>,
    blocked: Vec<bool>,
    /// What the light trees work in.
    trees: ShadowBuffers,
    /// The colour (linear sRGB) of each hit.
    colors: Vec<DVec3>,
}

/// What a primary ray that meets nothing sees (along `dir`, the camera's lookback factor
/// `camera_s` for it): the sky or background, and the stars of its pixel (image coordinates).
fn missed<B: Band>(
    shader: &Shader<B>,
    camera_s: f64,
    dir: DVec3,
    stars: Option<&StarPixels>,
    (x, y): (u32, u32),
) -> DVec3 {
    let mut sky = shader.background_along(dir, camera_s, 1.0);
    // Through a fog without end: only wavelengths it does not attenuate arrive.
    let fog = shader.fog_over(dir, camera_s, 1.0, f64::INFINITY);
    if let Some(t) = &fog {
        sky.mul_by(t);
    }
    let stars = stars.map(|st| st.at(x, y) * fog.as_ref().map_or(1.0, |t| t.mean_value()));
    sky.to_rgb() + stars.unwrap_or(DVec3::ZERO)
}

/// The colours (linear sRGB) of primary hits by the path integrator, into `colors`: one path
/// per hit, its random numbers those of sample `sample` of its pixel, the paths of the round
/// traced together (`PathTracer::trace_paths`); as [`shade_hits`] where a ray meets nothing.
#[allow(clippy::too_many_arguments)]
fn shade_paths<B: Band>(
    tracer: &PathTracer<B>,
    shader: &Shader<B>,
    cam: &CameraRays,
    primary: &PrimaryHits,
    (coords, (ox, oy)): (&[(u32, u32)], (u32, u32)),
    stars: Option<&StarPixels>,
    sample: u32,
    (colors, wave): (&mut Vec<DVec3>, &mut WaveScratch<B>),
) {
    let follows = shader.follows_frames();
    let black_sky = shader.primary_misses_add_nothing();
    let seed = shader.scene.render.seed;
    let spreads = shader.finds_star_cones();
    let camera_s = |ray: &NullRay| match follows {
        true => cam.lookback_factor_of(ray),
        false => 1.0,
    };
    let starts = (0..primary.len()).filter_map(|i| {
        let h = primary.hit(i)?;
        let ray = primary.ray(i);
        let (x, y) = (coords[i].0 + ox, coords[i].1 + oy);
        // The pixel's bundle, for stars seen after mirrors and glass.
        let spread = match spreads {
            true => Spread {
                sr: cam.pixel_solid_angle(x, y),
                s: cam.lookback_factor_of(&ray),
            },
            false => Spread::NONE,
        };
        Some(Start {
            ray,
            hit: h,
            camera_s: camera_s(&ray),
            spread,
            rng: sample_rng(seed, x, y, sample),
        })
    });
    tracer.trace_paths(starts, wave);
    let mut light = wave.light().iter();
    colors.clear();
    colors.extend((0..primary.len()).map(|i| {
        let ray = primary.ray(i);
        match primary.is_hit(i) {
            true => light.next().expect("a path per hit").to_rgb(),
            false if black_sky => DVec3::ZERO,
            false => {
                let (x, y) = (coords[i].0 + ox, coords[i].1 + oy);
                missed(shader, camera_s(&ray), ray.dir, stars, (x, y))
            }
        }
    }));
}

/// What one frame's camera sees, the same for every tile: its rays, the screen cull, and the
/// stars in its pixels.
pub struct View<'a> {
    pub cam: &'a CameraRays,
    pub cull: Option<&'a ScreenCull>,
    pub stars: Option<&'a StarPixels>,
    pub cones: Option<&'a StarCones>,
    /// The glowing primitives, where the path integrator renders.
    pub emitters: Option<&'a Emitters>,
    /// The index of the first sample of this round in each pixel's samples (a progressive
    /// render's rounds; 0 otherwise).
    pub sample_base: u32,
}

pub struct TileResult {
    pub pixels: Vec<TilePixel>,
    pub primary_rays: u64,
    pub nonfinite: u64,
}

/// Render one tile, carrying light as `B` (RGB, or radiance at the camera's wavelengths) with
/// changes of frame doing what `seen` says.
#[allow(clippy::too_many_arguments)]
pub(crate) fn render_tile<B: Band + Send + 'static>(
    seen: Seen,
    scene: &Scene,
    world: &World,
    view: &View,
    (x0, y0): (u32, u32),
    passes: Passes,
    scratch: &mut TileScratch,
) -> TileResult {
    let (cam, cull) = (view.cam, view.cull);
    let (t, px, primary, round, wave) = scratch.tile_with_wave::<B>(scene, cam, cull, (x0, y0));
    let (offset, live, live_coords) = (t.offset, &t.live, &t.live_coords);
    let (w, h) = scene.image.frame_size();
    let coords = tile_pixels(x0, y0, w, h);
    let n = scene.image.samples;
    let shader = Shader::<B>::new(scene, world, seen).with_star_cones(view.cones);
    let tracer = view.emitters.map(|e| PathTracer::new(&shader, e));
    let mut sum = background_sums(&shader, scene, cam, (&coords, offset), n);
    for &k in live {
        sum[k] = DVec3::ZERO;
    }
    let mut covered = vec![0u32; coords.len()];
    let mut aov: Vec<Option<(NullRay, SurfaceHit)>> = vec![None; coords.len()];
    let mut traced = 0u64;
    // With one sample the pixel centre serves both colour and passes; with more, an extra
    // centre ray gives crisp passes (ids, lookback) that compositors expect. Colour alone needs
    // neither. With an open shutter the one sample sees from elsewhere than the imaging event, where
    // the passes are taken.
    let aov_sample = match passes {
        Passes::Colour => None,
        Passes::All if n > 1 || cam.has_shutter() => Some(n),
        Passes::All => Some(0),
    };
    let aov_pass = aov_sample == Some(n);
    // Which objects and materials each pixel's samples saw, for the mattes (with the passes).
    let mut seen: Vec<[Counts; 2]> = if aov_sample.is_some() {
        // Made, not cloned: a clone of an empty SmallVec costs more than making one.
        std::iter::repeat_with(Default::default)
            .take(coords.len())
            .collect()
    } else {
        Vec::new()
    };
    // Each hit prepared for shading; as a tile's rounds have one entry per pixel, it grows in
    // the first alone.
    let mut lits = Vec::new();
    for s in 0..n + u32::from(aov_pass) {
        let centre = s == n;
        let sample = if centre { None } else { Some((s, n)) };
        let which = (sample, view.sample_base, cam.has_shutter());
        image_points(live_coords, offset, which, px);
        traced += coords.len() as u64;
        world.primary_hits(cam, px, primary);
        if centre {
        } else if let Some(t) = &tracer {
            let at = (live_coords.as_slice(), offset);
            let index = view.sample_base + s;
            let colors = (&mut round.colors, &mut *wave);
            shade_paths(t, &shader, cam, primary, at, view.stars, index, colors);
        } else {
            let at = (live_coords.as_slice(), offset);
            let stars = view.stars;
            shade_hits(&shader, world, cam, primary, at, stars, &mut lits, round);
        }
        let colors = &round.colors;
        for (j, &k) in live.iter().enumerate() {
            if !centre {
                covered[k] += u32::from(primary.is_hit(j));
                sum[k] += colors[j];
                if let (Some(h), Some([objects, materials])) = (primary.hit(j), seen.get_mut(k)) {
                    let part = world.groups[h.group].geometry.part_of(h.prim);
                    count(objects, part.object + 1);
                    count(materials, part.material + 1);
                }
            }
            if Some(s) == aov_sample {
                aov[k] = primary.hit(j).map(|hh| (primary.ray(j), hh));
            }
        }
    }
    let gathered = Gathered {
        sum,
        covered,
        aov,
        seen,
        passes: aov_sample.is_some(),
    };
    let (pixels, nonfinite) = gathered.pixels(&coords, n, scene, world, cam);
    TileResult {
        pixels,
        primary_rays: traced,
        nonfinite,
    }
}

/// Every pixel's colour summed over its `n` samples, before any sample is traced: the
/// background in every sample, as the pixels the screen cull leaves out keep it (nothing, in a
/// transparent image). The same everywhere unless the camera moves through a background that
/// is not black (then each pixel's, as seen along its centre ray).
fn background_sums<B: Band>(
    shader: &Shader<B>,
    scene: &Scene,
    cam: &CameraRays,
    (coords, (ox, oy)): (&[(u32, u32)], (u32, u32)),
    n: u32,
) -> Vec<DVec3> {
    let still = scene.camera.velocity.is_zero()
        || !shader.follows_frames()
        || scene.image.background.is_black();
    if scene.image.is_transparent() {
        vec![DVec3::ZERO; coords.len()]
    } else if still {
        vec![n as f64 * shader.background(1.0, 1.0).to_rgb(); coords.len()]
    } else {
        coords
            .iter()
            .map(|&(x, y)| {
                let ray = cam.ray((x + ox) as f64 + 0.5, (y + oy) as f64 + 0.5);
                n as f64
                    * shader
                        .background(cam.lookback_factor_of(&ray), 1.0)
                        .to_rgb()
            })
            .collect()
    }
}
