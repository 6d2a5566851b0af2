//! io node shell: steps the simulated lathe once per servo setpoint and answers with feedback.
//!
//! The simulated machine's time advances one servo period per setpoint, so it runs exactly as
//! fast as motion drives it. Emergency stop, robot signals, panel keys and faults come over the
//! machine bus, from the bridge, which took them from allowed clients on `/<ns>/sim/input`.

use std::time::Duration;

use cnc_msgs::msg::{Overrides, SimInput};
use cnc_msgs::servo::{ServoFeedback, ServoSetpoint};
use cnc_msgs::signals::{x, Bit, SignalTable, XImage, YImage};
use cnc_runtime::bus::Subscription;
use cnc_runtime::dds::RosNode;
use cnc_runtime::shm::{channel, ShmNode};
use cnc_runtime::topics;
use cnc_runtime::{LaunchConfig, Shutdown};

use crate::sim::{DeviceConfig, Encoder, SimConfig, SimLathe};

pub fn sim_config(cfg: &LaunchConfig) -> SimConfig {
    SimConfig {
        drive_lag: cfg.machine.axes.iter().map(|a| a.drive_lag).collect(),
        spindle_acceleration: cfg.sim.spindle_acceleration,
        at_speed_tolerance: cfg.sim.at_speed_tolerance,
        devices: DeviceConfig {
            turret_stations: if cfg.sim.tool_magazine {
                crate::sim::devices::MAGAZINE_POCKETS
            } else {
                cfg.sim.turret_stations
            },
            coolant_delay: cfg.sim.coolant_delay,
            ..DeviceConfig::default()
        },
        encoders: cfg
            .machine
            .axes
            .iter()
            .map(|a| {
                a.reference.map(|r| Encoder {
                    reference: a.home * a.scale(),
                    positive: r.positive,
                    grid: r.grid,
                    dog_length: r.dog_length,
                })
            })
            .collect(),
        overtravel: cfg
            .machine
            .axes
            .iter()
            .map(|a| {
                let [lo, hi] = a.overtravel_switches();
                let (lo, hi) = (lo * a.scale(), hi * a.scale());
                [lo.min(hi), lo.max(hi)]
            })
            .collect(),
        // Displayed coordinates to slide travel (a lathe's X in diameter to radius).
        probe: cfg
            .sim
            .probe
            .iter()
            .map(|t| {
                let scaled = |v: &[f64]| -> Vec<f64> {
                    v.iter()
                        .zip(&cfg.machine.axes)
                        .map(|(v, a)| v * a.scale())
                        .collect()
                };
                let (lo, hi) = (scaled(&t.min), scaled(&t.max));
                crate::sim::probe::Target {
                    min: lo.iter().zip(&hi).map(|(a, b)| a.min(*b)).collect(),
                    max: lo.iter().zip(&hi).map(|(a, b)| a.max(*b)).collect(),
                }
            })
            .collect(),
        fixed_stops: cfg
            .machine
            .axes
            .iter()
            .map(|a| {
                cfg.sim
                    .fixed_stops
                    .iter()
                    .find(|s| s.axis == a.name)
                    .map(|s| s.at * a.scale())
            })
            .collect(),
        live_tool_lag: cfg.machine.live_tool.as_ref().map_or(0.0, |t| t.drive_lag),
    }
}

/// The X bit a robot signal or panel key of [`SimInput`] sets.
fn input_bit(input: u8) -> Option<Bit> {
    Some(match input {
        SimInput::ROBOT_CLEAR => x::ROBOT_CLEAR,
        SimInput::ROBOT_CHUCK_OPEN => x::ROBOT_CHUCK_OPEN,
        SimInput::ROBOT_CHUCK_CLOSE => x::ROBOT_CHUCK_CLOSE,
        SimInput::ROBOT_DOOR_OPEN => x::ROBOT_DOOR_OPEN,
        SimInput::ROBOT_DOOR_CLOSE => x::ROBOT_DOOR_CLOSE,
        SimInput::ROBOT_CYCLE_START => x::ROBOT_CYCLE_START,
        SimInput::CYCLE_START_KEY => x::KEY_CYCLE_START,
        SimInput::RESET_KEY => x::KEY_RESET,
        SimInput::MACHINE_LOCK_KEY => x::KEY_MACHINE_LOCK,
        SimInput::AUX_LOCK_KEY => x::KEY_AUX_LOCK,
        SimInput::DRY_RUN_KEY => x::KEY_DRY_RUN,
        SimInput::BLOCK_SKIP_KEY => x::KEY_BLOCK_SKIP,
        SimInput::HANDWHEEL_SELECT_X => x::HANDWHEEL_SELECT_X,
        SimInput::HANDWHEEL_SELECT_Z => x::HANDWHEEL_SELECT_Z,
        SimInput::HANDWHEEL_X10 => x::HANDWHEEL_X10,
        SimInput::HANDWHEEL_X100 => x::HANDWHEEL_X100,
        SimInput::Z_AXIS_LOCK_KEY => x::KEY_Z_AXIS_LOCK,
        SimInput::HANDWHEEL_TRIAL_KEY => x::KEY_HANDWHEEL_TRIAL,
        SimInput::FEED_HOLD_KEY => x::KEY_FEED_HOLD,
        SimInput::JOG_PLUS_X_KEY => x::KEY_JOG_PLUS_X,
        SimInput::JOG_MINUS_X_KEY => x::KEY_JOG_MINUS_X,
        SimInput::JOG_PLUS_Z_KEY => x::KEY_JOG_PLUS_Z,
        SimInput::JOG_MINUS_Z_KEY => x::KEY_JOG_MINUS_Z,
        SimInput::SINGLE_BLOCK_KEY => x::KEY_SINGLE_BLOCK,
        _ => return None,
    })
}

/// Applies one input to the simulated machine; false if the input is unknown.
pub fn apply_input(sim: &mut SimLathe, input: &SimInput) -> bool {
    let d = &mut sim.devices;
    match input.input {
        SimInput::EMERGENCY_STOP => sim.set_emergency_stop(input.value),
        SimInput::TURRET_STUCK => d.turret_stuck = input.value,
        SimInput::AIR_LOST => d.air_lost = input.value,
        SimInput::DOOR_FORCED_OPEN => d.door_forced_open = input.value,
        SimInput::HANDWHEEL_DETENT => sim.turn_handwheel(if input.value { 1 } else { -1 }),
        other => match input_bit(other) {
            Some(bit) => d.inputs.set(bit, input.value),
            None => return false,
        },
    }
    true
}

/// Sets the override switch bytes X16–X18 (rapid as its ROV code).
pub fn set_override_switches(inputs: &mut XImage, o: &Overrides) {
    inputs.bytes[x::FEED_OVERRIDE_SWITCH as usize] = o.feed_percent;
    inputs.bytes[x::SPINDLE_OVERRIDE_SWITCH as usize] = o.spindle_percent;
    inputs.bytes[x::RAPID_OVERRIDE_SWITCH as usize] = match o.rapid_percent {
        100.. => 0,
        50..=99 => 1,
        1..=49 => 2,
        0 => 3,
    };
}

/// The inputs a robot drives (X8.0–X8.5).
pub fn is_robot_signal(input: u8) -> bool {
    matches!(
        input,
        SimInput::ROBOT_CLEAR
            | SimInput::ROBOT_CHUCK_OPEN
            | SimInput::ROBOT_CHUCK_CLOSE
            | SimInput::ROBOT_DOOR_OPEN
            | SimInput::ROBOT_DOOR_CLOSE
            | SimInput::ROBOT_CYCLE_START
    )
}

/// Runs the io node until shutdown (blocking).
/// With the drives' queue it returns their loop's statistics.
pub fn run(cfg: LaunchConfig, instance: String, shutdown: Shutdown) -> Result<String, String> {
    let mut ros = RosNode::new(&cfg.network, &cfg.machine.namespace, "io")?;
    let inputs = ros.subscription::<SimInput>(&topics::SIM_INPUT_CHECKED)?;
    let robot = ros.subscription::<SimInput>(&topics::ROBOT_SIGNALS)?;
    let panel = ros.subscription::<Overrides>(&topics::PANEL_OVERRIDES)?;
    let shm = ShmNode::new(&instance, "io")?;
    let setpoints = shm.receiver::<ServoSetpoint>(channel::SETPOINT, true)?;
    let feedback = shm.sender::<ServoFeedback>(channel::FEEDBACK, true)?;
    let outputs = shm.receiver::<YImage>(channel::Y_IMAGE, false)?;
    let x_out = shm.sender::<XImage>(channel::X_IMAGE, false)?;
    let period = cfg.servo.period_ms / 1000.0;
    let mut sim = SimLathe::new(sim_config(&cfg), &cfg.power_on_slide());
    let mut y = YImage::default();
    // Report the power-on position before motion starts.
    let idle = ServoSetpoint::default();
    feedback.send(sim.step(&idle, &y, 0.0))?;
    // The drives answer the servo loop every tick: real time too, just below it, once the
    // DDS participant's threads (which must not inherit it) exist.
    let rt = &cfg.realtime;
    cnc_runtime::realtime::enter(
        "io drive loop",
        rt.io_priority,
        rt.servo_cpu,
        rt.lock_memory,
    );
    if cfg.servo.drive_queue_ms > 0.0 {
        let doors = Doors {
            ros: &mut ros,
            inputs: &inputs,
            robot: &robot,
            panel: &panel,
            outputs: &outputs,
            x_out: &x_out,
        };
        return crate::drive_clock::run(&cfg, &shm, doors, &mut sim, &shutdown);
    }
    while !shutdown.requested() {
        ros.refresh();
        take_network_inputs(&inputs, &robot, &panel, &mut sim);
        if let Some(latest) = outputs.latest()? {
            y = latest;
        }
        match setpoints.wait(Duration::from_millis(50))? {
            Some(sp) => {
                let fb = sim.step(&sp, &y, period);
                feedback.send(fb)?;
            }
            // No setpoint for 50 ms (no motion node): the drives are off and stay where they
            // are (`enable` 0); the spindle and devices go on in real time. The drives still
            // report where they are: a motion node that starts (or subscribes) after the
            // power-on report learns the position from the next one.
            None => {
                let fb = sim.step(&idle, &y, 0.05);
                feedback.send(fb)?;
            }
        }
        x_out.send(sim.x_image(&y))?;
    }
    Ok(String::new())
}

/// What reaches the drives besides setpoints: the network's inputs and the PLC's images.
pub struct Doors<'a> {
    pub ros: &'a mut RosNode,
    pub inputs: &'a Subscription<SimInput>,
    pub robot: &'a Subscription<SimInput>,
    pub panel: &'a Subscription<Overrides>,
    pub outputs: &'a cnc_runtime::shm::Receiver<YImage>,
    pub x_out: &'a cnc_runtime::shm::Sender<XImage>,
}

/// The simulated inputs, the panel's override switches and the robot's signals that came
/// over the network since the last call.
pub fn take_network_inputs(
    inputs: &Subscription<SimInput>,
    robot: &Subscription<SimInput>,
    panel: &Subscription<Overrides>,
    sim: &mut SimLathe,
) {
    while let Ok(Some(input)) = inputs.take() {
        if apply_input(sim, &input) {
            log::info!("simulated input {} = {}", input.input, input.value);
        } else {
            log::warn!("unknown simulated input {} ignored", input.input);
        }
    }
    // The panel's override switches set over the network (hmi_bridge checks the values).
    while let Ok(Some(o)) = panel.take() {
        // Only the switch positions reach the PLC, whoever sent the message.
        match cnc_runtime::overrides::check(&o) {
            Ok(o) => set_override_switches(&mut sim.devices.inputs, &o),
            Err(why) => log::error!("io: panel overrides refused: {why}"),
        }
    }
    // The robot interface block (X8) set over the network: robot signals only.
    while let Ok(Some(input)) = robot.take() {
        if is_robot_signal(input.input) {
            apply_input(sim, &input);
        } else {
            log::warn!(
                "robot signal {} is not a robot signal: ignored",
                input.input
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The panel's keys and the handwheel's switches from `sim/input` reach the PLC's X image;
    /// a detent turns the wheel's counter four counts either way; an unknown input is refused.
    #[test]
    fn the_simulated_panel_and_handwheel_inputs_reach_the_machine() {
        let text = include_str!("../../../launch_configs/sim_lathe.yaml");
        let cfg = LaunchConfig::from_yaml(text).expect("sim_lathe.yaml");
        let mut sim = SimLathe::new(sim_config(&cfg), &cfg.power_on_slide());
        let input = |input, value| SimInput { input, value };
        for (key, bit) in [
            (SimInput::HANDWHEEL_SELECT_X, x::HANDWHEEL_SELECT_X),
            (SimInput::HANDWHEEL_SELECT_Z, x::HANDWHEEL_SELECT_Z),
            (SimInput::HANDWHEEL_X10, x::HANDWHEEL_X10),
            (SimInput::HANDWHEEL_X100, x::HANDWHEEL_X100),
            (SimInput::Z_AXIS_LOCK_KEY, x::KEY_Z_AXIS_LOCK),
            (SimInput::HANDWHEEL_TRIAL_KEY, x::KEY_HANDWHEEL_TRIAL),
            (SimInput::FEED_HOLD_KEY, x::KEY_FEED_HOLD),
            (SimInput::JOG_PLUS_X_KEY, x::KEY_JOG_PLUS_X),
            (SimInput::JOG_MINUS_Z_KEY, x::KEY_JOG_MINUS_Z),
            (SimInput::SINGLE_BLOCK_KEY, x::KEY_SINGLE_BLOCK),
        ] {
            assert!(apply_input(&mut sim, &input(key, true)));
            let y = YImage::default();
            assert!(sim.x_image(&y).get(bit), "input {key}");
            assert!(apply_input(&mut sim, &input(key, false)));
            assert!(!sim.x_image(&y).get(bit), "input {key} released");
        }
        let count = |sim: &mut SimLathe| {
            sim.step(&ServoSetpoint::default(), &YImage::default(), 0.0)
                .handwheel_count
        };
        let before = count(&mut sim);
        apply_input(&mut sim, &input(SimInput::HANDWHEEL_DETENT, true));
        apply_input(&mut sim, &input(SimInput::HANDWHEEL_DETENT, true));
        apply_input(&mut sim, &input(SimInput::HANDWHEEL_DETENT, false));
        assert_eq!(count(&mut sim) - before, 4);
        assert!(!apply_input(&mut sim, &input(200, true)));
    }
}
