//! Fisher information of range measurements about a target's horizontal position
//! (sousa eq. 3.11-3.15).

use nalgebra::{Matrix2, Vector2, Vector3};

/// FIM of the horizontal position w = (N, E) of a target at `target` (NED) from ranges
/// taken at `sources` (NED), each with noise variance `sigma2` (eq. 3.12-3.14): the sum
/// over sources of g g' / sigma^2 with g = d Z / d w = ((N - N_i) / Z_i, (E - E_i) / Z_i).
/// The target is assumed not to move between the ranges (the synthetic baseline).
pub fn range_fim(target: &Vector3<f64>, sources: &[Vector3<f64>], sigma2: f64) -> Matrix2<f64> {
    let mut fim = Matrix2::zeros();
    for s in sources {
        let d = target - s;
        let z2 = d.norm_squared();
        if z2 > 0.0 {
            let g = Vector2::new(d.x, d.y);
            fim += g * g.transpose() / (z2 * sigma2); // eq. 3.14
        }
    }
    fim
}

/// Determinant of a 2x2 matrix, a b - c^2 for the symmetric FIM (eq. 3.15).
pub fn det2(m: &Matrix2<f64>) -> f64 {
    m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn determinant_matches_hand_computed_cases() {
        // target 20 m deep under the origin; ASV 15 m north, then 15 m east: Z = 25,
        // g1 = (-0.6, 0), g2 = (0, -0.6): FIM = 0.36 I / sigma^2
        let target = Vector3::new(0.0, 0.0, 20.0);
        let north = Vector3::new(15.0, 0.0, 0.0);
        let east = Vector3::new(0.0, 15.0, 0.0);
        assert_relative_eq!(det2(&range_fim(&target, &[north, east], 1.0)), 0.36 * 0.36, max_relative = 1e-12);
        assert_relative_eq!(det2(&range_fim(&target, &[north, east], 4.0)), 0.36 * 0.36 / 16.0, max_relative = 1e-12);
        // 60 deg apart instead of 90: det = 0.36^2 sin^2(60 deg)
        let sixty = Vector3::new(15.0 * 0.5, 15.0 * 3f64.sqrt() / 2.0, 0.0);
        assert_relative_eq!(det2(&range_fim(&target, &[north, sixty], 1.0)), 0.1296 * 0.75, max_relative = 1e-12);
        // collinear ranges carry no 2-D information
        let south = Vector3::new(-15.0, 0.0, 0.0);
        assert!(det2(&range_fim(&target, &[north, south], 1.0)).abs() < 1e-15);
        // eq. 3.15 term by term for an arbitrary pair
        let (a, b) = (Vector3::new(3.0, -7.0, 0.0), Vector3::new(-11.0, 4.0, 0.0));
        let t = Vector3::new(1.0, 2.0, 6.0);
        let term = |s: &Vector3<f64>| {
            let d = t - s;
            let z2 = d.norm_squared();
            (d.x * d.x / z2, d.y * d.y / z2, d.x * d.y / z2)
        };
        let ((nn1, ee1, ne1), (nn2, ee2, ne2)) = (term(&a), term(&b));
        let closed = (nn1 + nn2) * (ee1 + ee2) - (ne1 + ne2).powi(2);
        assert_relative_eq!(det2(&range_fim(&t, &[a, b], 1.0)), closed, max_relative = 1e-12);
    }
}
