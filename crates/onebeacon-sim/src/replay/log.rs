//! The log description (TOML) and the loading of its CSV files into one time-ordered
//! stream. Every error is one line naming the file, the line, the column or key and
//! what was expected.

use crate::scenario::EstimatorSpec;
use crate::scenario::load::deserialize;
use nalgebra::Vector3;
use onebeacon::geo::Frame;
use onebeacon::nav::Kind;
use onebeacon::nav::session::{Input, Item, Limits, TruthPose, resolve_beacon};
use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Why a log could not be loaded: one line each.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    #[error(transparent)]
    Description(#[from] crate::ScenarioError),
    #[error("{file}: {message}")]
    File { file: String, message: String },
    #[error("{file} line {line}, column `{column}`: {message}")]
    Cell { file: String, line: u64, column: String, message: String },
}

/// The frame of the log's x, y, z and headings (`frame` key).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FrameKey {
    #[default]
    Ned,
    Enu,
}

impl From<FrameKey> for Frame {
    fn from(f: FrameKey) -> Self {
        match f {
            FrameKey::Ned => Frame::Ned,
            FrameKey::Enu => Frame::Enu,
        }
    }
}

/// What a CSV source holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SourceKind {
    Odometry,
    BodyOdometry,
    Speed,
    Heading,
    SpeedHeading,
    Depth,
    Range,
    Doppler,
    BeaconTrack,
    GroundTruth,
}

impl SourceKind {
    /// The column keys this kind needs, and those it may have.
    pub(crate) fn columns(self) -> (&'static [&'static str], &'static [&'static str]) {
        match self {
            SourceKind::Odometry => (&["distance", "heading_change"], &[]),
            SourceKind::BodyOdometry => (&["forward", "lateral", "heading_change"], &[]),
            SourceKind::Speed => (&["speed"], &[]),
            SourceKind::Heading => (&["heading"], &[]),
            SourceKind::SpeedHeading => (&["speed", "heading"], &[]),
            SourceKind::Depth => (&["depth"], &[]),
            SourceKind::Range => (&["beacon", "range"], &[]),
            SourceKind::Doppler => (&["beacon", "radial_speed"], &[]),
            SourceKind::BeaconTrack => (&["beacon", "x", "y"], &["z"]),
            SourceKind::GroundTruth => (&["x", "y"], &["heading"]),
        }
    }
}

#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LengthUnit {
    #[default]
    M,
    Cm,
    Mm,
    Km,
}

impl LengthUnit {
    fn metres(self) -> f64 {
        match self {
            LengthUnit::M => 1.0,
            LengthUnit::Cm => 0.01,
            LengthUnit::Mm => 0.001,
            LengthUnit::Km => 1000.0,
        }
    }
}

#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AngleUnit {
    #[default]
    Rad,
    Deg,
}

impl AngleUnit {
    fn radians(self) -> f64 {
        match self {
            AngleUnit::Rad => 1.0,
            AngleUnit::Deg => std::f64::consts::PI / 180.0,
        }
    }
}

/// One CSV file: its kind, the time column and the column of each quantity.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Source {
    pub kind: SourceKind,
    /// Relative to the log description's directory.
    pub file: PathBuf,
    /// The time column, seconds.
    pub time: String,
    /// Added to every time of this file, s.
    #[serde(default)]
    pub time_offset_s: f64,
    #[serde(default)]
    pub length_unit: LengthUnit,
    #[serde(default)]
    pub angle_unit: AngleUnit,
    /// Sort the rows by time instead of refusing rows out of order.
    #[serde(default)]
    pub sort: bool,
    pub distance: Option<String>,
    pub heading_change: Option<String>,
    pub forward: Option<String>,
    pub lateral: Option<String>,
    pub speed: Option<String>,
    pub heading: Option<String>,
    pub depth: Option<String>,
    pub beacon: Option<String>,
    pub range: Option<String>,
    pub radial_speed: Option<String>,
    pub x: Option<String>,
    pub y: Option<String>,
    pub z: Option<String>,
}

impl Source {
    pub(crate) fn column(&self, key: &str) -> Option<&String> {
        match key {
            "distance" => self.distance.as_ref(),
            "heading_change" => self.heading_change.as_ref(),
            "forward" => self.forward.as_ref(),
            "lateral" => self.lateral.as_ref(),
            "speed" => self.speed.as_ref(),
            "heading" => self.heading.as_ref(),
            "depth" => self.depth.as_ref(),
            "beacon" => self.beacon.as_ref(),
            "range" => self.range.as_ref(),
            "radial_speed" => self.radial_speed.as_ref(),
            "x" => self.x.as_ref(),
            "y" => self.y.as_ref(),
            "z" => self.z.as_ref(),
            _ => None,
        }
    }
}

pub(crate) const COLUMN_KEYS: [&str; 13] = [
    "distance",
    "heading_change",
    "forward",
    "lateral",
    "speed",
    "heading",
    "depth",
    "beacon",
    "range",
    "radial_speed",
    "x",
    "y",
    "z",
];

/// Fixed beacon positions from a CSV file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeaconTable {
    pub file: PathBuf,
    pub id: String,
    pub x: String,
    pub y: String,
    pub z: Option<String>,
    #[serde(default)]
    pub length_unit: LengthUnit,
}

/// One fixed beacon given inline.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeaconEntry {
    pub id: u32,
    pub x_m: f64,
    pub y_m: f64,
    #[serde(default)]
    pub z_m: f64,
}

#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InitialFrom {
    /// The first ground-truth pose.
    #[default]
    GroundTruth,
    /// `x_m`, `y_m`, `heading_deg`.
    Given,
}

#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HeadingFrom {
    /// The ground truth's heading column.
    #[default]
    Column,
    /// The direction of the ground-truth track over its first `track_m` metres (when
    /// the heading column is missing or not to be trusted); replay only.
    Track,
}

/// Where the estimators start.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Initial {
    #[serde(default)]
    pub from: InitialFrom,
    #[serde(default)]
    pub heading_from: HeadingFrom,
    #[serde(default = "default_track_m")]
    pub track_m: f64,
    pub x_m: Option<f64>,
    pub y_m: Option<f64>,
    pub heading_deg: Option<f64>,
    /// Initial standard deviations (`sigma_position_m`, `sigma_heading_deg`, the old
    /// names, are read too).
    #[serde(default = "default_position_sigma_m", alias = "sigma_position_m")]
    pub position_sigma_m: f64,
    #[serde(default = "default_heading_sigma_deg", alias = "sigma_heading_deg")]
    pub heading_sigma_deg: f64,
}

/// Left out, `[initial]` starts from the first ground-truth pose and its heading column.
impl Default for Initial {
    fn default() -> Self {
        Self {
            from: InitialFrom::default(),
            heading_from: HeadingFrom::default(),
            track_m: default_track_m(),
            x_m: None,
            y_m: None,
            heading_deg: None,
            position_sigma_m: default_position_sigma_m(),
            heading_sigma_deg: default_heading_sigma_deg(),
        }
    }
}

impl Initial {
    /// The given pose in NED (N, E, psi) when `from = "given"`.
    pub fn given_pose(&self, frame: Frame) -> Option<(f64, f64, f64)> {
        if self.from != InitialFrom::Given {
            return None;
        }
        let p = frame.to_ned(self.x_m?, self.y_m?, 0.0);
        Some((p.x, p.y, frame.heading_to_ned(self.heading_deg?.to_radians())))
    }
}

fn default_track_m() -> f64 {
    2.0
}
fn default_position_sigma_m() -> f64 {
    1.0
}
fn default_heading_sigma_deg() -> f64 {
    5.0
}

/// The log description file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LogDescription {
    pub name: String,
    #[serde(default)]
    pub description: String,
    #[serde(default)]
    pub frame: FrameKey,
    #[serde(default, rename = "source")]
    pub sources: Vec<Source>,
    pub beacons: Option<BeaconTable>,
    #[serde(default, rename = "beacon")]
    pub beacon_list: Vec<BeaconEntry>,
    #[serde(default)]
    pub initial: Initial,
    /// `[[estimators]]` as in scenarios (`[[estimator]]`, the old name, is read too).
    #[serde(alias = "estimator")]
    pub estimators: Vec<EstimatorSpec>,
    /// What an item must respect before any estimator sees it.
    #[serde(default)]
    pub limits: Limits,
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
    tracked: BTreeSet<u32>,
    base: PathBuf,
}

impl LogDescription {
    /// Reads and checks a log description (the CSV files are not read).
    pub fn load(path: &Path) -> Result<Self, LogError> {
        let name = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|e| LogError::File { file: name.clone(), message: e.to_string() })?;
        Self::parse(&text, &name)
    }

    /// Parses and checks the text of a log description; `name` names it in errors.
    pub fn parse(text: &str, name: &str) -> Result<Self, LogError> {
        let d: LogDescription = deserialize(text, name)?;
        crate::scenario::validate::validate_log(&d)
            .map_err(|v| LogError::Description(crate::scenario::load::invalid(name, v)))?;
        Ok(d)
    }

    /// Fixed beacons (the log's frame): the `[beacons]` file and the inline `[[beacon]]`
    /// entries.
    pub fn fixed_beacons(&self, base: &Path) -> Result<BTreeMap<u32, Vector3<f64>>, LogError> {
        let mut out = BTreeMap::new();
        if let Some(t) = &self.beacons {
            let mut table = Table::open(base, &t.file)?;
            let (id, x, y) = (table.index(&t.id)?, table.index(&t.x)?, table.index(&t.y)?);
            let z = t.z.as_ref().map(|z| table.index(z)).transpose()?;
            let scale = t.length_unit.metres();
            while let Some(row) = table.next_row()? {
                let b = row.beacon_id(id)?;
                let z = z.map_or(Ok(0.0), |z| row.number(z))?;
                let p = Vector3::new(row.number(x)?, row.number(y)?, z) * scale;
                if out.insert(b, p).is_some() {
                    return Err(row.error(id, format!("beacon {b} appears twice")));
                }
            }
        }
        for b in &self.beacon_list {
            if out.insert(b.id, Vector3::new(b.x_m, b.y_m, b.z_m)).is_some() {
                return Err(LogError::File {
                    file: "[[beacon]]".into(),
                    message: format!("beacon {} is given twice", b.id),
                });
            }
        }
        Ok(out)
    }
}

impl Log {
    /// Loads a log description, its fixed beacons and the beacon ids of its tracks,
    /// and opens every file it names (relative to its directory): headers, columns and
    /// first rows are checked here; a later bad row is an error of [`Log::items`].
    pub fn load(path: &Path) -> Result<Self, LogError> {
        let description = LogDescription::load(path)?;
        let base = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        let frame = Frame::from(description.frame);
        let beacons = description.fixed_beacons(&base)?;
        // beacon tracks first, so that ranges may name tracked beacons
        let (mut tracked, none) = (BTreeSet::new(), BTreeSet::new());
        for s in description.sources.iter().filter(|s| s.kind == SourceKind::BeaconTrack) {
            let mut rows = SourceRows::open(&base, s, &beacons, &none)?;
            while let Some(item) = rows.next_item()? {
                if let Input::BeaconPosition { beacon_id, .. } = item.input {
                    tracked.insert(beacon_id);
                }
            }
        }
        let log = Self { description, frame, beacons, tracked, base };
        log.items()?;
        Ok(log)
    }

    /// The merged, time-ordered stream of every source. At equal times: beacon
    /// positions, then measurements, then the truth; then in the order of the sources.
    pub fn items(&self) -> Result<Items<'_>, LogError> {
        let (mut heads, mut rows) = (Vec::new(), Vec::new());
        for s in &self.description.sources {
            let mut source = SourceRows::open(&self.base, s, &self.beacons, &self.tracked)?;
            let head = source
                .next_item()?
                .ok_or_else(|| LogError::File { file: source.table.file.clone(), message: "no rows".into() })?;
            if s.sort {
                let mut all = vec![head];
                while let Some(item) = source.next_item()? {
                    all.push(item);
                }
                all.sort_by(|a, b| a.t_s.total_cmp(&b.t_s)); // stable: equal times keep their rows' order
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
        Ok(Items { heads, rows, ranks, error: None })
    }

    /// Every beacon of the log: fixed ones and those with a track.
    pub fn beacon_ids(&self) -> BTreeSet<u32> {
        self.beacons.keys().chain(&self.tracked).copied().collect()
    }

    /// Whether the log has a ground truth.
    pub fn has_truth(&self) -> bool {
        self.description.sources.iter().any(|s| s.kind == SourceKind::GroundTruth)
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
            return Ok((first_t, pose));
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

/// The rows of one source still to come.
enum Rows<'a> {
    Streamed(Box<SourceRows<'a>>),
    /// A source with `sort = true`, read whole and sorted.
    Sorted(std::vec::IntoIter<Item>),
}

/// The merged stream of a log's sources ([`Log::items`]): each source is read as the
/// merge needs its next row. A bad row ends the stream with its error, given right after
/// the row above it.
pub struct Items<'a> {
    /// The next item of each source (in the description's order), None once it is done.
    heads: Vec<Option<Item>>,
    rows: Vec<Rows<'a>>,
    /// 0 beacon positions, 1 measurements, 2 ground truth.
    ranks: Vec<u8>,
    /// A source's error, given after the item in hand.
    error: Option<LogError>,
}

impl Iterator for Items<'_> {
    type Item = Result<Item, LogError>;

    fn next(&mut self) -> Option<Self::Item> {
        if let Some(e) = self.error.take() {
            self.heads.iter_mut().for_each(|h| *h = None);
            return Some(Err(e));
        }
        let key = |i: usize| self.heads[i].as_ref().map(|h| (h.t_s, self.ranks[i], i));
        let next = (0..self.heads.len())
            .filter_map(key)
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)))?
            .2;
        let refill = match &mut self.rows[next] {
            Rows::Streamed(rows) => rows.next_item(),
            Rows::Sorted(rows) => Ok(rows.next()),
        };
        match refill {
            Ok(head) => std::mem::replace(&mut self.heads[next], head).map(Ok),
            Err(e) => {
                // the item in hand first, the error at the next call, then the end
                self.error = Some(e);
                self.heads[next].take().map(Ok)
            }
        }
    }
}

/// A CSV file being read, with its header.
struct Table {
    file: String,
    header: Vec<String>,
    reader: csv::Reader<LineLimited<std::fs::File>>,
    record: csv::StringRecord,
}

/// Longest CSV line read, bytes: a file that is not a CSV (a device, a binary) is
/// refused with an error instead of filling the memory.
const MAX_CSV_LINE_BYTES: usize = 1 << 20;

/// A reader that fails on a line longer than [`MAX_CSV_LINE_BYTES`].
struct LineLimited<R> {
    inner: R,
    line: usize,
}

impl<R: std::io::Read> std::io::Read for LineLimited<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        for &b in &buf[..n] {
            self.line = if b == b'\n' { 0 } else { self.line + 1 };
            if self.line > MAX_CSV_LINE_BYTES {
                return Err(std::io::Error::other(format!(
                    "a line longer than {MAX_CSV_LINE_BYTES} bytes: not a CSV file"
                )));
            }
        }
        Ok(n)
    }
}

/// One row of a [`Table`].
struct Row<'a> {
    table: &'a Table,
    line: u64,
}

impl Table {
    fn open(base: &Path, file: &Path) -> Result<Self, LogError> {
        let path = base.join(file);
        let name = path.display().to_string();
        let f = std::fs::File::open(&path)
            .map_err(|e| LogError::File { file: name.clone(), message: format!("cannot open: {e}") })?;
        let mut reader = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(LineLimited { inner: f, line: 0 });
        let header = reader
            .headers()
            .map_err(|e| LogError::File { file: name.clone(), message: format!("cannot read the header: {e}") })?
            .iter()
            .map(String::from)
            .collect();
        Ok(Self { file: name, header, reader, record: csv::StringRecord::new() })
    }

    fn index(&self, column: &str) -> Result<usize, LogError> {
        self.header.iter().position(|h| h == column).ok_or_else(|| LogError::File {
            file: self.file.clone(),
            message: format!("no column `{column}` (columns: {})", self.header.join(", ")),
        })
    }

    fn next_row(&mut self) -> Result<Option<Row<'_>>, LogError> {
        match self.reader.read_record(&mut self.record) {
            Ok(false) => Ok(None),
            Ok(true) => {
                let line = self.record.position().map_or(0, |p| p.line());
                Ok(Some(Row { table: self, line }))
            }
            Err(e) => Err(LogError::File { file: self.file.clone(), message: format!("malformed CSV: {e}") }),
        }
    }
}

impl Row<'_> {
    fn error(&self, column: usize, message: String) -> LogError {
        LogError::Cell {
            file: self.table.file.clone(),
            line: self.line,
            column: self.table.header[column].clone(),
            message,
        }
    }

    fn cell(&self, column: usize) -> &str {
        self.table.record.get(column).unwrap_or("")
    }

    fn number(&self, column: usize) -> Result<f64, LogError> {
        let cell = self.cell(column);
        match cell.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(self.error(column, format!("`{cell}` is not finite; a finite number is expected"))),
            Err(_) => Err(self.error(column, format!("`{cell}` is not a number"))),
        }
    }

    fn beacon_id(&self, column: usize) -> Result<u32, LogError> {
        let cell = self.cell(column);
        cell.parse::<u32>()
            .map_err(|_| self.error(column, format!("`{cell}` is not a beacon id (a non-negative integer)")))
    }
}

/// One source read row by row into stream items (the log's frame, SI units).
struct SourceRows<'a> {
    source: &'a Source,
    table: Table,
    time: usize,
    cols: BTreeMap<&'static str, usize>,
    beacons: &'a BTreeMap<u32, Vector3<f64>>,
    tracked: &'a BTreeSet<u32>,
    previous: Option<f64>,
    /// The second item of a `speed_heading` row.
    pending: Option<Item>,
}

impl<'a> SourceRows<'a> {
    fn open(
        base: &Path,
        source: &'a Source,
        beacons: &'a BTreeMap<u32, Vector3<f64>>,
        tracked: &'a BTreeSet<u32>,
    ) -> Result<Self, LogError> {
        let table = Table::open(base, &source.file)?;
        let time = table.index(&source.time)?;
        let cols = COLUMN_KEYS
            .iter()
            .filter_map(|k| source.column(k).map(|c| table.index(c).map(|c| (*k, c))))
            .collect::<Result<_, _>>()?;
        Ok(Self { source, table, time, cols, beacons, tracked, previous: None, pending: None })
    }

    /// The next item, None at the end of the file.
    fn next_item(&mut self) -> Result<Option<Item>, LogError> {
        if let Some(item) = self.pending.take() {
            return Ok(Some(item));
        }
        let (s, cols, time) = (self.source, &self.cols, self.time);
        let (beacons, tracked) = (self.beacons, self.tracked);
        let previous = self.previous;
        let Some(row) = self.table.next_row()? else { return Ok(None) };
        let t = row.number(time)? + s.time_offset_s;
        if let Some(p) = previous.filter(|p| t < *p && !s.sort) {
            return Err(row.error(
                time,
                format!("time {t} is before {p} on the row above; rows must be in time order (or set sort = true on this source)"),
            ));
        }
        let (len, ang) = (s.length_unit.metres(), s.angle_unit.radians());
        let num = |k: &str| row.number(cols[k]);
        let beacon = || {
            let id = row.beacon_id(cols["beacon"])?;
            resolve_beacon(id, beacons, tracked).map_err(|m| row.error(cols["beacon"], m))
        };
        let measurement = |m: Kind| Item { t_s: t, input: Input::Measurement(m) };
        let mut pending = None;
        let item = match s.kind {
            SourceKind::Odometry => measurement(Kind::Odometry {
                distance_m: num("distance")? * len,
                heading_change_rad: num("heading_change")? * ang,
            }),
            SourceKind::BodyOdometry => measurement(Kind::BodyOdometry {
                forward_m: num("forward")? * len,
                lateral_m: num("lateral")? * len,
                heading_change_rad: num("heading_change")? * ang,
            }),
            SourceKind::Speed => measurement(Kind::Speed { speed_m_s: num("speed")? * len }),
            SourceKind::Heading => measurement(Kind::Heading { heading_rad: num("heading")? * ang }),
            SourceKind::SpeedHeading => {
                pending = Some(measurement(Kind::Heading { heading_rad: num("heading")? * ang }));
                measurement(Kind::Speed { speed_m_s: num("speed")? * len })
            }
            SourceKind::Depth => measurement(Kind::Depth { depth_m: num("depth")? * len }),
            SourceKind::Range => measurement(Kind::Range { beacon: beacon()?, range_m: num("range")? * len }),
            SourceKind::Doppler => {
                measurement(Kind::Doppler { beacon: beacon()?, radial_speed_m_s: num("radial_speed")? * len })
            }
            SourceKind::BeaconTrack => {
                let beacon_id = row.beacon_id(cols["beacon"])?;
                let z = cols.get("z").map_or(Ok(0.0), |&c| row.number(c))?;
                let position = Vector3::new(num("x")?, num("y")?, z) * len;
                Item { t_s: t, input: Input::BeaconPosition { beacon_id, position } }
            }
            SourceKind::GroundTruth => {
                let heading_rad = cols.get("heading").map(|&c| row.number(c)).transpose()?.map(|h| h * ang);
                let pose = TruthPose { north_m: num("x")? * len, east_m: num("y")? * len, heading_rad };
                Item { t_s: t, input: Input::Truth(pose) }
            }
        };
        self.previous = Some(t);
        self.pending = pending;
        Ok(Some(item))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;
    use onebeacon::nav::BeaconFix;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// A log description (`body`, then a dead-reckoning estimator) and its CSV files in
    /// a directory of their own, loaded.
    fn load(name: &str, body: &str, files: &[(&str, &str)]) -> Result<Log, LogError> {
        let dir = std::env::temp_dir().join(format!("onebeacon-log-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (file, text) in files {
            std::fs::write(dir.join(file), text).unwrap();
        }
        let toml = format!(
            "name = \"{name}\"\n{body}\n[initial]\nfrom = \"given\"\nx_m = 0.0\ny_m = 0.0\nheading_deg = 0.0\n\
             [[estimators]]\nname = \"dr\"\nkind = \"dead-reckoning\"\n"
        );
        std::fs::write(dir.join("log.toml"), toml).unwrap();
        Log::load(&dir.join("log.toml"))
    }

    fn items(log: &Log) -> Vec<Item> {
        log.items().unwrap().map(Result::unwrap).collect()
    }

    fn measurement(item: &Item) -> Kind {
        match item.input {
            Input::Measurement(m) => m,
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
            .map(|i| match i.input {
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

    /// Without `[initial]`, a log starts at its first ground-truth pose and heading (the
    /// documented defaults), with the default sigmas.
    #[test]
    fn initial_is_optional() {
        let toml = "name = \"no-initial\"\n[[source]]\nkind = \"ground_truth\"\nfile = \"t.csv\"\ntime = \"t\"\n\
                    x = \"x\"\ny = \"y\"\nheading = \"h\"\n[[estimators]]\nname = \"dr\"\nkind = \"dead-reckoning\"\n";
        let d = LogDescription::parse(toml, "no-initial.toml").unwrap();
        assert_eq!((d.initial.from, d.initial.heading_from), (InitialFrom::GroundTruth, HeadingFrom::Column));
        assert_eq!((d.initial.position_sigma_m, d.initial.heading_sigma_deg, d.initial.track_m), (1.0, 5.0, 2.0));
        let dir = std::env::temp_dir().join(format!("onebeacon-log-{}-no-initial", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("t.csv"), "t,x,y,h\n4.0,1.0,2.0,0.25\n5.0,1.5,2.0,0.25\n").unwrap();
        std::fs::write(dir.join("log.toml"), toml).unwrap();
        let log = Log::load(&dir.join("log.toml")).unwrap();
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
        let Input::BeaconPosition { position, .. } = items[0].input.to_ned(log.frame) else { panic!() };
        assert_eq!(position, Vector3::new(4.0, 3.0, 2.0));
        let Input::Truth(p) = items[1].input.to_ned(log.frame) else { panic!() };
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
}
