//! Tables, CSV and JSON of runs and Monte Carlo results.

use anyhow::Result;
use onebeacon_sim::Scenario;
use onebeacon_sim::json;
use onebeacon_sim::montecarlo::McResult;
use onebeacon_sim::run::trajectory;
use onebeacon_sim::run::{RunOutput, StepRecord};
use onebeacon_sim::scenario::{Cell, MovingBeaconCell};
use std::fmt::Write;

/// trajectory.csv: one row per step with the truth of every vehicle (`vehicles`; its
/// columns prefixed with its name when there are several) and every track's estimate
/// (`names`, in the records' order), standard deviations, error and NEES.
pub fn trajectory_csv(vehicles: &[String], names: &[String], trajectory: &[StepRecord]) -> Result<Vec<u8>> {
    let mut w = TrajectoryWriter::new(Vec::new(), vehicles, names)?;
    for r in trajectory {
        w.write(r)?;
    }
    w.finish()
}

/// trajectory.csv written row by row as the steps come ([`trajectory_csv`]).
pub struct TrajectoryWriter<W: std::io::Write> {
    w: csv::Writer<W>,
    formats: Vec<Format>,
}

/// How a trajectory.csv column is written.
enum Format {
    Time,
    Flag,
    Degrees,
    Speed,
    Metres,
}

impl<W: std::io::Write> TrajectoryWriter<W> {
    /// Writes the header ([`trajectory::header`]).
    pub fn new(out: W, vehicles: &[String], names: &[String]) -> Result<Self> {
        let mut w = csv::Writer::from_writer(out);
        let header = trajectory::header(vehicles, names);
        w.write_record(&header)?;
        // t_s to 0.01 s, headings to 0.001 deg, the frame flag as 0/1, the rest to 0.1 mm
        // (a speed the estimator does not have left empty)
        let formats = header
            .iter()
            .map(|h| match h.as_str() {
                "t_s" => Format::Time,
                "frame" => Format::Flag,
                h if h.ends_with("_deg") => Format::Degrees,
                h if h.ends_with("speed_m_s") => Format::Speed,
                _ => Format::Metres,
            })
            .collect();
        Ok(Self { w, formats })
    }

    /// Writes one step's row.
    pub fn write(&mut self, r: &StepRecord) -> Result<()> {
        let row = trajectory::values(r).into_iter().zip(&self.formats).map(|(v, f)| match f {
            Format::Time => format!("{v:.2}"),
            Format::Flag => format!("{v}"),
            Format::Degrees => format!("{v:.3}"),
            Format::Speed if v.is_nan() => String::new(),
            Format::Speed | Format::Metres => format!("{v:.4}"),
        });
        self.w.write_record(row)?;
        Ok(())
    }

    /// Flushes and returns the writer.
    pub fn finish(self) -> Result<W> {
        self.w.into_inner().map_err(|e| anyhow::anyhow!("{}", e.error()))
    }
}

/// summary.json of one run.
pub fn run_summary_json(s: &Scenario, seed: u64, run: u64, cell: &Cell, out: &RunOutput) -> String {
    serde_json::to_string_pretty(&json::run_summary(s, seed, run, cell, out)).expect("serialisable") + "\n"
}

/// The table printed by `run`.
pub fn run_table(s: &Scenario, seed: u64, run: u64, cell: &Cell, out: &RunOutput) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "{}: seed {seed}, run {run}, {}: {} m in {:.0} s, {} acoustic measurements",
        s.name(),
        cell.label(),
        out.distance_m.iter().map(|d| format!("{d:.0}")).collect::<Vec<_>>().join(" + "),
        s.duration_s(),
        out.frames_decoded
    );
    let _ = writeln!(
        t,
        "{:<24} {:>10} {:>9} {:>9} {:>10} {:>9}",
        "estimator", "mean_err_m", "rmse_m", "max_m", "final_m", "nees"
    );
    for (name, m) in s.track_labels().iter().zip(&out.metrics) {
        let _ = writeln!(
            t,
            "{:<24} {:>10.3} {:>9.3} {:>9.3} {:>10.3} {:>9.2}",
            name,
            m.mean_error_m,
            m.mse_m2.sqrt(),
            m.max_error_m,
            m.final_error_m,
            m.nees_mean
        );
    }
    t
}

/// The `mc --json` object ([`json::mc`]).
pub fn mc_json(s: &Scenario, r: &McResult, wall_s: f64) -> String {
    serde_json::to_string(&json::mc(s, r, wall_s)).expect("serialisable")
}

/// For moving-beacon sweeps, sousa's layout (Tables 4.1, 4.2): per guidance and
/// vehicle, rows of depth, columns of path, "mean (variance) [RMSE/PCRB]" of the
/// vehicle's first estimator.
fn depth_by_path_tables(s: &Scenario, r: &McResult) -> String {
    let mut t = String::new();
    let cells: Vec<(&MovingBeaconCell, &onebeacon_sim::montecarlo::CellResult)> = r
        .cells
        .iter()
        .filter_map(|c| match &c.cell {
            Cell::MovingBeacon(m) => Some((m, c)),
            _ => None,
        })
        .collect();
    let mut paths = Vec::new();
    let mut depths: Vec<f64> = Vec::new();
    let mut guidances = Vec::new();
    for (m, _) in &cells {
        if !paths.contains(&m.path) {
            paths.push(m.path);
        }
        if !depths.contains(&m.depth_m) {
            depths.push(m.depth_m);
        }
        if !guidances.contains(&m.guidance) {
            guidances.push(m.guidance);
        }
    }
    let tracks = s.tracks();
    let firsts: Vec<usize> =
        (0..s.vehicle_names().len()).filter_map(|v| tracks.iter().position(|t| t.vehicle_index == v)).collect();
    for g in guidances {
        for &first in &firsts {
            let track = &tracks[first];
            let _ = writeln!(t);
            let _ = writeln!(t, "guidance {}: {} mean error m (variance m^2) [RMSE/PCRB]", g.label(), track.label);
            let _ = write!(t, "{:>8}", "depth_m");
            for p in &paths {
                let _ = write!(t, " {:>26}", p.label());
            }
            let _ = writeln!(t);
            for &d in &depths {
                let _ = write!(t, "{d:>8}");
                for p in &paths {
                    let found = cells.iter().find(|(m, _)| m.path == *p && m.depth_m == d && m.guidance == g);
                    let text = match found {
                        Some((_, c)) => {
                            let e = &c.estimators[first].1;
                            let ratio = c
                                .pcrb(track.vehicle_index)
                                .map(|b| format!("{:.2}", e.rmse_m / b))
                                .unwrap_or_else(|| "-".into());
                            format!("{:.3} ({:.3}) [{ratio}]", e.mean_error_m, e.error_variance_m2)
                        }
                        None => "-".into(),
                    };
                    let _ = write!(t, " {text:>26}");
                }
                let _ = writeln!(t);
            }
        }
    }
    t
}

/// The `mc` tables: mean error (outliers) of every estimator side by side, as
/// garin2024 Table 4, then every statistic per estimator, as Table 3; for moving-beacon
/// sweeps also sousa's depth-by-path layout.
pub fn mc_table(s: &Scenario, r: &McResult, wall_s: f64) -> String {
    let mut t = String::new();
    let _ = writeln!(t, "{}: {} runs per cell, seed {}, {:.2} s", s.name(), r.runs, r.seed, wall_s);
    let _ = writeln!(
        t,
        "(outliers: runs whose mean error is beyond 1.5 IQR of the quartiles; left out of every statistic but nees_all)"
    );
    let _ = writeln!(t);
    let _ = writeln!(t, "Mean positioning error in m (outliers)");
    let width = r.cells.iter().map(|c| c.cell.label().len()).max().unwrap_or(5).max(5);
    let _ = write!(t, "{:<width$}", "sweep");
    for name in s.track_labels() {
        let _ = write!(t, " {:>18}", name);
    }
    let _ = writeln!(t);
    for c in &r.cells {
        let _ = write!(t, "{:<width$}", c.cell.label());
        for (_, m) in &c.estimators {
            let _ = write!(t, " {:>18}", format!("{:.4} ({})", m.mean_error_m, m.outliers));
        }
        let _ = writeln!(t);
    }
    let _ = writeln!(t);
    let _ = writeln!(
        t,
        "{:<width$} {:<24} {:>10} {:>5} {:>10} {:>8} {:>9} {:>10} {:>8} {:>15} {:>10} {:>9} {:>6}",
        "sweep",
        "estimator",
        "mean_m",
        "out",
        "var_m2",
        "rmse_m",
        "etd_max%",
        "etd_mean%",
        "nees",
        "nees_band95",
        "nees_all",
        "pcrb_m",
        "h2/h1"
    );
    for c in &r.cells {
        for (track, m) in &c.estimators {
            let _ = writeln!(
                t,
                "{:<width$} {:<24} {:>10.4} {:>5} {:>10.4} {:>8.3} {:>9.4} {:>10.4} {:>8.2} {:>15} {:>10.1} {:>9} {:>6.2}",
                c.cell.label(),
                track.label,
                m.mean_error_m,
                m.outliers,
                m.error_variance_m2,
                m.rmse_m,
                m.etd_max_pct,
                m.etd_mean_pct,
                m.nees_mean,
                format!("{:.2}-{:.2}", m.nees_band[0], m.nees_band[1]),
                m.nees_mean_all_runs,
                c.pcrb(track.vehicle_index).map(|p| format!("{p:.3}")).unwrap_or_else(|| "-".into()),
                m.mean_error_second_half_m / m.mean_error_first_half_m,
            );
        }
    }
    if matches!(s, Scenario::MovingBeacon(_)) {
        t.push_str(&depth_by_path_tables(s, r));
    }
    t
}
