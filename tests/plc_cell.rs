//! The standard PLC program end to end in simulation: the interpreter, motion, the ladder PLC
//! and the simulated lathe with its devices, each core as the cell runs it, stepped together on
//! one simulated clock (servo 4 ms, PLC scan 10 ms). Deterministic and fast; the same cores run
//! in the nodes over DDS and iceoryx2 (`cell_end_to_end.rs`).

#[path = "rig/mod.rs"]
mod rig;

use cnc_motion::RunState;
use cnc_msgs::msg::MachineState;
use cnc_msgs::signals::{f, g, x, y, SignalTable};
use cnc_plc::memory::Retained;
use cnc_plc::{PlcEvent, Value};
use rig::*;
#[test]
fn t0303_turns_the_short_way_locks_fins_and_the_program_goes_on() {
    // From tool 1: T0303 is 2 stations forward (CW); then T0808 from 3 is 3 back (CCW), not
    // 5 forward.
    let mut r = powered("O0001\nT0303\nG00 X150 Z50\nT0808\nG00 X160\nM30\n");
    assert_eq!(r.turret_station(), Some(1));
    let mut outputs = vec![];
    let mut stations = vec![1u8];
    let mut fin_at = None;
    let ok = r.run_until(20.0, |r| {
        if r.yi.get(y::TURRET_CW) || r.yi.get(y::TURRET_CCW) {
            let o = (r.yi.get(y::TURRET_CW), r.yi.get(y::TURRET_CCW));
            if outputs.last() != Some(&o) {
                outputs.push(o);
            }
        }
        if let Some(s) = r.turret_station() {
            if stations.last() != Some(&s) {
                stations.push(s);
            }
        }
        if r.nc().get(f::TF) && r.gi.get(g::FIN) && fin_at.is_none() {
            fin_at = Some((r.t, r.xi.get(x::TURRET_LOCKED), r.turret_station()));
        }
        r.program_done()
    });
    assert!(ok, "program did not finish; events {:?}", r.events);
    assert_eq!(
        outputs,
        [(true, false), (false, true)],
        "CW for T0303, CCW for T0808"
    );
    assert_eq!(stations, [1, 2, 3, 2, 1, 8]);
    let (_, locked, station) = fin_at.expect("FIN for the T code");
    assert!(locked, "FIN only once the turret is locked");
    assert_eq!(station, Some(3));
    assert_eq!(r.gi.bytes[g::NTOL as usize], 8, "current tool for the NC");
    let pos = r.motion.commanded_display();
    assert!(
        (pos[0] - 160.0).abs() < 1e-9 && (pos[1] - 50.0).abs() < 1e-9,
        "{pos:?}"
    );
    assert!(r.message("A0.1").is_none() && r.message("A0.3").is_none());
}

#[test]
fn a_stuck_turret_raises_a0_1_after_the_timer_and_the_program_stops() {
    let mut r = powered("O0001\nT0303\nG00 X150 Z50\nM30\n");
    r.sim.devices.turret_stuck = true;
    let mut strobe_at = None;
    r.run_until(8.0, |r| {
        if r.nc().get(f::TF) && strobe_at.is_none() {
            strobe_at = Some(r.t);
        }
        r.message("A0.1").is_some()
    });
    let strobe = strobe_at.expect("TF strobe");
    let alarm = r.message("A0.1").expect("A0.1 raised");
    let preset = match r.plc.read("T1").unwrap() {
        Value::Timer { preset_ms, .. } => preset_ms as f64 / 1000.0,
        v => panic!("{v:?}"),
    };
    assert!(
        alarm - strobe >= preset && alarm - strobe <= preset + 0.05,
        "A0.1 {:.3} s after the strobe, preset {preset} s",
        alarm - strobe
    );
    // The program stops: no FIN, feed hold, the axes stay where they were.
    let before = r.motion.commanded_display();
    r.run_until(3.0, |_| false);
    assert!(!r.gi.get(g::FIN));
    assert!(!r.gi.get(g::SP_N), "feed hold");
    assert!(r.nc().get(f::TF), "still waiting on the T code");
    assert_eq!(r.motion.commanded_display(), before);
    assert!(
        !r.yi.get(y::TURRET_CW) && !r.yi.get(y::TURRET_CCW),
        "motor off"
    );
    assert!(r.yi.get(y::LAMP_RED));
}

#[test]
fn m03_s1200_fins_only_once_the_spindle_is_at_speed() {
    let mut r = powered("O0001\nG97 S1200 M03\nG01 W-1 F100\nM30\n");
    let mut first_move = None;
    let mut fin_rpm = None;
    let z0 = r.motion.commanded_display()[1];
    r.run_until(5.0, |r| {
        let m03 = r.nc().get(f::MF) && r.nc().read_i32(f::M_CODE) == 3;
        if m03 && r.gi.get(g::FIN) && fin_rpm.is_none() {
            fin_rpm = Some(r.sim.spindle_rpm());
        }
        if r.motion.commanded_display()[1] != z0 && first_move.is_none() {
            first_move = Some(r.sim.spindle_rpm());
        }
        r.program_done()
    });
    let rpm = fin_rpm.expect("FIN for M03");
    assert!(rpm >= 1200.0 * 0.98, "FIN at {rpm} rpm");
    assert!(first_move.expect("moved") >= 1200.0 * 0.98);
}

#[test]
fn opening_the_door_during_a_cycle_stops_it_with_the_door_alarm() {
    let mut r = powered("O0001\nS500 M03\nG01 W-40 F300\nM30\n");
    r.run_until(2.0, |r| r.motion.active_cutting() == Some(true));
    r.run_until(0.5, |_| false);
    r.sim.devices.door_forced_open = true;
    let opened = r.t;
    assert!(
        r.run_until(0.1, |r| r.message("A3.0").is_some()),
        "door alarm"
    );
    assert!(
        r.message("A3.0").unwrap() - opened <= 0.03,
        "within a scan or two"
    );
    r.run_until(0.5, |_| false);
    assert_eq!(r.motion.state(), RunState::Hold);
    let held = r.motion.commanded_display();
    assert!(!r.yi.get(y::SPINDLE_CW), "spindle off");
    // Closing the door again does not restart the cycle: the alarm holds until reset.
    r.sim.devices.door_forced_open = false;
    r.run_until(2.0, |_| false);
    assert_eq!(r.motion.commanded_display(), held);
    assert!(!r.gi.get(g::SP_N));
}

#[test]
fn emergency_stop_turns_every_output_off_within_one_scan() {
    let mut r = powered("O0001\nS800 M03\nM08\nG01 W-40 F300\nM30\n");
    r.run_until(3.0, |r| r.motion.active_cutting() == Some(true));
    assert!(r.yi.get(y::SPINDLE_CW) && r.yi.get(y::COOLANT));
    r.sim.set_emergency_stop(true);
    let scans = r.plc.scans();
    r.run_until(0.1, |r| r.plc.scans() > scans);
    assert!(!r.xi.get(x::ESP_N), "the scan read the pressed button");
    assert_eq!(r.yi.bytes, [0; 20], "every output off in that scan");
    assert_eq!(r.yi.spindle_rpm, 0.0);
    assert!(!r.gi.get(g::ESP_N));
    r.tick();
    assert_eq!(r.motion.state(), RunState::Alarm);
    assert!(r
        .events
        .iter()
        .any(|(_, e)| *e == PlcEvent::EmergencyStop(true)));
    // Released: the spindle and coolant stay off (their latches were reset).
    r.sim.set_emergency_stop(false);
    r.run_until(0.2, |_| false);
    assert!(!r.yi.get(y::SPINDLE_CW) && !r.yi.get(y::COOLANT));
    assert!(r.gi.get(g::ESP_N));
}

#[test]
fn robot_handshake_from_cycle_complete_to_the_next_cycle_start() {
    // A robot cell: the keep relay K1.0 makes the door open at the end of a cycle.
    let retained = Retained {
        k: vec![0b1000, 0b1],
        d: {
            let mut d = vec![0; 1000];
            d[16] = 8;
            d
        },
        ..Default::default()
    };
    let mut r = Rig::new("O0001\nS500 M03\nG01 W-2 F300\nM05\nM30\n", Some(&retained));
    r.run_until(0.1, |_| false);
    r.started = true;
    let set = |r: &mut Rig, bit, on| r.sim.devices.inputs.set(bit, on);
    assert!(r.run_until(10.0, |r| r.program_done()), "cycle");
    // Cycle complete -> the door opens by itself -> ready for load.
    assert!(
        r.run_until(3.0, |r| r.yi.get(y::READY_FOR_LOAD)),
        "ready for load"
    );
    assert!(r.yi.get(y::CYCLE_COMPLETE) && r.xi.get(x::DOOR_OPEN));
    assert_eq!(r.plc.read_value("PART_COUNT", 4).unwrap(), 1);
    // The robot reaches in and asks for the chuck to open.
    set(&mut r, x::ROBOT_CLEAR, false);
    set(&mut r, x::ROBOT_CHUCK_OPEN, true);
    assert!(
        r.run_until(2.0, |r| r.xi.get(x::CHUCK_UNCLAMPED)),
        "chuck opened"
    );
    set(&mut r, x::ROBOT_CHUCK_OPEN, false);
    // Cycle start while the robot is in the machine: refused with a message.
    set(&mut r, x::ROBOT_CYCLE_START, true);
    r.run_until(0.1, |_| false);
    assert!(!r.gi.get(g::ST), "cycle start refused");
    assert!(r.message("A4.0").is_some(), "robot not clear");
    set(&mut r, x::ROBOT_CYCLE_START, false);
    // The robot asks for the chuck to close on the new part and reports clear.
    set(&mut r, x::ROBOT_CHUCK_CLOSE, true);
    assert!(
        r.run_until(2.0, |r| r.xi.get(x::CHUCK_CLAMPED)),
        "chuck closed"
    );
    set(&mut r, x::ROBOT_CHUCK_CLOSE, false);
    // The door will not close on a robot that has not reported clear.
    set(&mut r, x::ROBOT_DOOR_CLOSE, true);
    r.run_until(1.5, |_| false);
    assert!(!r.xi.get(x::DOOR_CLOSED));
    set(&mut r, x::ROBOT_DOOR_CLOSE, false);
    set(&mut r, x::ROBOT_CLEAR, true);
    set(&mut r, x::ROBOT_DOOR_CLOSE, true);
    assert!(
        r.run_until(2.0, |r| r.xi.get(x::DOOR_CLOSED)),
        "door closed"
    );
    set(&mut r, x::ROBOT_DOOR_CLOSE, false);
    // Now cycle start is accepted: ST to the NC, cycle complete and the messages cleared.
    set(&mut r, x::ROBOT_CYCLE_START, true);
    assert!(
        r.run_until(0.1, |r| r.gi.get(g::ST)),
        "cycle start accepted"
    );
    r.run_until(0.05, |_| false);
    assert!(!r.yi.get(y::CYCLE_COMPLETE) && !r.bit("A4.0"));
}

/// Presses a panel key for two scans and lets it go.
fn press(r: &mut Rig, key: cnc_msgs::signals::Bit) {
    r.sim.devices.inputs.set(key, true);
    r.run_until(SCAN * 2.0, |_| false);
    r.sim.devices.inputs.set(key, false);
    r.run_until(SCAN * 2.0, |_| false);
}

/// Issue 28, program-proving switches through the standard ladder: the machine-lock and
/// aux-lock keys (X19.0, X19.1) toggle G44.1 MLK and G5.6 AFL; a whole program runs, its
/// positions follow the program while the slides never move, and M03 S600 never reaches the
/// spindle. Released, the position is the slides' again.
#[test]
fn machine_lock_and_aux_lock_run_a_program_without_moving_the_machine() {
    let mut r = Rig::new(
        "O0001\nG98 G97 S600 M03\nG01 X100 Z-20 F3000\nG02 X120 Z-30 R10\nG00 X150 Z50\nM05\nM30\n",
        None,
    );
    r.run_until(0.1, |_| false);
    press(&mut r, x::KEY_MACHINE_LOCK);
    press(&mut r, x::KEY_AUX_LOCK);
    assert!(
        r.gi.get(g::MLK) && r.gi.get(g::AFL),
        "G44.1 and G5.6 from the keys"
    );
    assert!(
        r.nc().get(f::MMLK) && r.nc().get(f::MAFL),
        "F4.1 and F4.4 answer"
    );
    let slides = r.fb.position;
    let start = r.motion.commanded_display();
    r.started = true;
    let mut moved = false;
    let mut turned = false;
    let mut strobes = vec![];
    let ok = r.run_until(30.0, |r| {
        moved |= r.fb.position != slides;
        turned |= r.sim.spindle_rpm().abs() > 0.0;
        let m = r.nc().get(f::MF).then(|| r.nc().read_i32(f::M_CODE));
        if m.is_some() && strobes.last() != Some(&m) {
            strobes.push(m);
        }
        r.program_done()
    });
    assert!(ok, "the program ran to its end; events {:?}", r.events);
    assert!(!moved, "a slide moved under machine lock");
    assert!(!turned, "the spindle turned under aux lock");
    assert!(
        strobes.iter().all(|m| *m == Some(30)),
        "only M30 reaches the PLC: {strobes:?}"
    );
    let end = r.motion.commanded_display();
    assert!(
        (end[0] - 150.0).abs() < 1e-9 && (end[1] - 50.0).abs() < 1e-9,
        "the displayed position followed the program: {end:?} from {start:?}"
    );

    // Both keys again: released at rest, the position is where the slides stand.
    press(&mut r, x::KEY_MACHINE_LOCK);
    press(&mut r, x::KEY_AUX_LOCK);
    assert!(!r.nc().get(f::MMLK) && !r.nc().get(f::MAFL));
    assert_eq!(r.motion.commanded_display(), start);
    // The dry-run key, which the ladder did not wire before, toggles G46.7 the same way.
    press(&mut r, x::KEY_DRY_RUN);
    assert!(r.gi.get(g::DRN) && r.nc().get(f::DRUR));
    press(&mut r, x::KEY_DRY_RUN);
    assert!(!r.gi.get(g::DRN) && !r.nc().get(f::DRUR));
    // Block skip is on from the first power-up (K2.0), as the interpreter's default, and the
    // key turns it off and on (G44.0, answered on F4.0).
    assert!(r.gi.get(g::BDT1) && r.nc().get(f::MBDT));
    press(&mut r, x::KEY_BLOCK_SKIP);
    assert!(!r.gi.get(g::BDT1) && !r.nc().get(f::MBDT));
    press(&mut r, x::KEY_BLOCK_SKIP);
    assert!(r.gi.get(g::BDT1) && r.nc().get(f::MBDT));
}

/// Issue 28, jog through the PLC's G signals (D71): the standard ladder turns the jog keys
/// X19.4 +X and X19.5 −X into G100.0 and G102.0. In JOG mode, +X held for half a second moves
/// X at the key jog feed and stops at the release, and half as far with the feed override
/// switch at 50 %; in HANDWHEEL mode each press of −X moves
/// one step of 0.001 mm; in AUTO the keys move nothing.
#[test]
fn the_jog_keys_drive_the_axes_through_the_ladder_in_jog_and_handwheel_modes() {
    let mut r = powered("M30\n");
    let x = |r: &Rig| r.sim.position()[0] / 0.5;
    let start = x(&r);
    // AUTO: nothing moves.
    r.sim.devices.inputs.set(x::KEY_JOG_PLUS_X, true);
    r.run_until(0.3, |_| false);
    r.sim.devices.inputs.set(x::KEY_JOG_PLUS_X, false);
    r.run_until(0.1, |_| false);
    assert!((x(&r) - start).abs() < 1e-9, "moved in AUTO");
    // JOG: held half a second.
    r.motion.set_mode(MachineState::MODE_JOG);
    r.run_until(0.05, |_| false);
    assert!(r.nc().get(f::MJ), "F3.2 MJ in JOG mode");
    r.sim.devices.inputs.set(x::KEY_JOG_PLUS_X, true);
    r.run_until(0.5, |_| false);
    assert!(r.gi.get(g::jog_plus(0)), "G100.0 from the key");
    r.sim.devices.inputs.set(x::KEY_JOG_PLUS_X, false);
    r.run_until(0.3, |_| false);
    let held = x(&r) - start;
    println!("+X held 0.5 s in JOG mode: {held:.3} mm");
    // 1000 mm/min for 0.5 s, less the PLC's scan on press and release.
    assert!((7.0..9.0).contains(&held), "{held}");
    let after = x(&r);
    r.run_until(0.3, |_| false);
    assert!(
        (x(&r) - after).abs() < 1e-6,
        "still moving after the release"
    );
    // The feed override switch at 50 % (X16 → G12): the same half second moves half as far.
    r.sim.devices.inputs.bytes[x::FEED_OVERRIDE_SWITCH as usize] = 50;
    let before = x(&r);
    r.sim.devices.inputs.set(x::KEY_JOG_PLUS_X, true);
    r.run_until(0.5, |_| false);
    r.sim.devices.inputs.set(x::KEY_JOG_PLUS_X, false);
    r.run_until(0.3, |_| false);
    let half = x(&r) - before;
    println!("+X held 0.5 s at 50 % feed override: {half:.3} mm");
    assert!((half / held - 0.5).abs() < 0.03, "{half} against {held}");
    r.sim.devices.inputs.bytes[x::FEED_OVERRIDE_SWITCH as usize] = 100;
    let after = x(&r);
    // HANDWHEEL: three presses of −X, three steps of 0.001.
    r.motion.set_mode(MachineState::MODE_HANDWHEEL);
    for _ in 0..3 {
        press(&mut r, x::KEY_JOG_MINUS_X);
        r.run_until(0.1, |_| false);
    }
    let steps = x(&r) - after;
    println!("three -X presses in HANDWHEEL mode: {steps:.4} mm");
    assert!((steps + 0.003).abs() < 1e-6, "{steps}");
}

/// Turns the simulated handwheel `detents` every servo period for `ticks` periods.
fn turn(r: &mut Rig, detents: i32, ticks: usize) {
    for _ in 0..ticks {
        r.sim.turn_handwheel(detents);
        r.tick();
    }
}

/// Sets the external handwheel's switches (X2.1 X, X6.0 Z; X2.2 ×10, X2.3 ×100) and lets the
/// ladder scan them.
fn handwheel_switches(r: &mut Rig, axis: Option<cnc_msgs::signals::Bit>, times: u32) {
    for b in [x::HANDWHEEL_SELECT_X, x::HANDWHEEL_SELECT_Z] {
        r.sim.devices.inputs.set(b, Some(b) == axis);
    }
    r.sim.devices.inputs.set(x::HANDWHEEL_X10, times == 10);
    r.sim.devices.inputs.set(x::HANDWHEEL_X100, times == 100);
    r.run_until(SCAN * 3.0, |_| false);
}

/// Issue 28, the handwheel through the standard ladder (D72): the external handwheel's axis
/// switch (X2.1 X, X6.0 Z) and multiplier switch (X2.2 ×10, X2.3 ×100) reach the NC as G18
/// HS1 and G19 MP1/MP2 and are confirmed on F208/F209; in HANDWHEEL mode each detent of the
/// wheel (four counts of the drives' bus counter) moves the selected axis 0.001 mm × the
/// multiplier, either way; nothing moves in another mode or with no axis selected; and a wheel
/// spun faster than the axis may follow (6,000 mm/min) moves it at that speed and no more than
/// 0.1 s of it behind the wheel, so it stands soon after the wheel does.
#[test]
fn the_handwheel_moves_the_selected_axis_by_its_detents_times_the_multiplier() {
    let mut r = powered("M30\n");
    // Slide to display units: X is a diameter.
    let shown = |r: &Rig| [r.sim.position()[0] / 0.5, r.sim.position()[1]];
    let start = shown(&r);
    // AUTO with X selected, then HANDWHEEL with no axis: the wheel moves nothing.
    handwheel_switches(&mut r, Some(x::HANDWHEEL_SELECT_X), 1);
    turn(&mut r, 1, 50);
    // (The feedback of the last period of turning reaches the NC in the next.)
    r.run_until(0.02, |_| false);
    r.motion.set_mode(MachineState::MODE_HANDWHEEL);
    handwheel_switches(&mut r, None, 1);
    assert_eq!(r.nc().bytes[f::HANDWHEEL_AXIS], 0, "F208: no axis");
    turn(&mut r, 1, 50);
    r.run_until(0.2, |_| false);
    assert_eq!(
        shown(&r),
        start,
        "moved without an axis or outside HANDWHEEL mode"
    );

    // X ×1: 100 detents at 250 a second, 0.100 mm of diameter.
    handwheel_switches(&mut r, Some(x::HANDWHEEL_SELECT_X), 1);
    assert!(r.gi.get(g::HS1A) && !r.gi.get(g::HS1B), "G18: HS1 code 1");
    assert_eq!(r.nc().bytes[f::HANDWHEEL_AXIS], 1, "F208 confirms X");
    assert!(r.nc().get(f::HANDWHEEL_X1));
    turn(&mut r, 1, 100);
    r.run_until(0.3, |_| false);
    let x1 = shown(&r)[0] - start[0];
    // ×10 the other way: 30 detents, −0.300 mm.
    handwheel_switches(&mut r, Some(x::HANDWHEEL_SELECT_X), 10);
    assert!(r.gi.get(g::MP1) && r.nc().get(f::HANDWHEEL_X10));
    turn(&mut r, -1, 30);
    r.run_until(0.3, |_| false);
    let x10 = shown(&r)[0] - start[0] - x1;
    // Z ×100: a detent every 20 ms, ten of them, 1 mm.
    handwheel_switches(&mut r, Some(x::HANDWHEEL_SELECT_Z), 100);
    assert!(r.gi.get(g::HS1A) && r.gi.get(g::HS1B), "G18: HS1 code 3");
    assert_eq!(r.nc().bytes[f::HANDWHEEL_AXIS], 3, "F208 confirms Z");
    assert!(r.gi.get(g::MP2) && r.nc().get(f::HANDWHEEL_X100));
    for _ in 0..10 {
        turn(&mut r, 1, 1);
        turn(&mut r, 0, 4);
    }
    r.run_until(0.3, |_| false);
    let z100 = shown(&r)[1] - start[1];
    println!("handwheel: X ×1 +100 detents {x1:.4} mm, X ×10 −30 detents {x10:.4} mm, Z ×100 +10 detents {z100:.4} mm");
    assert!((x1 - 0.1).abs() < 1e-6, "{x1}");
    assert!((x10 + 0.3).abs() < 1e-6, "{x10}");
    assert!((z100 - 1.0).abs() < 1e-6, "{z100}");

    // Spun far too fast: 50 detents a period for 80 ms at ×100 asks for 100 mm of −Z.
    let z0 = r.sim.position()[1];
    let mut fastest: f64 = 0.0;
    let mut last = z0;
    let mut speed = |r: &Rig| {
        let z = r.sim.position()[1];
        fastest = fastest.max((z - last).abs() / DT);
        last = z;
    };
    for _ in 0..20 {
        r.sim.turn_handwheel(-50);
        r.tick();
        speed(&r);
    }
    let mut still = 0;
    let mut stood_after = None;
    for k in 0..250 {
        r.tick();
        speed(&r);
        still = if r.motion.handwheel_moving() {
            0
        } else {
            still + 1
        };
        if still == 1 && stood_after.is_none() {
            stood_after = Some((k + 1) as f64 * DT);
        }
    }
    let moved = z0 - r.sim.position()[1];
    let stood_after = stood_after.expect("the axis never stood");
    println!(
        "spun 100 mm in 80 ms: moved {moved:.2} mm, fastest {:.0} mm/min, stood {:.0} ms after the wheel",
        fastest * 60.0,
        stood_after * 1000.0
    );
    assert!((5.0..20.0).contains(&moved), "{moved}");
    assert!(fastest * 60.0 <= 6000.0 * 1.01, "{fastest}");
    assert!(stood_after <= 0.3, "{stood_after}");

    // A counter that jumps (a broken cable, a glitch) is not a hand: nothing moves.
    let before = shown(&r);
    turn(&mut r, 1_000_000, 1);
    r.run_until(0.2, |_| false);
    assert_eq!(shown(&r), before, "a jump of the counter moved the axis");
    // JOG mode: the wheel moves nothing.
    r.motion.set_mode(MachineState::MODE_JOG);
    turn(&mut r, 1, 50);
    r.run_until(0.2, |_| false);
    assert_eq!(shown(&r), before);
}

/// Issue 28, the mill's Z-axis lock (`003` part 2 §2.1.2; D73): the cell's Z-axis lock key
/// (X9.0) toggles G108.2 through the standard ladder; a program runs with X and Y moving and
/// Z's drive held where it stood, while Z's displayed position follows the program. Released
/// at rest, Z's position is where the slide stands again.
#[test]
fn the_z_axis_lock_holds_z_while_the_program_moves_x_and_y() {
    let mut r = Rig::on(
        config("sim_mill"),
        "O0001\nG90 G00 X10. Y10.\nZ-5.\nG01 Z-20. F600.\nX40. Y30.\nG00 Z50.\nM30\n",
        None,
    );
    r.run_until(0.1, |_| false);
    press(&mut r, x::KEY_Z_AXIS_LOCK);
    assert!(r.gi.get(g::axis_lock(2)), "G108.2 from the key");
    assert_eq!(r.motion.locked_axes(), 0b100, "Z alone is held");
    assert!(!r.nc().get(f::MMLK), "not the whole machine's lock");
    let z0 = r.sim.position()[2];
    let start = r.motion.commanded_display();
    r.started = true;
    let mut z_moved = false;
    let ok = r.run_until(30.0, |r| {
        z_moved |= r.sim.position()[2] != z0;
        r.program_done()
    });
    assert!(ok, "the program ran to its end; events {:?}", r.events);
    r.run_until(0.2, |_| false);
    assert!(!z_moved, "Z moved under the Z-axis lock");
    let slides = r.sim.position();
    assert!(
        (slides[0] - 40.0).abs() < 1e-6 && (slides[1] - 30.0).abs() < 1e-6,
        "X and Y moved: {slides:?}"
    );
    assert_eq!(
        r.motion.commanded_display()[2],
        50.0,
        "Z's position followed"
    );
    // Released at rest: Z's position is the slide's again.
    press(&mut r, x::KEY_Z_AXIS_LOCK);
    assert_eq!(r.motion.locked_axes(), 0);
    assert_eq!(r.motion.commanded_display()[2], start[2]);
}

/// Issue 28, the handwheel trial run (`000` §13.3; D74): the trial key (X9.1) toggles G19.6
/// through the standard ladder; in AUTO the program then stands while the wheel stands, moves
/// as fast as the wheel turns clockwise (a detent 0.001 mm × the multiplier of path), never
/// faster than its F, and stops when the wheel stops. Off again, the program runs on at F.
#[test]
fn in_the_handwheel_trial_run_the_program_moves_as_fast_as_the_wheel_turns() {
    let mut r = Rig::new("O0001\nG98 G01 Z40 F600\nM30\n", None);
    r.run_until(0.1, |_| false);
    press(&mut r, x::KEY_HANDWHEEL_TRIAL);
    assert!(r.gi.get(g::HANDWHEEL_TRIAL), "G19.6 from the key");
    assert!(r.motion.handwheel_trial(), "in effect in AUTO");
    let z = |r: &Rig| r.motion.commanded_display()[1];
    let z0 = z(&r);
    r.started = true;
    r.run_until(1.0, |_| false);
    assert_eq!(z(&r), z0, "moved with the wheel standing");
    // ×1, 250 detents a second: 0.25 mm/s.
    handwheel_switches(&mut r, None, 1);
    turn(&mut r, 1, 250);
    let a = z(&r);
    turn(&mut r, 1, 250);
    let slow = a - z(&r);
    // ×100, 250 detents a second asks for 25 mm/s; F600 is 10 mm/s.
    handwheel_switches(&mut r, None, 100);
    turn(&mut r, 1, 250);
    let b = z(&r);
    turn(&mut r, 1, 250);
    let capped = b - z(&r);
    // The wheel stops: so does the program.
    r.run_until(0.3, |_| false);
    let stopped = z(&r);
    r.run_until(0.5, |_| false);
    println!(
        "trial run: ×1 at 250 detents/s {slow:.3} mm/s; ×100 {capped:.2} mm/s (F600 is 10); \
         stood at Z {stopped:.3}"
    );
    assert!((slow - 0.25).abs() < 0.01, "{slow}");
    assert!((capped - 10.0).abs() < 0.05, "{capped}");
    assert_eq!(z(&r), stopped, "went on after the wheel stopped");
    // Backwards turns do not run the program.
    turn(&mut r, -1, 250);
    assert_eq!(z(&r), stopped, "ran on a counter-clockwise turn");
    // The key again: the program runs on at F to its end.
    press(&mut r, x::KEY_HANDWHEEL_TRIAL);
    assert!(!r.motion.handwheel_trial());
    assert!(r.run_until(10.0, |r| r.program_done()), "{:?}", r.events);
    assert!((z(&r) - 40.0).abs() < 1e-9);
}

/// The 802D mill (`sim_mill_802d`): the standard ladder with K1.2 runs its drum magazine of
/// 24 pockets. T12 preselects (the drum turns the short way to pocket 12 and locks before the
/// T is acknowledged), M6 stops and orients the spindle and puts tool 12 into it (the NC's
/// current tool G68), M19 orients a running spindle; T30, beyond the magazine, is A3.2.
/// Decision D94.
#[test]
fn the_mill_magazine_preselects_with_t_changes_with_m6_and_m19_orients() {
    // The launch config changes tools with T at once; with M6 here (the builder's K1.3 and
    // the interpreter's machine data).
    let mut cfg = config("sim_mill_802d");
    assert!(!cfg.machine.tool_change_with_m6);
    cfg.machine.tool_change_with_m6 = true;
    cfg.plc.keep_relays.push("K1.3".into());
    let kept = Retained::first_power_up(&cfg.plc.keep_relays).unwrap();
    let program = "T12\nS1000 M3\nG0 X10 Y10 Z50\nM6\nD1\nS800 M3\nG0 X20\nM19\nG0 X30\nM30\n";
    let mut r = Rig::on(cfg.clone(), program, Some(&kept));
    r.run_until(0.1, |_| false);
    r.started = true;
    assert_eq!(r.turret_station(), Some(1));
    let mut pockets = vec![1u8];
    let (mut t_fin, mut m6_fin, mut m19_fin) = (None, None, None);
    let ok = r.run_until(60.0, |r| {
        if let Some(s) = r.turret_station() {
            if pockets.last() != Some(&s) {
                pockets.push(s);
            }
        }
        let fin = r.gi.get(g::FIN);
        let m = r.nc().read_i32(f::M_CODE);
        let seen = (
            r.sim.devices.turret_station(),
            r.xi.get(x::TURRET_LOCKED),
            r.fb.spindle_rpm,
            r.fb.spindle_angle_deg,
            r.gi.bytes[g::NTOL as usize],
        );
        if fin && r.nc().get(f::TF) && t_fin.is_none() {
            t_fin = Some(seen);
        }

        if fin && r.nc().get(f::MF) && m == 6 && m6_fin.is_none() {
            m6_fin = Some(seen);
        }
        if t_fin.is_some() && m6_fin.is_none() {
            assert_eq!(seen.4, 0, "no tool in the spindle before M6");
        }
        if fin && r.nc().get(f::MF) && m == 19 && m19_fin.is_none() {
            m19_fin = Some(seen);
        }
        r.program_done()
    });
    assert!(ok, "program did not finish; events {:?}", r.events);
    assert_eq!(pockets, (1..=12).collect::<Vec<u8>>(), "the short way, CW");
    let (pocket, locked, ..) = t_fin.expect("FIN for T12");
    assert_eq!((pocket, locked), (Some(12), true));
    let (pocket, locked, rpm, angle, _) = m6_fin.expect("FIN for M6");
    assert_eq!((pocket, locked), (Some(12), true));
    assert_eq!(
        (rpm, angle),
        (0.0, 0.0),
        "the spindle stands oriented for the change"
    );
    let (_, _, rpm, angle, tool) = m19_fin.expect("FIN for M19");
    assert_eq!((rpm, angle), (0.0, 0.0), "M19 from 800 rpm");
    assert_eq!(tool, 12, "tool 12 in the spindle for the NC");
    assert!(r.message("A3.2").is_none() && r.message("A0.1").is_none());
    // Where T changes at once (the launch config), the tool is in the spindle at T's FIN,
    // and the manual's `T1 D1` programs run unchanged; their M6 (fixture 109) is no tool
    // change there and leaves the spindle turning.
    let cfg = config("sim_mill_802d");
    let kept = Retained::first_power_up(&cfg.plc.keep_relays).unwrap();
    let mut r = Rig::on(
        cfg.clone(),
        "T20 D1 S500 M3\nM6\nG0 X10\nM30\n",
        Some(&kept),
    );
    r.run_until(0.1, |_| false);
    r.started = true;
    assert!(r.run_until(30.0, |r| r.program_done()), "{:?}", r.events);
    assert_eq!(r.turret_station(), Some(20));
    assert_eq!(r.gi.bytes[g::NTOL as usize], 20);
    assert!(
        r.fb.spindle_rpm > 400.0,
        "neither T nor M6 stopped the spindle"
    );
    // Beyond the magazine: the tool-number alarm, and the program stops.
    let mut r = Rig::on(cfg, "T30\nG0 X10\nM30\n", Some(&kept));
    r.run_until(0.1, |_| false);
    r.started = true;
    assert!(!r.run_until(5.0, |r| r.program_done()));
    assert!(r.message("A3.2").is_some(), "{:?}", r.events);
}
