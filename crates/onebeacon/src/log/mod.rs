//! Real logs: a log description (TOML) maps CSV files and columns to measurement kinds
//! ([`load`]: [`LogDescription`], and [`Log`], which reads its files as one time-ordered
//! stream of the session's items), with the fixed beacons, clocks, units, frames and
//! latitudes it may hold. A log description is also what `onebeacon stream` reads to set
//! up a vehicle's computer ([`stream_setup`]): a vehicle reads its configuration with
//! this crate alone. The replay, smoother and tuning that run over a log live in the
//! simulator crate.

mod cell;
mod csv;
mod error;
mod geodesy;
pub mod load;
mod merge;
#[cfg(feature = "ros2")]
pub mod ros2;
mod rows;
pub mod schema;
mod table;
#[cfg(any(test, feature = "test-util"))]
pub mod testing;
#[cfg(feature = "ros2")]
pub mod topics;
mod validate;

pub use error::LogError;
pub use load::{InitialStart, Log, LogDescription};
pub use rows::Dropped;

use crate::config::stream::{Beacon, StreamConfig};
use crate::vehicle::unit::Unit;

/// The vehicle's computer `onebeacon stream CONFIG` (and the Python `Navigator`) runs,
/// from a log description: its stream configuration with the fixed beacons of its files
/// ([`StreamConfig::unit`]), refused where `fits` refuses it
/// (the CLI: where its filters would not fit in the memory budget).
pub fn stream_setup<E: std::fmt::Display>(
    config: &std::path::Path,
    fits: impl FnOnce(&StreamConfig) -> Result<(), E>,
) -> Result<Unit, LogError> {
    let d = LogDescription::load(config)?;
    let base = config.parent().unwrap_or(std::path::Path::new("."));
    let beacons =
        d.fixed_beacons(base)?.into_iter().map(|(id, p)| Beacon { id, x_m: p.x, y_m: p.y, z_m: p.z }).collect();
    let file = config.display().to_string();
    let stream = d.stream_config(beacons);
    fits(&stream).map_err(|e| LogError::File { file: file.clone(), message: e.to_string() })?;
    stream.unit().map_err(|v| LogError::File { file, message: v.to_string() })
}

/// `unit` fed the first `items` items of `log` as stream lines (a started stream, for a
/// benchmark of the next line): the lines read so far and the last item's time.
pub fn feed_items(unit: &mut Unit, log: &Log, items: usize) -> Result<(crate::io::stream::Lines, f64), LogError> {
    let mut lines = crate::io::stream::Lines::default();
    let mut t0 = 0.0;
    for item in log.items()?.take(items) {
        let item = item?;
        t0 = item.t_s;
        lines.push(unit, crate::io::jsonl::item_json(&item).to_string().as_bytes(), false, |_, _| {});
    }
    Ok((lines, t0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn plaza1() -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/plaza/plaza1.toml")
    }

    /// A vehicle sets up `stream`'s computer from a log description with this crate
    /// alone: plaza1's beacons come from its CSV file (read here as text, independently),
    /// its estimators are the description's (read here by the toml crate), in order.
    #[test]
    fn a_stream_is_set_up_from_a_log_description_without_the_simulator() {
        let unit = stream_setup(&plaza1(), |_| Ok::<_, String>(())).unwrap();
        let csv = std::fs::read_to_string(plaza1().with_file_name("plaza1_beacons.csv")).unwrap();
        let beacons: Vec<(u32, f64, f64)> = csv
            .lines()
            .skip(1)
            .map(|l| {
                let f: Vec<&str> = l.split(',').collect();
                (f[0].parse().unwrap(), f[1].parse().unwrap(), f[2].parse().unwrap())
            })
            .collect();
        assert_eq!(unit.fixed.len(), beacons.len());
        for (id, x, y) in beacons {
            assert_eq!((unit.fixed[&id].x, unit.fixed[&id].y, unit.fixed[&id].z), (x, y, 0.0), "beacon {id}");
        }
        let toml: toml::Table = toml::from_str(&std::fs::read_to_string(plaza1()).unwrap()).unwrap();
        let names: Vec<&str> =
            toml["estimators"].as_array().unwrap().iter().map(|e| e["name"].as_str().unwrap()).collect();
        assert_eq!(unit.sessions().len(), 1);
        assert_eq!(unit.session(0).names, names);
        assert_eq!(unit.frame, crate::geo::Frame::Enu);
    }

    /// What `fits` refuses is one line naming the file; a missing file is named too.
    #[test]
    fn a_refused_setup_names_the_file() {
        let e = stream_setup(&plaza1(), |_| Err("needs 9 GiB, 1 GiB available")).unwrap_err().to_string();
        assert!(e.ends_with("plaza1.toml: needs 9 GiB, 1 GiB available"), "{e}");
        let e = stream_setup(&plaza1().with_file_name("nope.toml"), |_| Ok::<_, String>(())).unwrap_err().to_string();
        assert!(e.contains("nope.toml") && e.contains("cannot open"), "{e}");
    }
}
