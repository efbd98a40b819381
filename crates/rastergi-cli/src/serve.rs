//! `rastergi serve`: serves the web page (`web/`, built by `scripts/web-build.sh`) on
//! localhost, so that a browser with WebGPU can open it. A static file server for one user:
//! GET and HEAD of files under the folder, nothing else.

use std::io::{BufRead, BufReader, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Component, Path, PathBuf};

use anyhow::{Context, bail};

#[derive(clap::Args, Debug)]
pub struct ServeArgs {
    /// Port to listen on (localhost only); 0 picks a free one.
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// The page's folder (default: `web` here, else the checkout this program was built from).
    #[arg(long, value_name = "DIR")]
    pub dir: Option<PathBuf>,
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

pub fn run(a: &ServeArgs) -> anyhow::Result<()> {
    let dir = page_dir(a)?;
    let listener = TcpListener::bind(("127.0.0.1", a.port))
        .with_context(|| format!("cannot listen on port {}; choose another with --port", a.port))?;
    let port = listener.local_addr()?.port();
    // The one line a script waits for (scripts/web-test.sh reads the port from it).
    println!("serving {} at http://127.0.0.1:{port}/ (Ctrl-C stops)", dir.display());
    std::io::stdout().flush()?;
    for stream in listener.incoming() {
        let Ok(stream) = stream else { continue };
        let dir = dir.clone();
        std::thread::spawn(move || {
            if let Err(e) = answer(stream, &dir) {
                log::info!("serve: {e}");
            }
        });
    }
    Ok(())
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

fn answer(stream: TcpStream, dir: &Path) -> std::io::Result<()> {
    let mut reader = BufReader::new(stream.try_clone()?);
    let mut request = String::new();
    reader.read_line(&mut request)?;
    // The headers are not used; read them to the blank line.
    let mut line = String::new();
    while reader.read_line(&mut line)? > 2 {
        line.clear();
    }
    let mut words = request.split_whitespace();
    let (method, target) = (words.next().unwrap_or(""), words.next().unwrap_or("/"));
    let mut out = stream;
    if method != "GET" && method != "HEAD" {
        return reply(&mut out, "405 Method Not Allowed", "text/plain", b"GET or HEAD only\n", true);
    }
    match resolve(dir, target).and_then(|f| std::fs::read(&f).ok().map(|b| (f, b))) {
        Some((file, body)) => reply(&mut out, "200 OK", content_type(&file), &body, method == "GET"),
        None => reply(&mut out, "404 Not Found", "text/plain", b"not found\n", method == "GET"),
    }
}

fn reply(out: &mut TcpStream, status: &str, kind: &str, body: &[u8], with_body: bool) -> std::io::Result<()> {
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
}
