//! Range to a beacon at a known position: horizontal (garin2024 eq. 19) or slant
//! (sousa eq. 3.7, 3.11).

use super::ScalarModel;
use nalgebra::{SMatrix, SVector, Vector2, Vector3};

/// Range from the state's position (components 0, 1) to `beacon` (NED, m), with noise
/// variance `var` (m^2).
#[derive(Debug, Clone, Copy)]
pub struct Range2d {
    pub beacon: Vector2<f64>,
    pub var: f64,
}

impl<const N: usize> ScalarModel<N> for Range2d {
    fn predict(&self, x: &SVector<f64, N>) -> f64 {
        (x[0] - self.beacon.x).hypot(x[1] - self.beacon.y) // eq. 19
    }

    fn jacobian(&self, x: &SVector<f64, N>) -> SMatrix<f64, 1, N> {
        let (dx, dy) = (x[0] - self.beacon.x, x[1] - self.beacon.y);
        let r = dx.hypot(dy);
        let mut h = SMatrix::<f64, 1, N>::zeros();
        if r > 1e-9 {
            // eq. 22, row of d: A (x - x_ref), A (y - y_ref) with A = 1 / d (eq. 23)
            h[0] = dx / r;
            h[1] = dy / r;
        }
        h
    }

    fn variance(&self, _x: &SVector<f64, N>) -> f64 {
        self.var
    }
}

/// Slant range from the state's position (components 0, 1, 2: N, E, D) to `beacon`
/// (NED, m), e.g. an ASV's transducer at its position when it transmitted, with range
/// noise `sigma_m` and the beacon's own position error `beacon_sigma_m` per horizontal
/// axis (its GPS): the variance adds that error's projection on the line of sight.
#[derive(Debug, Clone, Copy)]
pub struct Range3d {
    pub beacon: Vector3<f64>,
    pub sigma_m: f64,
    pub beacon_sigma_m: f64,
}

impl<const N: usize> ScalarModel<N> for Range3d {
    fn predict(&self, x: &SVector<f64, N>) -> f64 {
        (Vector3::new(x[0], x[1], x[2]) - self.beacon).norm() // eq. 3.7
    }

    fn jacobian(&self, x: &SVector<f64, N>) -> SMatrix<f64, 1, N> {
        let d = Vector3::new(x[0], x[1], x[2]) - self.beacon;
        let r = d.norm();
        let mut h = SMatrix::<f64, 1, N>::zeros();
        if r > 1e-9 {
            for i in 0..3 {
                h[i] = d[i] / r; // eq. 3.13, with the depth row
            }
        }
        h
    }

    fn variance(&self, x: &SVector<f64, N>) -> f64 {
        let h = ScalarModel::<N>::jacobian(self, x);
        let horizontal = h[0] * h[0] + h[1] * h[1];
        self.sigma_m.powi(2) + self.beacon_sigma_m.powi(2) * horizontal // eq. 3.10 with the GPS error
    }
}

/// Slant range from a vehicle at a known depth (pressure sensor) whose horizontal
/// position is the state's components 0, 1 (N, E) to `beacon` (NED, m), as a sensor
/// with a scale error and an offset reads it: (1 + k) r + b. The scale error k is read
/// from state component `scale` (a wrong propagation speed: travel times converted
/// with a sound speed 2 % low read 2 % short) and the offset b from component `bias`
/// (a fixed latency, a cable delay); either is zero when its index is `None`. Noise
/// variance `var` (m^2).
#[derive(Debug, Clone, Copy)]
pub struct SlantRange {
    pub beacon: Vector3<f64>,
    pub depth_m: f64,
    pub bias: Option<usize>,
    pub scale: Option<usize>,
    pub var: f64,
}

impl SlantRange {
    fn gain<const N: usize>(&self, x: &SVector<f64, N>) -> f64 {
        1.0 + self.scale.map_or(0.0, |i| x[i])
    }
}

impl<const N: usize> ScalarModel<N> for SlantRange {
    fn predict(&self, x: &SVector<f64, N>) -> f64 {
        let d = Vector3::new(x[0], x[1], self.depth_m) - self.beacon;
        self.gain(x) * d.norm() + self.bias.map_or(0.0, |i| x[i])
    }

    fn jacobian(&self, x: &SVector<f64, N>) -> SMatrix<f64, 1, N> {
        let d = Vector3::new(x[0], x[1], self.depth_m) - self.beacon;
        let r = d.norm();
        let mut h = SMatrix::<f64, 1, N>::zeros();
        if r > 1e-9 {
            let g = self.gain(x);
            h[0] = g * d.x / r;
            h[1] = g * d.y / r;
        }
        if let Some(i) = self.bias {
            h[i] = 1.0;
        }
        if let Some(i) = self.scale {
            h[i] = r;
        }
        h
    }

    fn variance(&self, _x: &SVector<f64, N>) -> f64 {
        self.var
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::finite_difference;
    use approx::assert_abs_diff_eq;

    #[test]
    fn range_and_jacobian() {
        let m = Range2d { beacon: Vector2::new(50.0, 100.0), var: 1.0 };
        let m3 = Range3d { beacon: Vector3::new(50.0, 100.0, 0.5), sigma_m: 1.0, beacon_sigma_m: 0.0 };
        let x3 = SVector::<f64, 6>::from([53.0, 104.0, 12.5, 0.1, -0.1, 2.0]);
        assert_abs_diff_eq!(ScalarModel::<6>::predict(&m3, &x3), 13.0, epsilon = 1e-12); // 3-4-12
        let (h, fd) = (ScalarModel::<6>::jacobian(&m3, &x3), finite_difference::<6>(&m3, &x3));
        assert_abs_diff_eq!(h, fd, epsilon = 1e-7);
        let x = SVector::<f64, 6>::from([53.0, 104.0, 0.3, 1.0, 0.0, 0.0]);
        assert_abs_diff_eq!(ScalarModel::<6>::predict(&m, &x), 5.0, epsilon = 1e-12);
        for x in [x, SVector::<f64, 6>::from([-20.0, 240.0, -2.0, 1.3, 0.1, 0.0])] {
            let h = ScalarModel::<6>::jacobian(&m, &x);
            let fd = finite_difference::<6>(&m, &x);
            for j in 0..6 {
                assert_abs_diff_eq!(h[j], fd[j], epsilon = 1e-7);
            }
        }
    }

    #[test]
    fn slant_range_with_bias_and_scale() {
        let m = SlantRange {
            beacon: Vector3::new(50.0, 100.0, 0.5),
            depth_m: 12.5,
            bias: Some(3),
            scale: Some(4),
            var: 1.0,
        };
        let x = SVector::<f64, 5>::from([53.0, 104.0, 0.3, 2.8, 0.07]);
        assert_abs_diff_eq!(ScalarModel::<5>::predict(&m, &x), 1.07 * 13.0 + 2.8, epsilon = 1e-12); // 3-4-12
        assert_abs_diff_eq!(ScalarModel::<5>::jacobian(&m, &x), finite_difference::<5>(&m, &x), epsilon = 1e-7);
        let fixed = SlantRange { bias: None, scale: None, ..m };
        assert_abs_diff_eq!(ScalarModel::<5>::predict(&fixed, &x), 13.0, epsilon = 1e-12);
        let h = ScalarModel::<5>::jacobian(&fixed, &x);
        assert_eq!((h[3], h[4]), (0.0, 0.0));
    }
}
