//! `rest-embree bench`: run time against error, for each backend and setting, on a fixed set of
//! cases (the paper's lattice at several speeds, a large lattice, many velocity groups), in one
//! run on one machine.
//!
//! Each row measures the build, the primary-ray throughput (tracing only, the renderer's own
//! tiles and packets), a full render (both the fastest of `repeat`), the peak memory, the error of the
//! render against f64 BVH references: the same samples per pixel (backend error) and 16 samples
//! (sampling error). Single-group cases also trace the same rest-frame rays with bare Embree
//! (prepared f32 rays: no camera, boosts, rebasing or hit bookkeeping; the same Embree scene and
//! primitive tests), so the relativistic layer's overhead is a ratio measured in the same run.

mod csv_table;
mod exr_writing;
mod film_cost;
mod memory;
mod path_noise;
mod path_room;
mod plot;
mod primary;
pub mod probe;
mod report;
mod scene_files;
mod suite;
mod threads;

pub(crate) use crate::scene::paper::{paper, PAPER_SCENES};
pub(crate) use primary::trace_primary;
pub(crate) use suite::{cases, many_groups};

use crate::accel::backend_by_name;
use crate::compare::{compare, Comparison};
use crate::render::{render_world, render_world_passes, Frame, Passes, World, WorldOptions};
use crate::scene::{PassSet, Scene};
use std::time::Instant;

/// A case of the suite, built only when it is run.
pub(crate) struct LazyCase {
    pub name: String,
    make: Box<dyn Fn() -> Result<Case, crate::scene::SceneError>>,
}

impl LazyCase {
    pub fn new(
        name: &str,
        make: impl Fn() -> Result<Case, crate::scene::SceneError> + 'static,
    ) -> LazyCase {
        LazyCase {
            name: name.to_string(),
            make: Box::new(make),
        }
    }

    /// A case that is already built.
    pub fn ready(case: Case) -> LazyCase {
        let name = case.name.clone();
        let cell = std::cell::RefCell::new(Some(case));
        LazyCase::new(&name, move || {
            cell.borrow_mut()
                .take()
                .ok_or_else(|| crate::scene::SceneError::new("bench", "", "a ready case runs once"))
        })
    }

    pub fn build(&self) -> Result<Case, crate::scene::SceneError> {
        (self.make)()
    }
}

pub(crate) struct Case {
    pub name: String,
    pub scene: Scene,
    pub settings: Vec<String>,
    /// Extra samples-per-pixel rows for the plain `embree` and `bvh` settings.
    pub extra_spp: Vec<u32>,
    /// Also trace the same rays with bare Embree (single-group scenes).
    pub bare: bool,
    /// Compare with a 16-spp f64 render (costly for the large cases).
    pub hi_reference: bool,
    /// A scene measured beside this one (`beside`), with what it is: the same boxes in one
    /// group beside many groups, or the same scene with the Doppler and searchlight effects off.
    pub beside: Option<(String, Scene)>,
    /// How long making the scene took (set by `run`: making the case, less the scene beside
    /// and the writing of a generated scene's text).
    pub load_s: f64,
    /// How long writing the scene's text took, where the bench generates it (`written_in`):
    /// a command reads a file instead.
    pub text_s: f64,
    /// How long making the scene beside took (`beside`).
    pub beside_load_s: f64,
}

impl Case {
    pub fn new(name: &str, scene: Scene, settings: &[&str]) -> Case {
        Case {
            name: name.to_string(),
            scene,
            settings: settings.iter().map(|s| s.to_string()).collect(),
            extra_spp: Vec::new(),
            bare: false,
            hi_reference: true,
            beside: None,
            load_s: 0.0,
            text_s: 0.0,
            beside_load_s: 0.0,
        }
    }
    /// The scene's text was written in `text_s` seconds before it was read (a generated
    /// scene): the row's load leaves that out.
    pub fn written_in(mut self, text_s: f64) -> Case {
        self.text_s = text_s;
        self
    }
    /// Measure the scene `load` makes, which is `what`, beside this case (`beside`). Its load
    /// is timed apart: the row's load is its own scene's.
    pub fn beside(
        mut self,
        what: &str,
        load: impl FnOnce() -> Result<Scene, crate::scene::SceneError>,
    ) -> Result<Case, crate::scene::SceneError> {
        let t = Instant::now();
        let scene = load()?;
        self.beside_load_s = t.elapsed().as_secs_f64();
        self.beside = Some((what.to_string(), scene));
        Ok(self)
    }
    pub fn with_bare(mut self) -> Case {
        self.bare = true;
        self
    }
    pub fn with_spp(mut self, spp: &[u32]) -> Case {
        self.extra_spp = spp.to_vec();
        self
    }
    pub fn without_hi_reference(mut self) -> Case {
        self.hi_reference = false;
        self
    }
}

#[derive(Clone, Debug)]
pub(crate) struct Row {
    pub case: String,
    pub setting: String,
    pub spp: u32,
    pub width: u32,
    pub height: u32,
    pub primitives: usize,
    pub groups: usize,
    pub build_s: f64,
    pub primary_rays: u64,
    pub primary_s: f64,
    pub render_s: f64,
    /// The first render (fastest is `render_s`): it also builds what is built on first use.
    pub first_render_s: f64,
    pub peak_mib: Option<f64>,
    /// Making the scene (parsing its file, or generating it).
    pub load_s: f64,
    /// Writing the first render's frame as the command line would: an EXR with every pass,
    /// or a PNG of the colour alone (`colour-only` settings), or an EXR of colour and alpha
    /// (`rgba`).
    pub write_s: f64,
    /// Against the f64 BVH at the same samples per pixel.
    pub vs_same: Option<Comparison>,
    /// Against the f64 BVH at 16 samples per pixel.
    pub vs_hi: Option<Comparison>,
    /// The case's other scene on the same setting (`Case::beside`).
    pub beside: Option<Beside>,
}

/// What the case's other scene costs beside a row (`beside`).
#[derive(Clone, Debug)]
pub(crate) struct Beside {
    /// What the other scene is.
    pub what: String,
    pub build_s: f64,
    pub first_render_s: f64,
    pub render_s: f64,
}

impl Row {
    /// The whole command's time: load, build, the first render, write.
    pub fn whole_s(&self) -> f64 {
        self.load_s + self.build_s + self.first_render_s + self.write_s
    }

    pub fn mrays_per_s(&self) -> f64 {
        self.primary_rays as f64 / self.primary_s.max(1e-12) / 1e6
    }
}

/// What a setting may switch off or leave out, beside its backend's name: each word is one.
pub(crate) const SETTING_WORDS: [(&str, &str); 8] = [
    ("no-cull", "bounds and screen culling"),
    ("no-tree", "the trees over many groups"),
    ("no-merge", "merging groups of one velocity"),
    ("no-fused", "fans of primary rays"),
    ("colour-only", "the EXR passes (a PNG's render)"),
    (
        "rgba",
        "the EXR passes, but to an EXR of colour and alpha (--passes none)",
    ),
    ("instanced", "every lattice instanced, however small"),
    ("listed", "every lattice listed primitive by primitive"),
];

/// A setting: a backend name, then any of [`SETTING_WORDS`]; an unknown word is an error, so a
/// misspelt setting is never measured as another under its name.
pub(crate) fn parse_setting(setting: &str) -> crate::Result<(&str, WorldOptions, Written)> {
    let mut o = WorldOptions::default();
    let mut passes = Written::Exr(PassSet::ALL);
    let mut parts = setting.split_whitespace();
    let backend = parts.next().unwrap_or("embree");
    for p in parts {
        match p {
            "no-cull" => o.bounds_cull = false,
            "no-tree" => o.group_tree = false,
            "no-merge" => o.merge_equal_velocities = false,
            "no-fused" => o.fused_primary = false,
            "colour-only" => passes = Written::Png,
            "rgba" => passes = Written::Exr(PassSet::NONE),
            "instanced" => o.instance_over = 0,
            "listed" => o.instance_over = u64::MAX,
            other => {
                let known: Vec<String> = SETTING_WORDS
                    .iter()
                    .map(|(w, what)| format!("{w} ({what})"))
                    .collect();
                return Err(crate::Error::flag(
                    "--backend",
                    format!(
                        "unknown word `{other}` in the setting `{setting}`; after the backend's name a setting may say: {}",
                        known.join(", ")
                    ),
                ));
            }
        }
    }
    Ok((backend, o, passes))
}

/// The file a setting's render is written to, as `render -o` would write it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Written {
    /// An EXR with these passes.
    Exr(PassSet),
    /// A PNG: colour alone.
    Png,
}

impl Written {
    /// What the renderer fills in for this file.
    pub(crate) fn passes(self) -> Passes {
        match self {
            Written::Exr(set) if !set.is_empty() => Passes::All,
            _ => Passes::Colour,
        }
    }
}

fn with_spp(scene: &Scene, spp: u32) -> Scene {
    let mut s = scene.clone();
    s.image.samples = spp;
    s
}

fn reference(scene: &Scene, spp: u32) -> crate::Result<Frame> {
    let s = with_spp(scene, spp);
    let bvh = backend_by_name("bvh")?;
    Ok(render_world(&s, &World::build(&s, bvh.as_ref())?).0)
}

/// How long a timing runs: at least `repeat` runs, and more (at most 100) until `floor_s`
/// seconds have passed, since a pass of a few milliseconds is easily slowed by anything else on
/// the machine. `--quick` keeps the floor short: its figures are a look, not a record.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Timing {
    pub repeat: usize,
    pub floor_s: f64,
}

impl Timing {
    pub(crate) fn new(repeat: usize, quick: bool) -> Timing {
        Timing {
            repeat,
            floor_s: if quick { 0.03 } else { 0.25 },
        }
    }

    /// The same floor, with at least `repeat` runs.
    fn runs(self, repeat: usize) -> Timing {
        Timing { repeat, ..self }
    }
}

/// The fastest run of `f` under `t`.
fn fastest(t: Timing, mut f: impl FnMut()) -> f64 {
    let start = Instant::now();
    let mut best = f64::INFINITY;
    let mut runs = 0;
    while runs < t.repeat.max(1) || (start.elapsed().as_secs_f64() < t.floor_s && runs < 100) {
        let t = Instant::now();
        f();
        best = best.min(t.elapsed().as_secs_f64());
        runs += 1;
    }
    best
}

/// Write `frame` to a file of this process's own in the temporary folder, as `render` would
/// write it (an EXR with every pass and its header; a PNG for colour alone), and remove it;
/// the time it took.
fn write_like_the_command(
    scene: &Scene,
    backend_name: &str,
    written: Written,
    frame: &Frame,
) -> crate::Result<f64> {
    use crate::output;
    let (ext, passes) = match written {
        Written::Png => ("png", PassSet::NONE),
        Written::Exr(set) => ("exr", set),
    };
    let path = std::env::temp_dir().join(format!("rest-embree-bench-{}.{ext}", std::process::id()));
    let t = Instant::now();
    let exr = output::ExrOptions {
        passes,
        ..output::ExrOptions::for_render(scene, backend_name, "bench", &[])
    };
    let written = output::write_with(frame, &path, &exr);
    let secs = t.elapsed().as_secs_f64();
    let _ = std::fs::remove_file(&path);
    written.map(|()| secs)
}

fn measure(case: &Case, setting: &str, spp: u32, t: Timing) -> crate::Result<(Row, Frame)> {
    let (backend_name, options, written) = parse_setting(setting)?;
    let passes = written.passes();
    let backend = backend_by_name(backend_name)?;
    let scene = with_spp(&case.scene, spp);
    memory::reset_peak();
    // The cold cost of a frame: the build, then the first render, which also builds whatever is
    // built on first use (the time slices of many groups). Before that render one untimed
    // primary pass (thread pools, page faults; renders right after a build are slow while
    // Embree's build threads wind down). Frames of milliseconds vary by tens of percent: on
    // fresh worlds, one at a time, keep the fastest build and the fastest first render.
    let (mut build_s, mut first_render_s) = (f64::INFINITY, f64::INFINITY);
    let mut kept = None;
    for i in 0..t.repeat.max(1) {
        if i > 0 && build_s + first_render_s > 0.1 {
            break;
        }
        drop(kept.take());
        let t = Instant::now();
        let world = World::build_with(&scene, backend.as_ref(), options)?;
        build_s = build_s.min(t.elapsed().as_secs_f64());
        trace_primary(&scene, &world);
        let t = Instant::now();
        let (frame, _) = render_world_passes(&scene, &world, passes);
        first_render_s = first_render_s.min(t.elapsed().as_secs_f64());
        kept = Some((world, frame));
    }
    let (world, frame) = kept.expect("at least one build");
    // Then the fastest primary pass and render: passes of a few milliseconds vary by tens of
    // percent.
    let mut primary_rays = 0;
    let primary_s = fastest(t, || primary_rays = trace_primary(&scene, &world).0);
    let render_s = first_render_s.min(fastest(t.runs(t.repeat.saturating_sub(1)), || {
        render_world_passes(&scene, &world, passes);
    }));
    // No figure of a render the backend recorded a fault in.
    world.check()?;
    let peak_mib = memory::peak_mib();
    let write_s = write_like_the_command(&scene, backend_name, written, &frame)?;
    let (w, h) = scene.image.frame_size();
    Ok((
        Row {
            case: case.name.clone(),
            setting: setting.to_string(),
            spp,
            width: w,
            height: h,
            primitives: scene.primitive_count(),
            groups: scene.groups.len(),
            build_s,
            primary_rays,
            primary_s,
            render_s,
            first_render_s,
            peak_mib,
            load_s: case.load_s,
            write_s,
            vs_same: None,
            vs_hi: None,
            beside: None,
        },
        frame,
    ))
}

/// The case's other scene (`other`, which is `what`) beside a row of `case` on `setting`: its
/// frame measured as `measure` measures one, then the warm renders of both in alternating
/// blocks, each the fastest of its passes, which count among the row's (as `bare_embree` sets
/// the layer beside bare Embree). Measured as two cases seconds apart, a slow spell of the
/// machine can fall on one side only.
fn beside(
    case: &Case,
    (what, one): (&str, &Scene),
    setting: &str,
    t: Timing,
    row: &mut Row,
) -> crate::Result<Beside> {
    let alone = Case::new(&case.name, one.clone(), &[setting]).without_hi_reference();
    let (one_row, _) = measure(&alone, setting, 1, t)?;
    let (backend_name, options, written) = parse_setting(setting)?;
    let passes = written.passes();
    let backend = backend_by_name(backend_name)?;
    let (many, one) = (with_spp(&case.scene, 1), with_spp(one, 1));
    let many_world = World::build_with(&many, backend.as_ref(), options)?;
    let one_world = World::build_with(&one, backend.as_ref(), options)?;
    let render = |scene: &Scene, world: &World| {
        render_world_passes(scene, world, passes);
    };
    render(&many, &many_world);
    render(&one, &one_world);
    let (mut many_s, mut one_s) = (row.render_s, one_row.render_s);
    for _ in 0..PAIRED_BLOCKS {
        many_s = many_s.min(fastest(t, || render(&many, &many_world)));
        one_s = one_s.min(fastest(t, || render(&one, &one_world)));
    }
    row.render_s = many_s;
    many_world.check()?;
    one_world.check()?;
    Ok(Beside {
        what: what.to_string(),
        build_s: one_row.build_s,
        first_render_s: one_row.first_render_s,
        render_s: one_s,
    })
}

/// A world of `scene` on the Embree backend `name` (`embree`, `embree-16`, …) with `options`,
/// and the Embree accelerator of its one group, shared with the world (None unless the world is
/// one group traced through an accelerator): bare Embree measured beside the layer on the same
/// structure.
#[cfg(feature = "embree")]
pub(crate) fn world_and_accel(
    scene: &Scene,
    name: &str,
    options: WorldOptions,
) -> crate::Result<(World, Option<std::sync::Arc<crate::accel::EmbreeAccel>>)> {
    use crate::accel::{Accelerator, Backend, CullerFactory, EmbreeAccel, EmbreeBackend};
    use crate::geometry::Geometry;
    use std::sync::Arc;
    /// Builds as `inner` does and keeps a handle on what it built.
    struct Keeping {
        inner: EmbreeBackend,
        built: std::sync::Mutex<Vec<Arc<EmbreeAccel>>>,
    }
    impl Backend for Keeping {
        fn name(&self) -> &'static str {
            self.inner.name()
        }
        fn build(&self, geometry: Arc<Geometry>) -> crate::Result<Box<dyn Accelerator>> {
            let accel = Arc::new(self.inner.accelerator(geometry)?);
            self.built.lock().expect("not poisoned").push(accel.clone());
            Ok(Box::new(accel))
        }
        fn cullers(&self) -> CullerFactory {
            self.inner.cullers()
        }
        fn faults(&self) -> Option<Arc<crate::accel::Faults>> {
            self.inner.faults()
        }
    }
    // As `--backend` makes it: the instruction set `REST_EMBREE_ISA` names, if any.
    let inner = crate::accel::embree_backend(name)
        .ok_or_else(|| crate::Error::flag("--backend", format!("`{name}` is no Embree backend")))?
        .configured_by_env()?;
    let backend = Keeping {
        inner,
        built: Default::default(),
    };
    let world = World::build_with(scene, &backend, options)?;
    let built = backend.built.into_inner().expect("not poisoned");
    let accel = match (world.groups.as_slice(), built.as_slice()) {
        ([_], [a]) => Some(a.clone()),
        _ => None,
    };
    Ok((world, accel))
}

/// The scene's primary rays (pixel centres, tile by tile) in the rest frame of the world's one
/// group, as bare f32 rays for `accel`.
#[cfg(feature = "embree")]
pub(crate) fn bare_rays(
    scene: &Scene,
    world: &World,
    accel: &crate::accel::EmbreeAccel,
) -> Vec<Vec<crate::accel::BareRay>> {
    let g = &world.groups[0];
    primary::primary_rays_by_tile(scene)
        .iter()
        .map(|rays| {
            rays.iter()
                .map(|r| accel.bare_ray(g.boost.event(r.origin).x, g.boost.view_dir(r.dir).0))
                .collect()
        })
        .collect()
}

/// Blocks of each side where two measurements are set side by side (`bare_embree`, `beside`).
const PAIRED_BLOCKS: usize = 3;

/// Bare Embree on the rest-frame primary rays of the scene's one group, and the layer's
/// primary pass (`trace_primary`, the "embree" setting's) on the same world, in alternating
/// blocks, each block the fastest of its warm passes (`fastest`): (rays, bare Embree's best
/// seconds, the layer's). Both trace the one Embree scene in the same stretch of time, so
/// neither the memory layout of two scenes built apart nor the machine's drift from one second
/// to the next falls on one side alone (measured apart, the layer's best pass varied far more
/// from run to run than bare Embree's). Passes alternated one by one instead would start each
/// with the other's data in the caches.
#[cfg(feature = "embree")]
fn bare_embree(case: &Case, t: Timing) -> crate::Result<Option<(u64, f64, f64)>> {
    use rayon::prelude::*;
    let (world, accel) = world_and_accel(&case.scene, "embree", WorldOptions::default())?;
    let Some(accel) = accel else {
        return Ok(None);
    };
    let tiles = bare_rays(&case.scene, &world, &accel);
    let n: u64 = tiles.iter().map(|t| t.len() as u64).sum();
    let bare = || {
        let _hits: usize = tiles.par_iter().map(|t| accel.trace_bare(t)).sum();
    };
    // One sample per pixel, as the bare rays are (and as the "embree" row's passes).
    let one_spp = with_spp(&case.scene, 1);
    let layer = || {
        trace_primary(&one_spp, &world);
    };
    let (mut bare_s, mut layer_s) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..PAIRED_BLOCKS {
        layer_s = layer_s.min(fastest(t, layer));
        bare_s = bare_s.min(fastest(t, bare));
    }
    world.check()?;
    Ok(Some((n, bare_s, layer_s)))
}

#[cfg(not(feature = "embree"))]
fn bare_embree(_: &Case, _: Timing) -> crate::Result<Option<(u64, f64, f64)>> {
    Ok(None)
}

/// Run the cases; settings whose backend is not in this build are left out.
pub(crate) fn run(
    cases: &[LazyCase],
    timing: Timing,
    mut progress: impl FnMut(&str),
) -> crate::Result<Vec<Row>> {
    let mut rows = Vec::new();
    for lazy in cases {
        progress(&lazy.name);
        let t = Instant::now();
        let mut case = lazy.build()?;
        case.load_s = t.elapsed().as_secs_f64() - case.beside_load_s - case.text_s;
        // The scene beside was made within the case's making (never before: `LazyCase::ready`
        // cases have none).
        debug_assert!(case.load_s >= 0.0, "a scene beside made outside its case");
        let case = &case;
        let mut refs: Vec<(u32, Frame)> = Vec::new();
        let hi = if case.hi_reference {
            Some(reference(&case.scene, 16)?)
        } else {
            None
        };
        for setting in &case.settings {
            if backend_by_name(parse_setting(setting)?.0).is_err() {
                continue;
            }
            let plain = matches!(
                setting.as_str(),
                "embree" | "bvh" | "embree colour-only" | "embree rgba"
            );
            let spps: Vec<u32> = std::iter::once(1)
                .chain(case.extra_spp.iter().copied().filter(|_| plain))
                .collect();
            for spp in spps {
                let (mut row, frame) = measure(case, setting, spp, timing)?;
                if let (Some((what, other)), 1, "embree" | "bvh") =
                    (&case.beside, spp, setting.as_str())
                {
                    let b = beside(case, (what, other), setting, timing, &mut row)?;
                    row.beside = Some(b);
                }
                if !refs.iter().any(|(s, _)| *s == spp) {
                    refs.push((spp, reference(&case.scene, spp)?));
                }
                let same = &refs.iter().find(|(s, _)| *s == spp).expect("just added").1;
                row.vs_same = Some(compare(&frame, same));
                row.vs_hi = hi.as_ref().map(|h| compare(&frame, h));
                rows.push(row);
            }
        }
        if case.bare {
            if let Some((n, secs, layer_s)) = bare_embree(case, timing)? {
                // The layer's passes beside bare Embree's count among the "embree" setting's.
                if let Some(e) = rows
                    .iter_mut()
                    .find(|r| r.case == case.name && r.setting == "embree" && r.spp == 1)
                {
                    e.primary_s = e.primary_s.min(layer_s);
                }
                let (w, h) = case.scene.image.frame_size();
                rows.push(Row {
                    case: case.name.clone(),
                    setting: "embree bare (no relativity)".into(),
                    spp: 1,
                    width: w,
                    height: h,
                    primitives: case.scene.primitive_count(),
                    groups: case.scene.groups.len(),
                    build_s: 0.0,
                    primary_rays: n,
                    primary_s: secs,
                    render_s: f64::NAN,
                    first_render_s: f64::NAN,
                    peak_mib: None,
                    load_s: f64::NAN,
                    write_s: f64::NAN,
                    vs_same: None,
                    vs_hi: None,
                    beside: None,
                });
            }
        }
    }
    Ok(rows)
}

pub(crate) use csv_table::csv;
pub(crate) use exr_writing::summary as exr_writing;
pub(crate) use film_cost::summary as film_cost;
pub(crate) use memory::{peak_mib, reset_peak};
pub(crate) use path_noise::summary as path_noise;
pub(crate) use path_room::summary as path_room;
pub(crate) use plot::plot_svg;
pub(crate) use report::{summary, table};
pub(crate) use scene_files::{scene_file_here, summary as scene_files};
pub(crate) use threads::summary as thread_scaling;

#[cfg(test)]
mod tests {
    use super::*;

    /// A row's load is its own scene's: the scene measured beside it is made, and timed, apart
    /// (it used to count in the row's load, and so in its whole command). Both are made slowly
    /// here, within the case's making, as the suite's are.
    #[test]
    fn a_rows_load_leaves_out_the_scene_beside() {
        use std::time::Duration;
        let small = || {
            let sets = ["image.width=8", "image.height=8"].map(String::from);
            crate::scene::paper::paper("calibration_cube", &sets)
        };
        let (own, other) = (Duration::from_millis(300), Duration::from_millis(600));
        let lazy = LazyCase::new("small", move || {
            std::thread::sleep(own);
            Case::new("small", small()?, &["bvh"])
                .without_hi_reference()
                .beside("the same, slowly", || {
                    std::thread::sleep(other);
                    small()
                })
        });
        let rows = run(&[lazy], Timing::new(1, true), |_| {}).unwrap();
        assert_eq!(rows.len(), 1);
        let load = rows[0].load_s;
        assert!(
            load >= own.as_secs_f64() && load < other.as_secs_f64(),
            "load {load} s"
        );
        assert!(rows[0].beside.is_some(), "the scene beside was measured");
    }
}
