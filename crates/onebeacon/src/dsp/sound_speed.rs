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
    fn matches_the_check_values() {
        // check values computed from Mackenzie's (1981) nine-term equation by hand
        assert_abs_diff_eq!(mackenzie(10.0, 35.0, 50.0), 1490.6188, epsilon = 5e-5);
        assert_abs_diff_eq!(mackenzie(25.0, 35.0, 20.0), 1534.6204, epsilon = 5e-5);
    }
}
