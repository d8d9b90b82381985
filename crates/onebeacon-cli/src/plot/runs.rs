//! Plots of runs and campaigns: the top view, errors against time, the autopilots, the
//! Monte Carlo errors by sweep value.

use super::*;

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
