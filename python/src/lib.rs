//! `rest_embree._native`: the library's face to Python, kept thin. Scenes load through the
//! library's loader with the command line's `--set` overrides (and its errors, as `ValueError`);
//! renders run on a thread of their own with the GIL released while the calling thread watches
//! for Ctrl-C (`KeyboardInterrupt` stops the render after the strip in hand) and reports
//! progress; frames hand their passes to Python as bytes, which `rest_embree/__init__.py` turns
//! into NumPy arrays. A panic anywhere becomes a Python exception (PyO3's), never an abort.

use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use rest_embree::render::{Frame, Passes, RenderStats};
use rest_embree::scene::Scene as RustScene;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// A library error as the exception Python code expects of it: a bad scene, key or value is a
/// `ValueError`, a file that cannot be read or written an `OSError`, the rest `RuntimeError`; the
/// message is the command line's.
fn py_err(e: rest_embree::Error) -> PyErr {
    use rest_embree::Error as E;
    let text = e.to_string();
    match e {
        E::Scene(_) | E::Invalid(_) | E::Limit(_) | E::Flag { .. } | E::Backend(_) => {
            PyValueError::new_err(text)
        }
        E::Image { .. } => PyOSError::new_err(text),
    }
}

/// A loaded scene: what the file (or text) and its overrides gave.
#[pyclass(module = "rest_embree._native", frozen)]
struct Scene {
    inner: Arc<RustScene>,
    /// The file (or the name of the text) it was loaded from, and its overrides as shown: what
    /// a file written from its render records, as the command's do.
    source: String,
    shown: Vec<String>,
}

impl Scene {
    fn new(scene: RustScene, source: String, overrides: &[(String, String)]) -> Scene {
        Scene {
            inner: Arc::new(scene),
            source,
            shown: overrides.iter().map(|(s, _)| s.clone()).collect(),
        }
    }
}

/// Load the scene file at `path` with `overrides`, each (shown, "key=value") as `--set` takes
/// them.
#[pyfunction]
fn load(path: std::path::PathBuf, overrides: Vec<(String, String)>) -> PyResult<Scene> {
    let scene = rest_embree::scene::load_file(&path, &overrides).map_err(|e| {
        let e = rest_embree::Error::from(e);
        // A file that cannot be opened (missing, a folder, no permission) is an `OSError`, as
        // for every other file; what it holds, a `ValueError`.
        let opens =
            std::fs::File::open(&path).is_ok_and(|f| f.metadata().is_ok_and(|m| !m.is_dir()));
        if opens {
            py_err(e)
        } else {
            PyOSError::new_err(e.to_string())
        }
    })?;
    Ok(Scene::new(scene, path.display().to_string(), &overrides))
}

/// Load a scene from TOML `text`, named `name` in errors (its relative file paths lead from
/// `name`'s folder).
#[pyfunction]
fn load_str(name: &str, text: &str, overrides: Vec<(String, String)>) -> PyResult<Scene> {
    let scene = rest_embree::scene::load_str(name, text, &overrides)
        .map_err(|e| py_err(rest_embree::Error::from(e)))?;
    Ok(Scene::new(scene, name.to_string(), &overrides))
}

#[pymethods]
impl Scene {
    /// (width, height) of the image.
    #[getter]
    fn size(&self) -> (u32, u32) {
        self.inner.image.frame_size()
    }

    /// The camera's view time (its clock at the imaging event).
    #[getter]
    fn time(&self) -> f64 {
        self.inner.camera.time
    }

    /// The camera's place at its imaging event (world frame) and its axes: (position, right,
    /// up, forward).
    #[getter]
    fn camera(&self) -> ([f64; 3], [f64; 3], [f64; 3], [f64; 3]) {
        let c = &self.inner.camera;
        (
            c.imaging_event().x.to_array(),
            c.right.to_array(),
            c.up.to_array(),
            c.forward.to_array(),
        )
    }

    /// The velocity groups' names, in order (a group with a worldline of several segments is
    /// named once per segment).
    #[getter]
    fn groups(&self) -> Vec<String> {
        self.inner.groups.iter().map(|g| g.name.clone()).collect()
    }

    /// Each group's velocity (units of c).
    #[getter]
    fn velocities(&self) -> Vec<[f64; 3]> {
        self.inner
            .groups
            .iter()
            .map(|g| g.velocity.beta_vec().to_array())
            .collect()
    }

    /// Every object as (name or None, kind, group index), in file order: `object_id` − 1
    /// indexes it.
    #[getter]
    fn objects(&self) -> Vec<(Option<String>, String, usize)> {
        self.inner
            .objects
            .iter()
            .map(|o| (o.name.clone(), o.kind.clone(), o.group))
            .collect()
    }

    /// The materials' names; `material_id` − 1 indexes them.
    #[getter]
    fn materials(&self) -> Vec<String> {
        self.inner
            .materials
            .iter()
            .map(|m| m.name.clone())
            .collect()
    }

    /// How many frames its film has (0: it is a still).
    #[getter]
    fn frame_count(&self) -> u64 {
        self.inner.film.as_ref().map_or(0, |f| f.frame_count())
    }

    /// Frame `k` of its film, as a scene of its own.
    fn film_frame(&self, k: u64) -> PyResult<Scene> {
        let s = self
            .inner
            .film_frame(k)
            .ok_or_else(|| PyValueError::new_err(format!("the scene has no film frame {k}")))?;
        Ok(Scene {
            inner: Arc::new(s),
            source: self.source.clone(),
            shown: self.shown.clone(),
        })
    }

    /// What its files held that it does not take, one sentence each.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner.warnings.clone()
    }

    /// Whether the image is transparent where nothing is hit (else the background is
    /// composited).
    #[getter]
    fn transparent(&self) -> bool {
        self.inner.image.transparent.unwrap_or(true)
    }
}

/// A rendered frame: its passes as bytes of f32 (or u32 for ids), row by row from the top.
#[pyclass(module = "rest_embree._native", frozen)]
struct Image {
    frame: Frame,
    stats: RenderStats,
    backend: String,
    scene: Arc<RustScene>,
    source: String,
    shown: Vec<String>,
}

#[pymethods]
impl Image {
    #[getter]
    fn width(&self) -> u32 {
        self.frame.width
    }

    #[getter]
    fn height(&self) -> u32 {
        self.frame.height
    }

    /// Linear RGBA, f32, 4 a pixel.
    fn rgba<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        let mut out = Vec::with_capacity(self.frame.pixels.len() * 16);
        for p in &self.frame.pixels {
            for v in [p.color[0], p.color[1], p.color[2], p.alpha] {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        PyBytes::new(py, &out)
    }

    /// The channel of this EXR name (`lookback`, `doppler`, `depth`, `N.X`, ...) as f32
    /// bytes; None if there is no such channel.
    fn channel<'py>(&self, py: Python<'py>, name: &str) -> Option<Bound<'py, PyBytes>> {
        let values = self.frame.channel(name)?;
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        Some(PyBytes::new(py, &bytes))
    }

    /// The ids (`object_id`, `material_id`, `primitive_id`) as u32 bytes.
    fn ids<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyBytes>> {
        let pick: fn(&rest_embree::render::PixelValue) -> u32 = match name {
            "object_id" => |p| p.object_id,
            "material_id" => |p| p.material_id,
            "primitive_id" => |p| p.primitive_id,
            _ => {
                return Err(PyValueError::new_err(format!(
                    "no id pass `{name}` (object_id, material_id, primitive_id)"
                )))
            }
        };
        let bytes: Vec<u8> = self
            .frame
            .pixels
            .iter()
            .flat_map(|p| pick(p).to_le_bytes())
            .collect();
        Ok(PyBytes::new(py, &bytes))
    }

    /// Write it as `rest-embree render` writes its file: EXR (every pass, the header's
    /// attributes, Cryptomatte) or PNG (colour; alpha only for a transparent scene), by the
    /// name's extension.
    fn save(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        py.allow_threads(|| {
            rest_embree::output::write_render(
                &self.frame,
                &path,
                &self.scene,
                &self.backend,
                &self.source,
                &self.shown,
            )
        })
        .map_err(py_err)
    }

    /// What the render measured and ran on.
    fn facts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("backend", &self.backend)?;
        d.set_item("build_seconds", self.stats.build_time.as_secs_f64())?;
        d.set_item("trace_seconds", self.stats.trace_time.as_secs_f64())?;
        d.set_item("primary_rays", self.stats.primary_rays)?;
        d.set_item("nonfinite_pixels", self.stats.nonfinite_pixels)?;
        Ok(d)
    }
}

/// Render `scene` on `backend` (None: the default) with `threads` threads (0: every core),
/// every pass or colour alone; `progress(done, total)` is called with pixels done from the
/// calling thread (a few times a second at most). Ctrl-C raises `KeyboardInterrupt` once the
/// render has stopped.
#[pyfunction]
#[pyo3(signature = (scene, backend=None, threads=0, all_passes=true, progress=None))]
fn render(
    py: Python<'_>,
    scene: &Scene,
    backend: Option<String>,
    threads: usize,
    all_passes: bool,
    progress: Option<PyObject>,
) -> PyResult<Image> {
    let name = backend.unwrap_or_else(|| rest_embree::accel::default_backend_name().to_string());
    // The command line's limit (0 here means every core): a million threads would take the
    // machine's memory and minutes to start.
    if threads > 0 {
        rest_embree::render::thread_count_ok(threads)
            .map_err(|e| PyValueError::new_err(format!("threads={threads}: {e}")))?;
    }
    // Checked here, so that a bad name is a ValueError before any thread starts.
    rest_embree::accel::backend_by_name(&name).map_err(py_err)?;
    let scene_arc = scene.inner.clone();
    let stop = Arc::new(AtomicBool::new(false));
    let done = Arc::new(AtomicU64::new(0));
    let total = {
        let (w, h) = scene_arc.image.frame_size();
        u64::from(w) * u64::from(h)
    };
    let (stop2, done2, name2) = (stop.clone(), done.clone(), name.clone());
    let options = rest_embree::RenderOptions {
        passes: if all_passes {
            Passes::All
        } else {
            Passes::Colour
        },
        ..Default::default()
    };
    let worker = std::thread::Builder::new()
        .name("rest-embree render".into())
        .spawn(move || {
            let backend = rest_embree::accel::backend_by_name(&name2)?;
            let run = || {
                rest_embree::render::render_watched(
                    &scene_arc,
                    backend.as_ref(),
                    &options,
                    |d, _| {
                        done2.store(d, Ordering::Relaxed);
                        !stop2.load(Ordering::Relaxed)
                    },
                )
            };
            match threads {
                0 => run(),
                n => rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .map_err(|e| rest_embree::Error::invalid(format!("threads={n}: {e}")))?
                    .install(run),
            }
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start the render: {e}")))?;
    let mut reported = u64::MAX;
    let mut interrupted = None;
    while !worker.is_finished() {
        py.allow_threads(|| std::thread::sleep(Duration::from_millis(20)));
        if interrupted.is_none() {
            if let Err(e) = py.check_signals() {
                stop.store(true, Ordering::Relaxed);
                interrupted = Some(e);
            }
        }
        let d = done.load(Ordering::Relaxed);
        if let (Some(cb), true) = (&progress, d != reported && interrupted.is_none()) {
            reported = d;
            if let Err(e) = cb.call1(py, (d, total)) {
                stop.store(true, Ordering::Relaxed);
                interrupted = Some(e);
            }
        }
    }
    let result = py
        .allow_threads(|| worker.join())
        .map_err(|_| PyRuntimeError::new_err("the render panicked (a bug: please report it)"))?;
    if let Some(e) = interrupted {
        return Err(e);
    }
    let Some((frame, stats)) = result.map_err(py_err)? else {
        return Err(PyRuntimeError::new_err("the render stopped"));
    };
    if let (Some(cb), false) = (&progress, reported == total) {
        cb.call1(py, (total, total))?;
    }
    Ok(Image {
        frame,
        stats,
        backend: name,
        scene: scene.inner.clone(),
        source: scene.source.clone(),
        shown: scene.shown.clone(),
    })
}

/// Every channel of an EXR file's first layer: (width, height, {name: f32 bytes}).
#[pyfunction]
fn read_exr<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
) -> PyResult<(usize, usize, Bound<'py, PyDict>)> {
    let (w, h, channels) = py
        .allow_threads(|| rest_embree::output::read_exr_channels(&path))
        .map_err(py_err)?;
    let d = PyDict::new(py);
    for (name, values) in channels {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        d.set_item(name, PyBytes::new(py, &bytes))?;
    }
    Ok((w, h, d))
}

/// The viewer [`view_start`] runs, on a thread of its own. Its lock is never held while the
/// GIL is released (another Python thread holding the GIL would wait on it for ever).
static VIEWER: std::sync::Mutex<Option<std::thread::JoinHandle<rest_embree::Result<()>>>> =
    std::sync::Mutex::new(None);
/// Whether a start is under way (between its check and its hand-over of the thread).
static STARTING: AtomicBool = AtomicBool::new(false);

fn viewer_slot() -> PyResult<
    std::sync::MutexGuard<'static, Option<std::thread::JoinHandle<rest_embree::Result<()>>>>,
> {
    VIEWER
        .lock()
        .map_err(|_| PyRuntimeError::new_err("the viewer's state was poisoned"))
}

/// Start the viewer on the scene (its file `path`, or its `text` named so) with `overrides`, on
/// 127.0.0.1:`port` (0: a free one); its URL with the token once it listens. One at a time.
#[pyfunction]
#[pyo3(signature = (path, text, overrides, port=0, backend=None))]
fn view_start(
    py: Python<'_>,
    path: std::path::PathBuf,
    text: Option<String>,
    overrides: Vec<(String, String)>,
    port: u16,
    backend: Option<String>,
) -> PyResult<String> {
    let busy = || {
        PyRuntimeError::new_err(
            "a viewer runs already in this process: stop it first (its .stop())",
        )
    };
    if viewer_slot()?.as_ref().is_some_and(|h| !h.is_finished())
        || STARTING.swap(true, Ordering::SeqCst)
    {
        return Err(busy());
    }
    let backend = backend.unwrap_or_else(|| rest_embree::accel::default_backend_name().into());
    let (tx, rx) = std::sync::mpsc::channel();
    let spawned = std::thread::Builder::new()
        .name("rest-embree viewer".into())
        .spawn(move || rest_embree::serve_viewer(path, text, overrides, port, &backend, tx));
    let handle = match spawned {
        Ok(h) => h,
        Err(e) => {
            STARTING.store(false, Ordering::SeqCst);
            return Err(PyRuntimeError::new_err(format!(
                "cannot start the viewer: {e}"
            )));
        }
    };
    let url = py.allow_threads(move || rx.recv_timeout(Duration::from_secs(120)));
    let outcome = match url {
        Ok(url) => {
            *viewer_slot()? = Some(handle);
            Ok(url)
        }
        Err(wait) => {
            // It never said it listens: stopped with an error, or still loading (then stop it).
            if matches!(wait, std::sync::mpsc::RecvTimeoutError::Timeout) {
                rest_embree::stop_viewer();
            }
            let joined = py.allow_threads(|| handle.join());
            match joined {
                Ok(Err(e)) => Err(py_err(e)),
                Ok(Ok(())) => Err(PyRuntimeError::new_err(
                    "the viewer stopped before it listened (it took more than 120 s to start)",
                )),
                Err(_) => Err(PyRuntimeError::new_err(
                    "the viewer panicked (a bug: please report it)",
                )),
            }
        }
    };
    STARTING.store(false, Ordering::SeqCst);
    outcome
}

/// Stop the viewer [`view_start`] started (nothing if none runs).
#[pyfunction]
fn view_stop(py: Python<'_>) -> PyResult<()> {
    let handle = viewer_slot()?.take();
    let Some(handle) = handle else { return Ok(()) };
    rest_embree::stop_viewer();
    match py.allow_threads(|| handle.join()) {
        Ok(result) => result.map_err(py_err),
        Err(_) => Err(PyRuntimeError::new_err(
            "the viewer panicked (a bug: please report it)",
        )),
    }
}

/// The backends this build has, the default first.
#[pyfunction]
fn backends() -> Vec<&'static str> {
    rest_embree::accel::backend_names().to_vec()
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<Scene>()?;
    m.add_class::<Image>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(load_str, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(backends, m)?)?;
    m.add_function(wrap_pyfunction!(view_start, m)?)?;
    m.add_function(wrap_pyfunction!(view_stop, m)?)?;
    Ok(())
}
