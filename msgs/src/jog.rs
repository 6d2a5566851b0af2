//! A jog request in the text form it takes through the cell (`ProgramCommand::JOG`): the
//! bridge writes it, the interpreter checks the mode and passes it on, motion moves the axis.
//! Every value is checked here once: it may come from any client.

/// The feed of a jog that names none, mm/min.
pub const DEFAULT_JOG_FEED: f64 = 1000.0;
/// The largest increment one request may ask for, mm.
pub const MAX_INCREMENT: f64 = 1000.0;

#[derive(Debug, Clone, PartialEq)]
pub struct JogText {
    /// The axis letter.
    pub axis: String,
    /// +1, -1, or 0 (stop).
    pub direction: i8,
    /// mm/min, positive.
    pub feed: f64,
    /// mm, 0 for a continuous jog.
    pub increment: f64,
}

impl JogText {
    /// A request's values, checked; `feed` 0 is [`DEFAULT_JOG_FEED`].
    pub fn new(axis: &str, direction: i8, feed: f64, increment: f64) -> Result<JogText, String> {
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
        Ok(JogText {
            axis,
            direction,
            feed,
            increment,
        })
    }

    pub fn to_text(&self) -> String {
        let sign = match self.direction {
            1 => "+",
            -1 => "-",
            _ => "0",
        };
        format!("{} {sign} {} {}", self.axis, self.feed, self.increment)
    }

    pub fn parse(text: &str) -> Result<JogText, String> {
        let words: Vec<&str> = text.split_whitespace().collect();
        let [axis, sign, feed, increment] = words[..] else {
            return Err(format!("jog {text:?}: `<axis> <+|-|0> <feed> <increment>`"));
        };
        let direction = match sign {
            "+" => 1,
            "-" => -1,
            "0" => 0,
            _ => return Err(format!("jog {text:?}: direction + - or 0")),
        };
        let number = |w: &str| {
            w.parse::<f64>()
                .map_err(|_| format!("jog {text:?}: {w:?} is not a number"))
        };
        JogText::new(axis, direction, number(feed)?, number(increment)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_jog_reads_back_and_bad_values_are_refused() {
        let j = JogText::new("x", 1, 0.0, 0.0).unwrap();
        assert_eq!(j.to_text(), "X + 1000 0");
        assert_eq!(JogText::parse(&j.to_text()), Ok(j));
        assert_eq!(JogText::parse("Z - 600 0.1").unwrap().increment, 0.1);
        for bad in [
            "",
            "X + 600",
            "XY + 600 0",
            "X * 600 0",
            "X + nan 0",
            "X + 600 -1",
            "X + 1e9 0",
            "X + 600 2000",
            "X + inf 0",
        ] {
            assert!(JogText::parse(bad).is_err(), "{bad}");
        }
        assert!(JogText::new("X", 2, 100.0, 0.0).is_err());
    }
}
