//! Multiple repetitive cycles of the Huaxing dialect: G70–G73 from a finishing contour and the
//! G76 threading cycle (`000` §5.22, §5.23.6).

use cnc_interpreter_core::comp;
use cnc_interpreter_core::cycles::thread_depths;
use cnc_interpreter_core::geometry::{self, ArcError, Elem, Pt};
use cnc_interpreter_core::rough::{Move, Rough};
use cnc_interpreter_core::{find_number, read_line, Fault, MoveKind, Pos, ProgramError, Repeat};

use super::{Huaxing, HuaxingG};
use crate::fanuc::block::{incremental_letter, whole, Block};
use crate::fanuc::codes::{G, M};
use crate::fanuc::syntax::{parse_line, Stmt};
use crate::fanuc::Fanuc;

/// Most blocks in a G70–G73 contour (alarm 45).
const MAX_CONTOUR_BLOCKS: usize = 100;
/// Most passes or pecks one cycle block may generate.
pub(super) const MAX_CYCLE_STEPS: usize = 1_000_000;

/// What a contour's first block and position say about the cycle.
pub(super) struct Contour {
    pub elems: Vec<Elem>,
    /// The `ns` block has a Z(W) word (G71 Type II) / an X(U) word (G72 Type II).
    pub first_has_z: bool,
    pub first_has_x: bool,
    pub first_rapid: bool,
    /// The position after the `nf` line.
    pub after: Pos,
    /// Where the `ns` line starts.
    pub first: Pos,
}

/// Settings of the first block of G71/G72/G73 and G76, kept until changed (modal).
#[derive(Debug, Clone, Copy)]
pub struct CompoundWords {
    pub depth: f64,
    pub retract: f64,
    pub relief_x: f64,
    pub relief_z: f64,
    pub passes: u32,
    pub g76_finish_passes: u32,
    pub g76_runout: f64,
    pub g76_angle: f64,
    pub g76_min_depth: f64,
    pub g76_allowance: f64,
    pub g76_j: Option<f64>,
    pub g76_k: Option<f64>,
}

impl Default for CompoundWords {
    /// The global parameters' defaults (`000` GS#30–GS#42).
    fn default() -> Self {
        CompoundWords {
            depth: 0.1,
            retract: 0.1,
            relief_x: 1.0,
            relief_z: 1.0,
            passes: 2,
            g76_finish_passes: 1,
            g76_runout: 5.0,
            g76_angle: 60.0,
            g76_min_depth: 0.01,
            g76_allowance: 0.01,
            g76_j: None,
            g76_k: None,
        }
    }
}

impl Fanuc<Huaxing> {
    /// Reads blocks `ns`..`nf` as a contour from the work position `here`.
    pub(super) fn contour(&self, ns: u32, nf: u32, here: &[f64]) -> Result<Contour, ProgramError> {
        let level = self.core.current();
        let (text, from) = (level.text.clone(), level.pos);
        let first = find_number(&text, from, ns).ok_or_else(|| {
            self.fault(
                Fault::TargetNotFound,
                format!("contour block N{ns} not found"),
            )
        })?;
        let mut pos = first;
        let mut cur = here.to_vec();
        let mut motion = self.motion;
        let mut elems = Vec::new();
        // Tool-nose compensation inside the contour: (G41/G42, offset, first element) and the
        // element whose block cancels it (`000` §3.6: G71–G73 rough to the compensated contour).
        let mut nose: Option<(G<HuaxingG>, u32, usize)> = None;
        let mut nose_cancel: Option<usize> = None;
        let mut info = (false, false, false);
        let mut blocks = 0;
        loop {
            let Some((raw, next)) = read_line(&text, pos) else {
                return Err(self.fault(
                    Fault::TargetNotFound,
                    format!("contour end block N{nf} not found"),
                ));
            };
            pos = next;
            let line = parse_line(raw, self.rules.macros).map_err(|e| {
                let mut err = self.fault(e.fault, e.text);
                err.line = next.line;
                err
            })?;
            let at = |f: Fault, t: String| {
                let mut err = self.fault(f, t);
                err.line = next.line;
                err
            };
            if let Stmt::Words(words) = &line.stmt {
                let mut b = Block::<Huaxing>::default();
                self.decode(words, &mut b).map_err(|mut e| {
                    e.line = next.line;
                    e
                })?;
                for &(_, g, _) in &b.g {
                    match g {
                        G::Rapid | G::Linear | G::ArcCw | G::ArcCcw => motion = g,
                        G::NoseCancel => {
                            if nose.is_some() && nose_cancel.is_none() {
                                nose_cancel = Some(elems.len());
                            }
                        }
                        G::ConstantSurfaceSpeed
                        | G::ConstantRpm
                        | G::FeedPerMinute
                        | G::FeedPerRevolution
                        | G::Dwell
                        | G::ExactStopBlock
                        | G::ExactStopMode
                        | G::ContinuousMode => {}
                        G::NoseLeft | G::NoseRight if nose.is_none() => {
                            nose = Some((g, self.nose_offset_number(&b), elems.len()));
                        }
                        G::NoseLeft | G::NoseRight => {
                            return Err(at(
                                Fault::CompDirection,
                                "G41/G42 twice in a cycle contour".into(),
                            ))
                        }
                        other => {
                            return Err(at(
                                Fault::CycleFormat,
                                format!("{} is not allowed in a cycle contour", other.name()),
                            ))
                        }
                    }
                }
                if b.m
                    .iter()
                    .any(|m| matches!(m.0, M::SubprogramCall | M::SubprogramReturn | M::ProgramEnd))
                {
                    return Err(at(
                        Fault::CycleFormat,
                        "M98/M99/M30 inside a cycle contour".into(),
                    ));
                }
                let has = |c: char| b.has(c);
                if blocks == 0 {
                    info = (
                        has('Z') || has('W'),
                        has('X') || has('U'),
                        motion == G::Rapid,
                    );
                    if !matches!(motion, G::Rapid | G::Linear) {
                        return Err(at(
                            Fault::CycleFormat,
                            "the contour's first block must be G00 or G01".into(),
                        ));
                    }
                }
                blocks += 1;
                if blocks > MAX_CONTOUR_BLOCKS {
                    return Err(at(
                        Fault::ContourTooLong,
                        "cycle contour longer than 100 blocks".into(),
                    ));
                }
                if self.has_axis_words(&b) {
                    let mut end = cur.clone();
                    for (i, &letter) in self.core.setup.axes.iter().enumerate() {
                        if let Some(v) = b.get(letter) {
                            end[i] = v;
                        } else if let Some(d) = incremental_letter(letter).and_then(|c| b.get(c)) {
                            end[i] += d;
                        }
                    }
                    let (a, e) = (self.core.plane_point(&cur)?, self.core.plane_point(&end)?);
                    let elem = match motion {
                        G::ArcCw | G::ArcCcw => {
                            let ccw = motion == G::ArcCcw;
                            let c = match (b.get('R'), b.has('I') || b.has('K')) {
                                (Some(r), false) => geometry::center_from_radius(a, e, r, ccw),
                                (None, true) => geometry::check_center(
                                    a,
                                    e,
                                    Pt::new(
                                        a.z + b.get('K').unwrap_or(0.0),
                                        a.r + b.get('I').unwrap_or(0.0),
                                    ),
                                ),
                                _ => Err(ArcError::RadiusTooSmall),
                            }
                            .map_err(|x| {
                                let mut err = self.arc_error(x);
                                err.line = next.line;
                                err
                            })?;
                            Elem::Arc { a, b: e, c, ccw }
                        }
                        _ => Elem::Line { a, b: e },
                    };
                    if a.dist(e) > 1e-9 {
                        elems.push(elem);
                    }
                    cur = end;
                }
            } else if line.stmt != Stmt::Empty {
                return Err(at(
                    Fault::CycleFormat,
                    "macro statements inside a cycle contour are not supported".into(),
                ));
            }
            if line.number == Some(nf) {
                break;
            }
        }
        if let Some((g, offset, first_elem)) = nose {
            elems = self
                .compensated_contour(&elems, g, offset, first_elem, nose_cancel, here)
                .map_err(|mut e| {
                    e.line = self.core.line;
                    e
                })?;
        }
        Ok(Contour {
            elems,
            first_has_z: info.0,
            first_has_x: info.1,
            first_rapid: info.2,
            after: pos,
            first,
        })
    }

    fn p_q(&self, b: &Block<Huaxing>) -> Result<(u32, u32), ProgramError> {
        match (b.get('P'), b.get('Q')) {
            (Some(p), Some(q)) => Ok((whole(p), whole(q))),
            _ => Err(self.fault(Fault::MissingWord, "P(ns) and Q(nf) needed")),
        }
    }

    pub(super) fn compound_cycle(
        &mut self,
        b: &Block<Huaxing>,
        g: HuaxingG,
    ) -> Result<(), ProgramError> {
        if !(b.has('P') && b.has('Q')) {
            // First block: depth and retract (G71 U R, G72 W R, G73 U W R).
            let w = &mut self.d.compound;
            match g {
                HuaxingG::RoughTurning | HuaxingG::RoughFacing => {
                    let d = if g == HuaxingG::RoughTurning {
                        b.get('U')
                    } else {
                        b.get('W')
                    };
                    if let Some(d) = d {
                        w.depth = d.abs();
                    }
                    if let Some(e) = b.get('R') {
                        w.retract = e.abs();
                    }
                }
                _ => {
                    if let Some(u) = b.get('U') {
                        w.relief_x = u;
                    }
                    if let Some(v) = b.get('W') {
                        w.relief_z = v;
                    }
                    if let Some(r) = b.get('R') {
                        // 1–9999 passes (`000` §5.22.3).
                        w.passes = whole(r).clamp(1, 9999);
                    }
                }
            }
            return Ok(());
        }
        if self.core.comp.is_some() {
            return Err(self.fault(
                Fault::CompInCycle,
                "tool-nose compensation active on entering the cycle",
            ));
        }
        let (ns, nf) = self.p_q(b)?;
        let here = self.core.work_position();
        let a = self.core.plane_point(&here)?;
        let contour = self.contour(ns, nf, &here)?;
        let (du, dw) = (b.get('U').unwrap_or(0.0), b.get('W').unwrap_or(0.0));
        let (dr, dz) = (du * self.core.x_scale(), dw);
        let shifted: Vec<Elem> = contour.elems.iter().map(|e| e.shifted(dz, dr)).collect();
        let Some(first) = shifted.first().copied() else {
            return Err(self.fault(Fault::ContourData, "the contour has no motion"));
        };
        let feed = self.core.feed;
        let moves = match g {
            HuaxingG::PatternRepeat => self.g73_moves(a, &contour, dz, dr)?,
            _ => {
                let radial = g == HuaxingG::RoughTurning;
                let w = self.d.compound;
                if w.depth <= 0.0 {
                    return Err(self.fault(Fault::CycleZero, "depth of cut is 0"));
                }
                let type_two = if radial {
                    contour.first_has_z
                } else {
                    contour.first_has_x
                };
                if type_two && contour.first_rapid {
                    return Err(self.fault(
                        Fault::ContourStart,
                        "Type II contour: the ns block must not be G00",
                    ));
                }
                let coord = |p: Pt| if radial { p.r } else { p.z };
                let along = |p: Pt| if radial { p.z } else { p.r };
                let a1 = first.start();
                let diff = coord(a1) - coord(first.end());
                if diff.abs() < 1e-9 && !type_two {
                    return Err(self.fault(
                        Fault::CycleFormat,
                        "the ns block does not move along the depth axis",
                    ));
                }
                let sigma = if diff.abs() > 1e-9 {
                    diff.signum()
                } else {
                    // Type II may start along the cut: the deepest point decides.
                    let deepest = shifted
                        .iter()
                        .map(|e| coord(e.end()))
                        .fold(coord(a1), |m, c| {
                            if (c - coord(a1)).abs() > (m - coord(a1)).abs() {
                                c
                            } else {
                                m
                            }
                        });
                    (coord(a1) - deepest).signum()
                };
                // The contour tolerance GS#33 (0.05 mm unless the machine sets it).
                let tol = self.core.setup.contour_tolerance;
                // No contour point beyond the start (`000` alarm 57), within the tolerance.
                for e in &shifted {
                    let (lo, hi) = e.extent(radial);
                    let worst = if sigma > 0.0 {
                        hi - coord(a1)
                    } else {
                        coord(a1) - lo
                    };
                    if worst > tol {
                        return Err(self.fault(
                            Fault::ContourBeyondStart,
                            "a contour point lies beyond the cycle's start point",
                        ));
                    }
                }
                // The cut axis must run one way (Type I and II, `000` §5.22.1).
                let zeta = shifted
                    .iter()
                    .map(|e| along(e.end()) - along(e.start()))
                    .find(|d| d.abs() > 1e-9)
                    .unwrap_or(0.0)
                    .signum();
                for e in &shifted {
                    let (lo, hi) = e.extent(!radial);
                    let (s, t) = (along(e.start()), along(e.end()));
                    let back = if zeta >= 0.0 {
                        s - lo.min(t)
                    } else {
                        hi.max(t) - s
                    };
                    if (t - s) * zeta < -tol || back > tol + (t - s).abs() {
                        return Err(self.fault(
                            Fault::ContourData,
                            "the contour turns back along the cut axis",
                        ));
                    }
                }
                // G71 type I: no pockets, X runs one way too after the ns move (§5.22.1,
                // decision D54).
                if radial && !type_two {
                    self.type_one_monotonic(&shifted[1..], tol)?;
                }
                // Bound the work a cycle may generate (a tiny depth over a long contour).
                let span = shifted
                    .iter()
                    .map(|e| {
                        let (lo, hi) = e.extent(radial);
                        (lo - coord(a1)).abs().max((hi - coord(a1)).abs())
                    })
                    .fold(0.0, f64::max);
                if span / w.depth > MAX_CYCLE_STEPS as f64 {
                    return Err(self.fault(
                        Fault::OutOfRange,
                        format!(
                            "depth of cut {} gives more than {MAX_CYCLE_STEPS} passes",
                            w.depth
                        ),
                    ));
                }
                let rough = Rough {
                    radial,
                    sigma,
                    depth: w.depth,
                    retract: w.retract,
                    type_one: !type_two,
                    skip_final: false,
                };
                // The contour starts at A' (A shifted by the allowance).
                let mut elems = vec![Elem::Line {
                    a: Pt::new(a.z + dz, a.r + dr),
                    b: first.start(),
                }];
                if elems[0].start().dist(elems[0].end()) < 1e-9 {
                    elems.clear();
                }
                elems.extend(shifted.iter().copied());
                // The ns move A→B is the first element already (it starts at A).
                elems.retain(|e| e.start().dist(e.end()) > 1e-9);
                rough.moves(a, &elems)
            }
        };
        self.core.emit_plane(&moves, feed)?;
        // Continue after nf when the contour follows the cycle block, else after the block
        // (`000` §5.22.2).
        if contour.first == self.core.level().pos {
            self.core.level().pos = contour.after;
        }
        Ok(())
    }

    /// The depth axis (X) of a G71 type I contour after its ns move runs one way, within
    /// `tol`: a pocket needs type II (alarm 47, decision D54).
    fn type_one_monotonic(&self, elems: &[Elem], tol: f64) -> Result<(), ProgramError> {
        let x = |p: Pt| p.r;
        let dir = elems
            .iter()
            .map(|e| x(e.end()) - x(e.start()))
            .find(|d| d.abs() > tol)
            .unwrap_or(0.0)
            .signum();
        for e in elems {
            let (lo, hi) = e.extent(true);
            let (s, t) = (x(e.start()), x(e.end()));
            // How far the element goes back against the direction, arcs' bulges included.
            let back = if dir >= 0.0 {
                s.min(t) - lo + (s - t).max(0.0)
            } else {
                hi - s.max(t) + (t - s).max(0.0)
            };
            if back > tol {
                return Err(self.fault(
                    Fault::ContourData,
                    format!(
                        "G71 type I: the contour turns back along X by {} mm (a pocket): \
                         program it as type II, with Z(W) in the ns block",
                        cnc_interpreter_core::show(back)
                    ),
                ));
            }
        }
        Ok(())
    }

    fn g73_moves(
        &self,
        a: Pt,
        contour: &Contour,
        dz: f64,
        dr: f64,
    ) -> Result<Vec<Move>, ProgramError> {
        let w = self.d.compound;
        if w.relief_x == 0.0 && w.relief_z == 0.0 {
            return Err(self.fault(Fault::PatternReliefZero, "G73 relief U and W are both 0"));
        }
        let n = w.passes.max(2);
        let (ri, rk) = (w.relief_x, w.relief_z);
        let mut out = Vec::new();
        for i in 1..=n {
            let frac = (n - i) as f64 / (n - 1) as f64;
            let (sz, sr) = (rk * frac + dz, ri * frac + dr);
            out.push(Move::Rapid(Pt::new(a.z + sz, a.r + sr)));
            for (k, e) in contour.elems.iter().enumerate() {
                let e = e.shifted(sz, sr);
                out.push(match e {
                    Elem::Line { b, .. } if k == 0 && contour.first_rapid => Move::Rapid(b),
                    Elem::Line { b, .. } => Move::Feed(b),
                    Elem::Arc { b, c, ccw, .. } => Move::Arc { to: b, c, ccw },
                });
            }
        }
        out.push(Move::Rapid(a));
        Ok(out)
    }

    /// The contour the tool's controlled point follows with tool-nose compensation: the
    /// elements before `first` as written, the one at `first` the start-up move, the one at
    /// `cancel` (if any) the cancel move (decision D30).
    fn compensated_contour(
        &self,
        elems: &[Elem],
        g: G<HuaxingG>,
        offset: u32,
        first: usize,
        cancel: Option<usize>,
        here: &[f64],
    ) -> Result<Vec<Elem>, ProgramError> {
        let tool = self.core.setup.offsets.tool(offset);
        let radius = self.nose_radius(tool.radius, &format!("offset {offset}"))?;
        let side = self.comp_side(g);
        let start = elems
            .get(first)
            .map(|e| e.start())
            .map_or_else(|| self.core.plane_point(here), Ok)?;
        let mut comp =
            comp::RadiusComp::new(side, radius, tool.tip, start, comp::Startup::ToNextElement);
        let mut outs = Vec::new();
        let mut out_elems: Vec<Elem> = elems[..first.min(elems.len())].to_vec();
        for (i, e) in elems.iter().enumerate().skip(first) {
            if Some(i) == cancel {
                outs.extend(comp.cancel(e.end(), 0.0, comp::Kind::Feed(1.0), 0));
                out_elems.extend(outs.drain(..).map(|o| o.path));
                out_elems.extend(elems[i + 1..].iter().copied());
                return Ok(out_elems);
            }
            outs.extend(
                comp.push(
                    *e,
                    0.0,
                    comp::Kind::Feed(1.0),
                    0,
                    comp::ElementRules::default(),
                )
                .map_err(|x| self.core.comp_fault(x))?,
            );
        }
        outs.extend(comp.flush());
        out_elems.extend(outs.into_iter().map(|o| o.path));
        Ok(out_elems)
    }

    /// G70: runs the contour blocks as written, then returns to the start point.
    pub(super) fn finishing(&mut self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        let (ns, nf) = self.p_q(b)?;
        let text = self.core.level().text.clone();
        let first = find_number(&text, self.core.level().pos, ns)
            .ok_or_else(|| self.fault(Fault::TargetNotFound, format!("N{ns} not found")))?;
        if find_number(&text, first, nf).is_none() {
            return Err(self.fault(Fault::TargetNotFound, format!("N{nf} not found")));
        }
        let home = self.core.work_position();
        let then = self.core.level().pos;
        // A program end in the G70 block itself (`G70 P Q M30`) comes after the cycle.
        let end_code =
            b.m.iter()
                .find(|m| m.0 == M::ProgramEnd)
                .map(|m| (m.1 / 10) as i32);
        let f = self.core.level();
        f.repeats.push(Repeat::Range {
            first,
            last: nf,
            remaining: Some(1),
            then: Some(then),
            home: Some(home),
            end_code,
        });
        f.pos = first;
        Ok(())
    }

    /// G76 multiple threading cycle (`000` §5.23.6).
    pub(super) fn g76(&mut self, b: &Block<Huaxing>) -> Result<(), ProgramError> {
        let has_end = b.has('X') || b.has('U') || b.has('Z') || b.has('W');
        if !has_end {
            // First block: P(mmrraa) Q(Δdmin) R(d) J K.
            if let Some(p) = b.get('P') {
                let p = whole(p);
                let digits = p.to_string().len();
                let w = &mut self.d.compound;
                w.g76_angle = (p % 100) as f64;
                if digits > 2 {
                    w.g76_runout = ((p / 100) % 100) as f64;
                }
                if digits > 4 {
                    w.g76_finish_passes = p / 10000;
                }
            }
            if let Some(q) = self.increments(b, 'Q') {
                self.d.compound.g76_min_depth = q.abs();
            }
            if let Some(r) = b.get('R') {
                self.d.compound.g76_allowance = r.abs();
            }
            self.d.compound.g76_j = b.get('J');
            self.d.compound.g76_k = b.get('K');
            return Ok(());
        }
        let lead = self.lead(b, true)?;
        let (Some(k), Some(d1)) = (self.increments(b, 'P'), self.increments(b, 'Q')) else {
            return Err(self.fault(
                Fault::ThreadDepthMissing,
                "G76: thread height P(k) or first depth Q(Δd) missing",
            ));
        };
        let (k, d1) = (k.abs(), d1.abs());
        let w = self.d.compound;
        if d1 <= 0.0 || k <= 0.0 || w.g76_allowance >= k {
            return Err(self.fault(
                Fault::ThreadDepthMissing,
                "G76: depths must be positive and the allowance smaller than the height",
            ));
        }
        let here = self.core.work_position();
        let (xi, zi) = self.core.xz()?;
        let end = self.end_point(b)?;
        let (x0, z0) = (here[xi], here[zi]);
        let (xe, ze) = (end[xi], end[zi]);
        let taper = b.get('R').unwrap_or(0.0);
        // Outside thread when the start is outside the end diameter.
        let sigma = if x0 >= xe { 1.0 } else { -1.0 };
        let zeta = if ze < z0 { -1.0 } else { 1.0 };
        let tan = (w.g76_angle / 2.0).to_radians().tan();
        let runout = match (w.g76_j, w.g76_k) {
            (Some(j), k) => (j.abs(), k.unwrap_or(j).abs()),
            (None, Some(k)) => (0.0, k.abs()),
            (None, None) => {
                let r = w.g76_runout * 0.1 * lead;
                (r, r)
            }
        };
        let at = |x: f64, z: f64| {
            let mut v = here.clone();
            v[xi] = x;
            v[zi] = z;
            v
        };
        // Depths of the rough passes, then the finish allowance, then spring passes.
        let depths = thread_depths(d1, k, w.g76_min_depth, w.g76_allowance, w.g76_finish_passes);
        for d in depths {
            // Single-flank infeed along the flank at half the tool angle.
            let zs = z0 + zeta * d * tan;
            let xs = xe + 2.0 * taper + 2.0 * sigma * (k - d);
            let xend = xe + 2.0 * sigma * (k - d);
            self.core.emit(&at(xs, zs), MoveKind::Rapid)?;
            self.thread_to(&at(xend, ze), lead, 0.0, sigma * runout.0, runout.1)?;
            let cur = self.core.work_position();
            self.core.emit(&at(x0, cur[zi]), MoveKind::Rapid)?;
            self.core.emit(&at(x0, z0), MoveKind::Rapid)?;
        }
        Ok(())
    }
}
