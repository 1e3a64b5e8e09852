//! The viewer's HTTP layer, on hyper (HTTP/1.1) over tokio, bounded by construction in what it
//! reads and how long it waits for it, whoever is on the other end:
//!
//! - at most `MAX_CONNECTIONS` connections at once; one more is answered 503 and closed at
//!   once, without reading it;
//! - a request's head (its line and headers) at most `MAX_HEAD` bytes, read within
//!   `HEAD_TIMEOUT` (hyper answers 431 or closes the connection);
//! - exactly one `Host` header (400 otherwise);
//! - the access checks (token, Host, Origin: `access.rs`) before any body is read: a request
//!   without the token is answered 403 and its body never read;
//! - a body larger than `routes::MAX_BODY` refused by its Content-Length before it is read
//!   (413), and any body read at most that far and within `BODY_TIMEOUT` (408 otherwise);
//! - the endpoints (`routes.rs`, synchronous: a frame renders on every core) run on tokio's
//!   blocking threads, one per request in flight, so a slow render never stalls the others.

use super::routes::{self, Method, Payload, Reply, Req};
use super::Viewer;
use hyper::body::{Body, Bytes, Frame, Incoming};
use hyper::{Request, Response};
use std::convert::Infallible;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::Duration;
use tokio::io::AsyncWriteExt;
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::{Notify, Semaphore};

/// The most connections open at once (each holds a file descriptor and a task).
pub(super) const MAX_CONNECTIONS: usize = 256;
/// The most a request's line and headers may take.
const MAX_HEAD: usize = 16 * 1024;
/// How long a request's head may take to arrive.
const HEAD_TIMEOUT: Duration = Duration::from_secs(3);
/// How long a request's body (at most 64 KiB) may take to arrive.
const BODY_TIMEOUT: Duration = Duration::from_secs(3);

/// A reply's body: bytes made whole, or a file read as it is sent.
pub(super) enum ReplyBody {
    Bytes(Option<Bytes>),
    File(tokio::fs::File, bytes::BytesMut),
}

impl Body for ReplyBody {
    type Data = Bytes;
    type Error = std::io::Error;

    fn poll_frame(
        self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<Frame<Bytes>, std::io::Error>>> {
        match self.get_mut() {
            ReplyBody::Bytes(b) => Poll::Ready(b.take().map(|b| Ok(Frame::data(b)))),
            ReplyBody::File(f, buf) => {
                buf.reserve(64 * 1024);
                match tokio_util::io::poll_read_buf(Pin::new(f), cx, buf) {
                    Poll::Pending => Poll::Pending,
                    Poll::Ready(Err(e)) => Poll::Ready(Some(Err(e))),
                    Poll::Ready(Ok(0)) => Poll::Ready(None),
                    Poll::Ready(Ok(_)) => Poll::Ready(Some(Ok(Frame::data(buf.split().freeze())))),
                }
            }
        }
    }
}

/// Serve `viewer` on `listener` until `stop` is notified.
pub(super) async fn serve(listener: TcpListener, viewer: Arc<Viewer>, stop: Arc<Notify>) {
    let permits = Arc::new(Semaphore::new(MAX_CONNECTIONS));
    loop {
        let stream = tokio::select! {
            accepted = listener.accept() => match accepted {
                Ok((s, _)) => s,
                Err(e) => {
                    // Out of file descriptors, say: wait a moment rather than spin.
                    crate::text::warn(format_args!("rest-embree view: {e}"));
                    tokio::time::sleep(Duration::from_millis(10)).await;
                    continue;
                }
            },
            _ = stop.notified() => break,
        };
        match permits.clone().try_acquire_owned() {
            Ok(permit) => {
                let v = viewer.clone();
                tokio::spawn(async move {
                    connection(stream, v).await;
                    drop(permit);
                });
            }
            Err(_) => {
                tokio::spawn(busy(stream));
            }
        }
    }
}

/// One connection: HTTP/1.1 with keep-alive, its heads bounded in size and time.
async fn connection(stream: TcpStream, viewer: Arc<Viewer>) {
    let io = hyper_util::rt::TokioIo::new(stream);
    let service = hyper::service::service_fn(move |rq| {
        let v = viewer.clone();
        async move { Ok::<_, Infallible>(request(v, rq).await) }
    });
    let served = hyper::server::conn::http1::Builder::new()
        .timer(hyper_util::rt::TokioTimer::new())
        .header_read_timeout(HEAD_TIMEOUT)
        .max_buf_size(MAX_HEAD)
        .serve_connection(io, service)
        .await;
    // A client that went away, or sent no HTTP, is no error of ours.
    let _ = served;
}

/// Too many connections: a 503 written at once, the connection closed unread.
async fn busy(mut stream: TcpStream) {
    let body = "busy: too many connections at once\n";
    let reply = format!(
        "HTTP/1.1 503 Service Unavailable\r\nContent-Type: text/plain; charset=utf-8\r\nContent-Length: {}\r\nConnection: close\r\nRetry-After: 1\r\n\r\n{body}",
        body.len()
    );
    let _ = tokio::time::timeout(Duration::from_secs(1), stream.write_all(reply.as_bytes())).await;
}

/// The values of header `name` (there may be several).
fn values<'a>(rq: &'a Request<Incoming>, name: &str) -> Vec<&'a str> {
    rq.headers()
        .get_all(name)
        .iter()
        .map(|h| h.to_str().unwrap_or("\u{fffd}"))
        .collect()
}

/// One request: its Host and access checked, its body read within bounds, then answered on a
/// blocking thread.
async fn request(viewer: Arc<Viewer>, rq: Request<Incoming>) -> Response<ReplyBody> {
    let hosts = values(&rq, "host");
    let origins = values(&rq, "origin");
    if hosts.len() > 1 {
        return respond(routes::text(400, "more than one Host header"));
    }
    if origins.len() > 1 {
        return respond(routes::text(400, "more than one Origin header"));
    }
    let path = rq.uri().path().to_string();
    let query = rq.uri().query().unwrap_or("").to_string();
    if let Err(why) = viewer
        .access
        .check(&query, hosts.first().copied(), origins.first().copied())
    {
        return respond(routes::text(403, why));
    }
    let method = match *rq.method() {
        hyper::Method::GET => Method::Get,
        hyper::Method::POST => Method::Post,
        _ => Method::Other,
    };
    let body = if method == Method::Post {
        match read_body(rq).await {
            Ok(b) => b,
            Err(reply) => return respond(reply),
        }
    } else {
        Bytes::new()
    };
    let answered = tokio::task::spawn_blocking(move || {
        let rq = Req {
            method,
            path: &path,
            query: &query,
            body: &body,
        };
        routes::handle(&viewer, &rq)
    })
    .await;
    respond(answered.unwrap_or_else(|_| routes::text(500, "internal error")))
}

/// A POST's body: refused by its length before it is read where that is too long (413), else
/// read at most `MAX_BODY` bytes far and within `BODY_TIMEOUT` (408).
async fn read_body(rq: Request<Incoming>) -> Result<Bytes, Reply> {
    use http_body_util::BodyExt;
    let too_long = || {
        routes::text(
            413,
            &format!("the body is larger than {} bytes", routes::MAX_BODY),
        )
    };
    if rq
        .body()
        .size_hint()
        .exact()
        .or(rq.body().size_hint().upper())
        .is_some_and(|n| n > routes::MAX_BODY as u64)
    {
        return Err(too_long());
    }
    let limited = http_body_util::Limited::new(rq.into_body(), routes::MAX_BODY);
    match tokio::time::timeout(BODY_TIMEOUT, limited.collect()).await {
        Err(_) => Err(routes::text(
            408,
            "the body did not arrive in time (3 s for 64 KiB)",
        )),
        Ok(Err(e)) if e.is::<http_body_util::LengthLimitError>() => Err(too_long()),
        Ok(Err(e)) => Err(routes::text(400, &format!("cannot read the body: {e}"))),
        Ok(Ok(c)) => Ok(c.to_bytes()),
    }
}

/// A reply as hyper sends it.
fn respond(reply: Reply) -> Response<ReplyBody> {
    let body = match reply.body {
        Payload::Bytes(b) => ReplyBody::Bytes(Some(Bytes::from(b))),
        Payload::File(f) => ReplyBody::File(tokio::fs::File::from_std(f), bytes::BytesMut::new()),
    };
    let mut r = Response::new(body);
    *r.status_mut() = hyper::StatusCode::from_u16(reply.status)
        .unwrap_or(hyper::StatusCode::INTERNAL_SERVER_ERROR);
    for (name, value) in reply.headers {
        if let Ok(v) = hyper::header::HeaderValue::from_str(&value) {
            r.headers_mut().insert(name, v);
        }
    }
    r
}
