//! Plots of a fleet: the tracks coloured by command mode, the modes against time.

use super::*;

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
