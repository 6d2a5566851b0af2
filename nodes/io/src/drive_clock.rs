//! The drives on their own clock (issue 48, with `servo.drive_queue_ms` above 0): tick k is due
//! at t0 + k × period, whatever motion does. A thread that wakes late catches up by tick index,
//! stepping the simulated machine once per tick it missed, so the host's lateness never becomes
//! the machine's (a real drive's clock is not late). Each tick plays the setpoint motion queued
//! for it ([`SetpointQueue`]), or the brake tail when the queue ran dry, and reports feedback
//! stamped with the tick. Feed hold and the overrides reach the drives here, from the PLC's G
//! image and motion's control, and time-scale the queued path (D135). The drive trace, when the
//! config names a file, gets one line a tick.

use std::io::Write;

use cnc_msgs::servo::{BrakeTail, DriveControl, ServoFeedback, ServoSetpoint};
use cnc_msgs::signals::{GImage, YImage};
use cnc_runtime::clock::{monotonic_ns, sleep_until_ns};
use cnc_runtime::shm::{channel, ShmNode};
use cnc_runtime::{LaunchConfig, Shutdown};

use crate::node::{take_network_inputs, Doors};
use crate::sim::drive_queue::SetpointQueue;
use crate::sim::time_scale::HoldLatch;
use crate::sim::trace::{trace_header, trace_line};
use crate::SimLathe;

/// Setpoints and feedback a stream channel buffers: 4 s at the 4 ms period, more than any
/// queue (1 s at most) and any catch-up.
pub const STREAM_DEPTH: usize = 1024;

/// Upper bounds of the drives' wake-up lateness histogram, ms.
const LATENESS_BOUNDS_MS: [f64; 7] = [0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0];

/// The drives' own lateness (a real drive's clock would have none): how late their thread
/// woke for a tick, and how many ticks it had to catch up.
#[derive(Default)]
struct Lateness {
    wakes: u64,
    counts: [u64; LATENESS_BOUNDS_MS.len() + 1],
    max_ms: f64,
    caught_up: u64,
}

impl Lateness {
    fn record(&mut self, late_ms: f64, ticks: u64) {
        self.wakes += 1;
        let i = LATENESS_BOUNDS_MS
            .iter()
            .position(|b| late_ms < *b)
            .unwrap_or(LATENESS_BOUNDS_MS.len());
        self.counts[i] += 1;
        self.max_ms = self.max_ms.max(late_ms);
        self.caught_up += ticks.saturating_sub(1);
    }

    fn summary(&self, queue: &SetpointQueue, min_depth: Option<u32>, period_ms: f64) -> String {
        let mut s = format!(
            "drive loop: {} wakes, lateness max {:.3} ms, {} ticks caught up; underruns {} ticks \
             in {} episodes ({} without a tail); least queue depth {}",
            self.wakes,
            self.max_ms,
            self.caught_up,
            queue.underrun_ticks,
            queue.episode(),
            queue.tailless_stops,
            min_depth.map_or("-".to_string(), |d| format!(
                "{d} ticks ({:.0} ms)",
                f64::from(d) * period_ms
            )),
        );
        let mut lower = 0.0;
        for (i, n) in self.counts.iter().enumerate() {
            match LATENESS_BOUNDS_MS.get(i) {
                Some(b) => s.push_str(&format!("\n  late {lower:>4} – {b:>4} ms: {n}")),
                None => s.push_str(&format!("\n  late ≥ {lower} ms: {n}")),
            }
            lower = LATENESS_BOUNDS_MS.get(i).copied().unwrap_or(lower);
        }
        s
    }
}

/// The drive trace file, buffered; flushed every second so a killed node loses little.
struct Trace {
    out: std::io::BufWriter<std::fs::File>,
    lines: u64,
}

impl Trace {
    fn open(cfg: &LaunchConfig) -> Result<Option<Trace>, String> {
        let Some(path) = &cfg.servo.drive_trace else {
            return Ok(None);
        };
        let file = std::fs::File::create(path)
            .map_err(|e| format!("drive trace {}: {e}", path.display()))?;
        let mut out = std::io::BufWriter::new(file);
        let names: Vec<String> = cfg.machine.axes.iter().map(|a| a.name.clone()).collect();
        writeln!(out, "{}", trace_header(&names)).map_err(|e| e.to_string())?;
        log::info!("drive trace: {}", path.display());
        Ok(Some(Trace { out, lines: 0 }))
    }

    fn write(&mut self, line: &str, ticks_per_second: u64) {
        // A full disk stops the trace, not the drives.
        let _ = writeln!(self.out, "{line}");
        self.lines += 1;
        if self.lines.is_multiple_of(ticks_per_second) {
            let _ = self.out.flush();
        }
    }
}

/// Runs the drives on their own clock until shutdown.
pub fn run(
    cfg: &LaunchConfig,
    shm: &ShmNode,
    doors: Doors,
    sim: &mut SimLathe,
    shutdown: &Shutdown,
) -> Result<String, String> {
    let setpoints =
        shm.stream_receiver::<ServoSetpoint>(channel::SETPOINT_QUEUE, false, STREAM_DEPTH)?;
    let tails = shm.receiver::<BrakeTail>(channel::BRAKE_TAIL, false)?;
    let feedback =
        shm.stream_sender::<ServoFeedback>(channel::FEEDBACK_STREAM, true, STREAM_DEPTH)?;
    let g_in = shm.receiver::<GImage>(channel::G_IMAGE, false)?;
    let control = shm.receiver::<DriveControl>(channel::DRIVE_CONTROL, false)?;
    let mut g = GImage::released();
    let mut latch = HoldLatch::default();
    let period = cfg.servo.period_ms / 1000.0;
    let period_ns = (cfg.servo.period_ms * 1e6) as u64;
    let ticks_per_second = (1.0 / period).round().max(1.0) as u64;
    let n = cfg.machine.axes.len();
    let mut trace = Trace::open(cfg)?;
    let mut queue = SetpointQueue::new();
    let mut lateness = Lateness::default();
    let mut min_depth: Option<u32> = None;
    let mut y = YImage::default();
    let mut arrived = Vec::with_capacity(STREAM_DEPTH);
    // The drives' quick stop: each axis at its rated acceleration.
    let decel: Vec<f64> = cfg
        .machine
        .axes
        .iter()
        .map(|a| a.max_acceleration)
        .collect();
    queue.set_limits(&decel, period);
    // A geared tap's setpoint is reached at the end of the tick, the slide trailing it by its
    // drive's lag: computed that far ahead of the encoder.
    let lead: Vec<f64> = cfg
        .machine
        .axes
        .iter()
        .map(|a| period + a.drive_lag.max(0.0))
        .collect();
    queue.set_gear_lead(&lead);
    let mut estop = false;
    let t0 = monotonic_ns();
    let mut tick = 0u64;
    while !shutdown.requested() {
        let due = t0 + (tick + 1) * period_ns;
        sleep_until_ns(due);
        let now = monotonic_ns();
        doors.ros.refresh();
        take_network_inputs(doors.inputs, doors.robot, doors.panel, sim);
        if let Some(latest) = doors.outputs.latest()? {
            y = latest;
        }
        // Emergency stop reaches the drives here, not through motion: they ramp to a stop on
        // their own and then remove power (D134).
        let pressed = sim.emergency_stop_pressed();
        if pressed != estop {
            estop = pressed;
            queue.emergency_stop(pressed, &decel, period);
            log::warn!(
                "emergency stop {} at drive tick {tick}",
                if pressed { "pressed" } else { "released" }
            );
        }
        sim.power_drives(!(estop && queue.stopped_by_emergency_stop()));
        // The tail first: motion sends a batch's setpoints before its tail, so every setpoint
        // of the batch whose tail is read here is there to read after it.
        let tail = tails.latest()?;
        arrived.clear();
        setpoints.take_all(&mut arrived)?;
        for sp in &arrived {
            queue.push(*sp);
        }
        if let Some(t) = tail {
            queue.set_tail(&t);
        }
        if let Some(latest) = g_in.latest()? {
            g = latest;
        }
        let scaling = latch.update(&g, control.latest()?);
        queue.reset(latch.resets());
        // Every tick that is due by now, by index: a late wake-up catches up.
        let due_ticks = (now.saturating_sub(t0) / period_ns).max(tick + 1);
        lateness.record(
            now.saturating_sub(due) as f64 / 1e6,
            due_ticks.saturating_sub(tick),
        );
        while tick < due_ticks {
            tick += 1;
            let played = queue.play(&scaling);
            let mut fb = sim.step(&played.setpoint, &y, period);
            queue.read_spindle(fb.spindle_rpm, fb.spindle_angle_deg);
            let depth = queue.depth();
            fb.tick = queue.position();
            fb.queue_depth = depth;
            fb.underrun = u32::from(played.underrun);
            fb.episode = queue.episode();
            fb.dry_tick = queue.dry_tick();
            fb.episode_ended = queue.episode_ended();
            fb.emergency_stop = u32::from(estop);
            fb.held = u32::from(scaling.hold);
            fb.scale = played.scale;
            fb.setpoint = played.setpoint.position;
            fb.resets_done = queue.resets_done();
            let block_stop = queue.standing_at_block_end();
            fb.block_stop = u32::from(block_stop);
            if !played.underrun && queue.armed() {
                min_depth = Some(min_depth.map_or(depth, |d| d.min(depth)));
            }
            feedback.send(fb)?;
            if let Some(t) = &mut trace {
                let spindle = (fb.spindle_rpm, fb.spindle_angle_deg);
                let hold = match (block_stop, scaling.hold) {
                    (true, _) => 2,
                    (false, held) => u8::from(held),
                };
                let flags = (estop, hold);
                let line = trace_line(tick, &played, &fb.position[..n], depth, flags, spindle);
                t.write(&line, ticks_per_second);
            }
        }
        doors.x_out.send(sim.x_image(&y))?;
    }
    if let Some(t) = &mut trace {
        let _ = t.out.flush();
    }
    Ok(lateness.summary(&queue, min_depth, cfg.servo.period_ms))
}
