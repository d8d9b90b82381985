//! The log description (TOML) and the loading of its CSV files into one time-ordered
//! stream. Every error is one line naming the file, the line, the column or key and
//! what was expected.

use super::error::LogError;
use super::geodesy::{Geodetic, check_latlon};
use super::merge::{Items, Rows};
use super::rows::{Site, SourceRows};
pub use super::schema::*;
use super::table::Table;
use crate::config::builder::VehicleModel;
use crate::config::estimator::{EstimatorKind, EstimatorSpec, Host};
use crate::config::stream::{Beacon, StreamConfig};
use crate::config::toml_file::{deserialize, invalid as invalid_in, read};
use crate::geo::Frame;
use crate::nav::session::Input;
use crate::nav::{Kind, Measurement, Navigator};
use nalgebra::{Vector2, Vector3};
use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Where and when a log's estimators start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InitialStart {
    pub t0_s: f64,
    /// North, east (m) and heading (rad), NED.
    pub pose: (f64, f64, f64),
    /// The initial position sigma of each axis, m.
    pub position_sigma_m: f64,
}

/// A loaded log: the description and its fixed beacons (SI units, the log's frame). Its
/// CSV files are read as streams by [`Log::items`], never held whole (but for sources
/// with `sort = true`), so a log of any length replays in bounded memory.
#[derive(Debug, Clone)]
pub struct Log {
    pub description: LogDescription,
    pub frame: Frame,
    pub beacons: BTreeMap<u32, Vector3<f64>>,
    /// Beacons with a `beacon_track` source.
    pub(super) tracked: BTreeSet<u32>,
    /// Latitude and longitude to local positions, when the log has them.
    pub(super) geodetic: Option<Geodetic>,
    base: PathBuf,
    /// The description's own path.
    path: PathBuf,
}

impl Log {
    /// The directory the description's file names are relative to.
    pub fn base(&self) -> &Path {
        &self.base
    }

    /// Every file the log reads: its description, its CSV files and its beacons file.
    pub fn files(&self) -> Vec<PathBuf> {
        let mut files = vec![self.path.clone()];
        files.extend(
            self.description
                .sources
                .iter()
                .filter_map(|s| s.file.as_ref().or(s.bag.as_ref()))
                .map(|f| self.base.join(f)),
        );
        files.extend(self.description.beacons.iter().map(|b| self.base.join(&b.file)));
        files
    }

    /// The bytes of the log's CSV files (those that can be read; the replay names the
    /// others).
    pub fn source_bytes(&self) -> u64 {
        self.description
            .sources
            .iter()
            .filter_map(|s| std::fs::metadata(self.base.join(s.file.as_ref().or(s.bag.as_ref())?)).ok())
            .map(|m| m.len())
            .sum()
    }
}

impl LogDescription {
    /// Reads and checks a log description (the CSV files are not read).
    pub fn load(path: &Path) -> Result<Self, LogError> {
        Self::parse(&read(path)?, &path.display().to_string())
    }

    /// Parses and checks the text of a log description; `name` names it in errors.
    pub fn parse(text: &str, name: &str) -> Result<Self, LogError> {
        let mut d: LogDescription = deserialize(text, name)?;
        let invalid = |v| LogError::Description(invalid_in(name, v));
        // the onboard keys as a stream checks them, with `[noise]` handed out
        d.estimators = d.stream_config(Vec::new()).checked().map_err(invalid)?.estimators;
        super::validate::validate_log(&d).map_err(invalid)?;
        Ok(d)
    }

    /// Runs the `[[estimators]]` of the TOML file `path` (`replay --estimators`, what
    /// `tune` writes) instead of the description's, each given the `[noise]` keys it does
    /// not set, as the description's own are.
    pub fn use_estimators(&mut self, path: &Path) -> Result<(), LogError> {
        self.estimators = load_estimators(path)?;
        let file = path.display().to_string();
        let invalid = |v| LogError::Description(invalid_in(&file, v));
        self.estimators = self.stream_config(Vec::new()).checked().map_err(invalid)?.estimators;
        Ok(())
    }

    /// The noise of an estimator that sets no noise key of its own: the defaults with
    /// `[noise]`'s keys (what `smooth` weighs with, without `--like`).
    pub fn default_noise(&self) -> crate::nav::PlanarNoise {
        let mut spec = EstimatorSpec::new(crate::config::estimator::EstimatorKind::RangeEkf);
        for (key, v) in &self.noise {
            if let Some(slot) = spec.key_mut(key) {
                *slot = Some(*v);
            }
        }
        spec.planar_config().noise
    }

    /// The `[noise]` keys given, "key = value" each, comma-separated (None for none).
    pub fn noise_keys(&self) -> Option<String> {
        (!self.noise.is_empty())
            .then(|| self.noise.iter().map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>().join(", "))
    }

    /// The stream configuration the description holds, with the fixed beacons `beacons`
    /// (the log's resolved: [`LogDescription::fixed_beacons`]).
    pub fn stream_config(&self, beacons: Vec<Beacon>) -> StreamConfig {
        StreamConfig {
            name: self.name.clone(),
            description: self.description.clone(),
            frame: self.frame,
            model: self.model,
            beacons,
            initial: self.initial.clone(),
            tracked: self.tracked.clone(),
            estimators: self.estimators.clone(),
            noise: self.noise.clone(),
            limits: self.limits,
            controller: self.controller.clone(),
        }
    }

    /// The geodetic origin: `[origin]`, or the first latitude and longitude of the log
    /// (the `[beacons]` file, the `[[beacon]]` entries, then the sources in their order,
    /// each file's first row); None when the log has no latitude or longitude.
    fn geodetic(&self, base: &Path) -> Result<Option<Geodetic>, LogError> {
        let deg = std::f64::consts::PI / 180.0;
        let mut first = self.origin.map(|o| (o.lat_deg * deg, o.lon_deg * deg));
        let first_row =
            |mut table: Table, lat: &str, lon: &str, unit: LatLonUnit| -> Result<Option<(f64, f64)>, LogError> {
                let (lat, lon) = (table.index(lat)?, table.index(lon)?);
                if !table.next_row()? {
                    return Ok(None);
                }
                let (lat_rad, lon_rad) = (table.number(lat)? * unit.radians(), table.number(lon)? * unit.radians());
                check_latlon(lat_rad, lon_rad).map_err(|m| table.error(lat, m))?;
                Ok(Some((lat_rad, lon_rad)))
            };
        if let Some(t) = self.beacons.as_ref().filter(|_| first.is_none())
            && let (Some(lat), Some(lon)) = (&t.lat, &t.lon)
        {
            first = first_row(Table::csv(base, &t.file)?, lat, lon, t.latlon_unit)?;
        }
        if first.is_none() {
            first = self.beacon_list.iter().find_map(|b| Some((b.lat_deg? * deg, b.lon_deg? * deg)));
        }
        for s in &self.sources {
            if first.is_some() {
                break;
            }
            // a live topic cannot be read ahead (its latitudes need [origin]); a CSV
            // file's are named, a bag's may be a standard message's
            let live = s.file.is_none() && s.bag.is_none();
            if live || s.lat.is_none() && (s.bag.is_none() || !s.kind.positioned()) {
                continue;
            }
            // a bag's standard message may hold them (sensor_msgs/NavSatFix)
            let table = Table::open(base, s)?;
            let column = |k: &str| s.column(k).cloned().or_else(|| table.default_column(s.kind, k));
            if let (Some(lat), Some(lon)) = (column("lat"), column("lon")) {
                first = first_row(table, &lat, &lon, s.latlon_unit)?;
            }
        }
        let frame = Frame::from(self.frame);
        Ok(first.map(|(lat0_rad, lon0_rad)| Geodetic::new(lat0_rad, lon0_rad, frame)))
    }

    /// Fixed beacons (the log's frame): the `[beacons]` file and the inline `[[beacon]]`
    /// entries; `base` is the description's directory.
    pub fn fixed_beacons(&self, base: &Path) -> Result<BTreeMap<u32, Vector3<f64>>, LogError> {
        self.beacons_about(base, self.geodetic(base)?.as_ref())
    }

    fn beacons_about(&self, base: &Path, geo: Option<&Geodetic>) -> Result<BTreeMap<u32, Vector3<f64>>, LogError> {
        let mut out = BTreeMap::new();
        if let Some(t) = &self.beacons {
            let mut table = Table::csv(base, &t.file)?;
            let id = table.index(&t.id)?;
            let mut columns = |a: &Option<String>, b: &Option<String>| match (a, b) {
                (Some(a), Some(b)) => Ok(Some((table.index(a)?, table.index(b)?))),
                _ => Ok::<_, LogError>(None),
            };
            let (xy, latlon) = (columns(&t.x, &t.y)?, columns(&t.lat, &t.lon)?);
            let z = t.z.as_ref().map(|z| table.index(z)).transpose()?;
            let scale = t.length_unit.metres();
            while table.next_row()? {
                let row = &table;
                let b = row.beacon_id(id)?;
                let z = z.map_or(Ok(0.0), |z| row.number(z))? * scale;
                let (x, y) = match (xy, latlon, geo) {
                    (Some((x, y)), _, _) => (row.number(x)? * scale, row.number(y)? * scale),
                    (None, Some((lat, lon)), Some(geo)) => {
                        let unit = t.latlon_unit.radians();
                        geo.local(row.number(lat)? * unit, row.number(lon)? * unit).map_err(|m| row.error(lat, m))?
                    }
                    _ => unreachable!("validated: x and y, or lat and lon"),
                };
                if out.insert(b, Vector3::new(x, y, z)).is_some() {
                    return Err(row.error(id, format!("beacon {b} appears twice")));
                }
            }
        }
        let deg = std::f64::consts::PI / 180.0;
        for b in &self.beacon_list {
            let (x, y) = match (b.x_m.zip(b.y_m), b.lat_deg.zip(b.lon_deg), geo) {
                (Some(xy), _, _) => xy,
                (None, Some((lat, lon)), Some(geo)) => geo.local(lat * deg, lon * deg).map_err(|message| {
                    LogError::File { file: "[[beacon]]".into(), message: format!("beacon {}: {message}", b.id) }
                })?,
                _ => unreachable!("validated: x_m and y_m, or lat_deg and lon_deg"),
            };
            if out.insert(b.id, Vector3::new(x, y, b.z_m)).is_some() {
                return Err(LogError::File {
                    file: "[[beacon]]".into(),
                    message: format!("beacon {} is given twice", b.id),
                });
            }
        }
        Ok(out)
    }
}

/// A file of `[[estimators]]` tables alone (what `onebeacon tune` writes).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct EstimatorFile {
    #[serde(alias = "estimator")]
    estimators: Vec<EstimatorSpec>,
}

/// Reads and checks a file of `[[estimators]]` tables, to run on a log instead of its
/// own (`replay --estimators`).
fn load_estimators(path: &Path) -> Result<Vec<EstimatorSpec>, LogError> {
    let name = path.display().to_string();
    let f: EstimatorFile = deserialize(&read(path)?, &name)?;
    if f.estimators.is_empty() {
        return Err(LogError::File { file: name, message: "no [[estimators]] table".into() });
    }
    crate::config::check_estimators(&f.estimators, Host::Log)
        .map_err(|v| LogError::Description(invalid_in(&name, v)))?;
    Ok(f.estimators)
}

impl Log {
    /// Loads a log description, its fixed beacons and the beacon ids of its tracks,
    /// and opens every file it names (relative to its directory): headers, columns and
    /// first rows are checked here; a later bad row is an error of [`Log::items`].
    pub fn load(path: &Path) -> Result<Self, LogError> {
        let mut log = Self::described(path)?;
        // beacon tracks first, so that ranges may name tracked beacons
        let mut tracked = BTreeSet::new();
        for s in log.description.sources.iter().filter(|s| s.kind == SourceKind::BeaconTrack) {
            let mut rows = SourceRows::open(log.site(), s)?;
            while let Some(item) = rows.next_item()? {
                if let Input::BeaconPosition { beacon_id, .. } = item.input {
                    tracked.insert(beacon_id);
                }
            }
        }
        log.tracked = tracked;
        log.items()?;
        Ok(log)
    }

    /// The description at `path` with its fixed beacons and origin; no source opened.
    pub(super) fn described(path: &Path) -> Result<Self, LogError> {
        let description = LogDescription::load(path)?;
        let base = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        let frame = Frame::from(description.frame);
        let geodetic = description.geodetic(&base)?;
        let beacons = description.beacons_about(&base, geodetic.as_ref())?;
        let (tracked, path) = (BTreeSet::new(), path.to_path_buf());
        Ok(Self { description, frame, beacons, tracked, geodetic, base, path })
    }

    /// What its rows are read against.
    pub(super) fn site(&self) -> Site<'_> {
        let (base, frame, beacons, tracked, geodetic) =
            (&self.base, self.frame, &self.beacons, &self.tracked, self.geodetic);
        Site { base, frame, beacons, tracked, geodetic }
    }

    /// The merged, time-ordered stream of every source. At equal times: beacon
    /// positions, then measurements, then the truth; then in the order of the sources.
    pub fn items(&self) -> Result<Items<'_>, LogError> {
        let (mut heads, mut rows, mut damaged) = (Vec::new(), Vec::new(), Vec::new());
        for s in &self.description.sources {
            let mut source = SourceRows::open(self.site(), s)?;
            let head = source
                .next_item()?
                .ok_or_else(|| LogError::File { file: source.table.name().to_string(), message: "no rows".into() })?;
            if s.time_order() == TimeOrder::Sort {
                let mut all = vec![head];
                while let Some(item) = source.next_item()? {
                    all.push(item);
                }
                all.sort_by(|a, b| a.t_s.total_cmp(&b.t_s)); // stable: equal times keep their rows' order
                damaged.extend(source.table.damage().map(|d| format!("{}: {d}", source.table.name())));
                let mut all = all.into_iter();
                heads.push(all.next());
                rows.push(Rows::Sorted(all));
            } else {
                heads.push(Some(head));
                rows.push(Rows::Streamed(Box::new(source)));
            }
        }
        let rank = |s: &Source| match s.kind {
            SourceKind::BeaconTrack => 0,
            SourceKind::GroundTruth => 2,
            _ => 1,
        };
        let ranks = self.description.sources.iter().map(rank).collect();
        Ok(Items { heads, rows, ranks, error: None, damaged })
    }

    /// Every beacon of the log: fixed ones and those with a track.
    pub fn beacon_ids(&self) -> BTreeSet<u32> {
        self.beacons.keys().chain(&self.tracked).copied().collect()
    }

    /// Whether the log has a ground truth.
    pub fn has_truth(&self) -> bool {
        self.description.sources.iter().any(|s| s.kind == SourceKind::GroundTruth)
    }

    /// The initial time, pose (NED) and position sigma, from the description: given,
    /// the first ground-truth pose (heading from its column or its track), or a fix from
    /// the first ranges of `beacons` (all when None: a run on some beacons is not helped
    /// by the others; its sigma the larger of `position_sigma_m` and three times the
    /// fix's). Reads the log only as far as it needs.
    pub fn initial_start(&self, beacons: Option<&BTreeSet<u32>>) -> Result<InitialStart, LogError> {
        let position_sigma_m = self.description.initial.position_sigma_m;
        if self.description.initial.from == InitialFrom::Ranges {
            return self.start_from_ranges(beacons);
        }
        self.initial_pose().map(|(t0_s, pose)| InitialStart { t0_s, pose, position_sigma_m })
    }

    /// `from = "ranges"`: the fix of the first window's ranges to fixed beacons, the
    /// vehicle dead-reckoned through the window on the log's motion rows (in the frame of
    /// its first range, heading 0 there): each range is to the position the fix seeks
    /// plus the dead-reckoned displacement since, rotated by the heading then, so a
    /// moving vehicle is fixed where the window ends.
    fn start_from_ranges(&self, beacons: Option<&BTreeSet<u32>>) -> Result<InitialStart, LogError> {
        let init = &self.description.initial;
        let fail = |message: String| LogError::File { file: self.description.name.clone(), message };
        // ranges: (beacon id, its position, range, dead-reckoned (north, east, heading)
        // since the first range)
        let (mut ranges, mut heading, mut depth, mut window) = (Vec::new(), None, 0.0, None::<(f64, f64)>);
        let mut dr: Option<Box<dyn Navigator>> = None;
        // the dead-reckoned pose at t (a depth item moves a navigator's clock on)
        let dr_pose = |dr: &mut Box<dyn Navigator>, t: f64, depth_m: f64| {
            dr.process(&Measurement::new(t, Kind::Depth { depth_m }));
            let e = dr.estimate();
            (e.north_m(), e.east_m(), e.heading_rad())
        };
        for item in self.items()? {
            let item = item?;
            let t = item.t_s;
            if window.is_some_and(|(_, end)| t > end) {
                break;
            }
            let Input::Measurement(kind) = item.input.to_ned(self.frame) else { continue };
            match kind {
                Kind::Range { beacon, range_m }
                    if beacon.position_ned_m.iter().all(|v| v.is_finite())
                        && beacons.is_none_or(|b| b.contains(&beacon.id)) =>
                {
                    window.get_or_insert((t, t + init.ranges_window_s));
                    let dr = dr.get_or_insert_with(|| dead_reckoning(t));
                    ranges.push((beacon.id, beacon.position_ned_m, range_m, dr_pose(dr, t, depth)));
                }
                Kind::Heading { heading_rad } => {
                    if let Some(dr) = &mut dr {
                        heading.get_or_insert((heading_rad, dr_pose(dr, t, depth).2));
                    }
                }
                Kind::Depth { depth_m } => depth = depth_m,
                // motion alone: a heading or attitude fix is absolute, the frame is not
                Kind::Odometry { .. } | Kind::BodyOdometry { .. } | Kind::Speed { .. } | Kind::BodyVelocity { .. } => {
                    if let Some(dr) = &mut dr {
                        dr.process(&Measurement::new(t, kind));
                    }
                }
                _ => {}
            }
        }
        let (Some((_, end)), Some(mut dr)) = (window, dr) else {
            return Err(fail("initial.from = \"ranges\" but the log has no range to a fixed beacon".into()));
        };
        let (dn, de, turned) = dr_pose(&mut dr, end, depth);
        // the heading at the first range: the given one (at the window's end) or the
        // first measured one, less the turn dead-reckoned up to it
        let psi0 = match (init.heading_deg, heading) {
            (Some(h), _) => self.frame.heading_to_ned(h.to_radians()) - turned,
            (None, Some((h, turned_then))) => h - turned_then,
            (None, None) => {
                return Err(fail(
                    "initial.from = \"ranges\" needs initial.heading_deg or a heading measurement in the window".into(),
                ));
            }
        };
        let rotate = |n: f64, e: f64| {
            let (s, c) = psi0.sin_cos();
            Vector3::new(c * n - s * e, s * n + c * e, 0.0)
        };
        // a range to b from p0 + R d is a range to b - R d from p0
        let shifted: Vec<_> = ranges.iter().map(|(id, b, r, (n, e, _))| (*id, b - rotate(*n, *e), *r)).collect();
        let used = beacons.map_or(String::new(), |b| {
            format!(" of beacons {}", b.iter().map(u32::to_string).collect::<Vec<_>>().join(", "))
        });
        let fix = crate::nav::fix::multilaterate(&shifted, depth).ok_or_else(|| {
            fail(format!(
                "initial.from = \"ranges\": the {} ranges{used} in the first {} s (initial.ranges_window_s) do not fix a position (three beacons not in a line are needed; with fewer, start from = \"given\" or \"ground_truth\")",
                ranges.len(),
                init.ranges_window_s
            ))
        })?;
        // the ranges of one beacon in one window share its errors (its offset, the
        // window's dead reckoning): counted as one measurement per beacon, not one per
        // range, the fix's covariance grows by ranges / beacons
        let heard: BTreeSet<u32> = ranges.iter().map(|r| r.0).collect();
        let shared = ranges.len() as f64 / heard.len().max(1) as f64;
        let fix_sigma = (shared * fix.covariance.symmetric_eigenvalues().max().max(0.0)).sqrt();
        // an error the beacons share (a range scale, a biased beacon) leaves no residual:
        // with four beacons or more, the spread of the fixes without one beacon each
        // (the jackknife's variance, (n - 1) / n times their sum of squares about their
        // mean) measures it
        let without: Vec<Vector2<f64>> = if heard.len() >= 4 {
            heard
                .iter()
                .filter_map(|b| {
                    let others: Vec<_> = shifted.iter().filter(|r| r.0 != *b).copied().collect();
                    crate::nav::fix::multilaterate(&others, depth).map(|f| f.position)
                })
                .collect()
        } else {
            Vec::new()
        };
        let jackknife_sigma = if without.len() >= 2 {
            let n = without.len() as f64;
            let mean = without.iter().sum::<Vector2<f64>>() / n;
            ((n - 1.0) / n * without.iter().map(|p| (p - mean).norm_squared()).sum::<f64>() / 2.0).sqrt()
        } else {
            0.0
        };
        let position_sigma_m = init.position_sigma_m.max(3.0 * fix_sigma).max(jackknife_sigma);
        let p_end = fix.position + rotate(dn, de).xy();
        Ok(InitialStart { t0_s: end, pose: (p_end.x, p_end.y, psi0 + turned), position_sigma_m })
    }

    /// The initial pose (NED) and time, from the description: given, or the first
    /// ground-truth pose (heading from its column or its track). Reads the log only as
    /// far as it needs.
    pub fn initial_pose(&self) -> Result<(f64, (f64, f64, f64)), LogError> {
        let init = &self.description.initial;
        let mut items = self.items()?;
        let first = items.next().transpose()?;
        let first_t = first.as_ref().map_or(0.0, |i| i.t_s);
        if let Some(pose) = init.given_pose(self.frame) {
            return Ok((init.t0_s.unwrap_or(first_t), pose));
        }
        let mut truth = first.into_iter().map(Ok).chain(items).filter_map(|i| match i {
            Ok(i) => match i.input.to_ned(self.frame) {
                Input::Truth(p) => Some(Ok((i.t_s, p))),
                _ => None,
            },
            Err(e) => Some(Err(e)),
        });
        let no_truth = || {
            LogError::File {
            file: self.description.name.clone(),
            message: "initial.from = \"ground_truth\" but the log has no ground_truth source (give the pose with from = \"given\")".into(),
        }
        };
        let (t0, p0) = truth.next().transpose()?.ok_or_else(no_truth)?;
        let psi = match init.heading_from {
            HeadingFrom::Column => p0.heading_rad.ok_or_else(|| LogError::File {
                file: self.description.name.clone(),
                message: "initial.heading_from = \"column\" but the ground_truth source has no heading column (use \"track\")".into(),
            })?,
            HeadingFrom::Track => {
                let mut far = None;
                for pose in truth {
                    let (_, p) = pose?;
                    if (p.north_m - p0.north_m).hypot(p.east_m - p0.east_m) >= init.track_m {
                        far = Some(p);
                        break;
                    }
                }
                let p = far.ok_or_else(|| LogError::File {
                    file: self.description.name.clone(),
                    message: format!("the ground truth never moves {} m from its start (initial.track_m)", init.track_m),
                })?;
                (p.east_m - p0.east_m).atan2(p.north_m - p0.north_m)
            }
        };
        Ok((t0, (p0.north_m, p0.east_m, psi)))
    }
}

/// A dead-reckoning navigator at the origin, heading 0, from `t0_s` (the planar
/// default): the displacement of a vehicle through a window of ranges
/// ([`Log::initial_start`]).
fn dead_reckoning(t0_s: f64) -> Box<dyn Navigator> {
    let start = Initial::default().tracker_start();
    EstimatorSpec::new(EstimatorKind::DeadReckoning).builder(start, VehicleModel::Planar)(
        t0_s,
        (0.0, 0.0, 0.0),
        0.0,
        0.0,
    )
}

#[cfg(test)]
mod tests {
    use super::super::testing::dead_reckoning_log as load;
    use super::*;
    use crate::nav::BeaconFix;
    use crate::nav::session::Item;
    use approx::assert_abs_diff_eq;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn items(log: &Log) -> Vec<Item> {
        log.items().unwrap().map(Result::unwrap).collect()
    }

    fn measurement(item: &Item) -> Kind {
        match &item.input {
            Input::Measurement(m) => m.clone(),
            other => panic!("not a measurement: {other:?}"),
        }
    }

    /// Every source kind, with every unit key and a time offset, read into SI units in
    /// the log's frame, values worked out by hand.
    #[test]
    fn every_kind_and_unit_is_read_to_si() {
        let body = r#"frame = "ned"
[[source]]
kind = "odometry"
file = "odo.csv"
time = "t"
distance = "d"
heading_change = "dh"
length_unit = "cm"
angle_unit = "deg"
[[source]]
kind = "speed"
file = "speed.csv"
time = "t"
speed = "v"
length_unit = "km"
[[source]]
kind = "heading"
file = "heading.csv"
time = "t"
heading = "h"
angle_unit = "deg"
[[source]]
kind = "speed_heading"
file = "sh.csv"
time = "t"
speed = "v"
heading = "h"
[[source]]
kind = "depth"
file = "depth.csv"
time = "t"
depth = "z"
length_unit = "mm"
[[source]]
kind = "range"
file = "range.csv"
time = "t"
beacon = "id"
range = "r"
length_unit = "cm"
[[source]]
kind = "doppler"
file = "doppler.csv"
time = "t"
beacon = "id"
radial_speed = "vr"
time_offset_s = 0.5
[[source]]
kind = "beacon_track"
file = "track.csv"
time = "t"
beacon = "id"
x = "x"
y = "y"
z = "z"
length_unit = "km"
[[source]]
kind = "ground_truth"
file = "truth.csv"
time = "t"
x = "x"
y = "y"
heading = "h"
angle_unit = "deg"
[[beacon]]
id = 3
x_m = 10.0
y_m = -5.0
z_m = 2.0
"#;
        let files = [
            ("odo.csv", "t,d,dh\n1.0,150,90\n"),
            ("speed.csv", "t,v\n2.0,0.002\n"),
            ("heading.csv", "t,h\n3.0,-45\n"),
            ("sh.csv", "t,v,h\n4.0,1.25,0.5\n"),
            ("depth.csv", "t,z\n5.0,12500\n"),
            ("range.csv", "t,id,r\n6.0,3,4210\n7.0,8,100\n"),
            ("doppler.csv", "t,id,vr\n7.5,3,-0.4\n"),
            ("track.csv", "t,id,x,y,z\n6.5,8,0.1,-0.2,0.003\n"),
            ("truth.csv", "t,x,y,h\n9.0,3.5,-1.5,180\n"),
        ];
        let log = load("kinds", body, &files).unwrap();
        assert_eq!(log.beacon_ids(), BTreeSet::from([3, 8]));
        let items = items(&log);
        let times: Vec<f64> = items.iter().map(|i| i.t_s).collect();
        assert_eq!(times, [1.0, 2.0, 3.0, 4.0, 4.0, 5.0, 6.0, 6.5, 7.0, 8.0, 9.0]);
        let Kind::Odometry { distance_m, heading_change_rad } = measurement(&items[0]) else { panic!() };
        assert_abs_diff_eq!(distance_m, 1.5, epsilon = 1e-12);
        assert_abs_diff_eq!(heading_change_rad, FRAC_PI_2, epsilon = 1e-12);
        assert_eq!(measurement(&items[1]), Kind::Speed { speed_m_s: 2.0 });
        let Kind::Heading { heading_rad } = measurement(&items[2]) else { panic!() };
        assert_abs_diff_eq!(heading_rad, -PI / 4.0, epsilon = 1e-12);
        // a speed_heading row: the speed, then the heading, at its time
        assert_eq!(measurement(&items[3]), Kind::Speed { speed_m_s: 1.25 });
        assert_eq!(measurement(&items[4]), Kind::Heading { heading_rad: 0.5 });
        assert_eq!(measurement(&items[5]), Kind::Depth { depth_m: 12.5 });
        let Kind::Range { beacon, range_m } = measurement(&items[6]) else { panic!() };
        assert_abs_diff_eq!(range_m, 42.1, epsilon = 1e-12);
        assert_eq!(beacon, BeaconFix::fixed(3, Vector3::new(10.0, -5.0, 2.0)));
        let Input::BeaconPosition { beacon_id, position } = items[7].input else { panic!() };
        assert_eq!(beacon_id, 8);
        assert_abs_diff_eq!(position, Vector3::new(100.0, -200.0, 3.0), epsilon = 1e-9);
        // a range to a tracked beacon: its position comes from the session (NaN here)
        let Kind::Range { beacon, range_m } = measurement(&items[8]) else { panic!() };
        assert_eq!((beacon.id, range_m), (8, 1.0));
        assert!(beacon.position_ned_m.x.is_nan());
        // the Doppler row at 7.5 s with time_offset_s = 0.5
        let Kind::Doppler { beacon, radial_speed_m_s } = measurement(&items[9]) else { panic!() };
        assert_eq!((beacon.id, radial_speed_m_s), (3, -0.4));
        let Input::Truth(p) = items[10].input else { panic!() };
        assert_eq!((p.north_m, p.east_m), (3.5, -1.5));
        assert_abs_diff_eq!(p.heading_rad.unwrap(), PI, epsilon = 1e-12);
    }

    /// The kinds of a vehicle's computer from CSV (attitude, bearing, report, array_fix),
    /// with a beacon's error and its ping's transmit time, in an ENU log in degrees:
    /// values worked out by hand. Own fixes and the vehicle a row is about are refused
    /// in a file, naming the key.
    #[test]
    fn a_computers_kinds_are_read_and_its_own_fix_is_a_live_topics() {
        let body = r#"frame = "enu"
[[source]]
kind = "attitude"
file = "att.csv"
time = "t"
roll = "r"
pitch = "p"
heading = "h"
angle_unit = "deg"
[[source]]
kind = "bearing"
file = "usbl.csv"
time = "t"
beacon = "id"
station_heading = "h"
azimuth = "a"
elevation = "e"
beacon_sigma = "s"
angle_unit = "deg"
length_unit = "cm"
[[source]]
kind = "report"
file = "report.csv"
time = "t"
heading = "h"
speed = "v"
depth = "z"
[[source]]
kind = "array_fix"
file = "fix.csv"
time = "t"
beacon = "id"
range = "r"
azimuth = "a"
inclination = "i"
mode = "m"
t_tx = "tx"
time_offset_s = 100.0
[[beacon]]
id = 3
x_m = 10.0
y_m = -5.0
"#;
        let files = [
            ("att.csv", "t,r,p,h\n1.0,10,-20,90\n"),
            ("usbl.csv", "t,id,h,a,e,s\n2.0,3,45,-30,60,150\n"),
            ("report.csv", "t,h,v,z\n3.0,0.5,1.5,30\n"),
            ("fix.csv", "t,id,r,a,i,m,tx\n-96.0,beacon_3,120.5,1.0,2.0,2,-96.08\n"),
        ];
        let log = load("computer", body, &files).unwrap();
        let items = items(&log);
        assert_eq!(items.iter().map(|i| i.t_s).collect::<Vec<_>>(), [1.0, 2.0, 3.0, 4.0]);
        // in the log's frame (ENU, counter-clockwise): the stream turns them to NED
        let Kind::Attitude { roll_rad, pitch_rad, heading_rad } = measurement(&items[0]) else { panic!() };
        assert_abs_diff_eq!(roll_rad, 10f64.to_radians(), epsilon = 1e-12);
        assert_abs_diff_eq!(pitch_rad, -20f64.to_radians(), epsilon = 1e-12);
        assert_abs_diff_eq!(heading_rad, FRAC_PI_2, epsilon = 1e-12);
        let Kind::Bearing { station, station_heading_rad, azimuth_rad, elevation_rad } = measurement(&items[1]) else {
            panic!()
        };
        assert_eq!((station.id, station.sigma_m, station.t_tx_s), (3, 1.5, None));
        assert_abs_diff_eq!(station_heading_rad, PI / 4.0, epsilon = 1e-12);
        assert_abs_diff_eq!(azimuth_rad, -PI / 6.0, epsilon = 1e-12);
        assert_abs_diff_eq!(elevation_rad, PI / 3.0, epsilon = 1e-12);
        assert_eq!(measurement(&items[2]), Kind::Report { heading_rad: 0.5, speed_m_s: 1.5, depth_m: 30.0 });
        // the transmit time on the source's clock, its offset too
        let Kind::ArrayFix { beacon, range_m, azimuth_rad, inclination_rad, mode } = measurement(&items[3]) else {
            panic!()
        };
        assert_eq!((beacon.id, range_m, azimuth_rad, inclination_rad, mode), (3, 120.5, 1.0, 2.0, 2));
        assert_abs_diff_eq!(beacon.t_tx_s.unwrap(), 3.92, epsilon = 1e-12);
        // refused in a file: an own fix, the vehicle of several, a transmit time on a heading
        let own = "[[source]]\nkind = \"own_fix\"\nfile = \"f.csv\"\ntime = \"t\"\nx = \"x\"\ny = \"y\"\n\
                   heading = \"h\"\nspeed = \"v\"\n";
        let vehicle = body.replace("depth = \"z\"", "depth = \"z\"\nvehicle = \"auv\"");
        let t_tx = "[[source]]\nkind = \"heading\"\nfile = \"h.csv\"\ntime = \"t\"\nheading = \"h\"\nt_tx = \"tx\"\n";
        for (name, body, key) in [
            ("own", own, "source[0].kind"),
            ("vehicle", &vehicle, "source[2].vehicle"),
            ("ttx", t_tx, "source[0].t_tx"),
        ] {
            let e = load(name, body, &files).unwrap_err().to_string();
            assert!(e.contains(key), "{name}: {e}");
        }
    }

    /// At equal times: beacon positions, then measurements, then the truth, whatever the
    /// order of the sources; equal ranks in the order of the sources; a sorted source
    /// keeps its rows' order at equal times.
    #[test]
    fn equal_times_follow_the_documented_order() {
        let body = r#"[[source]]
kind = "ground_truth"
file = "truth.csv"
time = "t"
x = "x"
y = "y"
[[source]]
kind = "speed"
file = "speed.csv"
time = "t"
speed = "v"
sort = true
[[source]]
kind = "heading"
file = "heading.csv"
time = "t"
heading = "h"
[[source]]
kind = "beacon_track"
file = "track.csv"
time = "t"
beacon = "id"
x = "x"
y = "y"
"#;
        let files = [
            ("truth.csv", "t,x,y\n1.0,0,0\n"),
            ("speed.csv", "t,v\n1.0,0.3\n0.5,0.1\n1.0,0.4\n"),
            ("heading.csv", "t,h\n1.0,0.2\n"),
            ("track.csv", "t,id,x,y\n1.0,4,5,6\n"),
        ];
        let log = load("order", body, &files).unwrap();
        let order: Vec<String> = items(&log)
            .iter()
            .map(|i| match i.input.clone() {
                Input::Measurement(Kind::Speed { speed_m_s }) => format!("speed {speed_m_s}"),
                Input::Measurement(Kind::Heading { heading_rad }) => format!("heading {heading_rad}"),
                Input::BeaconPosition { .. } => "beacon".into(),
                Input::Truth(_) => "truth".into(),
                other => panic!("{other:?}"),
            })
            .collect();
        assert_eq!(order, ["speed 0.1", "beacon", "speed 0.3", "speed 0.4", "heading 0.2", "truth"]);
    }

    /// Body-frame odometry: forward, lateral and heading-change columns in the source's
    /// units.
    #[test]
    fn body_odometry_is_read_to_si() {
        let body = "[[source]]\nkind = \"body_odometry\"\nfile = \"b.csv\"\ntime = \"t\"\nforward = \"dx\"\n\
                    lateral = \"dy\"\nheading_change = \"dh\"\nlength_unit = \"cm\"\nangle_unit = \"deg\"\n";
        let log = load("body", body, &[("b.csv", "t,dx,dy,dh\n1.0,120,-15,-30\n")]).unwrap();
        let Kind::BodyOdometry { forward_m, lateral_m, heading_change_rad } = measurement(&items(&log)[0]) else {
            panic!()
        };
        assert_abs_diff_eq!(forward_m, 1.2, epsilon = 1e-12);
        assert_abs_diff_eq!(lateral_m, -0.15, epsilon = 1e-12);
        assert_abs_diff_eq!(heading_change_rad, -PI / 6.0, epsilon = 1e-12);
    }

    /// A CSV file without a header row (its first line is data) is refused by that
    /// name, even when a key names a column by a number the first line holds.
    #[test]
    fn a_file_without_a_header_row_is_named_so() {
        let body = "[[source]]\nkind = \"speed\"\nfile = \"s.csv\"\ntime = \"0\"\nspeed = \"1.5\"\n";
        let e = load("headless", body, &[("s.csv", "0,1.5\n1,1.4\n")])
            .and_then(|l| l.items()?.collect::<Result<Vec<_>, _>>());
        let e = e.unwrap_err().to_string();
        assert!(e.contains("s.csv") && e.contains("no header row") && e.contains("(0, 1.5)"), "{e}");
    }

    /// Without `[initial]`, a log starts at its first ground-truth pose and heading (the
    /// documented defaults), with the default sigmas.
    #[test]
    fn initial_is_optional() {
        let toml = "name = \"no-initial\"\n[[source]]\nkind = \"ground_truth\"\nfile = \"t.csv\"\ntime = \"t\"\n\
                    x = \"x\"\ny = \"y\"\nheading = \"h\"\n[[estimators]]\nname = \"dr\"\nkind = \"dead-reckoning\"\n";
        let d = LogDescription::parse(toml, "no-initial.toml").unwrap();
        assert_eq!((d.initial.from, d.initial.heading_from), (InitialFrom::GroundTruth, HeadingFrom::Column));
        assert_eq!((d.initial.position_sigma_m, d.initial.heading_sigma_deg, d.initial.track_m), (1.0, 5.0, 2.0));
        let log = super::super::testing::write_log(
            "log",
            "no-initial",
            toml,
            &[("t.csv", "t,x,y,h\n4.0,1.0,2.0,0.25\n5.0,1.5,2.0,0.25\n")],
        )
        .unwrap();
        assert_eq!(log.initial_pose().unwrap(), (4.0, (1.0, 2.0, 0.25)));
    }

    /// An ENU log stays in its frame through the reader; the session converts it: x east,
    /// y north, z up, heading counter-clockwise from east.
    #[test]
    fn an_enu_log_is_converted_once_at_the_session() {
        let body = r#"frame = "enu"
[[source]]
kind = "ground_truth"
file = "truth.csv"
time = "t"
x = "x"
y = "y"
heading = "h"
[[source]]
kind = "beacon_track"
file = "track.csv"
time = "t"
beacon = "id"
x = "x"
y = "y"
z = "z"
"#;
        let files = [("truth.csv", "t,x,y,h\n1.0,3.0,4.0,0.0\n"), ("track.csv", "t,id,x,y,z\n1.0,1,3.0,4.0,-2.0\n")];
        let log = load("enu", body, &files).unwrap();
        let items = items(&log);
        let Input::BeaconPosition { position, .. } = items[0].input.clone().to_ned(log.frame) else { panic!() };
        assert_eq!(position, Vector3::new(4.0, 3.0, 2.0));
        let Input::Truth(p) = items[1].input.clone().to_ned(log.frame) else { panic!() };
        assert_eq!((p.north_m, p.east_m), (4.0, 3.0));
        assert_abs_diff_eq!(p.heading_rad.unwrap(), FRAC_PI_2, epsilon = 1e-12);
    }

    /// Rows out of time order are refused with the line, unless the source sorts; a
    /// source without rows and a range to an unknown beacon are refused when loading.
    #[test]
    fn bad_sources_are_refused_by_line() {
        let body = "[[source]]\nkind = \"speed\"\nfile = \"speed.csv\"\ntime = \"t\"\nspeed = \"v\"\n";
        let log = load("backwards", body, &[("speed.csv", "t,v\n2.0,1\n1.0,1\n")]).unwrap();
        let e = log.items().unwrap().nth(1).unwrap().unwrap_err().to_string();
        assert!(e.contains("line 3, column `t`: time 1 is before 2"), "{e}");
        let sorted = body.replace("speed = \"v\"", "speed = \"v\"\nsort = true");
        let log = load("sorted", &sorted, &[("speed.csv", "t,v\n2.0,1\n1.0,1\n")]).unwrap();
        assert_eq!(items(&log).iter().map(|i| i.t_s).collect::<Vec<_>>(), [1.0, 2.0]);
        let e = load("empty", body, &[("speed.csv", "t,v\n")]).unwrap_err().to_string();
        assert!(e.ends_with("speed.csv: no rows"), "{e}");
        let range = "[[source]]\nkind = \"range\"\nfile = \"r.csv\"\ntime = \"t\"\nbeacon = \"id\"\nrange = \"r\"\n";
        let e = load("unknown", range, &[("r.csv", "t,id,r\n1.0,9,5\n")]).unwrap_err().to_string();
        assert!(e.contains("line 2, column `id`: beacon 9 is not among the beacons ()"), "{e}");
    }

    /// Times as loggers write them, against epochs worked out by hand: 2021-06-14 00:00:00
    /// UTC is UNIX 1623628800 s. A time of day with a date rolls over at midnight; a
    /// date-time with `Z` or an offset; UNIX milliseconds.
    #[test]
    fn clock_times_become_unix_seconds() {
        let body = r#"[[source]]
kind = "speed"
file = "clock.csv"
time = "t"
time_format = "%H:%M:%S%.f"
date = "2021-06-14"
speed = "v"
[[source]]
kind = "heading"
file = "iso.csv"
time = "t"
time_format = "%Y-%m-%dT%H:%M:%S%.f%:z"
heading = "h"
[[source]]
kind = "depth"
file = "ms.csv"
time = "t"
time_unit = "ms"
depth = "d"
"#;
        let files = [
            ("clock.csv", "t,v\n23:59:59.5,1\n00:00:00.25,2\n"),
            ("iso.csv", "t,h\n2021-06-15T02:00:01.5+02:00,0\n"),
            ("ms.csv", "t,d\n1623628800123,4\n"),
        ];
        let log = load("clock", body, &files).unwrap();
        let day = 1_623_628_800.0;
        let times: Vec<f64> = items(&log).iter().map(|i| i.t_s - day).collect();
        assert_eq!(times.len(), 4);
        let expected = [0.123, 86_399.5, 86_400.25, 86_400.0 + 1.5];
        for (t, e) in times.iter().zip(expected) {
            assert_abs_diff_eq!(*t, e, epsilon = 1e-6);
        }
        // a cell that does not match, and a time of day without its date
        let e = load("clock-bad", body, &[files[0], ("iso.csv", "t,h\n12:00:00,0\n"), files[2]]).unwrap_err();
        assert!(e.to_string().contains("line 2, column `t`: `12:00:00` does not match time_format"), "{e}");
        let no_date = body.replace("date = \"2021-06-14\"\n", "");
        let e = load("clock-nodate", &no_date, &files).unwrap_err().to_string();
        assert!(e.contains("needs the source's `date` key"), "{e}");
    }

    /// `time_order = "drop"`: a row stamped before the one above (a GPS row at .000
    /// between .800 and 13.100) and a row stamped far ahead are dropped and counted; the
    /// rest keep their order.
    #[test]
    fn rows_out_of_order_are_dropped_and_counted() {
        let body =
            "[[source]]\nkind = \"speed\"\nfile = \"s.csv\"\ntime = \"t\"\nspeed = \"v\"\ntime_order = \"drop\"\n";
        let csv = "t,v\n12.6,1\n12.8,2\n12.0,3\n13.1,4\n99.0,5\n13.3,6\n13.5,7\n";
        let log = load("drop", body, &[("s.csv", csv)]).unwrap();
        let mut stream = log.items().unwrap();
        let speeds: Vec<f64> = (&mut stream)
            .map(|i| match measurement(&i.unwrap()) {
                Kind::Speed { speed_m_s } => speed_m_s,
                other => panic!("{other:?}"),
            })
            .collect();
        assert_eq!(speeds, [1.0, 2.0, 4.0, 6.0, 7.0]);
        assert_eq!(stream.dropped().len(), 1);
        assert_eq!(stream.dropped()[0].dropped, 2);
    }

    /// Latitude and longitude on WGS-84 about `[origin]`, against the closed-form radii of
    /// curvature (meridian M, prime vertical N) for a small step at 45 deg: north = M dphi,
    /// east = N cos(phi) dlambda. Scaled integers (1e-7 deg) read the same; in an ENU log
    /// x is east.
    #[test]
    fn latitude_and_longitude_become_local_metres() {
        let (a, f) = (6_378_137.0, 1.0 / 298.257_223_563);
        let e2 = f * (2.0 - f);
        let phi = 45f64.to_radians();
        let w = (1.0 - e2 * phi.sin().powi(2)).sqrt();
        let (m, n) = (a * (1.0 - e2) / w.powi(3), a / w);
        let (dphi, dlam) = (0.0004f64.to_radians(), 0.0006f64.to_radians());
        let (north, east) = (m * dphi, n * phi.cos() * dlam);
        let body = r#"frame = "enu"
[origin]
lat_deg = 45.0
lon_deg = 7.0
[[source]]
kind = "ground_truth"
file = "gps.csv"
time = "t"
lat = "lat"
lon = "lon"
latlon_unit = "deg1e7"
[beacons]
file = "b.csv"
id = "id"
lat = "la"
lon = "lo"
"#;
        let files = [("gps.csv", "t,lat,lon\n1.0,450004000,70006000\n"), ("b.csv", "id,la,lo\n3,45.0004,7.0006\n")];
        let log = load("latlon", body, &files).unwrap();
        let b = log.beacons[&3];
        assert_abs_diff_eq!(b.x, east, epsilon = 2e-3);
        assert_abs_diff_eq!(b.y, north, epsilon = 2e-3);
        let Input::Truth(p) = items(&log)[0].input else { panic!() };
        assert_abs_diff_eq!(p.north_m, b.x, epsilon = 1e-6); // the log frame's x: east
        assert_abs_diff_eq!(p.east_m, b.y, epsilon = 1e-6);
        // without [origin], the first latitude and longitude (the beacons file) is 0, 0
        let log = load("latlon-first", &body.replace("[origin]\nlat_deg = 45.0\nlon_deg = 7.0\n", ""), &files).unwrap();
        assert_abs_diff_eq!(log.beacons[&3].norm(), 0.0, epsilon = 1e-9);
    }

    /// Heading conventions per source: a compass (clockwise from north) in an ENU log is
    /// `heading_clockwise = true`, `heading_offset_deg = 90`; its turns and lateral axis
    /// flip with it, so that the session sees the same NED values as from a NED source.
    #[test]
    fn heading_conventions_are_keys() {
        let body = r#"frame = "enu"
[[source]]
kind = "heading"
file = "compass.csv"
time = "t"
heading = "h"
angle_unit = "deg"
heading_clockwise = true
heading_offset_deg = 90.0
[[source]]
kind = "body_odometry"
file = "odo.csv"
time = "t"
forward = "dx"
lateral = "dy"
heading_change = "dh"
heading_clockwise = true
"#;
        let files = [("compass.csv", "t,h\n1.0,0\n2.0,90\n3.0,-30\n"), ("odo.csv", "t,dx,dy,dh\n4.0,1.0,0.2,0.1\n")];
        let log = load("compass", body, &files).unwrap();
        let ned: Vec<Kind> = items(&log)
            .iter()
            .map(|i| measurement(&Item { t_s: i.t_s, input: i.input.clone().to_ned(log.frame) }))
            .collect();
        for (k, expected_deg) in ned.iter().zip([0.0, 90.0, -30.0]) {
            let Kind::Heading { heading_rad } = k else { panic!("{k:?}") };
            assert_abs_diff_eq!(*heading_rad, f64::to_radians(expected_deg), epsilon = 1e-12);
        }
        let Kind::BodyOdometry { forward_m, lateral_m, heading_change_rad } = ned[3] else { panic!() };
        assert_eq!((forward_m, lateral_m, heading_change_rad), (1.0, 0.2, 0.1));
    }

    /// The new keys refuse what cannot be meant, naming the key.
    #[test]
    fn time_and_position_keys_are_checked() {
        let parse = |body: &str| {
            let toml = format!("name = \"k\"\n{body}\n[[estimators]]\nname = \"dr\"\nkind = \"dead-reckoning\"\n");
            LogDescription::parse(&toml, "k.toml").map(|_| ()).unwrap_err().to_string()
        };
        let truth = "[[source]]\nkind = \"ground_truth\"\nfile = \"t.csv\"\ntime = \"t\"\n";
        let e = parse(&format!("{truth}x = \"x\"\ny = \"y\"\nlat = \"la\"\nlon = \"lo\"\n"));
        assert!(e.contains("source[0].x") && e.contains("one pair, not both"), "{e}");
        let e = parse(&format!("{truth}lat = \"la\"\n"));
        assert!(e.contains("source[0].lat"), "{e}");
        let e = parse(&format!("{truth}x = \"x\"\ny = \"y\"\ndate = \"2021-06-14\"\n"));
        assert!(e.contains("source[0].date"), "{e}");
        let e = parse(&format!("{truth}x = \"x\"\ny = \"y\"\ntime_format = \"%H:%Q\"\n"));
        assert!(e.contains("source[0].time_format"), "{e}");
        let e = parse(&format!("{truth}x = \"x\"\ny = \"y\"\nsort = true\ntime_order = \"drop\"\n"));
        assert!(e.contains("source[0].sort"), "{e}");
        let e = parse(
            "[[source]]\nkind = \"speed\"\nfile = \"s.csv\"\ntime = \"t\"\nspeed = \"v\"\nheading_clockwise = true\n",
        );
        assert!(e.contains("source[0].heading_clockwise"), "{e}");
        let e = parse(
            "[[source]]\nkind = \"speed\"\nfile = \"s.csv\"\ntime = \"t\"\nspeed = \"v\"\nincrement_frame = \"start\"\n",
        );
        assert!(e.contains("source[0].increment_frame") && e.contains("odometry and body_odometry"), "{e}");
        let e = parse(&format!("{truth}x = \"x\"\ny = \"y\"\nincrement_frame = \"end\"\n"));
        assert!(e.contains("increment_frame") && e.contains("start"), "{e}");
        let e = parse("[[beacon]]\nid = 1\nx_m = 1.0\n");
        assert!(e.contains("beacon[0].x_m"), "{e}");
        let e = parse("[origin]\nlat_deg = 95.0\nlon_deg = 0.0\n");
        assert!(e.contains("origin"), "{e}");
    }

    /// `[noise]`: every estimator takes its keys unless it gives its own; a bad value is
    /// refused by its key.
    #[test]
    fn noise_table_is_inherited_and_overridden() {
        let toml = "name = \"n\"\n[noise]\nrange_sigma_m = 0.7\nheading_walk_deg_per_sqrt_m = 0.2\n\
                    [[estimators]]\nname = \"a\"\nkind = \"range-ekf\"\n\
                    [[estimators]]\nname = \"b\"\nkind = \"range-ekf\"\nrange_sigma_m = 2.0\n";
        let d = LogDescription::parse(toml, "n.toml").unwrap();
        let (a, b) = (d.estimators[0].planar_config().noise, d.estimators[1].planar_config().noise);
        assert_eq!((a.range_sigma_m, b.range_sigma_m), (0.7, 2.0));
        assert_abs_diff_eq!(a.heading_walk_rad_per_sqrt_m, 0.2f64.to_radians(), epsilon = 1e-15);
        assert_abs_diff_eq!(b.heading_walk_rad_per_sqrt_m, 0.2f64.to_radians(), epsilon = 1e-15);
        let e = LogDescription::parse(&toml.replace("0.7", "-1.0"), "n.toml").unwrap_err().to_string();
        assert!(e.contains("noise.range_sigma_m"), "{e}");
    }

    /// A DVL: forward and lateral speeds and a yaw rate in the source's units, read to
    /// SI; in an ENU log the lateral speed and yaw rate flip at the session (left-handed
    /// turns become NED's).
    #[test]
    fn body_velocity_is_read_to_si() {
        let body = "frame = \"enu\"\n[[source]]\nkind = \"body_velocity\"\nfile = \"dvl.csv\"\ntime = \"t\"\n\
                    forward_speed = \"u\"\nlateral_speed = \"v\"\nyaw_rate = \"r\"\nlength_unit = \"cm\"\nangle_unit = \"deg\"\n";
        let log = load("dvl", body, &[("dvl.csv", "t,u,v,r\n1.0,120,-15,-30\n")]).unwrap();
        let item = &items(&log)[0];
        let Kind::BodyVelocity { nu } = measurement(item) else { panic!() };
        assert_abs_diff_eq!(nu[0], 1.2, epsilon = 1e-12);
        assert_abs_diff_eq!(nu[1], -0.15, epsilon = 1e-12);
        assert_abs_diff_eq!(nu[5], -PI / 6.0, epsilon = 1e-12);
        let Kind::BodyVelocity { nu } = measurement(&Item { t_s: 1.0, input: item.input.clone().to_ned(log.frame) })
        else {
            panic!()
        };
        assert_abs_diff_eq!(nu[1], 0.15, epsilon = 1e-12);
        assert_abs_diff_eq!(nu[5], PI / 6.0, epsilon = 1e-12);
    }
}
