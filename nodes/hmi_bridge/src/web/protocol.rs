//! What a page may ask, as JSON over its WebSocket: `{"id": 7, "op": "start", "name": "O0001"}`.
//! Each request becomes the same [`Operation`] a ROS 2 service makes; a request that does not
//! parse is answered with why, and nothing happens.

use cnc_msgs::msg::{MachineState, Overrides, ToolOffset, WorkOffset};
use serde_json::Value;

use crate::operation::Operation;

/// A page's request: its id (echoed in the reply) and the operation, or why it is not one.
pub fn parse(text: &str) -> (u64, Result<Operation, String>) {
    let value: Value = match serde_json::from_str(text) {
        Ok(v) => v,
        Err(e) => return (0, Err(format!("request is not JSON: {e}"))),
    };
    let id = value.get("id").and_then(Value::as_u64).unwrap_or(0);
    (id, operation(&value))
}

/// A page's binary request: a JSON header (`{"id": 7, "op": "load", "name": "O0001"}`), a zero
/// byte, and the program's text unescaped, so a program up to the services' limit fits in one
/// WebSocket message (JSON escaping once pushed a 4 MiB program over it, issue 26).
pub fn parse_binary(data: &[u8]) -> (u64, Result<Operation, String>) {
    let Some(split) = data.iter().position(|&b| b == 0) else {
        return (
            0,
            Err("binary request without its zero byte after the header".into()),
        );
    };
    let header: Value = match serde_json::from_slice(&data[..split]) {
        Ok(v) => v,
        Err(e) => return (0, Err(format!("binary request header is not JSON: {e}"))),
    };
    let id = header.get("id").and_then(Value::as_u64).unwrap_or(0);
    if header.get("op").and_then(Value::as_str) != Some("load") {
        return (
            id,
            Err("a binary request loads a program: op must be \"load\"".into()),
        );
    }
    let name = match string(&header, "name") {
        Ok(n) => n,
        Err(e) => return (id, Err(e)),
    };
    match String::from_utf8(data[split + 1..].to_vec()) {
        Ok(text) => (id, Ok(Operation::Load { name, text })),
        Err(e) => (id, Err(format!("program text is not UTF-8: {e}"))),
    }
}

fn string(v: &Value, key: &str) -> Result<String, String> {
    v.get(key)
        .and_then(Value::as_str)
        .map(str::to_string)
        .ok_or_else(|| format!("{key} missing (a string)"))
}

fn percent(v: &Value, key: &str) -> Result<u8, String> {
    let n = v
        .get(key)
        .and_then(Value::as_u64)
        .ok_or_else(|| format!("{key} missing (a whole number of percent)"))?;
    u8::try_from(n).map_err(|_| format!("{key} {n} % is out of range"))
}

fn operation(v: &Value) -> Result<Operation, String> {
    let op = v.get("op").and_then(Value::as_str).ok_or("op missing")?;
    Ok(match op {
        "load" => Operation::Load {
            name: string(v, "name")?,
            text: string(v, "text")?,
        },
        "start" => {
            let at = string(v, "at").unwrap_or_default();
            if at.len() > 64 || at.chars().any(char::is_control) {
                return Err("at: at most 64 characters, no control characters".into());
            }
            Operation::Start {
                name: string(v, "name").unwrap_or_default(),
                at: at.trim().to_string(),
            }
        }
        "feed_hold" => Operation::Stop {
            mode: cnc_msgs::srv::StopRequest::FEED_HOLD,
        },
        "cycle_stop" => Operation::Stop {
            mode: cnc_msgs::srv::StopRequest::CYCLE_STOP,
        },
        "reset" => Operation::Reset,
        "list" => Operation::List,
        "delete" => Operation::Delete {
            name: string(v, "name")?,
        },
        "read" => Operation::Read {
            name: string(v, "name")?,
        },
        "overrides" => Operation::Overrides(Overrides {
            feed_percent: percent(v, "feed")?,
            spindle_percent: percent(v, "spindle")?,
            rapid_percent: percent(v, "rapid")?,
        }),
        "mode" => {
            let name = string(v, "mode")?;
            let mode = (0..=MachineState::MODE_HANDWHEEL)
                .find(|m| MachineState::mode_name_of(*m).eq_ignore_ascii_case(&name))
                .ok_or_else(|| {
                    format!("unknown mode {name:?}: AUTO, MDI, JOG, HOME, EDIT, HANDWHEEL")
                })?;
            Operation::Mode { mode }
        }
        "mdi" => Operation::Mdi {
            text: string(v, "text")?,
        },
        "jog" => {
            let number = |key: &str| v.get(key).and_then(Value::as_f64).unwrap_or(0.0);
            let direction = v.get("direction").and_then(Value::as_i64).unwrap_or(0);
            Operation::Jog {
                axis: string(v, "axis")?,
                direction: i8::try_from(direction)
                    .map_err(|_| format!("direction {direction}: +1, -1 or 0"))?,
                feed: number("feed"),
                increment: number("increment"),
            }
        }
        "offsets" => Operation::Offsets,
        "set_tool_offset" => {
            Operation::SetToolOffset(tool_row(&string(v, "number")?, &string(v, "values")?)?)
        }
        "set_work_offset" => {
            Operation::SetWorkOffset(work_row(&string(v, "code")?, &string(v, "values")?)?)
        }
        "parameters" => Operation::Parameters {
            prefix: string(v, "prefix").unwrap_or_default(),
        },
        "set_parameter" => Operation::SetParameter {
            name: string(v, "name")?,
            value: string(v, "value")?,
        },
        // Without source and number: every active alarm.
        "acknowledge" => Operation::Acknowledge {
            source: string(v, "source").unwrap_or_default(),
            number: match v.get("number") {
                None => 0,
                Some(n) => n
                    .as_u64()
                    .and_then(|n| u32::try_from(n).ok())
                    .ok_or("number: an alarm number")?,
            },
        },
        other => return Err(format!("unknown op {other:?}")),
    })
}

fn number(word: &str, what: &str) -> Result<f64, String> {
    word.trim()
        .parse()
        .map_err(|_| format!("{what}: {word:?} is not a number"))
}

/// A tool row as the panel's fields give it: the offset number, and `x z wear_x wear_z radius
/// tip` (the task checks the ranges).
fn tool_row(entry: &str, values: &str) -> Result<ToolOffset, String> {
    let n = entry
        .trim()
        .parse()
        .map_err(|_| format!("offset number {entry:?} is not a number"))?;
    let words: Vec<&str> = values.split_whitespace().collect();
    let [x, z, wx, wz, r, tip] = words[..] else {
        return Err(format!(
            "tool offset needs 6 values: x z wear_x wear_z radius tip, got {}",
            words.len()
        ));
    };
    Ok(ToolOffset {
        number: n,
        x: number(x, "X")?,
        z: number(z, "Z")?,
        wear_x: number(wx, "X wear")?,
        wear_z: number(wz, "Z wear")?,
        radius: number(r, "nose radius")?,
        tip: tip
            .parse()
            .map_err(|_| format!("tip direction {tip:?} out of range 0-9"))?,
    })
}

/// A work offset as the panel's fields give it: the code, and `X=.. Z=..`.
fn work_row(code: &str, values: &str) -> Result<WorkOffset, String> {
    let mut row = WorkOffset {
        code: code.trim().to_string(),
        ..WorkOffset::default()
    };
    for word in values.split_whitespace() {
        let (axis, v) = word
            .split_once('=')
            .ok_or_else(|| format!("{word:?}: write axis=value, e.g. Z=-120.5"))?;
        row.values.push(number(v, &format!("{code} {axis}"))?);
        row.axes.push(axis.trim().to_string());
    }
    Ok(row)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_become_the_services_operations_and_bad_ones_say_why() {
        assert_eq!(
            parse(r#"{"id":3,"op":"start","name":"O0001"}"#),
            (
                3,
                Ok(Operation::Start {
                    name: "O0001".into(),
                    at: String::new()
                })
            )
        );
        assert_eq!(
            parse(r#"{"id":4,"op":"start","name":"O0001","at":" line 12 "}"#).1,
            Ok(Operation::Start {
                name: "O0001".into(),
                at: "line 12".into()
            })
        );
        assert_eq!(
            parse(r#"{"id":6,"op":"jog","axis":"X","direction":-1,"feed":600}"#).1,
            Ok(Operation::Jog {
                axis: "X".into(),
                direction: -1,
                feed: 600.0,
                increment: 0.0
            })
        );
        assert!(parse(r#"{"id":7,"op":"jog","axis":"X","direction":300}"#)
            .1
            .is_err());
        assert!(parse(r#"{"id":5,"op":"start","name":"O1","at":"line\n1"}"#)
            .1
            .is_err());
        assert_eq!(
            parse(r#"{"op":"acknowledge"}"#).1,
            Ok(Operation::Acknowledge {
                source: String::new(),
                number: 0
            })
        );
        assert_eq!(
            parse(r#"{"op":"set_parameter","name":"servo.lookahead","value":"8"}"#).1,
            Ok(Operation::SetParameter {
                name: "servo.lookahead".into(),
                value: "8".into()
            })
        );
        assert!(parse(r#"{"op":"acknowledge","number":-3}"#).1.is_err());
        assert_eq!(
            parse(r#"{"op":"set_tool_offset","number":"3","values":"-120.5 40 0.02 -0.01 0.4 3"}"#)
                .1,
            Ok(Operation::SetToolOffset(ToolOffset {
                number: 3,
                x: -120.5,
                z: 40.0,
                wear_x: 0.02,
                wear_z: -0.01,
                radius: 0.4,
                tip: 3
            }))
        );
        assert_eq!(
            parse(r#"{"op":"set_work_offset","code":"g55","values":"X=10 Z=-200.25"}"#).1,
            Ok(Operation::SetWorkOffset(WorkOffset {
                code: "g55".into(),
                axes: vec!["X".into(), "Z".into()],
                values: vec![10.0, -200.25]
            }))
        );
        assert_eq!(
            parse(r#"{"id":4,"op":"mode","mode":"mdi"}"#).1,
            Ok(Operation::Mode {
                mode: MachineState::MODE_MDI
            })
        );
        assert_eq!(
            parse(r#"{"op":"overrides","feed":50,"spindle":100,"rapid":25}"#).1,
            Ok(Operation::Overrides(Overrides {
                feed_percent: 50,
                spindle_percent: 100,
                rapid_percent: 25
            }))
        );
        for (text, why) in [
            ("not json", "not JSON"),
            (r#"{"id":1}"#, "op missing"),
            (r#"{"op":"explode"}"#, "unknown op"),
            (r#"{"op":"load","name":"A"}"#, "text missing"),
            (
                r#"{"op":"overrides","feed":300,"spindle":100,"rapid":25}"#,
                "out of range",
            ),
            (
                r#"{"op":"overrides","feed":-5,"spindle":100,"rapid":25}"#,
                "feed missing",
            ),
            (r#"{"op":"mode","mode":"TURBO"}"#, "unknown mode"),
            (
                r#"{"op":"set_tool_offset","number":"3","values":"1 2 3"}"#,
                "needs 6 values",
            ),
            (
                r#"{"op":"set_tool_offset","number":"3","values":"x 0 0 0 0 3"}"#,
                "not a number",
            ),
            (
                r#"{"op":"set_work_offset","code":"G54","values":"Z:1"}"#,
                "axis=value",
            ),
        ] {
            let err = parse(text).1.unwrap_err();
            assert!(err.contains(why), "{text}: {err}");
        }
    }

    #[test]
    fn a_program_at_the_services_limit_fits_in_one_binary_message() {
        let text = "(\"\")\n".repeat((cnc_runtime::MAX_PROGRAM_BYTES - 100) / 5);
        let mut message = br#"{"id": 9, "op": "load", "name": "BIG.nc"}"#.to_vec();
        message.push(0);
        message.extend_from_slice(text.as_bytes());
        let max = crate::web::http::MAX_MESSAGE;
        assert!(message.len() <= max);
        let escaped = serde_json::to_string(&text).unwrap();
        assert!(escaped.len() > max, "JSON would not fit: {}", escaped.len());
        match parse_binary(&message) {
            (9, Ok(Operation::Load { name, text: t })) => assert!(name == "BIG.nc" && t == text),
            (id, other) => panic!("{id}: {other:?}"),
        }
        assert!(parse_binary(b"{\"op\": \"start\"}\0x").1.is_err());
        assert!(parse_binary(b"{\"op\": \"load\", \"name\": \"a\"}\0\xff")
            .1
            .is_err());
        assert!(parse_binary(b"no zero byte").1.is_err());
    }
}
