//! Lines, circles, helices and polar moves (`001` §9.2.5, §9.3.1–§9.3.6, §9.3.22): the end
//! point from the axis words (G90/G91, AC/IC, inches), or from the pole with AP/RP; a circle
//! by centre (I/J/K from the start, or `=AC(…)`), by radius CR (negative: more than a
//! semicircle), by opening angle AR with the centre or the end, by the pole (AP/RP), through an
//! intermediate point (CIP) or tangent to the path before it (CT); TURN= full turns more for a
//! helix.

use std::f64::consts::TAU;

use cnc_interpreter_core::geometry::{
    arc_sweep, center_from_radius, check_center, three_point, ArcError, Pt, ARC_TOLERANCE,
};
use cnc_interpreter_core::{Command, Fault, MoveKind, ProgramError, Turn, NO_WORK_OFFSET};

use super::contour::AngStep;
use super::exec::{Mode, Words};
use super::{Motion, Sinumerik};

/// The words that belong to a circle (a block with one of them moves).
const ARC_WORDS: [&str; 9] = ["I", "J", "K", "CR", "AR", "I1", "J1", "K1", "TURN"];

/// The interpolation parameter of an axis: I for X, J for Y, K for Z.
fn centre_letter(axis: char) -> Option<char> {
    match axis {
        'X' => Some('I'),
        'Y' => Some('J'),
        'Z' => Some('K'),
        _ => None,
    }
}

fn rotate(p: Pt, c: Pt, radians: f64) -> Pt {
    let (s, co) = radians.sin_cos();
    let (dz, dr) = (p.z - c.z, p.r - c.r);
    Pt::new(c.z + dz * co - dr * s, c.r + dz * s + dr * co)
}

impl Sinumerik {
    /// The non-modal instructions that take the block's words for themselves: dwell,
    /// frames, pole; `true` when the block moves nothing else.
    pub(super) fn non_modal(&mut self, w: &Words) -> Result<bool, ProgramError> {
        if let Some(sf) = w.get("SF") {
            if !(0.0..360.0).contains(&sf) {
                return Err(self.fault(Fault::OutOfRange, "SF= is 0…359.999 degrees"));
            }
            self.thread_angle = sf;
        }
        if let Some(offn) = w.get("OFFN") {
            self.set_contour_offset(offn)?;
        }
        if w.has_g(4) {
            return self.dwell(w).map(|()| true);
        }
        if self.limits_block(w)? {
            return Ok(true);
        }
        if w.has_g(74) {
            let reference = self.core.setup.reference.clone();
            return self
                .machine_point_approach(w, "G74", |i| reference.get(i).copied())
                .map(|()| true);
        }
        if w.has_g(75) {
            return self.fixed_point_approach(w).map(|()| true);
        }
        if w.addr.contains_key("FP") {
            return Err(self.fault(Fault::IllegalWord, "FP= belongs to G75"));
        }
        if self.frame_instruction(w)? {
            return Ok(true);
        }
        if let Some(g) = [110, 111, 112].into_iter().find(|&g| w.has_g(g)) {
            self.set_pole(g, w)?;
            return Ok(true);
        }
        Ok(false)
    }

    /// G75 (§9.3.10): the axes named to fixed point FP=n (1–4, default 1) of the machine
    /// data (D102).
    fn fixed_point_approach(&mut self, w: &Words) -> Result<(), ProgramError> {
        let n = match w.get("FP") {
            None => 1,
            Some(v) if v.fract() == 0.0 && (1.0..=4.0).contains(&v) => v as usize,
            Some(v) => {
                return Err(self.fault(
                    Fault::OutOfRange,
                    format!(
                        "FP={}: the fixed points are 1…4",
                        cnc_interpreter_core::show(v)
                    ),
                ))
            }
        };
        let points = self.core.setup.fixed_points.clone();
        self.machine_point_approach(w, "G75", |i| {
            points.get(i).and_then(|p| p.get(n - 1)).copied()
        })
    }

    /// G74 (§9.3.23) and G75: each axis named (`X1=0`; the value is not used) to its point
    /// (`point` of the axis index: the reference or a fixed point) at rapid, each axis at its
    /// own rate, in machine coordinates, no offset applied; an own block, not under radius
    /// compensation. An axis without the point stops the block before anything moves.
    fn machine_point_approach(
        &mut self,
        w: &Words,
        what: &str,
        point: impl Fn(usize) -> Option<f64>,
    ) -> Result<(), ProgramError> {
        if self.core.comp.is_some() {
            return Err(self.fault(
                Fault::CompInCycle,
                format!("{what} while radius compensation is active: G40 first"),
            ));
        }
        if w.axes.is_empty() {
            return Err(self.fault(
                Fault::MissingWord,
                format!("{what} names the axes: X1=0 Y1=0 Z1=0"),
            ));
        }
        let mut target = self.core.pos.clone();
        for (&i, _) in w.axes.iter() {
            target[i] = point(i).ok_or_else(|| {
                self.fault(
                    Fault::OutOfRange,
                    format!(
                        "{what}: axis {} has no such point in the machine data",
                        self.core.setup.axes[i]
                    ),
                )
            })?;
        }
        self.core.push(Command::Rapid {
            end: target.clone(),
        });
        self.core.pos = target;
        Ok(())
    }

    /// G4 F seconds or S spindle revolutions (§9.3.22); F and S stay as they were.
    fn dwell(&mut self, w: &Words) -> Result<(), ProgramError> {
        let seconds = match (w.get("F"), w.get("S")) {
            (Some(f), None) => f,
            (None, Some(s)) => {
                if self.core.rpm <= 0.0 {
                    return Err(
                        self.fault(Fault::DwellTime, "G4 S needs a spindle speed programmed")
                    );
                }
                s * 60.0 / self.core.rpm
            }
            _ => {
                return Err(self.fault(Fault::DwellTime, "G4 needs F (seconds) or S (revolutions)"))
            }
        };
        if !(0.001..=99_999.999).contains(&seconds) {
            return Err(self.fault(Fault::DwellTime, "dwell outside 0.001…99999.999"));
        }
        self.core.push(Command::Dwell { seconds });
        Ok(())
    }

    /// G110 (from the last position), G111 (from the work zero), G112 (from the last pole):
    /// the pole, given in the plane's axes or polar (§9.2.5).
    fn set_pole(&mut self, g: u32, w: &Words) -> Result<(), ProgramError> {
        let (h, v) = self.core.plane_axes()?;
        let base = match g {
            110 => self.core.plane_point(&self.core.work_position())?,
            111 => Pt::new(0.0, 0.0),
            _ => self.pole,
        };
        let unit = self.unit();
        let polar = w.addr.contains_key("AP") || w.addr.contains_key("RP");
        self.pole = if polar {
            let ap = w.get("AP").unwrap_or(0.0);
            let rp = w.get("RP").unwrap_or(0.0) * unit;
            let (s, c) = ap.to_radians().sin_cos();
            Pt::new(base.z + rp * c, base.r + rp * s)
        } else {
            let get = |i: usize| w.axes.get(&i).map_or(0.0, |a| a.0 * unit);
            Pt::new(base.z + get(h), base.r + get(v))
        };
        self.polar = (0.0, 0.0);
        Ok(())
    }

    fn unit(&self) -> f64 {
        if self.inch {
            25.4
        } else {
            1.0
        }
    }

    /// Whether machine axis `i` is a rotary axis (A, B, C: degrees).
    pub(super) fn rotary_axis(&self, i: usize) -> bool {
        self.core
            .setup
            .axes
            .get(i)
            .is_some_and(|c| "ABC".contains(*c))
    }

    /// The feed of a line from `here` to `end` along all its axes, so that F holds for the
    /// linear axes and the rotary axes follow in the same time; a rotary axis alone runs at F
    /// in degrees per minute (§9.3.21, D109). Motion takes a feed along all axes.
    fn rotary_feed(&self, feed: f64, here: &[f64], end: &[f64]) -> f64 {
        let (mut linear, mut rotary) = (0.0, 0.0);
        for (i, (a, b)) in here.iter().zip(end).enumerate() {
            let d = (b - a) * (b - a);
            if self.rotary_axis(i) {
                rotary += d;
            } else {
                linear += d;
            }
        }
        if rotary > 0.0 && linear > 1e-18 {
            // A short line with a long turn would ask for more than any feed: the control's
            // largest, which the axes' own limits slow further.
            let limit = self.core.feed_limit().max(feed);
            (feed * ((linear + rotary) / linear).sqrt()).min(limit)
        } else {
            feed
        }
    }

    /// The block's move, if it has one.
    pub(super) fn motion_block(&mut self, w: &Words) -> Result<(), ProgramError> {
        let polar = w.addr.contains_key("AP") || w.addr.contains_key("RP");
        let moves = !w.axes.is_empty()
            || polar
            || w.addr.contains_key("ANG")
            || ARC_WORDS.iter().any(|k| w.addr.contains_key(*k));
        self.corner = self.block_corner(w, moves)?;
        let wab = super::wab::code(w);
        if wab.is_none() {
            for k in ["DISR", "DISCL", "FAD"] {
                if w.addr.contains_key(k) {
                    return Err(self.fault(
                        Fault::IllegalWord,
                        format!("{k}= belongs to a WAB block (G147…G348)"),
                    ));
                }
            }
        }
        let probe = self.measuring_words(w)?;
        if probe.is_some() && !moves {
            return Err(self.fault(
                Fault::MissingWord,
                "MEAS/MEAW measure during the block's move: program the axes to move",
            ));
        }
        if probe.is_some() && w.fxs.is_some() {
            return Err(self.fault(
                Fault::IllegalWord,
                "MEAS and FXS are not programmed in one block (§9.3.23)",
            ));
        }
        if w.fxs.is_some() && !moves {
            return Err(self.fault(
                Fault::MissingWord,
                "FXS is selected and deselected in the block of a move (§9.3.23)",
            ));
        }
        self.check_clamped_axes(w)?;
        if !moves && wab.is_none() {
            return Ok(());
        }
        if w.has_g(53) || w.has_g(153) {
            if wab.is_some() {
                return Err(self.fault(
                    Fault::IllegalWord,
                    "WAB (G147…G348) moves in the work's coordinates, not with G53/G153",
                ));
            }
            return self.machine_coordinates(w);
        }
        // Where the block starts and ends in the work's coordinates, in lists kept from block
        // to block (a move a block is the front end's most frequent work).
        let mut here = std::mem::take(&mut self.here_room);
        self.core.work_position_into(&mut here);
        let mut end = std::mem::take(&mut self.end_room);
        end.clone_from(&here);
        let done = self.move_to(w, &here, &mut end, polar, probe, wab);
        self.here_room = here;
        self.end_room = end;
        done
    }

    /// The block's move from `here` to `end` (the work's coordinates; `end` as the position
    /// stands, the block's axis words still to apply).
    fn move_to(
        &mut self,
        w: &Words,
        here: &[f64],
        end: &mut [f64],
        polar: bool,
        probe: Option<(bool, bool)>,
        wab: Option<(super::wab::Shape, bool)>,
    ) -> Result<(), ProgramError> {
        let unit = self.unit();
        for (&i, &(v, mode)) in w.axes.iter() {
            let linear = !self.rotary_axis(i);
            let v = if linear { v * unit } else { v };
            end[i] = match mode {
                Mode::Rotary(way) => rotary_target(here[i], v, way),
                Mode::Abs => v,
                Mode::Inc => here[i] + v,
                Mode::Modal if self.absolute => v,
                Mode::Modal => here[i] + v,
            };
        }
        let circle = matches!(self.motion, Motion::Cw | Motion::Ccw);
        if polar {
            let (ap, rp) = self.polar_words(w)?;
            let (s, c) = ap.to_radians().sin_cos();
            let p = Pt::new(self.pole.z + rp * c, self.pole.r + rp * s);
            self.core.set_plane_point(end, p);
        }
        if let Some((rising, stop)) = probe {
            return self.measuring_move(w, here, end, rising, stop);
        }
        if self.fixed_stop_move(w, end)? {
            return Ok(());
        }
        if let Some(code) = wab {
            let (h, v) = self.core.plane_axes()?;
            let normal = self.core.plane_normal();
            let plane = polar || w.axes.iter().any(|(i, _)| *i == h || *i == v);
            let on_normal = w.axes.iter().any(|(i, _)| Some(*i) == normal);
            return self.wab_block(w, code, end.to_vec(), (plane, on_normal));
        }
        let threads = matches!(self.motion, Motion::Thread | Motion::TapIn | Motion::TapOut);
        if self.wab.is_some() && (threads || w.has_g(63)) {
            return Err(self.fault(
                Fault::CompBlocks,
                "WAB: the contour after an approach starts with G1, G2 or G3, not a thread",
            ));
        }
        // A waiting approach starts compensation with its own first move.
        if self.wab.is_none() {
            self.start_compensation()?;
        }
        if threads || w.has_g(63) {
            return self.thread_move(w, here, end);
        }
        let a = self.core.plane_point(here)?;
        let b = self.core.plane_point(end)?;
        let feed = self.core.feed;
        match self.motion {
            Motion::Rapid | Motion::Line => {
                if let Some(k) = ARC_WORDS.iter().find(|k| w.addr.contains_key(**k)) {
                    return Err(self.fault(
                        Fault::IllegalWord,
                        format!("{k} belongs to a circle (G2/G3/CIP)"),
                    ));
                }
                let kind = if self.motion == Motion::Rapid {
                    MoveKind::Rapid
                } else {
                    MoveKind::Feed(self.rotary_feed(feed, here, end))
                };
                let a = match self.ang_end(w, here, end, kind)? {
                    AngStep::Wait => return Ok(()),
                    AngStep::Via(corner) => self.core.plane_point(&corner)?,
                    AngStep::Plain => a,
                };
                let b = self.core.plane_point(end)?;
                self.emit_element(end, kind)?;
                if a.dist(b) > 1e-9 {
                    let l = a.dist(b);
                    self.tangent = Some(Pt::new((b.z - a.z) / l, (b.r - a.r) / l));
                }
            }
            _ => {
                if w.addr.contains_key("ANG") || self.ang.is_some() {
                    return Err(self.fault(
                        Fault::IllegalWord,
                        "ANG defines straight lines (G0/G1), not circles",
                    ));
                }
                let (c, ccw) = if circle {
                    self.circle(w, a, end, polar)?
                } else if self.motion == Motion::Cip {
                    self.through_point(w, a, end, here)?
                } else {
                    self.tangential(a, b)?
                };
                self.arc_to(here, end, c, ccw, w.get("TURN"), feed)?;
            }
        }
        Ok(())
    }

    /// `MEAS=±1` / `MEAW=±1` (§9.3.12): the probe's rising (1) or falling (−1) edge of
    /// measuring input 1, with (MEAS) or without (MEAW) delete distance to go.
    fn measuring_words(&self, w: &Words) -> Result<Option<(bool, bool)>, ProgramError> {
        if w.addr.is_empty() {
            return Ok(None);
        }
        let (value, stop) = match (w.get("MEAS"), w.get("MEAW")) {
            (None, None) => return Ok(None),
            (Some(_), Some(_)) => {
                return Err(self.fault(
                    Fault::IllegalWord,
                    "MEAS and MEAW in one block: one measuring job per block",
                ))
            }
            (Some(v), None) => (v, true),
            (None, Some(v)) => (v, false),
        };
        match value {
            1.0 => Ok(Some((true, stop))),
            -1.0 => Ok(Some((false, stop))),
            v => Err(self.fault(
                Fault::OutOfRange,
                format!(
                    "{}={}: 1 measures at the probe's rising edge, -1 at its falling edge \
                     (measuring input 1)",
                    if stop { "MEAS" } else { "MEAW" },
                    cnc_interpreter_core::show(v)
                ),
            )),
        }
    }

    /// A measuring block (§9.3.12): a straight G1 line to `end` while the probe's edge
    /// latches the axes; the program reads on once the machine has measured (D116).
    fn measuring_move(
        &mut self,
        w: &Words,
        here: &[f64],
        end: &[f64],
        rising: bool,
        stop: bool,
    ) -> Result<(), ProgramError> {
        let circle_words = ["I", "J", "K", "CR", "AR", "I1", "J1", "K1", "TURN", "ANG"];
        let other = circle_words.iter().find(|k| w.addr.contains_key(**k));
        if self.motion != Motion::Line || other.is_some() || self.ang.is_some() {
            return Err(self.fault(
                Fault::NotSupported,
                "MEAS/MEAW measure along a straight G1 line here (not G0, circles, ANG or threads)",
            ));
        }
        if self.corner.is_some() || self.wab.is_some() || w.has_g(63) || self.core.holding() {
            return Err(self.fault(
                Fault::NotSupported,
                "a measuring block takes no chamfer, rounding, approach or tapping",
            ));
        }
        self.no_wait_in_fifo("MEAS/MEAW")?;
        let feed = self.rotary_feed(self.core.feed, here, end);
        self.core.measure(end, feed, rising, stop)?;
        // Where the line ends is the machine's to say: no tangent carries over.
        self.tangent = None;
        Ok(())
    }

    /// A block whose end the machine decides waits for it: not inside a STOPFIFO section,
    /// which the machine runs from its buffer without the interpreter (D119).
    pub(super) fn no_wait_in_fifo(&self, what: &str) -> Result<(), ProgramError> {
        if self.fifo {
            return Err(self.fault(
                Fault::NotSupported,
                format!(
                    "{what} waits for the machine: not inside a STOPFIFO section (STARTFIFO first)"
                ),
            ));
        }
        Ok(())
    }

    /// G33 (§9.3.7): a straight thread locked to the spindle, its lead the I, J or K word
    /// of its longest axis (mm per revolution; inches under G70/G700), starting SF= degrees
    /// after the index pulse. G63 (§9.3.8, non-modal): tapping with a compensating chuck,
    /// where F must equal S × pitch and the overrides are out: the move is locked to the
    /// spindle at F/S per revolution (F under G95), which keeps both promises (D93).
    /// G331/G332 (§9.3.9): rigid tapping with the spindle in position control (SPOS first),
    /// the lead's sign the direction (+ as M3), G332 the other way of the last G331, at S;
    /// F and the overrides are out (D101).
    fn thread_move(&mut self, w: &Words, here: &[f64], end: &[f64]) -> Result<(), ProgramError> {
        let what = match self.motion {
            _ if w.has_g(63) => "G63",
            Motion::TapIn => "G331",
            Motion::TapOut => "G332",
            _ => "G33",
        };
        for k in ["CR", "AR", "I1", "J1", "K1", "TURN", "AP", "RP", "ANG"] {
            if w.addr.contains_key(k) {
                return Err(self.fault(
                    Fault::IllegalWord,
                    format!("{k} does not belong to {what}: a straight move"),
                ));
            }
        }
        if self.corner.is_some() || self.ang.is_some() {
            return Err(self.fault(
                Fault::IllegalWord,
                format!("{what} takes no chamfer, rounding or ANG"),
            ));
        }
        let travel = |i: usize| (end[i] - here[i]).abs();
        let long = (0..end.len())
            .max_by(|&i, &j| travel(i).total_cmp(&travel(j)))
            .filter(|&i| travel(i) > 1e-9)
            .ok_or_else(|| self.fault(Fault::MissingWord, format!("{what} needs an end point")))?;
        let leads: Vec<&str> = ["I", "J", "K"]
            .into_iter()
            .filter(|k| w.addr.contains_key(*k))
            .collect();
        let lead = if w.has_g(63) {
            if let Some(k) = leads.first() {
                return Err(self.fault(
                    Fault::IllegalWord,
                    format!("{k}: G63 takes its pitch from F and S"),
                ));
            }
            if self.core.feed_per_rev() {
                self.core.feed
            } else if self.core.rpm > 0.0 {
                self.core.feed / self.core.rpm
            } else {
                return Err(self.fault(Fault::FeedRange, "G63 needs S: the pitch is F/S"));
            }
        } else {
            let letter = centre_letter(self.core.setup.axes[long]).ok_or_else(|| {
                self.fault(Fault::AxisAddress, format!("{what} runs along X, Y or Z"))
            })?;
            let word = letter.to_string();
            match w.get(&word) {
                Some(k) => k * self.unit(),
                None => {
                    return Err(self.fault(
                        Fault::MissingWord,
                        format!(
                            "{what} needs the lead of its longest axis {} as {word}",
                            self.core.setup.axes[long]
                        ),
                    ))
                }
            }
        };
        let kind = if matches!(what, "G331" | "G332") {
            self.tap(what, lead)?
        } else {
            MoveKind::Thread {
                lead,
                angle: self.thread_angle,
            }
        };
        self.core.emit(end, kind)
    }

    /// The tap of G331/G332 with the lead word `lead` (D101).
    fn tap(&mut self, what: &str, lead: f64) -> Result<MoveKind, ProgramError> {
        if !self.positioned {
            return Err(self.fault(
                Fault::MissingWord,
                format!("{what} taps with the spindle in position control: program SPOS first"),
            ));
        }
        let hand = if what == "G331" {
            lead.signum()
        } else if self.tap_hand != 0.0 {
            -self.tap_hand
        } else {
            return Err(self.fault(
                Fault::MissingWord,
                "G332 retracts the tap of a G331, and none ran before it",
            ));
        };
        if what == "G331" {
            self.tap_hand = hand;
        }
        Ok(MoveKind::Tap {
            lead: lead.abs() * hand,
            rpm: self.core.rpm,
        })
    }

    /// AP/RP of the block, or the last ones; IC makes them incremental.
    fn polar_words(&mut self, w: &Words) -> Result<(f64, f64), ProgramError> {
        let mut ap = self.polar.0;
        let mut rp = self.polar.1;
        if let Some(&(v, mode)) = w.addr.get("AP") {
            ap = if mode == Mode::Inc { ap + v } else { v };
        }
        if let Some(&(v, mode)) = w.addr.get("RP") {
            let v = v * self.unit();
            rp = if mode == Mode::Inc { rp + v } else { v };
        }
        if rp < 0.0 {
            return Err(self.fault(Fault::OutOfRange, "RP= must not be negative"));
        }
        self.polar = (ap, rp);
        Ok((ap, rp))
    }

    /// G2/G3: the centre and the end point from the block's words (§9.3.3).
    fn circle(
        &self,
        w: &Words,
        a: Pt,
        end: &mut [f64],
        polar: bool,
    ) -> Result<(Pt, bool), ProgramError> {
        let ccw = self.motion == Motion::Ccw;
        let (h, v) = self.core.plane_axes()?;
        let letters = (
            centre_letter(self.core.setup.axes[h]),
            centre_letter(self.core.setup.axes[v]),
        );
        let unit = self.unit();
        let centre_word = |l: Option<char>, start: f64| -> Option<f64> {
            let (val, mode) = *w.addr.get(l?.encode_utf8(&mut [0; 4]) as &str)?;
            Some(if mode == Mode::Abs {
                val * unit
            } else {
                start + val * unit
            })
        };
        let has_centre = [letters.0, letters.1]
            .iter()
            .flatten()
            .any(|l| w.addr.contains_key(l.encode_utf8(&mut [0; 4]) as &str));
        let radius = w.get("CR").map(|r| r * unit);
        let angle = w.get("AR");
        let arc_err = |e: ArcError, what: &str| {
            self.fault(
                match e {
                    ArcError::RadiusTooSmall => Fault::ArcRadius,
                    _ => Fault::ArcEnd,
                },
                format!("error in the end point of the circle: {what}"),
            )
        };
        if polar {
            // The pole is the centre (§9.3.3).
            if has_centre || radius.is_some() {
                return Err(self.fault(
                    Fault::ArcRAndIk,
                    "a polar circle takes its centre from the pole",
                ));
            }
            // The start must lie on the circle the pole and RP make.
            let b = self.core.plane_point(end)?;
            let c = check_center(a, b, self.pole).map_err(|e| {
                arc_err(
                    e,
                    "the start is not on the circle of radius RP around the pole",
                )
            })?;
            return Ok((c, ccw));
        }
        let b = self.core.plane_point(end)?;
        let end_given = w.axes.contains_key(&h) || w.axes.contains_key(&v);
        match (has_centre, radius, angle) {
            (true, None, None) => {
                let c = Pt::new(
                    centre_word(letters.0, a.z).unwrap_or(a.z),
                    centre_word(letters.1, a.r).unwrap_or(a.r),
                );
                let c = check_center(a, b, c).map_err(|e| arc_err(e, "start and end are not on one circle around the centre"))?;
                Ok((c, ccw))
            }
            (false, Some(r), None) => {
                if r.abs() < 0.01 {
                    return Err(self.fault(Fault::ArcRadius, "CR= is 0.010…99999.999"));
                }
                let c = center_from_radius(a, b, r, ccw).map_err(|e| arc_err(e, "the radius does not reach the end, or the end is the start (a full circle needs its centre)"))?;
                Ok((c, ccw))
            }
            (true, None, Some(ar)) => {
                // Centre and opening angle: the end follows (§9.3.3).
                let c = Pt::new(
                    centre_word(letters.0, a.z).unwrap_or(a.z),
                    centre_word(letters.1, a.r).unwrap_or(a.r),
                );
                self.check_angle(ar)?;
                if a.dist(c) < ARC_TOLERANCE {
                    return Err(arc_err(ArcError::RadiusTooSmall, "the centre is the start"));
                }
                let turn = if ccw { ar } else { -ar }.to_radians();
                let p = rotate(a, c, turn);
                self.core.set_plane_point(end, p);
                Ok((c, ccw))
            }
            (false, None, Some(ar)) if end_given => {
                self.check_angle(ar)?;
                let half = a.dist(b) / 2.0;
                let r = half / (ar.to_radians() / 2.0).sin();
                // More than a semicircle: the centre on the other side.
                let r = if ar > 180.0 { -r } else { r };
                let c = center_from_radius(a, b, r, ccw).map_err(|e| arc_err(e, "AR with this end"))?;
                Ok((c, ccw))
            }
            _ => Err(self.fault(
                Fault::ArcRAndIk,
                "a circle needs its centre (I/J/K), or CR=, or AR= with the centre or the end: one of them",
            )),
        }
    }

    fn check_angle(&self, ar: f64) -> Result<(), ProgramError> {
        if !(0.00001..=359.99999).contains(&ar) {
            return Err(self.fault(Fault::ArcRadius, "AR= is 0.00001…359.99999 degrees"));
        }
        Ok(())
    }

    /// CIP: the circle from the start through I1/J1/K1 to the end (§9.3.4); G90/G91 apply to
    /// the intermediate point too.
    fn through_point(
        &self,
        w: &Words,
        a: Pt,
        end: &[f64],
        here: &[f64],
    ) -> Result<(Pt, bool), ProgramError> {
        let (h, v) = self.core.plane_axes()?;
        let unit = self.unit();
        let coord = |i: usize| -> Result<f64, ProgramError> {
            let l = centre_letter(self.core.setup.axes[i]).map(|c| format!("{c}1"));
            let (val, mode) = l
                .and_then(|l| w.addr.get(l.as_str()).copied())
                .ok_or_else(|| {
                    self.fault(
                        Fault::MissingWord,
                        "CIP needs the intermediate point I1=/J1=/K1= in the plane",
                    )
                })?;
            let absolute = match mode {
                Mode::Abs | Mode::Rotary(_) => true,
                Mode::Inc => false,
                Mode::Modal => self.absolute,
            };
            Ok(if absolute {
                val * unit
            } else {
                here[i] + val * unit
            })
        };
        let m = Pt::new(coord(h)?, coord(v)?);
        let b = self.core.plane_point(end)?;
        let (c, ccw) = three_point(a, m, b).map_err(|_| {
            self.fault(
                Fault::ThreePointArc,
                "intermediate point of the circle incorrect: the three points are on a line",
            )
        })?;
        Ok((c, ccw))
    }

    /// CT: the circle tangent to the path before it (§9.3.5).
    fn tangential(&self, a: Pt, b: Pt) -> Result<(Pt, bool), ProgramError> {
        let t = self.tangent.ok_or_else(|| {
            self.fault(
                Fault::ArcEnd,
                "CT needs a path element before it in this plane",
            )
        })?;
        let (dz, dr) = (b.z - a.z, b.r - a.r);
        let n = Pt::new(-t.r, t.z);
        let nd = n.z * dz + n.r * dr;
        if nd.abs() < 1e-9 {
            return Err(self.fault(Fault::ArcEnd, "CT: the end lies on the tangent, no circle"));
        }
        let rho = (dz * dz + dr * dr) / (2.0 * nd);
        Ok((Pt::new(a.z + rho * n.z, a.r + rho * n.r), nd > 0.0))
    }

    /// The arc (with TURN= full turns before it, a helix along the other axes) and the
    /// tangent after it.
    fn arc_to(
        &mut self,
        here: &[f64],
        end: &[f64],
        c: Pt,
        ccw: bool,
        turns: Option<f64>,
        feed: f64,
    ) -> Result<(), ProgramError> {
        let a = self.core.plane_point(here)?;
        let b = self.core.plane_point(end)?;
        if self.wab.is_some() {
            let start = super::wab::arc_tangent(a, c, ccw);
            self.wab_before_element(end, start, false)?;
        }
        let turns = match turns {
            None => 0,
            Some(t) if t.fract() == 0.0 && (0.0..=999.0).contains(&t) => t as u32,
            Some(_) => return Err(self.fault(Fault::OutOfRange, "TURN= is 0…999")),
        };
        let sweep = arc_sweep(a, b, c, ccw).abs();
        let total = sweep + TAU * f64::from(turns);
        let (hi, vi) = self.core.plane_axes()?;
        for k in 1..=turns {
            let share = TAU * f64::from(k) / total;
            let p: Vec<f64> = (0..here.len())
                .map(|i| {
                    if i == hi || i == vi {
                        here[i]
                    } else {
                        here[i] + (end[i] - here[i]) * share
                    }
                })
                .collect();
            self.core.emit(
                &p,
                MoveKind::Arc {
                    center: c,
                    ccw,
                    feed,
                },
            )?;
        }
        self.emit_element(
            end,
            MoveKind::Arc {
                center: c,
                ccw,
                feed,
            },
        )?;
        let (dz, dr) = (b.z - c.z, b.r - c.r);
        let l = dz.hypot(dr).max(1e-12);
        self.tangent = Some(if ccw {
            Pt::new(-dr / l, dz / l)
        } else {
            Pt::new(dr / l, -dz / l)
        });
        Ok(())
    }

    /// G53: this block's positions are machine positions (settable and programmable offsets
    /// off; the tool length stays), §9.2.10. G153 suppresses the basic frame as well; this
    /// controller has no basic frame, so G153 is G53 (D93).
    fn machine_coordinates(&mut self, w: &Words) -> Result<(), ProgramError> {
        if self.core.comp.is_some() {
            return Err(self.fault(
                Fault::CompInCycle,
                "G53 while radius compensation is active",
            ));
        }
        if !matches!(self.motion, Motion::Rapid | Motion::Line) {
            return Err(self.fault(Fault::IllegalWord, "G53 takes straight moves"));
        }
        let saved = (
            self.core.frame.clone(),
            self.core.work_system,
            std::mem::take(&mut self.core.shift),
        );
        let n = self.core.setup.axes.len();
        // Coupled travel is no offset: G53 positions the axis itself (what this block adds
        // through couplings is kept).
        let coupled = std::mem::replace(&mut self.core.coupled, vec![0.0; n]);
        self.core.shift = vec![0.0; n];
        self.core.frame = cnc_interpreter_core::Frame::identity(n);
        self.core.work_system = NO_WORK_OFFSET;
        let here = self.core.work_position();
        let mut end = here.clone();
        let unit = self.unit();
        for (&i, &(v, mode)) in w.axes.iter() {
            let absolute = mode != Mode::Inc && (mode != Mode::Modal || self.absolute);
            end[i] = if absolute {
                v * unit
            } else {
                here[i] + v * unit
            };
        }
        let kind = if self.motion == Motion::Rapid {
            MoveKind::Rapid
        } else {
            MoveKind::Feed(self.core.feed)
        };
        let r = self.core.emit(&end, kind);
        (self.core.frame, self.core.work_system, self.core.shift) = saved;
        for (c, before) in self.core.coupled.iter_mut().zip(coupled) {
            *c += before;
        }
        r
    }
}

/// DC/ACP/ACN on a rotary axis standing at `here` (degrees, any number of turns): the position
/// whose angle is `target` (taken modulo 360°), by the shortest way, the positive or the
/// negative one (§9.2.1, D109).
fn rotary_target(here: f64, target: f64, way: Turn) -> f64 {
    let up = (target - here).rem_euclid(360.0);
    match way {
        Turn::Plus => here + up,
        Turn::Minus if up > 0.0 => here + up - 360.0,
        Turn::Minus => here,
        _ if up <= 180.0 => here + up,
        _ => here + up - 360.0,
    }
}
