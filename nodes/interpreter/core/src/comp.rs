//! Radius compensation, a path filter: the tool's nose (a lathe tool) or the cutter (a mill)
//! is a circle of radius R, and the programmed point is its imaginary tip. With
//! compensation the nose circle runs along the programmed contour on the chosen side, and the
//! controlled point (the imaginary tip) follows the nose centre's path shifted by the tip
//! vector of the tool's tip direction.
//!
//! Works in the turning plane (`Pt`: Z, radius) on whole elements, one element behind the
//! program: an element is held until the next one shows how the two meet (decision D30 in
//! `docs/decisions.md`):
//! - inner corner: both offset elements are cut back to their intersection;
//! - outer corner: an arc of radius R around the corner joins them, or (when the front end
//!   asks) both offset elements are extended to their intersection while the contour turns
//!   by less than [`OUTER_INTERSECTION_LIMIT`] (decision D103);
//! - start-up: see [`Startup`];
//! - cancel: the held element ends at its offset end, then a line to the uncompensated point;
//! - restart (a new side or radius without a cancel): the held element ends at its offset
//!   end, then a line to the next element's new offset start (decision D104).
//!
//! On the mill the same geometry serves cutter radius compensation (tip 0: the programmed
//! point is the cutter's centre line). Moves along the plane's normal (Z in G17) with no
//! motion in the plane wait with the held element and follow its end (decision D48).
//!
//! Pure geometry: no interpreter state, errors as [`CompError`].

use crate::geometry::{Elem, Pt};

const EPS: f64 = 1e-9;

/// The turn of the contour, degrees, from which an outer corner gets the arc even where the
/// front end asks for the intersection: a sharp corner's intersection lies far out and the
/// cutter would travel there for nothing (decision D103).
pub const OUTER_INTERSECTION_LIMIT: f64 = 100.0;

/// What the front end's modal state asks of one element (decisions D98, D103).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ElementRules {
    /// The feed holds on the programmed contour, not at the cutter centre.
    pub feed_on_contour: bool,
    /// The largest feed of the control: a centre feed scaled up for the contour is held
    /// there (the axes' limits slow it further; 0: no limit).
    pub max_feed: f64,
    /// Outer corners before this element meet at the offsets' intersection (below
    /// [`OUTER_INTERSECTION_LIMIT`]) instead of an arc.
    pub outer_intersection: bool,
}

/// Which side of the contour the nose runs on, looking along the direction of travel in the
/// Z–X plane drawn with +Z to the right and +X up (decision D30).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    Left,
    Right,
}

impl Side {
    pub fn other(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }
}

/// How the element is moved: rapid or feed (G02/G03 carry their feed too).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kind {
    Rapid,
    Feed(f64),
}

/// How compensation starts (decisions D30, D48).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Startup {
    /// The start-up line goes from the uncompensated point to the offset start of the next
    /// element.
    ToNextElement,
    /// The first element is offset from its start; a connecting move gets there.
    Connect,
    /// The start-up move itself is compensated, its start left where the tool is, and meets
    /// the next element as any corner does (the type B start-up of ISO controls, and
    /// LinuxCNC's).
    AlongEntry,
}

/// One move for the controlled point (imaginary tip), in the plane, with its source line and
/// the coordinate along the plane's normal at its end (`depth`, unused on the lathe).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Out {
    pub path: Elem,
    pub depth: f64,
    pub kind: Kind,
    pub line: u32,
    /// The controlled point less the programmed contour's point at the element's end (the
    /// offset and the tip); `None` where it is what it was at the element's start. A
    /// transformation that offsets groove walls with a slide of its own needs it
    /// ([`crate::cylinder`]).
    pub offset: Option<Pt>,
}

#[derive(Debug, Clone, PartialEq)]
pub enum CompError {
    /// Two offset elements of an inner corner do not meet.
    NoIntersection,
    /// The nose radius is larger than a concave arc's radius.
    ArcVanishes,
    /// An arc cannot be the start-up move of [`Startup::AlongEntry`].
    ArcStartup,
    /// Trimmed at both corners, an offset line would run against its programmed direction:
    /// the tool would cut into the contour (the interference check of ISO controls).
    Interference,
    /// A new radius was asked for with an arc as the element that carries the change.
    RadiusChangeOnArc,
}

#[derive(Debug, Clone, Copy)]
struct Held {
    /// The offset element, its start already joined to what came before.
    path: Elem,
    /// The uncompensated point a [`Startup::AlongEntry`] start-up move leaves from.
    from: Option<Pt>,
    /// The programmed line's direction (None for arcs), for the interference check.
    course: Option<Pt>,
    depth: f64,
    kind: Kind,
    line: u32,
}

/// A move along the plane's normal only, waiting for the held element to end.
#[derive(Debug, Clone, Copy)]
struct Still {
    depth: f64,
    kind: Kind,
    line: u32,
}

#[derive(Debug, Clone, Copy)]
enum Start {
    /// The next element is the start-up move from this uncompensated point.
    Pending(Startup, Pt),
    Running,
}

#[derive(Debug, Clone)]
pub struct RadiusComp {
    /// Signed offset: +R to the left, −R to the right.
    offset: f64,
    /// From nose centre to imaginary tip.
    tip: Pt,
    /// The tip direction `tip` was made from (a restart makes it again for its radius).
    tip_direction: u8,
    /// A new radius the next element changes to along its length (decision D105).
    radius_to: Option<f64>,
    start: Start,
    /// The [`Startup::ToNextElement`] start-up element, waiting for the element after it.
    startup: Option<(Pt, Elem, f64, Kind, u32)>,
    held: Option<Held>,
    /// Moves along the normal after the held element, in program order.
    stills: Vec<Still>,
}

/// The vector from the nose centre to the imaginary tip for tip direction 0–9, with Z to the
/// right and X up: 3 is the outside-turning tool toward the chuck (tip below and left of the
/// centre), 2 the boring bar; 0 and 9 program the centre itself (decision D30).
pub fn tip_vector(direction: u8, radius: f64) -> Pt {
    let (z, r) = match direction {
        1 => (1.0, 1.0),
        2 => (-1.0, 1.0),
        3 => (-1.0, -1.0),
        4 => (1.0, -1.0),
        5 => (1.0, 0.0),
        6 => (0.0, 1.0),
        7 => (-1.0, 0.0),
        8 => (0.0, -1.0),
        _ => (0.0, 0.0),
    };
    Pt::new(z * radius, r * radius)
}

fn add(a: Pt, b: Pt) -> Pt {
    Pt::new(a.z + b.z, a.r + b.r)
}
fn sub(a: Pt, b: Pt) -> Pt {
    Pt::new(a.z - b.z, a.r - b.r)
}
fn scale(a: Pt, k: f64) -> Pt {
    Pt::new(a.z * k, a.r * k)
}
fn len(a: Pt) -> f64 {
    a.z.hypot(a.r)
}
fn unit(a: Pt) -> Pt {
    let l = len(a);
    if l < EPS {
        Pt::new(0.0, 0.0)
    } else {
        scale(a, 1.0 / l)
    }
}
fn cross(a: Pt, b: Pt) -> f64 {
    a.z * b.r - a.r * b.z
}
fn dot(a: Pt, b: Pt) -> f64 {
    a.z * b.z + a.r * b.r
}
/// Rotated a quarter turn counter-clockwise: the left normal of a direction.
fn left(a: Pt) -> Pt {
    Pt::new(-a.r, a.z)
}

/// What compensation needs of an element beyond `geometry`: tangents, and the element
/// moved, offset or cut back.
impl Elem {
    fn tangent_at(&self, p: Pt) -> Pt {
        match *self {
            Elem::Line { a, b } => unit(sub(b, a)),
            Elem::Arc { c, ccw, .. } => {
                let radial = unit(sub(p, c));
                // Counter-clockwise travel is the radial direction turned left.
                if ccw {
                    left(radial)
                } else {
                    scale(left(radial), -1.0)
                }
            }
        }
    }
    fn start_tangent(&self) -> Pt {
        self.tangent_at(self.start())
    }
    fn end_tangent(&self) -> Pt {
        self.tangent_at(self.end())
    }
    fn translated(&self, d: Pt) -> Elem {
        match *self {
            Elem::Line { a, b } => Elem::Line {
                a: add(a, d),
                b: add(b, d),
            },
            Elem::Arc { a, b, c, ccw } => Elem::Arc {
                a: add(a, d),
                b: add(b, d),
                c: add(c, d),
                ccw,
            },
        }
    }
    /// The element moved sideways by `offset` (+ left).
    fn offset(&self, offset: f64) -> Result<Elem, CompError> {
        match *self {
            Elem::Line { a, b } => {
                let n = scale(left(unit(sub(b, a))), offset);
                Ok(Elem::Line {
                    a: add(a, n),
                    b: add(b, n),
                })
            }
            Elem::Arc { a, b, c, ccw } => {
                let rho = len(sub(a, c));
                // The left side of a counter-clockwise arc is its inside.
                let new = if ccw { rho - offset } else { rho + offset };
                if new <= EPS {
                    return Err(CompError::ArcVanishes);
                }
                let k = new / rho;
                Ok(Elem::Arc {
                    a: add(c, scale(sub(a, c), k)),
                    b: add(c, scale(sub(b, c), new / len(sub(b, c)))),
                    c,
                    ccw,
                })
            }
        }
    }
    /// The element from `p` on. A full circle entered at `p` still ends at its own offset end,
    /// as ISO controls cut it (what lies between is left: a bore wants a lead-in arc).
    fn with_start(&self, p: Pt) -> Elem {
        match *self {
            Elem::Line { b, .. } => Elem::Line { a: p, b },
            Elem::Arc { b, c, ccw, .. } => Elem::Arc { a: p, b, c, ccw },
        }
    }
    fn with_end(&self, p: Pt) -> Elem {
        match *self {
            Elem::Line { a, .. } => Elem::Line { a, b: p },
            Elem::Arc { a, c, ccw, .. } => Elem::Arc { a, b: p, c, ccw },
        }
    }
}

/// Points where the full line or circle of `p` meets that of `q`.
fn intersections(p: &Elem, q: &Elem) -> Vec<Pt> {
    match (*p, *q) {
        (Elem::Line { a, b }, Elem::Line { a: c, b: d }) => {
            let (u, v) = (sub(b, a), sub(d, c));
            let den = cross(u, v);
            if den.abs() < EPS {
                return Vec::new();
            }
            let t = cross(sub(c, a), v) / den;
            vec![add(a, scale(u, t))]
        }
        (Elem::Line { a, b }, Elem::Arc { c, a: s, .. })
        | (Elem::Arc { c, a: s, .. }, Elem::Line { a, b }) => line_circle(a, b, c, len(sub(s, c))),
        (Elem::Arc { c: c1, a: s1, .. }, Elem::Arc { c: c2, a: s2, .. }) => {
            circle_circle(c1, len(sub(s1, c1)), c2, len(sub(s2, c2)))
        }
    }
}

fn line_circle(a: Pt, b: Pt, c: Pt, rho: f64) -> Vec<Pt> {
    let u = unit(sub(b, a));
    let f = sub(a, c);
    let bq = dot(f, u);
    let cq = dot(f, f) - rho * rho;
    let disc = bq * bq - cq;
    if disc < -EPS {
        return Vec::new();
    }
    let s = disc.max(0.0).sqrt();
    vec![add(a, scale(u, -bq - s)), add(a, scale(u, -bq + s))]
}

fn circle_circle(c1: Pt, r1: f64, c2: Pt, r2: f64) -> Vec<Pt> {
    let d = len(sub(c2, c1));
    if d < EPS || d > r1 + r2 + EPS || d < (r1 - r2).abs() - EPS {
        return Vec::new();
    }
    let a = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d);
    let h = (r1 * r1 - a * a).max(0.0).sqrt();
    let u = unit(sub(c2, c1));
    let m = add(c1, scale(u, a));
    let n = left(u);
    vec![add(m, scale(n, h)), add(m, scale(n, -h))]
}

impl RadiusComp {
    /// Compensation from the uncompensated point `from`, starting as `startup` says.
    pub fn new(side: Side, radius: f64, tip: u8, from: Pt, startup: Startup) -> RadiusComp {
        let offset = match side {
            Side::Left => radius,
            Side::Right => -radius,
        };
        RadiusComp {
            offset,
            tip: tip_vector(tip, radius),
            tip_direction: tip,
            radius_to: None,
            start: Start::Pending(startup, from),
            startup: None,
            held: None,
            stills: Vec::new(),
        }
    }

    /// The feed the cutter centre runs an offset element at: with the feed held on the
    /// contour (decision D98) an arc's feed is scaled by offset radius over programmed radius,
    /// so the contour runs at the programmed feed (faster outside an arc, slower inside).
    /// Lines need no correction.
    fn centre_feed(rules: ElementRules, path: &Elem, off: &Elem, kind: Kind) -> Kind {
        match (rules.feed_on_contour, path, off, kind) {
            (true, Elem::Arc { a, c, .. }, Elem::Arc { a: oa, c: oc, .. }, Kind::Feed(f)) => {
                let rho = len(sub(*a, *c));
                if rho > EPS {
                    let scaled = f * len(sub(*oa, *oc)) / rho;
                    let limit = if rules.max_feed > 0.0 {
                        rules.max_feed.max(f)
                    } else {
                        f64::INFINITY
                    };
                    Kind::Feed(scaled.min(limit))
                } else {
                    kind
                }
            }
            _ => kind,
        }
    }

    fn out(&self, path: Elem, depth: f64, kind: Kind, line: u32) -> Out {
        self.out_along(path, path.end_tangent(), depth, kind, line)
    }

    /// An offset element (or a corner arc) whose end runs along `tangent`: the contour's
    /// point there is the offset to the tangent's side away.
    fn out_along(&self, path: Elem, tangent: Pt, depth: f64, kind: Kind, line: u32) -> Out {
        Out {
            path: path.translated(self.tip),
            depth,
            kind,
            line,
            offset: self.offset_along(tangent),
        }
    }

    /// The controlled point less the contour's point on an element running along
    /// `tangent` (`None` for no direction).
    fn offset_along(&self, tangent: Pt) -> Option<Pt> {
        (len(tangent) > EPS).then(|| add(scale(left(unit(tangent)), self.offset), self.tip))
    }

    /// The held element as it is cut: from the uncompensated point if it is the start-up
    /// move, then the moves along the normal that waited for its end.
    fn release(&mut self, h: Held, out: &mut Vec<Out>) -> Result<(), CompError> {
        if let (None, Some(course), Elem::Line { a, b }) = (h.from, h.course, h.path) {
            if dot(sub(b, a), course) < -1e-6 {
                return Err(CompError::Interference);
            }
        }
        let path = match h.from {
            Some(from) => h.path.with_start(from),
            None => h.path,
        };
        // A line's own course: trimmed, its offset path may be reversed or empty.
        let tangent = h.course.unwrap_or_else(|| h.path.end_tangent());
        out.push(self.out_along(path, tangent, h.depth, h.kind, h.line));
        self.release_stills(add(path.end(), self.tip), out);
        Ok(())
    }

    /// The moves along the normal that waited, at `end` (a controlled point).
    fn release_stills(&mut self, end: Pt, out: &mut Vec<Out>) {
        for s in std::mem::take(&mut self.stills) {
            out.push(Out {
                path: Elem::Line { a: end, b: end },
                depth: s.depth,
                kind: s.kind,
                line: s.line,
                offset: None,
            });
        }
    }

    /// The depth the tool is at once everything released so far has run.
    fn depth_after(&self, h: &Held) -> f64 {
        self.stills.last().map(|s| s.depth).unwrap_or(h.depth)
    }

    /// Takes the next programmed element, ending at `depth` along the normal; returns the
    /// moves now certain. `rules`: the front end's modal switches for it (D98, D103).
    pub fn push(
        &mut self,
        path: Elem,
        depth: f64,
        kind: Kind,
        line: u32,
        rules: ElementRules,
    ) -> Result<Vec<Out>, CompError> {
        let starting = matches!(self.start, Start::Pending(..));
        let off = match self.radius_to.take() {
            // Before the first element the new radius holds from the start.
            Some(r) if starting => {
                self.set_radius(r);
                path.offset(self.offset)?
            }
            // The offset grows or shrinks along the line, from the old radius at its start
            // to the new at its end (decision D105).
            Some(r) => {
                let Elem::Line { a, b } = path else {
                    return Err(CompError::RadiusChangeOnArc);
                };
                let n = left(unit(sub(b, a)));
                let from = add(a, scale(n, self.offset));
                self.set_radius(r);
                Elem::Line {
                    a: from,
                    b: add(b, scale(n, self.offset)),
                }
            }
            None => path.offset(self.offset)?,
        };
        // The element's own feed; a corner arc before it keeps the programmed one.
        let cut = Self::centre_feed(rules, &path, &off, kind);
        let course = match path {
            Elem::Line { a, b } => Some(unit(sub(b, a))),
            Elem::Arc { .. } => None,
        };
        let mut out = Vec::new();
        // What this element leaves held: its offset path (or what joining made of it).
        let hold = |path, from| Held {
            path,
            from,
            course,
            depth,
            kind: cut,
            line,
        };
        if let Start::Pending(startup, from) = self.start {
            match startup {
                Startup::ToNextElement => {
                    // The start-up element waits for the element after it.
                    self.startup = Some((from, path, depth, kind, line));
                }
                Startup::Connect => {
                    out.push(Out {
                        path: Elem::Line {
                            a: from,
                            b: add(off.start(), self.tip),
                        },
                        depth,
                        kind,
                        line,
                        offset: self.offset_along(off.start_tangent()),
                    });
                    self.held = Some(hold(off, None));
                }
                Startup::AlongEntry => {
                    if matches!(path, Elem::Arc { .. }) {
                        return Err(CompError::ArcStartup);
                    }
                    self.held = Some(hold(off, Some(sub(from, self.tip))));
                }
            }
            self.start = Start::Running;
            return Ok(out);
        }
        if let Some((from, _, s_depth, s_kind, s_line)) = self.startup.take() {
            // Start-up move: to the offset start of this element (perpendicular to it).
            out.push(Out {
                path: Elem::Line {
                    a: from,
                    b: add(off.start(), self.tip),
                },
                depth: s_depth,
                kind: s_kind,
                line: s_line,
                offset: self.offset_along(off.start_tangent()),
            });
            self.release_stills(add(off.start(), self.tip), &mut out);
            self.held = Some(hold(off, None));
            return Ok(out);
        }
        let Some(held) = self.held.take() else {
            self.held = Some(hold(off, None));
            return Ok(out);
        };
        let next = self.join(held, path, off, kind, line, rules, &mut out)?;
        self.held = Some(hold(next, None));
        Ok(out)
    }

    /// A move along the plane's normal only (a plunge in G17): it runs where the held element
    /// ends, so it waits for it; with nothing held it runs where the tool is.
    pub fn push_still(&mut self, here: Pt, depth: f64, kind: Kind, line: u32) -> Vec<Out> {
        if self.holding() {
            self.stills.push(Still { depth, kind, line });
            return Vec::new();
        }
        vec![Out {
            path: Elem::Line { a: here, b: here },
            depth,
            kind,
            line,
            offset: None,
        }]
    }

    /// Joins the held offset element to the offset of `path`: queues the held element
    /// (trimmed or extended, and a corner arc after it when the corner is outside) and
    /// returns the next offset element from where it starts.
    #[allow(clippy::too_many_arguments)]
    fn join(
        &mut self,
        held: Held,
        path: Elem,
        off: Elem,
        kind: Kind,
        line: u32,
        rules: ElementRules,
        out: &mut Vec<Out>,
    ) -> Result<Elem, CompError> {
        // An offset element runs parallel to its programmed one: same tangents (a line's
        // from its programmed course: trimmed at its start it may already point backwards).
        let t1 = held.course.unwrap_or_else(|| held.path.end_tangent());
        let t2 = path.start_tangent();
        let turn = cross(t1, t2);
        let along = dot(t1, t2);
        let corner = sub(held.path.end(), scale(left(t1), self.offset));
        if turn.abs() < 1e-9 && along > 0.0 {
            // Tangent: the offsets meet (within rounding); go straight on.
            let end = held.path.end();
            self.release(held, out)?;
            return Ok(off.with_start(end));
        }
        // The nose is on the outside of the turn when it turns away from the offset side.
        let outside = turn * self.offset < 0.0 || along <= -1.0 + 1e-9;
        let turned = turn.abs().atan2(along).to_degrees();
        if outside && rules.outer_intersection && turned < OUTER_INTERSECTION_LIMIT {
            // Both offsets extended to where they cross.
            if let Some(next) = self.meet_at_crossing(held, off, corner, out)? {
                return Ok(next);
            }
        }
        if outside {
            let arc = Elem::Arc {
                a: held.path.end(),
                b: off.start(),
                c: corner,
                // Around an outer corner the nose turns the way the contour turns.
                ccw: self.offset < 0.0,
            };
            let depth = self.depth_after(&held);
            self.release(held, out)?;
            out.push(self.out(arc, depth, kind, line));
            return Ok(off);
        }
        // Inside: both are cut back to where they cross.
        self.meet_at_crossing(held, off, corner, out)?
            .ok_or(CompError::NoIntersection)
    }

    /// Ends the held element where it crosses `off` (the crossing nearest the programmed
    /// `corner`), queues it, and returns `off` from there; `None` where they do not cross.
    fn meet_at_crossing(
        &mut self,
        held: Held,
        off: Elem,
        corner: Pt,
        out: &mut Vec<Out>,
    ) -> Result<Option<Elem>, CompError> {
        let crossing = intersections(&held.path, &off).into_iter().min_by(|a, b| {
            len(sub(*a, corner))
                .partial_cmp(&len(sub(*b, corner)))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        let Some(x) = crossing else {
            return Ok(None);
        };
        self.release(
            Held {
                path: held.path.with_end(x),
                ..held
            },
            out,
        )?;
        Ok(Some(off.with_start(x)))
    }

    /// A new radius (a new cutting edge under compensation): the next element changes from
    /// the old radius at its start to this one at its end, and the elements after it run
    /// with it (decision D105). The side stays.
    pub fn change_radius(&mut self, radius: f64) {
        self.radius_to = Some(radius.abs());
    }

    fn set_radius(&mut self, radius: f64) {
        self.offset = match self.side() {
            Side::Left => radius,
            Side::Right => -radius,
        };
        self.tip = tip_vector(self.tip_direction, radius);
    }

    /// A new compensation on `side` with `radius` without a cancel (the same side again, the
    /// other side, a new radius): the held element ends normal to its end (no corner), and
    /// the next element pushed starts from there with a line to its new offset start.
    /// Returns the moves now certain; `here`: the controlled point when nothing was held.
    pub fn restart(&mut self, side: Side, radius: f64, here: Pt) -> Vec<Out> {
        let out = self.flush();
        let from = out
            .last()
            .map(|o| o.path.end())
            .or_else(|| self.startup_point())
            .unwrap_or(here);
        *self = RadiusComp::new(side, radius, self.tip_direction, from, Startup::Connect);
        out
    }

    /// Cancel (G40): the held element to its offset end, then a line to `target`
    /// uncompensated, ending at `depth`.
    pub fn cancel(&mut self, target: Pt, depth: f64, kind: Kind, line: u32) -> Vec<Out> {
        let mut out = self.flush();
        let from = out
            .last()
            .map(|o| o.path.end())
            .unwrap_or_else(|| self.startup_point().unwrap_or(target));
        out.push(Out {
            path: Elem::Line { a: from, b: target },
            depth,
            kind,
            line,
            offset: Some(Pt::new(0.0, 0.0)),
        });
        out
    }

    fn startup_point(&self) -> Option<Pt> {
        match self.start {
            Start::Pending(_, p) => Some(p),
            Start::Running => self.startup.map(|s| s.0),
        }
    }

    /// The side the tool runs on (radius 0 keeps the side it was given).
    pub fn side(&self) -> Side {
        if self.offset.is_sign_negative() {
            Side::Right
        } else {
            Side::Left
        }
    }

    /// The radius the tool runs at now (a new radius takes effect along the next element).
    pub fn radius(&self) -> f64 {
        self.offset.abs()
    }

    /// The source line of the element waiting for the next one.
    pub fn held_line(&self) -> Option<u32> {
        match (&self.startup, &self.held) {
            (Some(s), _) => Some(s.4),
            (None, Some(h)) => Some(h.line),
            (None, None) => None,
        }
    }

    /// True while an element waits for the next one.
    pub fn holding(&self) -> bool {
        self.held.is_some() || self.startup.is_some()
    }

    /// Ends compensation where it is (program end): the held element to its offset end.
    pub fn flush(&mut self) -> Vec<Out> {
        let mut out = Vec::new();
        if let Some((from, path, depth, kind, line)) = self.startup.take() {
            // Only the start-up element was given: it ends offset from its own end.
            let off = path.offset(self.offset).unwrap_or(path);
            out.push(Out {
                path: Elem::Line {
                    a: from,
                    b: add(off.end(), self.tip),
                },
                depth,
                kind,
                line,
                offset: self.offset_along(off.end_tangent()),
            });
            self.release_stills(add(off.end(), self.tip), &mut out);
        }
        if let Some(h) = self.held.take() {
            // At the end nothing trims the element's end: it cannot have turned around.
            let _ = self.release(h, &mut out);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(z: f64, r: f64) -> Pt {
        Pt::new(z, r)
    }

    fn close(a: Pt, b: Pt) -> bool {
        len(sub(a, b)) < 1e-9
    }

    #[test]
    fn outside_turning_with_tip_3_keeps_the_diameter_on_straight_cuts() {
        // G42, R1, tip 3: turning toward the chuck along r = 15, then facing up to r = 20.
        let mut c = RadiusComp::new(Side::Right, 1.0, 3, p(10.0, 15.0), Startup::Connect);
        let f = Kind::Feed(100.0);
        let out = c
            .push(
                Elem::Line {
                    a: p(10.0, 15.0),
                    b: p(-20.0, 15.0),
                },
                0.0,
                f,
                1,
                ElementRules::default(),
            )
            .unwrap();
        // The connecting move lands on the controlled point of the offset start: r stays 15.
        assert!(close(out[0].path.end(), p(9.0, 15.0)), "{out:?}");
        let out = c
            .push(
                Elem::Line {
                    a: p(-20.0, 15.0),
                    b: p(-20.0, 20.0),
                },
                0.0,
                f,
                2,
                ElementRules::default(),
            )
            .unwrap();
        // Inner corner (the shoulder): the nose centre stops at Z−19, touching the face at
        // Z−20; with tip 3 the controlled point runs exactly on axis-parallel contour lines.
        assert_eq!(out.len(), 1);
        assert!(close(out[0].path.end(), p(-20.0, 15.0)), "{out:?}");
        let out = c.flush();
        // Ended without a cancel move: the centre stops beside the end, r 20, the tip at r 19.
        assert!(close(out[0].path.end(), p(-20.0, 19.0)), "{out:?}");
    }

    #[test]
    fn outer_corners_get_an_arc_of_the_nose_radius() {
        let mut c = RadiusComp::new(Side::Left, 3.0, 0, p(0.0, 0.0), Startup::Connect);
        let f = Kind::Feed(100.0);
        c.push(
            Elem::Line {
                a: p(0.0, 0.0),
                b: p(0.0, 10.0),
            },
            0.0,
            f,
            1,
            ElementRules::default(),
        )
        .unwrap();
        // Up (+X) then toward +Z: a right turn, so the left offset is outside.
        let out = c
            .push(
                Elem::Line {
                    a: p(0.0, 10.0),
                    b: p(20.0, 10.0),
                },
                0.0,
                f,
                2,
                ElementRules::default(),
            )
            .unwrap();
        assert_eq!(out.len(), 2, "{out:?}");
        let out2 = c
            .push(
                Elem::Line {
                    a: p(20.0, 10.0),
                    b: p(20.0, 0.0),
                },
                0.0,
                f,
                3,
                ElementRules::default(),
            )
            .unwrap();
        let all: Vec<Out> = out.into_iter().chain(out2).collect();
        assert!(
            all.iter().any(|o| matches!(o.path, Elem::Arc { .. })),
            "{all:?}"
        );
        for o in &all {
            if let Elem::Arc { a, b, c, .. } = o.path {
                assert!((len(sub(a, c)) - 3.0).abs() < 1e-9 && (len(sub(b, c)) - 3.0).abs() < 1e-9);
            }
        }
    }

    /// Outer corners by intersection (D103): below a turn of 100° the offsets are extended
    /// to where they cross, no arc; from 100° on the arc again.
    #[test]
    fn outer_corners_meet_at_the_intersection_below_the_limit() {
        let rules = ElementRules {
            outer_intersection: true,
            ..ElementRules::default()
        };
        let f = Kind::Feed(100.0);
        let run = |second_end: Pt| {
            let mut c = RadiusComp::new(Side::Left, 3.0, 0, p(0.0, 0.0), Startup::Connect);
            let mut out = c
                .push(
                    Elem::Line {
                        a: p(0.0, 0.0),
                        b: p(0.0, 10.0),
                    },
                    0.0,
                    f,
                    1,
                    rules,
                )
                .unwrap();
            let second = Elem::Line {
                a: p(0.0, 10.0),
                b: second_end,
            };
            out.extend(c.push(second, 0.0, f, 2, rules).unwrap());
            out.extend(c.flush());
            out
        };
        // A right turn of 90°: the left offsets z = −3 and r = 13 cross at (−3, 13).
        let out = run(p(20.0, 10.0));
        assert!(
            !out.iter().any(|o| matches!(o.path, Elem::Arc { .. })),
            "{out:?}"
        );
        assert!(close(out[1].path.end(), p(-3.0, 13.0)), "{out:?}");
        assert!(close(out[2].path.start(), p(-3.0, 13.0)), "{out:?}");
        // A turn of 116.6° (toward (20, 0)): past the limit, the arc around the corner.
        let out = run(p(20.0, 0.0));
        assert!(
            out.iter().any(|o| matches!(o.path, Elem::Arc { .. })),
            "{out:?}"
        );
    }

    #[test]
    fn a_concave_arc_smaller_than_the_nose_is_an_error() {
        let mut c = RadiusComp::new(Side::Left, 5.0, 0, p(0.0, 0.0), Startup::Connect);
        // Counter-clockwise arc of radius 2: its left side is inside.
        let e = c.push(
            Elem::Arc {
                a: p(0.0, 0.0),
                b: p(-4.0, 0.0),
                c: p(-2.0, 0.0),
                ccw: true,
            },
            0.0,
            Kind::Feed(1.0),
            1,
            ElementRules::default(),
        );
        assert_eq!(e.unwrap_err(), CompError::ArcVanishes);
    }

    #[test]
    fn with_feed_on_the_contour_an_offset_arc_is_scaled_and_a_corner_arc_is_not() {
        // A line along +Z, then a clockwise arc of radius 10 turning left off it.
        let line = Elem::Line {
            a: p(-10.0, 0.0),
            b: p(0.0, 0.0),
        };
        let arc = Elem::Arc {
            a: p(0.0, 0.0),
            b: p(20.0, 0.0),
            c: p(10.0, 0.0),
            ccw: false,
        };
        // Right of a clockwise arc is its inside (radius 8), left its outside (radius 12).
        // With a control limit of 110 the outside arc's 120 is held at 110.
        for (side, on, radius, feed, max_feed) in [
            (Side::Right, false, 8.0, 100.0, 0.0),
            (Side::Right, true, 8.0, 80.0, 0.0),
            (Side::Left, true, 12.0, 120.0, 0.0),
            (Side::Left, true, 12.0, 110.0, 110.0),
        ] {
            let mut c = RadiusComp::new(side, 2.0, 0, p(-10.0, 0.0), Startup::Connect);
            let rules = ElementRules {
                feed_on_contour: on,
                max_feed,
                ..ElementRules::default()
            };
            let mut out = c.push(line, 0.0, Kind::Feed(100.0), 1, rules).unwrap();
            out.extend(c.push(arc, 0.0, Kind::Feed(100.0), 2, rules).unwrap());
            out.extend(c.flush());
            let arcs: Vec<(f64, Kind)> = out
                .iter()
                .filter_map(|o| match o.path {
                    Elem::Arc { a, c, .. } => Some((len(sub(a, c)), o.kind)),
                    Elem::Line { .. } => None,
                })
                .collect();
            let cut = arcs.iter().find(|(r, _)| (r - radius).abs() < 1e-9);
            assert!(
                matches!(cut, Some((_, Kind::Feed(f))) if (f - feed).abs() < 1e-9),
                "{side:?} {on}: {out:?}"
            );
            // The outer corner's arc (radius 2, G42 only) runs at the programmed feed.
            for (r, k) in &arcs {
                if (r - 2.0).abs() < 1e-9 {
                    assert_eq!(*k, Kind::Feed(100.0), "{out:?}");
                }
            }
            assert_eq!(
                arcs.len(),
                if side == Side::Right { 2 } else { 1 },
                "{out:?}"
            );
        }
    }
}
