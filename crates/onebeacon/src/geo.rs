//! Frames and angles. NED: x north, y east, z down; heading psi from north toward east.

use std::f64::consts::{PI, TAU};

/// Wraps an angle to (-pi, pi].
pub fn wrap_angle(a: f64) -> f64 {
    let w = a.rem_euclid(TAU); // [0, 2 pi)
    if w > PI { w - TAU } else { w }
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
    }
}
