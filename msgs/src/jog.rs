//! A jog request's values (`TaskRequest::Jog`): the bridge takes them from a client, the task
//! checks the mode and passes the jog on to motion, which moves the axis. Every value is
//! checked here once: it may come from any client.

/// The feed of a jog that names none, mm/min.
pub const DEFAULT_JOG_FEED: f64 = 1000.0;
/// The largest increment one request may ask for, mm.
pub const MAX_INCREMENT: f64 = 1000.0;

#[derive(Debug, Clone, PartialEq)]
pub struct Jog {
    /// The axis letter.
    pub axis: String,
    /// +1, -1, or 0 (stop).
    pub direction: i8,
    /// mm/min, positive.
    pub feed: f64,
    /// mm, 0 for a continuous jog.
    pub increment: f64,
}

impl Jog {
    /// A request's values, checked; `feed` 0 is [`DEFAULT_JOG_FEED`].
    pub fn new(axis: &str, direction: i8, feed: f64, increment: f64) -> Result<Jog, String> {
        let axis = axis.trim().to_ascii_uppercase();
        if axis.len() != 1 || !axis.chars().all(|c| c.is_ascii_uppercase()) {
            return Err(format!("jog: axis {axis:?} is not an axis letter"));
        }
        if !(-1..=1).contains(&direction) {
            return Err(format!("jog: direction {direction}: +1, -1 or 0"));
        }
        let feed = if feed == 0.0 { DEFAULT_JOG_FEED } else { feed };
        if !(feed.is_finite() && feed > 0.0 && feed <= 100_000.0) {
            return Err(format!("jog: feed {feed}: 0–100000 mm/min"));
        }
        if !(increment.is_finite() && (0.0..=MAX_INCREMENT).contains(&increment)) {
            return Err(format!("jog: increment {increment}: 0–{MAX_INCREMENT} mm"));
        }
        Ok(Jog {
            axis,
            direction,
            feed,
            increment,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_jog_values_are_refused() {
        let j = Jog::new("x", 1, 0.0, 0.0).unwrap();
        assert_eq!((j.axis.as_str(), j.direction, j.feed), ("X", 1, 1000.0));
        for (axis, direction, feed, increment) in [
            ("", 1, 600.0, 0.0),
            ("XY", 1, 600.0, 0.0),
            ("X", 2, 600.0, 0.0),
            ("X", 1, f64::NAN, 0.0),
            ("X", 1, 600.0, -1.0),
            ("X", 1, 1e9, 0.0),
            ("X", 1, 600.0, 2000.0),
            ("X", 1, f64::INFINITY, 0.0),
        ] {
            assert!(
                Jog::new(axis, direction, feed, increment).is_err(),
                "{axis} {direction} {feed} {increment}"
            );
        }
    }
}
