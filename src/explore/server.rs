//! The page's local HTTP server: std's sockets, request heads parsed by
//! httparse, one request a connection (`Connection: close`).
//!
//! - Bound to 127.0.0.1 unless asked otherwise. It serves the page's three
//!   files (compiled into the binary), three GET routes: `/api/model` (the
//!   controls and lessons), `/api/run?set=K=V&...&timeline=N` (one redraw)
//!   and `/api/model.toml?set=...` (the resolved model); and one POST
//!   route, `/api/replay?file=NAME&set=...`, a capture's bytes in the body
//!   replayed.
//! - It reads no file: the model was read when the server started, and an
//!   uploaded capture is read from memory.
//! - Everything is bounded. A request head is at most [`MAX_HEAD_BYTES`]
//!   (its line at most [`MAX_URL_BYTES`], 414 beyond). A body is at most
//!   [`MAX_UPLOAD_BYTES`]: 413 from its announced length, before a byte of
//!   it is read. A body needs a `Content-Length` (411 without one). A
//!   client that stops sending gets 408 after [`IO_TIMEOUT`]. At most
//!   [`MAX_CONNECTIONS`] connections are open, 503 beyond. [`RUNS`]
//!   simulations run at once with [`QUEUE`] waiting, 503 beyond. Each run
//!   is held to an event budget ([`super::page_run`]).
//! - A panic while answering gets 500; the server goes on.
//! - Ctrl-C (SIGINT) or SIGTERM stops it: it takes no new connection, the
//!   answers under way finish, and the command exits 0.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

use super::page_replay::{MAX_UPLOAD_BYTES, replay_upload};
use super::page_run::{Explorer, PageError, TIMELINE_FRAMES};

/// Simulations under way at once.
pub const RUNS: usize = 2;
/// Simulations waiting for a turn before the server answers 503.
pub const QUEUE: usize = 8;
/// Connections open at once before the server answers 503.
pub const MAX_CONNECTIONS: usize = 32;
/// The longest request line (method, path and query).
pub const MAX_URL_BYTES: usize = 16 * 1024;
/// The longest request head (request line and headers).
pub const MAX_HEAD_BYTES: usize = 32 * 1024;
/// How long a client may leave the server waiting for its request, or
/// its answer unread.
pub const IO_TIMEOUT: Duration = Duration::from_secs(15);

const INDEX_HTML: &str = include_str!("page/index.html");
const APP_JS: &str = include_str!("page/app.js");
const STYLE_CSS: &str = include_str!("page/style.css");

/// Why the server could not start.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The address could not be bound.
    #[error("cannot listen on {addr}: {source}")]
    Bind {
        /// The address asked for.
        addr: String,
        /// The system's reason.
        source: std::io::Error,
    },
    /// The signal handler could not be installed.
    #[error("cannot install the Ctrl-C handler: {0}")]
    Signal(std::io::Error),
}

/// One answer.
struct Answer {
    status: u16,
    content_type: &'static str,
    body: Vec<u8>,
    /// Extra header lines (`Name: value`).
    headers: Vec<String>,
}

impl Answer {
    fn new(status: u16, content_type: &'static str, body: impl Into<Vec<u8>>) -> Answer {
        Answer {
            status,
            content_type,
            body: body.into(),
            headers: Vec::new(),
        }
    }

    fn json(body: String) -> Answer {
        Answer::new(200, "application/json; charset=utf-8", body)
    }

    fn error(status: u16, message: &str) -> Answer {
        let body = serde_json::json!({ "error": message }).to_string();
        Answer::new(status, "application/json; charset=utf-8", body)
    }

    fn of(e: &PageError) -> Answer {
        Answer::error(e.status(), &e.to_string())
    }
}

fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        204 => "No Content",
        400 => "Bad Request",
        404 => "Not Found",
        405 => "Method Not Allowed",
        408 => "Request Timeout",
        411 => "Length Required",
        413 => "Content Too Large",
        414 => "URI Too Long",
        422 => "Unprocessable Content",
        431 => "Request Header Fields Too Large",
        503 => "Service Unavailable",
        _ => "Internal Server Error",
    }
}

fn write_answer(stream: &mut TcpStream, a: &Answer) {
    let mut head = format!(
        "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nConnection: close\r\n\
         Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\n",
        a.status,
        reason(a.status),
        a.content_type,
        a.body.len()
    );
    for h in &a.headers {
        head.push_str(h);
        head.push_str("\r\n");
    }
    head.push_str("\r\n");
    // A client that went away is no error of the server's.
    let _ = stream.write_all(head.as_bytes());
    let _ = stream.write_all(&a.body);
    let _ = stream.flush();
}

/// A request's query: `set` assignments (repeatable), the timeline's
/// frame count, and for an uploaded capture its file name and the
/// application whose swap chain to replay.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Query {
    sets: Vec<String>,
    timeline: u64,
    file: Option<String>,
    app: Option<String>,
}

fn query(url: &str) -> Result<Query, PageError> {
    let q = url.split_once('?').map_or("", |(_, q)| q);
    let mut out = Query {
        sets: Vec::new(),
        timeline: TIMELINE_FRAMES,
        file: None,
        app: None,
    };
    for (k, v) in form_urlencoded::parse(q.as_bytes()) {
        match k.as_ref() {
            "set" => out.sets.push(v.into_owned()),
            "timeline" => {
                out.timeline = v
                    .parse()
                    .map_err(|_| PageError::Request(format!("timeline={v:?}: expected a whole number of frames")))?
            }
            "file" => out.file = Some(v.into_owned()),
            "app" => out.app = Some(v.into_owned()).filter(|a| !a.is_empty()),
            other => {
                return Err(PageError::Request(format!(
                    "unknown query parameter {other:?} (set, timeline, file, app)"
                )));
            }
        }
    }
    Ok(out)
}

fn path_of(url: &str) -> &str {
    url.split_once('?').map_or(url, |(p, _)| p)
}

/// A parsed request: method, target and body.
struct Request {
    method: String,
    url: String,
    body: Vec<u8>,
}

/// Reads one request from `stream`, or the answer that refuses it.
fn read_request(stream: &mut TcpStream) -> Result<Request, Answer> {
    let mut buf = Vec::with_capacity(4096);
    let mut chunk = [0u8; 4096];
    let timed_out =
        |e: &std::io::Error| matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut);
    // The head: up to the blank line.
    let head_end = loop {
        if let Some(i) = buf.windows(4).position(|w| w == b"\r\n\r\n") {
            break i + 4;
        }
        if buf.len() > MAX_HEAD_BYTES {
            let line = buf.split(|&b| b == b'\n').next().map_or(0, <[u8]>::len);
            return Err(if line > MAX_URL_BYTES {
                Answer::error(
                    414,
                    &format!("the request line is over {MAX_URL_BYTES} bytes: fewer or shorter assignments"),
                )
            } else {
                Answer::error(431, &format!("the request head is over {MAX_HEAD_BYTES} bytes"))
            });
        }
        match stream.read(&mut chunk) {
            Ok(0) => return Err(Answer::error(400, "the connection closed before a whole request came")),
            Ok(n) => buf.extend_from_slice(&chunk[..n]),
            Err(e) if timed_out(&e) => return Err(Answer::error(408, "the request did not come in time")),
            Err(e) => return Err(Answer::error(400, &format!("reading the request: {e}"))),
        }
    };
    let mut headers = [httparse::EMPTY_HEADER; 64];
    let mut parsed = httparse::Request::new(&mut headers);
    match parsed.parse(&buf[..head_end]) {
        Ok(httparse::Status::Complete(_)) => {}
        Ok(httparse::Status::Partial) | Err(_) => return Err(Answer::error(400, "a malformed request")),
    }
    let method = parsed.method.unwrap_or("").to_string();
    let url = parsed.path.unwrap_or("").to_string();
    if url.len() > MAX_URL_BYTES {
        return Err(Answer::error(
            414,
            &format!("the request line is over {MAX_URL_BYTES} bytes: fewer or shorter assignments"),
        ));
    }
    let header = |name: &str| {
        parsed
            .headers
            .iter()
            .find(|h| h.name.eq_ignore_ascii_case(name))
            .map(|h| String::from_utf8_lossy(h.value).trim().to_string())
    };
    if header("transfer-encoding").is_some() {
        return Err(Answer::error(411, "send the body with a Content-Length, not in chunks"));
    }
    let length: u64 = match header("content-length") {
        None => 0,
        Some(v) => v
            .parse()
            .map_err(|_| Answer::error(400, &format!("Content-Length {v:?} is not a number")))?,
    };
    if length > MAX_UPLOAD_BYTES {
        return Err(Answer::error(
            413,
            &format!(
                "the capture is over the page's limit of {} MiB: replay it with `rendersim replay FILE`",
                MAX_UPLOAD_BYTES / (1024 * 1024)
            ),
        ));
    }
    if length > 0 && header("expect").is_some_and(|e| e.eq_ignore_ascii_case("100-continue")) {
        let _ = stream.write_all(b"HTTP/1.1 100 Continue\r\n\r\n");
    }
    let mut body = buf[head_end..].to_vec();
    body.truncate(length as usize);
    while (body.len() as u64) < length {
        let want = ((length - body.len() as u64) as usize).min(chunk.len());
        match stream.read(&mut chunk[..want]) {
            Ok(0) => return Err(Answer::error(400, "the connection closed before the whole body came")),
            Ok(n) => body.extend_from_slice(&chunk[..n]),
            Err(e) if timed_out(&e) => return Err(Answer::error(408, "the body did not come in time")),
            Err(e) => return Err(Answer::error(400, &format!("reading the body: {e}"))),
        }
    }
    Ok(Request { method, url, body })
}

/// Turns for the simulations: at most [`RUNS`] at once, [`QUEUE`] waiting.
struct Turns {
    state: Mutex<(usize, usize)>,
    freed: Condvar,
}

impl Turns {
    /// Waits for a turn; `None` when too many are waiting already.
    fn take(&self) -> Option<TurnGuard<'_>> {
        let mut s = self.state.lock().ok()?;
        if s.0 >= RUNS && s.1 >= QUEUE {
            return None;
        }
        s.1 += 1;
        while s.0 >= RUNS {
            s = self.freed.wait(s).ok()?;
        }
        s.1 -= 1;
        s.0 += 1;
        Some(TurnGuard(self))
    }
}

struct TurnGuard<'a>(&'a Turns);

impl Drop for TurnGuard<'_> {
    fn drop(&mut self) {
        if let Ok(mut s) = self.0.state.lock() {
            s.0 -= 1;
        }
        self.0.freed.notify_one();
    }
}

fn busy() -> Answer {
    Answer::error(
        503,
        &format!("the server is busy ({RUNS} runs under way, {QUEUE} waiting): try again"),
    )
}

/// The answer to `req`.
fn answer(explorer: &Explorer, turns: &Turns, req: &Request) -> Answer {
    let path = path_of(&req.url);
    let allowed = if path == "/api/replay" { "POST" } else { "GET" };
    if req.method != allowed {
        return Answer::error(405, &format!("{path} takes {allowed} only"));
    }
    let api = |f: &dyn Fn() -> Result<String, PageError>| match turns.take() {
        None => busy(),
        Some(_turn) => f().map_or_else(|e| Answer::of(&e), Answer::json),
    };
    match path {
        "/" | "/index.html" => Answer::new(200, "text/html; charset=utf-8", INDEX_HTML),
        "/app.js" => Answer::new(200, "text/javascript; charset=utf-8", APP_JS),
        "/style.css" => Answer::new(200, "text/css; charset=utf-8", STYLE_CSS),
        "/favicon.ico" => Answer::new(204, "text/plain", ""),
        "/api/model" => api(&|| explorer.page_model().and_then(|m| to_json(&m))),
        "/api/run" => api(&|| {
            let q = query(&req.url)?;
            to_json(&explorer.run(&q.sets, q.timeline)?)
        }),
        "/api/replay" => api(&|| {
            let q = query(&req.url)?;
            if req.body.is_empty() {
                return Err(PageError::Request(
                    "the upload is empty: drop a capture's CSV file".into(),
                ));
            }
            let file = q.file.clone().unwrap_or_else(|| "capture.csv".into());
            to_json(&replay_upload(&file, &req.body, &q.sets, q.app)?)
        }),
        "/api/model.toml" => match query(&req.url).and_then(|q| explorer.model_toml(&q.sets)) {
            Ok(text) => Answer {
                headers: vec!["Content-Disposition: attachment; filename=\"model.toml\"".into()],
                ..Answer::new(200, "application/toml; charset=utf-8", text)
            },
            Err(e) => Answer::of(&e),
        },
        other => Answer::error(404, &format!("no such page: {other}")),
    }
}

/// A route's result as the JSON the page reads.
fn to_json<T: serde::Serialize>(v: &T) -> Result<String, PageError> {
    serde_json::to_string(v).map_err(|e| PageError::View(e.to_string()))
}

/// One connection: its request read, answered, and closed.
fn connection(mut stream: TcpStream, explorer: &Explorer, turns: &Turns) {
    let _ = stream.set_read_timeout(Some(IO_TIMEOUT));
    let _ = stream.set_write_timeout(Some(IO_TIMEOUT));
    let a = match read_request(&mut stream) {
        Ok(req) => std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| answer(explorer, turns, &req)))
            .unwrap_or_else(|_| Answer::error(500, &format!("internal error while answering {}", req.url))),
        Err(refused) => refused,
    };
    write_answer(&mut stream, &a);
}

/// Serves `explorer` on `addr` until Ctrl-C; `ready` is told the address
/// the server listens on once it does.
pub fn serve(explorer: Explorer, addr: &str, ready: impl FnOnce(SocketAddr)) -> Result<(), ServeError> {
    let bind = |source| ServeError::Bind {
        addr: addr.to_string(),
        source,
    };
    let listener = TcpListener::bind(addr).map_err(bind)?;
    let local = listener.local_addr().map_err(bind)?;
    listener.set_nonblocking(true).map_err(bind)?;
    let stop = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(signal, stop.clone()).map_err(ServeError::Signal)?;
    }
    ready(local);
    let explorer = Arc::new(explorer);
    let turns = Arc::new(Turns {
        state: Mutex::new((0, 0)),
        freed: Condvar::new(),
    });
    let open = Arc::new(AtomicUsize::new(0));
    while !stop.load(Ordering::Relaxed) {
        match listener.accept() {
            Ok((mut stream, _)) => {
                let _ = stream.set_nonblocking(false);
                if open.load(Ordering::SeqCst) >= MAX_CONNECTIONS {
                    let _ = stream.set_write_timeout(Some(Duration::from_secs(1)));
                    write_answer(
                        &mut stream,
                        &Answer::error(503, &format!("over {MAX_CONNECTIONS} connections open: try again")),
                    );
                    continue;
                }
                open.fetch_add(1, Ordering::SeqCst);
                let (e, t, o) = (explorer.clone(), turns.clone(), open.clone());
                std::thread::spawn(move || {
                    connection(stream, &e, &t);
                    o.fetch_sub(1, Ordering::SeqCst);
                });
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => std::thread::sleep(Duration::from_millis(20)),
            Err(_) => std::thread::sleep(Duration::from_millis(20)),
        }
    }
    // The answers under way finish (each within its timeouts).
    while open.load(Ordering::SeqCst) > 0 {
        std::thread::sleep(Duration::from_millis(20));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_query_gives_the_assignments_in_order_and_refuses_the_unknown() {
        let q = query("/api/run?set=display.buffers%3D3&set=fidelity%3D%22draw%22&timeline=6").unwrap();
        assert_eq!(q.sets, ["display.buffers=3", "fidelity=\"draw\""]);
        assert_eq!(q.timeline, 6);
        assert!(
            query("/api/run?frames=3")
                .unwrap_err()
                .to_string()
                .contains("unknown query parameter")
        );
        assert!(
            query("/api/run?timeline=x")
                .unwrap_err()
                .to_string()
                .contains("whole number")
        );
        let empty = query("/api/run").unwrap();
        assert!(empty.sets.is_empty() && empty.timeline == TIMELINE_FRAMES && empty.file.is_none());
        assert_eq!(
            query("/api/replay?file=a%20b.csv&app=").unwrap().file.as_deref(),
            Some("a b.csv")
        );
    }

    #[test]
    fn turns_hold_runs_to_their_bound_and_refuse_past_the_queue() {
        let turns = Turns {
            state: Mutex::new((0, 0)),
            freed: Condvar::new(),
        };
        let a = turns.take().unwrap();
        let b = turns.take().unwrap();
        assert_eq!(*turns.state.lock().unwrap(), (RUNS, 0));
        // With the queue full too, a further one is refused at once.
        turns.state.lock().unwrap().1 = QUEUE;
        assert!(turns.take().is_none());
        turns.state.lock().unwrap().1 = 0;
        drop((a, b));
        assert_eq!(*turns.state.lock().unwrap(), (0, 0));
    }
}
