//! The REMUS 100 AUV (hoff2024's AUV) as a prolate spheroid of length 1.6 m and
//! diameter 0.19 m (../shared/vehicles.md): its displaced mass, and the added mass of a
//! prolate spheroid of eccentricity e by Lamb's k-factors (Lamb 1932, from alpha_0 and
//! beta_0; the added mass of a spheroid in Fossen 2021, ch. 6).

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

#[cfg(test)]
mod tests {
    use super::*;

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
