//! The one policy for an estimator whose state stops being sound (not finite, or its
//! horizontal covariance not positive definite): it is built again from its last sound
//! pose with its initial uncertainty, and the restart is reported. The session (replay,
//! stream, Python) and the simulator's engine apply it alike.

use super::{Estimate, Navigator};

/// Builds one estimator at time t0 (s) from a pose (north, east, heading; m, m, rad)
/// with the initial position and heading sigmas (m, rad): at the start, and again from
/// its last sound pose.
pub type Builder = Box<dyn Fn(f64, (f64, f64, f64), f64, f64) -> Box<dyn Navigator> + Send + Sync>;

/// Whether an estimate is sound: finite, with a positive definite horizontal covariance
/// and a finite heading variance.
pub fn sound(e: &Estimate) -> bool {
    let p = &e.horizontal_cov_m2;
    e.position_ned_m.iter().all(|v| v.is_finite())
        && e.heading_state_rad.is_finite()
        && e.heading_var_rad2.is_finite()
        && p.iter().all(|v| v.is_finite())
        && p[(0, 0)] > 0.0
        && p.determinant() > 0.0
}

/// One estimator's builder, its initial sigmas, and its last sound pose.
pub struct Restart {
    builder: Builder,
    sigmas: (f64, f64),
    last_sound: (f64, f64, f64),
}

impl std::fmt::Debug for Restart {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Restart").field("last_sound", &self.last_sound).finish_non_exhaustive()
    }
}

impl Restart {
    /// The policy of an estimator built by `builder` with initial sigmas `sigmas`
    /// (position m, heading rad), starting at `pose`.
    pub fn new(builder: Builder, pose: (f64, f64, f64), sigmas: (f64, f64)) -> Self {
        Self { builder, sigmas, last_sound: pose }
    }

    /// The estimator built at `t0_s` from `pose`.
    pub fn build(&self, t0_s: f64, pose: (f64, f64, f64)) -> Box<dyn Navigator> {
        (self.builder)(t0_s, pose, self.sigmas.0, self.sigmas.1)
    }

    /// After an update at `t_s` that left `navigator` with `estimate`: a sound estimate's
    /// pose is kept; an unsound navigator is replaced by one built at `t_s` from the last
    /// sound pose, `estimate` becomes its, and the answer is true.
    pub fn apply(&mut self, navigator: &mut Box<dyn Navigator>, estimate: &mut Estimate, t_s: f64) -> bool {
        if sound(estimate) {
            self.last_sound = (estimate.north_m(), estimate.east_m(), estimate.heading_state_rad);
            return false;
        }
        *navigator = self.build(t_s, self.last_sound);
        *estimate = navigator.estimate();
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::FilterKind;
    use crate::nav::{PlanarConfig, PlanarNavigator};

    /// An estimate is sound when finite with a positive definite horizontal covariance.
    #[test]
    fn soundness() {
        let pose = (1.0, 2.0, 0.5);
        let nav = PlanarNavigator::new(PlanarConfig::default(), FilterKind::Ekf, 0.0, pose, 1.0, 0.1);
        let good = nav.estimate();
        assert!(sound(&good));
        let mut e = good;
        e.position_ned_m.x = f64::NAN;
        assert!(!sound(&e));
        let mut e = good;
        e.horizontal_cov_m2[(0, 1)] = 2.0; // |rho| > 1: not positive definite
        e.horizontal_cov_m2[(1, 0)] = 2.0;
        assert!(!sound(&e));
        let mut e = good;
        e.heading_var_rad2 = f64::INFINITY;
        assert!(!sound(&e));
    }

    /// An unsound navigator is built again from the last sound pose, at the time of the
    /// update, with the initial sigmas.
    #[test]
    fn an_unsound_navigator_starts_again_from_its_last_sound_pose() {
        let builder: Builder = crate::nav::planar::builder(PlanarConfig::default(), FilterKind::Ekf);
        let mut r = Restart::new(builder, (1.0, 2.0, 0.5), (3.0, 0.1));
        let mut nav = r.build(0.0, (1.0, 2.0, 0.5));
        let mut e = nav.estimate();
        assert!(!r.apply(&mut nav, &mut e, 1.0));
        let mut bad = e;
        bad.position_ned_m.y = f64::NAN;
        assert!(r.apply(&mut nav, &mut bad, 2.0));
        assert_eq!((bad.north_m(), bad.east_m(), bad.t_s), (1.0, 2.0, 2.0));
        assert!((bad.sigma_north_m() - 3.0).abs() < 1e-12, "{}", bad.sigma_north_m());
    }
}
