//! `onebeacon sea-fit`: the sea of a log, fitted to the simulator's error models, written
//! as a `[sea]` table with each value's source and interval.

use crate::BadInput;
use crate::output::Staging;
use anyhow::Result;
use onebeacon::log::Log;
use onebeacon_sim::seafit::{SeaFitError, SeaFitOptions, fit};
use std::path::{Path, PathBuf};

/// What `sea-fit` is asked besides the log.
pub struct SeaFitArgs {
    pub beacons: Option<Vec<u32>>,
    pub window_s: f64,
    pub out: Option<PathBuf>,
    pub json: bool,
}

/// `onebeacon sea-fit LOG.toml [--beacons 1,2] [--window-s 60] [--out DIR] [--json]`:
/// writes sea.toml and sea-fit.json in DIR, prints the table (or the JSON).
pub fn sea_fit(path: &Path, a: SeaFitArgs) -> Result<()> {
    if !(a.window_s.is_finite() && a.window_s > 0.0) {
        return Err(BadInput(format!("--window-s {}: must be a number of seconds > 0", a.window_s)).into());
    }
    let log = Log::load(path)?;
    crate::budget().check_replay(&log, false).map_err(|e| BadInput(e.to_string()))?;
    let beacons = crate::replay::beacon_filter(a.beacons, &log.beacon_ids())?;
    let name = &log.description.name;
    let dir = a.out.unwrap_or_else(|| PathBuf::from("out").join(format!("{name}-sea")));
    let staging = Staging::new(&dir, &log.files())?;
    let started = std::time::Instant::now();
    let steps = beacons.as_ref().map_or(log.beacon_ids().len(), |b| b.len()) as u64 + 2;
    let bar = crate::progress::Progress::new(steps, "steps", format!("fitting the sea of {name}"));
    let opts = SeaFitOptions { beacons, window_s: a.window_s };
    let fitted = fit(&log, &opts, |step| {
        bar.set_message(format!("{name}: {step}"));
        bar.inc(1);
    })
    .map_err(|e| match e {
        SeaFitError::Nothing(_) => anyhow::Error::from(BadInput(format!("{}: {e}", path.display()))),
        e => e.into(),
    })?;
    bar.finish();
    let wall_s = started.elapsed().as_secs_f64();
    let command = format!("onebeacon sea-fit {}", path.display());
    let text = fitted.to_toml(&command);
    staging.write("sea.toml", text.as_bytes())?;
    let mut summary = fitted.to_json();
    summary["log"] = name.clone().into();
    summary["wall_s"] = wall_s.into();
    staging.write("sea-fit.json", serde_json::to_string_pretty(&summary)?.as_bytes())?;
    let files = staging.commit()?;
    if a.json {
        outln!("{summary}");
        return Ok(());
    }
    outln!("{text}");
    outln!(
        "# fitted in {wall_s:.1} s; written: {}",
        files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(", ")
    );
    Ok(())
}
