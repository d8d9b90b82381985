//! Fuzz-style properties of what a vehicle runs for hours (proptest): whatever a stream
//! line or an item holds, nothing panics, and no estimator is ever left with a state or
//! covariance that is not finite and positive definite.

use nalgebra::Vector3;
use onebeacon::filter::FilterKind;
use onebeacon::geo::Frame;
use onebeacon::nav::session::{Input, Item, Session, Start, TruthPose};
use onebeacon::nav::{Aiding, BeaconFix, Kind, PlanarConfig};
use proptest::prelude::*;
use std::collections::{BTreeMap, BTreeSet};

/// Any f64 at all, extremes and non-finite ones included, or a plausible value.
fn value() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -50.0..50.0f64,
        1 => prop::num::f64::ANY,
        1 => prop_oneof![Just(0.0), Just(-0.0), Just(1e308), Just(-1e308), Just(f64::MIN_POSITIVE), Just(1e-300)],
    ]
}

fn item() -> impl Strategy<Value = (f64, Input)> {
    // beacon 2 is tracked: its position comes from beacon_position items
    let beacon = || {
        (0u32..3, value(), value()).prop_map(|(id, n, e)| BeaconFix {
            id,
            position_ned_m: if id == 2 { Vector3::repeat(f64::NAN) } else { Vector3::new(n, e, 0.0) },
            sigma_m: 0.0,
            t_tx_s: None,
        })
    };
    let m = Input::Measurement;
    let input = prop_oneof![
        (value(), value()).prop_map(move |(d, h)| m(Kind::Odometry { distance_m: d, heading_change_rad: h })),
        value().prop_map(move |v| m(Kind::Speed { speed_m_s: v })),
        value().prop_map(move |h| m(Kind::Heading { heading_rad: h })),
        (beacon(), value()).prop_map(move |(b, r)| m(Kind::Range { beacon: b, range_m: r })),
        (beacon(), value()).prop_map(move |(b, v)| m(Kind::Doppler { beacon: b, radial_speed_m_s: v })),
        (beacon(), value(), value()).prop_map(move |(b, r, v)| m(Kind::RangeDoppler {
            beacon: b,
            range_m: r,
            radial_speed_m_s: v
        })),
        (0u32..3, value(), value())
            .prop_map(|(id, x, y)| Input::BeaconPosition { beacon_id: id, position: Vector3::new(x, y, 0.0) }),
        (value(), value()).prop_map(|(n, e)| Input::Truth(TruthPose::exact(n, e, None))),
    ];
    // mostly small steps forward, sometimes a jump or a step back
    (prop_oneof![8 => 0.0..2.0f64, 1 => value()], input)
}

fn session() -> Session {
    let start = Start::At { t0_s: None, pose: (0.0, 0.0, 0.0) };
    let estimators = vec![
        ("ekf".to_string(), PlanarConfig::default(), FilterKind::Ekf),
        ("gated".to_string(), PlanarConfig { nis_gate: Some(10.83), ..PlanarConfig::default() }, FilterKind::Ekf),
        (
            "cal".to_string(),
            PlanarConfig {
                estimate_bias: true,
                estimate_range_scale: true,
                estimate_distance_scale: true,
                estimate_turn_scale: true,
                ..PlanarConfig::default()
            },
            FilterKind::Ukf(Default::default()),
        ),
        ("dr".to_string(), PlanarConfig { aiding: Aiding::NONE, ..PlanarConfig::default() }, FilterKind::Ekf),
    ];
    let builders = estimators.into_iter().map(|(n, c, f)| (n, onebeacon::nav::planar::builder(c, f))).collect();
    Session::new(Frame::Ned, builders, start, (1.0, 0.1), None)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// 300 random streams of 200 items each, values anywhere in f64: every estimate the
    /// session gives is finite with a positive definite horizontal covariance.
    #[test]
    fn no_item_poisons_an_estimator(steps in prop::collection::vec(item(), 1..200)) {
        let mut s = session();
        let mut t = 100.0;
        for (dt, input) in steps {
            t += dt;
            if let Ok(Some(step)) = s.push(&Item { t_s: t, input }) {
                for e in &step.estimates {
                    let p = e.horizontal_cov_m2;
                    prop_assert!(e.position_ned_m.iter().all(|v| v.is_finite()), "{e:?}");
                    prop_assert!(p.iter().all(|v| v.is_finite()) && p[(0, 0)] > 0.0 && p.determinant() > 0.0, "{e:?}");
                }
            }
        }
    }
}

#[cfg(feature = "stream")]
mod lines {
    use super::*;
    use onebeacon::io::jsonl::parse_item;

    const GOOD: &str = r#"{"t_s": 12.5, "kind": "range_doppler", "beacon": 1, "range_m": 40.5, "radial_speed_m_s": -0.3, "beacon_sigma_m": 0.5}"#;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3000))]

        /// Any text, and any one-byte edit of a good line, parses or is refused: no panic.
        #[test]
        fn no_line_panics_the_parser(text in ".{0,200}", at in 0usize..200, byte in any::<u8>()) {
            let fixed = BTreeMap::from([(1, Vector3::new(1.0, 2.0, 0.0))]);
            let tracked = BTreeSet::from([2]);
            let _ = parse_item(&text, &fixed, &tracked);
            let mut edited = GOOD.as_bytes().to_vec();
            let i = at % edited.len();
            edited[i] = byte;
            if let Ok(line) = std::str::from_utf8(&edited) {
                let _ = parse_item(line, &fixed, &tracked);
            }
        }
    }
}
