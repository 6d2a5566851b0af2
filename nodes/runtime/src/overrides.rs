//! Override switch positions: the steps of the standard PLC (`000` §7.3). The bridge checks
//! a client's request with them, and the io node checks again what reaches the switch bytes,
//! so no other value gets to the PLC whatever the message's path (issue 26).

use cnc_msgs::msg::Overrides;

/// Feed and spindle override steps of the standard PLC, percent.
pub const STEPS: [u8; 16] = [
    0, 10, 15, 20, 25, 30, 35, 40, 50, 60, 70, 80, 90, 100, 125, 150,
];
/// Rapid override positions, percent (0 is F0).
pub const RAPID: [u8; 4] = [0, 25, 50, 100];

/// The switch positions, or which value is out of range and what is allowed.
pub fn check(r: &Overrides) -> Result<Overrides, String> {
    let steps = || {
        STEPS
            .iter()
            .map(|s| s.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    if !STEPS.contains(&r.feed_percent) {
        return Err(format!(
            "feed override {} %: one of {} %",
            r.feed_percent,
            steps()
        ));
    }
    if !STEPS.contains(&r.spindle_percent) {
        return Err(format!(
            "spindle override {} %: one of {} %",
            r.spindle_percent,
            steps()
        ));
    }
    if !RAPID.contains(&r.rapid_percent) {
        return Err(format!(
            "rapid override {} %: one of 0 (F0), 25, 50, 100 %",
            r.rapid_percent
        ));
    }
    Ok(Overrides {
        feed_percent: r.feed_percent,
        spindle_percent: r.spindle_percent,
        rapid_percent: r.rapid_percent,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn req(feed: u8, spindle: u8, rapid: u8) -> Overrides {
        Overrides {
            feed_percent: feed,
            spindle_percent: spindle,
            rapid_percent: rapid,
        }
    }

    #[test]
    fn only_the_switch_steps_are_taken() {
        assert!(check(&req(100, 100, 100)).is_ok());
        assert!(check(&req(0, 150, 0)).is_ok());
        assert!(check(&req(151, 100, 100))
            .unwrap_err()
            .contains("feed override 151 %"));
        assert!(check(&req(45, 100, 100)).is_err());
        assert!(check(&req(100, 200, 100)).unwrap_err().contains("spindle"));
        assert!(check(&req(100, 100, 75))
            .unwrap_err()
            .contains("rapid override 75 %"));
    }
}
