use crate::geometry::Geometry;
use crate::spacetime::{Boost, Event, Velocity};
use crate::spectrum::{Colour, Role};
use glam::DVec3;
use std::sync::Arc;

/// How camera-frame directions map to pixels.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum Projection {
    /// Pinhole with a vertical field of view (radians).
    Pinhole {
        /// The vertical field of view, radians.
        fov_y: f64,
    },
    /// Parallel rays from an image plane that is simultaneous in the camera frame (Scott & Viner).
    Orthographic {
        /// The image plane's height, scene units.
        view_height: f64,
    },
    /// The whole sky: longitude across, latitude down, the look direction at the centre.
    Equirectangular,
}

/// The camera: at `position` at world time `time` (the imaging event), with its axes given in its
/// own rest frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Camera {
    /// Where the imaging event is (world frame).
    pub position: DVec3,
    /// When the imaging event is (world time).
    pub time: f64,
    /// The unit look direction (camera rest frame).
    pub forward: DVec3,
    /// The unit direction of the image's +x (camera rest frame).
    pub right: DVec3,
    /// The unit direction of the image's up (camera rest frame).
    pub up: DVec3,
    /// How directions map to pixels.
    pub projection: Projection,
    /// The camera's velocity in the world frame.
    pub velocity: Velocity,
    /// How long the exposure lasts in the camera's proper time, centred on the imaging event
    /// (`[camera] shutter`); 0 is an instant. Each sample sees from its own event on the
    /// camera's worldline within it.
    pub shutter: f64,
    /// Its worldline where it changes velocity (`[camera] worldline`): through the imaging
    /// event given in the scene; `velocity` is its velocity at `time`. None: uniform motion.
    pub worldline: Option<super::Worldline>,
}

impl Camera {
    /// The event of the exposure (world frame), where every primary ray starts.
    pub fn imaging_event(&self) -> Event {
        Event::new(self.time, self.position)
    }

    /// The same camera at world time `t` on its worldline (uniform: it moves with its
    /// velocity from where it is at `self.time`), with its velocity there.
    pub fn at_time(&self, t: f64) -> Camera {
        let mut c = self.clone();
        match &self.worldline {
            Some(w) => {
                c.position = w.position(t);
                c.velocity = w.velocity(t);
            }
            None => c.position = self.position + self.velocity.beta_vec() * (t - self.time),
        }
        c.time = t;
        c
    }

    /// The world time at which the camera's clock reads `tau`: it reads `time` at the imaging
    /// event the scene gives (where a worldline is anchored) and runs at the camera's proper
    /// rate. A uniformly moving camera moved by [`Camera::at_time`] has its clock set anew.
    pub fn world_time_at(&self, tau: f64) -> f64 {
        match &self.worldline {
            Some(w) => w.world_time(tau - w.anchor_time()),
            None => self.time + self.velocity.gamma() * (tau - self.time),
        }
    }
}

/// A film (`[film]`): frames at view times from `start` to `end` (inclusive, where the
/// spacing lands on it), `1 / fps` or `step` apart, in world time or on the camera's clock;
/// frame k is the camera at `start + k · spacing` on its worldline.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Film {
    /// The first frame's view time.
    pub start: f64,
    /// The last view time a frame may have.
    pub end: f64,
    /// The spacing of the frames.
    pub spacing: FrameSpacing,
    /// Whether the times are world time or the camera's clock (`clock = "proper"`).
    pub clock: Clock,
}

/// The clock a film's times are read on (`[film] clock`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize)]
pub enum Clock {
    /// World time (the default).
    #[default]
    World,
    /// The camera's proper time: it reads the camera's `time` at the imaging event.
    Proper,
}

/// How far apart a film's frames are in world time.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum FrameSpacing {
    /// Frames per unit of world time.
    Fps(f64),
    /// World time between frames.
    Step(f64),
}

/// The most frames a film may have.
pub(crate) const MAX_FRAMES: u64 = 1_000_000;

impl Film {
    /// The number of frames: every k from 0 with `time(k) <= end` (a rounding error of a part
    /// in 1e9 of the film's length does not drop the last).
    pub fn frame_count(&self) -> u64 {
        let per_unit = match self.spacing {
            FrameSpacing::Fps(f) => f,
            FrameSpacing::Step(s) => 1.0 / s,
        };
        ((self.end - self.start) * per_unit * (1.0 + 1e-9)).floor() as u64 + 1
    }

    /// The view time of frame `k`.
    pub fn time(&self, k: u64) -> f64 {
        match self.spacing {
            FrameSpacing::Fps(f) => self.start + k as f64 / f,
            FrameSpacing::Step(s) => self.start + k as f64 * s,
        }
    }
}

/// The most pixels one render's frame (the image, or its crop) may have.
pub(crate) const MAX_FRAME_PIXELS: u64 = 1 << 28;

/// The image: its size, samples, background and crop.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ImageSettings {
    /// Width of the full image, pixels.
    pub width: u32,
    /// Height of the full image, pixels.
    pub height: u32,
    /// Samples per pixel (stratified).
    pub samples: u32,
    /// What a ray that meets nothing sees: radiance of a sky at rest in the world frame.
    pub background: Colour,
    /// Render only this window `[x, y, width, height]` of the full image (pixels).
    pub crop: Option<[u32; 4]>,
    /// Whether the background is left out of the primary rays' colour (premultiplied RGB,
    /// alpha the coverage) or composited in (alpha 1). None: transparent, except for a PNG
    /// written by the command line (see [`ImageSettings::is_transparent`]).
    pub transparent: Option<bool>,
    /// The passes an EXR holds beside colour and alpha.
    pub passes: super::PassSet,
}

impl ImageSettings {
    /// Whether the render leaves the background out (the default when the scene says
    /// nothing): RGB premultiplied by alpha, so that "over" a plate in a compositor equals a
    /// render with that plate as the background.
    pub fn is_transparent(&self) -> bool {
        self.transparent.unwrap_or(true)
    }

    /// Size of the rendered frame: the crop window, or the whole image.
    pub fn frame_size(&self) -> (u32, u32) {
        self.crop
            .map_or((self.width, self.height), |c| (c[2], c[3]))
    }

    /// Full-image coordinates of the frame's pixel (0, 0).
    pub fn frame_offset(&self) -> (u32, u32) {
        self.crop.map_or((0, 0), |c| (c[0], c[1]))
    }
}

/// How light is followed: bounces, ambient light, and which relativistic effects on light apply.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RenderSettings {
    /// Reflection/refraction bounces after the primary hit.
    pub max_depth: u32,
    /// Secondary rays one primary sample may spawn, at most (see `render/ray_budget.rs`): the
    /// ray tree's cost is bounded whatever `max_depth` is.
    pub max_rays: u32,
    /// Light every surface receives in its own rest frame (a rendering convenience, not
    /// shifted), times its reflectance.
    pub ambient: Colour,
    /// Shift wavelengths at every change of frame along a path (the Doppler effect).
    pub doppler: bool,
    /// Scale radiance by D⁴ (and a point light's irradiance by D²) at every change of frame
    /// (the searchlight effect).
    pub searchlight: bool,
    /// How light is followed from the camera: Whitted's ray tree, or Monte Carlo paths.
    pub integrator: Integrator,
    /// The seed of the path integrator's random numbers: the same seed gives the same image
    /// on any number of threads.
    pub seed: u64,
    /// Whether a render warns where colours given as RGB may be seen shifted beyond the
    /// camera's band (`rgb_shift_warning = false` silences it, as `--quiet` does).
    pub rgb_shift_warning: bool,
}

/// How light is followed from the camera (`[render] integrator`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize)]
pub enum Integrator {
    /// Whitted: point lights, Phong, mirror and refracted rays (the default).
    #[default]
    Whitted,
    /// Unbiased Monte Carlo path tracing: glowing objects light others, light bounces between
    /// surfaces, rough metal and glass (src/render/path/).
    Path,
}

/// The largest `max_rays` a scene may give.
pub(crate) const MAX_RAYS: u32 = 65536;

impl Default for RenderSettings {
    /// Five bounces (every ray of their tree: 62 at most), ambient 0.1, both effects on light.
    fn default() -> Self {
        Self {
            max_depth: 5,
            max_rays: 256,
            ambient: Colour::grey(0.1, Role::Emitter),
            doppler: true,
            searchlight: true,
            integrator: Integrator::Whitted,
            seed: 0,
            rgb_shift_warning: true,
        }
    }
}

impl RenderSettings {
    /// Whether any change of frame alters the light (either switch on).
    pub fn shifts_light(&self) -> bool {
        self.doppler || self.searchlight
    }
}

/// A rest-frame surface description: Phong plus Whitted mirror and dielectric terms.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Material {
    /// The name objects refer to it by.
    pub name: String,
    /// Diffuse reflectance.
    pub color: Colour,
    /// Phong highlight's reflectance.
    pub specular: Colour,
    /// The Phong exponent.
    pub shininess: f64,
    /// The share of light mirrored (Whitted).
    pub reflect: f64,
    /// The share of light refracted (Whitted).
    pub transmit: f64,
    /// The index of refraction, for `transmit`.
    pub ior: f64,
    /// The microfacet roughness of the mirror (`reflect`) and glass (`transmit`) lobes, 0 to 1
    /// (GGX, α = roughness²): 0 is a perfect mirror and clear glass. The path integrator's;
    /// Whitted's rays are perfect.
    pub roughness: f64,
    /// Radiance emitted in the surface's rest frame (the surface then reflects nothing).
    pub emission: Option<Colour>,
    /// What fills the object (`medium`): light inside is absorbed and scattered. With
    /// `transmit` 0 the object's surface is invisible (a fog bank); with `transmit` it is glass
    /// (coloured or murky).
    pub medium: Option<Medium>,
    /// A texture giving the diffuse reflectance in place of `color`.
    pub color_texture: Option<std::sync::Arc<super::Texture>>,
    /// A texture giving the emitted radiance in place of `emission` (which then holds its first
    /// colour, so that the surface is known to emit).
    pub emission_texture: Option<std::sync::Arc<super::Texture>>,
}

/// A homogeneous medium at rest in its object's frame: absorption and scattering coefficients
/// (per unit length, spectra) and the Henyey-Greenstein asymmetry g of its scattering.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Medium {
    /// Absorption per unit length.
    pub sigma_a: Colour,
    /// Scattering per unit length.
    pub sigma_s: Colour,
    /// −1 (back) to 1 (forward); 0 scatters alike in every direction.
    pub g: f64,
}

impl Material {
    /// Whether the surface is only the boundary of a medium: light crosses it unchanged.
    pub fn is_invisible(&self) -> bool {
        self.medium.is_some() && self.transmit == 0.0
    }

    /// Every colour the material may show: its own and its textures'.
    pub fn colours(&self) -> impl Iterator<Item = &Colour> {
        [&self.color, &self.specular]
            .into_iter()
            .chain(self.emission.as_ref())
            .chain(self.medium.iter().flat_map(|m| [&m.sigma_a, &m.sigma_s]))
            .chain(self.color_texture.iter().flat_map(|t| t.colours()))
            .chain(self.emission_texture.iter().flat_map(|t| t.colours()))
    }

    /// The material of objects that name none: grey 0.8 diffuse.
    pub fn default_white() -> Material {
        Material {
            name: "default".into(),
            color: Colour::grey(0.8, Role::Reflectance),
            specular: Colour::grey(0.0, Role::Reflectance),
            shininess: 32.0,
            reflect: 0.0,
            transmit: 0.0,
            ior: 1.5,
            roughness: 0.0,
            medium: None,
            emission: None,
            color_texture: None,
            emission_texture: None,
        }
    }
}

/// An isotropic point light at rest in the frame moving at `velocity`, at `position` in that
/// frame's coordinates (whose origin passes through the world origin at world time 0).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Light {
    /// Where it is, in its own rest frame.
    pub position: DVec3,
    /// Radiant intensity in the light's rest frame: its colour times its intensity.
    pub radiance: Colour,
    /// Its velocity in the world frame.
    pub velocity: Velocity,
    /// Whether its irradiance falls off as 1/r² (else it is constant, as in the paper).
    pub inverse_square: bool,
    /// How its emission varies over its proper time: the time of the frame it rests in, whose
    /// clock reads 0 where that frame's origin passes the world origin at world time 0.
    pub timing: super::Timing,
    /// Its worldline where its velocity changes (`worldline`, or a flash on a camera whose
    /// velocity changes): then `position` and `velocity` are unused, and its clock reads the
    /// worldline's anchor time at the anchor.
    pub worldline: Option<super::Worldline>,
}

/// Objects sharing one uniform velocity; geometry in their rest frame.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Group {
    /// The name `--set group.NAME.…` refers to it by.
    pub name: String,
    /// The velocity all its objects share (world frame).
    pub velocity: Velocity,
    /// Its primitives, in its rest frame.
    pub geometry: Arc<Geometry>,
    /// For one segment of a worldline (`worldline`): the emission events at which it is
    /// seen, between two hyperplanes of simultaneity; None: all.
    pub window: Option<Box<crate::spacetime::Window>>,
    /// For a segment of constant proper acceleration: how its geometry moves through the
    /// frame it starts at rest in (`velocity` is that frame's).
    pub accelerated: Option<Accelerated>,
    /// After accelerating across its motion: the rotation (passive, X ↦ R X) from the axes of
    /// the plain boost to `velocity` to the axes its geometry is given in, a Thomas-Wigner
    /// rotation (docs/physics.md §12.7); None: those axes.
    pub turn: Option<glam::DMat3>,
}

/// Whether `b` is the piece after `a` of one worldline (the loader puts a worldline's pieces
/// side by side, and group names are unique).
fn same_worldline(a: &Group, b: &Group) -> bool {
    a.window.is_some() && b.window.is_some() && a.name == b.name
}

impl Group {
    /// The transformation from the world frame into its rest frame, in its own axes.
    pub fn to_rest(&self) -> Boost {
        let plain = Boost::to_rest(&self.velocity);
        match self.turn {
            Some(r) => plain.turned(r),
            None => plain,
        }
    }
}

/// A group's hyperbolic motion (docs/physics.md §12.7), in the frame S' it starts at rest in:
/// its origin starts at `start` and moves with proper acceleration `a` along `axis`; every
/// point keeps its place relative to the origin in the frame moving with it (Born-rigid). Its
/// geometry is its shape in that moving frame.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Accelerated {
    /// The origin's start event, in S' (in the group's axes).
    pub start: Event,
    /// The proper acceleration of the origin, a > 0.
    pub a: f64,
    /// The unit direction of the acceleration (in S', in the group's axes: turned as
    /// `Group::turn` says).
    pub axis: glam::DVec3,
    /// The origin's rapidity (relative to S') at the end of the segment.
    pub theta_end: f64,
}

/// A `[[group.object]]` of the scene, for naming what a pixel sees.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ObjectInfo {
    /// Its `name`, where it has one.
    pub name: Option<String>,
    /// Its `type` (`sphere`, `box`, `lattice`, …).
    pub kind: String,
    /// The index of its group in [`Scene::groups`].
    pub group: usize,
}

/// A loaded scene (see docs/scene-format.md): what a render needs, validated.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Scene {
    /// The camera and its imaging event.
    pub camera: Camera,
    /// The image.
    pub image: ImageSettings,
    /// How light is followed.
    pub render: RenderSettings,
    /// The materials, by index.
    pub materials: Vec<Material>,
    /// The point lights.
    pub lights: Vec<Light>,
    /// The velocity groups.
    pub groups: Vec<Group>,
    /// Every `[[group.object]]` in file order; `object_id` in the output is index + 1.
    pub objects: Vec<ObjectInfo>,
    /// The film, if the scene is one.
    pub film: Option<Film>,
    /// The sky every ray that meets nothing sees, in place of the image's background.
    pub sky: Option<super::Sky>,
    /// A fog filling all space outside objects (`[fog]`), at rest in a group's frame.
    pub fog: Option<Fog>,
    /// What the scene's files hold that it does not take (a glTF file's unmapped extensions,
    /// say), one sentence each, for the user to be told.
    pub warnings: Vec<String>,
    /// The files its load read beside the scene file (textures, sky maps, meshes, glTF files
    /// and theirs), as given or found: a render's output must not be one of them.
    #[serde(skip)]
    pub inputs: Vec<std::path::PathBuf>,
}

/// A homogeneous medium everywhere outside objects, at rest in a group's frame. Its medium is
/// the invisible material `materials[material]` (one no object uses), so it is crossed and
/// scattered in as a fog bank's is.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Fog {
    /// The scene group whose rest frame it is at rest in.
    pub group: usize,
    /// Its material's index (a medium and no surface).
    pub material: u32,
}

impl Scene {
    /// The scene as frame `k` of its film sees it: the camera at the frame's view time on its
    /// worldline. None if the scene is not a film.
    pub fn film_frame(&self, k: u64) -> Option<Scene> {
        let film = self.film.as_ref()?;
        let mut s = self.clone();
        let t = match film.clock {
            Clock::World => film.time(k),
            Clock::Proper => self.camera.world_time_at(film.time(k)),
        };
        s.camera = self.camera.at_time(t);
        Some(s)
    }

    /// The whole scene, camera and lights moved by a spacetime translation `shift` (world
    /// frame). Physics is translation-invariant, so the image must not change; each group's
    /// rest-frame geometry moves by the spatial part of the shift as that group measures it.
    pub fn translated(&self, shift: Event) -> Scene {
        let mut s = self.clone();
        s.camera.position += shift.x;
        s.camera.time += shift.t;
        s.camera.worldline = s.camera.worldline.as_ref().map(|w| w.translated(shift));
        for l in &mut s.lights {
            match &l.worldline {
                Some(w) => {
                    // The clock moves with the anchor: it reads the same at the moved events.
                    l.worldline = Some(w.translated(shift));
                    l.timing = l.timing.delayed(shift.t);
                }
                None => {
                    let own = Boost::to_rest(&l.velocity).event(shift);
                    l.position += own.x;
                    l.timing = l.timing.delayed(own.t);
                }
            }
        }
        for g in &mut s.groups {
            if let Some(w) = g.window.as_deref_mut() {
                *w = w.translated(shift);
            }
            let own = g.to_rest().event(shift);
            match &mut g.accelerated {
                // Its shape is in the frame moving with it: its start moves instead.
                Some(acc) => acc.start = acc.start + own,
                None => g.geometry = Arc::new(g.geometry.moved(own)),
            }
        }
        s
    }

    /// The memory the groups' primitives cost rendered (`memory`): listed ones one by one,
    /// instanced lattices and bar arrays by their blocks, held meshes by their triangles; and
    /// the sky's stars.
    pub fn primitive_bytes(&self) -> u64 {
        let stars = self
            .sky
            .iter()
            .flat_map(|s| &s.stars)
            .map(|f| f.count.saturating_mul(crate::memory::BYTES_PER_STAR))
            .sum::<u64>();
        // A shared mesh's placements in a group: listed when all of them together are at
        // most `INSTANCE_OVER` triangles (as the world lists them), else the mesh once for the
        // scene (the backend builds over it once for every group) and each placement its own.
        let mut held = std::collections::HashSet::new();
        let meshes: u64 = self
            .groups
            .iter()
            .map(|g| {
                let mut placed: std::collections::HashMap<
                    *const crate::geometry::IndexedMesh,
                    u64,
                > = Default::default();
                for r in &g.geometry.implicit {
                    if let crate::geometry::Implicit::Instance(m) = &r.shape {
                        *placed.entry(std::sync::Arc::as_ptr(&m.mesh)).or_default() += m.len();
                    }
                }
                g.geometry
                    .implicit
                    .iter()
                    .filter_map(|r| match &r.shape {
                        crate::geometry::Implicit::Instance(m) => Some(m),
                        _ => None,
                    })
                    .map(|m| {
                        let all = placed.insert(std::sync::Arc::as_ptr(&m.mesh), 0);
                        match all {
                            // Met before: counted at its first placement.
                            None | Some(0) => 0,
                            // The first placement met: the mesh's cost in this group.
                            Some(n) if n <= crate::geometry::INSTANCE_OVER => {
                                n.saturating_mul(crate::memory::BYTES_PER_PRIMITIVE)
                            }
                            Some(_) if held.insert(std::sync::Arc::as_ptr(&m.mesh)) => m
                                .len()
                                .saturating_mul(crate::memory::BYTES_PER_HELD_TRIANGLE),
                            Some(_) => 0,
                        }
                    })
                    .fold(0, u64::saturating_add)
            })
            .fold(0, u64::saturating_add);
        stars.saturating_add(meshes).saturating_add(
            self.groups
                .iter()
                .map(|g| {
                    let held = g.geometry.prims.len() as u64 * crate::memory::BYTES_PER_PRIMITIVE;
                    let implicit: u64 = g
                        .geometry
                        .implicit
                        .iter()
                        .map(|r| crate::memory::implicit_bytes(&r.shape))
                        .sum();
                    held.saturating_add(implicit)
                })
                .fold(0, u64::saturating_add),
        )
    }

    /// The groups as the scene file names them: of a worldline's pieces (groups of one name,
    /// each seen in its own window of emission times) the first alone.
    pub fn named_groups(&self) -> impl Iterator<Item = &Group> {
        let g = &self.groups;
        (0..g.len())
            .filter(move |&i| i == 0 || !same_worldline(&g[i - 1], &g[i]))
            .map(move |i| &g[i])
    }

    /// For a group that is a piece of a worldline: which piece it is, from 1, and how many
    /// the worldline has.
    pub fn worldline_piece(&self, i: usize) -> Option<(usize, usize)> {
        let g = &self.groups;
        g[i].window.as_ref()?;
        let first = (1..=i)
            .rev()
            .take_while(|&j| same_worldline(&g[j - 1], &g[j]))
            .count();
        let after = (i + 1..g.len())
            .take_while(|&j| same_worldline(&g[j - 1], &g[j]))
            .count();
        Some((first + 1, first + 1 + after))
    }

    /// How many primitives all groups hold.
    pub fn primitive_count(&self) -> usize {
        self.groups.iter().map(|g| g.geometry.len() as usize).sum()
    }
}
