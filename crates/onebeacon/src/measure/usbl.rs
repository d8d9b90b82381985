//! Bearing of an underwater vehicle measured by a USBL on a surface vehicle (hoff2024
//! eq. 1-3): the azimuth relative to the surface vehicle's heading and the elevation
//! angle from the vertical, each with a standard deviation that grows with the range.

use super::ScalarModel;
use crate::geo::{wrap_angle, wrap_near};
use nalgebra::{SMatrix, SVector, Vector3};
use std::f64::consts::PI;

/// The USBL on the surface vehicle: its NED position and heading when the message
/// arrives, the baseline noise sigma_USBL in rad per metre of range (the paper's deg/m,
/// converted), and how well the station knows its own position (GPS, m per horizontal
/// axis) and heading (compass, rad): the paper takes both as exact (zero). `floor_rad` is
/// an angle noise floor (standard deviation) besides eq. 3's range-proportional term, as
/// USBL datasheets state their accuracy (zero in the paper). `as_printed` reads eq. 6 as
/// the paper prints it (see [`Usbl::base_variance`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Usbl {
    pub position_ned_m: Vector3<f64>,
    pub heading_rad: f64,
    pub sigma_rad_per_m: f64,
    pub position_sigma_m: f64,
    pub heading_sigma_rad: f64,
    pub floor_rad: f64,
    pub as_printed: bool,
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
        let a = d.y.atan2(d.x) - self.heading_rad; // eq. 1
        // a wrapped heading needs one add or subtract (the hot loops' case)
        let alpha = if self.heading_rad.abs() <= PI { wrap_near(a) } else { wrap_angle(a) };
        let phi = h.atan2(d.z); // eq. 2: acos(dz / r), the angle of (dz, h)
        (alpha, phi, (h2 + d.z * d.z).sqrt() * self.sigma_rad_per_m) // eq. 3
    }

    /// A USBL whose station knows its own pose exactly.
    pub fn exact(position_ned_m: Vector3<f64>, heading_rad: f64, sigma_rad_per_m: f64) -> Self {
        Self {
            position_ned_m,
            heading_rad,
            sigma_rad_per_m,
            position_sigma_m: 0.0,
            heading_sigma_rad: 0.0,
            floor_rad: 0.0,
            as_printed: false,
        }
    }

    /// The variance of each angle from eq. 3 at squared range `r2`: (sigma_USBL r)^2; as
    /// printed, eq. 6's covariance diag(sigma_alpha, sigma_phi) puts eq. 3's sigma where a
    /// variance belongs: sigma_USBL r itself (rad taken as rad^2). The floor's variance
    /// adds to either (independent errors).
    pub fn base_variance(&self, r2: f64) -> f64 {
        let floor = self.floor_rad * self.floor_rad;
        if self.as_printed {
            floor + self.sigma_rad_per_m * r2.sqrt() // eq. 6 as printed
        } else {
            floor + self.sigma_rad_per_m * self.sigma_rad_per_m * r2 // eq. 3, squared
        }
    }

    /// The variances of the azimuth and the elevation of a vehicle at `p`: eq. 3's
    /// (sigma_USBL r)^2 on each, plus, to first order, what the station's pose errors add:
    /// its heading error wholly on the azimuth; its position error, across the line of
    /// sight, on the azimuth (sigma^2 / h^2) and, along it, on the elevation (d phi / d h
    /// = dz / r^2).
    pub fn variances(&self, p: &Vector3<f64>) -> (f64, f64) {
        let d = p - self.position_ned_m;
        let h2 = (d.x * d.x + d.y * d.y).max(1e-12);
        let r2 = h2 + d.z * d.z;
        let base = self.base_variance(r2);
        let g2 = self.position_sigma_m * self.position_sigma_m;
        let c2 = self.heading_sigma_rad * self.heading_sigma_rad;
        (base + g2 / h2 + c2, base + g2 * d.z * d.z / (r2 * r2))
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
        let (az, el) = self.usbl.variances(&x.fixed_rows::<3>(0).into_owned());
        match self.angle {
            UsblAngle::Azimuth => az,
            UsblAngle::Elevation => el,
        }
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
        let usbl = Usbl::exact(Vector3::new(10.0, 20.0, 0.0), FRAC_PI_2, 1e-3);
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

    /// Eq. 6 as printed at 35 m with Table 1's filter column (0.022 deg/m): the angles'
    /// variance is 0.022 x 35 = 0.77 deg = 0.013439 rad (as rad^2), a standard deviation of
    /// 6.64 deg, where the squared reading gives 0.77 deg.
    #[test]
    fn eq_6_as_printed_takes_sigma_as_the_variance() {
        let literal = Usbl { as_printed: true, ..Usbl::exact(Vector3::zeros(), 0.0, 0.022f64.to_radians()) };
        let p = Vector3::new(21.0, 0.0, 28.0); // 35 m away
        let (var_az, var_el) = literal.variances(&p);
        assert_abs_diff_eq!(var_az, 0.77f64.to_radians(), epsilon = 1e-12);
        assert_abs_diff_eq!(var_el, 0.77f64.to_radians(), epsilon = 1e-12);
        assert_abs_diff_eq!(var_az.sqrt().to_degrees(), 6.642, epsilon = 1e-3);
        let squared = Usbl { as_printed: false, ..literal };
        assert_abs_diff_eq!(squared.variances(&p).0.sqrt().to_degrees(), 0.77, epsilon = 1e-12);
    }

    /// A floor adds its variance to eq. 3's: 0.5 deg and 0.01 deg/m at 30 m give
    /// sqrt(0.5^2 + 0.3^2) = 0.5831 deg on each angle.
    #[test]
    fn the_floor_adds_in_quadrature() {
        let u = Usbl { floor_rad: 0.5f64.to_radians(), ..Usbl::exact(Vector3::zeros(), 0.0, 0.01f64.to_radians()) };
        let (var_az, var_el) = u.variances(&Vector3::new(0.0, 18.0, 24.0));
        assert_abs_diff_eq!(var_az.sqrt().to_degrees(), 0.583_095, epsilon = 1e-6);
        assert_abs_diff_eq!(var_el.sqrt().to_degrees(), 0.583_095, epsilon = 1e-6);
    }

    /// The station's pose errors in the variances against the spread of the angles
    /// over many stations drawn around the nominal one (Monte Carlo, 2e5 draws; the
    /// first-order terms hold to a few per cent 40 m away with 1 m and 2 deg errors).
    #[test]
    fn station_errors_add_their_spread() {
        use rand::SeedableRng;
        let nominal = Usbl {
            position_sigma_m: 1.0,
            heading_sigma_rad: 2f64.to_radians(),
            ..Usbl::exact(Vector3::zeros(), 0.3, 0.0)
        };
        let p = Vector3::new(20.0, 15.0, 30.0);
        let (var_az, var_el) = nominal.variances(&p);
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        let n = 200_000;
        let (a0, e0, _) = nominal.angles(&p);
        let (mut sa, mut se) = (0.0, 0.0);
        for _ in 0..n {
            let g = |rng: &mut rand_pcg::Pcg64Mcg, s: f64| crate::filter::gauss(rng, s);
            let station = Usbl::exact(
                Vector3::new(g(&mut rng, 1.0), g(&mut rng, 1.0), 0.0),
                0.3 + g(&mut rng, 2f64.to_radians()),
                0.0,
            );
            let (a, e, _) = station.angles(&p);
            sa += crate::geo::wrap_angle(a - a0).powi(2);
            se += (e - e0).powi(2);
        }
        assert_abs_diff_eq!(sa / n as f64, var_az, epsilon = 0.03 * var_az);
        assert_abs_diff_eq!(se / n as f64, var_el, epsilon = 0.03 * var_el);
    }
}
