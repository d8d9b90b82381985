//! Properties of every measurement model at random points (proptest): finite states give
//! finite predictions, Jacobians and variances, and each Jacobian matches central finite
//! differences of the model's own prediction (an independent reference).

use nalgebra::{SMatrix, SVector, Vector2, Vector3};
use onebeacon::measure::{RadialSpeed2d, Range2d, Range3d, ScalarModel, SlantRange, StateComponent};
use proptest::prelude::*;

const N: usize = 6;

/// Central differences of `m.predict` at `x` (step scaled to each component).
fn numeric_jacobian(m: &impl ScalarModel<N>, x: &SVector<f64, N>) -> SMatrix<f64, 1, N> {
    SMatrix::from_fn(|_, j| {
        let h = 1e-6 * x[j].abs().max(1.0);
        let (mut a, mut b) = (*x, *x);
        a[j] += h;
        b[j] -= h;
        let mut d = m.predict(&a) - m.predict(&b);
        if m.is_angle() {
            d = onebeacon::geo::wrap_angle(d);
        }
        d / (2.0 * h)
    })
}

/// The model is finite at `x` and its Jacobian is the finite-difference one.
fn check(m: &impl ScalarModel<N>, x: &SVector<f64, N>) -> Result<(), TestCaseError> {
    let (z, h, v) = (m.predict(x), m.jacobian(x), m.variance(x));
    prop_assert!(z.is_finite() && v.is_finite() && v >= 0.0, "z {z}, variance {v}");
    prop_assert!(h.iter().all(|e| e.is_finite()), "{h}");
    let numeric = numeric_jacobian(m, x);
    let scale = h.iter().chain(numeric.iter()).fold(1.0f64, |a, e| a.max(e.abs()));
    for j in 0..N {
        prop_assert!((h[j] - numeric[j]).abs() <= 1e-5 * scale, "column {j}: analytic {h} numeric {numeric}");
    }
    Ok(())
}

fn state() -> impl Strategy<Value = SVector<f64, N>> {
    // positions within 5 km, heading any, speed, yaw rate and acceleration plausible
    (-5e3..5e3f64, -5e3..5e3f64, -10.0..10.0f64, -5.0..5.0f64, -1.0..1.0f64, -2.0..2.0f64)
        .prop_map(|(a, b, c, d, e, f)| SVector::from([a, b, c, d, e, f]))
}

fn beacon() -> impl Strategy<Value = Vector3<f64>> {
    (-5e3..5e3f64, -5e3..5e3f64, 0.0..100.0f64).prop_map(|(n, e, d)| Vector3::new(n, e, d))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn horizontal_range(x in state(), b in beacon()) {
        // not on top of the beacon, where the range is not differentiable
        prop_assume!((x.xy() - b.xy()).norm() > 1e-2);
        check(&Range2d { beacon: b.xy(), var: 4.0 }, &x)?;
    }

    #[test]
    fn slant_range_with_beacon_error(x in state(), b in beacon(), sigma in 0.0..5.0f64) {
        prop_assume!((Vector3::new(x[0], x[1], x[2]) - b).norm() > 1e-2);
        check(&Range3d { beacon: b, sigma_m: 1.0, beacon_sigma_m: sigma }, &x)?;
    }

    #[test]
    fn slant_range_with_bias_and_scale(x in state(), b in beacon(), depth in 0.0..200.0f64) {
        prop_assume!((Vector3::new(x[0], x[1], depth) - b).norm() > 1e-2);
        check(&SlantRange { beacon: b, depth_m: depth, bias: Some(4), scale: Some(5), var: 2.25 }, &x)?;
    }

    #[test]
    fn radial_speed(x in state(), b in beacon(), known in proptest::option::of(-3.0..3.0f64)) {
        prop_assume!((x.xy() - b.xy()).norm() > 1.0);
        check(&RadialSpeed2d { beacon: Vector2::new(b.x, b.y), known_speed_m_s: known, dz_m: 0.0, var: 0.2 }, &x)?;
    }

    #[test]
    fn state_components(x in state(), i in 0..N, angle: bool) {
        check(&StateComponent { index: i, angle, var: 0.01 }, &x)?;
    }
}
