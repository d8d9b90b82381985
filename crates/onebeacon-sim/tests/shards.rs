//! Sharded Monte Carlo: every share's partial, written as JSON, read back and merged,
//! gives the unsharded result bit for bit; the merge refuses what is not one campaign.

use onebeacon_sim::metrics::RunMetrics;
use onebeacon_sim::montecarlo::{Shard, monte_carlo, monte_carlo_shard};
use onebeacon_sim::partial::{MergeError, Partial, merge};
use onebeacon_sim::scenario::moving_beacon::{GuidanceKind, PathKind};
use onebeacon_sim::scenario::{BUILTINS, Scenario, builtin, parse};

fn short(name: &str) -> Scenario {
    match parse(builtin(name).unwrap().toml, name).unwrap() {
        Scenario::FixedBeacon(mut s) => {
            s.mission.duration_s = Some(300.0);
            s.sweep.t_com_s = Some(vec![3.0, 15.0]);
            Scenario::FixedBeacon(s)
        }
        Scenario::MovingBeacon(mut s) => {
            s.mission.duration_s = 200.0;
            s.sweep.path = Some(vec![PathKind::Circular]);
            s.sweep.depth_m = Some(vec![25.0]);
            s.sweep.guidance = Some(vec![GuidanceKind::ApproachA, GuidanceKind::ApproachB]);
            Scenario::MovingBeacon(s)
        }
        _ => unreachable!(),
    }
}

/// The partials of `n` shards, each through its JSON file's text.
fn partials(s: &Scenario, runs: usize, seed: u64, n: usize) -> Vec<(String, Partial)> {
    (0..n)
        .map(|index| {
            let shard = Shard { index, count: n };
            let summaries = monte_carlo_shard(s, runs, seed, shard, Some(2), &|| {}).unwrap();
            let text = Partial::new(s, runs, seed, shard, 0.5, &summaries).to_json();
            let name = format!("p{index}");
            (name.clone(), Partial::from_json(&text, &name).unwrap())
        })
        .collect()
}

#[test]
fn merged_shards_equal_the_unsharded_sweep() {
    for name in ["garin2024", "sousa"] {
        let s = short(name);
        let whole = monte_carlo(&s, 5, 3, None, &|| {}).unwrap();
        for n in [1, 3, 7] {
            let merged = merge(partials(&s, 5, 3, n)).unwrap();
            assert_eq!(merged.result, whole, "{name}, {n} shards");
            assert_eq!(merged.scenario, s);
            assert!((merged.wall_s - 0.5 * n as f64).abs() < 1e-12);
        }
        // the shares' order does not matter
        let mut reversed = partials(&s, 5, 3, 3);
        reversed.reverse();
        assert_eq!(merge(reversed).unwrap().result, whole);
    }
}

#[test]
fn every_pair_belongs_to_exactly_one_share() {
    let (cells, runs, n) = (4, 7, 5);
    let mut seen = vec![0; cells * runs];
    for index in 0..n {
        let pairs: Vec<_> = Shard { index, count: n }.pairs(cells, runs).collect();
        // shares differ in size by at most one pair
        assert!(pairs.len() == cells * runs / n || pairs.len() == cells * runs / n + 1);
        for (c, r) in pairs {
            seen[c * runs + r as usize] += 1;
        }
    }
    assert!(seen.iter().all(|&k| k == 1));
}

#[test]
fn shard_parses_i_of_n_only() {
    assert_eq!("2/7".parse::<Shard>(), Ok(Shard { index: 2, count: 7 }));
    for bad in ["7/7", "1/0", "-1/3", "1", "a/b", "1/3/4", ""] {
        assert!(bad.parse::<Shard>().is_err(), "{bad}");
    }
}

#[test]
fn every_builtin_survives_its_canonical_toml() {
    for b in BUILTINS {
        let s = parse(b.toml, b.name).unwrap();
        let text = s.to_toml();
        let again = parse(&text, b.name).unwrap_or_else(|e| panic!("{}: {e}\n{text}", b.name));
        assert_eq!(again, s, "{}", b.name);
        assert_eq!(again.to_toml(), text, "{}", b.name);
    }
}

#[test]
fn metrics_words_carry_infinity_and_nan_exactly() {
    let m = RunMetrics {
        mean_error_m: f64::INFINITY,
        error_variance_m2: f64::NAN,
        mse_m2: 0.1 + 0.2,
        max_error_m: -0.0,
        final_error_m: f64::MIN_POSITIVE / 3.0,
        etd_max_pct: 1e300,
        etd_mean_pct: 2.5,
        nees_mean: f64::NEG_INFINITY,
        failed_updates: u64::MAX,
        mean_error_first_half_m: 7.0,
        mean_error_second_half_m: 8.0,
    };
    let back = RunMetrics::from_words(&m.to_words());
    assert_eq!(back.to_words(), m.to_words());
    assert!(back.error_variance_m2.is_nan() && back.mean_error_m == f64::INFINITY);
    assert_eq!(back.mse_m2.to_bits(), (0.1f64 + 0.2).to_bits());
}

#[test]
fn merge_refuses_what_is_not_one_campaign() {
    let s = short("garin2024");
    let good = partials(&s, 3, 1, 3);
    let err = |p: Vec<(String, Partial)>| merge(p).unwrap_err();
    let with = |i: usize, edit: &dyn Fn(&mut Partial)| {
        let mut p = good.clone();
        edit(&mut p[i].1);
        p
    };
    assert!(matches!(err(Vec::new()), MergeError::Empty));
    assert!(matches!(err(good[..2].to_vec()), MergeError::Missing { .. }));
    let mut dup = good.clone();
    dup.push(("again".into(), good[1].1.clone()));
    assert!(matches!(err(dup), MergeError::Duplicate { .. }));
    assert!(matches!(err(with(1, &|p| p.seed = 2)), MergeError::Mismatch { what: "seed", .. }));
    assert!(matches!(err(with(1, &|p| p.runs = 4)), MergeError::Mismatch { what: "runs per cell", .. }));
    assert!(matches!(err(with(2, &|p| p.version = "0.0.1".into())), MergeError::Version { .. }));
    let other = short("sousa").to_toml();
    let sousa = |p: &mut Partial| {
        p.scenario_toml = other.clone();
        p.scenario = "sousa".into();
    };
    assert!(matches!(err(with(1, &sousa)), MergeError::Mismatch { what: "scenario", .. }));
    let edited = s.to_toml().replace("seed = 1", "seed = 5");
    assert_ne!(edited, s.to_toml());
    assert!(matches!(err(with(1, &|p| p.scenario_toml = edited.clone())), MergeError::Mismatch { .. }));
    assert!(matches!(
        err(with(0, &|p| {
            p.results.pop();
        })),
        MergeError::Incomplete { .. }
    ));
    // a share count that disagrees is refused before shares are counted
    let four = partials(&s, 3, 1, 4);
    let mixed = vec![good[0].clone(), four[1].clone()];
    assert!(matches!(err(mixed), MergeError::Mismatch { what: "shard count", .. }));
    // every message is one line
    let e = err(with(1, &|p| p.seed = 2)).to_string();
    assert!(!e.contains('\n') && e.contains("p0") && e.contains("p1"), "{e}");
    // not a partial at all
    assert!(matches!(Partial::from_json("{\"a\": 1}", "x"), Err(MergeError::NotPartial { .. })));
    assert!(matches!(Partial::from_json("[", "x"), Err(MergeError::NotPartial { .. })));
}

/// Counts from a corrupt or hostile file are checked before anything is allocated by
/// them: one error each, no abort, no panic.
#[test]
fn merge_checks_counts_before_using_them() {
    let s = short("sousa");
    let good = partials(&s, 2, 1, 2);
    let err = |p: Vec<(String, Partial)>| merge(p).unwrap_err();
    let with = |edit: &dyn Fn(&mut Partial)| {
        let mut p = good.clone();
        for (_, q) in &mut p {
            edit(q);
        }
        p
    };
    for shards in [1_000_000_000, 1 << 62, usize::MAX] {
        let e = err(with(&|p| p.shards = shards));
        assert!(matches!(e, MergeError::Count { what: "shards", .. }), "{shards}: {e}");
    }
    for runs in [1_000_000_000, usize::MAX, 0] {
        let e = err(with(&|p| p.runs = runs));
        assert!(matches!(e, MergeError::Count { .. } | MergeError::Incomplete { .. }), "{runs}: {e}");
    }
    let vehicles = s.vehicle_names().len();
    let info = |v: usize, n: usize| {
        with(&|p: &mut Partial| {
            if let Some(r) = p.results.first_mut() {
                r.information.push((v, 1, n, vec![0; n * n]));
            }
        })
    };
    assert!(matches!(err(info(vehicles, 6)), MergeError::Aggregate(_)), "a vehicle out of range");
    assert!(matches!(err(info(0, 5)), MergeError::Aggregate(_)), "a 5 x 5 matrix where 6 x 6 belong");
    assert!(merge(info(0, 6)).is_ok(), "a well-formed extra entry is merged");
    // a matrix whose side squared overflows is not a partial
    let mut p = good[0].1.clone();
    p.results[0].information.push((0, 1, 1 << 33, vec![0; 4]));
    assert!(Partial::from_json(&p.to_json(), "x").is_err());
}
