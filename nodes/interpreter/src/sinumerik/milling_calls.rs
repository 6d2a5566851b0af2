//! The 802D's milling cycles called (`001` §10.6): each one's parameters read from the call
//! (`cycle_call.rs`), its modes resolved against the machine's state (the spindle's direction
//! for climb and conventional milling, the active cutting edge's radius), its moves made by
//! its pure function (`thread_mill.rs`, `pocket.rs`, `rect_pocket.rs`, `spigot.rs`) and
//! emitted (`cutter_path.rs`).

use cnc_interpreter_core::{ProgramError, SpindleDir};

use super::cycle_call::CycleCall;
use super::drilling::CycleAlarm;
use super::face::{face_milling, Face};
use super::pocket::{circular_pocket, CirclePocket, Insertion};
use super::rect_pocket::{rectangular_pocket, RectPocket};
use super::slots::{arc_slots, long_holes, slots, ArcSlot, Pattern, Slot};
use super::spigot::{spigot, Spigot};
use super::thread_mill::{thread_milling, Thread};
use super::Sinumerik;

impl Sinumerik {
    /// LONGHOLE, SLOT1 and SLOT2: holes or slots on a circle with the active cutting edge;
    /// the slots finish at SSF when it is given.
    pub(super) fn slots(&mut self, c: &CycleCall) -> Result<(), ProgramError> {
        let (rtp, rfp) = (c.or("RTP", 0.0), c.or("RFP", 0.0));
        let dp = match c.get("DPR").filter(|d| *d != 0.0) {
            Some(r) => rfp - (rtp - rfp).signum() * r.abs(),
            None => c.or("DP", rfp),
        };
        let p = Pattern {
            rtp,
            rfp,
            sdis: c.or("SDIS", 0.0),
            dp,
            num: c.or("NUM", 0.0).round().clamp(0.0, 9_999.0) as usize,
            leng: c.or("LENG", 0.0).abs(),
            centre: (c.or("CPA", 0.0), c.or("CPO", 0.0)),
            rad: c.or("RAD", 0.0),
            sta1: c.or("STA1", 0.0),
            inda: c.or("INDA", 0.0),
            ffd: c.or("FFD", 0.0),
            ffp1: c.or("FFP1", 0.0),
            mid: c.or("MID", 0.0).abs(),
        };
        let radius = self.offset_entry().map(|e| e.radius);
        if c.name == "LONGHOLE" {
            let (h, v) = self.core.plane_axes()?;
            let here = self.core.work_position();
            let moves = long_holes(p, radius, (here[h], here[v]))
                .map_err(|a| self.cycle_alarm(a, c.name))?;
            return self.run_path(moves);
        }
        let s = Slot {
            wid: c.or("WID", 0.0).abs(),
            // CDIR 2 is G2; anything else G3, as the manual's message says.
            ccw: c.or("CDIR", 3.0).round() != 2.0,
            fal: c.or("FAL", 0.0),
            vari: c.or("VARI", 0.0).round() as i64,
            midf: c.or("MIDF", 0.0).abs(),
            ffp2: c.or("FFP2", 0.0),
        };
        let made = if c.name == "SLOT2" {
            let arc = ArcSlot {
                afsl: c.or("AFSL", 0.0),
                slot: s,
            };
            arc_slots(p, arc, radius)
        } else {
            slots(p, s, radius)
        };
        let (rough, finish) = made.map_err(|a| self.cycle_alarm(a, c.name))?;
        self.run_path(rough)?;
        let before = self.core.rpm;
        let ssf = c.get("SSF").filter(|s| *s > 0.0 && !finish.is_empty());
        if let Some(s) = ssf {
            self.core.set_rpm(s);
        }
        self.run_path(finish)?;
        if ssf.is_some() {
            self.core.set_rpm(before);
        }
        Ok(())
    }

    /// CYCLE71: face milling with the active cutting edge.
    pub(super) fn face(&mut self, c: &CycleCall) -> Result<(), ProgramError> {
        let p = Face {
            rtp: c.or("RTP", 0.0),
            rfp: c.or("RFP", 0.0),
            sdis: c.or("SDIS", 0.0),
            dp: c.or("DP", 0.0),
            corner: (c.or("PA", 0.0), c.or("PO", 0.0)),
            leng: c.or("LENG", 0.0),
            wid: c.or("WID", 0.0),
            sta: c.or("STA", 0.0),
            mid: c.or("MID", 0.0).abs(),
            mida: c.or("MIDA", 0.0).abs(),
            fdp: c.or("FDP", 0.0),
            fald: c.or("FALD", 0.0).abs(),
            ffp1: c.or("FFP1", 0.0),
            vari: c.or("VARI", 0.0).round() as i64,
            fdp1: c.or("FDP1", 0.0),
        };
        let radius = self.offset_entry().map(|e| e.radius);
        let moves = face_milling(p, radius).map_err(|a| self.cycle_alarm(a, c.name))?;
        self.run_path(moves)
    }

    /// CYCLE90: the thread milled about CPA/CPO with the active cutting edge's radius.
    pub(super) fn mill_thread(&mut self, c: &CycleCall) -> Result<(), ProgramError> {
        let (rtp, rfp) = (c.or("RTP", 0.0), c.or("RFP", 0.0));
        let bottom = match (c.get("DPR").filter(|d| *d != 0.0), c.get("DP")) {
            (Some(r), _) => rfp - (rtp - rfp).signum() * r.abs(),
            (None, Some(dp)) => dp,
            (None, None) => rfp,
        };
        let external = match c.or("TYPTH", 0.0).round() as i64 {
            0 => false,
            1 => true,
            _ => {
                return Err(self.cycle_alarm(
                    CycleAlarm {
                        number: 61002,
                        text: "TYPTH is 0 (internal) or 1 (external)".into(),
                    },
                    c.name,
                ))
            }
        };
        let t = Thread {
            rtp,
            rfp,
            sdis: c.or("SDIS", 0.0),
            bottom,
            diath: c.or("DIATH", 0.0),
            kdiam: c.or("KDIAM", 0.0),
            pit: c.or("PIT", 0.0),
            ffr: c.or("FFR", 0.0),
            // CDIR 2 is G2; anything else G3, as the manual's message says.
            ccw: c.or("CDIR", 3.0).round() != 2.0,
            external,
            centre: (c.or("CPA", 0.0), c.or("CPO", 0.0)),
        };
        let radius = self.offset_entry().map(|e| e.radius);
        let moves = thread_milling(t, radius).map_err(|a| self.cycle_alarm(a, c.name))?;
        self.run_path(moves)
    }

    /// POCKET3/POCKET4's VARI and CDIR: roughing or finishing, the insertion, G3 or G2.
    fn pocket_modes(&self, c: &CycleCall) -> Result<(bool, Insertion, bool), ProgramError> {
        let wrong = |number: u32, text: &str| {
            self.cycle_alarm(
                CycleAlarm {
                    number,
                    text: text.into(),
                },
                c.name,
            )
        };
        let vari = c.or("VARI", 0.0).round() as i64;
        let roughing = match vari % 10 {
            1 => true,
            2 => false,
            _ => return Err(wrong(61002, "VARI: units 1 roughing, 2 finishing")),
        };
        let insertion = match vari / 10 {
            0 | 1 => Insertion::Vertical,
            2 => Insertion::Helix {
                radius: c.or("RAD1", 0.0),
                per_turn: c.or("DP1", 0.0),
            },
            3 if c.name == "POCKET3" => Insertion::Reciprocating {
                angle: c.or("RAD1", 0.0),
            },
            _ => return Err(wrong(61002, "VARI: tens 0/1 vertical, 2 helical insertion")),
        };
        let ccw = match (c.or("CDIR", 0.0).round() as i64, self.core.spindle()) {
            (2, _) => false,
            (3, _) => true,
            // Climb: the tooth leaves the wall it finishes, the chip thick to thin (D87, issue
            // 46). Inside a pocket that is counter-clockwise under M3 (the wall on the right
            // of the travel), clockwise under M4; conventional the other way.
            (0, SpindleDir::Cw | SpindleDir::Stopped) | (1, SpindleDir::Ccw) => true,
            (0, SpindleDir::Ccw) | (1, _) => false,
            _ => {
                return Err(wrong(
                    61109,
                    "CDIR is 0 climb, 1 conventional, 2 G2 or 3 G3",
                ))
            }
        };
        Ok((roughing, insertion, ccw))
    }

    /// CYCLE76/CYCLE77: the rectangular or circular spigot with the active cutting edge.
    pub(super) fn spigot(&mut self, c: &CycleCall) -> Result<(), ProgramError> {
        let wrong = |text: &str| {
            self.cycle_alarm(
                CycleAlarm {
                    number: 61002,
                    text: text.into(),
                },
                c.name,
            )
        };
        let roughing = match c.or("VARI", 0.0).round() as i64 {
            1 => true,
            2 => false,
            _ => return Err(wrong("VARI is 1 roughing or 2 finishing")),
        };
        // Climb round a spigot is clockwise under M3 (the spigot on the right of the travel),
        // counter-clockwise under M4; conventional the other way (D87, issue 46: §10.6.4's
        // table "M3→G3" is the pocket's, against the definition it gives).
        let ccw = match (c.or("CDIR", 0.0).round() as i64, self.core.spindle()) {
            (2, _) => false,
            (3, _) => true,
            (0, SpindleDir::Cw | SpindleDir::Stopped) | (1, SpindleDir::Ccw) => false,
            (0, SpindleDir::Ccw) | (1, _) => true,
            _ => return Err(wrong("CDIR is 0 climb, 1 conventional, 2 G2 or 3 G3")),
        };
        let (rtp, rfp) = (c.or("RTP", 0.0), c.or("RFP", 0.0));
        let dp = match c.get("DPR").filter(|d| *d != 0.0) {
            Some(r) => rfp - (rtp - rfp).signum() * r.abs(),
            None => c.or("DP", rfp),
        };
        let round = c.name == "CYCLE77";
        let (half, crad, blank) = if round {
            let r = c.or("PRAD", 0.0).abs() / 2.0;
            // The round blank's farthest point from the spigot, at 45°.
            let b = c.get("AP1").filter(|v| *v > 0.0).map(|d| {
                let h = d / 2.0 / std::f64::consts::SQRT_2;
                (h, h)
            });
            ((r, r), r, b)
        } else {
            let blank = match (c.get("AP1"), c.get("AP2")) {
                (Some(l), Some(w)) if l > 0.0 && w > 0.0 => Some((l / 2.0, w / 2.0)),
                _ => None,
            };
            (
                (c.or("LENG", 0.0).abs() / 2.0, c.or("WID", 0.0).abs() / 2.0),
                c.or("CRAD", 0.0).abs(),
                blank,
            )
        };
        let p = Spigot {
            rtp,
            rfp,
            sdis: c.or("SDIS", 0.0),
            dp,
            half,
            crad,
            centre: (c.or("PA", 0.0), c.or("PO", 0.0)),
            sta: if round { 0.0 } else { c.or("STA", 0.0) },
            mid: c.or("MID", 0.0).abs(),
            fal: c.or("FAL", 0.0).abs(),
            fald: c.or("FALD", 0.0).abs(),
            ffp1: c.or("FFP1", 0.0),
            ffd: c.or("FFD", 0.0),
            ccw,
            roughing,
            blank,
        };
        let radius = self.offset_entry().map(|e| e.radius);
        let moves = spigot(p, radius).map_err(|a| self.cycle_alarm(a, c.name))?;
        self.run_path(moves)
    }

    /// POCKET3: the rectangular pocket with the active cutting edge.
    pub(super) fn rectangular_pocket(&mut self, c: &CycleCall) -> Result<(), ProgramError> {
        let (roughing, insertion, ccw) = self.pocket_modes(c)?;
        let p = RectPocket {
            rtp: c.or("RTP", 0.0),
            rfp: c.or("RFP", 0.0),
            sdis: c.or("SDIS", 0.0),
            dp: c.or("DP", 0.0),
            leng: c.or("LENG", 0.0),
            wid: c.or("WID", 0.0),
            crad: c.or("CRAD", 0.0).abs(),
            centre: (c.or("PA", 0.0), c.or("PO", 0.0)),
            sta: c.or("STA", 0.0),
            mid: c.or("MID", 0.0).abs(),
            fal: c.or("FAL", 0.0).abs(),
            fald: c.or("FALD", 0.0).abs(),
            ffp1: c.or("FFP1", 0.0),
            ffd: c.or("FFD", 0.0),
            ccw,
            roughing,
            insertion,
            mida: c.or("MIDA", 0.0).abs(),
        };
        let radius = self.offset_entry().map(|e| e.radius);
        let moves = rectangular_pocket(p, radius).map_err(|a| self.cycle_alarm(a, c.name))?;
        self.run_path(moves)
    }

    /// POCKET4: the circular pocket with the active cutting edge.
    pub(super) fn circular_pocket(&mut self, c: &CycleCall) -> Result<(), ProgramError> {
        let (roughing, insertion, ccw) = self.pocket_modes(c)?;
        let p = CirclePocket {
            rtp: c.or("RTP", 0.0),
            rfp: c.or("RFP", 0.0),
            sdis: c.or("SDIS", 0.0),
            dp: c.or("DP", 0.0),
            prad: c.or("PRAD", 0.0),
            centre: (c.or("PA", 0.0), c.or("PO", 0.0)),
            mid: c.or("MID", 0.0).abs(),
            fal: c.or("FAL", 0.0).abs(),
            fald: c.or("FALD", 0.0).abs(),
            ffp1: c.or("FFP1", 0.0),
            ffd: c.or("FFD", 0.0),
            ccw,
            roughing,
            insertion,
            mida: c.or("MIDA", 0.0).abs(),
        };
        let radius = self.offset_entry().map(|e| e.radius);
        let moves = circular_pocket(p, radius).map_err(|a| self.cycle_alarm(a, c.name))?;
        self.run_path(moves)
    }
}
