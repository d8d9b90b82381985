//! Bearing of an underwater vehicle measured by a USBL on a surface vehicle (hoff2024
//! eq. 1-3): the azimuth relative to the surface vehicle's heading and the elevation
//! angle from the vertical, each with a standard deviation that grows with the range.

use super::ScalarModel;
use nalgebra::{SMatrix, SVector, Vector3};

/// The USBL on the surface vehicle: its NED position and heading when the message
/// arrives, and the baseline noise sigma_USBL in rad per metre of range (the paper's
/// deg/m, converted).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Usbl {
    pub position_ned_m: Vector3<f64>,
    pub heading_rad: f64,
    pub sigma_rad_per_m: f64,
}

/// Which angle of a [`Usbl`] a scalar model measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UsblAngle {
    /// alpha = atan2(dy, dx) - psi_ASV (eq. 1).
    Azimuth,
    /// phi = acos(dz / r) (eq. 2): 0 straight down, pi/2 level.
    Elevation,
}

impl Usbl {
    /// The azimuth and elevation of a vehicle at `p` (NED), and their common standard
    /// deviation (eq. 1-3).
    pub fn angles(&self, p: &Vector3<f64>) -> (f64, f64, f64) {
        let d = p - self.position_ned_m;
        // sqrt, not hypot: metres cannot overflow, and hypot's care costs
        let h2 = d.x * d.x + d.y * d.y;
        let h = h2.sqrt();
        let alpha = crate::geo::wrap_angle(d.y.atan2(d.x) - self.heading_rad); // eq. 1
        let phi = h.atan2(d.z); // eq. 2: acos(dz / r), the angle of (dz, h)
        (alpha, phi, (h2 + d.z * d.z).sqrt() * self.sigma_rad_per_m) // eq. 3
    }

    /// The scalar model of one of the two angles (states with the NED position first).
    pub fn model(self, angle: UsblAngle) -> UsblModel {
        UsblModel { usbl: self, angle }
    }
}

/// One USBL angle as a [`ScalarModel`]; stack the two (`[az, el]`) for an EKF or UKF.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UsblModel {
    pub usbl: Usbl,
    pub angle: UsblAngle,
}

impl<const N: usize> ScalarModel<N> for UsblModel {
    fn predict(&self, x: &SVector<f64, N>) -> f64 {
        let (alpha, phi, _) = self.usbl.angles(&x.fixed_rows::<3>(0).into_owned());
        match self.angle {
            UsblAngle::Azimuth => alpha,
            UsblAngle::Elevation => phi,
        }
    }

    fn jacobian(&self, x: &SVector<f64, N>) -> SMatrix<f64, 1, N> {
        let d = x.fixed_rows::<3>(0) - self.usbl.position_ned_m;
        let (h2, r2) = (d.x * d.x + d.y * d.y, d.norm_squared());
        let mut j = SMatrix::<f64, 1, N>::zeros();
        if h2 < 1e-18 || r2 < 1e-18 {
            return j; // straight below: the azimuth is undefined
        }
        match self.angle {
            // d atan2(dy, dx) = (dx ddy - dy ddx) / h^2
            UsblAngle::Azimuth => {
                j[0] = -d.y / h2;
                j[1] = d.x / h2;
            }
            // phi = acos(dz / r): d phi = -(1 / sqrt(1 - dz^2/r^2)) d(dz / r), with
            // sqrt(1 - dz^2 / r^2) = h / r and d(dz / r) = (r^2 e_z - dz d) / r^3
            UsblAngle::Elevation => {
                let h = h2.sqrt();
                j[0] = d.z * d.x / (r2 * h);
                j[1] = d.z * d.y / (r2 * h);
                j[2] = -h / r2;
            }
        }
        j
    }

    fn is_angle(&self) -> bool {
        self.angle == UsblAngle::Azimuth
    }

    fn variance(&self, x: &SVector<f64, N>) -> f64 {
        let (_, _, sigma) = self.usbl.angles(&x.fixed_rows::<3>(0).into_owned());
        sigma * sigma
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::finite_difference;
    use approx::assert_abs_diff_eq;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

    /// Angles worked out by hand, and the Jacobian of both against finite differences at
    /// points around the surface vehicle.
    #[test]
    fn angles_and_jacobians() {
        let usbl =
            Usbl { position_ned_m: Vector3::new(10.0, 20.0, 0.0), heading_rad: FRAC_PI_2, sigma_rad_per_m: 1e-3 };
        // 30 m north and 30 m down of the ASV heading east: azimuth -90 deg, elevation 45 deg
        let (a, p, s) = usbl.angles(&Vector3::new(40.0, 20.0, 30.0));
        assert_abs_diff_eq!(a, -FRAC_PI_2, epsilon = 1e-12);
        assert_abs_diff_eq!(p, FRAC_PI_4, epsilon = 1e-12);
        assert_abs_diff_eq!(s, 30.0 * 2f64.sqrt() * 1e-3, epsilon = 1e-12);
        for x in [[40.0, 25.0, 30.0, 0.0], [-5.0, -60.0, 12.0, 1.0], [11.0, 19.0, 300.0, 0.0]] {
            let x = SVector::<f64, 4>::from(x);
            for angle in [UsblAngle::Azimuth, UsblAngle::Elevation] {
                let m = usbl.model(angle);
                assert_abs_diff_eq!(ScalarModel::<4>::jacobian(&m, &x), finite_difference::<4>(&m, &x), epsilon = 1e-7);
            }
        }
    }
}
