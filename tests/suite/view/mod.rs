//! `rest-embree view` for real: the binary started as a user starts it, spoken to over HTTP
//! (docs/viewer.md). Every endpoint refuses requests without the token, from another Host or
//! another Origin; hostile requests get a clear 4xx and the server goes on (hostile.rs); the final frame is,
//! pixel for pixel, `rest-embree render` of the view it saves; a hundred rapid changes leave one
//! frame of work; Ctrl-C stops it cleanly.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

mod hostile;

struct Viewer {
    child: Child,
    port: u16,
    token: String,
    out: PathBuf,
    stdout: BufReader<std::process::ChildStdout>,
}

impl Drop for Viewer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A reply: status, headers (lower-case names) and body.
struct Reply {
    status: u16,
    headers: Vec<(String, String)>,
    body: Vec<u8>,
}

impl Reply {
    fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
    fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }
    fn json(&self) -> serde_json::Value {
        serde_json::from_slice(&self.body).unwrap_or_else(|e| panic!("{e}: {}", self.text()))
    }
}

fn start(scene: &str, name: &str) -> Viewer {
    let out = std::env::temp_dir().join(format!("rest-embree-view-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let mut child = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args(["view", scene, "--no-browser", "--backend", "bvh", "--out"])
        .arg(&out)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("the binary starts");
    let mut stdout = BufReader::new(child.stdout.take().expect("piped"));
    let mut url = String::new();
    for _ in 0..3 {
        let mut line = String::new();
        stdout.read_line(&mut line).expect("a line");
        if let Some(at) = line.find("http://") {
            url = line[at..].trim().to_string();
            break;
        }
    }
    assert!(url.starts_with("http://127.0.0.1:"), "printed: {url}");
    let rest = &url["http://127.0.0.1:".len()..];
    let (port, token) = rest.split_once("/?token=").expect("a token in the URL");
    assert_eq!(token.len(), 32, "128 random bits in hex");
    Viewer {
        child,
        port: port.parse().unwrap(),
        token: token.to_string(),
        out,
        stdout,
    }
}

impl Viewer {
    /// A raw HTTP/1.0 request (so the reply is not chunked), with the Host the browser sends
    /// unless `host` says otherwise, and `extra` headers.
    fn raw(
        &self,
        method: &str,
        target: &str,
        host: Option<&str>,
        extra: &[(&str, &str)],
        body: &[u8],
    ) -> Reply {
        let mut s = TcpStream::connect(("127.0.0.1", self.port)).expect("connects");
        s.set_read_timeout(Some(Duration::from_secs(120))).unwrap();
        let host = host.map_or(format!("127.0.0.1:{}", self.port), str::to_string);
        let mut head = format!(
            "{method} {target} HTTP/1.0\r\nHost: {host}\r\nContent-Length: {}\r\n",
            body.len()
        );
        for (k, v) in extra {
            head.push_str(&format!("{k}: {v}\r\n"));
        }
        head.push_str("\r\n");
        s.write_all(head.as_bytes()).unwrap();
        s.write_all(body).unwrap();
        let mut all = Vec::new();
        s.read_to_end(&mut all).expect("a reply");
        let split = all
            .windows(4)
            .position(|w| w == b"\r\n\r\n")
            .expect("headers end");
        let head = String::from_utf8_lossy(&all[..split]).into_owned();
        let mut lines = head.lines();
        let status = lines
            .next()
            .unwrap()
            .split(' ')
            .nth(1)
            .unwrap()
            .parse()
            .unwrap();
        let headers = lines
            .filter_map(|l| l.split_once(':'))
            .map(|(k, v)| (k.trim().to_ascii_lowercase(), v.trim().to_string()))
            .collect();
        Reply {
            status,
            headers,
            body: all[split + 4..].to_vec(),
        }
    }

    fn with_token(&self, path: &str) -> String {
        let sep = if path.contains('?') { '&' } else { '?' };
        format!("{path}{sep}token={}", self.token)
    }

    fn get(&self, path: &str) -> Reply {
        self.raw("GET", &self.with_token(path), None, &[], b"")
    }

    fn post(&self, path: &str, body: &serde_json::Value) -> Reply {
        let origin = format!("http://127.0.0.1:{}", self.port);
        self.raw(
            "POST",
            &self.with_token(path),
            None,
            &[("Origin", &origin), ("Content-Type", "application/json")],
            body.to_string().as_bytes(),
        )
    }

    fn status(&self) -> serde_json::Value {
        self.get("/api/status").json()
    }
}

fn frame_request(level: u64, view: serde_json::Value) -> serde_json::Value {
    serde_json::json!({ "client": "test", "level": level, "pass": "colour", "view": view })
}

fn decode_png(bytes: &[u8]) -> (u32, u32, Vec<u8>) {
    let mut r = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .unwrap();
    let mut buf = vec![0; r.output_buffer_size()];
    let info = r.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    assert_eq!(info.color_type, png::ColorType::Rgb);
    (info.width, info.height, buf)
}

/// The ladder of frames ends at the render of the saved view, pixel for pixel; a click asks the
/// last frame what it shows, which the EXR of the background render holds too.
#[test]
fn the_final_frame_is_rest_embree_render_of_the_saved_view() {
    let v = start("scenes/lattice.toml", "frames");
    let info = v.get("/api/scene").json();
    let levels = info["levels"].as_array().unwrap().len() as u64;
    assert_eq!(levels, 3, "{info}");
    let view = serde_json::json!({
        "groups": { "lattice": [-0.9, 0.0, 0.0] },
        "camera": { "time": 3.5, "position": [-3.0, 0.3, 0.2], "direction": [1.0, -0.1, 0.0] },
        "doppler": true,
        "searchlight": true
    });
    let mut last = None;
    for level in 0..levels {
        let r = v.post("/api/frame", &frame_request(level, view.clone()));
        assert_eq!(r.status, 200, "{}", r.text());
        assert_eq!(r.header("content-type"), Some("image/png"));
        let (w, h, px) = decode_png(&r.body);
        let want = if level == 0 { 256 } else { 512 };
        assert_eq!((w, h), (want, want));
        assert_eq!(
            r.header("x-final"),
            Some(if level + 1 == levels { "true" } else { "false" })
        );
        last = Some(px);
    }
    let saved = v.post("/api/save", &serde_json::json!({ "view": view }));
    assert_eq!(saved.status, 200, "{}", saved.text());
    assert!(saved
        .header("content-disposition")
        .unwrap()
        .contains("lattice-view.toml"));
    let dir = std::env::temp_dir().join(format!("rest-embree-view-saved-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let toml = dir.join("view.toml");
    std::fs::write(&toml, &saved.body).unwrap();
    let png = dir.join("view.png");
    let out = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args(["render", "--backend", "bvh", "-q"])
        .arg(&toml)
        .arg("-o")
        .arg(&png)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (_, _, rendered) = decode_png(&std::fs::read(&png).unwrap());
    let last = last.unwrap();
    let differ = last.iter().zip(&rendered).filter(|(a, b)| a != b).count();
    assert_eq!(
        differ, 0,
        "the final frame differs from the render of the saved view in {differ} bytes"
    );
    // The click: what the last frame shows at pixels across the middle row, as the library
    // renders the saved file.
    let scene = rest_embree::scene::load_file(&toml, &[]).unwrap();
    let backend = rest_embree::accel::backend_by_name("bvh").unwrap();
    let (frame, _) = rest_embree::render(&scene, backend.as_ref(), &Default::default()).unwrap();
    let lookback = frame.channel("lookback.V").unwrap();
    let mut hits = 0;
    for x in (0..512).step_by(16) {
        let p = v.get(&format!("/api/probe?client=test&x={x}&y=256")).json();
        let i = 256 * 512 + x;
        assert_eq!(
            p["hit"].as_bool(),
            Some(frame.pixels[i].object_id != 0),
            "{p}"
        );
        if p["hit"] == true {
            hits += 1;
            assert_eq!(p["lookback"].as_f64().unwrap() as f32, lookback[i], "{p}");
            let t = p["emission"]["t"].as_f64().unwrap();
            assert!((t - (3.5 - f64::from(lookback[i]))).abs() < 1e-6, "{p}");
            assert_eq!(p["object"], "lattice");
            assert_eq!(p["group"], "lattice");
        }
    }
    assert!(hits > 5, "the middle row sees the lattice ({hits} probes)");
    // Render this view: the scene file and an EXR, offered by name.
    let job = v
        .post("/api/render", &serde_json::json!({ "view": view }))
        .json();
    let id = job["id"].as_u64().unwrap();
    let t0 = Instant::now();
    loop {
        let j = v.get(&format!("/api/job?id={id}")).json();
        match j["state"].as_str() {
            Some("done") => break,
            Some("running") => assert!(t0.elapsed() < Duration::from_secs(120), "{j}"),
            _ => panic!("{j}"),
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let toml_back = v.get(&format!("/files/view-{id}.toml"));
    assert_eq!(toml_back.status, 200);
    assert_eq!(
        toml_back.body, saved.body,
        "the file rendered is the file saved"
    );
    let exr = v.get(&format!("/files/view-{id}.exr"));
    assert_eq!(exr.status, 200);
    assert_eq!(
        exr.body,
        std::fs::read(v.out.join(format!("view-{id}.exr"))).unwrap()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A view of a scene that names files (an OBJ mesh, a texture image) saved and rendered from
/// another folder is still the viewer's final frame: the saved file names them by full path.
#[test]
fn a_saved_view_with_files_renders_the_same_from_anywhere() {
    let v = start("scenes/rocket.toml", "files");
    let levels = v.get("/api/scene").json()["levels"]
        .as_array()
        .unwrap()
        .len() as u64;
    let view =
        serde_json::json!({ "groups": { "rocket": [0.6, 0.0, 0.1] }, "camera": { "time": 1.5 } });
    let r = v.post("/api/frame", &frame_request(levels - 1, view.clone()));
    assert_eq!(r.status, 200, "{}", r.text());
    let (_, _, shown) = decode_png(&r.body);
    let saved = v.post("/api/save", &serde_json::json!({ "view": view }));
    assert_eq!(saved.status, 200, "{}", saved.text());
    let text = saved.text();
    assert!(
        text.contains("rocket.obj\"") && !text.contains("file = \"rocket.obj\""),
        "{text}"
    );
    let dir =
        std::env::temp_dir().join(format!("rest-embree-view-elsewhere-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("rocket-view.toml"), &saved.body).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args([
            "render",
            "--backend",
            "bvh",
            "-q",
            "rocket-view.toml",
            "-o",
            "rocket-view.png",
        ])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (_, _, rendered) = decode_png(&std::fs::read(dir.join("rocket-view.png")).unwrap());
    assert!(
        shown == rendered,
        "the render of the saved view differs from the final frame"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Requests arrive out of order: one older than the newest the page sent is refused, and a
/// click on a frame that has been replaced is refused, so the page never shows or reads a
/// view it has moved past.
#[test]
fn an_older_request_never_supersedes_a_newer_one() {
    let v = start("scenes/lattice.toml", "order");
    let ask = |seq: u64, beta: f64| {
        v.post(
            "/api/frame",
            &serde_json::json!({ "client": "p", "seq": seq, "level": 0, "view": { "groups": { "lattice": [beta, 0.0, 0.0] } } }),
        )
    };
    assert_eq!(ask(10, -0.5).status, 200);
    let stale = ask(9, -0.1);
    assert_eq!(stale.status, 409, "{}", stale.text());
    assert_eq!(ask(10, -0.1).status, 409, "the same number again");
    assert_eq!(ask(11, -0.6).status, 200);
    assert_eq!(v.get("/api/probe?client=p&seq=10&x=1&y=1").status, 409);
    assert_eq!(v.get("/api/probe?client=p&seq=11&x=1&y=1").status, 200);
    let bad = v.post(
        "/api/frame",
        &serde_json::json!({ "client": "p", "seq": -1, "level": 0, "view": {} }),
    );
    assert_eq!(bad.status, 400, "{}", bad.text());
    // u64's last number would leave every later request older: refused, and the client's
    // next request without a number is served.
    let last = ask(u64::MAX, -0.2);
    assert_eq!(last.status, 400, "{}", last.text());
    let next = v.post(
        "/api/frame",
        &serde_json::json!({ "client": "p", "level": 0, "view": {} }),
    );
    assert_eq!(next.status, 200, "{}", next.text());
    // A mistyped key is named, not dropped.
    let typo = v.post(
        "/api/frame",
        &serde_json::json!({ "client": "p", "levle": 0, "level": 0, "view": {} }),
    );
    assert!(
        typo.status == 400 && typo.text().contains("`levle`"),
        "{}",
        typo.text()
    );
}

/// A hundred changes as fast as a slider sends them: every superseded view's work stops, at no
/// time does more than one frame render, and the newest view is the one drawn.
#[test]
fn a_hundred_rapid_changes_leave_one_frame_of_work() {
    let v = std::sync::Arc::new(start("scenes/lattice.toml", "rapid"));
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let watcher = {
        let (v, stop) = (v.clone(), stop.clone());
        std::thread::spawn(move || {
            let mut most = 0;
            while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                most = most.max(v.status()["rendering"].as_u64().unwrap());
                std::thread::sleep(Duration::from_millis(2));
            }
            most
        })
    };
    let senders: Vec<_> = (0..100)
        .map(|k| {
            let v = v.clone();
            std::thread::sleep(Duration::from_millis(3));
            std::thread::spawn(move || {
                let beta = -0.5 - 0.004 * k as f64;
                let r = v.post(
                    "/api/frame",
                    &frame_request(
                        2,
                        serde_json::json!({ "groups": { "lattice": [beta, 0.0, 0.0] } }),
                    ),
                );
                (k, r.status)
            })
        })
        .collect();
    let statuses: Vec<(usize, u16)> = senders.into_iter().map(|s| s.join().unwrap()).collect();
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    let most = watcher.join().unwrap();
    assert!(most <= 1, "{most} frames rendered at once");
    let ok: Vec<usize> = statuses
        .iter()
        .filter(|s| s.1 == 200)
        .map(|s| s.0)
        .collect();
    assert!(
        statuses.iter().all(|s| s.1 == 200 || s.1 == 409),
        "{statuses:?}"
    );
    assert!(
        !ok.is_empty() && ok.len() < 10,
        "most were superseded: {} drawn",
        ok.len()
    );
    let s = v.status();
    assert_eq!(
        (s["rendering"].as_u64(), s["waiting"].as_u64()),
        (Some(0), Some(0)),
        "{s}"
    );
}

/// Ctrl-C (SIGINT) stops the server: it says so and exits 0.
#[test]
fn ctrl_c_stops_it_cleanly() {
    let mut v = start("scenes/lattice.toml", "stop");
    assert_eq!(v.get("/api/status").status, 200);
    let pid = v.child.id().to_string();
    assert!(Command::new("kill")
        .args(["-INT", &pid])
        .status()
        .unwrap()
        .success());
    let t0 = Instant::now();
    let status = loop {
        if let Some(s) = v.child.try_wait().unwrap() {
            break s;
        }
        assert!(t0.elapsed() < Duration::from_secs(10), "still running");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(status.success(), "{status:?}");
    let mut rest = String::new();
    v.stdout.read_to_string(&mut rest).unwrap();
    assert!(rest.contains("stopped"), "{rest}");
    assert!(
        TcpStream::connect(("127.0.0.1", v.port)).is_err(),
        "no longer listening"
    );
}

/// A bad scene is refused by `view` as by `render`: the same message, naming the line of the
/// file (the text the viewer renders has lines of its own at the top), exit status 1.
#[test]
fn a_bad_scene_is_said_at_its_own_line() {
    let dir = std::env::temp_dir().join(format!("rest-embree-view-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("typo.toml");
    let text = "[camera]\nposition = [0, 0, 0]\nlookat = [0, 0, 0]\n";
    std::fs::write(&scene, text).unwrap();
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
            .args(args)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let path = scene.to_str().unwrap();
    let png = dir.join("x.png");
    let (code, viewed) = run(&["view", path, "--no-browser", "--port", "0"]);
    let (rendered_code, rendered) = run(&["render", path, "-o", png.to_str().unwrap()]);
    assert_eq!(
        (code, rendered_code),
        (Some(1), Some(1)),
        "{viewed}\n{rendered}"
    );
    assert!(
        viewed.contains("typo.toml:3: key `camera.lookat`"),
        "{viewed}"
    );
    assert_eq!(viewed, rendered);
    let _ = std::fs::remove_dir_all(&dir);
}
