//! The viewer against requests it must refuse: without the token, from another Host or
//! Origin, malformed, hostile and abusive ones; each gets its 4xx and the server goes on.

use super::{frame_request, start, Reply};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// A request target, a Host header (None: this server's) and more headers.
type Attempt<'a> = (String, Option<&'a str>, Vec<(&'a str, &'a str)>);

const ENDPOINTS: [(&str, &str); 9] = [
    ("GET", "/"),
    ("GET", "/api/scene"),
    ("GET", "/api/status"),
    ("GET", "/api/probe?client=test&x=1&y=1"),
    ("GET", "/api/job?id=1"),
    ("GET", "/files/view-1.toml"),
    ("POST", "/api/frame"),
    ("POST", "/api/save"),
    ("POST", "/api/render"),
];

/// Without the token, with a wrong one, from another Host (DNS rebinding) or another Origin,
/// every endpoint answers 403 and nothing is rendered or written.
#[test]
fn only_the_token_holder_on_this_host_is_answered() {
    let v = start("scenes/lattice.toml", "access");
    let body = frame_request(0, serde_json::json!({})).to_string();
    let here = format!("http://127.0.0.1:{}", v.port);
    for (method, path) in ENDPOINTS {
        let sep = if path.contains('?') { '&' } else { '?' };
        let cases: [Attempt; 5] = [
            (path.to_string(), None, vec![]),
            (
                format!("{path}{sep}token=0123456789abcdef0123456789abcdef"),
                None,
                vec![],
            ),
            (v.with_token(path), Some("attacker.example:80"), vec![]),
            (
                v.with_token(path),
                None,
                vec![("Origin", "http://attacker.example")],
            ),
            (
                v.with_token(path),
                Some("localhost.attacker.example"),
                vec![("Origin", here.as_str())],
            ),
        ];
        for (target, host, extra) in cases {
            let r = v.raw(method, &target, host, &extra, body.as_bytes());
            assert_eq!(
                r.status,
                403,
                "{method} {target} {host:?} {extra:?}: {}",
                r.text()
            );
        }
    }
    let s = v.status();
    assert_eq!(
        (s["rendering"].as_u64(), s["clients"].as_u64()),
        (Some(0), Some(0)),
        "{s}"
    );
    assert!(!v.out.exists(), "nothing written");
    // The same requests with the token, from here, are answered.
    assert_eq!(v.get("/").status, 200);
    assert_eq!(
        v.raw(
            "GET",
            &v.with_token("/api/scene"),
            Some(&format!("localhost:{}", v.port)),
            &[],
            b""
        )
        .status,
        200
    );
}

/// Malformed and hostile requests get a clear 4xx, and the server goes on serving.
#[test]
fn hostile_requests_get_a_clear_4xx_and_no_panic() {
    let v = start("scenes/lattice.toml", "hostile");
    let view = |x: serde_json::Value| frame_request(0, x);
    let cases: Vec<(Reply, u16, &str)> = vec![
        (
            v.post(
                "/api/frame",
                &view(serde_json::json!({ "groups": { "lattice": [1.0, 0.0, 0.0] } })),
            ),
            400,
            "must be below 1",
        ),
        (
            v.post(
                "/api/frame",
                &view(serde_json::json!({ "groups": { "lattice": [-0.99999999, 0.01, 0.0] } })),
            ),
            400,
            "must be below 1",
        ),
        (
            v.post(
                "/api/frame",
                &view(serde_json::json!({ "groups": { "nothing": [0.1, 0.0, 0.0] } })),
            ),
            400,
            "group `nothing`",
        ),
        (
            v.post(
                "/api/frame",
                &view(serde_json::json!({ "camera": { "position": [0.0, 0.0] } })),
            ),
            400,
            "three numbers",
        ),
        (
            v.post(
                "/api/frame",
                &view(serde_json::json!({ "camera": { "fov_y": 0.0 } })),
            ),
            400,
            "fov_y",
        ),
        (
            v.post(
                "/api/frame",
                &view(serde_json::json!({ "width": 1_000_000 })),
            ),
            400,
            "unknown view value",
        ),
        (
            v.post(
                "/api/frame",
                &serde_json::json!({ "client": "t", "level": 99, "view": {} }),
            ),
            400,
            "`level` must be 0 to 2",
        ),
        (
            v.post(
                "/api/frame",
                &serde_json::json!({ "client": "../x", "level": 0, "view": {} }),
            ),
            400,
            "`client`",
        ),
        (
            v.post(
                "/api/frame",
                &serde_json::json!({ "client": "t", "level": 0, "pass": "secrets", "view": {} }),
            ),
            400,
            "`pass`",
        ),
        (
            v.raw(
                "POST",
                &v.with_token("/api/frame"),
                None,
                &[],
                br#"{"client":"t","level":0,"view":{"groups":{"lattice":[NaN,0,0]}}}"#,
            ),
            400,
            "not JSON",
        ),
        (
            v.raw(
                "POST",
                &v.with_token("/api/frame"),
                None,
                &[],
                br#"{"client":"t","level":0,"view":{"groups":{"lattice":[1e400,0,0]}}}"#,
            ),
            400,
            "not JSON",
        ),
        (
            v.raw(
                "POST",
                &v.with_token("/api/frame"),
                None,
                &[],
                &vec![b' '; 70_000],
            ),
            413,
            "larger than",
        ),
        (
            v.get("/files/..%2F..%2Fetc%2Fpasswd"),
            400,
            "a file name, not a path",
        ),
        (v.get("/files/%2e%2e"), 400, "a file name, not a path"),
        (v.get("/files/view-1.exr"), 404, "no file"),
        (v.get("/files/Cargo.toml"), 404, "no file"),
        (v.get("/api/probe?client=test&x=0&y=0"), 404, "no frame"),
        (
            v.get("/api/probe?client=test&x=-1&y=0"),
            400,
            "whole number",
        ),
        (v.get("/api/job?id=7"), 404, "no render 7"),
        (v.get("/api/nothing"), 404, "no such page"),
        (
            v.raw("DELETE", &v.with_token("/api/frame"), None, &[], b""),
            405,
            "method",
        ),
    ];
    for (r, status, needle) in cases {
        assert_eq!(r.status, status, "{}", r.text());
        assert!(r.text().contains(needle), "{status}: {}", r.text());
    }
    // A line that is no HTTP at all, and a connection that says nothing.
    let mut s = TcpStream::connect(("127.0.0.1", v.port)).unwrap();
    s.write_all(b"\x00\xffnot http\r\n\r\n").unwrap();
    drop(s);
    drop(TcpStream::connect(("127.0.0.1", v.port)).unwrap());
    let s = v.status();
    assert_eq!(s["rendering"], 0, "{s}");
    assert_eq!(v.get("/api/scene").status, 200, "still serving");
}

/// The server's resident memory, from /proc (MiB).
fn rss_mib(pid: u32) -> f64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
    status
        .lines()
        .find(|l| l.starts_with("VmRSS:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|k| k.parse::<f64>().ok())
        .map_or(0.0, |k| k / 1024.0)
}

/// Abuse without the token (and some with it) leaves the server up, small and answering: a
/// body claimed to be 40 GB, a head of megabytes, two Host headers, more connections than it
/// takes trickling their heads a byte at a time while a request with the token is answered
/// within 5 s; a body that never finishes gets 408 (docs/viewer.md, "Limits").
#[test]
fn abuse_neither_kills_nor_fills_nor_stalls_it() {
    let v = start("scenes/lattice.toml", "abuse");
    let pid = v.child.id();
    let host = format!("127.0.0.1:{}", v.port);
    let send = |bytes: &[u8]| -> (Option<u16>, Vec<u8>) {
        let mut s = TcpStream::connect(("127.0.0.1", v.port)).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
        let _ = s.write_all(bytes);
        let mut all = Vec::new();
        let _ = s.read_to_end(&mut all);
        let status = String::from_utf8_lossy(&all)
            .split(' ')
            .nth(1)
            .and_then(|c| c.parse().ok());
        (status, all)
    };
    // 40 GB claimed, without the token and with it: answered without a byte of it read.
    for (target, want) in [
        ("/api/frame".to_string(), 403),
        (v.with_token("/api/frame"), 413),
    ] {
        let head = format!(
            "POST {target} HTTP/1.1\r\nHost: {host}\r\nContent-Length: 40000000000\r\n\r\n{{"
        );
        let t0 = Instant::now();
        let (status, _) = send(head.as_bytes());
        assert_eq!(status, Some(want), "{target}");
        assert!(t0.elapsed() < Duration::from_secs(5));
    }
    // A head of 4 MB: refused (431) or the connection closed, never held.
    let huge = format!(
        "GET /api/status HTTP/1.1\r\nHost: {host}\r\nX-Junk: {}\r\n\r\n",
        "a".repeat(4 << 20)
    );
    let (status, _) = send(huge.as_bytes());
    assert!(matches!(status, None | Some(431)), "{status:?}");
    // Two Host headers.
    let two = format!(
        "GET {} HTTP/1.1\r\nHost: {host}\r\nHost: evil.example\r\nConnection: close\r\n\r\n",
        v.with_token("/api/status")
    );
    assert_eq!(send(two.as_bytes()).0, Some(400));
    // A body that stops coming: 408 within the body's time.
    let mut s = TcpStream::connect(("127.0.0.1", v.port)).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let head = format!(
        "POST {} HTTP/1.1\r\nHost: {host}\r\nContent-Length: 100\r\n\r\n{{\"a\"",
        v.with_token("/api/save")
    );
    s.write_all(head.as_bytes()).unwrap();
    let mut reply = Vec::new();
    let _ = s.read_to_end(&mut reply);
    assert!(String::from_utf8_lossy(&reply).starts_with("HTTP/1.1 408"));
    // 300 connections trickling their heads: the token's request is answered within 5 s
    // (served, or 503 where every connection is taken), and served once theirs time out.
    let mut slow: Vec<TcpStream> = (0..300)
        .filter_map(|_| TcpStream::connect(("127.0.0.1", v.port)).ok())
        .collect();
    for s in &mut slow {
        let _ = s.write_all(b"GET / HTTP/1.1\r\nHo");
    }
    let t0 = Instant::now();
    let (status, _) = send(
        format!(
            "GET {} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n",
            v.with_token("/api/status")
        )
        .as_bytes(),
    );
    assert!(
        t0.elapsed() < Duration::from_secs(5),
        "waited {:?}",
        t0.elapsed()
    );
    assert!(matches!(status, Some(200 | 503)), "{status:?}");
    std::thread::sleep(Duration::from_secs(4));
    assert_eq!(v.get("/api/status").status, 200, "served again");
    drop(slow);
    assert!(rss_mib(pid) < 300.0, "{} MiB", rss_mib(pid));
    assert_eq!(v.get("/api/scene").status, 200, "still serving");
}
