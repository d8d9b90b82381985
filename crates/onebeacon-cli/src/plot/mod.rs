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
        let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
        {
            let $root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
            $draw?;
        }
        crate::plot::write_png(path, size, &rgb)?;
        let svg = path.with_extension("svg");
        let $root = SVGBackend::new(&svg, size).into_drawing_area();
        $draw
    }};
}

/// Writes 8-bit RGB pixels, row by row, as the PNG `path` (the png crate: plotters' own
/// encoder would pull in the whole `image` crate for this one format).
fn write_png(path: &Path, (width, height): (u32, u32), rgb: &[u8]) -> Result<()> {
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(())
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

mod beliefs;
mod dsp;
mod fleet;
mod runs;
mod twin;

pub use beliefs::{bearing_map, belief_density, factored_snapshot, guidance_map};
pub use dsp::{beam_map, range_distribution};
pub use fleet::{fleet_modes, fleet_tracks};
pub use runs::{autopilots, error_vs_time, mc_errors, top_view};
pub use twin::twin_bands;
