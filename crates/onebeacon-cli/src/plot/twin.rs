//! A twin's cells: each one's simulated RMSE band beside the real replay's RMSE.

use super::*;
use onebeacon_sim::twin::Twin;

/// One column per (beacon set, estimator) cell: the simulated runs' 5-95 % RMSE band (a
/// bar), their median (a dot) and the real replay's RMSE (a red cross), on a log10 axis.
pub fn twin_bands(path: &Path, title: &str, t: &Twin) -> Result<()> {
    register_fonts();
    let lg = |v: f64| if v > 0.0 { v.log10() } else { f64::NAN };
    let values = t.cells.iter().flat_map(|c| {
        let b = c.rmse();
        [lg(b.p5), lg(b.p95), lg(c.real.rmse_m)]
    });
    let (y0, y1) = span(values, 0.05);
    let n = t.cells.len().max(1) as f64;
    both!(path, (1400, 650), |root| (|| -> Result<()> {
        let caption = format!("{title}: RMSE, twin 5-95 % (bar), median (dot), real (red x)");
        let mut chart =
            chart(&root, &caption, -0.5..n - 0.5, y0..y1, ("cell (beacons / estimator)", "log10 RMSE (m)"))?;
        for (i, c) in t.cells.iter().enumerate() {
            let (x, b) = (i as f64, c.rmse());
            let band = colour(1).mix(if b.holds(c.real.rmse_m) { 0.5 } else { 0.25 });
            chart.draw_series(std::iter::once(Rectangle::new(
                [(x - 0.3, lg(b.p5)), (x + 0.3, lg(b.p95))],
                band.filled(),
            )))?;
            chart.draw_series(std::iter::once(Circle::new((x, lg(b.median)), 3, colour(1).filled())))?;
            chart.draw_series(std::iter::once(Cross::new((x, lg(c.real.rmse_m)), 6, colour(0).stroke_width(2))))?;
        }
        // the beacon sets' names above their first cell
        let mut last = None;
        for (i, c) in t.cells.iter().enumerate() {
            if last != Some(&c.beacons) {
                let label = c.beacons.iter().map(u32::to_string).collect::<Vec<_>>().join("+");
                chart.draw_series(std::iter::once(Text::new(label, (i as f64 - 0.4, y1), (FONT, 14))))?;
                last = Some(&c.beacons);
            }
        }
        root.present()?;
        Ok(())
    })())
}
