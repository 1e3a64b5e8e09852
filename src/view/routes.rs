//! The viewer's endpoints. Every request passes `access` first (403 otherwise, before any
//! work); bodies are JSON of at most 64 KiB; every error is a 4xx or 5xx with a line of text.
//!
//! - `GET /` the page; `GET /api/scene` what its controls start from; `GET /api/status` the
//!   work running;
//! - `POST /api/frame` `{client, level, pass, view}`: the view rendered at a level, as PNG;
//! - `GET /api/probe?client&x&y`: what a pixel of the client's last frame shows;
//! - `POST /api/save` `{view}`: the view as a scene file; `POST /api/render` `{view}`: that
//!   file rendered to an EXR in the background; `GET /api/job?id`: how far it is;
//! - `GET /files/NAME`: a file a render of a view wrote.

use super::{edits, frames, jobs, Client, Viewer, MAX_CLIENTS};
use serde_json::{json, Value};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// The most a request's body may hold.
pub(super) const MAX_BODY: usize = 64 * 1024;

/// A request as the endpoints see it, after the server has checked its access and read its
/// body (`server.rs`).
pub(super) struct Req<'a> {
    pub method: Method,
    pub path: &'a str,
    pub query: &'a str,
    pub body: &'a [u8],
}

/// The methods the endpoints tell apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Method {
    Get,
    Post,
    Other,
}

/// A reply: its status, headers and body (bytes, or a file the server streams).
pub(super) struct Reply {
    pub status: u16,
    pub headers: Vec<(&'static str, String)>,
    pub body: Payload,
}

pub(super) enum Payload {
    Bytes(Vec<u8>),
    File(std::fs::File),
}

impl Reply {
    fn with_header(mut self, name: &'static str, value: &str) -> Reply {
        self.headers.push((name, value.to_string()));
        self
    }
}

/// The page: its HTML with its style and script, all from the binary.
fn page() -> String {
    include_str!("page/index.html")
        .replace("/*STYLE*/", include_str!("page/style.css"))
        .replace("/*SCRIPT*/", include_str!("page/app.js"))
}

fn reply(code: u16, mime: &str, data: Vec<u8>) -> Reply {
    Reply {
        status: code,
        headers: vec![
            ("Content-Type", mime.to_string()),
            ("Cache-Control", "no-store".into()),
            ("X-Content-Type-Options", "nosniff".into()),
        ],
        body: Payload::Bytes(data),
    }
}

/// A line of text with a status.
pub(super) fn text(code: u16, message: &str) -> Reply {
    reply(
        code,
        "text/plain; charset=utf-8",
        format!("{message}\n").into_bytes(),
    )
}

fn json_reply(code: u16, v: &Value) -> Reply {
    reply(code, "application/json", v.to_string().into_bytes())
}

/// A request whose access the server has checked, answered. A bug that panics answers 500;
/// the server goes on (the panic is printed on stderr).
pub(super) fn handle(v: &Viewer, rq: &Req) -> Reply {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| route(v, rq))).unwrap_or_else(|_| {
        text(
            500,
            "internal error: this request failed (a bug: please report it)",
        )
    })
}

fn route(v: &Viewer, rq: &Req) -> Reply {
    let result = match (rq.method, rq.path) {
        (Method::Get, "/") => Ok(reply(200, "text/html; charset=utf-8", page().into_bytes())
            .with_header("X-Frame-Options", "DENY")
            .with_header("Referrer-Policy", "no-referrer")
            .with_header(
                "Content-Security-Policy",
                "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src blob:; connect-src 'self'; frame-ancestors 'none'",
            )),
        (Method::Get, "/api/scene") => Ok(json_reply(200, &v.info)),
        (Method::Get, "/api/status") => Ok(status(v)),
        (Method::Post, "/api/frame") => body(rq).and_then(|b| frame(v, &b)),
        (Method::Get, "/api/probe") => probe(v, rq.query),
        (Method::Post, "/api/save") => body(rq).and_then(|b| save(v, &b)),
        (Method::Post, "/api/render") => body(rq).and_then(|b| start_render(v, &b)),
        (Method::Get, "/api/job") => job(v, rq.query),
        (Method::Get, p) if p.starts_with("/files/") => file(v, &p["/files/".len()..]),
        (_, "/" | "/api/scene" | "/api/status" | "/api/frame" | "/api/probe" | "/api/save"
        | "/api/render" | "/api/job") => Err((405, "method not allowed here".into())),
        _ => Err((404, "no such page".into())),
    };
    result.unwrap_or_else(|(code, message)| text(code, &message))
}

type Answer = Result<Reply, (u16, String)>;

/// The request's body as JSON (the server has read at most `MAX_BODY` bytes of it).
fn body(rq: &Req) -> Result<Value, (u16, String)> {
    if rq.body.len() > MAX_BODY {
        return Err((413, format!("the body is larger than {MAX_BODY} bytes")));
    }
    serde_json::from_slice(rq.body).map_err(|e| (400, format!("the body is not JSON: {e}")))
}

fn status(v: &Viewer) -> Reply {
    let clients = v.clients.lock().expect("not poisoned").len();
    json_reply(
        200,
        &json!({
            "rendering": v.rendering.load(Ordering::Acquire),
            "waiting": v.waiting.load(Ordering::Acquire),
            "clients": clients,
        }),
    )
}

/// A client's name: the page's random one.
fn client_id(x: Option<&Value>) -> Result<String, (u16, String)> {
    let id = x.and_then(|c| c.as_str()).unwrap_or("");
    let ok = (1..=64).contains(&id.len())
        && id
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_');
    ok.then(|| id.to_string()).ok_or((
        400,
        "`client` must be 1 to 64 letters, digits, - or _".into(),
    ))
}

/// The view's text: the scene file with the view's edits.
fn view_text(v: &Viewer, body: &Value) -> Result<String, (u16, String)> {
    v.view_text(body.get("view").ok_or((400, "no `view`".to_string()))?)
}

fn frame(v: &Viewer, body: &Value) -> Answer {
    // A mistyped key (`levle`) would otherwise be dropped without a word.
    const KEYS: [&str; 5] = ["client", "seq", "level", "pass", "view"];
    if let Some(k) = body
        .as_object()
        .and_then(|o| o.keys().find(|k| !KEYS.contains(&k.as_str())))
    {
        return Err((
            400,
            format!(
                "unknown key `{}` (a frame request takes {})",
                edits::clip(k),
                KEYS.join(", ")
            ),
        ));
    }
    let client = client_id(body.get("client"))?;
    let n = v.levels.len();
    let level = body
        .get("level")
        .and_then(|l| l.as_u64())
        .filter(|&l| (l as usize) < n)
        .ok_or((400, format!("`level` must be 0 to {}", n - 1)))? as usize;
    let pass = body
        .get("pass")
        .and_then(|p| p.as_str())
        .unwrap_or("colour");
    if !frames::PASSES.contains(&pass) {
        return Err((
            400,
            format!("`pass` must be one of {}", frames::PASSES.join(", ")),
        ));
    }
    // The page numbers its requests; one without a number counts as the newest.
    // At most 2^53, the page's whole numbers: a client that jumped to u64's last would have
    // every later request refused as older.
    let seq = match body.get("seq") {
        None => None,
        Some(x) => Some(x.as_u64().filter(|&n| n <= MAX_SEQ).ok_or((
            400,
            format!("`seq` must be a whole number from 0 to {MAX_SEQ}"),
        ))?),
    };
    let view = body.get("view").ok_or((400, "no `view`".to_string()))?;
    // The view's values checked before it supersedes anything (the scene is read later).
    edits::edits(view, &v.editable).map_err(|e| (400, e.to_string()))?;
    // This request supersedes the client's earlier ones: their renders stop at their next
    // strip; an earlier one arriving late is refused here.
    let (seq, cancel) = register(v, &client, seq)?;
    let current = || {
        v.clients
            .lock()
            .expect("not poisoned")
            .get(&client)
            .is_some_and(|c| c.latest == seq)
    };
    let superseded = || (409, "superseded by a newer view".to_string());
    let turn = {
        let _waiting = Count::new(&v.waiting);
        v.render_lock.lock().unwrap_or_else(|p| p.into_inner())
    };
    if !current() {
        return Err(superseded());
    }
    // Read only now, one at a time: a drag's many requests never hold many scenes.
    let mut scene = v.scene_for(view, level)?;
    let t0 = Instant::now();
    let rendered = {
        let _rendering = Count::new(&v.rendering);
        v.rest_groups(&scene)
            .map_err(frames::Stopped::Failed)
            .and_then(|rest| frames::render(&mut scene, &rest, v.backend.as_ref(), &cancel))
    };
    let ms = t0.elapsed().as_secs_f64() * 1e3;
    drop(turn);
    let frame = match rendered {
        Ok(f) => f,
        Err(frames::Stopped::Superseded) => return Err(superseded()),
        Err(frames::Stopped::Failed(e)) => return Err((500, e.to_string())),
    };
    let png = frames::png(&frame, pass, scene.image.is_transparent())
        .map_err(|e| (500, e.to_string()))?;
    let (w, h, l, last) = (frame.width, frame.height, v.levels[level], level + 1 == n);
    {
        let mut clients = v.clients.lock().expect("not poisoned");
        match clients.get_mut(&client) {
            Some(c) if c.latest == seq => {
                c.shown = Some(Arc::new(super::Shown::new(seq, &scene, frame)));
            }
            _ => return Err(superseded()),
        }
    }
    Ok(reply(200, "image/png", png)
        .with_header("X-Seq", &seq.to_string())
        .with_header("X-Level", &level.to_string())
        .with_header("X-Final", if last { "true" } else { "false" })
        .with_header("X-Width", &w.to_string())
        .with_header("X-Height", &h.to_string())
        .with_header("X-Samples", &l.samples.to_string())
        .with_header("X-Render-Ms", &format!("{ms:.1}")))
}

/// A count of work in progress, held up while the guard lives (a panic lowers it too).
pub(super) struct Count<'a>(&'a AtomicUsize);

impl<'a> Count<'a> {
    pub(super) fn new(c: &'a AtomicUsize) -> Count<'a> {
        c.fetch_add(1, Ordering::AcqRel);
        Count(c)
    }
}

impl Drop for Count<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::AcqRel);
    }
}

/// The largest request number a client may give: 2^53, the largest whole number JavaScript
/// counts exactly.
const MAX_SEQ: u64 = 1 << 53;

/// Make request `seq` the client's newest (None: one past its newest): stop the render of the
/// one before, and forget the client seen longest ago when there are too many. A request older
/// than the client's newest is refused (409).
fn register(
    v: &Viewer,
    client: &str,
    seq: Option<u64>,
) -> Result<(u64, Arc<AtomicBool>), (u16, String)> {
    let mut clients = v.clients.lock().expect("not poisoned");
    if !clients.contains_key(client) && clients.len() >= MAX_CLIENTS {
        let oldest = clients
            .iter()
            .min_by_key(|(_, c)| c.seen)
            .map(|(k, _)| k.clone());
        if let Some(k) = oldest {
            if let Some(c) = clients.remove(&k) {
                c.cancel.store(true, Ordering::Relaxed);
            }
        }
    }
    let c = clients.entry(client.to_string()).or_insert_with(|| Client {
        latest: 0,
        cancel: Arc::new(AtomicBool::new(false)),
        shown: None,
        seen: Instant::now(),
    });
    let seq = seq.unwrap_or(c.latest.saturating_add(1));
    if seq <= c.latest {
        return Err((409, "superseded by a newer view".into()));
    }
    c.cancel.store(true, Ordering::Relaxed);
    c.latest = seq;
    c.cancel = Arc::new(AtomicBool::new(false));
    c.seen = Instant::now();
    Ok((seq, c.cancel.clone()))
}

fn query_u32(query: &str, key: &str) -> Result<u32, (u16, String)> {
    super::access::query_value(query, key)
        .and_then(|x| x.parse().ok())
        .ok_or((400, format!("`{key}` must be a whole number")))
}

fn probe(v: &Viewer, query: &str) -> Answer {
    let client = client_id(
        super::access::query_value(query, "client")
            .map(Value::String)
            .as_ref(),
    )?;
    let (x, y) = (query_u32(query, "x")?, query_u32(query, "y")?);
    let shown = v
        .clients
        .lock()
        .expect("not poisoned")
        .get(&client)
        .and_then(|c| c.shown.clone())
        .ok_or((404, "no frame shown to this client yet".to_string()))?;
    // The frame the page shows, if it says which: a newer one may have been rendered since.
    if let Some(seq) = super::access::query_value(query, "seq") {
        if seq.parse::<u64>().ok() != Some(shown.seq) {
            return Err((409, "that frame has been replaced: click again".into()));
        }
    }
    let frame = &shown.frame;
    if x >= frame.width || y >= frame.height {
        return Err((
            400,
            format!("the frame is {}x{}", frame.width, frame.height),
        ));
    }
    Ok(json_reply(200, &frames::probe(&shown, x, y)))
}

/// The view's scene, checked by loading it, as a file to download.
fn save(v: &Viewer, body: &Value) -> Answer {
    let text = view_text(v, body)?;
    crate::scene::load_str(&v.source, &text, &[]).map_err(|e| (400, e.to_string()))?;
    let stem: String = std::path::Path::new(&v.source)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || *c == '-' || *c == '_')
        .take(40)
        .collect();
    Ok(
        reply(200, "application/toml", text.into_bytes()).with_header(
            "Content-Disposition",
            &format!("attachment; filename=\"{stem}-view.toml\""),
        ),
    )
}

fn start_render(v: &Viewer, body: &Value) -> Answer {
    let text = view_text(v, body)?;
    crate::scene::load_str(&v.source, &text, &[]).map_err(|e| (400, e.to_string()))?;
    let job = v.jobs.start(text, &v.source, &v.backend_name)?;
    Ok(json_reply(200, &job_json(&job)))
}

fn job_json(job: &jobs::Job) -> Value {
    let (state, error) = match job.state() {
        jobs::State::Running => ("running", None),
        jobs::State::Done => ("done", None),
        jobs::State::Failed(e) => ("failed", Some(e)),
    };
    json!({
        "id": job.id,
        "state": state,
        "progress": job.fraction(),
        "error": error,
        "toml": format!("{}.toml", job.name()),
        "exr": format!("{}.exr", job.name()),
    })
}

fn job(v: &Viewer, query: &str) -> Answer {
    let id = query_u32(query, "id")?;
    let job = v
        .jobs
        .get(u64::from(id))
        .ok_or((404, format!("no render {id}")))?;
    Ok(json_reply(200, &job_json(&job)))
}

fn file(v: &Viewer, name: &str) -> Answer {
    let name =
        super::access::percent_decode(name).ok_or((400, "a badly escaped name".to_string()))?;
    let path = v.jobs.file(&name)?;
    let f = std::fs::File::open(&path).map_err(|e| (404, format!("{name}: {e}")))?;
    let mime = if name.ends_with(".exr") {
        "image/x-exr"
    } else {
        "application/toml"
    };
    Ok(Reply {
        status: 200,
        headers: vec![
            ("Content-Type", mime.into()),
            ("Cache-Control", "no-store".into()),
            ("X-Content-Type-Options", "nosniff".into()),
            (
                "Content-Disposition",
                format!("attachment; filename=\"{name}\""),
            ),
        ],
        body: Payload::File(f),
    })
}
