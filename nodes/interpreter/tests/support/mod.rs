//! Helpers shared by the interpreter's test files.

/// The radius at `z` of a contour given as (Z, X diameter) corners, on its first element
/// that spans `z` (elements along X alone are skipped).
pub fn contour_at(points: &[[f64; 2]], z: f64) -> Option<f64> {
    points.windows(2).find_map(|w| {
        let ([z0, x0], [z1, x1]) = (w[0], w[1]);
        let (lo, hi) = (z0.min(z1), z0.max(z1));
        (z >= lo && z <= hi && (z1 - z0).abs() > 1e-9)
            .then(|| (x0 + (x1 - x0) * (z - z0) / (z1 - z0)) / 2.0)
    })
}
