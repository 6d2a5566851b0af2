//! The operator's web HMI: one page (`web/`), live over a WebSocket. [`server`] is the network
//! shell, [`protocol`] turns a page's requests into the bridge's [`Operation`]s, [`view`]
//! keeps what the page shows. [`WebHmi`] joins them for the bridge's loop.

pub mod assets;
pub mod http;
pub mod login;
pub mod protocol;
pub mod view;

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use serde_json::{json, Value};

use crate::access::Who;
use crate::operation::{Answer, Operation};
use http::{Outbox, Payload, WebEvent, WebServer};
use view::View;

/// How often pages get a state frame.
const FRAME_PERIOD: Duration = Duration::from_millis(100);

/// A page's request waiting for its answer.
pub struct Pending {
    connection: u64,
    id: u64,
    op: Operation,
}

/// Whether the panel of `hmi` may be served as configured (see [`login::exposure`]): the cell
/// refuses to start rather than serve the panel to the network without logins.
pub fn check(hmi: &cnc_runtime::config::HmiConfig) -> Result<(), String> {
    if hmi.web_address.is_empty() {
        return Ok(());
    }
    let operators = match &hmi.operators_file {
        Some(path) => login::OperatorsFile::load(path)?.operators.len(),
        None => 0,
    };
    login::exposure(&hmi.web_address, operators, &hmi.web_origins)
}

pub struct WebHmi {
    server: WebServer,
    /// Logins at the panel since the last [`WebHmi::take_logins`]: client, operator,
    /// accepted, message.
    logins: Vec<(String, String, bool, String)>,
    pages: BTreeMap<u64, Outbox>,
    pub view: View,
    /// Sent once to every page, and again when it changes.
    ladder: Option<Value>,
    last_frame: Instant,
}

impl WebHmi {
    /// The panel of machine `machine`.
    pub fn start(
        hmi: &cnc_runtime::config::HmiConfig,
        machine: &str,
        axes: Vec<String>,
        diameter: Vec<bool>,
    ) -> Result<WebHmi, String> {
        // Whether it may be served at all was [`check`]ed when the bridge started.
        let operators = match &hmi.operators_file {
            Some(path) => login::OperatorsFile::load(path)?.operators,
            None => BTreeMap::new(),
        };
        let lifetime = Duration::from_secs(hmi.session_seconds.max(1));
        let origins = hmi.web_origins.clone();
        let cell = serde_json::json!({"machine": machine, "panels": hmi.cell_panels});
        let server = WebServer::start(&hmi.web_address, move |bound| {
            let mut gate = login::Gate::new(bound, operators, origins, lifetime);
            gate.cell = cell;
            gate
        })?;
        log::info!("web HMI on http://{}/", server.address);
        Ok(WebHmi {
            server,
            logins: Vec::new(),
            pages: BTreeMap::new(),
            view: View::new(axes, diameter),
            ladder: None,
            last_frame: Instant::now(),
        })
    }

    pub fn address(&self) -> std::net::SocketAddr {
        self.server.address
    }

    fn send(&mut self, page: u64, frame: &Value) {
        if let Some(outbox) = self.pages.get(&page) {
            if outbox.send(frame.to_string()).is_err() {
                self.pages.remove(&page);
            }
        }
    }

    fn broadcast(&mut self, frame: &Value) {
        let text = frame.to_string();
        self.pages
            .retain(|_, outbox| outbox.send(text.clone()).is_ok());
    }

    /// The PLC program for the ladder monitor (sent now and to every page that opens later).
    pub fn set_ladder(&mut self, program: &cnc_msgs::msg::PlcProgram) {
        let ladder = json!({
            "type": "ladder",
            "source": program.source,
            "rungs": program.rungs,
            "lines": program.lines,
        });
        self.broadcast(&ladder);
        self.ladder = Some(ladder);
    }

    /// New pages are greeted; their requests come out as operations (bad ones are answered
    /// here).
    pub fn take_operations(&mut self) -> Vec<(Who, Operation, Pending)> {
        let mut out = Vec::new();
        while let Ok(event) = self.server.events.try_recv() {
            match event {
                WebEvent::Connected { id, client, outbox } => {
                    log::info!("web HMI: page {id} opened by {client}");
                    self.pages.insert(id, outbox);
                    let welcome = self.view.welcome();
                    self.send(id, &welcome);
                    if let Some(l) = self.ladder.clone() {
                        self.send(id, &l);
                    }
                }
                WebEvent::Closed { id } => {
                    self.pages.remove(&id);
                }
                WebEvent::Login {
                    client,
                    operator,
                    accepted,
                    message,
                } => self.logins.push((client, operator, accepted, message)),
                WebEvent::Request {
                    id,
                    client,
                    payload,
                } => match match payload {
                    Payload::Text(text) => protocol::parse(&text),
                    Payload::Binary(data) => protocol::parse_binary(&data),
                } {
                    (request, Ok(op)) => out.push((
                        Who::Web(client),
                        op.clone(),
                        Pending {
                            connection: id,
                            id: request,
                            op,
                        },
                    )),
                    (request, Err(why)) => {
                        let reply = json!({"type": "reply", "id": request, "accepted": false, "message": why});
                        self.send(id, &reply);
                    }
                },
            }
        }
        out
    }

    /// Logins since the last call (for the command events).
    pub fn take_logins(&mut self) -> Vec<(String, String, bool, String)> {
        std::mem::take(&mut self.logins)
    }

    /// Answers a page's request; reads bring their data in a frame of their own.
    pub fn answer(&mut self, pending: Pending, answer: Answer) {
        let data = match (&pending.op, answer.accepted) {
            (Operation::Read { name }, true) => {
                Some(json!({"type": "program", "name": name, "text": answer.message}))
            }
            (Operation::Offsets, true) => {
                let tools: Vec<Value> = answer
                    .tools
                    .iter()
                    .map(|t| {
                        json!({"number": t.number, "x": t.x, "z": t.z, "wear_x": t.wear_x,
                               "wear_z": t.wear_z, "radius": t.radius, "tip": t.tip})
                    })
                    .collect();
                let work: Vec<Value> = answer
                    .work
                    .iter()
                    .map(|w| json!({"code": w.code, "axes": w.axes, "values": w.values}))
                    .collect();
                Some(json!({"type": "offsets", "tools": tools, "work": work}))
            }
            (Operation::Parameters { .. }, true) => {
                let rows: Vec<Value> = answer
                    .parameters
                    .iter()
                    .map(|(name, value, pending)| json!([name, value, pending]))
                    .collect();
                Some(json!({"type": "parameters", "rows": rows}))
            }
            (Operation::List, true) => {
                let list: Vec<Value> = answer
                    .programs
                    .iter()
                    .map(|(name, size)| json!({"name": name, "size": size}))
                    .collect();
                Some(json!({"type": "programs", "programs": list}))
            }
            _ => None,
        };
        let shown = if data.is_some() {
            "ok".to_string()
        } else {
            answer.message
        };
        let reply = json!({
            "type": "reply",
            "id": pending.id,
            "op": pending.op.command(),
            "accepted": answer.accepted,
            "message": shown,
        });
        if let Some(d) = data {
            self.send(pending.connection, &d);
        }
        self.send(pending.connection, &reply);
    }

    /// Sends the state frame when it is due.
    pub fn tick(&mut self) {
        if self.pages.is_empty() {
            // Nobody watches: a page that opens gets everything in its welcome.
            self.view.mark_sent();
            return;
        }
        if self.last_frame.elapsed() >= FRAME_PERIOD {
            self.last_frame = Instant::now();
            let frame = self.view.frame();
            self.broadcast(&frame);
            if let Some(s) = self.view.signals_frame() {
                self.broadcast(&s);
            }
        }
    }
}
