//! The web HMI's network shell: a small HTTP/1.1 server for the page's three files and a
//! WebSocket per open page. Connections are dumb pipes: each request a page sends goes to the
//! bridge's loop as a [`WebEvent`], and the loop sends frames back through the connection's
//! [`Outbox`]. All machine state stays in the loop.

use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::net::{IpAddr, SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use tungstenite::protocol::Role;
use tungstenite::{Message, WebSocket};

use super::assets;
use super::login::{session_cookie, Gate};

/// What a page sent: a JSON request, or a binary one (a JSON header, a zero byte, the
/// program's text as it is).
#[derive(Debug)]
pub enum Payload {
    Text(String),
    Binary(Vec<u8>),
}

/// The longest request head accepted (request line and headers).
const MAX_HEAD: usize = 16 * 1024;
/// The longest message a page may send: a program as large as the services take, sent as a
/// binary message (its text unescaped, [`super::protocol::parse_binary`]), and its header.
pub const MAX_MESSAGE: usize = cnc_runtime::MAX_PROGRAM_BYTES + 64 * 1024;

/// Connections served at once; more are answered 503 and closed, so a client that opens
/// connections without end cannot take the bridge's threads.
pub const MAX_CONNECTIONS: usize = 64;
/// Connections from one address at once: one host that opens many (or trickles its requests
/// a byte at a time) cannot lock the operator's panel out.
pub const MAX_PER_ADDRESS: usize = 8;
/// The whole request head (and a login's body) must arrive within this, however slowly its
/// bytes come.
const HEAD_DEADLINE: Duration = Duration::from_secs(5);
/// A failed login answers after this: guessing passwords over the network is slow.
const LOGIN_FAILURE_DELAY: Duration = Duration::from_secs(1);
/// The longest login body.
const MAX_LOGIN_BODY: usize = 4096;

/// Frames for one page; a page that is gone makes `send` fail and is forgotten.
pub type Outbox = Sender<String>;

pub enum WebEvent {
    /// A page opened its WebSocket: `client` is `web@<address>`.
    Connected {
        id: u64,
        client: String,
        outbox: Outbox,
    },
    /// A page sent a message: JSON text, or a binary program load.
    Request {
        id: u64,
        client: String,
        payload: Payload,
    },
    Closed {
        id: u64,
    },
    /// A login at the panel, accepted or refused (an audit event).
    Login {
        client: String,
        operator: String,
        accepted: bool,
        message: String,
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
    /// Listens on `address` (`127.0.0.1:8080`); `gate` is made for the address bound.
    pub fn start(
        address: &str,
        gate: impl FnOnce(SocketAddr) -> Gate,
    ) -> Result<WebServer, String> {
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
        let gate = Arc::new(gate(local));
        std::thread::Builder::new()
            .name("web-hmi".into())
            .spawn(move || accept_loop(listener, tx, stopped, gate))
            .map_err(|e| format!("web HMI: {e}"))?;
        Ok(WebServer {
            events: rx,
            address: local,
            stop,
        })
    }
}

fn accept_loop(
    listener: TcpListener,
    events: Sender<WebEvent>,
    stop: Arc<AtomicBool>,
    gate: Arc<Gate>,
) {
    let mut next_id = 0u64;
    let open = Arc::new(Mutex::new(Open::default()));
    while !stop.load(Ordering::Relaxed) {
        match listener.accept() {
            Ok((mut stream, peer)) => {
                let Some((slot, flags)) = Slot::take(&open, peer.ip()) else {
                    let _ = stream.set_nonblocking(false);
                    let _ = stream.set_write_timeout(Some(Duration::from_millis(200)));
                    let _ = respond(
                        &mut stream,
                        "503 Service Unavailable",
                        "text/plain",
                        b"too many connections\n",
                    );
                    continue;
                };
                next_id += 1;
                let id = next_id;
                let events = events.clone();
                let stop = stop.clone();
                let gate = gate.clone();
                let spawned = std::thread::Builder::new()
                    .name(format!("web-hmi-{id}"))
                    .spawn(move || {
                        let _slot = slot;
                        if let Err(e) = serve(stream, peer, id, &events, &stop, &gate, &flags) {
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

/// Connections open, each with its address, when it came and whether its request is still
/// being read.
#[derive(Default)]
struct Open {
    next: u64,
    conns: BTreeMap<u64, Conn>,
}

struct Conn {
    ip: IpAddr,
    since: Instant,
    /// Its request head has not come whole yet (a slow or idle client).
    reading: Arc<AtomicBool>,
    /// Set when it is evicted: its thread stops reading within [`READ_SLICE`].
    evicted: Arc<AtomicBool>,
}

/// How long a read waits before the connection's thread looks whether it was evicted.
const READ_SLICE: Duration = Duration::from_millis(100);

/// What a connection's thread is told by the slots: whether its request is still being read
/// (set by the thread), and whether it was evicted (set by the slots).
pub(crate) struct Flags {
    reading: Arc<AtomicBool>,
    evicted: Arc<AtomicBool>,
}

/// One of the [`MAX_CONNECTIONS`] (and of its address's [`MAX_PER_ADDRESS`]), given back when
/// the connection's thread ends (or was never started).
struct Slot(Arc<Mutex<Open>>, u64);

impl Slot {
    /// A slot for a connection from `ip`. When every slot is taken, the connection that has
    /// been reading its request longest is closed to make room: slow sockets (a byte at a
    /// time, from many addresses) cannot lock the operator out, while a connection that has
    /// sent its request (a page's WebSocket) keeps its slot (issue 45 item 8).
    fn take(open: &Arc<Mutex<Open>>, ip: IpAddr) -> Option<(Slot, Flags)> {
        let mut o = open.lock().unwrap_or_else(|e| e.into_inner());
        let mine = o.conns.values().filter(|c| c.ip == ip).count();
        if mine >= MAX_PER_ADDRESS {
            return None;
        }
        if o.conns.len() >= MAX_CONNECTIONS {
            let slowest = o
                .conns
                .iter()
                .filter(|(_, c)| c.reading.load(Ordering::Relaxed))
                .min_by_key(|(_, c)| c.since)
                .map(|(id, _)| *id)?;
            if let Some(c) = o.conns.remove(&slowest) {
                c.evicted.store(true, Ordering::Relaxed);
            }
        }
        o.next += 1;
        let id = o.next;
        let flags = Flags {
            reading: Arc::new(AtomicBool::new(true)),
            evicted: Arc::new(AtomicBool::new(false)),
        };
        o.conns.insert(
            id,
            Conn {
                ip,
                since: Instant::now(),
                reading: flags.reading.clone(),
                evicted: flags.evicted.clone(),
            },
        );
        Some((Slot(open.clone(), id), flags))
    }
}

impl Drop for Slot {
    fn drop(&mut self) {
        let mut o = self.0.lock().unwrap_or_else(|e| e.into_inner());
        o.conns.remove(&self.1);
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

/// Reads until `done(buf)` or `limit` bytes, all within `deadline`, unless the connection is
/// evicted meanwhile.
fn read_until(
    stream: &mut TcpStream,
    deadline: Instant,
    limit: usize,
    evicted: &AtomicBool,
    done: impl Fn(&[u8]) -> bool,
) -> Result<Vec<u8>, String> {
    let mut buf = Vec::with_capacity(1024);
    let mut chunk = [0u8; 1];
    while !done(&buf) {
        if buf.len() >= limit {
            return Err("request too long".into());
        }
        if evicted.load(Ordering::Relaxed) {
            return Err("evicted: the slowest request when every slot was taken".into());
        }
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err("request not complete in time".into());
        }
        stream
            .set_read_timeout(Some(left.min(READ_SLICE)))
            .map_err(|e| e.to_string())?;
        match stream.read(&mut chunk) {
            Ok(0) => return Err("closed before the request was complete".into()),
            Ok(_) => buf.push(chunk[0]),
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            Err(e) => return Err(e.to_string()),
        }
    }
    Ok(buf)
}

fn read_head(
    stream: &mut TcpStream,
    deadline: Instant,
    evicted: &AtomicBool,
) -> Result<Head, String> {
    let buf = read_until(stream, deadline, MAX_HEAD, evicted, |b| {
        b.ends_with(b"\r\n\r\n")
    })?;
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
    respond_with(stream, status, kind, "", body)
}

/// A response with extra header lines (`Set-Cookie: …\r\n`).
fn respond_with(
    stream: &mut TcpStream,
    status: &str,
    kind: &str,
    extra: &str,
    body: &[u8],
) -> Result<(), String> {
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: no-store\r\n{extra}Connection: close\r\n\r\n",
        body.len()
    );
    stream
        .write_all(head.as_bytes())
        .and_then(|()| stream.write_all(body))
        .map_err(|e| e.to_string())
}

fn serve(
    mut stream: TcpStream,
    peer: SocketAddr,
    id: u64,
    events: &Sender<WebEvent>,
    stop: &AtomicBool,
    gate: &Gate,
    flags: &Flags,
) -> Result<(), String> {
    stream.set_nonblocking(false).map_err(|e| e.to_string())?;
    stream
        .set_write_timeout(Some(HEAD_DEADLINE))
        .map_err(|e| e.to_string())?;
    let deadline = Instant::now() + HEAD_DEADLINE;
    let head = read_head(&mut stream, deadline, &flags.evicted)?;
    flags.reading.store(false, Ordering::Relaxed);
    let path = head.path.split('?').next().unwrap_or_default().to_string();
    let token = session_cookie(head.header("Cookie")).map(str::to_string);
    let operator = token
        .as_deref()
        .and_then(|t| gate.operator(t, Instant::now()));
    match (head.method.as_str(), path.as_str()) {
        ("POST", "/login") => {
            let reader = (deadline, &*flags.evicted);
            return login(&mut stream, &head, peer, reader, events, gate);
        }
        ("POST", "/logout") => {
            if let Some(t) = &token {
                gate.logout(t);
            }
            return respond_with(
                &mut stream,
                "200 OK",
                "application/json",
                "Set-Cookie: cnc_session=; Max-Age=0; Path=/; HttpOnly; SameSite=Strict\r\n",
                b"{}",
            );
        }
        ("GET", "/session") => {
            let body = serde_json::json!({
                "required": gate.required,
                "operator": operator,
                "cell": gate.cell,
            });
            return respond(
                &mut stream,
                "200 OK",
                "application/json",
                body.to_string().as_bytes(),
            );
        }
        ("GET", "/ws") => {}
        ("GET", _) => {
            return match assets::file(&path) {
                Some((kind, body)) => respond(&mut stream, "200 OK", kind, body.as_bytes()),
                None => respond(&mut stream, "404 Not Found", "text/plain", b"not found\n"),
            };
        }
        _ => {
            return respond(
                &mut stream,
                "405 Method Not Allowed",
                "text/plain",
                b"GET, or POST to /login and /logout\n",
            );
        }
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
    if !gate.origin_allowed(head.header("Origin")) {
        return respond(
            &mut stream,
            "403 Forbidden",
            "text/plain",
            b"other origin\n",
        );
    }
    if gate.required && operator.is_none() {
        return respond(
            &mut stream,
            "401 Unauthorized",
            "text/plain",
            b"log in first\n",
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
    // Commands carry the operator's name into the command events.
    let client = match &operator {
        Some(name) => format!("web:{name}@{}", peer.ip()),
        None => format!("web@{}", peer.ip()),
    };
    let (outbox, frames) = mpsc::channel::<String>();
    let _ = events.send(WebEvent::Connected {
        id,
        client: client.clone(),
        outbox,
    });
    let session = token.filter(|_| operator.is_some());
    let result = pump(&mut ws, id, &client, events, &frames, stop, gate, session);
    let _ = events.send(WebEvent::Closed { id });
    result
}

/// `POST /login` with `{"name": …, "password": …}`: a session cookie, or 401 after a delay.
fn login(
    stream: &mut TcpStream,
    head: &Head,
    peer: SocketAddr,
    (deadline, evicted): (Instant, &AtomicBool),
    events: &Sender<WebEvent>,
    gate: &Gate,
) -> Result<(), String> {
    if !gate.origin_allowed(head.header("Origin")) {
        return respond(stream, "403 Forbidden", "text/plain", b"other origin\n");
    }
    let length = head
        .header("Content-Length")
        .and_then(|n| n.parse::<usize>().ok())
        .filter(|n| *n <= MAX_LOGIN_BODY);
    let Some(length) = length else {
        return respond(
            stream,
            "400 Bad Request",
            "text/plain",
            b"Content-Length up to 4096\n",
        );
    };
    let body = read_until(stream, deadline, length, evicted, |b| b.len() >= length)?;
    let value: serde_json::Value = serde_json::from_slice(&body).unwrap_or_default();
    let field = |k: &str| value.get(k).and_then(|v| v.as_str()).unwrap_or_default();
    let (name, password) = (field("name"), field("password"));
    let client = format!("web@{}", peer.ip());
    let result = gate.login(name, password, Instant::now());
    let shown: String = name.chars().take(32).collect();
    let _ = events.send(WebEvent::Login {
        client,
        operator: shown,
        accepted: result.is_ok(),
        message: match &result {
            Ok(_) => "logged in".into(),
            Err((why, _)) => why.clone(),
        },
    });
    match result {
        Ok(token) => {
            let cookie = format!(
                "Set-Cookie: cnc_session={token}; Max-Age={}; Path=/; HttpOnly; SameSite=Strict\r\n",
                gate.lifetime().as_secs()
            );
            let body = serde_json::json!({"operator": name}).to_string();
            respond_with(
                stream,
                "200 OK",
                "application/json",
                &cookie,
                body.as_bytes(),
            )
        }
        // Refused before any check: at once, with the wait (the throttle keeps the pace).
        Err((why, Some(_))) => respond(
            stream,
            "429 Too Many Requests",
            "text/plain",
            why.as_bytes(),
        ),
        Err((why, None)) => {
            std::thread::sleep(LOGIN_FAILURE_DELAY);
            respond(stream, "401 Unauthorized", "text/plain", why.as_bytes())
        }
    }
}

/// Moves messages both ways until the page or the node goes away, or the page's session
/// expires.
#[allow(clippy::too_many_arguments)]
fn pump(
    ws: &mut WebSocket<TcpStream>,
    id: u64,
    client: &str,
    events: &Sender<WebEvent>,
    frames: &Receiver<String>,
    stop: &AtomicBool,
    gate: &Gate,
    session: Option<String>,
) -> Result<(), String> {
    while !stop.load(Ordering::Relaxed) {
        if let Some(t) = &session {
            if gate.operator(t, Instant::now()).is_none() {
                let _ = ws.close(Some(tungstenite::protocol::CloseFrame {
                    code: tungstenite::protocol::frame::coding::CloseCode::Policy,
                    reason: "session expired: log in again".into(),
                }));
                let _ = ws.flush();
                return Ok(());
            }
        }
        match ws.read() {
            Ok(Message::Text(text)) => {
                let _ = events.send(WebEvent::Request {
                    id,
                    client: client.to_string(),
                    payload: Payload::Text(text.to_string()),
                });
            }
            Ok(Message::Binary(data)) => {
                let _ = events.send(WebEvent::Request {
                    id,
                    client: client.to_string(),
                    payload: Payload::Binary(data.to_vec()),
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

    fn get(address: SocketAddr, request: &str) -> String {
        let mut s = TcpStream::connect(address).expect("connect");
        s.write_all(request.as_bytes()).expect("send");
        let mut answer = String::new();
        let _ = s.read_to_string(&mut answer);
        answer
    }

    fn open_gate(bound: SocketAddr) -> Gate {
        Gate::new(bound, BTreeMap::new(), vec![], Duration::from_secs(60))
    }

    #[test]
    fn the_page_is_served_other_paths_are_not_and_connections_are_capped() {
        let server = WebServer::start("127.0.0.1:0", open_gate).expect("listens");
        let a = server.address;
        assert!(get(a, "GET / HTTP/1.1\r\nHost: x\r\n\r\n").contains("<title>CNC operator panel"));
        assert!(get(a, "GET /app.js HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 200"));
        assert!(get(a, "GET /../etc/passwd HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 404"));
        assert!(get(a, "POST / HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 405"));
        assert!(get(a, "GET /ws HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 400"));
        assert!(get(a, "GET /session HTTP/1.1\r\n\r\n").contains("\"required\":false"));
        // Connections that never send a request hold their slots until their deadline; one
        // address holds at most its share.
        let idle: Vec<TcpStream> = (0..MAX_PER_ADDRESS)
            .map(|_| TcpStream::connect(a).expect("connect"))
            .collect();
        std::thread::sleep(Duration::from_millis(300));
        assert!(get(a, "GET / HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 503"));
        drop(idle);
        std::thread::sleep(Duration::from_millis(300));
        assert!(get(a, "GET / HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 200"));
    }

    /// Issue 45 item 8: 64 slow sockets from 8 addresses (each at its own cap) take every
    /// slot; the operator's requests are still served, every one of 12, each by closing the
    /// connection that has been reading longest.
    #[test]
    fn slow_sockets_from_many_addresses_do_not_lock_the_operator_out() {
        use socket2::{Domain, Socket, Type};
        let server = WebServer::start("127.0.0.1:0", open_gate).expect("listens");
        let a = server.address;
        let mut slow = Vec::new();
        for host in 2..=9u8 {
            for _ in 0..MAX_PER_ADDRESS {
                let s = Socket::new(Domain::IPV4, Type::STREAM, None).expect("socket");
                let from: SocketAddr = format!("127.0.0.{host}:0").parse().unwrap();
                s.bind(&from.into()).expect("bind a loopback address");
                s.connect(&a.into()).expect("connect");
                let mut t: TcpStream = s.into();
                let _ = t.write_all(b"GET / HT");
                slow.push(t);
            }
        }
        assert_eq!(slow.len(), MAX_CONNECTIONS);
        std::thread::sleep(Duration::from_millis(300));
        for k in 0..12 {
            let answer = get(a, "GET / HTTP/1.1\r\nHost: x\r\n\r\n");
            assert!(answer.starts_with("HTTP/1.1 200"), "try {k}: {answer:.40}");
        }
    }

    #[test]
    fn a_request_trickled_a_byte_at_a_time_is_cut_at_the_deadline() {
        let server = WebServer::start("127.0.0.1:0", open_gate).expect("listens");
        let mut s = TcpStream::connect(server.address).expect("connect");
        let t0 = Instant::now();
        let mut answer = String::new();
        for b in b"GET / HTTP/1.1\r\nX: ".iter().cycle() {
            if s.write_all(&[*b]).is_err() || t0.elapsed() > Duration::from_secs(30) {
                break;
            }
            std::thread::sleep(Duration::from_millis(400));
            // The server closes the connection after its deadline: reads then end.
            s.set_nonblocking(true).expect("nonblocking");
            let mut buf = [0u8; 64];
            match s.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => answer.push_str(&String::from_utf8_lossy(&buf[..n])),
                Err(_) => {}
            }
            s.set_nonblocking(false).expect("blocking");
        }
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "the trickle was never cut"
        );
        assert!(answer.is_empty(), "{answer}");
    }

    #[test]
    fn a_websocket_from_another_site_is_refused() {
        let server = WebServer::start("127.0.0.1:0", open_gate).expect("listens");
        let a = server.address;
        let ws = |origin: &str, host: &str| {
            get(
                a,
                &format!(
                    "GET /ws HTTP/1.1\r\nHost: {host}\r\nOrigin: {origin}\r\nUpgrade: websocket\r\n\
                     Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\
                     Sec-WebSocket-Version: 13\r\n\r\n"
                ),
            )
        };
        // A DNS-rebound page: its Host header names its own site, so comparing the two would
        // let it through.
        assert!(ws("http://evil.example:1", "evil.example:1").starts_with("HTTP/1.1 403"));
        assert!(ws("null", &a.to_string()).starts_with("HTTP/1.1 403"));
    }
}
