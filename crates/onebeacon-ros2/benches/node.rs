//! The node's own cost of a message, without DDS: a sensor_msgs/Range sample's CDR bytes
//! decoded by its topic's seed, turned into its stream line, and pushed through the
//! stream's loop with plaza1.toml's estimators (as `onebeacon ros2` does after RustDDS
//! hands it a sample, before it publishes); beside it the same range as a stream line
//! alone (`stream`'s cost, onebeacon-bench's "stream line: range").

use criterion::{Criterion, criterion_group, criterion_main};
use onebeacon::io::jsonl::line_json;
use onebeacon::log::{Log, feed_items, stream_setup};
use std::hint::black_box;
use std::path::PathBuf;

/// A sensor_msgs/Range sample (Humble's layout) as CDR, little-endian: its stamp, the
/// beacon as its frame id and the range (float32), with CDR's alignment.
fn range_cdr(t_s: f64, beacon: &str, range: f32) -> Vec<u8> {
    let mut b = vec![0, 1, 0, 0];
    let sec = t_s.floor();
    b.extend((sec as i32).to_le_bytes());
    b.extend((((t_s - sec) * 1e9).round() as u32).to_le_bytes());
    b.extend((beacon.len() as u32 + 1).to_le_bytes());
    b.extend(beacon.as_bytes());
    b.push(0);
    b.push(0); // radiation_type
    // float32s aligned to 4 from the start of the payload (after the 4-byte header)
    while (b.len() - 4) % 4 != 0 {
        b.push(0);
    }
    for v in [0.1f32, 0.5, 500.0, range] {
        b.extend(v.to_le_bytes());
    }
    b
}

fn bench(c: &mut Criterion) {
    let plaza1 = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/plaza/plaza1.toml");
    let full = Log::load(&plaza1).unwrap();
    let mut unit = stream_setup(&plaza1, |_| Ok::<_, String>(())).unwrap();
    // a started stream: plaza1's first 2000 items
    let (mut lines, mut t0) = feed_items(&mut unit, &full, 2000).unwrap();
    assert!(unit.session(0).started());
    // the range topic of a live description (sensor_msgs/Range: its fields are known)
    let dir = std::env::temp_dir().join(format!("onebeacon-bench-node-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let description = dir.join("live.toml");
    std::fs::write(
        &description,
        "name = \"bench\"\n[[source]]\nkind = \"range\"\ntopic = \"/usbl/range\"\ntype = \"sensor_msgs/msg/Range\"\n\
         [[estimators]]\nname = \"dr\"\nkind = \"dead-reckoning\"\n",
    )
    .unwrap();
    let live = Log::load_topics(&description).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    let mut topics = live.topics().unwrap();
    let seed = topics[0].seed();
    let names = unit.session(0).names.len();
    c.bench_function(&format!("node message: range, {names} estimators (decode, line, update, output line)"), |b| {
        b.iter_custom(|iters| {
            let batch: Vec<Vec<u8>> =
                (0..iters).map(|k| range_cdr(t0 + 0.01 * (k + 1) as f64, "beacon_1", 30.0)).collect();
            t0 += 0.01 * (iters + 1) as f64;
            let start = std::time::Instant::now();
            for bytes in &batch {
                let message = seed.decode(bytes).unwrap();
                for line in topics[0].lines(message, 0.0).unwrap() {
                    let text = line_json(&line).to_string();
                    black_box(lines.push(&mut unit, text.as_bytes(), false, |_, _| {}));
                }
            }
            start.elapsed()
        })
    });
    c.bench_function("node message: decode and line alone", |b| {
        let bytes = range_cdr(t0, "beacon_1", 30.0);
        b.iter(|| {
            let message = seed.decode(&bytes).unwrap();
            black_box(
                topics[0].lines(message, 0.0).unwrap().iter().map(|l| line_json(l).to_string()).collect::<Vec<_>>(),
            )
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
