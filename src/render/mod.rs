//! Rendering: camera rays on the past light cone of the imaging event, a boost of every ray into
//! each velocity group's rest frame, the merge of hits by world-frame lookback time, and Whitted
//! shading in the rest frame of the surface hit.

mod band;
mod camera;
mod frame;
mod optics;
mod path;
mod progress;
mod progressive;
mod ray_budget;
mod sampler;
mod screen_cull;
mod shade;
mod star_pixels;
mod tile;
mod world;

pub(crate) use band::extrapolation_warning;
pub use band::needs_spectra;
pub use frame::{pass, Frame, Mattes, PixelValue, DEPTH_FAR};
pub(crate) use frame::{CHANNELS, MATTE_RANKS};
pub use progressive::{Converged, StopAt};
pub use world::WorldOptions;

/// More worker threads than this per core only cost memory (each has a stack) and switching:
/// the command line's `--threads` and Python's `threads=` take at most this many a core.
pub const THREADS_PER_CORE: usize = 8;

/// Whether a render may run on `n` worker threads here: an error saying the limit where `n` is
/// 0 or more than [`THREADS_PER_CORE`] per core of this machine.
pub fn thread_count_ok(n: usize) -> Result<(), String> {
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    match n {
        0 => Err("must be at least 1".into()),
        n if n > THREADS_PER_CORE * cores => Err(format!(
            "{n} is more than {THREADS_PER_CORE} per core ({} on this machine's {cores} cores)",
            THREADS_PER_CORE * cores
        )),
        _ => Ok(()),
    }
}

pub(crate) use band::Seen;
pub(crate) use camera::CameraRays;
pub(crate) use progress::Progress;
pub(crate) use progressive::render as render_progressive;
pub(crate) use screen_cull::ScreenCull;
pub(crate) use tile::TileScratch;
pub(crate) use world::{simd_env_checked, RestGroups, World};
// What the bench's passes of primary rays alone reach (src/bench/primary.rs).
#[cfg(feature = "cli")]
pub(crate) use tile::image_points;
#[cfg(all(feature = "cli", feature = "embree"))]
pub(crate) use tile::{primary_rays, tile_pixels};
// What the tests of the internals reach (src/tests/).
#[cfg(test)]
pub(crate) use {
    path::Emitters,
    shade::Shader,
    tile::{render_tile, View},
    world::{apparent_box, reach_box, world_box, GroupTree, LightTree, SlicedGroupTree},
};

use crate::accel::Backend;
use crate::scene::Scene;
use crate::spectrum::Sampled;
use glam::DVec3;
use rayon::prelude::*;
use smallvec::SmallVec;
use std::time::{Duration, Instant};

pub(crate) const TILE: u32 = 16;

/// What a render did, for the command's report and the benchmarks.
#[derive(Clone, Debug, Default)]
pub struct RenderStats {
    /// Building the acceleration structures.
    pub build_time: Duration,
    /// Tracing and shading every pixel.
    pub trace_time: Duration,
    /// Primary rays traced (samples, and with several, the passes' centre rays).
    pub primary_rays: u64,
    /// Pixels whose colour came out NaN or infinite and were replaced by black (a bug if > 0).
    pub nonfinite_pixels: u64,
    /// Samples per pixel rendered, where a progressive render chose (None: the scene's).
    pub samples: Option<u32>,
}

/// What a render fills in besides the colour and alpha of each pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Passes {
    /// The extra passes too (lookback, Doppler factor, object id, normal, positions): what an
    /// EXR holds. With several samples per pixel they come from one more ray per pixel, through
    /// its centre.
    All,
    /// Colour and alpha only (what a PNG holds); the pass channels stay 0, and no ray is traced
    /// for them.
    Colour,
}

/// How to render: which passes to fill in, and what the renderer may skip or fuse.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// What to fill in besides colour and alpha.
    pub passes: Passes,
    /// The renderer's skips and fusions; each leaves the picture the same (the tests and the
    /// bench switch them off to prove it and to measure them).
    pub world: WorldOptions,
}

impl Default for RenderOptions {
    /// Every pass, every skip.
    fn default() -> Self {
        Self {
            passes: Passes::All,
            world: WorldOptions::default(),
        }
    }
}

/// Render `scene`: build one acceleration structure per velocity group with `backend`, then
/// trace every pixel. The one entry point of the library (see `examples/render_from_code.rs`).
pub fn render(
    scene: &Scene,
    backend: &dyn Backend,
    options: &RenderOptions,
) -> crate::Result<(Frame, RenderStats)> {
    let t0 = Instant::now();
    let world = World::build_with(scene, backend, options.world)?;
    let build_time = t0.elapsed();
    let t1 = Instant::now();
    let (frame, mut stats) = render_world_passes(scene, &world, options.passes);
    world.check()?;
    stats.build_time = build_time;
    stats.trace_time = t1.elapsed();
    Ok((frame, stats))
}

/// As [`render`], a strip of rows at a time, for a caller that shows progress and may stop it
/// (the Python package): after each strip `go_on(pixels_done, pixels)` says whether to go on.
/// None if it said no; the frame is the one [`render`] makes.
pub fn render_watched(
    scene: &Scene,
    backend: &dyn Backend,
    options: &RenderOptions,
    mut go_on: impl FnMut(u64, u64) -> bool,
) -> crate::Result<Option<(Frame, RenderStats)>> {
    /// Why the strips stopped: an error, or the caller.
    enum Stop {
        Failed(crate::Error),
        Asked,
    }
    impl From<crate::Error> for Stop {
        fn from(e: crate::Error) -> Stop {
            Stop::Failed(e)
        }
    }
    let t0 = Instant::now();
    let world = World::build_with(scene, backend, options.world)?;
    let build_time = t0.elapsed();
    let t1 = Instant::now();
    let (w, h) = scene.image.frame_size();
    let pixels = u64::from(w) * u64::from(h);
    let mut frame = Frame::new(w, 0);
    frame.pixels.reserve(pixels as usize);
    // Strips of about a tenth of the image: progress in tenths, a stop within one.
    let min_pixels = (pixels / 10).max(1);
    let result = render_world_in_strips(scene, &world, options.passes, min_pixels, None, |s| {
        frame.pixels.extend_from_slice(&s.pixels);
        frame.mattes.extend_from_slice(&s.mattes);
        frame.height += s.height;
        match go_on(frame.pixels.len() as u64, pixels) {
            true => Ok(()),
            false => Err(Stop::Asked),
        }
    });
    match result {
        Ok(mut stats) => {
            stats.build_time = build_time;
            stats.trace_time = t1.elapsed();
            Ok(Some((frame, stats)))
        }
        Err(Stop::Asked) => Ok(None),
        Err(Stop::Failed(e)) => Err(e),
    }
}

/// The top-left pixels of the image's tiles, row by row.
pub(crate) fn tiles(scene: &Scene) -> Vec<(u32, u32)> {
    let (w, h) = scene.image.frame_size();
    let tiles_x = w.div_ceil(TILE);
    (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..tiles_x).map(move |tx| (tx * TILE, ty * TILE)))
        .collect()
}

/// Render with acceleration structures already built. Each tile is rendered straight into
/// its place in the frame (no second copy of the image in flight).
pub(crate) fn render_world(scene: &Scene, world: &World) -> (Frame, RenderStats) {
    render_world_passes(scene, world, Passes::All)
}

/// As [`render_world`], filling in only `passes`.
pub(crate) fn render_world_passes(
    scene: &Scene,
    world: &World,
    passes: Passes,
) -> (Frame, RenderStats) {
    render_world_watched(scene, world, passes, None)
}

/// As [`render_world_passes`], counting the pixels done on `progress`.
pub(crate) fn render_world_watched(
    scene: &Scene,
    world: &World,
    passes: Passes,
    progress: Option<&Progress>,
) -> (Frame, RenderStats) {
    let (_, h) = scene.image.frame_size();
    Rows::new(scene, world, passes, progress).render(0..h)
}

/// Render the frame a strip of at least `min_pixels` pixels at a time (whole rows of tiles),
/// top to bottom, handing each strip to `put`: a large image written as it is rendered never
/// holds the whole frame. The strips hold the whole frame's pixels exactly. A strip the backend
/// recorded a fault in (`World::check`) is not handed on: the render ends with the error.
pub(crate) fn render_world_in_strips<E: From<crate::Error>>(
    scene: &Scene,
    world: &World,
    passes: Passes,
    min_pixels: u64,
    progress: Option<&Progress>,
    mut put: impl FnMut(&Frame) -> Result<(), E>,
) -> Result<RenderStats, E> {
    let (w, h) = scene.image.frame_size();
    // An even number of rows of tiles: whole 32-row blocks of an EXR (PIZ's).
    let per_thread = crate::memory::STRIP_TILE_ROWS_PER_THREAD;
    let tile_rows = min_pixels
        .div_ceil(u64::from(w.max(1)) * u64::from(TILE))
        .max(per_thread * rayon::current_num_threads() as u64)
        .next_multiple_of(2);
    let rows_per_strip = u32::try_from(tile_rows * u64::from(TILE)).unwrap_or(u32::MAX);
    let rows = Rows::new(scene, world, passes, progress);
    let mut stats = RenderStats::default();
    // One strip's memory, refilled strip after strip (fresh memory costs its page faults).
    let mut strip = Frame::new(0, 0);
    let mut y = 0;
    while y < h {
        let end = y.saturating_add(rows_per_strip).min(h);
        let s = rows.render_into(y..end, &mut strip);
        world.check()?;
        put(&strip)?;
        stats.primary_rays += s.primary_rays;
        stats.nonfinite_pixels += s.nonfinite_pixels;
        y = end;
    }
    Ok(stats)
}

/// What renders rows of the frame: the camera's rays, the screen cull, the kind of light.
struct Rows<'a> {
    scene: &'a Scene,
    world: &'a World,
    passes: Passes,
    cam: CameraRays,
    cull: Option<ScreenCull>,
    stars: Option<star_pixels::StarPixels>,
    cones: Option<star_pixels::StarCones>,
    /// The glowing primitives, where the path integrator renders.
    emitters: Option<path::Emitters>,
    /// The index of this round's first sample in each pixel's samples (progressive renders).
    sample_base: u32,
    spectral: bool,
    progress: Option<&'a Progress>,
}

impl<'a> Rows<'a> {
    fn new(
        scene: &'a Scene,
        world: &'a World,
        passes: Passes,
        progress: Option<&'a Progress>,
    ) -> Self {
        let cam = CameraRays::new(&scene.camera, scene.image.width, scene.image.height);
        // A sky is seen through every pixel: nothing to cull. The cull's cones are seen from the
        // imaging event, not from the other events of an open shutter.
        let cull =
            ScreenCull::new(world, &cam).filter(|_| scene.sky.is_none() && !cam.has_shutter());
        let spectral = needs_spectra(scene);
        let seen = if spectral {
            Seen::of(scene)
        } else {
            Seen::NONE
        };
        let stars = scene
            .sky
            .as_ref()
            .and_then(|sky| star_pixels::StarPixels::new(sky, &cam, seen, spectral));
        // Rays leaving after a bounce see stars too, where anything reflects or transmits.
        let bounces = scene.render.max_depth > 0
            && scene
                .materials
                .iter()
                .any(|m| m.reflect > 0.0 || m.transmit > 0.0);
        let cones = scene
            .sky
            .as_ref()
            .filter(|_| bounces)
            .and_then(star_pixels::StarCones::new);
        let emitters = (scene.render.integrator == crate::scene::Integrator::Path)
            .then(|| path::Emitters::new(scene, world));
        Self {
            scene,
            world,
            passes,
            cam,
            cull,
            stars,
            cones,
            emitters,
            sample_base: 0,
            spectral,
            progress,
        }
    }

    /// These rows as a round of samples that starts at sample `base` of each pixel.
    fn with_sample_base(mut self, base: u32) -> Self {
        self.sample_base = base;
        self
    }

    /// Rows `rows` of the frame (`rows.start` a multiple of TILE), as a frame of their own.
    fn render(&self, rows: std::ops::Range<u32>) -> (Frame, RenderStats) {
        let mut frame = Frame::new(0, 0);
        let stats = self.render_into(rows, &mut frame);
        (frame, stats)
    }

    /// Rows `rows` of the frame into `frame` (made their size, its memory reused where it
    /// has the room; every pixel is written). Each tile is a task of its own, rendered
    /// straight into its place (no second copy of the image in flight).
    fn render_into(&self, rows: std::ops::Range<u32>, frame: &mut Frame) -> RenderStats {
        debug_assert!(rows.start.is_multiple_of(TILE));
        let (scene, world, passes) = (self.scene, self.world, self.passes);
        let (w, _) = scene.image.frame_size();
        let n = (w as usize) * (rows.end - rows.start) as usize;
        (frame.width, frame.height) = (w, rows.end - rows.start);
        refill(&mut frame.pixels, n);
        if passes == Passes::All {
            refill(&mut frame.mattes, n);
        } else {
            frame.mattes.clear();
        }
        // Tiles, not rows of them, are the unit of work: a strip of few rows of tiles is
        // still shared out evenly between the threads.
        let tiles = strip_tiles(w, rows.start, &mut frame.pixels, &mut frame.mattes);
        let per_tile: Vec<(u64, u64)> = tiles
            .into_par_iter()
            .map_init(tile::TileScratch::default, |scratch, mut out| {
                let xy = (out.x0, out.y0);
                let (cam, cull) = (&self.cam, self.cull.as_ref());
                let view = tile::View {
                    cam,
                    cull,
                    stars: self.stars.as_ref(),
                    cones: self.cones.as_ref(),
                    emitters: self.emitters.as_ref(),
                    sample_base: self.sample_base,
                };
                let tile = if self.spectral {
                    let seen = Seen::of(scene);
                    tile::render_tile::<Sampled>(seen, scene, world, &view, xy, passes, scratch)
                } else {
                    let seen = Seen::NONE;
                    tile::render_tile::<DVec3>(seen, scene, world, &view, xy, passes, scratch)
                };
                if let Some(p) = self.progress {
                    p.add(tile.pixels.len() as u64);
                }
                for p in tile.pixels {
                    let (dx, dy) = ((p.x - out.x0) as usize, (p.y - out.y0) as usize);
                    out.pixels[dy][dx] = p.value;
                    if let Some(line) = out.mattes.get_mut(dy) {
                        line[dx] = p.mattes;
                    }
                }
                (tile.primary_rays, tile.nonfinite)
            })
            .collect();
        let mut stats = RenderStats::default();
        for (rays, nonfinite) in per_tile {
            stats.primary_rays += rays;
            stats.nonfinite_pixels += nonfinite;
        }
        stats
    }
}

/// Where one tile of a strip writes: its corner in the frame, and the runs of its lines in the
/// strip's pixels and mattes (no mattes in a render of colour alone).
struct TileOut<'f> {
    x0: u32,
    y0: u32,
    pixels: SmallVec<[&'f mut [PixelValue]; TILE as usize]>,
    mattes: SmallVec<[&'f mut [Mattes]; TILE as usize]>,
}

/// The tiles of a strip `w` pixels wide whose first row is the frame's `y0`, row of tiles by
/// row of tiles, left to right, each holding its own parts of `pixels` and `mattes` (empty, or
/// one per pixel).
fn strip_tiles<'f>(
    w: u32,
    y0: u32,
    pixels: &'f mut [PixelValue],
    mattes: &'f mut [Mattes],
) -> Vec<TileOut<'f>> {
    let (line, side) = ((w as usize).max(1), TILE as usize);
    let columns = line.div_ceil(side);
    let rows = pixels.len().div_ceil(line * side);
    let mut tiles: Vec<TileOut> = (0..rows * columns)
        .map(|i| TileOut {
            x0: (i % columns * side) as u32,
            y0: y0 + (i / columns * side) as u32,
            pixels: SmallVec::new(),
            mattes: SmallVec::new(),
        })
        .collect();
    for (i, run) in tile_runs(pixels, line) {
        tiles[i].pixels.push(run);
    }
    for (i, run) in tile_runs(mattes, line) {
        tiles[i].mattes.push(run);
    }
    tiles
}

/// The runs of `values` (lines `line` long, one value a pixel) that each tile of their strip
/// holds, line by line, with the tile's number (row of tiles by row, left to right).
fn tile_runs<T>(values: &mut [T], line: usize) -> impl Iterator<Item = (usize, &mut [T])> {
    let (side, columns) = (TILE as usize, line.div_ceil(TILE as usize));
    values
        .chunks_mut(line)
        .enumerate()
        .flat_map(move |(l, runs)| {
            let first = l / side * columns;
            runs.chunks_mut(side)
                .enumerate()
                .map(move |(c, run)| (first + c, run))
        })
}

/// Make `v` hold `n` values, keeping its memory where it has the room; the values it already
/// holds stay (the caller overwrites them). Fresh memory is first touched by the threads: a
/// frame of every pass is about 190 bytes a pixel, and made on one thread its page faults
/// would be a serial part of the render.
fn refill<T: Default + Send>(v: &mut Vec<T>, n: usize) {
    if v.capacity() >= n {
        v.truncate(n);
        v.resize_with(n, Default::default);
    } else {
        *v = (0..n).into_par_iter().map(|_| T::default()).collect();
    }
}
