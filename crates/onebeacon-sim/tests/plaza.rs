//! The real plaza logs (data/plaza) through the replay engine. The table of the closing
//! note: `cargo test --release -p onebeacon-sim --test plaza -- --ignored --nocapture`.

use onebeacon_sim::replay::{Log, LogError, replay};
use std::collections::BTreeSet;
use std::path::PathBuf;

fn log(n: u8) -> Log {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../data/plaza/plaza{n}.toml"));
    Log::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// The replay engine and the stream engine are one: items pushed one by one into a
/// session give the replay's statistics.
#[test]
fn replay_is_the_session_fed_item_by_item() {
    let l = log(2);
    let mut rows = 0;
    let r = replay(&l, None, |_| {
        rows += 1;
        Ok::<_, LogError>(())
    })
    .unwrap();
    let mut s = onebeacon_sim::replay::session_for(&l, None).unwrap();
    for item in l.items().unwrap() {
        s.push(&item.unwrap()).expect("no plaza item is screened out");
    }
    assert_eq!(s.stats, r.session.stats);
    assert_eq!(s.final_estimates(), r.session.final_estimates());
    assert_eq!(rows, 4091); // one row per ground-truth pose (4092 lines less the header)
    assert_eq!(r.items, 4091 + 4090 + 1816); // every CSV row of the three sources
}

#[test]
#[ignore]
fn measure_plaza_table() {
    for n in [1, 2] {
        let l = log(n);
        let names = replay(&l, None, |_| Ok::<_, LogError>(())).unwrap().session.names;
        eprintln!("| plaza{n} beacons | {} |", names.join(" | "));
        for b in [None, Some(0), Some(1), Some(5), Some(6)] {
            let r = replay(&l, b.map(|b| BTreeSet::from([b])), |_| Ok::<_, LogError>(())).unwrap();
            let cells: Vec<String> = r
                .session
                .stats
                .iter()
                .zip(r.session.final_estimates())
                .map(|(s, e)| {
                    format!(
                        "{:.2} [{} rej, b {:.2}, kr {:.3}, kt {:.3}]",
                        s.rmse_m(),
                        s.rejected,
                        e.range_bias_m,
                        e.range_scale,
                        e.turn_scale
                    )
                })
                .collect();
            eprintln!("| {} | {} |", b.map_or("all".into(), |b| b.to_string()), cells.join(" | "));
        }
    }
}
