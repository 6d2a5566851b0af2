//! The web panel on a network address (issue 25): it does not start without operator logins;
//! with them, no WebSocket without a session, wrong passwords are refused and recorded, a
//! foreign Origin is refused (also one whose Host header agrees with it: DNS rebinding),
//! commands carry the operator's name into the command events, sessions expire, and 40 slow
//! clients on another host do not lock the operator out. The login is also done in headless
//! chromium (`tests/hmi/login.cjs`): a login form first, then the panel under the operator's
//! name.
//!
//! Runs inside the network namespace of `scripts/test.sh` (it refuses to run outside one), to
//! which it adds two addresses on `lo`: 10.99.25.1 (the panel, and the operator's side) and
//! 10.99.25.2 (the slow clients' host).

mod common;

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

use cnc::cell::Cell;
use tungstenite::client::IntoClientRequest;

const PANEL: &str = "10.99.25.1:18125";
const ORIGIN: &str = "http://10.99.25.1:18125";
const PASSWORD: &str = "correct horse battery";

fn in_own_netns() -> bool {
    let ns = |p: &str| std::fs::read_link(p).map(|l| l.display().to_string());
    ns("/proc/self/ns/net").ok() != ns("/proc/1/ns/net").ok()
}

fn add_address(addr: &str) {
    let out = std::process::Command::new("ip")
        .args(["addr", "add", addr, "dev", "lo"])
        .output()
        .expect("ip runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() || err.contains("exists") || err.contains("already assigned"),
        "ip addr add {addr}: {err}"
    );
}

/// A connection to the panel from `source` (an address of this namespace).
fn try_connect_from(source: &str) -> std::io::Result<TcpStream> {
    let socket = socket2::Socket::new(socket2::Domain::IPV4, socket2::Type::STREAM, None)?;
    let from: SocketAddr = format!("{source}:0").parse().unwrap();
    socket.bind(&from.into())?;
    let to: SocketAddr = PANEL.parse().unwrap();
    socket.connect(&to.into())?;
    Ok(socket.into())
}

fn connect_from(source: &str) -> TcpStream {
    try_connect_from(source).expect("connect to the panel")
}

/// One HTTP exchange; returns the whole answer.
fn http(request: &str) -> String {
    let mut s = connect_from("10.99.25.1");
    s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    s.write_all(request.as_bytes()).unwrap();
    let mut answer = String::new();
    let _ = s.read_to_string(&mut answer);
    answer
}

fn login(name: &str, password: &str, origin: &str) -> String {
    let body = serde_json::json!({"name": name, "password": password}).to_string();
    http(&format!(
        "POST /login HTTP/1.1\r\nHost: {PANEL}\r\nOrigin: {origin}\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    ))
}

fn upgrade(cookie: Option<&str>, origin: &str) -> String {
    let cookie = cookie
        .map(|c| format!("Cookie: cnc_session={c}\r\n"))
        .unwrap_or_default();
    http(&format!(
        "GET /ws HTTP/1.1\r\nHost: {PANEL}\r\nOrigin: {origin}\r\n{cookie}Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n"
    ))
}

type Ws = tungstenite::WebSocket<TcpStream>;

fn open_ws(token: &str) -> Ws {
    let mut request = format!("ws://{PANEL}/ws").into_client_request().unwrap();
    let headers = request.headers_mut();
    headers.insert("Origin", ORIGIN.parse().unwrap());
    headers.insert("Cookie", format!("cnc_session={token}").parse().unwrap());
    let stream = connect_from("10.99.25.1");
    stream
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    let (ws, _) = tungstenite::client::client(request, stream).expect("WebSocket with a session");
    ws
}

/// Frames until one of `kind` (`reply`) arrives; `None` if the panel closed the socket.
fn next_of(ws: &mut Ws, kind: &str, deadline: Instant) -> Option<serde_json::Value> {
    while Instant::now() < deadline {
        match ws.read() {
            Ok(tungstenite::Message::Text(t)) => {
                let v: serde_json::Value = serde_json::from_str(&t).unwrap();
                if v["type"] == kind {
                    return Some(v);
                }
            }
            Ok(tungstenite::Message::Close(_)) => return None,
            Ok(_) => {}
            Err(tungstenite::Error::Io(e)) if e.kind() == std::io::ErrorKind::WouldBlock => {}
            Err(_) => return None,
        }
    }
    panic!("no {kind} frame in time");
}

#[test]
fn the_panel_on_a_network_address_needs_a_login_and_keeps_the_operator_in() {
    assert!(
        in_own_netns(),
        "run inside a network namespace (scripts/test.sh makes one): this test adds addresses"
    );
    add_address("10.99.25.1/32");
    add_address("10.99.25.2/32");
    let dir = std::env::temp_dir().join(format!("cnc_web_login_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let operators = dir.join("operators.yaml");
    let mut cfg = common::sim_lathe(62);
    cfg.hmi.web_address = PANEL.into();
    cfg.hmi.operators_file = Some(operators.clone());
    cfg.hmi.session_seconds = 8;
    cfg.hmi.allowed_clients = Some(vec!["web:anna@*".into()]);

    // 1. No operators: the cell does not start.
    let e = Cell::start(&cfg).err().expect("refused without logins");
    assert!(e.contains("cnc operator set"), "{e}");

    // 2. `cnc operator set` stores a salted hash, readable by nobody else.
    let config = dir.join("cell.yaml");
    std::fs::write(&config, serde_yaml::to_string(&cfg).unwrap()).unwrap();
    let set = |name: &str, password: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_cnc"))
            .args(["operator", "set", name, "--config"])
            .arg(&config)
            .stdin(std::process::Stdio::piped())
            .output_with(password)
    };
    trait OutputWith {
        fn output_with(&mut self, input: &str) -> std::process::Output;
    }
    impl OutputWith for std::process::Command {
        fn output_with(&mut self, input: &str) -> std::process::Output {
            let mut child = self
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .expect("cnc runs");
            child
                .stdin
                .take()
                .unwrap()
                .write_all(format!("{input}\n").as_bytes())
                .unwrap();
            child.wait_with_output().unwrap()
        }
    }
    let short = set("bob", "short");
    assert!(!short.status.success());
    let ok = set("anna", PASSWORD);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let stored = std::fs::read_to_string(&operators).unwrap();
    assert!(stored.contains("anna: pbkdf2-sha256$") && !stored.contains(PASSWORD));
    use std::os::unix::fs::PermissionsExt;
    assert_eq!(
        std::fs::metadata(&operators).unwrap().permissions().mode() & 0o777,
        0o600
    );

    let cell = Cell::start(&cfg).unwrap();
    let auditor = common::Auditor::new(&cfg);
    let t0 = Instant::now();
    while try_connect_from("10.99.25.1").is_err() {
        assert!(t0.elapsed() < Duration::from_secs(30), "panel never up");
        std::thread::sleep(Duration::from_millis(100));
    }
    std::thread::sleep(Duration::from_secs(1)); // the auditor's reader is matched

    // 3. Forty slow clients on another host, each trickling a byte every 4 s, while the
    // operator uses the panel.
    let slow: Vec<std::thread::JoinHandle<()>> = (0..40)
        .map(|_| {
            std::thread::spawn(|| {
                let Ok(mut s) = try_connect_from("10.99.25.2") else {
                    return;
                };
                for b in b"GET / HTTP/1.1\r\n" {
                    if s.write_all(&[*b]).is_err() {
                        return;
                    }
                    std::thread::sleep(Duration::from_secs(4));
                }
            })
        })
        .collect();
    std::thread::sleep(Duration::from_millis(500));
    let until = Instant::now() + Duration::from_secs(9);
    let mut served = 0;
    while Instant::now() < until {
        let page = http("GET / HTTP/1.1\r\n\r\n");
        assert!(
            page.starts_with("HTTP/1.1 200"),
            "operator locked out: {}",
            page.lines().next().unwrap_or("")
        );
        served += 1;
        std::thread::sleep(Duration::from_millis(500));
    }
    assert!(served >= 10);
    let session = http("GET /session HTTP/1.1\r\n\r\n");
    assert!(
        session.contains("\"required\":true") && session.contains("\"operator\":null"),
        "{session}"
    );

    // 4. The same in a real browser: a login form, then the panel under the operator's name.
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let playwright = root.join("target/npm/node_modules/playwright-core");
    let mut browser = std::process::Command::new("node");
    browser
        .arg(root.join("tests/hmi/login.cjs"))
        .args([&format!("{ORIGIN}/"), "anna", PASSWORD])
        .env("PLAYWRIGHT_CORE", &playwright);
    let out = common::output_within(&mut browser, std::time::Duration::from_secs(300));
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(
        out.status.success(),
        "browser login failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );

    // 5. No WebSocket without a session; logins checked; origins are the panel's own.
    assert!(upgrade(None, ORIGIN).starts_with("HTTP/1.1 401"));
    assert!(upgrade(Some("forged"), ORIGIN).starts_with("HTTP/1.1 401"));
    let wrong = login("anna", "wrong password", ORIGIN);
    assert!(wrong.starts_with("HTTP/1.1 401"), "{wrong}");
    assert!(login("anna", PASSWORD, "http://evil.example:18125").starts_with("HTTP/1.1 403"));
    let good = login("anna", PASSWORD, ORIGIN);
    assert!(good.starts_with("HTTP/1.1 200"), "{good}");
    let token = good
        .split("cnc_session=")
        .nth(1)
        .and_then(|t| t.split(';').next())
        .expect("a session cookie")
        .to_string();
    assert!(upgrade(Some(&token), "http://evil.example:18125").starts_with("HTTP/1.1 403"));

    // 6. A command carries the operator's name.
    let mut ws = open_ws(&token);
    let request =
        serde_json::json!({"id": 1, "op": "overrides", "feed": 100, "spindle": 100, "rapid": 100});
    ws.send(tungstenite::Message::text(request.to_string()))
        .unwrap();
    let reply = next_of(&mut ws, "reply", Instant::now() + Duration::from_secs(10)).expect("reply");
    assert_eq!(reply["accepted"], true, "{reply}");

    // 7. The session expires (8 s here): the panel closes the socket, and the cookie opens no
    // other.
    let closed = next_of(&mut ws, "never", Instant::now() + Duration::from_secs(20));
    assert!(closed.is_none());
    assert!(upgrade(Some(&token), ORIGIN).starts_with("HTTP/1.1 401"));
    for h in slow {
        let _ = h.join();
    }

    std::thread::sleep(Duration::from_millis(500));
    let seen: Vec<_> = auditor
        .events()
        .into_iter()
        .map(|e| (e.command, e.detail, e.client, e.accepted))
        .collect();
    let has = |command: &str, client: &str, accepted: bool| {
        seen.iter()
            .any(|(c, _, who, a)| c == command && who == client && *a == accepted)
    };
    assert!(has("web_login", "web@10.99.25.1", false), "{seen:?}");
    assert!(has("web_login", "web@10.99.25.1", true), "{seen:?}");
    assert!(
        has("set_overrides", "web:anna@10.99.25.1", true),
        "{seen:?}"
    );
    // The browser's button press, under the operator's name.
    assert!(
        seen.iter()
            .any(|(c, _, who, _)| c == "stop" && who == "web:anna@10.99.25.1"),
        "{seen:?}"
    );
    let (_, errors) = cell.stop();
    assert!(errors.is_empty(), "{errors:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
