//! Plots of what a vehicle believed and decided: the FIM guidance's metric over the
//! reaching set, the bearing planner's candidates, a particle belief, a factored filter's
//! range and angle sets.

use super::*;

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
