//! The Maritime Robotics Otter USV (hoff2024's ASV): two pontoons, two propellers. Mass
//! properties from ../shared/vehicles.md (Fossen 2021's Otter: 2.0 x 1.08 m, hull 55 kg
//! with its centre of gravity at [0.2, 0, -0.2] m, radii of gyration 0.4 B and 0.25 L,
//! payload 25 kg at [0.05, 0, -0.35] m).

use super::rigid_body::{rigid_body_mass, skew};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

/// Sea water density, kg/m^3.
pub const RHO: f64 = 1025.0;

/// The Otter's mass properties.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OtterMass {
    pub length_m: f64,
    pub beam_m: f64,
    pub hull_kg: f64,
    pub hull_cg_m: Vector3<f64>,
    pub payload_kg: f64,
    pub payload_at_m: Vector3<f64>,
}

impl Default for OtterMass {
    fn default() -> Self {
        Self {
            length_m: 2.0,
            beam_m: 1.08,
            hull_kg: 55.0,
            hull_cg_m: Vector3::new(0.2, 0.0, -0.2),
            payload_kg: 25.0,
            payload_at_m: Vector3::new(0.05, 0.0, -0.35),
        }
    }
}

impl OtterMass {
    /// Hull and payload.
    pub fn mass_kg(&self) -> f64 {
        self.hull_kg + self.payload_kg
    }

    /// The centre of gravity of hull and payload, body metres.
    pub fn cg_m(&self) -> Vector3<f64> {
        (self.hull_cg_m * self.hull_kg + self.payload_at_m * self.payload_kg) / self.mass_kg()
    }

    /// The inertia of hull and payload about their common centre of gravity: the hull's
    /// from its radii of gyration (R44 = 0.4 B, R55 = R66 = 0.25 L), the payload a point
    /// mass, both moved to the common centre by the parallel-axis theorem (Fossen 2021,
    /// eq. 3.37).
    pub fn inertia_cg(&self) -> Matrix3<f64> {
        let (r44, r55) = (0.4 * self.beam_m, 0.25 * self.length_m);
        let hull = Matrix3::from_diagonal(&Vector3::new(r44 * r44, r55 * r55, r55 * r55)) * self.hull_kg;
        let cg = self.cg_m();
        let (sh, sp) = (skew(&(self.hull_cg_m - cg)), skew(&(self.payload_at_m - cg)));
        hull - self.hull_kg * sh * sh - self.payload_kg * sp * sp
    }

    /// M = M_RB + M_A about the body origin. Added mass (vehicles.md): surge by Soding's
    /// formula X_u' = -2.7 rho V^(5/3) / L^2, sway -1.5 m, heave -1.0 m, with V and m the
    /// hull's (55 kg: what vehicles.md's regression values imply); roll -0.2, pitch -0.8
    /// and yaw -1.7 times the inertia about the centre of gravity.
    pub fn mass_matrix(&self) -> Matrix6<f64> {
        let inertia = self.inertia_cg();
        let mrb = rigid_body_mass(self.mass_kg(), &self.cg_m(), &inertia);
        let volume = self.hull_kg / RHO;
        let added = Vector6::new(
            2.7 * RHO * volume.powf(5.0 / 3.0) / (self.length_m * self.length_m),
            1.5 * self.hull_kg,
            1.0 * self.hull_kg,
            0.2 * inertia[(0, 0)],
            0.8 * inertia[(1, 1)],
            1.7 * inertia[(2, 2)],
        );
        mrb + Matrix6::from_diagonal(&added)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mass matrix's diagonal against vehicles.md's regression values (about [85.3,
    /// 162.5, 135.0, 17.7, 32.9, 40.0] with the 25 kg payload), within 0.1 unit; and it
    /// is symmetric positive definite.
    #[test]
    fn mass_matrix_matches_the_regression_values() {
        let m = OtterMass::default().mass_matrix();
        let expected = [85.3, 162.5, 135.0, 17.7, 32.9, 40.0];
        for (k, e) in expected.iter().enumerate() {
            assert!((m[(k, k)] - e).abs() < 0.1, "M{}{}: {} against {e}", k + 1, k + 1, m[(k, k)]);
        }
        assert!((m - m.transpose()).norm() < 1e-12);
        assert!(m.cholesky().is_some());
    }
}
