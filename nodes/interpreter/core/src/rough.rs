//! Rough turning and facing from a finishing contour (the G71/G72 cycles of lathe controls).
//!
//! The contour, already shifted by the finishing allowance, starts at the cycle's start point
//! A' (the `ns` move A'→B' is its first element). Depth is measured from A' into the material
//! along X (G71) or Z (G72). Each level k cuts the layer between depths (k−1)·Δd and k·Δd: where
//! the contour lies in that layer the tool follows it, where the contour lies deeper it cuts
//! straight at depth k·Δd. One rule covers Type I (monotonic contour: one straight cut per level,
//! then up the contour to the previous level) and Type II (pockets: the
//! tool also follows the contour down into each pocket). A last pass follows the whole contour.
//! So the material left is exactly the shifted contour, no pass is deeper than Δd, and the
//! travel moves stay in material already removed (decision D15).

use crate::geometry::{Elem, Pt};

/// A tool move of a cycle, in the ZX plane (radius).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Move {
    Rapid(Pt),
    Feed(Pt),
    Arc { to: Pt, c: Pt, ccw: bool },
}

pub struct Rough {
    /// `true`: depth along X (G71); `false`: along Z (G72).
    pub radial: bool,
    /// +1 when depth grows as the coordinate falls (outside turning, facing toward −Z).
    pub sigma: f64,
    /// Depth per pass, > 0.
    pub depth: f64,
    /// Retract amount, ≥ 0.
    pub retract: f64,
    /// Type I: retract at 45°; Type II: along the depth axis only.
    pub type_one: bool,
    /// Skip the last pass along the contour (Type I only).
    pub skip_final: bool,
}

impl Rough {
    fn coord(&self, p: Pt) -> f64 {
        if self.radial {
            p.r
        } else {
            p.z
        }
    }
    fn along(&self, p: Pt) -> f64 {
        if self.radial {
            p.z
        } else {
            p.r
        }
    }
    fn point(&self, depth_coord: f64, along: f64) -> Pt {
        if self.radial {
            Pt::new(along, depth_coord)
        } else {
            Pt::new(depth_coord, along)
        }
    }

    /// The moves from the start point `a` (A, unshifted) over the contour (from A').
    pub fn moves(&self, a: Pt, contour: &[Elem]) -> Vec<Move> {
        let mut out = Vec::new();
        let Some(first) = contour.first() else {
            return out;
        };
        let a1 = first.start();
        let base = self.coord(a1);
        let depth_of = |c: f64| self.sigma * (base - c);
        let coord_of = |d: f64| base - self.sigma * d;
        let dmax = contour
            .iter()
            .map(|e| {
                let (lo, hi) = e.extent(self.radial);
                depth_of(lo).max(depth_of(hi))
            })
            .fold(0.0, f64::max);
        // Direction of travel along the cut axis.
        let zeta = contour
            .iter()
            .map(|e| self.along(e.end()) - self.along(e.start()))
            .find(|d| d.abs() > 1e-9)
            .map(f64::signum)
            .unwrap_or(-1.0);
        out.push(Move::Rapid(a1));
        let mut cur = a1;
        let mut k = 1;
        loop {
            let (d0, d1) = ((k - 1) as f64 * self.depth, k as f64 * self.depth);
            if d1 >= dmax - 1e-9 {
                break;
            }
            k += 1;
            for (p0, path) in self.level_paths(contour, coord_of(d0), coord_of(d1), &depth_of) {
                self.travel(&mut out, &mut cur, p0, d0, contour, &depth_of, &coord_of);
                for &m in &path {
                    out.push(m);
                    cur = end_of(m);
                }
                // Retract out of the cut.
                let back = if self.type_one { self.retract } else { 0.0 };
                let r = self.point(
                    coord_of(depth_of(self.coord(cur)) - self.retract),
                    self.along(cur) - zeta * back,
                );
                out.push(Move::Feed(r));
                cur = r;
            }
        }
        if !self.skip_final {
            self.travel(&mut out, &mut cur, a1, dmax, contour, &depth_of, &coord_of);
            for e in contour {
                let m = elem_move(e);
                out.push(m);
                cur = end_of(m);
            }
        }
        // Back to A: first out of the material along the depth axis, then along the cut axis.
        let out_coord = if self.sigma > 0.0 {
            self.coord(cur).max(self.coord(a))
        } else {
            self.coord(cur).min(self.coord(a))
        };
        let out_pt = self.point(out_coord, self.along(cur));
        if out_pt.dist(cur) > 1e-9 {
            out.push(Move::Rapid(out_pt));
        }
        out.push(Move::Rapid(a));
        out
    }

    /// Moves the tool from `cur` to `to` through material already removed: out to a clearance
    /// depth, along the cut axis at rapid, then in at feed.
    #[allow(clippy::too_many_arguments)]
    fn travel(
        &self,
        out: &mut Vec<Move>,
        cur: &mut Pt,
        to: Pt,
        done_depth: f64,
        contour: &[Elem],
        depth_of: &dyn Fn(f64) -> f64,
        coord_of: &dyn Fn(f64) -> f64,
    ) {
        if cur.dist(to) < 1e-9 {
            return;
        }
        let (t0, t1) = (self.along(*cur), self.along(to));
        let (lo, hi) = (t0.min(t1) - 1e-9, t0.max(t1) + 1e-9);
        // Shallowest contour depth over the span (whole elements touching it: conservative).
        let mut clear = done_depth;
        for e in contour {
            let (alo, ahi) = e.extent(!self.radial);
            if ahi >= lo && alo <= hi {
                let (clo, chi) = e.extent(self.radial);
                clear = clear.min(depth_of(clo)).min(depth_of(chi));
            }
        }
        let clear = clear
            .min(depth_of(self.coord(*cur)))
            .min(depth_of(self.coord(to)))
            - self.retract.max(0.0);
        let c = coord_of(clear);
        let up = self.point(c, t0);
        if up.dist(*cur) > 1e-9 {
            out.push(Move::Rapid(up));
        }
        let over = self.point(c, t1);
        if over.dist(up) > 1e-9 {
            out.push(Move::Rapid(over));
        }
        if to.dist(over) > 1e-9 {
            out.push(Move::Feed(to));
        }
        *cur = to;
    }

    /// The cutting paths of one level between coordinates `c0` (depth d0) and `c1` (d1):
    /// each is a start point and its moves.
    fn level_paths(
        &self,
        contour: &[Elem],
        c0: f64,
        c1: f64,
        depth_of: &dyn Fn(f64) -> f64,
    ) -> Vec<(Pt, Vec<Move>)> {
        #[derive(PartialEq, Clone, Copy)]
        enum Class {
            Above,
            In,
            Below,
        }
        let (d0, d1) = (depth_of(c0), depth_of(c1));
        let mut paths = Vec::new();
        let mut path: Vec<Move> = Vec::new();
        let mut start: Option<Pt> = None;
        // End of a run where the contour lies below the level (cut straight at the level).
        let mut run_end: Option<Pt> = None;
        let close_run = |path: &mut Vec<Move>, run_end: &mut Option<Pt>| {
            if let Some(e) = run_end.take() {
                path.push(Move::Feed(self.point(c1, self.along(e))));
            }
        };
        for e in contour {
            let mut cuts = e.crossings(c0, self.radial);
            cuts.extend(e.crossings(c1, self.radial));
            cuts.push(0.0);
            cuts.push(1.0);
            cuts.sort_by(f64::total_cmp);
            cuts.dedup_by(|x, y| (*x - *y).abs() < 1e-12);
            for w in cuts.windows(2) {
                let p = e.piece(w[0], w[1]);
                if p.start().dist(p.end()) < 1e-9 {
                    continue;
                }
                let dm = depth_of(self.coord(e.at((w[0] + w[1]) / 2.0)));
                let class = if dm < d0 - 1e-9 {
                    Class::Above
                } else if dm > d1 + 1e-9 {
                    Class::Below
                } else {
                    Class::In
                };
                match class {
                    Class::Above => {
                        close_run(&mut path, &mut run_end);
                        if let Some(s) = start.take() {
                            paths.push((s, std::mem::take(&mut path)));
                        }
                    }
                    Class::Below => {
                        if start.is_none() {
                            // The path begins below the level: plunge one layer at most.
                            start = Some(self.point(c0, self.along(p.start())));
                            path.push(Move::Feed(self.point(c1, self.along(p.start()))));
                        }
                        run_end = Some(p.end());
                    }
                    Class::In => {
                        close_run(&mut path, &mut run_end);
                        if start.is_none() {
                            start = Some(p.start());
                        }
                        path.push(elem_move(&p));
                    }
                }
            }
        }
        close_run(&mut path, &mut run_end);
        if let Some(s) = start {
            paths.push((s, path));
        }
        paths
    }
}

fn elem_move(e: &Elem) -> Move {
    match *e {
        Elem::Line { b, .. } => Move::Feed(b),
        Elem::Arc { b, c, ccw, .. } => Move::Arc { to: b, c, ccw },
    }
}

pub fn end_of(m: Move) -> Pt {
    match m {
        Move::Rapid(p) | Move::Feed(p) => p,
        Move::Arc { to, .. } => to,
    }
}
