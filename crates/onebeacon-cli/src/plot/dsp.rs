//! Plots of the receiver: the range distribution of a capture, the beam map.

use super::*;

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
