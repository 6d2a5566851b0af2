//! The machine's active alarms as the bridge keeps them for `/<ns>/alarms`: raised and cleared
//! by their sources' events, acknowledged by people (decisions D44). Acknowledging says "seen";
//! only the cause going away and a reset (or the source) clear an alarm.

use std::collections::BTreeMap;

use cnc_msgs::msg::{Alarm, AlarmEvent};

#[derive(Default)]
pub struct AlarmList {
    /// By source and number: one alarm of a number per source is active at a time.
    active: BTreeMap<(String, u32), Alarm>,
}

impl AlarmList {
    /// Takes one alarm event; true if the list changed.
    pub fn on_event(&mut self, e: AlarmEvent) -> bool {
        let key = (e.alarm.source.clone(), e.alarm.number);
        if e.kind == AlarmEvent::RAISED {
            // The same occurrence heard again (the bridge's own alarms come back over DDS)
            // keeps its acknowledgement.
            if let Some(a) = self.active.get(&key) {
                if a.stamp == e.alarm.stamp && a.text == e.alarm.text {
                    return false;
                }
            }
            self.active.insert(
                key,
                Alarm {
                    acknowledged: false,
                    ..e.alarm
                },
            );
            true
        } else {
            self.active.remove(&key).is_some()
        }
    }

    /// Marks alarm `number` of `source` as seen; an empty source and number 0 mark every one.
    pub fn acknowledge(&mut self, source: &str, number: u32) -> Result<String, String> {
        let all = source.is_empty() && number == 0;
        let mut marked = 0;
        for ((s, n), a) in self.active.iter_mut() {
            if all || (s == source && *n == number) {
                marked += usize::from(!a.acknowledged);
                a.acknowledged = true;
                if !all {
                    return Ok(format!("alarm {n} ({s}) acknowledged"));
                }
            }
        }
        if all {
            Ok(format!("{marked} alarms acknowledged"))
        } else {
            Err(format!("no active alarm {number} from {source:?}"))
        }
    }

    pub fn alarms(&self) -> Vec<Alarm> {
        self.active.values().cloned().collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn event(kind: u8, source: &str, number: u32, sec: i32) -> AlarmEvent {
        AlarmEvent {
            kind,
            alarm: Alarm {
                number,
                source: source.into(),
                text: format!("alarm {number}"),
                stamp: cnc_msgs::msg::Time { sec, nanosec: 0 },
                ..Alarm::default()
            },
        }
    }

    #[test]
    fn an_acknowledged_alarm_stays_until_cleared_and_a_new_occurrence_is_unseen_again() {
        let mut list = AlarmList::default();
        assert!(list.on_event(event(AlarmEvent::RAISED, "plc", 65, 1)));
        assert!(list.on_event(event(AlarmEvent::RAISED, "motion", 3, 1)));
        assert_eq!(
            list.acknowledge("plc", 65).unwrap(),
            "alarm 65 (plc) acknowledged"
        );
        assert!(list
            .acknowledge("plc", 99)
            .unwrap_err()
            .contains("no active alarm 99"));
        let seen: Vec<bool> = list.alarms().iter().map(|a| a.acknowledged).collect();
        assert_eq!(seen, [false, true], "motion 3 unseen, plc 65 seen");
        // Heard again: the same occurrence keeps its mark; a new one does not.
        assert!(!list.on_event(event(AlarmEvent::RAISED, "plc", 65, 1)));
        assert!(list.alarms()[1].acknowledged);
        assert!(list.on_event(event(AlarmEvent::RAISED, "plc", 65, 2)));
        assert!(!list.alarms()[1].acknowledged);
        assert_eq!(list.acknowledge("", 0).unwrap(), "2 alarms acknowledged");
        assert_eq!(list.alarms().len(), 2, "acknowledging clears nothing");
        assert!(list.on_event(event(AlarmEvent::CLEARED, "plc", 65, 3)));
        assert_eq!(list.alarms().len(), 1);
        assert!(!list.on_event(event(AlarmEvent::CLEARED, "plc", 65, 3)));
    }
}
