//! "Render this view" in the background: the saved scene written to the output folder as
//! `view-N.toml`, rendered at full quality to `view-N.exr` (every pass) with its progress
//! counted, and those two files, and no others, offered for download by name.

use crate::render::{Passes, Progress, World};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

/// The most renders one server starts.
const MAX_JOBS: usize = 1000;

/// How a background render stands.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum State {
    Running,
    Done,
    Failed(String),
}

pub(crate) struct Job {
    pub id: u64,
    progress: Mutex<Option<Arc<Progress>>>,
    state: Mutex<State>,
}

impl Job {
    pub fn state(&self) -> State {
        self.state.lock().expect("not poisoned").clone()
    }

    /// The share rendered, 0 to 1.
    pub fn fraction(&self) -> f64 {
        match self.state() {
            State::Done => 1.0,
            _ => self
                .progress
                .lock()
                .expect("not poisoned")
                .as_ref()
                .map_or(0.0, |p| p.fraction()),
        }
    }

    pub fn name(&self) -> String {
        format!("view-{}", self.id)
    }
}

/// The server's background renders and their folder.
pub(crate) struct Jobs {
    dir: PathBuf,
    list: Mutex<Vec<Arc<Job>>>,
    busy: Arc<AtomicBool>,
}

impl Jobs {
    pub fn new(dir: PathBuf) -> Jobs {
        Jobs {
            dir,
            list: Mutex::new(Vec::new()),
            busy: Arc::new(AtomicBool::new(false)),
        }
    }

    /// Write `text` as the next free `view-N.toml` and render it to `view-N.exr` on a thread of
    /// its own; one at a time. `source` is the scene file the text came from: its folder is
    /// where the text's file paths lead.
    pub fn start(
        &self,
        text: String,
        source: &str,
        backend_name: &str,
    ) -> Result<Arc<Job>, (u16, String)> {
        if self.busy.swap(true, Ordering::AcqRel) {
            return Err((
                409,
                "a render of a view is running: wait for it to finish".into(),
            ));
        }
        let started = self.begin(text, source, backend_name);
        if started.is_err() {
            self.busy.store(false, Ordering::Release);
        }
        started
    }

    fn begin(
        &self,
        text: String,
        source: &str,
        backend_name: &str,
    ) -> Result<Arc<Job>, (u16, String)> {
        let mut list = self.list.lock().expect("not poisoned");
        if list.len() >= MAX_JOBS {
            return Err((
                429,
                format!("this server has rendered {MAX_JOBS} views: start it again"),
            ));
        }
        std::fs::create_dir_all(&self.dir)
            .map_err(|e| (500, format!("cannot make {}: {e}", self.dir.display())))?;
        // The first number whose files do not exist yet (a server before may have left some).
        let mut id = list.last().map_or(1, |j| j.id + 1);
        while ["toml", "exr"]
            .iter()
            .any(|ext| self.dir.join(format!("view-{id}.{ext}")).exists())
        {
            id += 1;
        }
        let job = Arc::new(Job {
            id,
            progress: Mutex::new(None),
            state: Mutex::new(State::Running),
        });
        let toml = self.dir.join(format!("{}.toml", job.name()));
        std::fs::write(&toml, &text)
            .map_err(|e| (500, format!("cannot write {}: {e}", toml.display())))?;
        let backend =
            crate::accel::backend_by_name(backend_name).map_err(|e| (500, e.to_string()))?;
        let exr = self.dir.join(format!("{}.exr", job.name()));
        let (j, source, busy) = (job.clone(), source.to_string(), self.busy.clone());
        std::thread::spawn(move || {
            let render = || -> crate::Result<()> {
                let mut scene = crate::scene::load_str(&source, &text, &[])?;
                scene.film = None;
                let (w, h) = scene.image.frame_size();
                let progress = Arc::new(Progress::silent(u64::from(w) * u64::from(h)));
                *j.progress.lock().expect("not poisoned") = Some(progress.clone());
                let world = World::build(&scene, backend.as_ref())?;
                let (frame, _) = crate::render::render_world_watched(
                    &scene,
                    &world,
                    Passes::All,
                    Some(&progress),
                );
                world.check()?;
                crate::output::write(&frame, &exr)
            };
            // A bug that panics fails the job rather than leaving it running for ever.
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(render))
                .unwrap_or_else(|_| {
                    Err(crate::Error::flag(
                        "view",
                        "the render failed inside (a bug: please report it)",
                    ))
                });
            *j.state.lock().expect("not poisoned") = match result {
                Ok(()) => State::Done,
                Err(e) => State::Failed(e.to_string()),
            };
            busy.store(false, Ordering::Release);
        });
        list.push(job.clone());
        Ok(job)
    }

    pub fn get(&self, id: u64) -> Option<Arc<Job>> {
        self.list
            .lock()
            .expect("not poisoned")
            .iter()
            .find(|j| j.id == id)
            .cloned()
    }

    /// The path of a file this server wrote, by its name alone: `view-N.toml` or `view-N.exr`
    /// of a render it started (the EXR once done). Anything else is refused: 400 for a name
    /// that is no file name (a path, `..`), 404 for one it did not write.
    pub fn file(&self, name: &str) -> Result<PathBuf, (u16, String)> {
        let bad = name.is_empty()
            || name.len() > 64
            || name.contains(['/', '\\', '\0'])
            || name.contains("..")
            || !name
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'.');
        if bad {
            return Err((400, "a file name, not a path, is needed".into()));
        }
        let not_ours = || (404, format!("no file {name} here"));
        let (stem, ext) = name.rsplit_once('.').ok_or_else(not_ours)?;
        let id: u64 = stem
            .strip_prefix("view-")
            .and_then(|n| n.parse().ok())
            .ok_or_else(not_ours)?;
        let job = self.get(id).ok_or_else(not_ours)?;
        match ext {
            "toml" => Ok(self.dir.join(name)),
            "exr" if job.state() == State::Done => Ok(self.dir.join(name)),
            _ => Err(not_ours()),
        }
    }
}
