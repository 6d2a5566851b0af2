//! `cnc security init`: the keystore of a cell that runs DDS Security, in the layout SROS2's
//! `ros2 security` makes, so a ROS 2 node on rmw_cyclonedds or rmw_fastrtps can be given an
//! enclave of it (README, "DDS Security").
//!
//! One certificate authority signs both the identities and the documents (SROS2's default):
//! `public/ca.cert.pem` (also as `identity_ca.cert.pem` and `permissions_ca.cert.pem`),
//! `private/ca.key.pem` (also under the two other names), `enclaves/governance.p7s`, and per enclave `enclaves/<path>/` with
//! `cert.pem`, `key.pem`, `permissions.xml`, `permissions.p7s` and copies of the public files.
//!
//! What each identity may do is its role ([`Role`]): a machine writes its own topics and
//! answers its own services; the supervisor may call every service; the robot only
//! `robot_request`; an observer only reads state. Everything else is denied, and the
//! governance admits no participant without a certificate of this authority.

use std::path::{Path, PathBuf};

use openssl::asn1::Asn1Time;
use openssl::bn::{BigNum, MsbOption};
use openssl::ec::{EcGroup, EcKey};
use openssl::hash::MessageDigest;
use openssl::nid::Nid;
use openssl::pkcs7::{Pkcs7, Pkcs7Flags};
use openssl::pkey::{PKey, Private};
use openssl::stack::Stack;
use openssl::x509::extension::{BasicConstraints, KeyUsage};
use openssl::x509::{X509Name, X509};

/// What an identity of the cell may do.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Role {
    /// A controller: all the nodes of machine `namespace` share this identity.
    Machine { namespace: String },
    /// Starts programs and watches alarms: may call every service of every machine.
    Supervisor,
    /// Loads parts: may call `robot_request` and nothing else.
    Robot,
    /// Reads state topics; calls nothing.
    Observer,
}

/// One identity: its enclave path (its certificate's common name) and its role.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Enclave {
    pub path: String,
    pub role: Role,
}

/// The cell's identities for `machines`: `/<machine>` for each, `/cell/supervisor`,
/// `/cell/robot` and `/cell/observer`.
pub fn cell_enclaves(machines: &[String]) -> Result<Vec<Enclave>, String> {
    let mut out = Vec::new();
    for m in machines {
        let ok = !m.is_empty()
            && m.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            && !m.starts_with(|c: char| c.is_ascii_digit());
        if !ok || m == "cell" {
            return Err(format!(
                "machine {m:?}: a namespace is letters, digits and '_', not starting with a digit, and not \"cell\""
            ));
        }
        out.push(Enclave {
            path: format!("/{m}"),
            role: Role::Machine {
                namespace: m.clone(),
            },
        });
    }
    for (path, role) in [
        ("/cell/supervisor", Role::Supervisor),
        ("/cell/robot", Role::Robot),
        ("/cell/observer", Role::Observer),
    ] {
        out.push(Enclave {
            path: path.into(),
            role,
        });
    }
    Ok(out)
}

/// Topics every participant of a ROS 2 graph writes and reads.
const COMMON: [&str; 3] = ["ros_discovery_info", "rt/rosout", "rt/parameter_events"];

/// The DDS topic expressions `role` may (publish, subscribe).
pub fn grants(role: &Role) -> (Vec<String>, Vec<String>) {
    let mut publish: Vec<String> = COMMON.iter().map(|s| s.to_string()).collect();
    let mut subscribe = publish.clone();
    // Every node follows the ROS clock (simulated time); nobody here publishes it.
    subscribe.push("rt/clock".into());
    let add = |v: &mut Vec<String>, items: &[&str]| v.extend(items.iter().map(|s| s.to_string()));
    match role {
        Role::Machine { namespace: m } => {
            publish.extend([format!("rt/{m}/*"), format!("rr/{m}/*")]);
            subscribe.extend([format!("rt/{m}/*"), format!("rq/{m}/*")]);
        }
        Role::Supervisor => {
            add(
                &mut publish,
                &["rq/*", "rt/cell/*", "rr/cell/*", "rt/*/sim/input"],
            );
            add(&mut subscribe, &["rr/*", "rt/*", "rq/cell/*"]);
        }
        Role::Robot => {
            add(&mut publish, &["rq/*/robot_requestRequest", "rr/cell/*"]);
            add(
                &mut subscribe,
                &["rr/*/robot_requestReply", "rt/*", "rq/cell/*"],
            );
        }
        Role::Observer => add(&mut subscribe, &["rt/*"]),
    }
    (publish, subscribe)
}

/// How the cell's traffic is protected on the wire (D113). Both kinds authenticate every RTPS
/// message with the sender's key and a MAC per receiver (origin authentication), so a host
/// without credentials can neither forge nor alter a message, and an authenticated participant
/// cannot send in another's name; they differ in whether the samples, the endpoints' submessages
/// and discovery are also encrypted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Protection {
    /// Everything signed, nothing encrypted: a capture reads the programs and the state.
    Sign,
    /// Signed, and discovery, liveliness, submessages and samples encrypted (the default).
    #[default]
    Encrypt,
}

impl Protection {
    pub fn parse(s: &str) -> Result<Protection, String> {
        match s {
            "sign" => Ok(Protection::Sign),
            "encrypt" => Ok(Protection::Encrypt),
            other => Err(format!("protection {other:?}: sign or encrypt")),
        }
    }

    /// The governance's protection kinds: (discovery and liveliness, RTPS, metadata, data).
    fn kinds(self) -> [&'static str; 4] {
        match self {
            Protection::Sign => [
                "SIGN",
                "SIGN_WITH_ORIGIN_AUTHENTICATION",
                "SIGN_WITH_ORIGIN_AUTHENTICATION",
                "SIGN",
            ],
            Protection::Encrypt => [
                "ENCRYPT",
                "SIGN_WITH_ORIGIN_AUTHENTICATION",
                "ENCRYPT_WITH_ORIGIN_AUTHENTICATION",
                "ENCRYPT",
            ],
        }
    }
}

/// The governance document: only participants with a certificate of the cell's authority
/// join, every topic is under read and write access control (a participant's permissions
/// decide what it may write and read), and every message is protected as `protection` says.
/// The RTPS level is signed, not encrypted, in both: under `Encrypt` what it would hide is
/// encrypted a level below already (D113).
pub fn governance_xml(protection: Protection) -> String {
    let [discovery, rtps, metadata, data] = protection.kinds();
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-Security/20170801/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
{domains}
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>{discovery}</discovery_protection_kind>
      <liveliness_protection_kind>{discovery}</liveliness_protection_kind>
      <rtps_protection_kind>{rtps}</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>{metadata}</metadata_protection_kind>
          <data_protection_kind>{data}</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
"#,
        domains = domains(6),
    )
}

/// The domains every document covers, 0–232 (all a ROS 2 domain id can be), indented by
/// `indent` spaces.
fn domains(indent: usize) -> String {
    let lines = [
        "<domains>",
        "  <id_range>",
        "    <min>0</min>",
        "    <max>232</max>",
        "  </id_range>",
        "</domains>",
    ];
    let pad = " ".repeat(indent);
    lines
        .iter()
        .map(|l| format!("{pad}{l}"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The permissions document of `enclave`, valid from `not_before` to `not_after`
/// (`YYYY-MM-DDTHH:MM:SS`).
pub fn permissions_xml(enclave: &Enclave, not_before: &str, not_after: &str) -> String {
    let (publish, subscribe) = grants(&enclave.role);
    let topics = |v: &[String]| {
        v.iter()
            .map(|t| format!("            <topic>{t}</topic>\n"))
            .collect::<String>()
    };
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-Security/20170801/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="{path}">
      <subject_name>CN={path}</subject_name>
      <validity>
        <not_before>{not_before}</not_before>
        <not_after>{not_after}</not_after>
      </validity>
      <allow_rule>
{domains}
        <publish>
          <topics>
{publish}          </topics>
        </publish>
        <subscribe>
          <topics>
{subscribe}          </topics>
        </subscribe>
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
"#,
        path = enclave.path,
        domains = domains(8),
        publish = topics(&publish),
        subscribe = topics(&subscribe),
    )
}

/// How long certificates and permissions are valid.
const VALID_DAYS: u32 = 3650;

/// An OpenSSL failure named by what was being made.
fn e(what: &'static str) -> impl Fn(openssl::error::ErrorStack) -> String {
    move |err| format!("{what}: {err}")
}

/// Creates the keystore at `dir` (which must not exist, so a cell's authority is never
/// replaced by accident) with the authority, every enclave and the governance of `protection`.
/// Returns the enclave folders.
pub fn init(
    dir: &Path,
    enclaves: &[Enclave],
    protection: Protection,
) -> Result<Vec<PathBuf>, String> {
    if dir.exists() {
        return Err(format!(
            "{}: exists; a keystore is made once (remove it to start a new authority)",
            dir.display()
        ));
    }
    let ca_key = new_key().map_err(e("CA key"))?;
    let ca = ca_certificate(&ca_key).map_err(e("CA certificate"))?;
    let ca_pem = String::from_utf8_lossy(&ca.to_pem().map_err(e("CA PEM"))?).into_owned();
    for sub in ["public", "private", "enclaves"] {
        std::fs::create_dir_all(dir.join(sub))
            .map_err(|err| format!("{}: {err}", dir.display()))?;
    }
    for name in [
        "ca.cert.pem",
        "identity_ca.cert.pem",
        "permissions_ca.cert.pem",
    ] {
        write(&dir.join("public").join(name), ca_pem.as_bytes(), false)?;
    }
    let ca_key_pem = ca_key.private_key_to_pem_pkcs8().map_err(e("CA key PEM"))?;
    for name in [
        "ca.key.pem",
        "identity_ca.key.pem",
        "permissions_ca.key.pem",
    ] {
        write(&dir.join("private").join(name), &ca_key_pem, true)?;
    }
    let governance_text = governance_xml(protection);
    let governance = sign(&ca, &ca_key, governance_text.as_bytes()).map_err(e("governance"))?;
    write(
        &dir.join("enclaves/governance.xml"),
        governance_text.as_bytes(),
        false,
    )?;
    write(&dir.join("enclaves/governance.p7s"), &governance, false)?;

    let now = Asn1Time::days_from_now(0).map_err(e("time"))?;
    let not_before = xml_time(&now.to_string(), -1);
    let later = Asn1Time::days_from_now(VALID_DAYS).map_err(e("time"))?;
    let not_after = xml_time(&later.to_string(), 0);
    let mut folders = Vec::new();
    for enclave in enclaves {
        let rel = enclave.path.trim_start_matches('/');
        if rel.is_empty()
            || rel
                .split('/')
                .any(|s| s.is_empty() || s == "." || s == "..")
        {
            return Err(format!(
                "enclave {:?}: not a path like /lathe1",
                enclave.path
            ));
        }
        let folder = dir.join("enclaves").join(rel);
        std::fs::create_dir_all(&folder).map_err(|err| format!("{}: {err}", folder.display()))?;
        let key = new_key().map_err(e("key"))?;
        let cert = identity_certificate(&enclave.path, &key, &ca, &ca_key)
            .map_err(e("identity certificate"))?;
        write(
            &folder.join("cert.pem"),
            &cert.to_pem().map_err(e("PEM"))?,
            false,
        )?;
        let key_pem = key.private_key_to_pem_pkcs8().map_err(e("key PEM"))?;
        write(&folder.join("key.pem"), &key_pem, true)?;
        let permissions = permissions_xml(enclave, &not_before, &not_after);
        let signed = sign(&ca, &ca_key, permissions.as_bytes()).map_err(e("permissions"))?;
        write(
            &folder.join("permissions.xml"),
            permissions.as_bytes(),
            false,
        )?;
        write(&folder.join("permissions.p7s"), &signed, false)?;
        write(&folder.join("governance.p7s"), &governance, false)?;
        for name in ["identity_ca.cert.pem", "permissions_ca.cert.pem"] {
            write(&folder.join(name), ca_pem.as_bytes(), false)?;
        }
        folders.push(folder);
    }
    Ok(folders)
}

/// `Nov 25 20:30:00 2026 GMT` (OpenSSL's text of a time) as `2026-11-25T20:30:00`, moved by
/// `days` (a grant valid from yesterday tolerates clocks of the cell that differ a little).
fn xml_time(openssl_text: &str, days: i64) -> String {
    let parts: Vec<&str> = openssl_text.split_whitespace().collect();
    let month = [
        "Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec",
    ]
    .iter()
    .position(|m| parts.first() == Some(m))
    .map_or(1, |i| i + 1);
    let day: i64 = parts.get(1).and_then(|d| d.parse().ok()).unwrap_or(1);
    let time = parts.get(2).copied().unwrap_or("00:00:00");
    let year: i64 = parts.get(3).and_then(|y| y.parse().ok()).unwrap_or(1970);
    // Moving back a day: the first of a month becomes the first again (a day's slack at most).
    let day = (day + days).max(1);
    format!("{year:04}-{month:02}-{day:02}T{time}")
}

fn new_key() -> Result<PKey<Private>, openssl::error::ErrorStack> {
    let group = EcGroup::from_curve_name(Nid::X9_62_PRIME256V1)?;
    PKey::from_ec_key(EcKey::generate(&group)?)
}

fn serial() -> Result<openssl::asn1::Asn1Integer, openssl::error::ErrorStack> {
    let mut bn = BigNum::new()?;
    bn.rand(127, MsbOption::MAYBE_ZERO, false)?;
    bn.to_asn1_integer()
}

fn name(common_name: &str) -> Result<X509Name, openssl::error::ErrorStack> {
    let mut n = X509Name::builder()?;
    n.append_entry_by_nid(Nid::COMMONNAME, common_name)?;
    Ok(n.build())
}

fn ca_certificate(key: &PKey<Private>) -> Result<X509, openssl::error::ErrorStack> {
    let mut b = X509::builder()?;
    b.set_version(2)?;
    b.set_serial_number(&*serial()?)?;
    let subject = name("cnc cell authority")?;
    b.set_subject_name(&subject)?;
    b.set_issuer_name(&subject)?;
    b.set_not_before(&*Asn1Time::days_from_now(0)?)?;
    b.set_not_after(&*Asn1Time::days_from_now(VALID_DAYS)?)?;
    b.set_pubkey(key)?;
    b.append_extension(BasicConstraints::new().critical().ca().build()?)?;
    b.append_extension(
        KeyUsage::new()
            .critical()
            .key_cert_sign()
            .crl_sign()
            .digital_signature()
            .build()?,
    )?;
    b.sign(key, MessageDigest::sha256())?;
    Ok(b.build())
}

fn identity_certificate(
    common_name: &str,
    key: &PKey<Private>,
    ca: &X509,
    ca_key: &PKey<Private>,
) -> Result<X509, openssl::error::ErrorStack> {
    let mut b = X509::builder()?;
    b.set_version(2)?;
    b.set_serial_number(&*serial()?)?;
    b.set_subject_name(&*name(common_name)?)?;
    b.set_issuer_name(ca.subject_name())?;
    b.set_not_before(&*Asn1Time::days_from_now(0)?)?;
    b.set_not_after(&*Asn1Time::days_from_now(VALID_DAYS)?)?;
    b.set_pubkey(key)?;
    b.append_extension(BasicConstraints::new().build()?)?;
    b.sign(ca_key, MessageDigest::sha256())?;
    Ok(b.build())
}

/// `text` signed by the authority as S/MIME, as `openssl smime -sign -text` writes it.
fn sign(
    ca: &X509,
    key: &PKey<Private>,
    text: &[u8],
) -> Result<Vec<u8>, openssl::error::ErrorStack> {
    let flags = Pkcs7Flags::DETACHED | Pkcs7Flags::TEXT;
    let p7 = Pkcs7::sign(ca, key, &*Stack::<X509>::new()?, text, flags)?;
    p7.to_smime(text, flags)
}

/// Writes a keystore file; a private key readable by its owner only.
fn write(path: &Path, bytes: &[u8], private: bool) -> Result<(), String> {
    use std::io::Write;
    use std::os::unix::fs::OpenOptionsExt;
    let mode = if private { 0o600 } else { 0o644 };
    let mut f = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(mode)
        .open(path)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    f.write_all(bytes)
        .and_then(|_| f.sync_all())
        .map_err(|e| format!("{}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_role_is_granted_only_its_own_doors() {
        let (p, s) = grants(&Role::Robot);
        assert!(p.contains(&"rq/*/robot_requestRequest".to_string()));
        assert!(!p.iter().any(|t| t == "rq/*"));
        assert!(s.contains(&"rr/*/robot_requestReply".to_string()));
        let (p, s) = grants(&Role::Machine {
            namespace: "lathe1".into(),
        });
        assert!(p.contains(&"rr/lathe1/*".to_string()));
        assert!(s.contains(&"rq/lathe1/*".to_string()));
        assert!(!p.iter().any(|t| t.starts_with("rq/")));
        let (p, _) = grants(&Role::Observer);
        assert_eq!(p.len(), COMMON.len());
    }

    #[test]
    fn names_that_are_no_namespace_are_refused() {
        for bad in ["", "cell", "1lathe", "la the", "../x", "a/b"] {
            assert!(cell_enclaves(&[bad.to_string()]).is_err(), "{bad}");
        }
        let e = cell_enclaves(&["lathe1".into()]).unwrap();
        assert_eq!(e[0].path, "/lathe1");
        assert_eq!(e.len(), 4);
    }

    #[test]
    fn openssl_times_become_xml_times() {
        assert_eq!(
            xml_time("Nov 25 20:30:00 2026 GMT", -1),
            "2026-11-24T20:30:00"
        );
        assert_eq!(
            xml_time("Dec  1 01:02:03 2036 GMT", 0),
            "2036-12-01T01:02:03"
        );
        assert_eq!(
            xml_time("Dec  1 01:02:03 2036 GMT", -1),
            "2036-12-01T01:02:03"
        );
    }

    #[test]
    fn every_message_is_authenticated_whichever_the_protection() {
        for protection in [Protection::Sign, Protection::Encrypt] {
            let g = governance_xml(protection);
            assert!(!g.contains(">NONE<"), "{protection:?}: {g}");
            assert!(
                g.contains("<rtps_protection_kind>SIGN_WITH_ORIGIN_AUTHENTICATION<"),
                "{g}"
            );
            let encrypted = g.matches(">ENCRYPT").count();
            assert_eq!(
                encrypted,
                if protection == Protection::Sign { 0 } else { 4 }
            );
        }
        assert_eq!(Protection::parse("sign"), Ok(Protection::Sign));
        assert!(Protection::parse("none").is_err());
    }

    #[test]
    fn a_keystore_is_made_once_with_signed_documents() {
        let dir = std::env::temp_dir().join(format!("cnc_keystore_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let enclaves = cell_enclaves(&["lathe1".into()]).unwrap();
        let folders = init(&dir, &enclaves, Protection::Encrypt).unwrap();
        assert_eq!(folders.len(), 4);
        let robot = dir.join("enclaves/cell/robot");
        let p7s = std::fs::read_to_string(robot.join("permissions.p7s")).unwrap();
        assert!(p7s.contains("multipart/signed"), "{p7s}");
        assert!(p7s.contains("CN=/cell/robot"));
        // The signature verifies against the authority, and the signed text is the document.
        let ca = X509::from_pem(&std::fs::read(dir.join("public/ca.cert.pem")).unwrap()).unwrap();
        let (p7, content) = Pkcs7::from_smime(p7s.as_bytes()).unwrap();
        let mut store = openssl::x509::store::X509StoreBuilder::new().unwrap();
        store.add_cert(ca).unwrap();
        let store = store.build();
        let mut out = Vec::new();
        p7.verify(
            &Stack::<X509>::new().unwrap(),
            &store,
            content.as_deref(),
            Some(&mut out),
            Pkcs7Flags::TEXT,
        )
        .unwrap();
        // S/MIME signs the text with CRLF line ends (its canonical form).
        let xml = std::fs::read_to_string(robot.join("permissions.xml")).unwrap();
        assert!(String::from_utf8_lossy(&out).replace("\r\n", "\n") == xml);
        let cert = X509::from_pem(&std::fs::read(robot.join("cert.pem")).unwrap()).unwrap();
        let cn = cert
            .subject_name()
            .entries()
            .next()
            .unwrap()
            .data()
            .to_string()
            .unwrap();
        assert_eq!(cn, "/cell/robot");
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(robot.join("key.pem"))
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(mode & 0o077, 0);
        assert!(
            init(&dir, &enclaves, Protection::Encrypt).is_err(),
            "a second init must not replace the authority"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
