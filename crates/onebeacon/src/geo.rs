//! Frames and angles. NED: x north, y east, z down; heading psi from north toward east.

use nalgebra::Vector3;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Wraps an angle to (-pi, pi].
pub fn wrap_angle(a: f64) -> f64 {
    let w = a.rem_euclid(TAU); // [0, 2 pi)
    if w > PI { w - TAU } else { w }
}

/// Wraps an angle in (-3 pi, 3 pi] to (-pi, pi] with one add or subtract: the
/// difference or sum of two wrapped angles, in a hot loop (no remainder).
#[inline]
pub fn wrap_near(a: f64) -> f64 {
    if a > PI {
        a - TAU
    } else if a <= -PI {
        a + TAU
    } else {
        a
    }
}

/// The horizontal frame of external data (logs, streams), converted to NED at the
/// boundary. In both, headings turn from the x axis toward the y axis.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Frame {
    /// x north, y east, z down; heading clockwise from north.
    #[default]
    Ned,
    /// x east, y north, z up; heading (yaw) counter-clockwise from east.
    Enu,
}

impl Frame {
    /// A position (x, y, z) in this frame, in NED.
    pub fn to_ned(self, x: f64, y: f64, z: f64) -> Vector3<f64> {
        match self {
            Frame::Ned => Vector3::new(x, y, z),
            Frame::Enu => Vector3::new(y, x, -z),
        }
    }

    /// A NED position in this frame, (x, y, z).
    pub fn from_ned(self, p: &Vector3<f64>) -> (f64, f64, f64) {
        match self {
            Frame::Ned => (p.x, p.y, p.z),
            Frame::Enu => (p.y, p.x, -p.z),
        }
    }

    /// A heading in this frame as a NED heading, and back (the map is its own inverse).
    pub fn heading_to_ned(self, h: f64) -> f64 {
        match self {
            Frame::Ned => wrap_angle(h),
            Frame::Enu => wrap_angle(FRAC_PI_2 - h),
        }
    }

    pub fn heading_from_ned(self, psi: f64) -> f64 {
        self.heading_to_ned(psi)
    }

    /// A heading change in this frame as a NED heading change.
    pub fn turn_to_ned(self, dh: f64) -> f64 {
        match self {
            Frame::Ned => dh,
            Frame::Enu => -dh,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn wraps_into_half_open_interval() {
        assert_abs_diff_eq!(wrap_angle(0.0), 0.0);
        assert_abs_diff_eq!(wrap_angle(PI), PI);
        assert_abs_diff_eq!(wrap_angle(-PI), PI);
        assert_abs_diff_eq!(wrap_angle(3.0 * PI / 2.0), -PI / 2.0, epsilon = 1e-12);
        assert_abs_diff_eq!(wrap_angle(-7.0 * PI / 2.0), PI / 2.0, epsilon = 1e-12);
        assert_abs_diff_eq!(wrap_angle(10.0 * TAU + 0.1), 0.1, epsilon = 1e-9);
        // one add or subtract agrees with the remainder across (-3 pi, 3 pi]
        for k in -3000..=3000 {
            let a = k as f64 * 3.0 * PI / 3000.0 + 1e-6;
            if a > -3.0 * PI && a <= 3.0 * PI {
                assert_abs_diff_eq!(wrap_near(a), wrap_angle(a), epsilon = 1e-12);
            }
        }
    }

    /// Plaza-style ENU data: moving along +y (north) with yaw pi/2 is NED heading 0;
    /// a counter-clockwise turn is a negative NED turn; positions round-trip.
    #[test]
    fn enu_converts_to_ned() {
        let f = Frame::Enu;
        assert_eq!(f.to_ned(3.0, 4.0, 5.0), Vector3::new(4.0, 3.0, -5.0));
        assert_eq!(f.from_ned(&f.to_ned(3.0, 4.0, 5.0)), (3.0, 4.0, 5.0));
        assert_abs_diff_eq!(f.heading_to_ned(FRAC_PI_2), 0.0);
        assert_abs_diff_eq!(f.heading_to_ned(0.0), FRAC_PI_2); // east
        assert_abs_diff_eq!(f.heading_from_ned(f.heading_to_ned(2.5)), 2.5, epsilon = 1e-12);
        // dead reckoning in either frame traces the same path
        let (yaw, d) = (0.7f64, 2.0);
        let step_enu = f.to_ned(d * yaw.cos(), d * yaw.sin(), 0.0);
        let psi = f.heading_to_ned(yaw);
        assert_abs_diff_eq!(step_enu, Vector3::new(d * psi.cos(), d * psi.sin(), 0.0), epsilon = 1e-12);
        assert_abs_diff_eq!(f.heading_to_ned(yaw + 0.1), wrap_angle(psi + f.turn_to_ned(0.1)), epsilon = 1e-12);
        assert_eq!(Frame::Ned.to_ned(3.0, 4.0, 5.0), Vector3::new(3.0, 4.0, 5.0));
    }
}
