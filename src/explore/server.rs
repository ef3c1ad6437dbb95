//! The page's local HTTP server (tiny_http: synchronous, no async runtime).
//!
//! - Bound to 127.0.0.1 unless asked otherwise; it serves the page's three
//!   files (compiled into the binary) and three GET routes: `/api/model`
//!   (the controls and lessons), `/api/run?set=K=V&...&timeline=N` (one
//!   redraw) and `/api/model.toml?set=...` (the resolved model).
//! - It reads no file: the model was read when the server started.
//! - Runs are bounded: [`WORKERS`] at a time, [`QUEUE`] waiting; a request
//!   beyond that gets 503 at once. Each run is held to an event budget
//!   ([`super::page_run`]). A request line over [`MAX_URL_BYTES`] gets
//!   414, a body is never read (405 for any method but GET).
//! - Ctrl-C (SIGINT) or SIGTERM stops it: the runs under way finish, the
//!   waiting ones get 503, and the command exits 0.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use tiny_http::{Header, Method, Request, Response, Server};

use super::page_run::{Explorer, PageError, TIMELINE_FRAMES};

/// Runs under way at once.
pub const WORKERS: usize = 2;
/// Requests waiting for a worker before the server answers 503.
pub const QUEUE: usize = 8;
/// The longest request line (path and query) the server takes.
pub const MAX_URL_BYTES: usize = 16 * 1024;

const INDEX_HTML: &str = include_str!("page/index.html");
const APP_JS: &str = include_str!("page/app.js");
const STYLE_CSS: &str = include_str!("page/style.css");

/// Why the server could not start or stopped.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The address could not be bound.
    #[error("cannot listen on {addr}: {message}")]
    Bind {
        /// The address asked for.
        addr: String,
        /// The system's reason.
        message: String,
    },
    /// The signal handler could not be installed.
    #[error("cannot install the Ctrl-C handler: {0}")]
    Signal(std::io::Error),
}

fn header(name: &str, value: &str) -> Header {
    Header::from_bytes(name.as_bytes(), value.as_bytes()).expect("ASCII header")
}

fn respond(req: Request, status: u16, content_type: &str, body: String) {
    let response = Response::from_string(body)
        .with_status_code(status)
        .with_header(header("Content-Type", content_type))
        .with_header(header("Cache-Control", "no-store"))
        .with_header(header("X-Content-Type-Options", "nosniff"));
    // A client that went away is no error of the server's.
    let _ = req.respond(response);
}

fn respond_error(req: Request, status: u16, message: &str) {
    let body = serde_json::json!({ "error": message }).to_string();
    respond(req, status, "application/json; charset=utf-8", body);
}

/// The query's `set` assignments and `timeline` frame count.
fn query(url: &str) -> Result<(Vec<String>, u64), PageError> {
    let q = url.split_once('?').map_or("", |(_, q)| q);
    let mut sets = Vec::new();
    let mut timeline = TIMELINE_FRAMES;
    for (k, v) in form_urlencoded::parse(q.as_bytes()) {
        match k.as_ref() {
            "set" => sets.push(v.into_owned()),
            "timeline" => {
                timeline = v
                    .parse()
                    .map_err(|_| PageError::Request(format!("timeline={v:?}: expected a whole number of frames")))?
            }
            other => {
                return Err(PageError::Request(format!(
                    "unknown query parameter {other:?} (set, timeline)"
                )));
            }
        }
    }
    Ok((sets, timeline))
}

fn path_of(url: &str) -> &str {
    url.split_once('?').map_or(url, |(p, _)| p)
}

/// Answers one API request (run by a worker).
fn answer(explorer: &Explorer, req: Request) {
    let url = req.url().to_string();
    let json = |v: Result<String, PageError>, req: Request| match v {
        Ok(body) => respond(req, 200, "application/json; charset=utf-8", body),
        Err(e) => respond_error(req, e.status(), &e.to_string()),
    };
    let to_json = |v: &dyn erased::Json| v.json().map_err(|e| PageError::View(e.to_string()));
    match path_of(&url) {
        "/api/model" => json(explorer.page_model().and_then(|m| to_json(&m)), req),
        "/api/run" => json(
            query(&url)
                .and_then(|(sets, tl)| explorer.run(&sets, tl))
                .and_then(|r| to_json(&r)),
            req,
        ),
        "/api/model.toml" => match query(&url).and_then(|(sets, _)| explorer.model_toml(&sets)) {
            Ok(text) => {
                let response = Response::from_string(text)
                    .with_header(header("Content-Type", "application/toml; charset=utf-8"))
                    .with_header(header("Content-Disposition", "attachment; filename=\"model.toml\""))
                    .with_header(header("Cache-Control", "no-store"));
                let _ = req.respond(response);
            }
            Err(e) => respond_error(req, e.status(), &e.to_string()),
        },
        other => respond_error(req, 404, &format!("no such page: {other}")),
    }
}

mod erased {
    /// Serialisation behind a `dyn` (the routes' results are of several types).
    pub trait Json {
        fn json(&self) -> serde_json::Result<String>;
    }
    impl<T: serde::Serialize> Json for T {
        fn json(&self) -> serde_json::Result<String> {
            serde_json::to_string(self)
        }
    }
}

/// Serves a static file, or passes an API request to the workers.
fn dispatch(req: Request, work: &SyncSender<Request>) {
    if req.url().len() > MAX_URL_BYTES {
        return respond_error(
            req,
            414,
            &format!("the request line is over {MAX_URL_BYTES} bytes: fewer or shorter assignments"),
        );
    }
    if req.method() != &Method::Get {
        return respond_error(req, 405, "only GET is served");
    }
    let path = path_of(req.url()).to_string();
    match path.as_str() {
        "/" | "/index.html" => respond(req, 200, "text/html; charset=utf-8", INDEX_HTML.into()),
        "/app.js" => respond(req, 200, "text/javascript; charset=utf-8", APP_JS.into()),
        "/style.css" => respond(req, 200, "text/css; charset=utf-8", STYLE_CSS.into()),
        "/favicon.ico" => respond(req, 204, "text/plain", String::new()),
        p if p.starts_with("/api/") => match work.try_send(req) {
            Ok(()) => {}
            Err(TrySendError::Full(req)) | Err(TrySendError::Disconnected(req)) => respond_error(
                req,
                503,
                &format!("the server is busy ({WORKERS} runs under way, {QUEUE} waiting): try again"),
            ),
        },
        other => respond_error(req, 404, &format!("no such page: {other}")),
    }
}

fn worker(explorer: Arc<Explorer>, queue: Arc<Mutex<Receiver<Request>>>) {
    loop {
        let next = match queue.lock() {
            Ok(rx) => rx.recv(),
            Err(_) => return,
        };
        match next {
            Ok(req) => {
                // A panic in one run must not take the server down: the
                // request, dropped unanswered, gets tiny_http's empty 500,
                // and the worker goes on.
                let e = explorer.clone();
                let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(move || answer(&e, req)));
            }
            Err(_) => return,
        }
    }
}

/// Serves `explorer` on `addr` until Ctrl-C; `ready` is told the address
/// the server listens on once it does.
pub fn serve(explorer: Explorer, addr: &str, ready: impl FnOnce(std::net::SocketAddr)) -> Result<(), ServeError> {
    let server = Server::http(addr).map_err(|e| ServeError::Bind {
        addr: addr.to_string(),
        message: e.to_string(),
    })?;
    let stop = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(signal, stop.clone()).map_err(ServeError::Signal)?;
    }
    if let Some(a) = server.server_addr().to_ip() {
        ready(a);
    }
    let explorer = Arc::new(explorer);
    let (tx, rx) = sync_channel::<Request>(QUEUE);
    let rx = Arc::new(Mutex::new(rx));
    let workers: Vec<_> = (0..WORKERS)
        .map(|_| {
            let (e, q) = (explorer.clone(), rx.clone());
            std::thread::spawn(move || worker(e, q))
        })
        .collect();
    while !stop.load(Ordering::Relaxed) {
        match server.recv_timeout(Duration::from_millis(100)) {
            Ok(Some(req)) => dispatch(req, &tx),
            Ok(None) => {}
            Err(e) => {
                let _ = writeln!(std::io::stderr(), "warning: a request could not be read: {e}");
            }
        }
    }
    drop(tx);
    for w in workers {
        let _ = w.join();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_query_gives_the_assignments_in_order_and_refuses_the_unknown() {
        let (sets, tl) = query("/api/run?set=display.buffers%3D3&set=fidelity%3D%22draw%22&timeline=6").unwrap();
        assert_eq!(sets, ["display.buffers=3", "fidelity=\"draw\""]);
        assert_eq!(tl, 6);
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
        assert_eq!(query("/api/run").unwrap(), (vec![], TIMELINE_FRAMES));
    }
}
