//! The REMUS 100 AUV (hoff2024's AUV) as a prolate spheroid of length 1.6 m and
//! diameter 0.19 m (../shared/vehicles.md): its displaced mass, and the added mass of a
//! prolate spheroid of eccentricity e by Lamb's k-factors (Lamb 1932, from alpha_0 and
//! beta_0; the added mass of a spheroid in Fossen 2021, ch. 6).

use super::rigid_body::{BodyState, G, Inertia, Vessel, restoring, rigid_body_mass};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

/// Sea water density used for the REMUS, kg/m^3.
pub const RHO: f64 = 1026.0;

/// A prolate spheroid's half axes a (along) and b (across), m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spheroid {
    pub a_m: f64,
    pub b_m: f64,
}

impl Spheroid {
    /// REMUS 100's hull: L = 1.6 m, D = 0.19 m.
    pub fn remus100() -> Self {
        Self { a_m: 0.8, b_m: 0.095 }
    }

    /// Its displaced mass (neutrally buoyant: the vehicle's mass), kg.
    pub fn mass_kg(&self) -> f64 {
        RHO * 4.0 / 3.0 * std::f64::consts::PI * self.a_m * self.b_m * self.b_m
    }

    /// Lamb's k-factors (k1 surge, k2 sway and heave, k' pitch and yaw).
    pub fn lamb_k(&self) -> (f64, f64, f64) {
        let e2 = 1.0 - (self.b_m / self.a_m).powi(2);
        let e = e2.sqrt();
        let log = ((1.0 + e) / (1.0 - e)).ln();
        let alpha0 = 2.0 * (1.0 - e2) / (e * e2) * (0.5 * log - e);
        let beta0 = 1.0 / e2 - (1.0 - e2) / (2.0 * e * e2) * log;
        let k1 = alpha0 / (2.0 - alpha0);
        let k2 = beta0 / (2.0 - beta0);
        let kp = e2 * e2 * (beta0 - alpha0) / ((2.0 - e2) * (2.0 * e2 - (2.0 - e2) * (beta0 - alpha0)));
        (k1, k2, kp)
    }
}

/// REMUS 100's hull as a [`Vessel`] (the propeller and fins to come): neutrally buoyant,
/// its centre of gravity `cg_below_cb_m` under the centre of buoyancy (the origin),
/// linear damping from time constants (surge, sway, heave 20 s; yaw 1 s) and damping
/// ratios of the restoring oscillation (roll 0.3, pitch 0.8) (vehicles.md).
#[derive(Debug, Clone, PartialEq)]
pub struct Remus100 {
    pub hull: Spheroid,
    pub cg_below_cb_m: f64,
    inertia: Inertia,
    damping: Vector6<f64>,
}

impl Remus100 {
    pub fn new(hull: Spheroid, cg_below_cb_m: f64) -> Self {
        let mass = hull.mass_kg();
        let (a, b) = (hull.a_m, hull.b_m);
        // a solid spheroid's inertia about its centre
        let inertia = Matrix3::from_diagonal(&Vector3::new(
            0.4 * mass * b * b,
            0.2 * mass * (a * a + b * b),
            0.2 * mass * (a * a + b * b),
        ));
        let (k1, k2, kp) = hull.lamb_k();
        let added = Vector6::new(k1 * mass, k2 * mass, k2 * mass, 0.0, kp * inertia[(1, 1)], kp * inertia[(2, 2)]);
        let m =
            rigid_body_mass(mass, &Vector3::new(0.0, 0.0, cg_below_cb_m), &inertia) + Matrix6::from_diagonal(&added);
        // roll and pitch: the restoring stiffness W BG and the damping ratio's share of
        // the critical damping 2 sqrt(K M)
        let stiffness = mass * G * cg_below_cb_m;
        let critical = |k: usize| 2.0 * (stiffness * m[(k, k)]).sqrt();
        let damping = Vector6::new(
            m[(0, 0)] / 20.0,
            m[(1, 1)] / 20.0,
            m[(2, 2)] / 20.0,
            0.3 * critical(3),
            0.8 * critical(4),
            m[(5, 5)] / 1.0,
        );
        Self { hull, cg_below_cb_m, inertia: Inertia::new(m), damping }
    }
}

impl Default for Remus100 {
    fn default() -> Self {
        Self::new(Spheroid::remus100(), 0.02)
    }
}

impl Vessel for Remus100 {
    fn inertia(&self) -> &Inertia {
        &self.inertia
    }

    fn forces(&self, state: &BodyState, nu_r: &Vector6<f64>, _actuators: &[f64]) -> Vector6<f64> {
        let w = self.hull.mass_kg() * G;
        let g = restoring(&state.attitude, w, w, &Vector3::new(0.0, 0.0, self.cg_below_cb_m), &Vector3::zeros());
        -self.damping.component_mul(nu_r) - g
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vehicles::rigid_body::rk4_step;

    /// Neutrally buoyant and level at rest, it stays put: 10 min at 0.05 s, under 1e-12
    /// m and rad.
    #[test]
    fn at_rest_it_stays_put() {
        let remus = Remus100::default();
        let start = BodyState::at_rest(Vector3::new(5.0, -3.0, 30.0), 0.7);
        let mut s = start;
        for _ in 0..12_000 {
            s = rk4_step(&remus, &s, &[], &Vector3::zeros(), 0.05);
        }
        assert!((s.position_ned_m - start.position_ned_m).norm() < 1e-12);
        assert!(s.attitude.angle_to(&start.attitude) < 1e-12 && s.nu.norm() < 1e-12);
    }

    /// Yaw and heave are decoupled on this hull (no products of inertia, the centre of
    /// gravity straight under the origin), so a yaw rate or a heave speed decays as
    /// exp(-t / T) with the time constant their damping is defined by (1 s and 20 s):
    /// within 1e-8 after 3 s and 60 s.
    #[test]
    fn linear_damping_time_constants_match_their_definitions() {
        let remus = Remus100::default();
        for (k, t) in [(5, 1.0), (2, 20.0)] {
            let mut s = BodyState::at_rest(Vector3::new(0.0, 0.0, 30.0), 0.0);
            s.nu[k] = 0.2;
            let h = 0.01;
            for _ in 0..(3.0 * t / h) as usize {
                s = rk4_step(&remus, &s, &[], &Vector3::zeros(), h);
            }
            let expected = 0.2 * (-3.0f64).exp();
            assert!((s.nu[k] - expected).abs() < 1e-8, "{k}: {} against {expected}", s.nu[k]);
        }
    }

    /// Lamb's k-factors of REMUS 100's spheroid against vehicles.md's k1 ~ 0.027,
    /// k2 ~ 0.949, k' ~ 0.851 (to the last digit printed); a sphere's are 1/2, 1/2, 0
    /// (the limit e -> 0, approached at b = 0.999 a).
    #[test]
    fn lamb_factors_match_the_printed_values() {
        let (k1, k2, kp) = Spheroid::remus100().lamb_k();
        assert!((k1 - 0.027).abs() < 5e-4 && (k2 - 0.949).abs() < 5e-4 && (kp - 0.851).abs() < 5e-4, "{k1} {k2} {kp}");
        let (k1, k2, kp) = Spheroid { a_m: 1.0, b_m: 0.999 }.lamb_k();
        assert!((k1 - 0.5).abs() < 2e-3 && (k2 - 0.5).abs() < 2e-3 && kp.abs() < 2e-3, "{k1} {k2} {kp}");
    }
}
