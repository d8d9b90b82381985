//! Small one-dimensional searches shared by the planners and estimators.

/// Golden-section search for the maximum of a unimodal `f` on [a, b]: `iterations`
/// steps shrink the bracket by 0.618 each. Returns the best point evaluated and its
/// value.
pub fn golden_section_max(f: impl Fn(f64) -> f64, a: f64, b: f64, iterations: usize) -> (f64, f64) {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (a, b);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..iterations {
        if fc > fd {
            (b, d, fd) = (d, c, fc);
            c = b - g * (b - a);
            fc = f(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    if fc > fd { (c, fc) } else { (d, fd) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_vertex_of_a_parabola() {
        let (x, v) = golden_section_max(|x| 3.0 - (x - 1.234).powi(2), -5.0, 5.0, 60);
        assert!((x - 1.234).abs() < 1e-6, "{x}"); // a flat maximum: sqrt(eps) resolution
        assert!((v - 3.0).abs() < 1e-12);
    }
}
