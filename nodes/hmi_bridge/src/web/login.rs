//! Who is at the web panel: operators with salted password hashes (PBKDF2-HMAC-SHA256, written
//! by `cnc operator set`), sessions that expire, and the page origins the panel trusts.
//!
//! On a loopback address the panel is the machine's own screen and login is optional; on any
//! other address every WebSocket needs a session, and the cell refuses to serve the panel
//! there without operators ([`exposure`]).

use std::collections::BTreeMap;
use std::io::Read;
use std::net::SocketAddr;
use std::path::Path;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use sha2::{Digest, Sha256};

/// Iterations `cnc operator set` uses: a guess costs the same tenth of a second or so.
pub const ITERATIONS: u32 = 200_000;
/// Sessions held at once; the oldest goes when a new login would exceed it.
const MAX_SESSIONS: usize = 64;

fn hmac(key: &[u8], message: &[&[u8]]) -> [u8; 32] {
    let mut block = [0u8; 64];
    if key.len() > 64 {
        block[..32].copy_from_slice(&Sha256::digest(key));
    } else {
        block[..key.len()].copy_from_slice(key);
    }
    let mut inner = Sha256::new();
    inner.update(block.map(|b| b ^ 0x36));
    for m in message {
        inner.update(m);
    }
    let mut outer = Sha256::new();
    outer.update(block.map(|b| b ^ 0x5c));
    outer.update(inner.finalize());
    outer.finalize().into()
}

/// PBKDF2-HMAC-SHA256 with one 32-byte block (RFC 8018 §5.2).
fn pbkdf2(password: &[u8], salt: &[u8], iterations: u32) -> [u8; 32] {
    let mut u = hmac(password, &[salt, &1u32.to_be_bytes()]);
    let mut out = u;
    for _ in 1..iterations {
        u = hmac(password, &[&u]);
        for (o, x) in out.iter_mut().zip(u) {
            *o ^= x;
        }
    }
    out
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn unhex(text: &str) -> Option<Vec<u8>> {
    if !text.len().is_multiple_of(2) {
        return None;
    }
    (0..text.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(text.get(i..i + 2)?, 16).ok())
        .collect()
}

/// `n` bytes from the kernel's random source.
pub fn random(n: usize) -> Result<Vec<u8>, String> {
    let mut out = vec![0u8; n];
    std::fs::File::open("/dev/urandom")
        .and_then(|mut f| f.read_exact(&mut out))
        .map_err(|e| format!("/dev/urandom: {e}"))?;
    Ok(out)
}

/// `pbkdf2-sha256$<iterations>$<salt hex>$<hash hex>`.
pub fn hash_password(password: &str, salt: &[u8], iterations: u32) -> String {
    let hash = pbkdf2(password.as_bytes(), salt, iterations.max(1));
    format!("pbkdf2-sha256${iterations}${}${}", hex(salt), hex(&hash))
}

/// Whether `password` matches `stored` (compared in constant time); a malformed entry matches
/// nothing.
pub fn verify(stored: &str, password: &str) -> bool {
    let mut parts = stored.split('$');
    let (Some("pbkdf2-sha256"), Some(n), Some(salt), Some(hash), None) = (
        parts.next(),
        parts.next(),
        parts.next(),
        parts.next(),
        parts.next(),
    ) else {
        return false;
    };
    let (Ok(n), Some(salt), Some(hash)) = (n.parse::<u32>(), unhex(salt), unhex(hash)) else {
        return false;
    };
    if n == 0 || n > 10_000_000 || hash.len() != 32 {
        return false;
    }
    let got = pbkdf2(password.as_bytes(), &salt, n);
    got.iter().zip(&hash).fold(0u8, |d, (a, b)| d | (a ^ b)) == 0
}

/// The operators file: `operators: {name: hash}`.
#[derive(Debug, Default, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct OperatorsFile {
    #[serde(default)]
    pub operators: BTreeMap<String, String>,
}

impl OperatorsFile {
    /// The file at `path`; none there means no operators.
    pub fn load(path: &Path) -> Result<OperatorsFile, String> {
        if !path.exists() {
            return Ok(OperatorsFile::default());
        }
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("operators file {}: {e}", path.display()))?;
        serde_yaml::from_str(&text).map_err(|e| format!("operators file {}: {e}", path.display()))
    }

    /// A name an operator can log in with: letters, digits, `_`, `-`, `.`, 1–32 of them.
    pub fn valid_name(name: &str) -> bool {
        (1..=32).contains(&name.len())
            && name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c))
    }
}

/// Whether the panel may be served on `address` with these operators: not on a network
/// address without logins, not on an unspecified address without named origins.
pub fn exposure(address: &str, operators: usize, origins: &[String]) -> Result<(), String> {
    let Ok(addr) = address.parse::<SocketAddr>() else {
        // A host name: treated as a network address.
        return match operators {
            0 => Err(no_logins(address)),
            _ => Ok(()),
        };
    };
    if addr.ip().is_loopback() {
        return Ok(());
    }
    if operators == 0 {
        return Err(no_logins(address));
    }
    if addr.ip().is_unspecified() && origins.is_empty() {
        return Err(format!(
            "web HMI on {address}: name the page origins operators use (hmi.web_origins, e.g. \
             http://panel.cell:{}): on an unspecified address the panel cannot tell its own \
             pages from another site's",
            addr.port()
        ));
    }
    Ok(())
}

fn no_logins(address: &str) -> String {
    format!(
        "web HMI on {address} is reachable from the network and needs operator logins: set \
         one with `cnc operator set <name>` (hmi.operators_file), or serve it on 127.0.0.1"
    )
}

/// What the panel's server checks: operators, sessions, origins.
pub struct Gate {
    /// Whether every page needs a session (a network address).
    pub required: bool,
    operators: BTreeMap<String, String>,
    origins: Vec<String>,
    lifetime: Duration,
    sessions: Mutex<BTreeMap<String, (String, Instant)>>,
    /// What `/session` also tells the page: the machine and the cell's other panels.
    pub cell: serde_json::Value,
}

impl Gate {
    /// The gate for a panel bound to `bound`.
    pub fn new(
        bound: SocketAddr,
        operators: BTreeMap<String, String>,
        mut origins: Vec<String>,
        lifetime: Duration,
    ) -> Gate {
        if origins.is_empty() {
            origins.push(format!("http://{bound}"));
            if bound.ip().is_loopback() {
                origins.push(format!("http://localhost:{}", bound.port()));
            }
        }
        for o in &mut origins {
            *o = o.trim_end_matches('/').to_string();
        }
        Gate {
            required: !bound.ip().is_loopback(),
            operators,
            origins,
            lifetime,
            sessions: Mutex::new(BTreeMap::new()),
            cell: serde_json::Value::Null,
        }
    }

    /// A page's Origin (browsers send it with every WebSocket and POST) must be one the panel
    /// is served under: comparing it with the Host header instead would let a DNS-rebound
    /// site through. Clients that are not browsers send none.
    pub fn origin_allowed(&self, origin: Option<&str>) -> bool {
        match origin {
            None => true,
            Some(o) => self.origins.iter().any(|x| x == o.trim_end_matches('/')),
        }
    }

    /// A new session token for `name` with `password`, or why not.
    pub fn login(&self, name: &str, password: &str, now: Instant) -> Result<String, String> {
        let ok = self
            .operators
            .get(name)
            .is_some_and(|stored| verify(stored, password));
        if !ok {
            return Err("unknown operator or wrong password".into());
        }
        let token = hex(&random(32)?);
        let mut sessions = self.sessions.lock().unwrap_or_else(|e| e.into_inner());
        sessions.retain(|_, (_, until)| *until > now);
        while sessions.len() >= MAX_SESSIONS {
            let oldest = sessions
                .iter()
                .min_by_key(|(_, (_, until))| *until)
                .map(|(t, _)| t.clone());
            match oldest {
                Some(t) => sessions.remove(&t),
                None => break,
            };
        }
        sessions.insert(token.clone(), (name.to_string(), now + self.lifetime));
        Ok(token)
    }

    /// The operator of a live session.
    pub fn operator(&self, token: &str, now: Instant) -> Option<String> {
        let mut sessions = self.sessions.lock().unwrap_or_else(|e| e.into_inner());
        match sessions.get(token) {
            Some((name, until)) if *until > now => Some(name.clone()),
            Some(_) => {
                sessions.remove(token);
                None
            }
            None => None,
        }
    }

    pub fn logout(&self, token: &str) {
        let mut sessions = self.sessions.lock().unwrap_or_else(|e| e.into_inner());
        sessions.remove(token);
    }

    pub fn lifetime(&self) -> Duration {
        self.lifetime
    }
}

/// The session token in a `Cookie` header.
pub fn session_cookie(cookie: Option<&str>) -> Option<&str> {
    cookie?
        .split(';')
        .filter_map(|c| c.trim().split_once('='))
        .find(|(n, _)| *n == "cnc_session")
        .map(|(_, v)| v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pbkdf2_matches_the_rfc_7914_vectors() {
        assert_eq!(
            hex(&pbkdf2(b"password", b"salt", 1)),
            "120fb6cffcf8b32c43e7225256c4f837a86548c92ccc35480805987cb70be17b"
        );
        assert_eq!(
            hex(&pbkdf2(b"password", b"salt", 2)),
            "ae4d0c95af6b46d32d0adff928f06dd02a303f8ef3c251dfd6e2d85a95474c43"
        );
    }

    #[test]
    fn hashes_verify_and_malformed_ones_match_nothing() {
        let h = hash_password("s3cret", b"0123456789abcdef", 50);
        assert!(verify(&h, "s3cret"));
        assert!(!verify(&h, "s3cret "));
        assert!(!verify("pbkdf2-sha256$0$00$00", ""));
        assert!(!verify("plain", "plain"));
        assert!(!verify(&h.replace("pbkdf2", "md5"), "s3cret"));
    }

    #[test]
    fn sessions_expire_and_origins_are_the_panels_own() {
        let bound: SocketAddr = "10.0.0.5:8080".parse().unwrap();
        let ops = BTreeMap::from([("anna".to_string(), hash_password("pw", b"salt", 10))]);
        let gate = Gate::new(bound, ops, vec![], Duration::from_secs(60));
        assert!(gate.required);
        let t0 = Instant::now();
        assert!(gate.login("anna", "nope", t0).is_err());
        assert!(gate.login("bob", "pw", t0).is_err());
        let token = gate.login("anna", "pw", t0).unwrap();
        assert_eq!(
            gate.operator(&token, t0 + Duration::from_secs(59)),
            Some("anna".into())
        );
        assert_eq!(gate.operator(&token, t0 + Duration::from_secs(60)), None);
        assert!(gate.origin_allowed(Some("http://10.0.0.5:8080")));
        assert!(gate.origin_allowed(None));
        // DNS rebinding: another name for the same address is another site.
        assert!(!gate.origin_allowed(Some("http://evil.example:8080")));
        assert_eq!(
            session_cookie(Some("a=1; cnc_session=abc; b=2")),
            Some("abc")
        );
        let local = Gate::new(
            "127.0.0.1:8080".parse().unwrap(),
            BTreeMap::new(),
            vec![],
            Duration::from_secs(1),
        );
        assert!(!local.required);
        assert!(local.origin_allowed(Some("http://localhost:8080")));
    }

    #[test]
    fn the_panel_is_not_served_to_the_network_without_logins() {
        assert!(exposure("127.0.0.1:8080", 0, &[]).is_ok());
        assert!(exposure("[::1]:8080", 0, &[]).is_ok());
        let e = exposure("0.0.0.0:8080", 0, &[]).unwrap_err();
        assert!(e.contains("cnc operator set"), "{e}");
        assert!(exposure("10.0.0.5:8080", 0, &[]).is_err());
        assert!(exposure("10.0.0.5:8080", 1, &[]).is_ok());
        assert!(exposure("0.0.0.0:8080", 1, &[]).is_err());
        assert!(exposure("0.0.0.0:8080", 1, &["http://panel:8080".into()]).is_ok());
        assert!(exposure("panel.local:8080", 0, &[]).is_err());
    }
}
