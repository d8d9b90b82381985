//! Consistency statistics: normalised estimation error squared (NEES).

use nalgebra::{SMatrix, SVector};

/// NEES e' P^-1 e of an error `e` with covariance `p`; `None` if P is not positive
/// definite. Distributed chi-square with D degrees of freedom for a consistent filter.
pub fn nees<const D: usize>(e: &SVector<f64, D>, p: &SMatrix<f64, D, D>) -> Option<f64> {
    p.cholesky()?; // positive definite
    Some(e.dot(&(p.try_inverse()? * e)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Matrix2, Vector2};

    #[test]
    fn nees_matches_hand_computation() {
        let p = Matrix2::new(4.0, 1.0, 1.0, 2.0); // det 7, inverse [2 -1; -1 4] / 7
        let e = Vector2::new(1.0, 2.0);
        // [1 2] [2 -1; -1 4] [1 2]' / 7 = (2 - 2 - 2 + 16) / 7 = 2
        assert_relative_eq!(nees(&e, &p).unwrap(), 2.0, max_relative = 1e-12);
        assert!(nees(&e, &Matrix2::new(1.0, 2.0, 2.0, 1.0)).is_none());
    }
}
