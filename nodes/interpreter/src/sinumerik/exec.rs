//! One block in the control's order (`001` §9.1.6, §9.7; inventory §11.3): the items as
//! written (definitions, variables, jumps' conditions), then the modal G functions, feed and
//! speed, tool and cutting edge, the M functions output before the motion (M3/M4/M5 and the
//! machine's own), the non-modal functions (dwell, frames, pole), radius compensation and
//! the motion, then the stops and ends after it, the program call and the jump.

use std::borrow::Borrow;
use std::sync::Arc;

use cnc_interpreter_core::{Aux, Command, Fault, ProgramError, ServiceOutput, SpindleDir, Turn};

use super::block::{Block, Item};
use super::cycle_call::{is_cycle, CycleCall};
use super::expr::Expr;
use super::{find_target, Motion, Sinumerik};

/// How an axis value counts: the modal G90/G91, or `AC`/`IC`/`DC`/`ACP`/`ACN` for this word.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    Modal,
    Abs,
    Inc,
    /// DC/ACP/ACN: absolute on a rotary axis or the spindle, by the shortest way or in one
    /// direction.
    Rotary(Turn),
}

/// A block's few addresses in key order: a list kept from block to block, so sorting a
/// block's words allocates nothing once the first blocks have run.
#[derive(Debug)]
pub struct AddrMap<K>(Vec<(K, (f64, Mode))>);

impl<K> Default for AddrMap<K> {
    fn default() -> Self {
        AddrMap(Vec::new())
    }
}

impl<K: Ord + Copy> AddrMap<K> {
    /// Sets `k`; the value it had, if any (an address written twice).
    pub fn insert(&mut self, k: K, v: (f64, Mode)) -> Option<(f64, Mode)> {
        match self.0.binary_search_by(|(x, _)| x.cmp(&k)) {
            Ok(i) => Some(std::mem::replace(&mut self.0[i].1, v)),
            Err(i) => {
                self.0.insert(i, (k, v));
                None
            }
        }
    }
    /// A block holds a few addresses: a scan that rejects by length is faster than a binary
    /// search comparing strings (most blocks ask for a dozen addresses they do not have).
    #[inline]
    pub fn get<Q: PartialEq + ?Sized>(&self, k: &Q) -> Option<&(f64, Mode)>
    where
        K: Borrow<Q>,
    {
        self.0.iter().find(|(x, _)| x.borrow() == k).map(|(_, v)| v)
    }
    #[inline]
    pub fn contains_key<Q: PartialEq + ?Sized>(&self, k: &Q) -> bool
    where
        K: Borrow<Q>,
    {
        self.get(k).is_some()
    }
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
    pub fn iter(&self) -> impl Iterator<Item = (&K, &(f64, Mode))> {
        self.0.iter().map(|(k, v)| (k, v))
    }
}

/// A block's addresses, sorted out of its items.
#[derive(Debug, Default)]
pub struct Words {
    /// Machine axis index → value and how it counts.
    pub axes: AddrMap<usize>,
    /// Other addresses: `I`, `J`, `K`, `I1`, `CR`, `AR`, `AP`, `RP`, `TURN`, `RPL`, `F`,
    /// `S`, `T`, `D`, `P`…
    pub addr: AddrMap<&'static str>,
    pub g: Vec<u32>,
    /// The same G functions as bits (G0–G1023), for `has_g`, which a block asks a few dozen
    /// times.
    g_bits: [u64; 16],
    pub m: Vec<u32>,
    /// H functions: address and value (§9.8).
    pub h: Vec<(u16, f64)>,
    /// Keywords in the order written (`CIP`, `TRANS`, `STOPRE`…).
    pub keys: Vec<&'static str>,
    /// The program the block calls.
    pub call: Option<String>,
    /// The cycle the block calls (or makes modal with MCALL).
    pub cycle: Option<CycleCall>,
    /// TRACYL or TRAFOOF (§9.15).
    pub cylinder: Option<super::tracyl::CylinderWord>,
    /// FXS[axis]=1 or =0: the axis and whether it is selected (§9.3.23).
    pub fxs: Option<(usize, bool)>,
}

impl Words {
    /// Empty for the next block, its lists' room kept.
    fn clear(&mut self) {
        self.axes.0.clear();
        self.addr.0.clear();
        for &g in &self.g {
            if let Some(w) = self.g_bits.get_mut(g as usize / 64) {
                *w = 0;
            }
        }
        self.g.clear();
        self.m.clear();
        self.h.clear();
        self.keys.clear();
        self.call = None;
        self.cycle = None;
        self.cylinder = None;
        self.fxs = None;
    }

    fn push_g(&mut self, n: u32) {
        self.g.push(n);
        if let Some(w) = self.g_bits.get_mut(n as usize / 64) {
            *w |= 1 << (n % 64);
        }
    }

    #[inline]
    pub fn has_g(&self, n: u32) -> bool {
        self.g_bits
            .get(n as usize / 64)
            .is_some_and(|w| w >> (n % 64) & 1 == 1)
    }
    #[inline]
    pub fn key(&self, k: &str) -> bool {
        self.keys.contains(&k)
    }
    #[inline]
    pub fn get(&self, a: &str) -> Option<f64> {
        self.addr.get(a).map(|v| v.0)
    }
}

use super::names::{address_name, ADDRESSES, KEYWORDS, NOT_BUILT, NOT_BUILT_G};

impl Sinumerik {
    /// Runs one parsed block.
    pub(super) fn run_block(&mut self, b: &Block, text: &Arc<str>) -> Result<(), ProgramError> {
        if !self
            .program_text
            .as_ref()
            .is_some_and(|t| Arc::ptr_eq(t, text))
        {
            self.program_text = Some(text.clone());
        }
        let mut w = std::mem::take(&mut self.words);
        w.clear();
        let done = self.run_words(b, &mut w, text);
        self.words = w;
        done
    }

    /// The block's items, then its words in the control's order, then its jump
    /// (docs/decisions.md D83).
    fn run_words(&mut self, b: &Block, w: &mut Words, text: &Arc<str>) -> Result<(), ProgramError> {
        self.jump = None;
        for item in &b.items {
            if !matches!(item, Item::Def(_) | Item::Proc(..)) {
                if let Some(d) = self.may_define.last_mut() {
                    *d = false;
                }
            }
            self.item(item, w)?;
        }
        self.cylinder_block(w)?;
        self.check_cylinder_axes(w)?;
        let from = self.core.queued();
        // Where the block starts, for the work area check (a buffer kept from block to block).
        let mut start = std::mem::take(&mut self.block_start);
        start.clone_from(&self.core.pos);
        self.block_entry = (self.motion, self.core.feed);
        self.modal(w)?;
        self.feed_and_speed(w)?;
        self.tool_words(w)?;
        self.m_before(w)?;
        let nonmodal = self.non_modal(w)?;
        if !nonmodal {
            self.motion_block(w)?;
            // A corner no element took (G53) does not carry over.
            self.corner = None;
        }
        self.cycles(w, nonmodal)?;
        self.wab_after_block()?;
        let from = from + std::mem::take(&mut self.moved_before);
        let checked = self.check_work_area(from, &start);
        self.block_start = start;
        checked?;
        if w.has_g(9) {
            self.core.exact_stop_block(from);
        }
        self.m_after(w)?;
        if w.key("RET") {
            self.no_line_waits_for_ang()?;
            self.no_approach_waits()?;
            self.return_from_program();
        }
        if let Some(name) = &w.call {
            let count = match w.get("P") {
                None => 1,
                Some(p) if p.fract() == 0.0 && (1.0..=9999.0).contains(&p) => p as u32,
                Some(p) => {
                    return Err(self.fault(
                        Fault::OutOfRange,
                        format!(
                            "P{} repeats a call 1…9999 times",
                            cnc_interpreter_core::show(p)
                        ),
                    ))
                }
            };
            self.core.call_named(name, count, None)?;
            self.sync_scopes();
        }
        if let Some((forward, target)) = self.jump.take() {
            let level = self.core.current();
            let pos = find_target(text, self.core.block_start, level.pos, forward, &target)
                .ok_or_else(|| {
                    self.fault(
                        Fault::TargetNotFound,
                        format!(
                            "jump target {target} not found {} in this program",
                            if forward {
                                "after this block"
                            } else {
                                "before this block"
                            }
                        ),
                    )
                })?;
            self.core.level().pos = pos;
        }
        Ok(())
    }

    /// Sorts one item into the block's words, or runs it when it runs as written (a
    /// definition, a variable, a jump's condition, a message).
    fn item(&mut self, item: &Item, w: &mut Words) -> Result<(), ProgramError> {
        match item {
            Item::Def(d) => self.define(d)?,
            Item::Goto {
                condition,
                forward,
                target,
            } => {
                if self.jump.is_none() {
                    let go = match condition {
                        None => true,
                        Some(c) => self.number(c)? != 0.0,
                    };
                    if go {
                        self.jump = Some((*forward, target.to_string()));
                    }
                }
            }
            Item::Param { number, value } => self.write_param(*number, value)?,
            Item::Proc(name, params) => self.proc(name, *params)?,
            Item::Assign { name, index, value } => {
                let axis = self.axis_named(name);
                if name.starts_with('H') && name[1..].bytes().all(|b| b.is_ascii_digit()) {
                    let v = self.number(value)?;
                    return self.h_function(w, &name[1..], v);
                }
                if name == "ACC" {
                    return self.acceleration_override(index, value);
                }
                if ["FXS", "FXST", "FXSW"].contains(&name.as_ref()) {
                    return self.fixed_stop_word(w, name, index, value);
                }
                if ["$MA_", "$MN_", "$MC_"].iter().any(|p| name.starts_with(p)) {
                    return Err(self.fault(
                        Fault::NotSupported,
                        format!(
                            "{name}: machine data are set in the launch config, not from a program"
                        ),
                    ));
                }
                if index.is_empty()
                    && (axis.is_some()
                        || ADDRESSES.contains(&name.as_ref())
                        || "FSTDIJKP".contains(name.as_ref()) && name.len() == 1)
                {
                    let (v, mode) = self.address_value(name, value)?;
                    self.put(w, name, v, mode, axis)?;
                } else if NOT_BUILT.iter().any(|(k, _)| k == name) {
                    self.not_built(name)?;
                } else {
                    self.write(name, index, value)?;
                }
            }
            Item::Word {
                letter,
                digits,
                value,
            } => self.word(w, *letter, digits, *value)?,
            Item::Name(n) => {
                if ["TRAFOOF", "TRAFOFF"].contains(&n.as_ref()) {
                    self.set_cylinder_word(w, super::tracyl::CylinderWord::Off)?;
                } else if let Some(k) = KEYWORDS.iter().find(|k| **k == n.as_ref()) {
                    w.keys.push(k);
                } else if NOT_BUILT.iter().any(|(k, _)| k == n) {
                    self.not_built(n)?;
                } else if is_cycle(n) {
                    self.cycle_item(w, n, &[])?;
                } else if self.core.library.get_named(n).is_some() {
                    self.program_call(w, n)?;
                } else {
                    return Err(self.fault(
                        Fault::NoSuchAddress,
                        format!("{n} is not defined: no address, keyword, variable or program of this name"),
                    ));
                }
            }
            Item::Call(name, args) => self.call_item(w, name, args)?,
            Item::Indirect(var) => self.indirect_call(w, var)?,
        }
        Ok(())
    }

    /// `CALL NAME` (§9.1.6): a call without parameters of the cycle or program whose name the
    /// variable holds.
    fn indirect_call(&mut self, w: &mut Words, var: &str) -> Result<(), ProgramError> {
        let name = self
            .read(var, &[])
            .map_err(|e| self.eval_error(e))?
            .text()
            .trim()
            .to_ascii_uppercase();
        if is_cycle(&name) {
            self.cycle_item(w, &name, &[])
        } else if self.core.library.get_named(&name).is_some() {
            self.program_call(w, &name)
        } else {
            Err(self.fault(
                Fault::ProgramNotFound,
                format!("CALL {var}: no cycle or program {name:?}"),
            ))
        }
    }

    /// `PROC name`: accepted as the program's first block; a parameter list is not built.
    fn proc(&mut self, name: &str, params: bool) -> Result<(), ProgramError> {
        if params {
            return Err(self.fault(
                Fault::NotSupported,
                format!("PROC {name}(…): subprograms with parameters are not built yet"),
            ));
        }
        // Nothing but comments (and DEF) before it: the level may still define variables.
        if !self.may_define.last().copied().unwrap_or(false) {
            return Err(self.fault(
                Fault::Macro,
                format!("PROC {name} must be the first block of its program"),
            ));
        }
        Ok(())
    }

    fn not_built(&self, name: &str) -> Result<(), ProgramError> {
        let why = NOT_BUILT
            .iter()
            .find(|(k, _)| *k == name)
            .map_or("not built", |(_, w)| w);
        Err(self.fault(Fault::NotSupported, format!("{name}: {why}")))
    }

    fn program_call(&mut self, w: &mut Words, name: &str) -> Result<(), ProgramError> {
        if w.call.is_some() || w.cycle.is_some() {
            return Err(self.fault(Fault::Call, "one program call per block"));
        }
        w.call = Some(name.to_string());
        Ok(())
    }

    /// A cycle call: evaluated now, run after the block's own words.
    fn cycle_item(
        &mut self,
        w: &mut Words,
        name: &str,
        args: &[Option<Expr>],
    ) -> Result<(), ProgramError> {
        if w.call.is_some() || w.cycle.is_some() {
            return Err(self.fault(Fault::Call, "one program or cycle call per block"));
        }
        w.cycle = Some(self.cycle_call(name, args)?);
        Ok(())
    }

    fn call_item(
        &mut self,
        w: &mut Words,
        name: &str,
        args: &[Option<Expr>],
    ) -> Result<(), ProgramError> {
        if name == "MSG" {
            let text = match args {
                [] | [None] => String::new(),
                [Some(e)] => self.value(e)?.text(),
                _ => return Err(self.fault(Fault::MacroArgument, "MSG takes one text")),
            };
            if let Some((output, text)) = service_output(&text) {
                self.service_message(output, text);
                return Ok(());
            }
            // The display shows 65 characters (§9.1.6).
            let shown: String = text.chars().take(65).collect();
            self.messages.push((self.core.line, shown.clone()));
            self.core.operator_message(shown);
            return Ok(());
        }
        if is_cycle(name) {
            return self.cycle_item(w, name, args);
        }
        if name == "EXTCALL" {
            return self.external_call(w, args);
        }
        if name == "SETPIECE" {
            return self.setpiece(args);
        }
        if name == "RESETMON" {
            return self.resetmon(args);
        }
        if name == "TRAILON" {
            return self.trail_on(args);
        }
        if name == "TRACYL" {
            return self.tracyl(w, args);
        }
        if name == "TRAILOF" {
            return self.trail_off(args);
        }
        if NOT_BUILT.iter().any(|(k, _)| *k == name) {
            return self.not_built(name);
        }
        Err(self.fault(
            Fault::NoSuchAddress,
            format!("{name}(…) is not defined: no function, cycle or procedure of this name"),
        ))
    }

    /// `EXTCALL("D:\FOLDER\NAME")` (§9.11.4): calls a program of an external drive, as the
    /// launch config's drives held it at the program's start (D110). The path names the drive;
    /// the setting data of a default path is not kept here.
    fn external_call(&mut self, w: &mut Words, args: &[Option<Expr>]) -> Result<(), ProgramError> {
        let path = match args {
            [Some(e)] => self.value(e)?.text(),
            _ => {
                return Err(self.fault(
                    Fault::MacroArgument,
                    "EXTCALL(\"D:\\FOLDER\\NAME\") takes the program's path",
                ))
            }
        };
        let name = crate::library::external_name(&path);
        if name.as_bytes().get(1) != Some(&b':') {
            return Err(self.fault(
                Fault::ProgramNotFound,
                format!("EXTCALL {path}: name the drive and folder (D:\\…)"),
            ));
        }
        if self.core.library.get_named(&name).is_none() {
            return Err(self.fault(
                Fault::ProgramNotFound,
                format!("EXTCALL {path}: no such program on the external drives"),
            ));
        }
        w.call = Some(name);
        Ok(())
    }

    /// The machine axis an address names: a channel axis (`X`) or a machine axis (`X1`).
    pub(super) fn axis_named(&self, name: &str) -> Option<usize> {
        let mut c = name.chars();
        let letter = c.next()?;
        let rest = c.as_str();
        let axis_name = (rest.is_empty() || rest == "1") && !"IJKFSTDP".contains(letter);
        self.core.axis(letter).filter(|_| axis_name)
    }

    /// An address's expression: its value and `AC`/`IC`/`DC`/`ACP`/`ACN` when it has one.
    fn address_value(&self, name: &str, value: &Expr) -> Result<(f64, Mode), ProgramError> {
        if let Expr::Call(f, args) = value {
            let mode = match f.as_ref() {
                "AC" => Some(Mode::Abs),
                "IC" => Some(Mode::Inc),
                "DC" => Some(Mode::Rotary(Turn::Shortest)),
                "ACP" => Some(Mode::Rotary(Turn::Plus)),
                "ACN" => Some(Mode::Rotary(Turn::Minus)),
                _ => None,
            };
            if let Some(mode) = mode {
                let [Some(arg)] = args.as_slice() else {
                    return Err(self.fault(Fault::MacroArgument, format!("{name}={f}(value)")));
                };
                let rotary = self.axis_named(name).is_some_and(|i| self.rotary_axis(i));
                if matches!(mode, Mode::Rotary(_)) && name != "SPOS" && !rotary {
                    return Err(self.fault(
                        Fault::IllegalWord,
                        format!(
                            "{name}={f}(…): DC, ACP and ACN position rotary axes and the spindle"
                        ),
                    ));
                }
                return Ok((self.number(arg)?, mode));
            }
        }
        Ok((self.number(value)?, Mode::Modal))
    }

    fn put(
        &self,
        w: &mut Words,
        name: &str,
        v: f64,
        mode: Mode,
        axis: Option<usize>,
    ) -> Result<(), ProgramError> {
        if !v.is_finite() {
            return Err(self.fault(Fault::OutOfRange, format!("{name}: value not finite")));
        }
        let dup = match (axis, address_name(name)) {
            (Some(i), _) => w.axes.insert(i, (v, mode)).is_some(),
            (None, Some(a)) => w.addr.insert(a, (v, mode)).is_some(),
            (None, None) => {
                return Err(self.fault(Fault::NoSuchAddress, format!("{name} is no address")))
            }
        };
        if dup {
            return Err(self.fault(
                Fault::RepeatedWord,
                format!("address {name} programmed twice in one block"),
            ));
        }
        Ok(())
    }

    fn word(
        &mut self,
        w: &mut Words,
        letter: char,
        digits: &str,
        value: f64,
    ) -> Result<(), ProgramError> {
        match letter {
            'G' => {
                if value.fract() != 0.0 || !(0.0..=1000.0).contains(&value) {
                    return Err(
                        self.fault(Fault::UndefinedCode, format!("G{value} does not exist"))
                    );
                }
                w.push_g(value as u32);
            }
            'M' => {
                if value.fract() != 0.0 || !(0.0..=99.0).contains(&value) {
                    return Err(self.fault(Fault::OutOfRange, "M functions are 0…99"));
                }
                w.m.push(value as u32);
            }
            'L' => {
                if digits.is_empty() || digits.len() > 7 || value.fract() != 0.0 {
                    return Err(
                        self.fault(Fault::DataFormat, "L needs 1–7 digits: a subprogram number")
                    );
                }
                // Leading zeros are part of the name: L128, L0128 and L00128 differ (§9.11.1).
                self.program_call(w, &format!("L{digits}"))?;
            }
            'N' => {
                return Err(self.fault(Fault::DataFormat, "the block number N must start the block"))
            }
            // `H5` is H0=5.0 (§9.8).
            'H' => self.h_function(w, "", value)?,
            'R' => {
                return Err(self.fault(
                    Fault::DataFormat,
                    format!("R{digits} needs '=' and a value"),
                ))
            }
            _ => {
                let mut buf = [0; 4];
                let name: &str = letter.encode_utf8(&mut buf);
                let axis = self
                    .core
                    .axis(letter)
                    .filter(|_| !"IJKFSTDP".contains(letter));
                if axis.is_none() && !"IJKFSTDP".contains(letter) {
                    return Err(self.fault(
                        Fault::NoSuchAddress,
                        format!("{letter} is no address of this machine"),
                    ));
                }
                self.put(w, name, value, Mode::Modal, axis)?;
            }
        }
        Ok(())
    }

    /// The block's cycle: MCALL makes it modal (MCALL alone cancels), a call runs it here;
    /// without one, a modal cycle runs after a block that moved (§10.1, §10.5).
    fn cycles(&mut self, w: &mut Words, nonmodal: bool) -> Result<(), ProgramError> {
        let moved = !nonmodal
            && (!w.axes.is_empty() || w.addr.contains_key("AP") || w.addr.contains_key("RP"));
        if w.key("MCALL") {
            self.set_modal_cycle(w.cycle.take())
        } else if let Some(c) = w.cycle.take() {
            self.run_cycle(&c)
        } else if moved {
            self.run_modal_cycle()
        } else {
            Ok(())
        }
    }

    /// The modal G functions of the block, one per group (§9.1.6).
    fn modal(&mut self, w: &Words) -> Result<(), ProgramError> {
        for (at, &g) in w.g.iter().enumerate() {
            let group = g_group(g).ok_or_else(|| {
                self.fault(
                    Fault::UndefinedCode,
                    format!("G{g} is no G function of this control"),
                )
            })?;
            if let Some((_, why)) = NOT_BUILT_G.iter().find(|(n, _)| *n == g) {
                return Err(self.fault(Fault::NotSupported, *why));
            }
            let same = w.g[..at].iter().find(|o| g_group(**o) == Some(group));
            if let Some(other) = same {
                return Err(self.fault(
                    Fault::SameGroup,
                    format!("G{other} and G{g} are of one group: one per block"),
                ));
            }
            match g {
                0 => self.motion = Motion::Rapid,
                1 => self.motion = Motion::Line,
                2 => self.motion = Motion::Cw,
                3 => self.motion = Motion::Ccw,
                33 => self.motion = Motion::Thread,
                331 => self.motion = Motion::TapIn,
                332 => self.motion = Motion::TapOut,
                17..=19 => self.set_plane(g as u8)?,
                90 => self.absolute = true,
                91 => self.absolute = false,
                70 | 71 | 700 | 710 => {
                    self.inch = g == 70 || g == 700;
                    self.inch_feed = g == 700;
                }
                94 | 95 => {
                    let per_rev = g == 95;
                    if self.core.feed_per_rev() != per_rev {
                        self.core.set_feed_mode(per_rev);
                    }
                }
                60 | 64 => {
                    let exact = g == 60;
                    if self.core.exact_stop_mode() != exact {
                        self.core.set_path_mode(exact);
                    }
                }
                // The corners of radius compensation (§9.6.5, D103).
                450 | 451 => self.core.outer_intersection = g == 451,
                // How WAB comes down to the contour: in space or in the plane (§9.14).
                340 | 341 => self.approach_in_plane = g == 341,
                500 => self.set_work_offset(None),
                // G54–G59 are the 1st–6th settable offsets, G507–G554 the 7th–54th (§9.2.10).
                54..=59 => self.set_work_offset(Some((g - 54) as u8)),
                507..=554 => self.set_work_offset(Some((g - 507 + 6) as u8)),
                _ => {}
            }
        }
        for k in &w.keys {
            match *k {
                "CIP" => self.motion = Motion::Cip,
                "CT" => self.motion = Motion::Ct,
                "WALIMON" => self.limits.monitored = true,
                "WALIMOF" => self.limits.monitored = false,
                // Feed on the contour of compensated arcs, or at the cutter centre (D98).
                "CFC" => self.core.feed_on_contour = true,
                "CFTCP" => self.core.feed_on_contour = false,
                // The planner's profiles: BRISK trapezoidal, SOFT jerk-limited (D99).
                "BRISK" | "SOFT" => self.core.push(Command::Profile {
                    jerk_limited: *k == "SOFT",
                }),
                // The drives' feedforward (D106).
                "FFWON" | "FFWOF" => self.core.push(Command::Feedforward { on: *k == "FFWON" }),
                // The compressor, and the look-ahead buffer's fast section (D119).
                "COMPCAD" | "COMPOF" => self.core.push(Command::Compressor {
                    on: *k == "COMPCAD",
                }),
                "STOPFIFO" | "STARTFIFO" => {
                    self.fifo = *k == "STOPFIFO";
                    self.core.push(Command::Fifo { fill: self.fifo });
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// F and S (§9.3.14, §9.4.1): F in G700 counts inches; S sets the speed.
    fn feed_and_speed(&mut self, w: &Words) -> Result<(), ProgramError> {
        let dwell = w.has_g(4);
        if let Some(f) = w.get("F").filter(|_| !dwell) {
            if f <= 0.0 {
                return Err(self.fault(Fault::FeedRange, "F must be above 0 (0.001…99999.999)"));
            }
            self.core.feed = if self.inch_feed { f * 25.4 } else { f };
        }
        // Under G25/G26, S is a limit (limits.rs), not the speed.
        let limit = w.has_g(25) || w.has_g(26);
        if let Some(s) = w.get("S").filter(|_| !dwell && !limit) {
            if !(0.0..=99_999.999).contains(&s) {
                return Err(self.fault(Fault::OutOfRange, "S is 0…99999.999 rpm"));
            }
            self.core.set_rpm(self.limited_rpm(s));
        }
        Ok(())
    }

    /// `ACC[axis]=percent` (§9.3.18): the axis's (or with `ACC[S]` the spindle's) acceleration
    /// from the next block on, 1–200 % of its rated value, until changed, reset or the
    /// program's end (D108).
    fn acceleration_override(&mut self, index: &[Expr], value: &Expr) -> Result<(), ProgramError> {
        let [Expr::Axis(name)] = index else {
            return Err(self.fault(Fault::MacroArgument, "ACC[axis]=percent names one axis"));
        };
        // The 802D has one spindle: S, or S1 as its number.
        let axis = if name == "S" || name == "S1" {
            usize::from(cnc_msgs::canon::SPINDLE_AXIS)
        } else {
            self.axis_named(name).ok_or_else(|| {
                self.fault(Fault::NoSuchAxis, format!("ACC[{name}]: no such axis"))
            })?
        };
        let percent = self.number(value)?;
        if !(1.0..=200.0).contains(&percent) {
            return Err(self.fault(
                Fault::OutOfRange,
                format!(
                    "ACC[{name}]={}: the override is 1…200 %",
                    cnc_interpreter_core::show(percent)
                ),
            ));
        }
        let axis = u8::try_from(axis)
            .map_err(|_| self.fault(Fault::NoSuchAxis, format!("ACC[{name}]: no such axis")))?;
        self.core.push(Command::Acceleration { axis, percent });
        Ok(())
    }

    /// An H function (§9.8): H0–H9999 with a value for the PLC, at most 3 in a block; the
    /// address written as `digits` (none: H0). Output with the M functions before the move
    /// (D107).
    fn h_function(&self, w: &mut Words, digits: &str, value: f64) -> Result<(), ProgramError> {
        let address = if digits.is_empty() {
            Some(0)
        } else {
            digits.parse::<u16>().ok()
        };
        let Some(address) = address.filter(|a| *a <= cnc_interpreter_core::MAX_H_ADDRESS) else {
            return Err(self.fault(
                Fault::OutOfRange,
                format!("H{digits}: H functions are H0…H9999"),
            ));
        };
        if !value.is_finite() {
            return Err(self.fault(Fault::OutOfRange, format!("H{address}: value not finite")));
        }
        if w.h.len() == 3 {
            return Err(self.fault(Fault::TooManyM, "more than 3 H functions in one block"));
        }
        w.h.push((address, value));
        Ok(())
    }

    fn m_before(&mut self, w: &Words) -> Result<(), ProgramError> {
        if w.m.len() > 5 {
            return Err(self.fault(Fault::TooManyM, "more than 5 M functions in one block"));
        }
        for &m in &w.m {
            match m {
                0 | 1 | 2 | 17 | 30 | 6 => {}
                3 => self.spindle(3),
                4 => self.spindle(4),
                5 => self.spindle(5),
                19 => {
                    self.spindle(19);
                    self.positioned = true;
                }
                _ => self.core.aux(Aux::M(m as i32)),
            }
        }
        for &(address, value) in &w.h {
            self.core.aux(Aux::H { address, value });
        }
        if let Some(&(v, mode)) = w.addr.get("SPOS") {
            self.spindle_position(v, mode)?;
        }
        Ok(())
    }

    /// SPOS (§9.4.3): the spindle to an angle in position control, where it stays until
    /// M3/M4/M5. It is positioned before the block's axes move, not beside them (D100).
    /// `SPOS=a`, `AC(a)`, `DC(a)` the shortest way (turning: on in its direction), `ACP`/`ACN`
    /// in one direction, 0 ≤ a < 360; `IC(d)` a signed travel of up to 99 999.999°.
    fn spindle_position(&mut self, v: f64, mode: Mode) -> Result<(), ProgramError> {
        let way = match mode {
            Mode::Modal | Mode::Abs => Turn::Shortest,
            Mode::Rotary(t) => t,
            Mode::Inc => Turn::Incremental,
        };
        if !way.accepts(v) {
            return Err(self.fault(
                Fault::OutOfRange,
                format!(
                    "SPOS={}: a spindle position is 0…359.999° (IC: a travel of at most ±{}°)",
                    cnc_interpreter_core::show(v),
                    Turn::MAX_INCREMENT
                ),
            ));
        }
        self.positioned = true;
        self.core.orient_spindle(v, way);
        Ok(())
    }

    fn spindle(&mut self, code: i32) {
        self.positioned = false;
        self.core.spindle_code(code);
    }

    /// M0, M1 after the motion; M2/M30 end the program (in a called program M2 returns, as
    /// M17 does, §9.11.1).
    fn m_after(&mut self, w: &Words) -> Result<(), ProgramError> {
        for &m in &w.m {
            match m {
                0 | 1 => self.core.aux(Aux::M(m as i32)),
                2 | 30 | 17 => {
                    self.no_line_waits_for_ang()?;
                    self.no_approach_waits()?;
                    if self.core.depth() > 1 {
                        self.return_from_program();
                    } else if m == 17 {
                        return Err(self.fault(
                            Fault::ReturnWithoutCall,
                            "M17 ends a subprogram; the main program ends with M2 or M30",
                        ));
                    } else {
                        self.count_part();
                        self.core.saw_end = true;
                        self.core.spindle_left_by_code(SpindleDir::Stopped);
                        self.positioned = false;
                        self.core.aux(Aux::M(m as i32));
                        self.core.finish();
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// A program may not end or return while a line given by its angle alone (`ANG=`, §9.5.2)
    /// waits for the block that completes it: the line would be lost.
    fn no_line_waits_for_ang(&self) -> Result<(), ProgramError> {
        if self.ang.is_some() {
            return Err(self.fault(
                Fault::MissingWord,
                "ANG: the line given by its angle alone waits for a block with the end point \
                 and its own ANG; the program ends or returns first",
            ));
        }
        Ok(())
    }

    fn return_from_program(&mut self) {
        if self.core.depth() > 1 {
            self.core.return_from_call();
            self.sync_scopes();
        } else {
            self.core.saw_end = true;
            self.core.finish();
        }
    }
}

/// The group of a numeric G function (§9.1.6; inventory §3.1), `None` when the control has
/// no such G.
pub fn g_group(g: u32) -> Option<u8> {
    Some(match g {
        0..=3 | 33 | 331 | 332 => 1,
        4 | 63 | 74 | 75 | 147 | 148 | 247 | 248 | 347 | 348 => 2,
        25 | 26 | 110..=112 => 3,
        17..=19 => 6,
        40..=42 => 7,
        500 | 54..=59 | 507..=554 => 8,
        53 | 153 => 9,
        60 | 64 => 10,
        9 => 11,
        601 | 602 => 12,
        70 | 71 | 700 | 710 => 13,
        90 | 91 => 14,
        94 | 95 => 15,
        450 | 451 => 18,
        340 | 341 => 44,
        290 | 291 => 47,
        // Corner deceleration: the manual lists no group; SINUMERIK's is 57.
        62 | 621 => 57,
        _ => return None,
    })
}

/// `MSG("V24: …")` and `MSG("File: …")` (`001` §8.4.4, tables 8-2, 8-5, 8-6; the table writes
/// `FILE:` too): the message service's output and the text after the interface's name.
fn service_output(text: &str) -> Option<(ServiceOutput, &str)> {
    let (head, rest) = text.split_once(':')?;
    let output = match head.trim().to_ascii_uppercase().as_str() {
        "V24" => ServiceOutput::Serial,
        "FILE" => ServiceOutput::File,
        _ => return None,
    };
    Some((output, rest.trim_start()))
}

impl Sinumerik {
    /// A text for the message service: sent unless it is the text this output sent last, which
    /// goes out again only after an empty text for it (§8.4.4's note: "如果在零件程序中相同的信
    /// 息文本重复出现，则在每次输出后必须输入空文本指令"). An empty text sends nothing.
    fn service_message(&mut self, output: ServiceOutput, text: &str) {
        let last = &mut self.service_last[output as usize];
        if text.is_empty() {
            *last = None;
        } else if last.as_deref() != Some(text) {
            *last = Some(text.to_string());
            self.core.service_message(output, text.to_string());
        }
    }
}
