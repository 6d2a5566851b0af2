//! The coordinate transform chain, from work coordinates (what a program writes) to machine
//! coordinates (what motion moves to), per axis:
//!
//! ```text
//! machine = frame(work) + work offset + shift + local system + tool offset + coupled travel
//! ```
//!
//! - the work offset of the active work system (off for a front end whose work offsets are
//!   shifts of their own, and for [`NO_WORK_OFFSET`]);
//! - shifts set from the program (setting the current point's coordinates, cumulative offset
//!   groups);
//! - a local system inside the work system;
//! - a programmable [`Frame`]: any composition of translations, rotations, scalings and
//!   mirrorings (identity unless a front end sets one);
//! - the tool offset (geometry plus wear, or a tool length along its axis);
//! - what a following axis of coupled motion has travelled with its leaders (`Coupling`):
//!   the program goes on writing the axis's own path.
//!
//! With the identity frame each axis is a sum, computed in this order; the inverse gives the
//! work position shown to the program.

/// The work system index that selects no work offset (a control's "settable offset off").
pub const NO_WORK_OFFSET: u8 = u8::MAX;

/// A programmable frame: the affine map `p ↦ L·p + t`, its linear part `L` (row-major,
/// n×n) a product of rotations, scalings and mirrorings. Each additive instruction acts in
/// the coordinates the frame already defines (post-multiplies), so a translation after a
/// scaling is scaled and one after a rotation runs along the rotated axes.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    n: usize,
    linear: Vec<f64>,
    inverse: Vec<f64>,
    pub translation: Vec<f64>,
}

impl Frame {
    /// The identity frame of `n` axes.
    pub fn identity(n: usize) -> Frame {
        let eye = identity_matrix(n);
        Frame {
            n,
            linear: eye.clone(),
            inverse: eye,
            translation: vec![0.0; n],
        }
    }

    /// Asked for every move: compares in place, without building an identity to compare with.
    pub fn is_identity(&self) -> bool {
        let n = self.n.max(1);
        self.translation.iter().all(|&t| t == 0.0)
            && self.linear.iter().enumerate().all(|(k, &v)| {
                let diagonal = k / n == k % n;
                v == if diagonal { 1.0 } else { 0.0 }
            })
    }

    /// `L[row][col]`.
    pub fn linear(&self, row: usize, col: usize) -> f64 {
        self.linear[row * self.n + col]
    }

    /// The frame applied to the point `p`.
    pub fn apply(&self, p: &[f64]) -> Vec<f64> {
        let mut q = mul(&self.linear, self.n, p);
        for (x, t) in q.iter_mut().zip(&self.translation) {
            *x += t;
        }
        q
    }

    /// The point the frame maps to `q`.
    pub fn invert(&self, q: &[f64]) -> Vec<f64> {
        let n = self.n;
        let d = |c: usize| {
            q.get(c).copied().unwrap_or(0.0) - self.translation.get(c).copied().unwrap_or(0.0)
        };
        (0..n)
            .map(|r| (0..n).map(|c| self.inverse[r * n + c] * d(c)).sum())
            .collect()
    }

    /// [`Frame::invert`] into `q` itself (a frame of up to 16 axes needs no allocation).
    pub fn invert_in_place(&self, q: &mut [f64]) {
        let n = self.n;
        if n > 16 || q.len() != n {
            let p = self.invert(q);
            for (dst, src) in q.iter_mut().zip(p) {
                *dst = src;
            }
            return;
        }
        let mut d = [0.0; 16];
        for (c, x) in d.iter_mut().enumerate().take(n) {
            *x = q[c] - self.translation.get(c).copied().unwrap_or(0.0);
        }
        for (r, out) in q.iter_mut().enumerate() {
            *out = (0..n).map(|c| self.inverse[r * n + c] * d[c]).sum();
        }
    }

    /// A translation by `v`, in the frame's own coordinates.
    pub fn translate(&mut self, v: &[f64]) {
        let d = mul(&self.linear, self.n, v);
        for (t, x) in self.translation.iter_mut().zip(d) {
            *t += x;
        }
    }

    /// A rotation by `degrees` counter-clockwise from axis `h` toward axis `v`, about the
    /// frame's origin.
    pub fn rotate(&mut self, h: usize, v: usize, degrees: f64) {
        let (s, c) = degrees.to_radians().sin_cos();
        let n = self.n;
        if h >= n || v >= n || h == v {
            return;
        }
        // linear × R (R turns h toward v) and R⁻¹ × inverse, in place: a rotation mixes only
        // the two columns (rows) of its plane.
        for k in 0..n {
            let (a, b) = (self.linear[k * n + h], self.linear[k * n + v]);
            self.linear[k * n + h] = a * c + b * s;
            self.linear[k * n + v] = b * c - a * s;
            let (p, q) = (self.inverse[h * n + k], self.inverse[v * n + k]);
            self.inverse[h * n + k] = c * p + s * q;
            self.inverse[v * n + k] = c * q - s * p;
        }
    }

    /// Per-axis factors (negative mirrors); a factor of 0 is refused by the caller.
    pub fn scale(&mut self, factors: &[f64]) {
        let n = self.n;
        let mut s = identity_matrix(n);
        let mut si = identity_matrix(n);
        for (i, &f) in factors.iter().enumerate().take(n) {
            if f != 0.0 && f.is_finite() {
                s[i * n + i] = f;
                si[i * n + i] = 1.0 / f;
            }
        }
        self.compose(&s, &si);
    }

    /// How the frame maps the plane of axes `h`, `v`: `Some((factor, mirrored))` when it maps
    /// the plane onto itself as a similarity (circles stay circles of radius × factor,
    /// turning the other way when mirrored) and leaves the plane's axes out of the others;
    /// `None` when circles in the plane would not stay circles in it.
    pub fn plane_similarity(&self, h: usize, v: usize) -> Option<(f64, bool)> {
        let n = self.n;
        if h >= n || v >= n {
            return None;
        }
        for k in (0..n).filter(|&k| k != h && k != v) {
            let leaks = [
                self.linear(h, k),
                self.linear(v, k),
                self.linear(k, h),
                self.linear(k, v),
            ];
            if leaks.iter().any(|x| x.abs() > 1e-12) {
                return None;
            }
        }
        let (a, b, c, d) = (
            self.linear(h, h),
            self.linear(h, v),
            self.linear(v, h),
            self.linear(v, v),
        );
        let det = a * d - b * c;
        // Columns orthogonal and of equal length.
        let len_h = a.hypot(c);
        let len_v = b.hypot(d);
        let ok = (a * b + c * d).abs() <= 1e-9 * len_h * len_v.max(1e-12)
            && (len_h - len_v).abs() <= 1e-9 * len_h.max(len_v)
            && det.abs() > 1e-12;
        ok.then_some((len_h, det < 0.0))
    }

    /// `self ∘ m`, with `mi` the inverse of `m`.
    fn compose(&mut self, m: &[f64], mi: &[f64]) {
        self.linear = matmul(&self.linear, m, self.n);
        self.inverse = matmul(mi, &self.inverse, self.n);
    }
}

fn identity_matrix(n: usize) -> Vec<f64> {
    let mut m = vec![0.0; n * n];
    for i in 0..n {
        m[i * n + i] = 1.0;
    }
    m
}

fn mul(m: &[f64], n: usize, p: &[f64]) -> Vec<f64> {
    (0..n)
        .map(|r| {
            (0..n)
                .map(|c| m[r * n + c] * p.get(c).copied().unwrap_or(0.0))
                .sum()
        })
        .collect()
}

fn matmul(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
    let mut out = vec![0.0; n * n];
    for r in 0..n {
        for c in 0..n {
            out[r * n + c] = (0..n).map(|k| a[r * n + k] * b[k * n + c]).sum();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_identity_leaves_every_bit() {
        let f = Frame::identity(3);
        let p = [1.0 / 3.0, -7.125, 1e-12];
        assert!(f.is_identity());
        assert_eq!(f.apply(&p), p);
        assert_eq!(f.invert(&p), p);
    }

    #[test]
    fn a_frame_translates_rotates_scales_and_mirrors_in_its_own_coordinates_and_inverts() {
        let mut f = Frame::identity(3);
        f.translate(&[10.0, 20.0, 30.0]);
        f.rotate(0, 1, 90.0);
        f.scale(&[-1.0, 2.0, 1.0]);
        // (1, 1, 5) → mirror/scale (−1, 2, 5) → rotate 90° (−2, −1, 5) → +T.
        let q = f.apply(&[1.0, 1.0, 5.0]);
        for (a, b) in q.iter().zip([8.0, 19.0, 35.0]) {
            assert!((a - b).abs() < 1e-12, "{q:?}");
        }
        let back = f.invert(&q);
        for (a, b) in back.iter().zip([1.0, 1.0, 5.0]) {
            assert!((a - b).abs() < 1e-12, "{back:?}");
        }
        assert!(!f.is_identity());
        // A translation now runs along the frame's axes, scaled: X+1 of the frame is −Y×1.
        let mut g = f.clone();
        g.translate(&[1.0, 0.0, 0.0]);
        let d: Vec<f64> = g
            .translation
            .iter()
            .zip(&f.translation)
            .map(|(a, b)| a - b)
            .collect();
        assert!((d[0]).abs() < 1e-12 && (d[1] + 1.0).abs() < 1e-12, "{d:?}");
    }

    #[test]
    fn circles_stay_circles_only_under_similarities_of_their_plane() {
        let mut f = Frame::identity(3);
        f.rotate(0, 1, 30.0);
        f.scale(&[2.0, 2.0, 1.0]);
        assert_eq!(f.plane_similarity(0, 1).map(|s| s.1), Some(false));
        assert!((f.plane_similarity(0, 1).unwrap().0 - 2.0).abs() < 1e-12);
        f.scale(&[-1.0, 1.0, 1.0]);
        assert_eq!(f.plane_similarity(0, 1).map(|s| s.1), Some(true));
        // Unequal factors: an ellipse.
        let mut e = Frame::identity(3);
        e.scale(&[2.0, 1.0, 1.0]);
        assert_eq!(e.plane_similarity(0, 1), None);
        // A rotation in the XY plane tilts the ZX plane out of itself.
        assert_eq!(f.plane_similarity(2, 0), None);
    }
}
