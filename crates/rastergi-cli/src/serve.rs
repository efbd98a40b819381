//! `rastergi serve`: serves the web page (`web/`, built by `scripts/web-build.sh`) on
//! localhost, so that a browser with WebGPU can open it. A static file server for one user:
//! GET and HEAD of files under the folder, nothing else.
//!
//! Bounded against careless or hostile clients: a request's head (its line and headers) is
//! read into at most [`MAX_HEAD`] bytes, its line at most [`MAX_LINE`] (414 beyond) and at most
//! [`MAX_HEADERS`] header lines (431 beyond), within `--request-timeout` seconds (408 after);
//! each connection is answered on a thread of its own, at most [`MAX_CONNECTIONS`] at once
//! (beyond, one thread answers 503 to [`MAX_WAITING`] of them at a time and closes the rest
//! at once), and a reply must be taken within [`WRITE_TIMEOUT`]. An
//! `accept` that fails (out of file descriptors) is retried after [`ACCEPT_BACKOFF`], not in a
//! spin.

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Component, Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};

/// Most bytes of a request line.
pub const MAX_LINE: usize = 8 << 10;
/// Most bytes of a request's head: its line and its headers.
pub const MAX_HEAD: usize = 64 << 10;
/// Most header lines of a request.
pub const MAX_HEADERS: usize = 100;
/// Most connections answered at once.
pub const MAX_CONNECTIONS: usize = 128;
/// Time a client has to take a reply.
pub const WRITE_TIMEOUT: Duration = Duration::from_secs(30);
/// Connections beyond [`MAX_CONNECTIONS`] waiting for their 503.
pub const MAX_WAITING: usize = 64;
/// Wait before accepting again after `accept` failed.
pub const ACCEPT_BACKOFF: Duration = Duration::from_millis(100);

#[derive(clap::Args, Debug)]
pub struct ServeArgs {
    /// Port to listen on (localhost only); 0 picks a free one.
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// The page's folder (default: `web` here, else the checkout this program was built from).
    #[arg(long, value_name = "DIR")]
    pub dir: Option<PathBuf>,
    /// Seconds a client has to send its request (its line and headers) once connected.
    #[arg(long, value_name = "SECONDS", default_value_t = 10.0)]
    pub request_timeout: f64,
}

/// The page's folder: as given, else `web` in the working directory, else in the checkout.
fn page_dir(a: &ServeArgs) -> anyhow::Result<PathBuf> {
    let built_from = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../web");
    let dir = match &a.dir {
        Some(d) => d.clone(),
        None if Path::new("web/index.html").is_file() => PathBuf::from("web"),
        None => built_from,
    };
    if !dir.join("index.html").is_file() {
        bail!("{} holds no index.html; give the page's folder with --dir", dir.display());
    }
    if !dir.join("pkg/rastergi_web.js").is_file() {
        bail!("the page in {} is not built (no pkg/rastergi_web.js); run scripts/web-build.sh first", dir.display());
    }
    Ok(dir)
}

/// Counts a connection as answered until it is dropped.
struct Active(Arc<AtomicUsize>);

impl Drop for Active {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

pub fn run(a: &ServeArgs) -> anyhow::Result<()> {
    if !(a.request_timeout.is_finite() && a.request_timeout > 0.0 && a.request_timeout <= 3600.0) {
        bail!("--request-timeout must be a number of seconds in (0, 3600], got {}", a.request_timeout);
    }
    let timeout = Duration::from_secs_f64(a.request_timeout);
    let dir = page_dir(a)?;
    let listener = TcpListener::bind(("127.0.0.1", a.port))
        .with_context(|| format!("cannot listen on port {}; choose another with --port", a.port))?;
    let port = listener.local_addr()?.port();
    // The one line a script waits for (scripts/web-test.sh reads the port from it).
    println!("serving {} at http://127.0.0.1:{port}/ (Ctrl-C stops)", dir.display());
    std::io::stdout().flush()?;
    let active = Arc::new(AtomicUsize::new(0));
    // Whether the last accept failed: a run of failures is logged once.
    let mut failing = false;
    let (refuse, refused) = std::sync::mpsc::sync_channel::<TcpStream>(MAX_WAITING);
    std::thread::Builder::new().name("serve-busy".into()).spawn(move || busy(refused))?;
    loop {
        let stream = match listener.accept() {
            Ok((stream, _)) => {
                failing = false;
                stream
            }
            Err(e) => {
                // Out of file descriptors, or a connection reset before it was taken: the
                // error repeats until something changes, so wait instead of spinning.
                if !std::mem::replace(&mut failing, true) {
                    log::warn!("serve: cannot accept connections ({e}); retrying every {ACCEPT_BACKOFF:?}");
                }
                std::thread::sleep(ACCEPT_BACKOFF);
                continue;
            }
        };
        if active.load(Ordering::SeqCst) >= MAX_CONNECTIONS {
            // Closed at once (dropped) where too many wait already.
            let _ = refuse.try_send(stream);
            continue;
        }
        active.fetch_add(1, Ordering::SeqCst);
        let guard = Active(active.clone());
        let dir = dir.clone();
        let spawned = std::thread::Builder::new().name("serve".into()).stack_size(256 << 10).spawn(move || {
            let _guard = guard;
            if let Err(e) = answer(stream, &dir, timeout) {
                log::info!("serve: {e}");
            }
        });
        if let Err(e) = spawned {
            log::warn!("serve: cannot start a thread for a connection ({e})");
            std::thread::sleep(ACCEPT_BACKOFF);
        }
    }
}

/// Answers 503 to the connections beyond [`MAX_CONNECTIONS`] and closes each once the
/// client has closed it or after a second, [`MAX_WAITING`] at a time on this one thread: what
/// a client sent is read before the close, which would otherwise reset the connection and
/// lose the reply.
fn busy(refused: std::sync::mpsc::Receiver<TcpStream>) {
    let body = "too many connections; try again\n";
    let mut waiting: Vec<(TcpStream, Instant)> = Vec::new();
    loop {
        if waiting.len() < MAX_WAITING {
            let next = match waiting.is_empty() {
                true => match refused.recv() {
                    Ok(stream) => Some(stream),
                    Err(_) => return,
                },
                false => refused.try_recv().ok(),
            };
            if let Some(stream) = next {
                // The reply fits the socket's buffer: written without waiting.
                if stream.set_nonblocking(true).is_ok() {
                    let _ = reply(&mut &stream, "503 Service Unavailable", "text/plain", body.as_bytes(), true);
                    let _ = stream.shutdown(std::net::Shutdown::Write);
                    waiting.push((stream, Instant::now() + Duration::from_secs(1)));
                }
                continue;
            }
        }
        let mut sink = [0u8; 4096];
        waiting.retain(|(stream, deadline)| {
            loop {
                match (&*stream).read(&mut sink) {
                    Ok(0) => return false,
                    Ok(_) => {}
                    Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => return Instant::now() < *deadline,
                    Err(_) => return false,
                }
            }
        });
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The content type of a file by its extension (the module scripts and wasm need theirs).
fn content_type(path: &Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()).unwrap_or("") {
        "html" => "text/html; charset=utf-8",
        "js" => "text/javascript; charset=utf-8",
        "css" => "text/css; charset=utf-8",
        "wasm" => "application/wasm",
        "json" | "gltf" => "application/json",
        "png" => "image/png",
        "jpg" | "jpeg" => "image/jpeg",
        _ => "application/octet-stream",
    }
}

/// The file a request path names under `dir`; `None` for paths that leave it.
fn resolve(dir: &Path, target: &str) -> Option<PathBuf> {
    let path = target.split(['?', '#']).next().unwrap_or("/");
    let relative = Path::new(path.trim_start_matches('/'));
    if relative.components().any(|c| !matches!(c, Component::Normal(_))) {
        return None;
    }
    let file = dir.join(relative);
    Some(if file.is_dir() { file.join("index.html") } else { file })
}

/// What became of reading a request's head.
#[derive(Debug, PartialEq, Eq)]
enum Head {
    /// The method and the target of a whole head.
    Request(String, String),
    /// A head refused: the status to answer.
    Refused(&'static str),
    /// The client closed the connection before a whole head.
    Closed,
}

/// Reads a request's head (up to its blank line) from `r` within the bounds of the module's
/// docs, by `deadline`; `set_timeout` gives the reader the time left before each read.
fn read_head(
    r: &mut impl Read,
    deadline: Instant,
    mut set_timeout: impl FnMut(Duration) -> std::io::Result<()>,
) -> std::io::Result<Head> {
    let mut head: Vec<u8> = Vec::with_capacity(1024);
    let mut chunk = [0u8; 4096];
    loop {
        // The request line: up to its line break, or all read so far.
        let line = head.iter().position(|&b| b == b'\n').unwrap_or(head.len());
        if line > MAX_LINE {
            return Ok(Head::Refused("414 URI Too Long"));
        }
        if let Some(end) = find_end(&head) {
            let text = String::from_utf8_lossy(&head[..end]);
            let mut lines = text.lines();
            let request = lines.next().unwrap_or("");
            if lines.filter(|l| !l.trim().is_empty()).count() > MAX_HEADERS {
                return Ok(Head::Refused("431 Request Header Fields Too Large"));
            }
            let mut words = request.split_whitespace();
            let (method, target) = (words.next().unwrap_or(""), words.next().unwrap_or("/"));
            return Ok(Head::Request(method.to_owned(), target.to_owned()));
        }
        if head.len() >= MAX_HEAD {
            return Ok(Head::Refused("431 Request Header Fields Too Large"));
        }
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Ok(Head::Refused("408 Request Timeout"));
        }
        set_timeout(left)?;
        let want = chunk.len().min(MAX_HEAD - head.len());
        match r.read(&mut chunk[..want]) {
            Ok(0) => return Ok(Head::Closed),
            Ok(n) => head.extend_from_slice(&chunk[..n]),
            Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {
                return Ok(Head::Refused("408 Request Timeout"));
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
}

/// Where a head's blank line ends (after `\r\n\r\n` or `\n\n`).
fn find_end(head: &[u8]) -> Option<usize> {
    let crlf = head.windows(4).position(|w| w == b"\r\n\r\n").map(|i| i + 4);
    let lf = head.windows(2).position(|w| w == b"\n\n").map(|i| i + 2);
    match (crlf, lf) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

fn answer(stream: TcpStream, dir: &Path, timeout: Duration) -> std::io::Result<()> {
    stream.set_write_timeout(Some(WRITE_TIMEOUT))?;
    let deadline = Instant::now() + timeout;
    let head = read_head(&mut &stream, deadline, |left| stream.set_read_timeout(Some(left)))?;
    let mut out = &stream;
    let (method, target) = match head {
        Head::Request(method, target) => (method, target),
        Head::Refused(status) => return reply(&mut out, status, "text/plain", format!("{status}\n").as_bytes(), true),
        Head::Closed => return Ok(()),
    };
    if method != "GET" && method != "HEAD" {
        return reply(&mut out, "405 Method Not Allowed", "text/plain", b"GET or HEAD only\n", true);
    }
    match resolve(dir, &target).and_then(|f| std::fs::read(&f).ok().map(|b| (f, b))) {
        Some((file, body)) => reply(&mut out, "200 OK", content_type(&file), &body, method == "GET"),
        None => reply(&mut out, "404 Not Found", "text/plain", b"not found\n", method == "GET"),
    }
}

fn reply(out: &mut impl Write, status: &str, kind: &str, body: &[u8], with_body: bool) -> std::io::Result<()> {
    write!(
        out,
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: no-cache\r\nConnection: close\r\n\r\n",
        body.len()
    )?;
    if with_body {
        out.write_all(body)?;
    }
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn request_paths_stay_inside_the_page() {
        let dir = Path::new("/srv/page");
        assert_eq!(resolve(dir, "/pkg/a.wasm?x=1"), Some(dir.join("pkg/a.wasm")));
        assert_eq!(resolve(dir, "/../etc/passwd"), None);
        assert_eq!(resolve(dir, "/pkg/../../x"), None);
        assert_eq!(content_type(Path::new("a/b.wasm")), "application/wasm");
        assert_eq!(content_type(Path::new("main.js")), "text/javascript; charset=utf-8");
    }

    fn head_of(bytes: &[u8]) -> Head {
        let far = Instant::now() + Duration::from_secs(60);
        read_head(&mut std::io::Cursor::new(bytes.to_vec()), far, |_| Ok(())).unwrap()
    }

    #[test]
    fn request_heads_are_read_within_their_bounds() {
        let get = |t: &str| Head::Request("GET".into(), t.into());
        assert_eq!(head_of(b"GET /a.js HTTP/1.1\r\nHost: x\r\n\r\n"), get("/a.js"));
        assert_eq!(head_of(b"GET / HTTP/1.0\n\n"), get("/"));
        assert_eq!(head_of(b"GET / HTTP/1.1\r\nHost: x\r\n"), Head::Closed);
        let long = format!("GET /{} HTTP/1.1\r\n\r\n", "a".repeat(MAX_LINE + 1));
        assert_eq!(head_of(long.as_bytes()), Head::Refused("414 URI Too Long"));
        let many = format!("GET / HTTP/1.1\r\n{}\r\n", "X: y\r\n".repeat(MAX_HEADERS + 1));
        assert_eq!(head_of(many.as_bytes()), Head::Refused("431 Request Header Fields Too Large"));
        let fits = format!("GET / HTTP/1.1\r\n{}\r\n", "X: y\r\n".repeat(MAX_HEADERS));
        assert_eq!(head_of(fits.as_bytes()), get("/"));
        let huge = format!("GET / HTTP/1.1\r\n{}", "X: yyyyyyyyyyyyyyyy\r\n".repeat(MAX_HEAD / 8));
        assert_eq!(head_of(huge.as_bytes()), Head::Refused("431 Request Header Fields Too Large"));
        let past = Instant::now() - Duration::from_secs(1);
        let late = read_head(&mut std::io::Cursor::new(b"GET".to_vec()), past, |_| Ok(())).unwrap();
        assert_eq!(late, Head::Refused("408 Request Timeout"));
    }
}
