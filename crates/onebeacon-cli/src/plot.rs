//! PNG plots with plotters and an embedded font (no system font libraries needed).

use anyhow::{Result, anyhow};
use onebeacon_sim::Scenario;
use onebeacon_sim::montecarlo::McResult;
use onebeacon_sim::run::RunOutput;
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};
use std::path::Path;
use std::sync::Once;

const FONT: &str = "sans-serif";
const PALETTE: [RGBColor; 6] = [
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // the bytes are a valid TrueType font shipped by the dejavu crate
        let _ = register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
        let _ = register_font(FONT, FontStyle::Bold, dejavu::sans::bold());
    });
}

fn plot_err<E: std::fmt::Debug>(what: &str) -> impl FnOnce(E) -> anyhow::Error + '_ {
    move |e| anyhow!("cannot draw {what}: {e:?}")
}

/// Range of values with a margin, never empty.
fn span(values: impl Iterator<Item = f64>, margin: f64) -> (f64, f64) {
    let (lo, hi) = values.filter(|v| v.is_finite()).fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    if lo > hi {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * margin).max(1e-3);
    (lo - pad, hi + pad)
}

/// Top view: truth, every estimate, the beacon. East to the right, north up.
pub fn top_view(path: &Path, s: &Scenario, out: &RunOutput) -> Result<()> {
    register_fonts();
    let beacon = s.beacon_ned_m();
    let traj = &out.trajectory;
    let norths =
        traj.iter().map(|r| r.truth.pos.x).chain(traj.iter().flat_map(|r| r.estimates.iter().map(|e| e.pos.x)));
    let easts = traj.iter().map(|r| r.truth.pos.y).chain(traj.iter().flat_map(|r| r.estimates.iter().map(|e| e.pos.y)));
    let (n0, n1) = span(norths.chain([beacon.x]), 0.05);
    let (e0, e1) = span(easts.chain([beacon.y]), 0.05);
    // equal scale on both axes
    let (w, h) = (1200u32, 800u32);
    let scale = ((e1 - e0) / (w - 120) as f64).max((n1 - n0) / (h - 120) as f64);
    let (ec, nc) = ((e0 + e1) / 2.0, (n0 + n1) / 2.0);
    let (he, hn) = (scale * (w - 120) as f64 / 2.0, scale * (h - 120) as f64 / 2.0);

    let root = BitMapBackend::new(path, (w, h)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err("top view"))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{}: top view (seed run, T_com {} s)", s.name, s.comms.t_com_s), (FONT, 24))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(ec - he..ec + he, nc - hn..nc + hn)
        .map_err(plot_err("top view"))?;
    chart
        .configure_mesh()
        .x_desc("east (m)")
        .y_desc("north (m)")
        .label_style((FONT, 16))
        .draw()
        .map_err(plot_err("top view"))?;
    chart
        .draw_series(LineSeries::new(traj.iter().map(|r| (r.truth.pos.y, r.truth.pos.x)), BLACK.stroke_width(2)))
        .map_err(plot_err("top view"))?
        .label("truth")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
    for (i, e) in s.estimators.iter().enumerate() {
        let c = colour(i);
        chart
            .draw_series(LineSeries::new(
                traj.iter().map(|r| (r.estimates[i].pos.y, r.estimates[i].pos.x)),
                c.stroke_width(1),
            ))
            .map_err(plot_err("top view"))?
            .label(e.name())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
    }
    chart
        .draw_series(std::iter::once(TriangleMarker::new((beacon.y, beacon.x), 9, BLUE.filled())))
        .map_err(plot_err("top view"))?
        .label("beacon")
        .legend(|(x, y)| TriangleMarker::new((x + 10, y), 6, BLUE.filled()));
    if let Some(first) = traj.first() {
        chart
            .draw_series(std::iter::once(Circle::new((first.truth.pos.y, first.truth.pos.x), 5, BLACK.filled())))
            .map_err(plot_err("top view"))?
            .label("start")
            .legend(|(x, y)| Circle::new((x + 10, y), 4, BLACK.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 16))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(plot_err("top view"))?;
    root.present().map_err(plot_err("top view"))?;
    Ok(())
}

/// Horizontal position error versus time, one line per estimator, with its 2-sigma
/// bound (root of the trace of the position covariance, times 2) dashed.
pub fn error_vs_time(path: &Path, s: &Scenario, out: &RunOutput) -> Result<()> {
    register_fonts();
    let traj = &out.trajectory;
    let t1 = traj.last().map(|r| r.t_s).unwrap_or(1.0).max(1e-3);
    let sigma2 = |e: &onebeacon_sim::run::Estimate| 2.0 * e.sigma_pos.norm();
    let (_, ymax) = span(traj.iter().flat_map(|r| r.estimates.iter().flat_map(|e| [e.error_m, sigma2(e)])), 0.05);
    let root = BitMapBackend::new(path, (1200, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err("error plot"))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{}: position error (solid) and 2-sigma bound (thin)", s.name), (FONT, 24))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t1, 0.0..ymax.max(0.01))
        .map_err(plot_err("error plot"))?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc("horizontal error (m)")
        .label_style((FONT, 16))
        .draw()
        .map_err(plot_err("error plot"))?;
    for (i, e) in s.estimators.iter().enumerate() {
        let c = colour(i);
        chart
            .draw_series(LineSeries::new(traj.iter().map(|r| (r.t_s, r.estimates[i].error_m)), c.stroke_width(2)))
            .map_err(plot_err("error plot"))?
            .label(e.name())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        chart
            .draw_series(LineSeries::new(
                traj.iter().map(|r| (r.t_s, sigma2(&r.estimates[i]))),
                c.mix(0.5).stroke_width(1),
            ))
            .map_err(plot_err("error plot"))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 16))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(plot_err("error plot"))?;
    root.present().map_err(plot_err("error plot"))?;
    Ok(())
}

/// Monte Carlo: mean error (inliers) and RMSE versus the first swept value.
pub fn mc_errors(path: &Path, s: &Scenario, r: &McResult) -> Result<()> {
    register_fonts();
    let xs: Vec<f64> = r.cells.iter().map(|c| c.cell.values()[0].1).collect();
    let key = r.cells.first().map(|c| c.cell.values()[0].0).unwrap_or("cell");
    let (x0, x1) = span(xs.iter().copied(), 0.05);
    let (_, ymax) =
        span(r.cells.iter().flat_map(|c| c.estimators.iter().flat_map(|(_, m)| [m.mean_error_m, m.rmse_m])), 0.1);
    let root = BitMapBackend::new(path, (1000, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err("mc plot"))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{}: {} runs per cell, mean error (solid) and RMSE (thin)", s.name, r.runs), (FONT, 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, 0.0..ymax.max(0.01))
        .map_err(plot_err("mc plot"))?;
    chart
        .configure_mesh()
        .x_desc(key)
        .y_desc("horizontal error (m)")
        .label_style((FONT, 16))
        .draw()
        .map_err(plot_err("mc plot"))?;
    for (i, e) in s.estimators.iter().enumerate() {
        let c = colour(i);
        let mean: Vec<(f64, f64)> =
            xs.iter().zip(&r.cells).map(|(&x, cell)| (x, cell.estimators[i].1.mean_error_m)).collect();
        let rmse: Vec<(f64, f64)> =
            xs.iter().zip(&r.cells).map(|(&x, cell)| (x, cell.estimators[i].1.rmse_m)).collect();
        chart
            .draw_series(LineSeries::new(mean.clone(), c.stroke_width(2)))
            .map_err(plot_err("mc plot"))?
            .label(e.name())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        chart.draw_series(mean.iter().map(|&p| Circle::new(p, 4, c.filled()))).map_err(plot_err("mc plot"))?;
        chart.draw_series(LineSeries::new(rmse, c.mix(0.6).stroke_width(1))).map_err(plot_err("mc plot"))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 16))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(plot_err("mc plot"))?;
    root.present().map_err(plot_err("mc plot"))?;
    Ok(())
}
