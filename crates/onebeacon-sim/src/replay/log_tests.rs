//! A log's reading seen through the replay: increments composed as factor-graph edges,
//! and a start from the first ranges as the replay and its summary give it.

use super::replay;
use approx::assert_abs_diff_eq;
use onebeacon::log::schema::InitialFrom;
use onebeacon::log::testing::dead_reckoning_log as load;
use onebeacon::log::{InitialStart, LogError};
use std::f64::consts::FRAC_PI_2;

/// `increment_frame = "start"`: factor-graph edges (a translation in the start pose's
/// frame, then the turn) with turns of 80-150 deg. Dead reckoning lands on the
/// closed-form SE(2) composition p += R(psi) (d, l), psi += dpsi at every step (1e-9
/// m), in a NED and an ENU log, from body_odometry and from odometry; the same rows
/// read at the mid-step heading (the default) end metres off.
#[test]
fn start_frame_increments_compose_as_factor_graph_edges() {
    for frame in ["ned", "enu"] {
        for (kind, columns) in [("body_odometry", "forward = \"d\"\nlateral = \"l\""), ("odometry", "distance = \"d\"")]
        {
            let (mut odometry, mut truth) = ("t,d,l,dh\n".to_string(), "t,x,y\n".to_string());
            let (mut x, mut y, mut psi) = (0.0f64, 0.0f64, 0.0f64);
            for k in 0..40 {
                let d = 1.0 + (k % 5) as f64;
                let l = if kind == "odometry" { 0.0 } else { 0.4 * ((k % 3) as f64 - 1.0) };
                let turn =
                    (80.0 + 70.0 * ((k * 7) % 11) as f64 / 10.0).to_radians() * if k % 2 == 0 { 1.0 } else { -1.0 };
                x += d * psi.cos() - l * psi.sin();
                y += d * psi.sin() + l * psi.cos();
                psi += turn;
                odometry += &format!("{k}.0,{d},{l},{turn}\n");
                truth += &format!("{k}.5,{x},{y}\n");
            }
            let run = |increment: &str| {
                let body = format!(
                    "frame = \"{frame}\"\n[[source]]\nkind = \"{kind}\"\nfile = \"o.csv\"\ntime = \"t\"\n{columns}\n\
                     heading_change = \"dh\"\n{increment}\n[[source]]\nkind = \"ground_truth\"\nfile = \"g.csv\"\n\
                     time = \"t\"\nx = \"x\"\ny = \"y\"\n"
                );
                let log =
                    load(&format!("start-{frame}-{kind}"), &body, &[("o.csv", &odometry), ("g.csv", &truth)]).unwrap();
                let mut worst: f64 = 0.0;
                let r = replay(&log, None, |row| {
                    worst = worst.max(row.estimates[0].error_m);
                    Ok::<_, LogError>(())
                })
                .unwrap();
                assert_eq!(r.session.stats[0].count, 40);
                (worst, r.warnings(true))
            };
            let ((start, quiet), (mid, warned)) = (run("increment_frame = \"start\""), run(""));
            assert!(start < 1e-9, "{frame} {kind}: {start} m off the composition");
            assert!(mid > 1.0, "{frame} {kind}: the mid-step reading is {mid} m off");
            // every turn is wider than the warning's 23 deg: read at mid-step, it is said
            assert!(quiet.is_empty(), "{quiet:?}");
            assert!(
                warned.iter().any(|w| w.starts_with("40 of 40 odometry rows") && w.contains("increment_frame")),
                "{warned:?}"
            );
        }
    }
}

/// `initial.from = "ranges"`: a vehicle resting at (3, 4) ranged from three beacons
/// (exact ranges, and one 150 m off): the start is the fix, at the end of the window,
/// with the heading given; with two beacons it is refused, naming the key.
#[test]
fn a_start_from_the_first_ranges() {
    let body = "[[source]]\nkind = \"range\"\nfile = \"r.csv\"\ntime = \"t\"\nbeacon = \"id\"\nrange = \"r\"\n\
                [[beacon]]\nid = 0\nx_m = 40.0\ny_m = 0.0\n[[beacon]]\nid = 1\nx_m = -20.0\ny_m = 30.0\n\
                [[beacon]]\nid = 2\nx_m = -20.0\ny_m = -30.0\n";
    let p = (3.0f64, 4.0f64);
    let d = |bx: f64, by: f64| (p.0 - bx).hypot(p.1 - by);
    let mut csv = String::from("t,id,r\n");
    for k in 0..12 {
        let (id, (bx, by)) = [(0, (40.0, 0.0)), (1, (-20.0, 30.0)), (2, (-20.0, -30.0))][k % 3];
        let outlier = if k == 4 { 150.0 } else { 0.0 };
        csv += &format!("{},{id},{}\n", 1.0 + k as f64, d(bx, by) + outlier);
    }
    let log = load("ranges-start", body, &[("r.csv", &csv)]).unwrap();
    let mut log = log;
    log.description.initial.from = InitialFrom::Ranges;
    log.description.initial.ranges_window_s = 10.0;
    log.description.initial.heading_deg = Some(90.0);
    let InitialStart { t0_s: t0, pose: (n, e, psi), position_sigma_m: sigma } = log.initial_start(None).unwrap();
    assert_eq!(t0, 11.0);
    // the 150 m outlier keeps a Huber weight of about 1e-4: 1 mm of pull
    assert_abs_diff_eq!(n, p.0, epsilon = 0.01);
    assert_abs_diff_eq!(e, p.1, epsilon = 0.01);
    assert_abs_diff_eq!(psi, FRAC_PI_2, epsilon = 1e-12);
    assert_eq!(sigma, 1.0); // the fix is exact: position_sigma_m's default
    // the replay starts there and says so in its summary (in the log's frame)
    let r = replay(&log, None, |_| Ok::<_, LogError>(())).unwrap();
    assert_eq!(r.start, log.initial_start(None).unwrap());
    let v = crate::json::replay_summary(&log, &[0, 1, 2], &r, 0.0);
    let at = |k: &str| v["start"][k].as_f64().unwrap();
    assert_eq!((v["start"]["from"].as_str(), at("t_s"), at("position_sigma_m")), (Some("ranges"), 11.0, 1.0));
    assert_eq!((at("x_m"), at("y_m"), at("heading_rad")), (n, e, psi));
    let two = csv.lines().filter(|l| !l.contains(",2,")).collect::<Vec<_>>().join("\n");
    let mut log = load("ranges-two", body, &[("r.csv", &two)]).unwrap();
    log.description.initial.from = InitialFrom::Ranges;
    log.description.initial.heading_deg = Some(0.0);
    let e = log.initial_start(None).unwrap_err().to_string();
    assert!(e.contains("initial.ranges_window_s") && e.contains("three beacons"), "{e}");
}
