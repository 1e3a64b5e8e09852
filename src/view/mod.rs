//! `rest-embree view SCENE`: the scene in the browser, its velocities, camera and passes on
//! controls, refined while nothing changes (docs/viewer.md). A local web server (hyper over
//! tokio, bounded in what it reads and how long it waits: `server.rs`) on 127.0.0.1 by
//! default, behind a random token, the Host and the Origin (`access.rs`); the
//! view's values become edits of the scene file (`edits.rs`), rendered at a ladder of levels
//! and cancelled by a newer view (`frames.rs`), or saved and rendered to an EXR in the
//! background (`jobs.rs`); the page is one file of HTML, style and script in the binary.

mod access;
mod edits;
mod frames;
mod jobs;
mod routes;
mod server;

use crate::accel::Backend;
use crate::render::Frame;
use crate::scene::Scene;
use std::collections::HashMap;
use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// How the viewer is started (`rest-embree view`'s flags).
#[derive(Clone, Debug)]
pub(crate) struct Config {
    /// The scene file (with `text`: the name its text goes by, its folder where its files are).
    pub scene: PathBuf,
    /// The scene's text when it is given, not read from `scene` (the Python package's).
    pub text: Option<String>,
    /// `--set` overrides written into the scene's text before it is served.
    pub overrides: Vec<(String, String)>,
    /// Where the page's URL (with its token) is sent once the server listens.
    pub tell_url: Option<std::sync::mpsc::Sender<String>>,
    pub bind: IpAddr,
    pub port: u16,
    pub backend: String,
    pub out: PathBuf,
    pub allow_hosts: Vec<String>,
    pub open_browser: bool,
}

/// The most clients whose last frame is kept (the oldest is forgotten first).
const MAX_CLIENTS: usize = 16;

/// One page's state: its newest request's number, the switch that stops that request's
/// render, and its last frame (for clicks).
struct Client {
    latest: u64,
    cancel: Arc<AtomicBool>,
    shown: Option<Arc<Shown>>,
    seen: Instant,
}

/// A frame as a click asks it: its pixels, and of its scene the view time and the objects'
/// and groups' names (not the geometry).
pub(crate) struct Shown {
    pub seq: u64,
    pub frame: Frame,
    pub time: f64,
    pub objects: Vec<crate::scene::ObjectInfo>,
    pub groups: Vec<String>,
}

impl Shown {
    fn new(seq: u64, scene: &Scene, frame: Frame) -> Shown {
        Shown {
            seq,
            frame,
            time: scene.camera.time,
            objects: scene.objects.clone(),
            groups: scene.groups.iter().map(|g| g.name.clone()).collect(),
        }
    }
}

/// What every request handler shares.
pub(crate) struct Viewer {
    access: access::Access,
    /// The scene file as given, for errors and for the folder its file paths lead from.
    source: String,
    text: String,
    editable: edits::Editable,
    /// The file's camera, which a new view time moves along its worldline.
    camera: crate::scene::Camera,
    info: serde_json::Value,
    levels: Vec<frames::Level>,
    backend: Box<dyn Backend>,
    backend_name: String,
    clients: Mutex<HashMap<String, Client>>,
    /// One frame renders at a time (it uses every core).
    render_lock: Mutex<()>,
    rendering: AtomicUsize,
    waiting: AtomicUsize,
    jobs: jobs::Jobs,
    /// The world's groups of the last view rendered, by a hash of the scene's groups.
    rest: Mutex<Option<(u64, Arc<crate::render::RestGroups>)>>,
}

/// What stops the running server (Ctrl-C, or the Python package's stop), while one runs: each
/// run has its own, so a stop asked for when none ran leaves no permit for the next.
static STOP: Mutex<Option<Arc<tokio::sync::Notify>>> = Mutex::new(None);

/// Ctrl-C while a viewer runs: stop serving and let `run` return (true); false if none runs.
pub(crate) fn interrupt() -> bool {
    match STOP.lock().map(|s| s.clone()) {
        Ok(Some(stop)) => {
            stop.notify_one();
            true
        }
        _ => false,
    }
}

/// Serve the scene until Ctrl-C.
pub(crate) fn run(config: &Config) -> crate::Result<()> {
    let viewer = Arc::new(Viewer::new(config)?);
    let addr = SocketAddr::new(config.bind, config.port);
    let listener = std::net::TcpListener::bind(addr)
        .map_err(|e| crate::Error::flag("--port", format!("cannot listen on {addr}: {e}")))?;
    let port = listener
        .local_addr()
        .map(|a| a.port())
        .unwrap_or(config.port);
    listener
        .set_nonblocking(true)
        .map_err(|e| crate::Error::flag("--port", format!("cannot listen on {addr}: {e}")))?;
    // Few threads for the connections (the work is on tokio's blocking threads and rayon's).
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| crate::Error::flag("view", format!("cannot start the server: {e}")))?;
    let stop = Arc::new(tokio::sync::Notify::new());
    let stop_mine = stop.clone();
    *STOP
        .lock()
        .map_err(|_| crate::Error::invalid("the viewer's stop was poisoned"))? = Some(stop.clone());
    let host = match config.bind {
        IpAddr::V6(a) if !a.is_unspecified() => format!("[{a}]"),
        a if a.is_unspecified() => "127.0.0.1".to_string(),
        a => a.to_string(),
    };
    let url = format!("http://{host}:{port}/?token={}", viewer.access.token());
    if let Some(tx) = &config.tell_url {
        let _ = tx.send(url.clone());
    }
    crate::text::say(format_args!(
        "rest-embree view: {} at\n  {url}",
        config.scene.display()
    ));
    if !config.bind.is_loopback() {
        crate::text::say(format_args!(
            "From another machine, through an SSH tunnel: ssh -N -L {port}:localhost:{port} THIS-HOST, then open\n  http://localhost:{port}/?token={}",
            viewer.access.token()
        ));
    }
    // A program that started it (Python's `view`) stops it its own way (`.stop()`).
    if config.tell_url.is_none() {
        crate::text::say("Ctrl-C stops it.");
    }
    if config.open_browser {
        open_browser(&url);
    }
    let served = runtime.block_on(async {
        match tokio::net::TcpListener::from_std(listener) {
            Ok(l) => {
                server::serve(l, viewer.clone(), stop).await;
                Ok(())
            }
            Err(e) => Err(crate::Error::flag(
                "--port",
                format!("cannot listen on {addr}: {e}"),
            )),
        }
    });
    // This run's stop, not a later run's (a stop asked for from another thread may have let
    // the next viewer start while this one shuts down).
    if let Ok(mut s) = STOP.lock() {
        if s.as_ref().is_some_and(|n| Arc::ptr_eq(n, &stop_mine)) {
            *s = None;
        }
    }
    served?;
    // Stop every render, and leave no half-written file.
    for c in viewer.clients.lock().expect("not poisoned").values() {
        c.cancel.store(true, Ordering::Relaxed);
    }
    runtime.shutdown_timeout(std::time::Duration::from_secs(1));
    // The process ends after the command's viewer: no half-written file is left. In the
    // Python package's process other files may be being written: left to their writers.
    if config.tell_url.is_none() {
        crate::output::file::remove_partial_files();
    }
    crate::text::say("rest-embree view: stopped");
    Ok(())
}

/// Ask the desktop to open `url`; where it cannot, the printed URL is there to copy.
fn open_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else {
        "xdg-open"
    };
    let spawned = std::process::Command::new(opener)
        .arg(url)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn();
    if spawned.is_err() {
        crate::text::warn(format_args!(
            "(could not start {opener}: open the URL above in a browser)"
        ));
    }
}

impl Viewer {
    fn new(config: &Config) -> crate::Result<Viewer> {
        let source = config.scene.display().to_string();
        // The path goes into the text the viewer saves and renders: refused where a
        // character of it could be read as more than a name.
        if source.chars().any(char::is_control) {
            return Err(crate::Error::flag(
                "view",
                format!(
                    "the scene's path `{}` has a control character (a newline, say); rename the file",
                    crate::text::shown(&source)
                ),
            ));
        }
        // Where renders of views go: a folder (made when the first is rendered), not a file.
        if config.out.exists() && !config.out.is_dir() {
            return Err(crate::Error::flag(
                "--out",
                format!(
                    "`{}` is a file, not a folder for the views' renders",
                    config.out.display()
                ),
            ));
        }
        let text = match &config.text {
            Some(t) => t.clone(),
            None => std::fs::read_to_string(&config.scene)
                .map_err(|e| crate::Error::flag("view", format!("cannot read {source}: {e}")))?,
        };
        let text = edits::with_overrides(&text, &source, &config.overrides)?;
        Viewer::from_text(
            source,
            text,
            &config.backend,
            config.out.clone(),
            config.allow_hosts.clone(),
        )
    }

    /// The viewer of the scene file `source` whose text is `text`.
    fn from_text(
        source: String,
        text: String,
        backend_name: &str,
        out: PathBuf,
        allow_hosts: Vec<String>,
    ) -> crate::Result<Viewer> {
        // The scene as the viewer will render it: loaded now so that a bad file is said at once.
        let base = edits::saved_text(&text, &source, &[]).map_err(|e| e.on_flag("view"))?;
        // A bad file is said as the file has it: the text the viewer renders has two lines
        // of its own at the top, and no film.
        let mut scene = match crate::scene::load_str(&source, &base, &[]) {
            Ok(scene) => scene,
            Err(e) => match crate::scene::load_str(&source, &text, &[]) {
                Err(in_file) => return Err(in_file.into()),
                Ok(_) => return Err(e.into()),
            },
        };
        scene.film = None;
        let backend =
            crate::accel::backend_by_name(backend_name).map_err(|e| e.on_flag("--backend"))?;
        let editable = editable(&scene);
        let levels = frames::levels(&scene.image);
        let info = info(&scene, &editable, &levels, &source);
        let mut names = allow_hosts;
        if let Some(h) = hostname() {
            names.push(h);
        }
        Ok(Viewer {
            access: access::Access::new(access::new_token()?, names),
            source,
            text,
            editable,
            camera: scene.camera.clone(),
            info,
            levels,
            backend,
            backend_name: backend_name.to_string(),
            clients: Mutex::new(HashMap::new()),
            render_lock: Mutex::new(()),
            rendering: AtomicUsize::new(0),
            waiting: AtomicUsize::new(0),
            jobs: jobs::Jobs::new(out),
            rest: Mutex::new(None),
        })
    }

    /// The scene a view's values make, at level `level` of the ladder (the last: the scene
    /// file the view saves, as it is): the user's file read once, with the view's edits as
    /// `--set` overrides (the saved file writes the same edits into its text). Errors are the
    /// 400 a request gets.
    fn scene_for(&self, view: &serde_json::Value, level: usize) -> Result<Scene, (u16, String)> {
        let mut edits = edits::edits(view, &self.editable).map_err(|e| (400, e.to_string()))?;
        edits::follow_worldline(&mut edits, &self.camera);
        let mut overrides: Vec<(String, String)> = edits
            .iter()
            .map(|e| ("the view".to_string(), e.assignment()))
            .collect();
        if level + 1 < self.levels.len() {
            let l = self.levels[level];
            overrides.extend(
                ["width", "height", "samples"]
                    .iter()
                    .zip([l.width, l.height, l.samples])
                    .map(|(k, x)| {
                        (
                            format!("the viewer's level {level}"),
                            format!("image.{k}={x}"),
                        )
                    }),
            );
        }
        let mut scene = crate::scene::load_str(&self.source, &self.text, &overrides)
            .map_err(|e| (400, e.to_string()))?;
        scene.film = None;
        Ok(scene)
    }

    /// The world's groups for `scene`: built once for each set of groups (geometry, velocities,
    /// worldlines) and kept while views change only the camera, the time or the level.
    fn rest_groups(&self, scene: &Scene) -> crate::Result<Arc<crate::render::RestGroups>> {
        let key = xxhash_rust::xxh3::xxh3_64(format!("{:?}", scene.groups).as_bytes());
        let mut held = self.rest.lock().unwrap_or_else(|p| p.into_inner());
        if let Some((k, rest)) = held.as_ref() {
            if *k == key {
                return Ok(rest.clone());
            }
        }
        // The old world is let go before the new one is built.
        *held = None;
        let rest = Arc::new(crate::render::RestGroups::build(
            scene,
            self.backend.as_ref(),
            crate::render::WorldOptions::default(),
        )?);
        *held = Some((key, rest.clone()));
        Ok(rest)
    }

    /// The scene file a view's values make: the user's file with their edits.
    fn view_text(&self, view: &serde_json::Value) -> Result<String, (u16, String)> {
        let mut edits = edits::edits(view, &self.editable).map_err(|e| (400, e.to_string()))?;
        edits::follow_worldline(&mut edits, &self.camera);
        edits::saved_text(&self.text, &self.source, &edits).map_err(|e| (400, e.to_string()))
    }
}

/// Markdown lines for the bench: how long the viewer takes from a change of the lattice's β,
/// and from a change of the view time, to the first frame of the new view as PNG bytes, on the
/// server (the same steps as a request: the edits, the scene file read, the world's groups
/// built where the groups changed, the frame rendered and encoded; not the HTTP exchange).
pub(crate) fn latency(quick: bool, backend: &str) -> crate::Result<String> {
    let viewer = Viewer::from_text(
        "scenes/lattice.toml".into(),
        include_str!("../../scenes/lattice.toml").into(),
        backend,
        std::env::temp_dir(),
        Vec::new(),
    )?;
    let n = if quick { 20 } else { 100 };
    let mut out = String::new();
    let changes: [(&str, &dyn Fn(f64) -> serde_json::Value); 2] = [
        (
            "a change of the lattice's β (its world's groups built again)",
            &|x| serde_json::json!({ "groups": { "lattice": [-(0.5 + 0.45 * x), 0.0, 0.0] } }),
        ),
        (
            "a change of the view time (the world's groups kept)",
            &|x| serde_json::json!({ "camera": { "time": 20.0 + 10.0 * x } }),
        ),
    ];
    for (what, view_at) in changes {
        let mut ms = Vec::with_capacity(n);
        let (mut w, mut h) = (0, 0);
        for k in 0..n {
            let view = view_at(k as f64 / n as f64);
            let t = Instant::now();
            let mut scene = viewer
                .scene_for(&view, 0)
                .map_err(|(_, e)| crate::Error::flag("bench", e))?;
            let rest = viewer.rest_groups(&scene)?;
            let frame = frames::render(
                &mut scene,
                &rest,
                viewer.backend.as_ref(),
                &AtomicBool::new(false),
            )
            .map_err(|e| match e {
                frames::Stopped::Failed(e) => e,
                frames::Stopped::Superseded => crate::Error::flag("bench", "stopped"),
            })?;
            let png = frames::png(&frame, "colour", false).map_err(|e| e.on_flag("bench"))?;
            ms.push(t.elapsed().as_secs_f64() * 1e3);
            std::hint::black_box(png);
            (w, h) = (frame.width, frame.height);
        }
        ms.sort_by(f64::total_cmp);
        out += &format!(
            "- viewer, {what} to the first frame of the new view ({w}x{h}, 1 spp, as PNG, on the server; {backend}): median {:.1} ms, slowest {:.1} ms of {n} changes\n",
            ms[n / 2],
            ms[n - 1]
        );
    }
    Ok(out)
}

/// This machine's name, which Host may name (a cluster node reached by its name).
fn hostname() -> Option<String> {
    let name = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::fs::read_to_string("/etc/hostname"))
        .ok()?;
    let name = name.trim().to_string();
    (!name.is_empty()).then_some(name)
}

/// The groups whose velocity the page may set: moving uniformly, one group of their name.
fn editable(scene: &Scene) -> edits::Editable {
    let mut count: HashMap<&str, usize> = HashMap::new();
    for g in &scene.groups {
        *count.entry(g.name.as_str()).or_default() += 1;
    }
    let groups = scene
        .groups
        .iter()
        // `--set group.NAME.velocity` addresses it: a name with a dot cannot be.
        .filter(|g| {
            count[g.name.as_str()] == 1
                && g.window.is_none()
                && g.accelerated.is_none()
                && !g.name.contains('.')
        })
        .map(|g| g.name.clone())
        .collect();
    edits::Editable {
        groups,
        pinhole: matches!(
            scene.camera.projection,
            crate::scene::Projection::Pinhole { .. }
        ),
    }
}

/// What the page needs to draw its controls.
fn info(
    scene: &Scene,
    editable: &edits::Editable,
    levels: &[frames::Level],
    source: &str,
) -> serde_json::Value {
    use serde_json::json;
    let c = &scene.camera;
    // Rounded to 12 significant digits for people (a field of view of 60 degrees read back
    // from radians is 59.99999999999999): the page shows these, and sends back only values
    // a control changed.
    let people = |x: f64| -> f64 {
        if x == 0.0 || !x.is_finite() {
            return x;
        }
        let scale = 10f64.powi(11 - x.abs().log10().floor() as i32);
        (x * scale).round() / scale
    };
    let v3 = |v: glam::DVec3| [people(v.x), people(v.y), people(v.z)];
    let mut seen = std::collections::HashSet::new();
    let groups: Vec<_> = scene
        .groups
        .iter()
        .filter(|g| seen.insert(g.name.clone()))
        .map(|g| {
            json!({
                "name": g.name,
                "velocity": v3(g.velocity.beta_vec()),
                "editable": editable.groups.contains(&g.name),
            })
        })
        .collect();
    let fov = match c.projection {
        crate::scene::Projection::Pinhole { fov_y } => Some(people(fov_y.to_degrees())),
        _ => None,
    };
    json!({
        "file": source,
        "levels": levels.iter().map(|l| json!({"width": l.width, "height": l.height, "samples": l.samples})).collect::<Vec<_>>(),
        "passes": frames::PASSES,
        "groups": groups,
        "camera": {
            "position": v3(c.position),
            "direction": v3(c.forward),
            "up": v3(c.up),
            "fov_y": fov,
            "time": people(c.time),
        },
        "doppler": scene.render.doppler,
        "searchlight": scene.render.searchlight,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A view that changes the camera, the time or the level reads the file once and keeps
    /// the world's groups; one that changes a group's velocity builds them again, and renders
    /// as `--set` of the same value does.
    #[test]
    fn views_keep_the_world_while_the_groups_stay() {
        let viewer = Viewer::from_text(
            "scenes/lattice.toml".into(),
            include_str!("../../scenes/lattice.toml").into(),
            "bvh",
            std::env::temp_dir(),
            Vec::new(),
        )
        .unwrap();
        let rest_of = |view: serde_json::Value, level: usize| {
            let scene = viewer.scene_for(&view, level).unwrap();
            (viewer.rest_groups(&scene).unwrap(), scene)
        };
        let (a, _) = rest_of(serde_json::json!({ "camera": { "time": 30.0 } }), 0);
        let (b, scene) = rest_of(serde_json::json!({ "camera": { "time": 31.5 } }), 1);
        assert!(Arc::ptr_eq(&a, &b), "a new time keeps the world's groups");
        assert_eq!(scene.camera.time, 31.5);
        let moved = serde_json::json!({ "groups": { "lattice": [-0.5, 0.0, 0.0] } });
        let (c, scene) = rest_of(moved, 1);
        assert!(!Arc::ptr_eq(&b, &c), "a new velocity builds them again");
        let set = crate::scene::load_str(
            "scenes/lattice.toml",
            include_str!("../../scenes/lattice.toml"),
            &[("--set".into(), "group.lattice.velocity=[-0.5, 0, 0]".into())],
        )
        .unwrap();
        assert_eq!(
            format!("{:?}", scene.groups),
            format!("{:?}", set.groups),
            "the view's velocity is --set's"
        );
    }
}
