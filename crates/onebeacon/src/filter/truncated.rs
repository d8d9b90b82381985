//! Draws from a normal distribution truncated to an interval (hoff2024 eq. 4 keeps the
//! depth below the splash zone, the pitch within +-pi/2 and the speed non-negative).

use rand::{Rng, RngExt};
use rand_distr::StandardNormal;

/// A draw of N(mean, sd^2) truncated to [lo, hi] (either bound may be infinite).
/// Robert (1995): plain rejection when the interval holds much of the mass, an
/// exponential proposal for a tail, a uniform proposal for a narrow interval in a tail.
pub fn truncated_normal<R: Rng + ?Sized>(rng: &mut R, mean: f64, sd: f64, lo: f64, hi: f64) -> f64 {
    if sd <= 0.0 {
        return mean.clamp(lo, hi);
    }
    let (a, b) = ((lo - mean) / sd, (hi - mean) / sd);
    // symmetric: a tail below the mean is the mirror of one above it
    let z = if a >= 0.0 {
        standard_tail(rng, a, b)
    } else if b <= 0.0 {
        -standard_tail(rng, -b, -a)
    } else {
        // the interval holds the mean: plain rejection accepts at least a third of the
        // draws when both bounds are past half a sigma, else use the uniform proposal
        if b - a < 1.0 { uniform_proposal(rng, a, b, 0.0) } else { rejection(rng, a, b) }
    };
    mean + sd * z
}

/// Plain rejection from the standard normal.
fn rejection<R: Rng + ?Sized>(rng: &mut R, a: f64, b: f64) -> f64 {
    loop {
        let z: f64 = rng.sample(StandardNormal);
        if (a..=b).contains(&z) {
            return z;
        }
    }
}

/// A uniform proposal on [a, b], accepted with exp((m^2 - z^2) / 2), m the point of the
/// interval nearest 0.
fn uniform_proposal<R: Rng + ?Sized>(rng: &mut R, a: f64, b: f64, m: f64) -> f64 {
    loop {
        let z = a + (b - a) * rng.random::<f64>();
        if rng.random::<f64>() <= ((m * m - z * z) / 2.0).exp() {
            return z;
        }
    }
}

/// The standard normal truncated to [a, b] with 0 <= a < b.
fn standard_tail<R: Rng + ?Sized>(rng: &mut R, a: f64, b: f64) -> f64 {
    if a < 0.5 && b - a > 1.0 {
        return rejection(rng, a, b);
    }
    // the exponential proposal's rate (Robert's optimum), unless the interval is so
    // narrow that a uniform proposal accepts more
    let lambda = (a + (a * a + 4.0).sqrt()) / 2.0;
    if b - a < 2.0 / lambda {
        return uniform_proposal(rng, a, b, a);
    }
    loop {
        let z = a - (-rng.random::<f64>()).ln_1p() / lambda; // an exponential step past a
        if z <= b && rng.random::<f64>() <= (-(z - lambda) * (z - lambda) / 2.0).exp() {
            return z;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// Moments of truncated standard normals against the closed forms: with phi and Phi
    /// the normal pdf and cdf and Z = Phi(b) - Phi(a), the mean is (phi(a) - phi(b)) / Z
    /// and the variance 1 + (a phi(a) - b phi(b)) / Z - mean^2. Every draw in bounds.
    #[test]
    fn draws_respect_bounds_and_moments() {
        let phi = |x: f64| if x.is_finite() { (-x * x / 2.0).exp() / (2.0 * std::f64::consts::PI).sqrt() } else { 0.0 };
        // Phi by Simpson's rule from -10
        let cdf = |x: f64| {
            if x == f64::INFINITY {
                return 1.0;
            }
            if x == f64::NEG_INFINITY {
                return 0.0;
            }
            let (lo, n) = (-10.0, 20_000);
            let h = (x - lo) / n as f64;
            let mut s = phi(lo) + phi(x);
            for k in 1..n {
                s += phi(lo + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
            }
            s * h / 3.0
        };
        let xphi = |x: f64| if x.is_finite() { x * phi(x) } else { 0.0 };
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        for (a, b) in [
            (1.0, f64::INFINITY),
            (3.0, f64::INFINITY),
            (-0.3, 0.2),
            (-2.0, 1.5),
            (2.0, 2.4),
            (f64::NEG_INFINITY, -2.5),
            (0.0, 5.0),
        ] {
            let z = cdf(b) - cdf(a);
            let mean = (phi(a) - phi(b)) / z;
            let var = 1.0 + (xphi(a) - xphi(b)) / z - mean * mean;
            let n = 200_000;
            let draws: Vec<f64> = (0..n).map(|_| truncated_normal(&mut rng, 0.0, 1.0, a, b)).collect();
            assert!(draws.iter().all(|d| (a..=b).contains(d)), "[{a}, {b}]");
            let m = draws.iter().sum::<f64>() / n as f64;
            let v = draws.iter().map(|d| (d - m) * (d - m)).sum::<f64>() / n as f64;
            // 5 standard errors
            assert!((m - mean).abs() < 5.0 * (var / n as f64).sqrt(), "[{a}, {b}]: mean {m} against {mean}");
            assert!((v / var - 1.0).abs() < 5.0 * (2.0 / n as f64).sqrt() * 2.0, "[{a}, {b}]: var {v} against {var}");
        }
        // scaled and shifted
        let d = truncated_normal(&mut rng, 30.0, 2.0, 35.0, f64::INFINITY);
        assert!(d >= 35.0);
    }
}
