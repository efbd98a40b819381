//! `rastergi serve` under careless and hostile clients: it keeps answering a normal request
//! while a slow client, a 100 MB request line and 100 idle connections are open; it refuses
//! connections beyond its limit without a thread and recovers when the idle ones time out;
//! and it does not spin when `accept` fails (out of file descriptors).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The server's request timeout in these tests, seconds.
const TIMEOUT: f64 = 3.0;

/// A page folder with an index and the built module the server checks for.
fn page(dir: &Path) -> Vec<u8> {
    let index = b"<!doctype html><title>rastergi</title><p>served\n".to_vec();
    std::fs::create_dir_all(dir.join("pkg")).unwrap();
    std::fs::write(dir.join("index.html"), &index).unwrap();
    std::fs::write(dir.join("pkg/rastergi_web.js"), b"export {};\n").unwrap();
    index
}

/// The server, killed when dropped.
struct Server {
    child: Child,
    port: u16,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn serve(dir: &Path, timeout: f64, setup: impl FnOnce(&mut Command)) -> Server {
    let mut command = Command::new(env!("CARGO_BIN_EXE_rastergi"));
    command
        .args(["serve", "--port", "0", "--request-timeout", &timeout.to_string(), "--dir"])
        .arg(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::null());
    setup(&mut command);
    let mut child = command.spawn().expect("rastergi serve starts");
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
    let port = line.rsplit(':').next().and_then(|p| p.split('/').next()).and_then(|p| p.parse().ok());
    let port = port.unwrap_or_else(|| panic!("no port in {line:?}"));
    Server { child, port }
}

/// GET `path`: the status line and the body, within `limit`.
fn get(port: u16, path: &str, limit: Duration) -> (String, Vec<u8>) {
    let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.set_read_timeout(Some(limit)).unwrap();
    write!(s, "GET {path} HTTP/1.1\r\nHost: localhost\r\n\r\n").unwrap();
    let mut reply = Vec::new();
    s.read_to_end(&mut reply).unwrap();
    let end = reply.windows(4).position(|w| w == b"\r\n\r\n").expect("a whole reply head") + 4;
    let status = String::from_utf8_lossy(&reply[..end]).lines().next().unwrap_or("").to_owned();
    (status, reply[end..].to_vec())
}

/// The server's resident memory (kB) and the CPU time it used (s), from /proc.
fn usage(pid: u32) -> (u64, f64) {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let rss = status.lines().find_map(|l| l.strip_prefix("VmRSS:")).and_then(|v| v.split_whitespace().next());
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    // The fields after the command's closing parenthesis; utime and stime are the 14th and
    // 15th of the line, in clock ticks.
    let fields: Vec<&str> = stat[stat.rfind(')').unwrap() + 2..].split(' ').collect();
    let ticks: f64 = fields[11].parse::<f64>().unwrap() + fields[12].parse::<f64>().unwrap();
    let hz = unsafe { libc::sysconf(libc::_SC_CLK_TCK) } as f64;
    (rss.unwrap().parse().unwrap(), ticks / hz)
}

#[test]
fn a_normal_request_is_answered_beside_a_slow_client_a_huge_line_and_100_idle_connections() {
    let dir = tempfile::tempdir().unwrap();
    let index = page(dir.path());
    let server = serve(dir.path(), TIMEOUT, |_| {});
    let port = server.port;
    let idle: Vec<TcpStream> = (0..100).map(|_| TcpStream::connect(("127.0.0.1", port)).unwrap()).collect();
    // A client that sends its request a byte every 100 ms: it is cut off at the timeout.
    let slow = std::thread::spawn(move || {
        let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
        let start = Instant::now();
        for b in b"GET / HTTP/1.1\r\nHost: localhost\r\nX-Slow: ".iter().cycle() {
            if s.write_all(&[*b]).is_err() || start.elapsed() > Duration::from_secs_f64(3.0 * TIMEOUT) {
                break;
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        let mut reply = String::new();
        let _ = s.read_to_string(&mut reply);
        (reply.lines().next().unwrap_or("").to_owned(), start.elapsed())
    });
    // A request line of 100 MB: refused after its first few kilobytes.
    let huge = std::thread::spawn(move || {
        let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
        s.set_write_timeout(Some(Duration::from_secs(20))).unwrap();
        let chunk = vec![b'a'; 1 << 20];
        let mut sent = s.write_all(b"GET /").map_or(0, |()| 5);
        for _ in 0..100 {
            match s.write_all(&chunk) {
                Ok(()) => sent += chunk.len(),
                Err(_) => break,
            }
        }
        let mut reply = Vec::new();
        let _ = s.read_to_end(&mut reply);
        (String::from_utf8_lossy(&reply).lines().next().unwrap_or("").to_owned(), sent)
    });
    std::thread::sleep(Duration::from_millis(500));
    let start = Instant::now();
    let (status, body) = get(port, "/", Duration::from_secs(5));
    let took = start.elapsed();
    let (rss, _) = usage(server.child.id());
    println!(
        "a normal request beside them: {status} in {:.3} s; the server holds {} MB",
        took.as_secs_f64(),
        rss >> 10
    );
    assert_eq!(status, "HTTP/1.1 200 OK");
    assert_eq!(body, index);
    assert!(took < Duration::from_secs(2), "the page took {took:?}");
    let (huge_status, sent) = huge.join().unwrap();
    println!("100 MB request line: '{huge_status}' after {} MB sent", sent >> 20);
    assert!(
        huge_status.contains("414") || sent < 100 << 20,
        "the server took the whole 100 MB line ('{huge_status}', {sent} bytes sent)"
    );
    let (slow_status, slow_took) = slow.join().unwrap();
    println!("slow client: '{slow_status}' after {:.1} s", slow_took.as_secs_f64());
    assert_eq!(slow_status, "HTTP/1.1 408 Request Timeout");
    assert!(slow_took < Duration::from_secs_f64(TIMEOUT + 2.0), "{slow_took:?}");
    // The idle connections were cut off at the timeout too: each reads a 408.
    for mut s in idle {
        s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        let mut reply = String::new();
        s.read_to_string(&mut reply).unwrap();
        assert!(reply.starts_with("HTTP/1.1 408"), "{reply}");
    }
}

#[test]
fn connections_beyond_the_limit_are_refused_and_the_server_recovers() {
    let dir = tempfile::tempdir().unwrap();
    page(dir.path());
    let server = serve(dir.path(), TIMEOUT, |_| {});
    let port = server.port;
    let max = rastergi_cli::serve::MAX_CONNECTIONS;
    let held: Vec<TcpStream> = (0..max + 20).map(|_| TcpStream::connect(("127.0.0.1", port)).unwrap()).collect();
    std::thread::sleep(Duration::from_millis(500));
    let (status, _) = get(port, "/", Duration::from_secs(5));
    println!("with {} idle connections: {status}", held.len());
    assert_eq!(status, "HTTP/1.1 503 Service Unavailable");
    // Once the idle ones time out the page is served again.
    std::thread::sleep(Duration::from_secs_f64(TIMEOUT + 1.0));
    let (status, _) = get(port, "/", Duration::from_secs(5));
    assert_eq!(status, "HTTP/1.1 200 OK");
}

#[test]
fn a_failing_accept_does_not_spin() {
    let dir = tempfile::tempdir().unwrap();
    page(dir.path());
    // Few file descriptors: a handful of connections exhaust them, and `accept` fails with
    // EMFILE for as long as the rest wait in the backlog.
    let server = serve(dir.path(), 30.0, |c| {
        use std::os::unix::process::CommandExt;
        // SAFETY: setrlimit is async-signal-safe; nothing else runs between fork and exec.
        unsafe {
            c.pre_exec(|| {
                let limit = libc::rlimit { rlim_cur: 16, rlim_max: 16 };
                if libc::setrlimit(libc::RLIMIT_NOFILE, &limit) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
    });
    let pid = server.child.id();
    let held: Vec<TcpStream> = (0..40).map(|_| TcpStream::connect(("127.0.0.1", server.port)).unwrap()).collect();
    std::thread::sleep(Duration::from_millis(500));
    let (_, before) = usage(pid);
    std::thread::sleep(Duration::from_secs(2));
    let (_, after) = usage(pid);
    println!("{} connections held: the server used {:.3} s of CPU in 2 s", held.len(), after - before);
    assert!(after - before < 0.2, "the server used {:.2} s of CPU in 2 s waiting to accept", after - before);
}
