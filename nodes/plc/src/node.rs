//! plc node shell: scans the logic every `plc.scan_ms` over the F/G and X/Y images (iceoryx2)
//! and publishes spindle, part count and PLC alarms on DDS.

use cnc_msgs::msg::{Alarm, PartCount, SpindleState};
use cnc_msgs::signals::{FImage, GImage, XImage, YImage};
use cnc_runtime::alarms::AlarmReporter;
use cnc_runtime::clock::{monotonic_ns, sleep_until_ns};
use cnc_runtime::dds::{qos, stamp, RosNode};
use cnc_runtime::shm::{channel, ShmNode};
use cnc_runtime::{LaunchConfig, Shutdown};

use crate::logic::{Plc, PlcEvent};

pub fn run(cfg: LaunchConfig, instance: String, shutdown: Shutdown) -> Result<(), String> {
    let mut ros = RosNode::new(&cfg.network, &cfg.machine.namespace, "plc")?;
    let spindle_pub =
        ros.publisher::<SpindleState>("spindle", "cnc_msgs/msg/SpindleState", qos::state())?;
    let parts_pub =
        ros.publisher::<PartCount>("part_count", "cnc_msgs/msg/PartCount", qos::state())?;
    let alarms = AlarmReporter::new(&mut ros, "plc")?;
    let shm = ShmNode::new(&instance, "plc")?;
    let f_in = shm.receiver::<FImage>(channel::F_IMAGE, false)?;
    let x_in = shm.receiver::<XImage>(channel::X_IMAGE, false)?;
    let g_out = shm.sender::<GImage>(channel::G_IMAGE, false)?;
    let y_out = shm.sender::<YImage>(channel::Y_IMAGE, false)?;
    let mut plc = Plc::new(0);
    let (mut f, mut x) = (FImage::default(), XImage::default());
    let period = (cfg.plc.scan_ms * 1e6) as u64;
    let t0 = monotonic_ns();
    let mut next = t0;
    let mut scans = 0u64;
    let mut last_cycle_time = 0.0;
    let publish_parts = |count: u32, last: f64| {
        let _ = parts_pub.publish(PartCount {
            stamp: stamp(),
            count,
            target: 0,
            last_cycle_time: last,
        });
    };
    publish_parts(0, 0.0);
    let mut last_spindle: Option<(f64, u32, bool, i64)> = None;
    while !shutdown.requested() {
        next += period;
        sleep_until_ns(next);
        if monotonic_ns() > next + 10 * period {
            next = monotonic_ns();
        }
        if let Some(v) = f_in.latest()? {
            f = v;
        }
        if let Some(v) = x_in.latest()? {
            x = v;
        }
        plc.scan(&f, &x, (monotonic_ns() - t0) as f64 * 1e-9);
        g_out.send(*plc.to_nc())?;
        y_out.send(*plc.outputs())?;
        for e in plc.take_events() {
            match e {
                PlcEvent::AlarmRaised { number, text } => {
                    alarms.raise(alarms.alarm(number, Alarm::SEVERITY_FATAL, &text, "", 0))
                }
                PlcEvent::AlarmCleared { number } => alarms.clear(number),
                PlcEvent::PartCounted { count, cycle_time } => {
                    last_cycle_time = cycle_time;
                    publish_parts(count, cycle_time);
                }
            }
        }
        scans += 1;
        // Spindle state on change (to the rpm) and at least every 100 ms.
        let y = plc.outputs();
        let key = (
            plc.commanded_rpm(),
            y.spindle_direction,
            x.spindle_at_speed != 0,
            x.spindle_actual_rpm.round() as i64,
        );
        if last_spindle != Some(key) || scans.is_multiple_of(10) {
            last_spindle = Some(key);
            let direction = match y.spindle_direction {
                1 => SpindleState::DIRECTION_CW,
                2 => SpindleState::DIRECTION_CCW,
                _ => SpindleState::DIRECTION_STOP,
            };
            let _ = spindle_pub.publish(SpindleState {
                stamp: stamp(),
                commanded_rpm: plc.commanded_rpm(),
                actual_rpm: x.spindle_actual_rpm.abs(),
                direction,
                // The simulated spindle models no cutting load yet.
                load: 0.0,
                override_percent: 100.0,
                at_speed: x.spindle_at_speed != 0 && direction != SpindleState::DIRECTION_STOP,
            });
        }
        if scans.is_multiple_of(500) {
            publish_parts(plc.part_count(), last_cycle_time);
        }
    }
    Ok(())
}
