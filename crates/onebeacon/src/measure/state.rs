//! Direct observation of one state component: heading from the AHRS, yaw rate and
//! acceleration from the IMU (garin2024 eq. 18, 24).

use super::ScalarModel;
use nalgebra::{SMatrix, SVector};

/// Measures state component `index` with noise variance `var`; `angle` wraps its
/// innovation.
#[derive(Debug, Clone, Copy)]
pub struct StateComponent {
    pub index: usize,
    pub angle: bool,
    pub var: f64,
}

impl StateComponent {
    /// A non-angular component.
    pub const fn value(index: usize, var: f64) -> Self {
        Self { index, angle: false, var }
    }
    /// An angular component (heading).
    pub const fn angle(index: usize, var: f64) -> Self {
        Self { index, angle: true, var }
    }
}

impl<const N: usize> ScalarModel<N> for StateComponent {
    fn predict(&self, x: &SVector<f64, N>) -> f64 {
        x[self.index]
    }
    fn jacobian(&self, _x: &SVector<f64, N>) -> SMatrix<f64, 1, N> {
        // eq. 24; element by element rather than a store at a run-time index into a
        // zeroed row, which the whole-row loads that follow stall on
        SMatrix::from_fn(|_, j| if j == self.index { 1.0 } else { 0.0 })
    }
    fn is_angle(&self) -> bool {
        self.angle
    }
    fn variance(&self, _x: &SVector<f64, N>) -> f64 {
        self.var
    }
    fn unit_row(&self) -> Option<usize> {
        Some(self.index)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::finite_difference;
    use approx::assert_abs_diff_eq;

    #[test]
    fn jacobian_matches_finite_differences() {
        let x = SVector::<f64, 6>::from([1.0, 2.0, 0.3, 1.1, 0.02, -0.1]);
        for i in 0..6 {
            let m = StateComponent::value(i, 1.0);
            let h = ScalarModel::<6>::jacobian(&m, &x);
            let fd = finite_difference::<6>(&m, &x);
            for j in 0..6 {
                assert_abs_diff_eq!(h[j], fd[j], epsilon = 1e-9);
            }
            assert_abs_diff_eq!(ScalarModel::<6>::predict(&m, &x), x[i]);
        }
    }
}
