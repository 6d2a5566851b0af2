//! Signal images exchanged over iceoryx2 every PLC scan: F (NC → PLC) and G (PLC → NC) between
//! motion and plc, Y (PLC → machine) and X (machine → PLC) between plc and io.
//!
//! Each image is the byte table of the Huaxing manual (`000` §18.1, inventory §9.1): F0–F255,
//! G0–G255, X0–X19, Y0–Y19, bit 0 the lowest. Multi-byte values (M code at F10, S at F22, T at
//! F26) are binary, least significant byte first, as in a FANUC PMC. The bit assignments the NC
//! uses are named in [`f`] and [`g`]; [`x`] and [`y`] name the standard lathe's bits that the
//! simulated machine drives (the full wiring table is `docs/plc.md`).

#[cfg(feature = "shm")]
use iceoryx2::prelude::ZeroCopySend;

pub const F_BYTES: usize = 256;
pub const G_BYTES: usize = 256;
pub const X_BYTES: usize = 20;
pub const Y_BYTES: usize = 20;

/// One bit of a signal table: byte number and bit 0–7.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Bit {
    pub byte: u16,
    pub bit: u8,
}

pub const fn bit(byte: u16, bit: u8) -> Bit {
    Bit { byte, bit }
}

impl std::fmt::Display for Bit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.{}", self.byte, self.bit)
    }
}

/// Bit and word access shared by the four images.
pub trait SignalTable {
    fn bytes(&self) -> &[u8];
    fn bytes_mut(&mut self) -> &mut [u8];

    /// False for a bit outside the table.
    fn get(&self, b: Bit) -> bool {
        self.bytes()
            .get(b.byte as usize)
            .is_some_and(|v| v >> (b.bit & 7) & 1 == 1)
    }
    /// A bit outside the table is ignored.
    fn set(&mut self, b: Bit, on: bool) {
        if let Some(v) = self.bytes_mut().get_mut(b.byte as usize) {
            let mask = 1u8 << (b.bit & 7);
            if on {
                *v |= mask;
            } else {
                *v &= !mask;
            }
        }
    }
    /// Four bytes from `byte`, least significant first (0 past the end).
    fn read_i32(&self, byte: usize) -> i32 {
        let mut v = [0u8; 4];
        for (i, d) in v.iter_mut().enumerate() {
            *d = self.bytes().get(byte + i).copied().unwrap_or(0);
        }
        i32::from_le_bytes(v)
    }
    fn write_i32(&mut self, byte: usize, value: i32) {
        for (i, s) in value.to_le_bytes().into_iter().enumerate() {
            if let Some(d) = self.bytes_mut().get_mut(byte + i) {
                *d = s;
            }
        }
    }
}

macro_rules! image {
    ($(#[$doc:meta])* $name:ident, $type_name:literal, $size:ident, { $($(#[$fdoc:meta])* $field:ident: $ty:ty),* }) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq)]
        #[cfg_attr(feature = "shm", derive(ZeroCopySend), type_name($type_name))]
        #[repr(C)]
        pub struct $name {
            /// Increments with every image the sender writes.
            pub seq: u64,
            $($(#[$fdoc])* pub $field: $ty,)*
            pub bytes: [u8; $size],
        }

        impl Default for $name {
            fn default() -> Self {
                $name { seq: 0, $($field: Default::default(),)* bytes: [0; $size] }
            }
        }

        impl SignalTable for $name {
            fn bytes(&self) -> &[u8] {
                &self.bytes
            }
            fn bytes_mut(&mut self) -> &mut [u8] {
                &mut self.bytes
            }
        }
    };
}

image!(
    /// NC → PLC.
    FImage, "cnc_msgs::FImage", F_BYTES, {}
);
image!(
    /// PLC → NC. All zero (as before the PLC's first scan) means emergency stop: `*ESP` is
    /// active low, so a PLC that never answered cannot let the machine move.
    GImage, "cnc_msgs::GImage", G_BYTES, {}
);
image!(
    /// Machine → PLC.
    XImage, "cnc_msgs::XImage", X_BYTES, {
        /// Spindle speed from the encoder, rpm (negative counter-clockwise), for display.
        spindle_actual_rpm: f64,
        /// The spindle's angle from the encoder, degrees (0 ≤ angle < 360), for display.
        spindle_angle_deg: f64
    }
);
image!(
    /// PLC → machine.
    YImage, "cnc_msgs::YImage", Y_BYTES, {
        /// The spindle drive's speed command (the analog output SPLCNT writes), rpm.
        spindle_rpm: f64
    }
);

impl GImage {
    /// The image of a running PLC with no key pressed: emergency stop and feed hold released
    /// (both active low), overrides at 100 %.
    pub fn released() -> Self {
        let mut g = GImage::default();
        g.set(g::ESP_N, true);
        g.set(g::SP_N, true);
        g.set(g::SSTP_N, true);
        g.bytes[g::FEED_OVERRIDE as usize] = 100;
        g.bytes[g::SPINDLE_OVERRIDE as usize] = 100;
        g
    }

    /// Feed override as a fraction: G12 is the percentage in binary (0–200).
    pub fn feed_override(&self) -> f64 {
        f64::from(self.bytes[g::FEED_OVERRIDE as usize]) / 100.0
    }

    /// Rapid override from ROV1/ROV2 (G14.0/G14.1): 100 %, 50 %, 25 % or F0 (0 %, D38).
    pub fn rapid_override(&self) -> f64 {
        match (self.get(g::ROV1), self.get(g::ROV2)) {
            (false, false) => 1.0,
            (true, false) => 0.5,
            (false, true) => 0.25,
            (true, true) => 0.0,
        }
    }
}

/// F signals the NC writes (`000` App.2, inventory §9.4).
pub mod f {
    use super::{bit, Bit};
    /// Automatic operation in progress.
    pub const OP: Bit = bit(0, 7);
    /// Servo ready.
    pub const SA: Bit = bit(0, 6);
    /// Cycle start lamp: automatic operation starting.
    pub const STL: Bit = bit(0, 5);
    /// Feed hold lamp.
    pub const SPL: Bit = bit(0, 4);
    /// CNC ready.
    pub const MA: Bit = bit(1, 7);
    /// Distribution end: no motion commanded, the axes in position.
    pub const DEN: Bit = bit(1, 3);
    /// Resetting.
    pub const RST: Bit = bit(1, 1);
    /// NC alarm.
    pub const AL: Bit = bit(1, 0);
    pub const DRUR: Bit = bit(2, 7);
    /// Cutting feed in progress.
    pub const CUT: Bit = bit(2, 6);
    pub const THRD: Bit = bit(2, 3);
    /// Automatic mode (the only mode of the cell's NC so far).
    pub const MCYC: Bit = bit(3, 5);
    pub const MSBK: Bit = bit(4, 3);
    /// JOG mode selected (F3.2 MJ) and HANDWHEEL mode selected (F3.1 MH).
    pub const MJ: Bit = bit(3, 2);
    pub const MH: Bit = bit(3, 1);
    /// Machine lock in effect (the axes do not move; `000` App.2 F4.1).
    pub const MMLK: Bit = bit(4, 1);
    /// Auxiliary function lock in effect (M, S, T not output; F4.4).
    pub const MAFL: Bit = bit(4, 4);
    /// Block skip in effect (F4.0).
    pub const MBDT: Bit = bit(4, 0);
    /// The handwheel's axis as the NC took it (F208: the HS1 code, 1 X … 6 C, 0 none; D72).
    pub const HANDWHEEL_AXIS: usize = 208;
    /// The handwheel's multiplier in effect: ×1, ×10, ×100 (F209.1, F209.2, F209.3).
    pub const HANDWHEEL_X1: Bit = bit(209, 1);
    pub const HANDWHEEL_X10: Bit = bit(209, 2);
    pub const HANDWHEEL_X100: Bit = bit(209, 3);
    /// Reference return in progress (`000` App.2 F4.5).
    pub const MREF: Bit = bit(4, 5);
    /// Reference return complete of axis `k` (0–5: X, Y, Z, A, B, C; F94.0–F94.5): the
    /// axis knows its machine position.
    pub const fn zp(k: usize) -> Bit {
        bit(94, k as u8)
    }
    pub const TF: Bit = bit(7, 3);
    /// The second auxiliary function's strobe (FANUC BF), carrying the H functions (D107).
    pub const HF: Bit = bit(7, 7);
    pub const SF: Bit = bit(7, 2);
    pub const MF: Bit = bit(7, 0);
    pub const DM00: Bit = bit(9, 7);
    pub const DM01: Bit = bit(9, 6);
    pub const DM02: Bit = bit(9, 5);
    pub const DM30: Bit = bit(9, 4);
    /// M code, 4 bytes binary.
    pub const M_CODE: usize = 10;
    /// S code (rpm), 4 bytes binary.
    pub const S_CODE: usize = 22;
    /// The target tool of the T code (3 for `T0303`), 4 bytes binary.
    pub const T_CODE: usize = 26;
    /// The spindle's stop position for M19, sent with every M code (0 unless positioned:
    /// SPOS, rigid tapping): the angle in 0.001° (4 bytes binary), the way
    /// ([`crate::canon::Turn`]), a count that changes with every positioning and the speed to
    /// position at, rpm (4 bytes binary, 0: the drive's own), so the ladder passes F30–F39 on
    /// to the drive as one (D100, D101).
    pub const ORIENT_ANGLE: usize = 30;
    pub const ORIENT_WAY: usize = 34;
    pub const ORIENT_COUNT: usize = 35;
    pub const ORIENT_SPEED: usize = 36;
    /// The H function with HF: its address (4 bytes binary) and value (8 bytes, IEEE double,
    /// least significant first; D107).
    pub const H_ADDRESS: usize = 40;
    pub const H_VALUE: usize = 44;
}

/// G signals the NC reads (`000` App.2, inventory §9.5).
pub mod g {
    use super::{bit, Bit};
    /// +J of axis `k` (0–5: X, Y, Z, A, B, C): jog key (`000` App.2 G100).
    pub const fn jog_plus(k: usize) -> Bit {
        bit(100, k as u8)
    }
    /// −J of axis `k` (G102).
    pub const fn jog_minus(k: usize) -> Bit {
        bit(102, k as u8)
    }
    /// Manual rapid traverse (G19.7 RT).
    pub const RT: Bit = bit(19, 7);
    /// Step and handwheel multiplier MP1/MP2 (G19.0, G19.1): ×1, ×10 (MP1), ×100 (MP2),
    /// ×1000 (both; a handwheel takes it as ×100) of 0.001 mm (decisions D72). The manual
    /// also names EXMP1/EXMP2 (G19.4, G19.5) for the external handwheel; the NC reads MP1/MP2
    /// only, and the ladder chooses what drives them (the manual's GB02.2).
    pub const MP1: Bit = bit(19, 0);
    pub const MP2: Bit = bit(19, 1);
    /// Handwheel trial run (G19.6, a free bit of the handwheel's byte: the manual gives the
    /// key no signal): in AUTO the program runs as fast as the handwheel turns (D74).
    pub const HANDWHEEL_TRIAL: Bit = bit(19, 6);
    /// Handwheel 1 axis select HS1A–HS1C (G18.0–G18.2): a binary code, 1 X, 2 Y, 3 Z, 4 A,
    /// 5 B, 6 C; 0 no axis.
    pub const HS1A: Bit = bit(18, 0);
    pub const HS1B: Bit = bit(18, 1);
    pub const HS1C: Bit = bit(18, 2);
    /// Machine lock of axis `k` alone (0–5: X, Y, Z, A, B, C; G108, FANUC's each-axis lock;
    /// the mill's Z-axis lock is G108.2; decisions D73).
    pub const fn axis_lock(k: usize) -> Bit {
        bit(108, k as u8)
    }
    /// Completion of the M/S/T function.
    pub const FIN: Bit = bit(4, 3);
    /// Auxiliary function lock: M, S and T are not output, M00/M01/M02/M30 still are
    /// (`000` §13, G5.6).
    pub const AFL: Bit = bit(5, 6);
    /// Cycle start (the NC acts on its rising edge).
    pub const ST: Bit = bit(7, 2);
    /// Feed hold, active low.
    pub const SP_N: Bit = bit(8, 5);
    /// Emergency stop, active low.
    pub const ESP_N: Bit = bit(8, 4);
    /// Spindle stop `*SSTP`, active low (`000` §9.5 G29.6): the NC's spindle output, which on
    /// a turn-mill is the live tool's, stops while it is low and comes back when it rises
    /// (B09.5 = 0: a spindle stop stops the live tool too; D143).
    pub const SSTP_N: Bit = bit(29, 6);
    /// Feed override, percent in binary (FANUC's `*FV` bits in positive logic).
    pub const FEED_OVERRIDE: u16 = 12;
    pub const ROV1: Bit = bit(14, 0);
    pub const ROV2: Bit = bit(14, 1);
    /// Spindle override, percent in binary.
    pub const SPINDLE_OVERRIDE: u16 = 30;
    /// Optional stop switch: not in the manual's G table (the key lamp is PLC-only there), so
    /// it takes the free bit G44.2 next to block skip BDT1 (G44.0).
    pub const MOPS: Bit = bit(44, 2);
    /// Machine lock: the program runs and its positions count, the axes do not move (G44.1).
    pub const MLK: Bit = bit(44, 1);
    /// Block skip: blocks that begin with `/` are skipped (G44.0 BDT1).
    pub const BDT1: Bit = bit(44, 0);
    pub const DRN: Bit = bit(46, 7);
    pub const SBK: Bit = bit(46, 1);
    /// Current tool number of turret 1, binary.
    pub const NTOL: u16 = 68;
}

/// Inputs of the standard lathe (`000` §19.1.7, inventory §9.3). Bits the manual leaves as
/// expansion carry the cell's devices (turret lock, door, air, robot), listed in
/// `docs/plc.md`.
pub mod x {
    use super::{bit, Bit};
    /// Spindle at the commanded speed (the manual's "spindle reached").
    pub const SPINDLE_AT_SPEED: Bit = bit(0, 1);
    pub const CHUCK_CLAMPED: Bit = bit(0, 3);
    /// Some axis is on its − / + overtravel switch (`000` XJ2: X0.2 LIM−, X0.4 LIM+).
    pub const LIMIT_MINUS: Bit = bit(0, 2);
    pub const LIMIT_PLUS: Bit = bit(0, 4);
    pub const CHUCK_UNCLAMPED: Bit = bit(0, 5);
    /// The spindle drive stands at its orientation angle (M19; D94).
    pub const SPINDLE_ORIENTED: Bit = bit(0, 7);
    /// The turret's station or the magazine's pocket, binary (0: between), for a magazine
    /// of more stations than the eight sensors (D94).
    pub const STATION_CODE: u16 = 7;
    /// Emergency stop, normally closed: 1 = released.
    pub const ESP_N: Bit = bit(1, 0);
    /// Turret position sensors, tool 1 … 8.
    pub const TOOL: [Bit; 8] = [
        bit(2, 7),
        bit(3, 7),
        bit(3, 6),
        bit(3, 5),
        bit(3, 4),
        bit(3, 3),
        bit(3, 2),
        bit(3, 1),
    ];
    pub const TAILSTOCK_FORWARD: Bit = bit(4, 0);
    pub const TAILSTOCK_BACK: Bit = bit(4, 1);
    pub const TURRET_LOCKED: Bit = bit(4, 2);
    pub const DOOR_CLOSED: Bit = bit(4, 3);
    pub const DOOR_OPEN: Bit = bit(4, 4);
    /// Air pressure switch: 1 = pressure good.
    pub const AIR_OK: Bit = bit(4, 5);
    pub const COOLANT_PRESSURE: Bit = bit(4, 6);
    /// Lubrication pressure / level good.
    pub const LUBE_OK: Bit = bit(4, 7);
    /// The external handwheel's switches on XJ3 (`000` §19.4.2.4) the simulated lathe has:
    /// axis select X (X2.1), Z (X6.0), and multiplier ×10 (X2.2), ×100 (X2.3); neither is ×1.
    /// (Y's, X2.0, is wired by the standard ladder for a machine that has Y.)
    pub const HANDWHEEL_SELECT_X: Bit = bit(2, 1);
    pub const HANDWHEEL_SELECT_Z: Bit = bit(6, 0);
    pub const HANDWHEEL_X10: Bit = bit(2, 2);
    pub const HANDWHEEL_X100: Bit = bit(2, 3);
    /// The handwheel-trial key (the cell's; `000` §13.3 "手轮试切/手轮倍率"; D74).
    pub const KEY_HANDWHEEL_TRIAL: Bit = bit(9, 1);
    /// The mill panel's Z-axis lock key (the cell's; `003` part 2 §2.1.2; decisions D73).
    pub const KEY_Z_AXIS_LOCK: Bit = bit(9, 0);
    /// Robot: clear of the work area.
    pub const ROBOT_CLEAR: Bit = bit(8, 0);
    pub const ROBOT_CHUCK_OPEN: Bit = bit(8, 1);
    pub const ROBOT_CHUCK_CLOSE: Bit = bit(8, 2);
    pub const ROBOT_DOOR_OPEN: Bit = bit(8, 3);
    pub const ROBOT_DOOR_CLOSE: Bit = bit(8, 4);
    pub const ROBOT_CYCLE_START: Bit = bit(8, 5);
    /// Panel keys (X10–X15 of the manual).
    pub const KEY_CYCLE_START: Bit = bit(13, 1);
    pub const KEY_FEED_HOLD: Bit = bit(15, 3);
    pub const KEY_RESET: Bit = bit(15, 6);
    pub const KEY_SINGLE_BLOCK: Bit = bit(10, 3);
    /// Feed override switch, percent in binary (a coded rotary switch on the panel).
    pub const FEED_OVERRIDE_SWITCH: u16 = 16;
    /// Spindle override switch, percent in binary.
    pub const SPINDLE_OVERRIDE_SWITCH: u16 = 17;
    /// Rapid override switch, as G14's ROV2/ROV1 code: 0 = 100 %, 1 = 50 %, 2 = 25 %, 3 = F0.
    pub const RAPID_OVERRIDE_SWITCH: u16 = 18;
    /// Program-proving keys. The manual has them as soft keys of its screen (enabled by
    /// GB35); the cell's panel gives them the free byte X19 (decisions D66).
    pub const KEY_MACHINE_LOCK: Bit = bit(19, 0);
    pub const KEY_AUX_LOCK: Bit = bit(19, 1);
    pub const KEY_DRY_RUN: Bit = bit(19, 2);
    pub const KEY_BLOCK_SKIP: Bit = bit(19, 3);
    /// Jog keys +X, −X, +Z, −Z (the cell's own byte X19, as the proving keys; D71).
    pub const KEY_JOG_PLUS_X: Bit = bit(19, 4);
    pub const KEY_JOG_MINUS_X: Bit = bit(19, 5);
    pub const KEY_JOG_PLUS_Z: Bit = bit(19, 6);
    pub const KEY_JOG_MINUS_Z: Bit = bit(19, 7);
}

/// Outputs of the standard lathe (`000` §19.1.6, inventory §9.3).
pub mod y {
    use super::{bit, Bit};
    pub const COOLANT: Bit = bit(1, 3);
    pub const CHUCK_CLAMP: Bit = bit(1, 7);
    pub const TAILSTOCK_BACK: Bit = bit(2, 0);
    pub const LAMP_RED: Bit = bit(2, 1);
    pub const CHUCK_UNCLAMP: Bit = bit(2, 2);
    pub const SPINDLE_BRAKE: Bit = bit(2, 3);
    pub const TAILSTOCK_FORWARD: Bit = bit(2, 4);
    pub const TURRET_CW: Bit = bit(2, 5);
    pub const TURRET_CCW: Bit = bit(2, 6);
    pub const SPINDLE_CW: Bit = bit(3, 0);
    pub const SPINDLE_CCW: Bit = bit(3, 1);
    /// Orient the spindle: with neither direction on, the drive positions it at its
    /// orientation angle and holds it there (M19; D94).
    pub const SPINDLE_ORIENT: Bit = bit(3, 2);
    /// Releases the turret lock (0 = locked: a turret without power stays locked).
    pub const TURRET_UNLOCK: Bit = bit(4, 0);
    pub const DOOR_OPEN: Bit = bit(4, 2);
    pub const DOOR_CLOSE: Bit = bit(4, 3);
    /// Cell: the machine waits for the robot to load a part.
    pub const READY_FOR_LOAD: Bit = bit(5, 0);
    /// Cell: the last cycle ended with M30/M02.
    pub const CYCLE_COMPLETE: Bit = bit(5, 1);
    /// The spindle drive's stop position while SPINDLE_ORIENT holds: F30–F39 as the ladder
    /// copied them (angle 0.001°, way, count, speed rpm; D100, D101).
    pub const ORIENT_ANGLE: usize = 8;
    pub const ORIENT_WAY: usize = 12;
    pub const ORIENT_COUNT: usize = 13;
    pub const ORIENT_SPEED: usize = 14;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bits_and_words_round_trip() {
        let mut f = FImage::default();
        f.set(f::MF, true);
        f.write_i32(f::M_CODE, 1234);
        assert!(f.get(f::MF));
        assert_eq!(f.bytes[7], 1);
        assert_eq!(f.read_i32(f::M_CODE), 1234);
        assert_eq!(f.bytes[10..14], [0xd2, 0x04, 0, 0]);
        f.set(f::MF, false);
        assert_eq!(f.bytes[7], 0);
        // Out of the table: ignored, reads false.
        f.set(bit(999, 0), true);
        assert!(!f.get(bit(999, 0)));
        let g = GImage::released();
        assert!(g.get(g::ESP_N) && g.get(g::SP_N));
        assert_eq!(g.feed_override(), 1.0);
        assert_eq!(g.rapid_override(), 1.0);
        assert!(!GImage::default().get(g::ESP_N));
    }
}
