//! The coordinate transform chain, from work coordinates (what a program writes) to machine
//! coordinates (what motion moves to), per axis:
//!
//! ```text
//! machine = frame(work) + work offset + shift + local system + tool offset
//! ```
//!
//! - the work offset of the active work system (off for a front end whose work offsets are
//!   shifts of their own);
//! - shifts set from the program (setting the current point's coordinates, cumulative offset
//!   groups);
//! - a local system inside the work system;
//! - a general [`Frame`]: mirror, scale, rotation in the working plane, translation (identity
//!   unless a front end sets one);
//! - the tool offset (geometry plus wear, or a tool length along its axis).
//!
//! With the identity frame each axis is a sum, computed in this order; the inverse gives the
//! work position shown to the program.

/// A general frame: each axis is mirrored, then scaled, then the working plane's two axes are
/// rotated, then every axis is translated.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Added last, per axis.
    pub translation: Vec<f64>,
    /// Degrees, counter-clockwise from the first plane axis toward the second.
    pub rotation: f64,
    /// The plane the rotation turns in, as axis indices (horizontal, vertical).
    pub rotation_plane: Option<(usize, usize)>,
    /// Per axis; 1 is none.
    pub scale: Vec<f64>,
    /// Per axis: the sign of the axis is reversed.
    pub mirror: Vec<bool>,
}

impl Frame {
    /// The identity frame of `n` axes.
    pub fn identity(n: usize) -> Frame {
        Frame {
            translation: vec![0.0; n],
            rotation: 0.0,
            rotation_plane: None,
            scale: vec![1.0; n],
            mirror: vec![false; n],
        }
    }

    pub fn is_identity(&self) -> bool {
        self.rotation == 0.0
            && self.translation.iter().all(|&t| t == 0.0)
            && self.scale.iter().all(|&s| s == 1.0)
            && !self.mirror.iter().any(|&m| m)
    }

    /// The frame applied to the point `p`.
    pub fn apply(&self, p: &[f64]) -> Vec<f64> {
        let mut q: Vec<f64> = p
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                let v = if self.mirror.get(i) == Some(&true) {
                    -v
                } else {
                    v
                };
                v * self.scale.get(i).copied().unwrap_or(1.0)
            })
            .collect();
        if let (Some((h, v)), true) = (self.rotation_plane, self.rotation != 0.0) {
            if h < q.len() && v < q.len() {
                let (s, c) = self.rotation.to_radians().sin_cos();
                let (a, b) = (q[h], q[v]);
                q[h] = a * c - b * s;
                q[v] = a * s + b * c;
            }
        }
        for (x, t) in q.iter_mut().zip(&self.translation) {
            *x += t;
        }
        q
    }

    /// The point the frame maps to `q`.
    pub fn invert(&self, q: &[f64]) -> Vec<f64> {
        let mut p: Vec<f64> = q
            .iter()
            .enumerate()
            .map(|(i, &v)| v - self.translation.get(i).copied().unwrap_or(0.0))
            .collect();
        if let (Some((h, v)), true) = (self.rotation_plane, self.rotation != 0.0) {
            if h < p.len() && v < p.len() {
                let (s, c) = self.rotation.to_radians().sin_cos();
                let (a, b) = (p[h], p[v]);
                p[h] = a * c + b * s;
                p[v] = -a * s + b * c;
            }
        }
        for (i, x) in p.iter_mut().enumerate() {
            let s = self.scale.get(i).copied().unwrap_or(1.0);
            if s != 0.0 {
                *x /= s;
            }
            if self.mirror.get(i) == Some(&true) {
                *x = -*x;
            }
        }
        p
    }
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
    fn a_frame_mirrors_scales_rotates_and_translates_and_inverts() {
        let mut f = Frame::identity(3);
        f.mirror[0] = true;
        f.scale[1] = 2.0;
        f.rotation = 90.0;
        f.rotation_plane = Some((0, 1));
        f.translation = vec![10.0, 20.0, 30.0];
        // (1, 1, 5) → mirror (−1, 1, 5) → scale (−1, 2, 5) → rotate 90° (−2, −1, 5) → +T.
        let q = f.apply(&[1.0, 1.0, 5.0]);
        for (a, b) in q.iter().zip([8.0, 19.0, 35.0]) {
            assert!((a - b).abs() < 1e-12, "{q:?}");
        }
        let back = f.invert(&q);
        for (a, b) in back.iter().zip([1.0, 1.0, 5.0]) {
            assert!((a - b).abs() < 1e-12, "{back:?}");
        }
        assert!(!f.is_identity());
    }
}
