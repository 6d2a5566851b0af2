//! The web HMI's network shell: a small HTTP/1.1 server for the page's three files and a
//! WebSocket per open page. Connections are dumb pipes: each request a page sends goes to the
//! bridge's loop as a [`WebEvent`], and the loop sends frames back through the connection's
//! [`Outbox`]. All machine state stays in the loop.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::Arc;
use std::time::Duration;

use tungstenite::protocol::Role;
use tungstenite::{Message, WebSocket};

use super::assets;

/// The longest request head accepted (request line and headers).
const MAX_HEAD: usize = 16 * 1024;
/// The longest message a page may send (an MDI entry, an offset row; not programs, which are
/// loaded through the same 4 MiB limit as the services).
pub const MAX_MESSAGE: usize = cnc_runtime::MAX_PROGRAM_BYTES + 64 * 1024;

/// Connections served at once; more are answered 503 and closed, so a client that opens
/// connections without end cannot take the bridge's threads.
pub const MAX_CONNECTIONS: usize = 32;

/// Frames for one page; a page that is gone makes `send` fail and is forgotten.
pub type Outbox = Sender<String>;

pub enum WebEvent {
    /// A page opened its WebSocket: `client` is `web@<address>`.
    Connected {
        id: u64,
        client: String,
        outbox: Outbox,
    },
    /// A page sent a text message.
    Request {
        id: u64,
        client: String,
        text: String,
    },
    Closed {
        id: u64,
    },
}

pub struct WebServer {
    pub events: Receiver<WebEvent>,
    pub address: SocketAddr,
    stop: Arc<AtomicBool>,
}

impl Drop for WebServer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

impl WebServer {
    /// Listens on `address` (`127.0.0.1:8080`).
    pub fn start(address: &str) -> Result<WebServer, String> {
        let listener =
            TcpListener::bind(address).map_err(|e| format!("web HMI on {address}: {e}"))?;
        let local = listener
            .local_addr()
            .map_err(|e| format!("web HMI on {address}: {e}"))?;
        listener
            .set_nonblocking(true)
            .map_err(|e| format!("web HMI: {e}"))?;
        let (tx, rx) = mpsc::channel();
        let stop = Arc::new(AtomicBool::new(false));
        let stopped = stop.clone();
        std::thread::Builder::new()
            .name("web-hmi".into())
            .spawn(move || accept_loop(listener, tx, stopped))
            .map_err(|e| format!("web HMI: {e}"))?;
        Ok(WebServer {
            events: rx,
            address: local,
            stop,
        })
    }
}

fn accept_loop(listener: TcpListener, events: Sender<WebEvent>, stop: Arc<AtomicBool>) {
    let mut next_id = 0u64;
    let open = Arc::new(AtomicUsize::new(0));
    while !stop.load(Ordering::Relaxed) {
        match listener.accept() {
            Ok((mut stream, peer)) => {
                if open.load(Ordering::Relaxed) >= MAX_CONNECTIONS {
                    let _ = stream.set_nonblocking(false);
                    let _ = respond(
                        &mut stream,
                        "503 Service Unavailable",
                        "text/plain",
                        b"too many connections\n",
                    );
                    continue;
                }
                let slot = Slot::take(&open);
                next_id += 1;
                let id = next_id;
                let events = events.clone();
                let stop = stop.clone();
                let spawned = std::thread::Builder::new()
                    .name(format!("web-hmi-{id}"))
                    .spawn(move || {
                        let _slot = slot;
                        if let Err(e) = serve(stream, peer, id, &events, &stop) {
                            log::debug!("web HMI connection {peer}: {e}");
                        }
                    });
                if let Err(e) = spawned {
                    log::warn!("web HMI: connection {peer} not served: {e}");
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                std::thread::sleep(Duration::from_millis(20));
            }
            Err(e) => {
                log::warn!("web HMI: accept: {e}");
                std::thread::sleep(Duration::from_millis(100));
            }
        }
    }
}

/// One of the [`MAX_CONNECTIONS`], given back when the connection's thread ends (or was never
/// started).
struct Slot(Arc<AtomicUsize>);

impl Slot {
    fn take(open: &Arc<AtomicUsize>) -> Slot {
        open.fetch_add(1, Ordering::Relaxed);
        Slot(open.clone())
    }
}

impl Drop for Slot {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::Relaxed);
    }
}

/// A parsed request head.
struct Head {
    method: String,
    path: String,
    headers: Vec<(String, String)>,
}

impl Head {
    fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }
}

fn read_head(stream: &mut TcpStream) -> Result<Head, String> {
    let mut buf = Vec::with_capacity(1024);
    let mut byte = [0u8; 1];
    while !buf.ends_with(b"\r\n\r\n") {
        if buf.len() >= MAX_HEAD {
            return Err("request head too long".into());
        }
        match stream.read(&mut byte) {
            Ok(0) => return Err("closed before the request was complete".into()),
            Ok(_) => buf.push(byte[0]),
            Err(e) => return Err(e.to_string()),
        }
    }
    let text = std::str::from_utf8(&buf).map_err(|_| "request head is not UTF-8".to_string())?;
    let mut lines = text.split("\r\n");
    let mut first = lines.next().unwrap_or_default().split(' ');
    let method = first.next().unwrap_or_default().to_string();
    let path = first.next().unwrap_or_default().to_string();
    let headers = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(n, v)| (n.trim().to_string(), v.trim().to_string()))
        .collect();
    Ok(Head {
        method,
        path,
        headers,
    })
}

fn respond(stream: &mut TcpStream, status: &str, kind: &str, body: &[u8]) -> Result<(), String> {
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
        body.len()
    );
    stream
        .write_all(head.as_bytes())
        .and_then(|()| stream.write_all(body))
        .map_err(|e| e.to_string())
}

/// A page from another site must not command the machine through the operator's browser:
/// a WebSocket whose Origin names another host than the one asked is refused.
fn same_origin(head: &Head) -> bool {
    match (head.header("Origin"), head.header("Host")) {
        (None, _) => true,
        (Some(origin), Some(host)) => origin
            .split_once("://")
            .is_some_and(|(_, rest)| rest.trim_end_matches('/') == host),
        (Some(_), None) => false,
    }
}

fn serve(
    mut stream: TcpStream,
    peer: SocketAddr,
    id: u64,
    events: &Sender<WebEvent>,
    stop: &AtomicBool,
) -> Result<(), String> {
    stream.set_nonblocking(false).map_err(|e| e.to_string())?;
    stream
        .set_read_timeout(Some(Duration::from_secs(5)))
        .map_err(|e| e.to_string())?;
    let head = read_head(&mut stream)?;
    if head.method != "GET" {
        return respond(
            &mut stream,
            "405 Method Not Allowed",
            "text/plain",
            b"GET only\n",
        );
    }
    let path = head.path.split('?').next().unwrap_or_default();
    if path != "/ws" {
        return match assets::file(path) {
            Some((kind, body)) => respond(&mut stream, "200 OK", kind, body.as_bytes()),
            None => respond(&mut stream, "404 Not Found", "text/plain", b"not found\n"),
        };
    }
    let key = head.header("Sec-WebSocket-Key");
    let upgrade = head
        .header("Upgrade")
        .is_some_and(|u| u.eq_ignore_ascii_case("websocket"));
    let Some(key) = key.filter(|_| upgrade) else {
        return respond(
            &mut stream,
            "400 Bad Request",
            "text/plain",
            b"WebSocket only\n",
        );
    };
    if !same_origin(&head) {
        return respond(
            &mut stream,
            "403 Forbidden",
            "text/plain",
            b"other origin\n",
        );
    }
    let accept = tungstenite::handshake::derive_accept_key(key.as_bytes());
    let answer = format!(
        "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: {accept}\r\n\r\n"
    );
    stream
        .write_all(answer.as_bytes())
        .map_err(|e| e.to_string())?;
    stream
        .set_read_timeout(Some(Duration::from_millis(10)))
        .map_err(|e| e.to_string())?;
    let config = tungstenite::protocol::WebSocketConfig::default()
        .max_message_size(Some(MAX_MESSAGE))
        .max_frame_size(Some(MAX_MESSAGE));
    let mut ws = WebSocket::from_raw_socket(stream, Role::Server, Some(config));
    let client = format!("web@{}", peer.ip());
    let (outbox, frames) = mpsc::channel::<String>();
    let _ = events.send(WebEvent::Connected {
        id,
        client: client.clone(),
        outbox,
    });
    let result = pump(&mut ws, id, &client, events, &frames, stop);
    let _ = events.send(WebEvent::Closed { id });
    result
}

/// Moves messages both ways until the page or the node goes away.
fn pump(
    ws: &mut WebSocket<TcpStream>,
    id: u64,
    client: &str,
    events: &Sender<WebEvent>,
    frames: &Receiver<String>,
    stop: &AtomicBool,
) -> Result<(), String> {
    while !stop.load(Ordering::Relaxed) {
        match ws.read() {
            Ok(Message::Text(text)) => {
                let _ = events.send(WebEvent::Request {
                    id,
                    client: client.to_string(),
                    text: text.to_string(),
                });
            }
            Ok(Message::Close(_)) => return Ok(()),
            Ok(_) => {}
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            Err(e) => return Err(e.to_string()),
        }
        loop {
            match frames.try_recv() {
                Ok(frame) => ws.send(Message::text(frame)).map_err(|e| e.to_string())?,
                Err(mpsc::TryRecvError::Empty) => break,
                Err(mpsc::TryRecvError::Disconnected) => return Ok(()),
            }
        }
    }
    let _ = ws.close(None);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn head(origin: Option<&str>, host: &str) -> Head {
        let mut headers = vec![("Host".to_string(), host.to_string())];
        if let Some(o) = origin {
            headers.push(("Origin".into(), o.into()));
        }
        Head {
            method: "GET".into(),
            path: "/ws".into(),
            headers,
        }
    }

    fn get(address: SocketAddr, request: &str) -> String {
        let mut s = TcpStream::connect(address).expect("connect");
        s.write_all(request.as_bytes()).expect("send");
        let mut answer = String::new();
        let _ = s.read_to_string(&mut answer);
        answer
    }

    #[test]
    fn the_page_is_served_other_paths_are_not_and_connections_are_capped() {
        let server = WebServer::start("127.0.0.1:0").expect("listens");
        let a = server.address;
        assert!(get(a, "GET / HTTP/1.1\r\nHost: x\r\n\r\n").contains("<title>CNC operator panel"));
        assert!(get(a, "GET /app.js HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 200"));
        assert!(get(a, "GET /../etc/passwd HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 404"));
        assert!(get(a, "POST / HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 405"));
        assert!(get(a, "GET /ws HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 400"));
        // Connections that never send a request hold their slots until their timeout.
        let idle: Vec<TcpStream> = (0..MAX_CONNECTIONS)
            .map(|_| TcpStream::connect(a).expect("connect"))
            .collect();
        std::thread::sleep(Duration::from_millis(300));
        assert!(get(a, "GET / HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 503"));
        drop(idle);
        std::thread::sleep(Duration::from_millis(300));
        assert!(get(a, "GET / HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 200"));
    }

    #[test]
    fn a_websocket_from_another_site_is_refused() {
        assert!(same_origin(&head(None, "127.0.0.1:8080")));
        assert!(same_origin(&head(
            Some("http://127.0.0.1:8080"),
            "127.0.0.1:8080"
        )));
        assert!(!same_origin(&head(
            Some("http://evil.example"),
            "127.0.0.1:8080"
        )));
        assert!(!same_origin(&head(Some("null"), "127.0.0.1:8080")));
    }
}
