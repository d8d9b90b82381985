//! Plots with plotters and an embedded font (no system font libraries needed): each
//! one as a PNG and, beside it, an SVG for print ([`both`]).

use anyhow::Result;
use nalgebra::Vector3;
use onebeacon::guidance::Metric;
use onebeacon_sim::Scenario;
use onebeacon_sim::montecarlo::{CellResult, McResult};
use onebeacon_sim::run::{BearingSnapshot, BeliefSnapshot, Estimate, FimSnapshot, StepRecord};
use onebeacon_sim::scenario::SweepValue;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};
use std::ops::Range;
use std::path::Path;
use std::sync::Once;

const FONT: &str = "sans-serif";
/// The ten "tab10" colours, red first: distinct for up to ten estimators.
const PALETTE: [RGBColor; 10] = [
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;
type Area<DB> = DrawingArea<DB, plotters::coord::Shift>;

/// Draws a plot twice: as the PNG `path` and as an SVG of the same name beside it.
macro_rules! both {
    ($path:expr, $size:expr, |$root:ident| $draw:expr) => {{
        let (path, size): (&Path, (u32, u32)) = ($path, $size);
        {
            let $root = BitMapBackend::new(path, size).into_drawing_area();
            $draw?;
        }
        let svg = path.with_extension("svg");
        let $root = SVGBackend::new(&svg, size).into_drawing_area();
        $draw
    }};
}

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

/// Range of values with a margin, never empty.
fn span(values: impl Iterator<Item = f64>, margin: f64) -> (f64, f64) {
    let (lo, hi) = values.filter(|v| v.is_finite()).fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    if lo > hi {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * margin).max(1e-3);
    (lo - pad, hi + pad)
}

/// The largest magnitude an axis reaches, m or s: beyond it (a diverged filter's 1e308,
/// an overflow) plotters' tick search does not end; what lies beyond is clipped.
const AXIS_LIMIT: f64 = 1e12;

/// An axis range that can be drawn: finite, within [`AXIS_LIMIT`], never empty.
fn drawable(r: Range<f64>) -> Range<f64> {
    let clamp = |v: f64| if v.is_nan() { 0.0 } else { v.clamp(-AXIS_LIMIT, AXIS_LIMIT) };
    let (lo, hi) = (clamp(r.start), clamp(r.end));
    if hi > lo { lo..hi } else { lo..lo + 1.0 }
}

/// A white canvas with a titled, labelled chart of the given ranges (made drawable).
fn chart<'a, DB: DrawingBackend + 'a>(
    root: &Area<DB>,
    caption: &str,
    x: Range<f64>,
    y: Range<f64>,
    labels: (&str, &str),
) -> Result<Chart<'a, DB>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(root)
        .caption(caption, (FONT, 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(drawable(x), drawable(y))?;
    chart.configure_mesh().x_desc(labels.0).y_desc(labels.1).label_style((FONT, 16)).draw()?;
    Ok(chart)
}

fn legend<'a, DB: DrawingBackend + 'a>(chart: &mut Chart<'a, DB>, position: SeriesLabelPosition) -> Result<()>
where
    DB::ErrorType: 'static,
{
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 16))
        .position(position)
        .draw()?;
    Ok(())
}

/// A line series with a legend entry.
fn line<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    points: impl IntoIterator<Item = (f64, f64)>,
    style: ShapeStyle,
    label: Option<&str>,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    styled_line(chart, points, style, false, label)
}

/// A solid or dashed line series, thinned ([`decimated`]), with a legend entry drawn
/// the same way.
fn styled_line<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    points: impl IntoIterator<Item = (f64, f64)>,
    style: ShapeStyle,
    dashed: bool,
    label: Option<&str>,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let points = decimated(points);
    let series = if dashed {
        chart.draw_series(DashedLineSeries::new(points, 8, 5, style))?
    } else {
        chart.draw_series(LineSeries::new(points, style))?
    };
    if let Some(label) = label {
        let gap = if dashed { 5 } else { 0 };
        series.label(label).legend(move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (8, 0)], style)
                + PathElement::new(vec![(8 + gap, 0), (20, 0)], style)
        });
    }
    Ok(())
}

/// Most points of one drawn line: a 1200-pixel plot shows no more, and a thick line of
/// many sub-pixel segments renders broken.
const MAX_LINE_POINTS: usize = 3000;

/// The finite points of a line, evenly thinned to at most [`MAX_LINE_POINTS`] (the last
/// one kept).
fn decimated(points: impl IntoIterator<Item = (f64, f64)>) -> Vec<(f64, f64)> {
    let all: Vec<(f64, f64)> = points.into_iter().filter(|(x, y)| x.is_finite() && y.is_finite()).collect();
    let stride = all.len().div_ceil(MAX_LINE_POINTS).max(1);
    let mut kept: Vec<(f64, f64)> = all.iter().step_by(stride).copied().collect();
    if let Some(&last) = all.last()
        && kept.last() != Some(&last)
    {
        kept.push(last);
    }
    kept
}

/// Estimator `i`'s line: its own colour, solid for even `i` and dashed for odd, so that
/// estimators whose tracks coincide stay visible on top of each other.
fn estimator_line<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    i: usize,
    points: impl IntoIterator<Item = (f64, f64)>,
    width: u32,
    label: Option<&str>,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let style = colour(i).stroke_width(width);
    styled_line(chart, points, style, !i.is_multiple_of(2), label)
}

/// A vertical colour bar for a heatmap from `lo` to `hi` (viridis), with its label, in
/// `area`.
fn colour_bar<DB: DrawingBackend>(area: &Area<DB>, lo: f64, hi: f64, label: &str) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let Range { start: lo, end: hi } = drawable(lo..hi);
    let mut bar = ChartBuilder::on(area)
        .margin_top(60)
        .margin_bottom(60)
        .margin_right(10)
        .y_label_area_size(85)
        .build_cartesian_2d(0.0..1.0, lo..hi)?;
    bar.configure_mesh()
        .disable_x_mesh()
        .disable_x_axis()
        .y_desc(label)
        .y_label_formatter(&|v| {
            if *v == 0.0 || (0.01..1000.0).contains(&v.abs()) { format!("{v:.3}") } else { format!("{v:.2e}") }
        })
        .label_style((FONT, 14))
        .draw()?;
    let n = 100;
    bar.draw_series((0..n).map(|k| {
        let (a, b) = (lo + (hi - lo) * k as f64 / n as f64, lo + (hi - lo) * (k + 1) as f64 / n as f64);
        Rectangle::new([(0.0, a), (1.0, b)], viridis((k as f64 + 0.5) / n as f64).filled())
    }))?;
    Ok(())
}

/// The records a plot of a trajectory of any length needs: every record until there
/// are `2 * cap`, then every second one of those and of what follows, and so on, so at
/// most `2 * cap` evenly spaced records are held.
pub struct Thinned {
    records: Vec<StepRecord>,
    cap: usize,
    stride: usize,
    seen: usize,
}

impl Thinned {
    pub fn new(cap: usize) -> Self {
        Self { records: Vec::new(), cap: cap.max(1), stride: 1, seen: 0 }
    }

    pub fn push(&mut self, r: StepRecord) {
        if self.seen.is_multiple_of(self.stride) {
            self.records.push(r);
            if self.records.len() >= 2 * self.cap {
                let mut k = 0;
                self.records.retain(|_| {
                    k += 1;
                    k % 2 == 1
                });
                self.stride *= 2;
            }
        }
        self.seen += 1;
    }

    pub fn records(&self) -> &[StepRecord] {
        &self.records
    }
}

/// Top view: every vehicle's truth (`vehicles`), every estimate (`names`, in the
/// records' order), the beacons: `fixed_beacons` when given (replayed logs), else the
/// records' beacon (its track when it moves). East to the right, north up, equal scales.
pub fn top_view(
    path: &Path,
    vehicles: &[String],
    names: &[String],
    title: &str,
    traj: &[StepRecord],
    fixed_beacons: Option<&[(u32, Vector3<f64>)]>,
) -> Result<()> {
    register_fonts();
    let fixed: Vec<Vector3<f64>> = fixed_beacons.unwrap_or(&[]).iter().map(|b| b.1).collect();
    let all = || {
        traj.iter()
            .flat_map(|r| {
                let beacon = if fixed_beacons.is_none() { Some(r.beacon) } else { None };
                r.truth.iter().map(|t| t.pos).chain(beacon).chain(r.estimates.iter().map(|e| e.pos))
            })
            .chain(fixed.iter().copied())
    };
    let (n0, n1) = span(all().map(|p| p.x), 0.05);
    let (e0, e1) = span(all().map(|p| p.y), 0.05);
    let (w, h) = (1200u32, 800u32);
    let scale = ((e1 - e0) / (w - 120) as f64).max((n1 - n0) / (h - 120) as f64);
    let (ec, nc) = ((e0 + e1) / 2.0, (n0 + n1) / 2.0);
    let (he, hn) = (scale * (w - 120) as f64 / 2.0, scale * (h - 120) as f64 / 2.0);

    both!(path, (w, h), |root| (|| -> Result<()> {
        let mut chart =
            chart(&root, &format!("{title}: top view"), ec - he..ec + he, nc - hn..nc + hn, ("east (m)", "north (m)"))?;
        let moving = fixed_beacons.is_none() && traj.windows(2).any(|w| (w[1].beacon - w[0].beacon).norm() > 1e-9);
        if moving {
            line(
                &mut chart,
                traj.iter().map(|r| (r.beacon.y, r.beacon.x)),
                BLUE.mix(0.25).stroke_width(1),
                Some("beacon (ASV)"),
            )?;
        }
        for (v, name) in vehicles.iter().enumerate() {
            let truth = traj.iter().map(|r| r.truth[v].pos).filter(|p| p.x.is_finite());
            let label = if vehicles.len() > 1 { format!("truth {name}") } else { "truth".into() };
            let style = BLACK.mix(1.0 - 0.35 * v.min(2) as f64).stroke_width(3);
            line(&mut chart, truth.map(|p| (p.y, p.x)), style, Some(&label))?;
        }
        for (i, name) in names.iter().enumerate() {
            let points = traj.iter().map(|r| (r.estimates[i].pos.y, r.estimates[i].pos.x));
            estimator_line(&mut chart, i, points, 2, Some(name))?;
        }
        let beacons: Vec<Vector3<f64>> = match fixed_beacons {
            Some(_) => fixed.clone(),
            None => traj.first().map(|r| r.beacon).into_iter().collect(),
        };
        for (id, b) in fixed_beacons.unwrap_or(&[]) {
            let label = EmptyElement::at((b.y, b.x)) + Text::new(format!("{id}"), (9, -22), (FONT, 18).into_font());
            chart.draw_series(std::iter::once(label))?;
        }
        if !beacons.is_empty() {
            chart
                .draw_series(beacons.iter().map(|b| TriangleMarker::new((b.y, b.x), 9, BLUE.filled())))?
                .label(if moving { "beacon start" } else { "beacon" })
                .legend(|(x, y)| TriangleMarker::new((x + 10, y), 6, BLUE.filled()));
        }
        let starts: Vec<Vector3<f64>> =
            (0..vehicles.len()).filter_map(|v| traj.iter().map(|r| r.truth[v].pos).find(|p| p.x.is_finite())).collect();
        if !starts.is_empty() {
            chart
                .draw_series(starts.iter().map(|p| Circle::new((p.y, p.x), 5, BLACK.filled())))?
                .label("start")
                .legend(|(x, y)| Circle::new((x + 10, y), 4, BLACK.filled()));
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present()?;
        Ok(())
    })())
}

/// Horizontal position error versus time, one line per estimator, with its 2-sigma
/// bound (twice the root of the trace of the position covariance) as a thin line.
pub fn error_vs_time(path: &Path, names: &[String], title: &str, traj: &[StepRecord]) -> Result<()> {
    register_fonts();
    let t0 = traj.first().map(|r| r.t_s).unwrap_or(0.0);
    let t1 = traj.last().map(|r| r.t_s - t0).unwrap_or(1.0).max(1e-3);
    let sigma2 = |e: &Estimate| 2.0 * e.sigma_pos.norm();
    let (_, ymax) = span(traj.iter().flat_map(|r| r.estimates.iter().flat_map(|e| [e.error_m, sigma2(e)])), 0.05);
    both!(path, (1200, 600), |root| (|| -> Result<()> {
        let start = if t0 == 0.0 { String::new() } else { format!(" from t = {t0:.1} s") };
        let caption = format!("{title}: position error (thick), 2-sigma bound (thin){start}");
        let x_desc = "elapsed time (s)";
        let mut chart = chart(&root, &caption, 0.0..t1, 0.0..ymax.max(0.01), (x_desc, "horizontal error (m)"))?;
        for (i, name) in names.iter().enumerate() {
            let c = colour(i);
            estimator_line(&mut chart, i, traj.iter().map(|r| (r.t_s - t0, r.estimates[i].error_m)), 2, Some(name))?;
            line(
                &mut chart,
                traj.iter().map(|r| (r.t_s - t0, sigma2(&r.estimates[i]))),
                c.mix(0.5).stroke_width(1),
                None,
            )?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
        root.present()?;
        Ok(())
    })())
}

/// The dynamic vehicles' autopilots: commanded (dashed) against actual (solid) heading,
/// surge speed and depth versus time, one colour per vehicle (the surface vehicle as
/// `asv`; depth for the underwater ones). Headings are unwrapped, each command drawn on
/// the turn of the heading it was given to.
pub fn autopilots(path: &Path, vehicles: &[String], title: &str, traj: &[StepRecord]) -> Result<()> {
    register_fonts();
    let mut keys: Vec<Option<usize>> = Vec::new();
    for p in traj.iter().flat_map(|r| &r.pilots) {
        if !keys.contains(&p.vehicle) {
            keys.push(p.vehicle);
        }
    }
    let label = |k: Option<usize>| k.and_then(|v| vehicles.get(v).cloned()).unwrap_or_else(|| "asv".into());
    // per vehicle: (t, commanded, actual) of heading (deg, unwrapped), speed, depth
    type Series = Vec<(f64, f64, f64)>;
    let series: Vec<[Series; 3]> = keys
        .iter()
        .map(|&k| {
            let (mut heading, mut speed, mut depth) = (Vec::new(), Vec::new(), Vec::new());
            let mut unwrapped: Option<f64> = None;
            for r in traj {
                let Some(p) = r.pilots.iter().find(|p| p.vehicle == k) else { continue };
                let actual = match unwrapped {
                    None => p.heading_rad,
                    Some(last) => last + onebeacon::geo::wrap_angle(p.heading_rad - last),
                };
                unwrapped = Some(actual);
                let commanded = actual + onebeacon::geo::wrap_angle(p.command.heading_rad - p.heading_rad);
                heading.push((r.t_s, commanded.to_degrees(), actual.to_degrees()));
                speed.push((r.t_s, p.command.speed_m_s, p.speed_m_s));
                if let Some(d) = p.command.depth_m {
                    depth.push((r.t_s, d, p.depth_m));
                }
            }
            [heading, speed, depth]
        })
        .collect();
    let t1 = traj.last().map_or(1.0, |r| r.t_s).max(1e-3);
    // (axis, legend word, the least span shown)
    let panels = [("heading (deg)", "heading", 10.0), ("surge speed (m/s)", "speed", 0.5), ("depth (m)", "depth", 1.0)];
    both!(path, (1200, 1100), |root| (|| -> Result<()> {
        root.fill(&WHITE)?;
        let (head, body) = root.split_vertically(40);
        head.draw(&Text::new(
            format!("{title}: autopilots, commanded (dashed) and actual (solid)"),
            (15, 10),
            (FONT, 22).into_font(),
        ))?;
        for (j, area) in body.split_evenly((3, 1)).iter().enumerate() {
            let all = series.iter().flat_map(|s| s[j].iter().flat_map(|&(_, c, a)| [c, a]));
            let (lo, hi) = span(all, 0.05);
            let (mid, half) = (0.5 * (lo + hi), (0.5 * (hi - lo)).max(0.5 * panels[j].2));
            let mut chart = chart(area, "", 0.0..t1, mid - half..mid + half, ("time (s)", panels[j].0))?;
            for (i, (s, &k)) in series.iter().zip(&keys).enumerate() {
                if s[j].is_empty() {
                    continue;
                }
                let c = colour(i);
                let name = format!("{} {}", label(k), panels[j].1);
                styled_line(&mut chart, s[j].iter().map(|&(t, cmd, _)| (t, cmd)), c.stroke_width(1), true, None)?;
                line(&mut chart, s[j].iter().map(|&(t, _, a)| (t, a)), c.stroke_width(2), Some(&name))?;
            }
            legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        }
        root.present()?;
        Ok(())
    })())
}

/// Monte Carlo: mean error (inliers) and RMSE versus the first numeric swept key. With
/// text keys too (path, guidance), one panel per value of the first text key and one
/// line per value of the others, for the first estimator, with the PCRB dashed where
/// known; otherwise one line per estimator.
pub fn mc_errors(path: &Path, s: &Scenario, r: &McResult) -> Result<()> {
    register_fonts();
    let Some(first) = r.cells.first() else { return Ok(()) };
    let values = first.cell.values();
    let x_key = values.iter().position(|(_, v)| matches!(v, SweepValue::Number(_))).unwrap_or(0);
    let text_keys: Vec<usize> = (0..values.len()).filter(|&k| matches!(values[k].1, SweepValue::Text(_))).collect();
    let x_of = |c: &CellResult| match c.cell.values()[x_key].1 {
        SweepValue::Number(x) => x,
        SweepValue::Text(_) => 0.0,
    };
    let text_of = |c: &CellResult, keys: &[usize]| {
        let v = c.cell.values();
        keys.iter().map(|&k| v[k].1.to_string()).collect::<Vec<_>>().join(" ")
    };
    // panels by the first text key
    let mut panels: Vec<String> = Vec::new();
    for c in &r.cells {
        let p = text_of(c, &text_keys[..text_keys.len().min(1)]);
        if !panels.contains(&p) {
            panels.push(p);
        }
    }
    let (x0, x1) = span(r.cells.iter().map(x_of), 0.05);
    let stats = r.cells.iter().flat_map(|c| c.estimators.iter().flat_map(|(_, m)| [m.mean_error_m, m.rmse_m]));
    let (_, ymax) = span(stats.chain(r.cells.iter().flat_map(|c| c.pcrb_rmse_m.iter().copied())), 0.1);
    let cols = if panels.len() > 1 { 2 } else { 1 };
    let rows = panels.len().div_ceil(cols);
    both!(path, (1000 * cols as u32, 600 * rows as u32), |root| (|| -> Result<()> {
        root.fill(&WHITE)?;
        let areas = root.split_evenly((rows, cols));
        let tracks = s.tracks();
        let names: Vec<String> = tracks.iter().map(|t| t.label.clone()).collect();
        for (panel, area) in panels.iter().zip(areas.iter()) {
            let cells: Vec<&CellResult> =
                r.cells.iter().filter(|c| text_of(c, &text_keys[..text_keys.len().min(1)]) == *panel).collect();
            let caption = if panel.is_empty() {
                format!("{}: {} runs per cell, mean error (thick), RMSE (thin)", s.name(), r.runs)
            } else {
                format!("{} {panel}: {} mean error (thick), RMSE (thin), PCRB (dashed)", s.name(), names[0])
            };
            let mut chart =
                chart(area, &caption, x0..x1, 0.0..ymax.max(0.01), (values[x_key].0, "horizontal error (m)"))?;
            // series: the remaining text keys, or the estimators
            let series: Vec<(String, usize)> = if text_keys.len() > 1 {
                let mut v: Vec<String> = Vec::new();
                for c in &cells {
                    let t = text_of(c, &text_keys[1..]);
                    if !v.contains(&t) {
                        v.push(t);
                    }
                }
                v.into_iter().map(|t| (t, 0)).collect()
            } else {
                names.iter().enumerate().map(|(i, n)| (n.clone(), i)).collect()
            };
            for (i, (label, est)) in series.iter().enumerate() {
                let c = colour(i);
                let mine: Vec<&&CellResult> = cells
                    .iter()
                    .filter(|cell| text_keys.len() <= 1 || text_of(cell, &text_keys[1..]) == *label)
                    .collect();
                let mean: Vec<(f64, f64)> =
                    mine.iter().map(|cell| (x_of(cell), cell.estimators[*est].1.mean_error_m)).collect();
                let rmse = mine.iter().map(|cell| (x_of(cell), cell.estimators[*est].1.rmse_m));
                estimator_line(&mut chart, i, mean.iter().copied(), 2, Some(label))?;
                chart.draw_series(mean.iter().map(|&p| Circle::new(p, 4, c.filled())))?;
                line(&mut chart, rmse, c.mix(0.6).stroke_width(1), None)?;
                let pcrb: Vec<(f64, f64)> = mine
                    .iter()
                    .filter_map(|cell| cell.pcrb(tracks[*est].vehicle_index).map(|p| (x_of(cell), p)))
                    .collect();
                if pcrb.len() > 1 {
                    styled_line(&mut chart, pcrb, c.mix(0.8).stroke_width(1), true, None)?;
                }
            }
            legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
        }
        root.present()?;
        Ok(())
    })())
}

/// A viridis-like colour for `v` in [0, 1].
fn viridis(v: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 5] =
        [(68.0, 1.0, 84.0), (59.0, 82.0, 139.0), (33.0, 145.0, 140.0), (94.0, 201.0, 98.0), (253.0, 231.0, 37.0)];
    let x = v.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |p: f64, q: f64| (p + (q - p) * f).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The guidance metric as a function of the beacon's next position at one ping (sousa
/// Fig. 3.5 and 3.7): colour from low (dark) to high (yellow), the reaching set as a
/// circle, the beacon's position, the vehicle's estimate (and its prediction for
/// approach B) and the chosen waypoint.
pub fn guidance_map(path: &Path, g: &FimSnapshot) -> Result<()> {
    register_fonts();
    let centre = g.target.xy();
    let half = ((g.previous - centre).norm() + g.reach_m).max(2.0 * g.reach_m) * 1.2;
    let (n0, e0) = (centre.x - half, centre.y - half);
    let cells = 160usize;
    let size = 2.0 * half / cells as f64;
    let mut values = vec![0.0; cells * cells];
    for i in 0..cells {
        for j in 0..cells {
            let p = nalgebra::Vector2::new(n0 + (i as f64 + 0.5) * size, e0 + (j as f64 + 0.5) * size);
            values[i * cells + j] = g.planner.metric_at(p, g.previous, &g.target, &g.target_next);
        }
    }
    let vmax = values.iter().cloned().fold(f64::MIN_POSITIVE, f64::max);
    both!(path, (950, 780), |root| (|| -> Result<()> {
        let metric = match g.planner.metric {
            Metric::ApproachA => "approach A (det FIM)",
            Metric::ApproachB => "approach B (det FIM now + next)",
        };
        let caption = format!("guidance metric, {metric}, ping at t = {:.0} s", g.t_s);
        root.fill(&WHITE)?;
        let (main, side) = root.split_horizontally(800);
        colour_bar(&side, 0.0, vmax, "metric")?;
        let root = main;
        let mut chart = chart(&root, &caption, e0..e0 + 2.0 * half, n0..n0 + 2.0 * half, ("east (m)", "north (m)"))?;
        chart.draw_series((0..cells).flat_map(|i| {
            let values = &values;
            (0..cells).map(move |j| {
                let (n, e) = (n0 + i as f64 * size, e0 + j as f64 * size);
                Rectangle::new([(e, n), (e + size, n + size)], viridis(values[i * cells + j] / vmax).filled())
            })
        }))?;
        let circle = (0..=180).map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 180.0;
            (g.previous.y + g.reach_m * a.sin(), g.previous.x + g.reach_m * a.cos())
        });
        line(&mut chart, circle, WHITE.stroke_width(2), Some("reaching set"))?;
        chart
            .draw_series(std::iter::once(TriangleMarker::new((g.previous.y, g.previous.x), 9, WHITE.filled())))?
            .label("beacon now")
            .legend(|(x, y)| TriangleMarker::new((x + 10, y), 6, BLACK.filled()));
        chart
            .draw_series(std::iter::once(Circle::new((g.target.y, g.target.x), 6, RED.filled())))?
            .label("vehicle estimate")
            .legend(|(x, y)| Circle::new((x + 10, y), 5, RED.filled()));
        if g.planner.metric == Metric::ApproachB {
            chart
                .draw_series(std::iter::once(Circle::new((g.target_next.y, g.target_next.x), 6, RED.stroke_width(2))))?
                .label("vehicle predicted")
                .legend(|(x, y)| Circle::new((x + 10, y), 5, RED.stroke_width(2)));
        }
        chart
            .draw_series(std::iter::once(Cross::new((g.waypoint.y, g.waypoint.x), 8, WHITE.stroke_width(3))))?
            .label("chosen waypoint")
            .legend(|(x, y)| Cross::new((x + 10, y), 6, BLACK.stroke_width(2)));
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present()?;
        Ok(())
    })())
}

/// The bearing planner's score over its half-annulus at one decision (hoff2024 eq.
/// 10-12): each candidate coloured by its score from low (dark) to high (yellow), the
/// ASV, the belief's shifted mean and the chosen waypoint.
pub fn bearing_map(path: &Path, g: &BearingSnapshot) -> Result<()> {
    register_fonts();
    let m = g.belief_mean.xy();
    let points = g.candidates.iter().map(|(p, _)| *p).chain([g.asv, m]);
    let half = points.map(|p| (p - m).abs().max()).fold(1.0f64, f64::max) * 1.15;
    let (lo, hi) = g.candidates.iter().fold((f64::MAX, f64::MIN), |(l, h), (_, v)| (l.min(*v), h.max(*v)));
    both!(path, (950, 780), |root| (|| -> Result<()> {
        let caption = format!("planner score (eq. 10), decision at t = {:.0} s", g.t_s);
        root.fill(&WHITE)?;
        let (main, side) = root.split_horizontally(800);
        colour_bar(&side, lo, hi, "score")?;
        let root = main;
        let mut chart =
            chart(&root, &caption, m.y - half..m.y + half, m.x - half..m.x + half, ("east (m)", "north (m)"))?;
        chart.draw_series(g.candidates.iter().map(|(p, v)| {
            let t = (v - lo) / (hi - lo).max(f64::MIN_POSITIVE);
            Circle::new((p.y, p.x), 6, viridis(t).filled())
        }))?;
        chart
            .draw_series(std::iter::once(TriangleMarker::new((g.asv.y, g.asv.x), 9, BLACK.filled())))?
            .label("ASV")
            .legend(|(x, y)| TriangleMarker::new((x + 10, y), 6, BLACK.filled()));
        chart
            .draw_series(std::iter::once(Circle::new((m.y, m.x), 6, RED.filled())))?
            .label("belief (shifted by the lead)")
            .legend(|(x, y)| Circle::new((x + 10, y), 5, RED.filled()));
        chart
            .draw_series(std::iter::once(Cross::new((g.waypoint.y, g.waypoint.x), 9, BLACK.stroke_width(3))))?
            .label("chosen waypoint")
            .legend(|(x, y)| Cross::new((x + 10, y), 6, BLACK.stroke_width(2)));
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present()?;
        Ok(())
    })())
}

/// The particle density at one message (hoff2024 Fig. 4-6): a histogram of the belief's
/// positions around the estimate, brighter where denser, the measured bearing from the
/// ASV with a +-3 deg wedge, the truth and the estimate.
pub fn belief_density(path: &Path, b: &BeliefSnapshot) -> Result<()> {
    register_fonts();
    let centre = b.estimate.xy();
    // a window four times the spread of the cloud about the estimate, the truth in it
    let spread =
        b.positions.iter().map(|p| (p.xy() - centre).norm_squared()).sum::<f64>() / b.positions.len().max(1) as f64;
    let half = (4.0 * spread.sqrt()).max(1.5 * (b.truth.xy() - centre).norm()).max(0.5);
    let (n0, e0) = (centre.x - half, centre.y - half);
    let cells = 80usize;
    let size = 2.0 * half / cells as f64;
    let mut counts = vec![0u32; cells * cells];
    for p in &b.positions {
        let (i, j) = (((p.x - n0) / size).floor(), ((p.y - e0) / size).floor());
        if (0.0..cells as f64).contains(&i) && (0.0..cells as f64).contains(&j) {
            counts[i as usize * cells + j as usize] += 1;
        }
    }
    let peak = f64::from(counts.iter().copied().max().unwrap_or(1).max(1));
    both!(path, (950, 780), |root| (|| -> Result<()> {
        let caption = format!("particle density at t = {:.0} s ({} particles drawn)", b.t_s, b.positions.len());
        root.fill(&WHITE)?;
        let (main, side) = root.split_horizontally(800);
        colour_bar(&side, 0.0, peak, "particles per cell")?;
        let root = main;
        let mut chart = chart(&root, &caption, e0..e0 + 2.0 * half, n0..n0 + 2.0 * half, ("east (m)", "north (m)"))?;
        chart.draw_series((0..cells).flat_map(|i| {
            let counts = &counts;
            (0..cells).map(move |j| {
                let (n, e) = (n0 + i as f64 * size, e0 + j as f64 * size);
                let v = f64::from(counts[i * cells + j]) / peak;
                Rectangle::new([(e, n), (e + size, n + size)], viridis(v).filled())
            })
        }))?;
        if let Some((station, heading, azimuth, _)) = b.bearing {
            // the bearing's ray from the ASV across the window, and the +-3 deg wedge
            let d = (centre - station.xy()).norm();
            for (offset, style, label) in [
                (0.0, RGBColor(148, 0, 211).stroke_width(3), Some("measured bearing")),
                (3f64.to_radians(), WHITE.stroke_width(1), Some("+-3 deg")),
                (-3f64.to_radians(), WHITE.stroke_width(1), None),
            ] {
                let a = heading + azimuth + offset;
                let u = nalgebra::Vector2::new(a.cos(), a.sin());
                let ray = [d - 2.0 * half, d + 2.0 * half].map(|r| {
                    let p = station.xy() + u * r.max(0.0);
                    (p.y, p.x)
                });
                line(&mut chart, ray, style, label)?;
            }
        }
        chart
            .draw_series(std::iter::once(Circle::new((b.truth.y, b.truth.x), 7, RED.filled())))?
            .label("truth")
            .legend(|(x, y)| Circle::new((x + 10, y), 5, RED.filled()));
        chart
            .draw_series(std::iter::once(Cross::new((b.estimate.y, b.estimate.x), 9, WHITE.stroke_width(3))))?
            .label("estimate (mean)")
            .legend(|(x, y)| Cross::new((x + 10, y), 6, BLACK.stroke_width(2)));
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present()?;
        Ok(())
    })())
}

/// The range pseudo-distribution of one ping (rypkema eq. 5, Fig. 3 top), with the
/// estimate marked.
pub fn range_distribution(
    path: &Path,
    distribution: &[f64],
    metres_per_sample: f64,
    offset_m: f64,
    estimate_m: f64,
) -> Result<()> {
    register_fonts();
    let r0 = -offset_m;
    let r1 = distribution.len() as f64 * metres_per_sample - offset_m;
    let (_, ymax) = span(distribution.iter().copied(), 0.05);
    both!(path, (1000, 500), |root| (|| -> Result<()> {
        let caption = format!("range pseudo-distribution, estimate {estimate_m:.2} m");
        let mut chart = chart(&root, &caption, r0..r1, 0.0..ymax.max(1e-9), ("range (m)", "pseudo-probability"))?;
        let points = distribution.iter().enumerate().map(|(i, v)| (i as f64 * metres_per_sample - offset_m, *v));
        line(&mut chart, points, BLUE.stroke_width(1), None)?;
        line(&mut chart, [(estimate_m, 0.0), (estimate_m, ymax)], RED.stroke_width(1), Some("estimate"))?;
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present()?;
        Ok(())
    })())
}

/// The beamformer's power over azimuth x inclination (rypkema Fig. 3 bottom), with the
/// estimate marked.
pub fn beam_map(
    path: &Path,
    power: impl Fn(&nalgebra::Vector3<f64>) -> f64,
    azimuth: f64,
    inclination: f64,
) -> Result<()> {
    register_fonts();
    // 2-degree cells: fine for the eye, and an SVG of 16 200 cells
    const CELL_DEG: f64 = 2.0;
    let (na, ni) = (180usize, 90usize);
    let mut values = vec![0.0; na * ni];
    for a in 0..na {
        for i in 0..ni {
            let u = onebeacon::dsp::beamform::direction(
                ((a as f64 + 0.5) * CELL_DEG).to_radians(),
                ((i as f64 + 0.5) * CELL_DEG).to_radians(),
            );
            values[a * ni + i] = power(&u);
        }
    }
    let (lo, hi) = values.iter().fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
    both!(path, (1150, 560), |root| (|| -> Result<()> {
        let caption = format!(
            "beam map (SPD-BF): azimuth {:.1} deg, inclination {:.1} deg",
            azimuth.to_degrees(),
            inclination.to_degrees()
        );
        root.fill(&WHITE)?;
        let (main, side) = root.split_horizontally(1000);
        colour_bar(&side, lo, hi, "power")?;
        let root = main;
        let mut chart =
            chart(&root, &caption, 0.0..360.0, 0.0..180.0, ("azimuth (deg)", "inclination (deg from down)"))?;
        chart.draw_series((0..na).flat_map(|a| {
            let values = &values;
            (0..ni).map(move |i| {
                let v = (values[a * ni + i] - lo) / (hi - lo).max(f64::MIN_POSITIVE);
                let (x, y) = (a as f64 * CELL_DEG, i as f64 * CELL_DEG);
                Rectangle::new([(x, y), (x + CELL_DEG, y + CELL_DEG)], viridis(v).filled())
            })
        }))?;
        chart
            .draw_series(std::iter::once(Cross::new(
                (azimuth.to_degrees(), inclination.to_degrees()),
                8,
                WHITE.stroke_width(3),
            )))?
            .label("estimate")
            .legend(|(x, y)| Cross::new((x + 10, y), 6, BLACK.stroke_width(2)));
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present()?;
        Ok(())
    })())
}

/// The colour of a confirmed command mode (None: none yet).
fn mode_colour(mode: Option<usize>) -> RGBColor {
    match mode {
        Some(m) => PALETTE[[1, 2, 3, 4][m % 4]],
        None => RGBColor(160, 160, 160),
    }
}

/// A fleet run (rypkema Fig. 12/14, top and bottom rows): for every AUV, its absolute
/// track (estimate coloured by the mode it had confirmed, truth in black, the beacon's
/// track in blue) and its beacon-relative track (the estimate less the beacon's
/// position).
pub fn fleet_tracks(path: &Path, vehicles: &[String], title: &str, traj: &[StepRecord]) -> Result<()> {
    register_fonts();
    let n = vehicles.len();
    // the first estimator of each vehicle flies the behaviours
    let first: Vec<usize> = (0..n)
        .map(|v| traj.first().and_then(|r| r.estimates.iter().position(|e| e.vehicle == v)).unwrap_or(v))
        .collect();
    let every = (traj.len() / 3000).max(1);
    both!(path, (1300, 520 * n as u32 + 40), |root| (|| -> Result<()> {
        root.fill(&WHITE)?;
        let (head, body) = root.split_vertically(40);
        head.draw(&Text::new(
            format!("{title}: absolute (left) and beacon-relative (right) tracks, estimate coloured by confirmed mode"),
            (15, 10),
            (FONT, 20).into_font(),
        ))?;
        let rows = body.split_evenly((n, 2));
        for v in 0..n {
            // (estimate, truth, beacon, confirmed mode)
            type Point = (Vector3<f64>, Vector3<f64>, Vector3<f64>, Option<usize>);
            let pts: Vec<Point> = traj
                .iter()
                .step_by(every)
                .filter(|r| r.truth[v].pos.z > 0.5)
                .map(|r| {
                    let mode = r.pilots.iter().find(|p| p.vehicle == Some(v)).and_then(|p| p.mode);
                    (r.estimates[first[v]].pos, r.truth[v].pos, r.beacon, mode)
                })
                .collect();
            for (panel, relative) in [(0usize, false), (1, true)] {
                let area = &rows[2 * v + panel];
                let xy =
                    |p: &Vector3<f64>, b: &Vector3<f64>| if relative { (p.y - b.y, p.x - b.x) } else { (p.y, p.x) };
                let mut all: Vec<(f64, f64)> =
                    pts.iter().flat_map(|(e, t, b, _)| [xy(e, b), xy(t, b), xy(b, b)]).collect();
                if !relative {
                    all.extend(pts.iter().map(|(_, _, b, _)| (b.y, b.x)));
                }
                let (x0, x1) = span(all.iter().map(|p| p.0), 0.05);
                let (y0, y1) = span(all.iter().map(|p| p.1), 0.05);
                let half = (x1 - x0).max(y1 - y0) / 2.0;
                let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
                let caption =
                    format!("{} {}", vehicles[v], if relative { "relative to the beacon" } else { "absolute" });
                let mut chart =
                    chart(area, &caption, cx - half..cx + half, cy - half..cy + half, ("east (m)", "north (m)"))?;
                line(&mut chart, pts.iter().map(|(_, t, b, _)| xy(t, b)), BLACK.stroke_width(1), Some("truth"))?;
                if !relative {
                    line(&mut chart, pts.iter().map(|(_, _, b, _)| (b.y, b.x)), BLUE.stroke_width(1), Some("beacon"))?;
                }
                for m in [None, Some(0), Some(1), Some(2), Some(3)] {
                    let c = mode_colour(m);
                    let label = m.map_or("no mode yet".to_string(), |m| format!("mode {}", m + 1));
                    chart
                        .draw_series(
                            pts.iter().filter(|p| p.3 == m).map(|(e, _, b, _)| Circle::new(xy(e, b), 1, c.filled())),
                        )?
                        .label(label)
                        .legend(move |(x, y)| Circle::new((x + 10, y), 4, c.filled()));
                }
                legend(&mut chart, SeriesLabelPosition::UpperRight)?;
            }
        }
        root.present()?;
        Ok(())
    })())
}

/// The mode each AUV had confirmed against time, and the operator's commands (rypkema
/// Fig. 12/14, middle row).
pub fn fleet_modes(
    path: &Path,
    vehicles: &[String],
    title: &str,
    traj: &[StepRecord],
    commands: &[(f64, usize)],
) -> Result<()> {
    register_fonts();
    let t1 = traj.last().map_or(1.0, |r| r.t_s).max(1.0);
    both!(path, (1200, 500), |root| (|| -> Result<()> {
        let caption = format!("{title}: confirmed mode per AUV (0: none yet) and commands (black)");
        let mut chart = chart(&root, &caption, 0.0..t1, -0.3..4.6, ("time (s)", "mode"))?;
        let mut cmd: Vec<(f64, f64)> = Vec::new();
        for (i, &(t, m)) in commands.iter().enumerate() {
            if i > 0 {
                cmd.push((t, cmd.last().map_or(0.0, |p| p.1)));
            }
            cmd.push((t, m as f64));
        }
        cmd.push((t1, cmd.last().map_or(0.0, |p| p.1)));
        line(&mut chart, cmd, BLACK.stroke_width(3), Some("commanded"))?;
        for (v, name) in vehicles.iter().enumerate() {
            let offset = 0.08 * (v as f64 + 1.0);
            let pts = traj.iter().map(|r| {
                let m =
                    r.pilots.iter().find(|p| p.vehicle == Some(v)).and_then(|p| p.mode).map_or(0.0, |m| m as f64 + 1.0);
                (r.t_s, m + offset)
            });
            line(&mut chart, pts, colour(v).stroke_width(2), Some(name))?;
        }
        legend(&mut chart, SeriesLabelPosition::LowerRight)?;
        root.present()?;
        Ok(())
    })())
}

/// The factored filter at one ping (rypkema Fig. 6): the primary particles relative to
/// the beacon with the truth and the estimate, the range-domain set (weight against
/// range) and the angle-domain set (inclination against azimuth, by weight).
pub fn factored_snapshot(path: &Path, b: &BeliefSnapshot) -> Result<()> {
    register_fonts();
    let sets = b.sets.clone().unwrap_or_default();
    let rel = |p: &Vector3<f64>| (p.y - b.beacon.y, p.x - b.beacon.x);
    both!(path, (1500, 520), |root| (|| -> Result<()> {
        root.fill(&WHITE)?;
        let panels = root.split_evenly((1, 3));
        let pts: Vec<(f64, f64)> = b.positions.iter().map(rel).collect();
        let (x0, x1) = span(pts.iter().map(|p| p.0).chain([rel(&b.truth).0]), 0.1);
        let (y0, y1) = span(pts.iter().map(|p| p.1).chain([rel(&b.truth).1]), 0.1);
        let half = (x1 - x0).max(y1 - y0).max(10.0) / 2.0;
        let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
        let caption = format!("particles relative to the beacon, t = {:.0} s", b.t_s);
        let mut cloud =
            chart(&panels[0], &caption, cx - half..cx + half, cy - half..cy + half, ("east (m)", "north (m)"))?;
        cloud.draw_series(pts.iter().map(|&p| Circle::new(p, 2, RGBColor(255, 140, 0).filled())))?;
        cloud
            .draw_series(std::iter::once(Circle::new(rel(&b.truth), 7, RED.filled())))?
            .label("truth")
            .legend(|(x, y)| Circle::new((x + 10, y), 5, RED.filled()));
        cloud
            .draw_series(std::iter::once(Cross::new(rel(&b.estimate), 9, BLACK.stroke_width(3))))?
            .label("estimate")
            .legend(|(x, y)| Cross::new((x + 10, y), 6, BLACK.stroke_width(2)));
        legend(&mut cloud, SeriesLabelPosition::UpperRight)?;
        let truth_range = (b.truth - b.beacon).norm();
        let (r0, r1) = span(sets.ranges.iter().map(|r| r.0).chain([truth_range]), 0.05);
        let wmax = sets.ranges.iter().map(|r| r.1).fold(1e-12, f64::max);
        let mut ranges = chart(&panels[1], "range-domain set", r0..r1, 0.0..wmax * 1.1, ("range (m)", "weight"))?;
        ranges.draw_series(sets.ranges.iter().map(|&(r, w)| PathElement::new(vec![(r, 0.0), (r, w)], BLUE)))?;
        line(&mut ranges, [(truth_range, 0.0), (truth_range, wmax * 1.1)], RED.stroke_width(2), Some("true range"))?;
        legend(&mut ranges, SeriesLabelPosition::UpperRight)?;
        let amax = sets.directions.iter().map(|d| d.1).fold(1e-12, f64::max);
        let axes = ("azimuth (deg)", "inclination (deg)");
        let mut angles = chart(&panels[2], "angle-domain set (body frame)", 0.0..360.0, 0.0..180.0, axes)?;
        angles.draw_series(sets.directions.iter().map(|(u, w)| {
            let (az, inc) = onebeacon::dsp::beamform::azimuth_inclination(u);
            Circle::new((az.to_degrees(), inc.to_degrees()), 3, viridis(w / amax).filled())
        }))?;
        root.present()?;
        Ok(())
    })())
}
