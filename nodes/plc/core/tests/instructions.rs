//! Every instruction against scan sequences worked out by hand.

use cnc_msgs::signals::FImage;
use cnc_msgs::signals::{SignalTable, XImage};
use cnc_plc_core::address::{self, Address};
use cnc_plc_core::engine::{rotate, RotateMode};
use cnc_plc_core::memory::Retained;
use cnc_plc_core::{Plc, PlcEvent, Program, Value};

/// A PLC running `level1` (END1/END2 appended unless the text has them), no E-stop input.
fn plc(level1: &str) -> Plc {
    let text = if level1.contains("END2") {
        level1.to_string()
    } else {
        format!("{level1}\nEND1\nEND2\n")
    };
    let program = Program::parse(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    let mut p = Plc::new(program, None, 1);
    p.set_emergency_stop_input(None);
    p
}

/// One scan at `now` ms with the listed X bits on.
fn scan(p: &mut Plc, on: &[&str], now: u64) {
    let mut x = XImage::default();
    for a in on {
        let Ok(Address::Bit(b)) = address::parse(a) else {
            panic!("{a}")
        };
        x.bytes[b.byte.index as usize] |= 1 << b.bit;
    }
    p.scan(&FImage::default(), &x, now);
}

fn bit(p: &Plc, a: &str) -> bool {
    match p.read(a).unwrap() {
        Value::Bit(b) => b,
        v => panic!("{a}: {v:?}"),
    }
}

fn val(p: &Plc, a: &str, format: u8) -> i64 {
    p.read_value(a, format).unwrap()
}

#[test]
fn basic_logic_and_write() {
    let mut p = plc("RD X0.0\nAND X0.1\nWRT Y0.0\nRD X0.0\nOR X0.1\nWRT Y0.1\n\
                     RD.NOT X0.0\nAND.NOT X0.1\nWRT Y0.2\nRD X0.0\nOR.NOT X0.1\nWRT.NOT Y0.3");
    for (inputs, expect) in [
        (vec![], [false, false, true, false]),
        (vec!["X0.0"], [false, true, false, false]),
        (vec!["X0.1"], [false, true, false, true]),
        (vec!["X0.0", "X0.1"], [true, true, false, false]),
    ] {
        scan(&mut p, &inputs, 0);
        let got = ["Y0.0", "Y0.1", "Y0.2", "Y0.3"].map(|a| bit(&p, a));
        assert_eq!(got, expect, "{inputs:?}");
        assert_eq!(
            p.outputs().bytes[0],
            got.iter().rev().fold(0, |a, b| a << 1 | u8::from(*b))
        );
    }
}

#[test]
fn stack_instructions() {
    // Y0.0 = (X0.0 AND X0.1) OR (X0.2 AND X0.3); Y0.1 = X0.0 AND (X0.1 OR NOT X0.2).
    let mut p = plc(
        "RD X0.0\nAND X0.1\nRD.STK X0.2\nAND X0.3\nOR.STK\nWRT Y0.0\n\
                     RD X0.0\nRD.STK X0.1\nRD.NOT.STK X0.2\nOR.STK\nAND.STK\nWRT Y0.1",
    );
    for n in 0..16u8 {
        let names = ["X0.0", "X0.1", "X0.2", "X0.3"];
        let on: Vec<&str> = (0..4)
            .filter(|i| n >> i & 1 == 1)
            .map(|i| names[i])
            .collect();
        scan(&mut p, &on, 0);
        let x = |i: u8| n >> i & 1 == 1;
        assert_eq!(bit(&p, "Y0.0"), x(0) && x(1) || x(2) && x(3), "{on:?}");
        assert_eq!(bit(&p, "Y0.1"), x(0) && (x(1) || !x(2)), "{on:?}");
    }
}

#[test]
fn set_and_reset_hold_across_scans() {
    let mut p = plc("RD X0.0\nSET R0.0\nRD X0.1\nRST R0.0\nRD R0.0\nWRT Y0.0");
    scan(&mut p, &[], 0);
    assert!(!bit(&p, "Y0.0"));
    scan(&mut p, &["X0.0"], 10);
    scan(&mut p, &[], 20);
    assert!(bit(&p, "Y0.0"), "held");
    scan(&mut p, &["X0.1"], 30);
    assert!(!bit(&p, "Y0.0"));
    scan(&mut p, &["X0.0", "X0.1"], 40);
    assert!(!bit(&p, "Y0.0"), "reset comes last: it wins");
}

#[test]
fn timers_count_across_scans() {
    let mut p = plc("PRESET T1 100\nRD X0.0\nTMR 1\nWRT Y0.0\nRD X0.0\nTMRB 7, 30\nWRT Y0.1");
    let seq = [
        (0, true, false, false),
        (20, true, false, false),
        (30, true, false, true),
        (90, true, false, true),
        (100, true, true, true),
        (110, false, false, false),
        (120, true, false, false),
        (219, true, false, true),
        (220, true, true, true),
    ];
    for (t, input, t1, tb) in seq {
        scan(&mut p, if input { &["X0.0"] } else { &[] }, t);
        assert_eq!((bit(&p, "Y0.0"), bit(&p, "Y0.1")), (t1, tb), "at {t} ms");
    }
    assert_eq!(
        p.read("T1").unwrap(),
        Value::Timer {
            preset_ms: 100,
            elapsed_ms: 100
        }
    );
    p.set_preset("T1", 50).unwrap();
    assert!(p.set_preset("T40", 50).is_err());
    assert!(p.set_preset("中", 50).is_err() && p.read("中").is_err());
}

#[test]
fn ring_counters_up_down_and_reset() {
    // CTR 0, preset 3: inputs CN0 = X0.3, UPDOWN = X0.2, RST = X0.1, ACT = X0.0.
    let mut p = plc("PRESET C0 3\nRD X0.3\nRD.STK X0.2\nRD.STK X0.1\nRD.STK X0.0\nCTR 0\nWRT Y0.0");
    let mut t = 0;
    let mut pulse = |p: &mut Plc, extra: &[&str]| {
        let mut on = vec!["X0.0"];
        on.extend_from_slice(extra);
        scan(p, &on, t);
        scan(p, extra, t + 10);
        t += 20;
    };
    let count = |p: &Plc| match p.read("C0").unwrap() {
        Value::Counter { current, .. } => current,
        v => panic!("{v:?}"),
    };
    // Up from 0: 1, 2, 3 (contact on), then round to 0.
    for expect in [1, 2, 3, 0, 1] {
        pulse(&mut p, &[]);
        assert_eq!(count(&p), expect);
        assert_eq!(bit(&p, "Y0.0"), expect == 3);
    }
    // Held ACT counts once.
    scan(&mut p, &["X0.0"], 1000);
    scan(&mut p, &["X0.0"], 1010);
    assert_eq!(count(&p), 2);
    // Reset to the start; down with CN0 = 1 starts at the preset and rounds at 1.
    scan(&mut p, &["X0.1"], 1020);
    assert_eq!(count(&p), 0);
    scan(&mut p, &["X0.1", "X0.2", "X0.3"], 1030);
    assert_eq!(count(&p), 3);
    for expect in [2, 1, 3] {
        pulse(&mut p, &["X0.2", "X0.3"]);
        assert_eq!(count(&p), expect);
        assert_eq!(bit(&p, "Y0.0"), expect == 1);
    }
    // CTRB (fixed preset 2) and CTRC (preset in D0, count in D2).
    let mut p = plc("INIT D0 2 2\nRD X0.0\nCTRB 5, 2\nWRT Y0.0\nRD X0.0\nCTRC D0, D2\nWRT Y0.1");
    for (k, expect) in [(0, 1), (1, 2), (2, 0)] {
        scan(&mut p, &["X0.0"], k * 20);
        scan(&mut p, &[], k * 20 + 10);
        assert_eq!(val(&p, "D2", 2), expect);
        assert_eq!(bit(&p, "Y0.0"), expect == 2);
        assert_eq!(bit(&p, "Y0.1"), expect == 2);
    }
}

#[test]
fn edges() {
    let mut p = plc("RD X0.0\nDIFU 1\nWRT Y0.0\nRD X0.0\nDIFD 2\nWRT Y0.1");
    let seq = [
        (false, false, false),
        (true, true, false),
        (true, false, false),
        (false, false, true),
        (false, false, false),
        (true, true, false),
    ];
    for (k, (input, up, down)) in seq.into_iter().enumerate() {
        scan(&mut p, if input { &["X0.0"] } else { &[] }, k as u64 * 10);
        assert_eq!((bit(&p, "Y0.0"), bit(&p, "Y0.1")), (up, down), "scan {k}");
    }
}

#[test]
fn decode_and_code_tables() {
    let mut p = plc("INIT D0 2 13\nRD X0.0\nDECB 2, D0, 10, R0\nINIT D2 1 2\nRD X0.0\n\
                     CODB 2, 4, D2, D4, 100, 200, 300, 400\nWRT Y0.0\nRD X0.0\nCODB 2, 2, D2, D6, 7, 8\nWRT Y0.1");
    scan(&mut p, &["X0.0"], 0);
    assert_eq!(val(&p, "R0", 1), 0b1000, "13 is the 4th code from 10");
    assert_eq!(val(&p, "D4", 2), 300);
    assert!(!bit(&p, "Y0.0"));
    assert!(bit(&p, "Y0.1"), "index 2 outside a table of 2: error");
    scan(&mut p, &[], 10);
    assert_eq!(val(&p, "R0", 1), 0, "DECB clears its output without ACT");
}

#[test]
fn rotation_takes_the_short_way() {
    let m = |shortest, one_before, steps| RotateMode {
        from_one: true,
        shortest,
        one_before,
        steps,
    };
    // 8 stations, from 1: to 3 forward 2, to 7 reverse 2, to 5 (a tie) forward 4.
    assert_eq!(rotate(8, 1, 3, m(true, false, true)), (2, false));
    assert_eq!(rotate(8, 1, 7, m(true, false, true)), (2, true));
    assert_eq!(rotate(8, 1, 5, m(true, false, true)), (4, false));
    assert_eq!(
        rotate(8, 1, 7, m(false, false, true)),
        (6, false),
        "always forward"
    );
    assert_eq!(
        rotate(8, 1, 7, m(true, true, false)),
        (8, true),
        "one before 7 coming back"
    );
    assert_eq!(rotate(8, 2, 8, m(true, true, true)), (1, true));
    assert_eq!(rotate(6, 6, 1, m(true, false, false)), (1, false));
    assert_eq!(
        rotate(
            4,
            0,
            3,
            RotateMode {
                shortest: true,
                ..Default::default()
            }
        ),
        (3, true)
    );
    // As an instruction: RN0, DIR, POS, INC, ACT from the stack.
    let mut p = plc(
        "INIT D0 1 8\nINIT D1 1 1\nINIT D2 1 7\nRD R9091.1\nRD.STK R9091.1\n\
                     RD.STK R9091.0\nRD.STK R9091.1\nRD.STK X0.0\nROTB 1, D0, D1, D2, D3\nWRT Y0.0",
    );
    scan(&mut p, &["X0.0"], 0);
    assert_eq!(val(&p, "D3", 1), 2);
    assert!(bit(&p, "Y0.0"), "reverse");
}

#[test]
fn moves() {
    let mut p = plc(
        "INIT D0 4 0x44332211\nRD X0.0\nMOVE 0b11110000, D0, D10\nRD X0.0\n\
                     MOVOR D0, D1, D11\nRD X0.0\nMOVB D1, D12\nRD X0.0\nMOVW D0, D14\n\
                     RD X0.0\nMOVN 3, D1, D20\nRD X0.0\nNUMEB 2, -2, D30",
    );
    scan(&mut p, &[], 0);
    assert_eq!(val(&p, "D10", 1), 0, "no ACT, no move");
    scan(&mut p, &["X0.0"], 10);
    assert_eq!(val(&p, "D10", 1), 0x10);
    assert_eq!(val(&p, "D11", 1), 0x11 | 0x22);
    assert_eq!(val(&p, "D12", 1), 0x22);
    assert_eq!(val(&p, "D14", 2), 0x2211);
    assert_eq!(val(&p, "D20", 4) & 0xff_ffff, 0x443322);
    assert_eq!(val(&p, "D30", 2), -2);
}

#[test]
fn parity_bcd_compare() {
    // 0b0000_0111 has three ones: odd. O.E = X0.2 (1 = odd expected), RST X0.1, ACT X0.0.
    let mut p = plc("INIT D0 1 7\nRD X0.2\nRD.STK X0.1\nRD.STK X0.0\nPARI D0\nWRT Y0.0\n\
                     INIT D2 2 1234\nRD R9091.0\nRD.STK R9091.0\nRD.STK R9091.0\nRD.STK X0.0\nDCNVB 2, D2, D4\nWRT Y0.1\n\
                     RD R9091.0\nRD.STK R9091.1\nRD.STK R9091.0\nRD.STK X0.0\nDCNVB 2, D4, D6\n\
                     INIT D8 2 5\nRD X0.0\nCOMPB 2, 3, D8\nRD R9000.1\nWRT Y0.2\nRD R9000.0\nWRT Y0.3");
    scan(&mut p, &["X0.0"], 0);
    assert!(bit(&p, "Y0.0"), "odd data, even expected: error");
    scan(&mut p, &["X0.0", "X0.2"], 10);
    assert!(!bit(&p, "Y0.0"));
    assert_eq!(val(&p, "D4", 2) as u16, 0x1234, "binary to BCD");
    assert_eq!(val(&p, "D6", 2), 1234, "and back");
    assert!(!bit(&p, "Y0.1"));
    assert!(bit(&p, "Y0.2") && !bit(&p, "Y0.3"), "3 < 5");
}

#[test]
fn shift_register() {
    // DIR X0.3 (1 right), CONT X0.2, RST X0.1, ACT X0.0; shifts on ACT's rising edge.
    let mut p =
        plc("INIT D0 2 0x8001\nRD X0.3\nRD.STK X0.2\nRD.STK X0.1\nRD.STK X0.0\nSFT D0\nWRT Y0.0");
    scan(&mut p, &["X0.0"], 0);
    assert_eq!(val(&p, "D0", 2) as u16, 0x0002);
    assert!(bit(&p, "Y0.0"), "bit 15 shifted out");
    scan(&mut p, &["X0.0"], 10);
    assert_eq!(val(&p, "D0", 2) as u16, 0x0002, "held ACT shifts once");
    scan(&mut p, &[], 20);
    scan(&mut p, &["X0.0", "X0.3", "X0.2"], 30);
    assert_eq!(
        val(&p, "D0", 2) as u16,
        0x0003,
        "right, keeping the old bit"
    );
    scan(&mut p, &["X0.1"], 40);
    assert_eq!(val(&p, "D0", 2), 0);
}

#[test]
fn table_search_and_indexed_move() {
    let mut p = plc("INIT D0 2 10\nINIT D2 2 20\nINIT D4 2 30\nRD X0.0\nDSCHB 2, 3, D0, 30, D10\nWRT Y0.0\n\
                     RD X0.0\nDSCHB 2, 3, D0, 31, D12\nWRT Y0.1\n\
                     INIT D20 2 1\nRD X0.1\nRD.STK R9091.0\nRD.STK X0.0\nXMOVB 2, 3, D0, D22, D20\nWRT Y0.2\n\
                     INIT D24 2 3\nRD R9091.0\nRD.STK R9091.0\nRD.STK X0.0\nXMOVB 2, 3, D0, D26, D24\nWRT Y0.3");
    scan(&mut p, &["X0.0"], 0);
    assert_eq!((val(&p, "D10", 2), bit(&p, "Y0.0")), (2, false));
    assert_eq!(
        (val(&p, "D12", 2), bit(&p, "Y0.1")),
        (-1, true),
        "not found"
    );
    assert_eq!(val(&p, "D22", 2), 20, "read entry 1");
    assert!(bit(&p, "Y0.3"), "index 3 of a table of 3");
    // RW = 1 writes D22 into entry 1.
    let mut p = plc(
        "INIT D0 2 10\nINIT D2 2 20\nINIT D20 2 1\nINIT D22 2 77\nRD X0.1\nRD.STK R9091.0\n\
                     RD.STK X0.0\nXMOVB 2, 2, D0, D22, D20",
    );
    scan(&mut p, &["X0.0", "X0.1"], 0);
    assert_eq!(val(&p, "D2", 2), 77);
}

#[test]
fn arithmetic_with_flags() {
    let mut p = plc("INIT D0 2 7\nINIT D2 2 3\nRD X0.0\nADDB 2, D0, D2, D10\nRD X0.0\nSUBB 2, D2, D0, D12\n\
                     RD R9000.1\nWRT Y0.0\nRD X0.0\nMULB 2, D0, 5, D14\nRD X0.0\nDIVB 2, D0, D2, D16\n\
                     RD X0.0\nDIVB 2, D0, 0, D18\nWRT Y0.1\nRD X0.0\nADDB 2, D0, 32767, D20\nWRT Y0.2\n\
                     RD X0.0\nADDB 1, D0, 250, D22\nWRT Y0.3");
    scan(&mut p, &["X0.0"], 0);
    assert_eq!(val(&p, "D10", 2), 10);
    assert_eq!(val(&p, "D12", 2), -4);
    assert!(bit(&p, "Y0.0"), "negative flag R9000.1");
    assert_eq!(val(&p, "D14", 2), 35);
    assert_eq!(val(&p, "D16", 2), 2);
    assert!(bit(&p, "Y0.1"), "division by zero: error");
    assert_eq!(val(&p, "D18", 2), 0, "result untouched");
    assert!(bit(&p, "Y0.2"), "32767 + 7 overflows two bytes");
    assert!(bit(&p, "Y0.3"), "250 + 7 overflows one byte");
    assert_eq!(val(&p, "D22", 1), 1, "wraps");
    let mut p = plc("INIT D0 2 7\nRD X0.0\nDIVB 2, D0, 3, D16\nRD X0.0\nMOVW R9002, D18");
    scan(&mut p, &["X0.0"], 0);
    assert_eq!(
        (val(&p, "D16", 2), val(&p, "D18", 2)),
        (2, 1),
        "remainder in R9002"
    );
}

#[test]
fn logic_on_bytes() {
    let mut p = plc(
        "INIT D0 1 0b1100\nRD X0.0\nEORB 1, D0, 0b1010, D1\nRD X0.0\nANDB 1, D0, 0b1010, D2\n\
                     RD X0.0\nORB 1, D0, 0b1010, D3\nRD X0.0\nNOTB 1, D0, D4",
    );
    scan(&mut p, &["X0.0"], 0);
    assert_eq!(
        [
            val(&p, "D1", 1),
            val(&p, "D2", 1),
            val(&p, "D3", 1),
            val(&p, "D4", 1)
        ],
        [0b0110, 0b1000, 0b1110, 0b1111_0011]
    );
}

#[test]
fn common_line_control() {
    let mut p = plc(
        "RD X0.0\nCOM\nRD X0.1\nWRT Y0.0\nRD X0.1\nWRT.NOT Y0.1\nCOME\nRD X0.1\nWRT Y0.2\n\
                     RD X0.0\nCOM 1\nRD X0.1\nWRT Y0.3\nRD X0.1\nWRT Y0.4",
    );
    scan(&mut p, &["X0.0", "X0.1"], 0);
    assert_eq!(p.outputs().bytes[0], 0b11101);
    scan(&mut p, &["X0.1"], 10);
    assert_eq!(
        p.outputs().bytes[0],
        0b10100,
        "coils up to COME, and the next 1, write 0"
    );
}

#[test]
fn subroutines_and_jumps() {
    let mut p = plc(
        "RD X0.0\nCALL P1\nCALLU P2\nRD X0.1\nJMPB L1\nRD R9091.1\nWRT Y0.2\nLBL L1\nEND1\nEND2\n\
                     SP P1\nRD R9091.1\nWRT Y0.0\nSPE\nSP P2\nRD X0.0\nWRT.NOT Y0.1\nSPE\n",
    );
    scan(&mut p, &[], 0);
    assert_eq!(
        p.outputs().bytes[0],
        0b110,
        "P1 not called; P2 always; no jump"
    );
    scan(&mut p, &["X0.0", "X0.1"], 10);
    assert_eq!(
        p.outputs().bytes[0],
        0b101,
        "P1 called; the jump skips the Y0.2 rung"
    );
}

#[test]
fn spindle_control_scales_the_s_code_by_the_override() {
    let mut p = plc("INIT D0 4 1200\nINIT D4 1 50\nRD X0.0\nSPLCNT D0, D4");
    scan(&mut p, &["X0.0"], 0);
    assert_eq!(p.outputs().spindle_rpm, 600.0);
    scan(&mut p, &[], 10);
    assert_eq!(p.outputs().spindle_rpm, 0.0);
}

/// Issue 26: an override byte of 255 % once ran 800 rpm at 2040; the drive's rating clamps
/// whatever the ladder computes.
#[test]
fn the_spindle_command_never_exceeds_the_drives_rating() {
    let mut p = plc("INIT D0 4 800\nINIT D4 1 255\nRD X0.0\nSPLCNT D0, D4");
    p.set_spindle_limit(1500.0);
    scan(&mut p, &["X0.0"], 0);
    assert_eq!(p.outputs().spindle_rpm, 1500.0);
}

#[test]
fn level_two_is_split_over_scans_and_level_one_runs_every_scan() {
    let program = Program::parse(
        "RD R9091.1\nADDB 2, D0, 1, D0\nEND1\nRD R9091.1\nADDB 2, D2, 1, D2\nRD R9091.1\n\
         ADDB 2, D4, 1, D4\nEND2\n",
    )
    .unwrap();
    let mut p = Plc::new(program, None, 2);
    for k in 1..=4 {
        scan(&mut p, &[], k * 10);
    }
    // Level 1 four times; each half of level 2 every other scan.
    assert_eq!(
        (val(&p, "D0", 2), val(&p, "D2", 2), val(&p, "D4", 2)),
        (4, 2, 2)
    );
}

#[test]
fn system_relays_and_the_watchdog() {
    let mut p = plc("RD R9091.5\nWRT Y0.0\nRD R9091.6\nWRT Y0.1\nRD R9091.1\nWRT Y0.2");
    scan(&mut p, &[], 150);
    assert_eq!(p.outputs().bytes[0], 0b101);
    scan(&mut p, &[], 550);
    assert_eq!(p.outputs().bytes[0], 0b111);
    let mut p = plc("LBL L1\nRD R9091.1\nWRT Y0.0\nRD R9091.1\nJMPB L1");
    scan(&mut p, &[], 0);
    assert!(p.fault().is_some_and(|f| f.contains("watchdog")));
    assert_eq!(p.outputs().bytes[0], 0, "outputs off");
    assert!(p
        .take_events()
        .iter()
        .any(|e| matches!(e, PlcEvent::Fault { .. })));
    p.load("RD R9091.1\nWRT Y0.0\nEND1\nEND2").unwrap();
    scan(&mut p, &[], 10);
    assert!(
        p.fault().is_none() && bit(&p, "Y0.0"),
        "a new program runs again"
    );
}

#[test]
fn emergency_stop_input_turns_every_output_off_in_the_same_scan() {
    let program = Program::parse(
        "RD R9091.1\nWRT Y0.0\nWRT Y19.7\nWRT G8.4\nRD R9091.1\nSPLCNT D0, D0\nEND1\nEND2",
    )
    .unwrap();
    let mut p = Plc::new(program, None, 1);
    scan(&mut p, &["X1.0"], 0);
    assert!(p.outputs().bytes.iter().any(|b| *b != 0));
    assert!(p.to_nc().get(cnc_msgs::signals::g::ESP_N));
    scan(&mut p, &[], 10);
    assert!(p.outputs().bytes.iter().all(|b| *b == 0));
    assert_eq!(p.outputs().spindle_rpm, 0.0);
    assert!(!p.to_nc().get(cnc_msgs::signals::g::ESP_N));
}

#[test]
fn messages_raise_and_clear_with_their_text() {
    let mut p = plc(
        "MSG A0.1 ALARM \"tool change timeout\"\nMSG A4.0 MESSAGE \"robot; not clear\"\n\
                     RD X0.0\nWRT A0.1\nRD X0.1\nWRT A4.0",
    );
    scan(&mut p, &["X0.0", "X0.1"], 0);
    let ev: Vec<PlcEvent> = p
        .take_events()
        .into_iter()
        .filter(|e| !matches!(e, PlcEvent::EmergencyStop(_)))
        .collect();
    assert_eq!(
        ev,
        vec![
            PlcEvent::MessageOn {
                number: 1001,
                address: "A0.1".into(),
                text: "tool change timeout".into(),
                alarm: true
            },
            PlcEvent::MessageOn {
                number: 1032,
                address: "A4.0".into(),
                text: "robot; not clear".into(),
                alarm: false
            }
        ]
    );
    scan(&mut p, &["X0.1"], 10);
    assert_eq!(p.take_events(), vec![PlcEvent::MessageOff { number: 1001 }]);
}

#[test]
fn kept_memory_survives_a_restart() {
    let text = "PRESET T1 100\nINIT D0 2 5\nRD X0.0\nADDB 2, D0, 1, D0\nEND1\nEND2";
    let mut p = Plc::new(Program::parse(text).unwrap(), None, 1);
    scan(&mut p, &["X0.0"], 0);
    p.set_preset("T1", 250).unwrap();
    let yaml = serde_yaml_round_trip(&p.retained());
    let p2 = Plc::new(Program::parse(text).unwrap(), Some(&yaml), 1);
    assert_eq!(val(&p2, "D0", 2), 6, "D kept, not the program's INIT");
    assert_eq!(
        p2.read("T1").unwrap(),
        Value::Timer {
            preset_ms: 250,
            elapsed_ms: 0
        }
    );
}

fn serde_yaml_round_trip(r: &Retained) -> Retained {
    let text = serde_yaml::to_string(r).unwrap();
    serde_yaml::from_str(&text).unwrap()
}

#[test]
fn malformed_programs_are_refused_with_line_and_reason() {
    let cases = [
        ("RD X0.0\nWRT Y0.0\nEND2", 3, "END2 before END1"),
        ("RD X0.0\nWRT Y0.0\nEND1", 3, "no END2"),
        ("RD X0.0\nFOO Y0.0\nEND1\nEND2", 2, "unknown instruction"),
        ("RD X20.0\nEND1\nEND2", 1, "outside the X table"),
        ("RD X0.0\nWRT X0.1\nEND1\nEND2", 2, "cannot be written"),
        ("RD X0.0\nWRT F0.1\nEND1\nEND2", 2, "written by the NC"),
        ("RD X0.0\nWRT R9091.1\nEND1\nEND2", 2, "system relays"),
        ("RD X0.0\nWRT Y0.8\nEND1\nEND2", 2, "bit must be 0–7"),
        ("AND X0.0\nEND1\nEND2", 1, "start the rung with RD"),
        ("RD X0.0\nAND.STK\nEND1\nEND2", 2, "needs two stack entries"),
        ("RD X0.0\nTMR 40\nEND1\nEND2", 2, "timer 40 outside 0–39"),
        ("RD X0.0\nADDB 3, D0, 1, D0\nEND1\nEND2", 2, "format"),
        ("RD X0.0\nADDB 2, D998, 1, D999\nEND1\nEND2", 2, "leave the D table"),
        ("RD X0.0\nJMPB L5\nEND1\nEND2", 2, "no such label"),
        ("RD X0.0\nCALL P3\nEND1\nEND2", 2, "no such subroutine"),
        ("END1\nEND2\nSP P1\nCALLU P2\nSPE\nSP P2\nCALLU P1\nSPE", 7, "calls itself"),
        ("END1\nEND2\nSP P1\nRD X0.0\n", 3, "has no SPE"),
        ("END1\nEND2\nRD X0.0\nWRT Y0.0", 3, "only subroutines"),
        ("RD X0.0\nWRT Y0.0 Y0.1\nEND1\nEND2", 2, "takes 1 operand"),
        ("RD X0.0\nNUMEB 1, 300, D0\nEND1\nEND2", 2, "does not fit"),
        ("SYM X1 Y0.0\nEND1\nEND2", 1, "cannot be a symbol"),
        ("MSG Y0.0 ALARM \"x\"\nEND1\nEND2", 1, "messages are A bits"),
        ("PRESET 中1 5\nEND1\nEND2", 1, "is not a timer"),
        ("PRESET C1 40000\nEND1\nEND2", 1, "out of range"),
        (
            "RD X0.0\nRD.STK X0.0\nRD.STK X0.0\nRD.STK X0.0\nRD.STK X0.0\nRD.STK X0.0\nRD.STK X0.0\nRD.STK X0.0\nRD.STK X0.0\nEND1\nEND2",
            9,
            "deeper than ST0–ST7",
        ),
    ];
    for (text, line, reason) in cases {
        let e = Program::parse(text).expect_err(text);
        assert_eq!(e.line, line, "{text:?}: {e}");
        assert!(e.reason.contains(reason), "{text:?}: {e}");
    }
}

#[test]
fn a_refused_program_leaves_the_running_one_in_charge() {
    let mut p = plc("RD X0.0\nWRT Y0.0");
    scan(&mut p, &["X0.0"], 0);
    let e = p.load("RD X0.0\nWRT Y0.0\nTMRB 1\nEND1\nEND2").unwrap_err();
    assert_eq!(e.line, 3);
    assert!(e.reason.contains("TMRB takes 2 operands"), "{e}");
    scan(&mut p, &[], 10);
    assert!(!bit(&p, "Y0.0"));
    scan(&mut p, &["X0.0"], 20);
    assert!(bit(&p, "Y0.0"), "the old program still scans");
}

#[test]
fn the_standard_program_parses_and_shows_as_rungs() {
    let p = Program::parse(cnc_plc_core::LATHE_STANDARD).unwrap_or_else(|e| panic!("{e}"));
    assert!(p.steps.len() > 300, "{}", p.steps.len());
    let rungs = p.rungs();
    assert!(rungs.len() > 100);
    let first = &p.steps[rungs[0].clone()];
    assert_eq!(first[0].text, "RD.NOT ESTOP_OK");
    assert!(p.messages.contains_key(&(0, 1)));
}
