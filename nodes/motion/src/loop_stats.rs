//! Servo loop statistics: tick interval and iceoryx2 round trip, kept as fixed histograms so
//! the loop allocates nothing after start-up.

/// 1 µs bins up to 100 ms; slower values land in the last bin (the maximum is kept exactly).
const BINS: usize = 100_000;

pub struct Histogram {
    bins: Vec<u32>,
    count: u64,
    min_us: f64,
    max_us: f64,
}

impl Default for Histogram {
    fn default() -> Self {
        Histogram {
            bins: vec![0; BINS],
            count: 0,
            min_us: f64::INFINITY,
            max_us: 0.0,
        }
    }
}

impl Histogram {
    pub fn record(&mut self, us: f64) {
        if !us.is_finite() || us < 0.0 {
            return;
        }
        let bin = (us as usize).min(BINS - 1);
        self.bins[bin] += 1;
        self.count += 1;
        self.min_us = self.min_us.min(us);
        self.max_us = self.max_us.max(us);
    }

    pub fn count(&self) -> u64 {
        self.count
    }

    /// Value below which `q` (0..1) of the samples lie, to 1 µs.
    pub fn quantile(&self, q: f64) -> f64 {
        if self.count == 0 {
            return 0.0;
        }
        let target = ((self.count as f64) * q).ceil().max(1.0) as u64;
        let mut seen = 0;
        for (i, &n) in self.bins.iter().enumerate() {
            seen += n as u64;
            if seen >= target {
                return (i as f64 + 0.5).clamp(self.min_us, self.max_us);
            }
        }
        self.max_us
    }

    /// Samples in `lo_us..hi_us` (1 µs resolution; the last bin holds everything slower).
    pub fn count_between(&self, lo_us: f64, hi_us: f64) -> u64 {
        let lo = (lo_us.max(0.0) as usize).min(BINS);
        let hi = (hi_us.max(0.0) as usize).min(BINS);
        self.bins[lo..hi.max(lo)].iter().map(|&c| c as u64).sum()
    }

    pub fn min(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            self.min_us
        }
    }
    pub fn max(&self) -> f64 {
        self.max_us
    }
}

use cnc_msgs::msg::ServoStats;

#[derive(Default)]
pub struct ServoStatistics {
    pub interval: Histogram,
    pub round_trip: Histogram,
    pub ticks: u64,
    pub late_ticks: u64,
    /// Whether the servo thread got `SCHED_FIFO`.
    pub realtime: bool,
    /// The worst of each phase, µs: waking after the deadline, interpolation, exchange.
    pub phase_max_us: [f64; 3],
}

/// The phases of a servo tick, in [`ServoStatistics::phase_max_us`] order.
pub const PHASES: [&str; 3] = ["wake", "interpolation", "exchange"];

impl ServoStatistics {
    /// Records one tick's phases, µs.
    pub fn phases(&mut self, wake_late: f64, interpolation: f64, exchange: f64) {
        for (m, v) in self
            .phase_max_us
            .iter_mut()
            .zip([wake_late, interpolation, exchange])
        {
            *m = m.max(v);
        }
    }

    /// The phase whose worst took the most time.
    pub fn worst_phase(&self) -> &'static str {
        let mut worst = 0;
        for (i, v) in self.phase_max_us.iter().enumerate() {
            if *v > self.phase_max_us[worst] {
                worst = i;
            }
        }
        PHASES[worst]
    }
}

/// What the lateness watch says about a tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Lateness {
    OnTime,
    /// The interval before this tick exceeded the warning limit (µs): a warning alarm.
    Warning(f64),
    /// No tick over the limit for the clearing time: the warning goes.
    Clear,
    /// Too many late ticks within the window: the servo alarm, and the machine stops.
    Overrun(usize),
}

/// Watches the tick intervals (pure: the shell passes them in). A tick is late when it comes
/// more than half a period after its deadline; `alarm_ticks` late ticks within `window` ticks
/// is an overrun. An interval over `warning_ns` is a warning, cleared after `clear_ticks`
/// ticks without one.
pub struct LateWatch {
    warning_ns: u64,
    alarm_ticks: usize,
    window: u64,
    clear_ticks: u64,
    /// Tick numbers of the late ticks within the window (capacity `alarm_ticks`).
    recent: std::collections::VecDeque<u64>,
    warned_at: Option<u64>,
    overrun: bool,
}

impl LateWatch {
    pub fn new(warning_ns: u64, alarm_ticks: usize, window: u64, clear_ticks: u64) -> LateWatch {
        LateWatch {
            warning_ns,
            alarm_ticks: alarm_ticks.max(1),
            window,
            clear_ticks,
            // No more late ticks than ticks fit in the window.
            recent: std::collections::VecDeque::with_capacity(
                alarm_ticks.max(1).min(window.max(1) as usize),
            ),
            warned_at: None,
            overrun: false,
        }
    }

    /// Tick number `tick`, `interval_ns` after the last, `late` when past its deadline by
    /// more than half a period.
    pub fn tick(&mut self, tick: u64, interval_ns: u64, late: bool) -> Lateness {
        while self
            .recent
            .front()
            .is_some_and(|t| tick.saturating_sub(*t) >= self.window)
        {
            self.recent.pop_front();
        }
        if late && !self.overrun {
            self.recent.push_back(tick);
            if self.recent.len() >= self.alarm_ticks {
                // Once per reset: the alarm stops the machine; counting again starts after.
                self.overrun = true;
                return Lateness::Overrun(self.recent.len());
            }
        }
        if interval_ns > self.warning_ns {
            // Raised once; later long intervals keep it up.
            let first = self.warned_at.is_none();
            self.warned_at = Some(tick);
            return match first {
                true => Lateness::Warning(interval_ns as f64 / 1000.0),
                false => Lateness::OnTime,
            };
        }
        match self.warned_at {
            Some(t) if tick.saturating_sub(t) >= self.clear_ticks => {
                self.warned_at = None;
                Lateness::Clear
            }
            _ => Lateness::OnTime,
        }
    }

    /// After a reset the overrun may be raised again.
    pub fn reset(&mut self) {
        self.overrun = false;
        self.recent.clear();
    }
}

impl ServoStatistics {
    /// The statistics as published on `servo_stats`.
    pub fn message(&self, period: f64) -> ServoStats {
        ServoStats {
            stamp: cnc_runtime::dds::stamp(),
            period_us: period * 1e6,
            ticks: self.ticks,
            late_ticks: self.late_ticks,
            interval_min_us: self.interval.min(),
            interval_p50_us: self.interval.quantile(0.5),
            interval_p99_us: self.interval.quantile(0.99),
            interval_max_us: self.interval.max(),
            round_trips: self.round_trip.count(),
            round_trip_min_us: self.round_trip.min(),
            round_trip_p50_us: self.round_trip.quantile(0.5),
            round_trip_p99_us: self.round_trip.quantile(0.99),
            round_trip_max_us: self.round_trip.max(),
            realtime: self.realtime,
            wake_late_max_us: self.phase_max_us[0],
            interpolation_max_us: self.phase_max_us[1],
            exchange_max_us: self.phase_max_us[2],
            worst_phase: self.worst_phase().into(),
        }
    }

    /// The tick intervals as a histogram around the period, one line per bucket: what the
    /// loop's timing looked like, late ticks included.
    pub fn interval_histogram(&self, period_us: f64) -> String {
        const EDGES: [f64; 12] = [
            0.0, 0.875, 0.975, 0.9975, 1.0025, 1.025, 1.125, 1.25, 1.5, 2.0, 3.0, 5.0,
        ];
        let total = self.interval.count().max(1) as f64;
        let mut out = String::from("tick interval histogram (us: ticks, share):\n");
        for (k, lo) in EDGES.iter().enumerate() {
            let lo_us = lo * period_us;
            let hi_us = EDGES.get(k + 1).map_or(f64::INFINITY, |h| h * period_us);
            let n = self.interval.count_between(lo_us, hi_us.min(BINS as f64));
            let label = if hi_us.is_finite() {
                format!("{lo_us:>7.0} - {hi_us:<7.0}")
            } else {
                format!("{lo_us:>7.0} and up  ")
            };
            out += &format!("  {label} {n:>10} {:>8.4} %\n", n as f64 / total * 100.0);
        }
        out
    }

    pub fn summary(&self, period_us: f64) -> String {
        format!(
            "servo loop ({}): {} ticks of {:.0} us, {} late; interval us min/p50/p99/max {:.0}/{:.0}/{:.0}/{:.0}; iceoryx2 round trip us min/p50/p99/max {:.1}/{:.0}/{:.0}/{:.0} ({} samples); worst phase us wake/interpolation/exchange {:.0}/{:.0}/{:.0} ({})",
            if self.realtime { "SCHED_FIFO" } else { "ordinary thread" },
            self.ticks,
            period_us,
            self.late_ticks,
            self.interval.min(),
            self.interval.quantile(0.5),
            self.interval.quantile(0.99),
            self.interval.max(),
            self.round_trip.min(),
            self.round_trip.quantile(0.5),
            self.round_trip.quantile(0.99),
            self.round_trip.max(),
            self.round_trip.count(),
            self.phase_max_us[0],
            self.phase_max_us[1],
            self.phase_max_us[2],
            self.worst_phase()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_interval_warns_and_repeated_lateness_is_an_overrun() {
        // 4 ms ticks: warn above 12 ms, overrun at 3 late ticks within 250, clear after 10.
        let mut w = LateWatch::new(12_000_000, 3, 250, 10);
        assert_eq!(w.tick(1, 4_000_000, false), Lateness::OnTime);
        assert_eq!(w.tick(2, 13_000_000, true), Lateness::Warning(13_000.0));
        // Another long interval keeps the warning up without raising it again.
        assert_eq!(w.tick(3, 14_000_000, true), Lateness::OnTime);
        for t in 4..13 {
            assert_eq!(w.tick(t, 4_000_000, false), Lateness::OnTime, "tick {t}");
        }
        assert_eq!(w.tick(13, 4_000_000, false), Lateness::Clear);
        assert_eq!(w.tick(14, 4_000_000, false), Lateness::OnTime);
        // Late ticks far apart never add up; close together they do.
        assert_eq!(w.tick(400, 7_000_000, true), Lateness::OnTime);
        assert_eq!(w.tick(500, 7_000_000, true), Lateness::OnTime);
        assert_eq!(w.tick(800, 7_000_000, true), Lateness::OnTime);
        assert_eq!(w.tick(801, 7_000_000, true), Lateness::OnTime);
        assert_eq!(w.tick(802, 7_000_000, true), Lateness::Overrun(3));
        // Raised once until reset.
        assert_eq!(w.tick(803, 7_000_000, true), Lateness::OnTime);
        w.reset();
        assert_eq!(w.tick(804, 7_000_000, true), Lateness::OnTime);
    }

    #[test]
    fn the_histogram_counts_every_interval_once() {
        let mut s = ServoStatistics::default();
        for us in [4000.0, 4001.0, 3990.0, 4300.0, 9000.0, 30000.0] {
            s.interval.record(us);
        }
        let text = s.interval_histogram(4000.0);
        let counts: Vec<u64> = text
            .lines()
            .skip(1)
            .map(|l| l.split_whitespace().rev().nth(2).unwrap().parse().unwrap())
            .collect();
        assert_eq!(counts.iter().sum::<u64>(), 6, "{text}");
        // 3990 and 4000 and 4001 lie within ±0.25 %: bucket 3 (3990..4010).
        assert_eq!(counts[3], 3, "{text}");
        assert_eq!(counts[11], 1, "{text}"); // 30 ms: 5 periods and up
    }

    #[test]
    fn quantiles_of_a_known_distribution() {
        let mut h = Histogram::default();
        for i in 1..=1000 {
            h.record(i as f64);
        }
        assert_eq!(h.min(), 1.0);
        assert_eq!(h.max(), 1000.0);
        assert!((h.quantile(0.5) - 500.5).abs() <= 1.0);
        assert!((h.quantile(0.99) - 990.5).abs() <= 1.0);
        h.record(1e9);
        assert_eq!(h.max(), 1e9);
    }
}
