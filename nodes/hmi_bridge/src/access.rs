//! Who is asking: the ROS 2 node names behind a request's DDS writer, and whether they may
//! move the machine.
//!
//! A request carries only its writer's GUID. ROS 2 participants announce which nodes they
//! host on `ros_discovery_info`; the first 12 bytes of a GUID name the participant, so the
//! bridge keeps a directory from those 12 bytes to node names. A client whose participant
//! announced nothing (a bare DDS program) is known by its GUID only, and only a `*` in the
//! allowed list lets it move the machine.

use std::collections::BTreeMap;

use cnc_runtime::topics::matches;

/// Who sent a command: a DDS writer (a ROS 2 service client, action client or robot) or a
/// page of the web HMI, named `web@<address>`.
#[derive(Debug, Clone, PartialEq)]
pub enum Who {
    Dds([u8; 16]),
    Web(String),
}

/// Participant (GUID prefix) → the nodes it hosts, `/namespace/name`.
#[derive(Debug, Default)]
pub struct Clients {
    nodes: BTreeMap<[u8; 12], Vec<String>>,
}

impl Clients {
    /// A participant's announcement of its nodes (replaces what it said before).
    pub fn learn(&mut self, participant: [u8; 12], nodes: Vec<String>) {
        self.nodes.insert(participant, nodes);
    }

    /// The node names behind a writer GUID (16 bytes), if its participant announced any.
    pub fn nodes_of(&self, writer: &[u8; 16]) -> &[String] {
        let mut prefix = [0u8; 12];
        prefix.copy_from_slice(&writer[..12]);
        self.nodes.get(&prefix).map_or(&[], |v| v.as_slice())
    }

    /// How events name the client: its node names, else `guid:<hex>`.
    pub fn describe(&self, writer: &[u8; 16]) -> String {
        let nodes = self.nodes_of(writer);
        if nodes.is_empty() {
            let hex: String = writer.iter().map(|b| format!("{b:02x}")).collect();
            format!("guid:{hex}")
        } else {
            nodes.join(",")
        }
    }
}

/// Whether a client with these node names may move the machine under `allowed` patterns.
pub fn may_move(allowed: &[String], nodes: &[String], described: &str) -> Result<(), String> {
    if allowed.iter().any(|p| p == "*") {
        return Ok(());
    }
    if nodes.iter().any(|n| allowed.iter().any(|p| matches(p, n))) {
        return Ok(());
    }
    Err(format!(
        "client {described} may not move this machine (hmi.allowed_clients of the launch config)"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clients_are_known_by_their_participants_nodes() {
        let mut c = Clients::default();
        let writer = [7u8; 16];
        assert_eq!(c.describe(&writer), format!("guid:{}", "07".repeat(16)));
        c.learn([7; 12], vec!["/cell/supervisor".into()]);
        assert_eq!(c.describe(&writer), "/cell/supervisor");
        let allowed = vec!["/cell/*".to_string()];
        assert!(may_move(&allowed, c.nodes_of(&writer), "x").is_ok());
        assert!(may_move(&allowed, &["/lathe1/intruder".into()], "y")
            .unwrap_err()
            .contains("may not move"));
        // Unknown clients are refused unless everyone is allowed.
        assert!(may_move(&allowed, &[], "guid:..").is_err());
        assert!(may_move(&["*".into()], &[], "guid:..").is_ok());
    }
}
