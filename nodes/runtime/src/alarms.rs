//! Publishing alarms: every node reports on `/<ns>/alarm_events`; hmi_bridge keeps the list.

use cnc_msgs::msg::{Alarm, AlarmEvent};

use crate::dds::{stamp, Publisher, RosNode};
use crate::topics;

/// A node's alarm reporter.
pub struct AlarmReporter {
    source: String,
    publisher: Publisher<AlarmEvent>,
}

impl AlarmReporter {
    pub fn new(node: &mut RosNode, source: &str) -> Result<Self, String> {
        Ok(AlarmReporter {
            source: source.into(),
            publisher: node.publisher(&topics::ALARM_EVENTS)?,
        })
    }

    pub fn alarm(&self, number: u32, severity: u8, text: &str, program: &str, line: u32) -> Alarm {
        Alarm {
            number,
            severity,
            text: text.into(),
            source: self.source.clone(),
            program: program.into(),
            line,
            stamp: stamp(),
            acknowledged: false,
        }
    }

    pub fn raise(&self, alarm: Alarm) {
        log::error!(
            "alarm {} ({}): {} [{} line {}]",
            alarm.number,
            alarm.source,
            alarm.text,
            alarm.program,
            alarm.line
        );
        if let Err(e) = self.publisher.publish(AlarmEvent {
            kind: AlarmEvent::RAISED,
            alarm,
        }) {
            log::error!("{}: alarm event not published: {e:?}", self.source);
        }
    }

    pub fn clear(&self, number: u32) {
        let alarm = self.alarm(number, Alarm::SEVERITY_INFO, "", "", 0);
        if let Err(e) = self.publisher.publish(AlarmEvent {
            kind: AlarmEvent::CLEARED,
            alarm,
        }) {
            log::error!("{}: alarm event not published: {e:?}", self.source);
        }
    }
}
