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
/// Failed logins of one operator before each further try must wait (the wait doubles with
/// every failure after these, from [`FIRST_WAIT`] up to [`LONGEST_WAIT`]).
const FREE_FAILURES: u32 = 5;
const FIRST_WAIT: Duration = Duration::from_secs(2);
const LONGEST_WAIT: Duration = Duration::from_secs(300);
/// Password checks (key derivations, a tenth of a second of a core each) the panel makes per
/// second at most, whoever asks, and in a burst: guessing from many addresses and connections
/// at once can neither go faster nor take the machine's CPU.
const CHECKS_PER_SECOND: f64 = 2.0;
const CHECK_BURST: f64 = 4.0;

/// Why a login was refused before any password was checked.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Throttled {
    /// Too many failed logins of this operator: wait this long.
    Operator(Duration),
    /// Too many logins at the panel at once.
    Panel,
}

/// Failed logins per operator name, and the panel's budget of password checks (D125).
struct Throttle {
    failures: BTreeMap<String, (u32, Instant)>,
    budget: f64,
    filled: Option<Instant>,
    /// Password checks made (for the tests: unknown names cost as much as known ones).
    checks: u64,
}

impl Throttle {
    fn new() -> Throttle {
        Throttle {
            failures: BTreeMap::new(),
            budget: CHECK_BURST,
            filled: None,
            checks: 0,
        }
    }

    /// Whether a password of `name` may be checked now; takes one check of the budget.
    fn admit(&mut self, name: &str, now: Instant) -> Result<(), Throttled> {
        if let Some(&(count, last)) = self.failures.get(name) {
            if count >= FREE_FAILURES {
                let doublings = (count - FREE_FAILURES).min(16);
                let wait = FIRST_WAIT.saturating_mul(1 << doublings).min(LONGEST_WAIT);
                let since = now.saturating_duration_since(last);
                if since < wait {
                    return Err(Throttled::Operator(wait - since));
                }
            }
        }
        let elapsed = self
            .filled
            .map_or(0.0, |t| now.saturating_duration_since(t).as_secs_f64());
        self.budget = (self.budget + elapsed * CHECKS_PER_SECOND).min(CHECK_BURST);
        self.filled = Some(now);
        if self.budget < 1.0 {
            return Err(Throttled::Panel);
        }
        self.budget -= 1.0;
        self.checks += 1;
        Ok(())
    }

    fn outcome(&mut self, name: &str, ok: bool, now: Instant) {
        if ok {
            self.failures.remove(name);
            return;
        }
        // Bounded: a name is any string a client sends.
        if self.failures.len() >= 4096 && !self.failures.contains_key(name) {
            let oldest = self
                .failures
                .iter()
                .min_by_key(|(_, (_, t))| *t)
                .map(|(n, _)| n.clone());
            if let Some(n) = oldest {
                self.failures.remove(&n);
            }
        }
        let entry = self.failures.entry(name.to_string()).or_insert((0, now));
        entry.0 = entry.0.saturating_add(1);
        entry.1 = now;
    }
}

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
    throttle: Mutex<Throttle>,
    /// What a name without an operator is checked against, so that a wrong name costs the
    /// same time as a wrong password (no telling which names exist); made at the first need.
    decoy: std::sync::OnceLock<String>,
    decoy_iterations: u32,
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
        // The decoy costs what the operators' own hashes cost.
        let decoy_iterations = operators
            .values()
            .filter_map(|h| h.split('$').nth(1)?.parse::<u32>().ok())
            .max()
            .unwrap_or(ITERATIONS);
        Gate {
            required: !bound.ip().is_loopback(),
            operators,
            origins,
            lifetime,
            sessions: Mutex::new(BTreeMap::new()),
            throttle: Mutex::new(Throttle::new()),
            decoy: std::sync::OnceLock::new(),
            decoy_iterations,
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

    /// A new session token for `name` with `password`, or why not. Before any password is
    /// checked the throttle decides (an operator's failures, the panel's budget of checks):
    /// such a refusal is `Err(Some(..))` with the wait, a wrong name or password `Err(None)`.
    pub fn login(
        &self,
        name: &str,
        password: &str,
        now: Instant,
    ) -> Result<String, (String, Option<Throttled>)> {
        let mut throttle = self.throttle.lock().unwrap_or_else(|e| e.into_inner());
        if let Err(t) = throttle.admit(name, now) {
            let why = match &t {
                Throttled::Operator(wait) => format!(
                    "too many failed logins for this operator: try again in {} s",
                    wait.as_secs().max(1)
                ),
                Throttled::Panel => "too many logins at once: try again in a second".into(),
            };
            return Err((why, Some(t)));
        }
        drop(throttle);
        // Known or not, the name costs one check of the same weight.
        let ok = match self.operators.get(name) {
            Some(stored) => verify(stored, password),
            None => {
                let decoy = self.decoy.get_or_init(|| {
                    hash_password("", b"no operator of this name", self.decoy_iterations)
                });
                let _ = verify(decoy, password);
                false
            }
        };
        let mut throttle = self.throttle.lock().unwrap_or_else(|e| e.into_inner());
        throttle.outcome(name, ok, now);
        drop(throttle);
        if !ok {
            return Err(("unknown operator or wrong password".into(), None));
        }
        let token = hex(&random(32).map_err(|e| (e, None))?);
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

    /// Password checks made so far.
    pub fn checks(&self) -> u64 {
        self.throttle
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .checks
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

    /// Issue 45 item 7: 200 guesses from many addresses and connections at once. The panel
    /// checks at most its budget of passwords per second whoever asks, an operator's account
    /// waits longer after every failure past five, a name without an operator costs a check
    /// like one with, and the operator gets in once the guessing stops.
    #[test]
    fn password_guessing_is_paced_per_operator_and_for_the_panel() {
        let bound: SocketAddr = "10.0.0.5:8080".parse().unwrap();
        let ops = BTreeMap::from([("anna".to_string(), hash_password("pw", b"salt", 10))]);
        let gate = Gate::new(bound, ops, vec![], Duration::from_secs(60));
        let t0 = Instant::now();
        // A burst: 200 guesses within one second.
        let (mut checked, mut paced) = (0, 0);
        for k in 0..200u32 {
            let at = t0 + Duration::from_millis(u64::from(k) * 5);
            match gate.login("anna", &format!("guess{k}"), at) {
                Err((_, None)) => checked += 1,
                Err((_, Some(_))) => paced += 1,
                Ok(_) => panic!("a guess got in"),
            }
        }
        assert!(checked <= 6, "{checked} passwords checked in a second");
        assert_eq!(checked + paced, 200);
        // A minute of one guess a second: the account's wait grows past the pace.
        let mut later_checks = 0;
        for s in 1..=60u64 {
            if let Err((_, None)) = gate.login("anna", "guess", t0 + Duration::from_secs(s)) {
                later_checks += 1;
            }
        }
        assert!(later_checks <= 6, "{later_checks} checks in a minute");
        let e = gate
            .login("anna", "pw", t0 + Duration::from_secs(61))
            .unwrap_err();
        assert!(e.0.contains("try again in"), "{}", e.0);
        // The operator gets in once the wait is over, and the count starts again.
        let after = t0 + Duration::from_secs(61) + LONGEST_WAIT;
        assert!(gate.login("anna", "pw", after).is_ok());
        assert!(gate
            .login("anna", "nope", after + Duration::from_secs(2))
            .is_err());
        assert!(gate
            .login("anna", "pw", after + Duration::from_secs(4))
            .is_ok());
        // A wrong name costs one check, as a wrong password does.
        let before = gate.checks();
        let later = after + Duration::from_secs(10);
        assert_eq!(gate.login("bob", "pw", later).unwrap_err().1, None);
        assert_eq!(gate.checks(), before + 1);
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
