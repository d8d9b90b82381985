//! Sound speed in sea water.

/// Mackenzie (1981): sound speed (m/s) from temperature `t` (deg C, 2-30), salinity
/// `s` (ppt, 25-40) and depth `d` (m, 0-8000).
pub fn mackenzie(t: f64, s: f64, d: f64) -> f64 {
    1448.96 + 4.591 * t - 5.304e-2 * t * t + 2.374e-4 * t.powi(3) + 1.340 * (s - 35.0) + 1.630e-2 * d + 1.675e-7 * d * d
        - 1.025e-2 * t * (s - 35.0)
        - 7.139e-13 * t * d.powi(3)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn matches_the_published_check_value() {
        // Mackenzie (1981, J. Acoust. Soc. Am. 70(3), 807-812) gives one check value:
        // 1550.744 m/s at 25 deg C, 35 ppt and 1000 m, printed to the millimetre per
        // second, so within half of that. At 1000 m every depth term counts (the cross
        // term t d^3 alone is 0.018 m/s).
        assert_abs_diff_eq!(mackenzie(25.0, 35.0, 1000.0), 1550.744, epsilon = 5e-4);
    }
}
