//! One source's rows into stream items: its clock (time cells to seconds), units and
//! frame to SI and the log's frame, and the rows dropped out of time order.

use super::cell::Cell;
use super::error::LogError;
use super::geodesy::Geodetic;
use super::schema::{COLUMN_KEYS, IncrementFrame, Source, SourceKind, TimeOrder};
use super::table::Table;
use crate::geo::Frame;
use crate::io::jsonl::Line;
use crate::nav::Kind;
use crate::nav::session::{Input, Item, TruthPose, resolve_beacon};
use crate::vehicle::OwnFix;
use nalgebra::{Vector2, Vector3};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// One source read row by row into stream items (the log's frame, SI units).
pub(super) struct SourceRows<'a> {
    pub(super) source: &'a Source,
    pub(super) table: Table,
    time: usize,
    cols: BTreeMap<&'static str, usize>,
    beacons: &'a BTreeMap<u32, Vector3<f64>>,
    tracked: &'a BTreeSet<u32>,
    geodetic: Option<Geodetic>,
    clock: Clock,
    pub(super) order: TimeOrder,
    /// +1, or -1 when the file's headings turn against the log frame's sense.
    sense: f64,
    /// The time of the row above.
    previous: Option<f64>,
    /// The second item of a `speed_heading` row.
    pending: Option<Line>,
    /// `time_order = "drop"`: the row read ahead, the time of the last row kept, the rows
    /// dropped, and an error met while reading ahead (given after the row in hand).
    ahead: Option<RowItems>,
    kept: Option<f64>,
    pub(super) dropped: usize,
    pub(super) kept_rows: usize,
    error: Option<LogError>,
    /// A live topic's: a beacon not among the fixed ones is left for the stream to
    /// resolve (it may be tracked by then).
    live: bool,
}

/// The rows of a `time_order = "drop"` source: dropped out of time order, and kept.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Dropped {
    pub file: String,
    pub dropped: usize,
    pub kept: usize,
}

impl Dropped {
    /// Whether the source lost more rows than it kept: its time column is suspect, and
    /// so is a score made of what is left.
    pub fn lost_most(&self) -> bool {
        self.dropped > self.kept
    }
}

/// The one or two lines of a row: items (about a vehicle when the row names it), or an
/// own fix.
type RowItems = (Line, Option<Line>);

/// How a source's time cells become seconds.
pub(super) enum Clock {
    Number(f64),
    /// A strftime pattern for a date and time (with an offset when `zoned`).
    DateTime {
        format: String,
        zoned: bool,
    },
    /// A strftime pattern for a time of day, the day of the first row (UNIX seconds),
    /// and the days passed since (a time of day 12 h before the one above is the next
    /// day's).
    TimeOfDay {
        format: String,
        day_s: f64,
        days: f64,
        last_s: Option<f64>,
    },
}

impl Clock {
    fn new(s: &Source) -> Self {
        match (&s.time_format, &s.date) {
            (None, _) => Clock::Number(s.time_unit.seconds()),
            (Some(format), None) => {
                let zoned = ["%z", "%:z", "%::z", "%:::z", "%#z"].iter().any(|z| format.contains(z));
                Clock::DateTime { format: format.clone(), zoned }
            }
            (Some(format), Some(date)) => {
                let day = chrono::NaiveDate::parse_from_str(date, "%Y-%m-%d").expect("validated: date is YYYY-MM-DD");
                let day_s = day.and_time(chrono::NaiveTime::MIN).and_utc().timestamp() as f64;
                Clock::TimeOfDay { format: format.clone(), day_s, days: 0.0, last_s: None }
            }
        }
    }

    /// The time of a cell, seconds; an error message when it cannot be read.
    fn read(&mut self, cell: Cell) -> Result<f64, String> {
        let cell = match (cell, &*self) {
            (Cell::Number(v), Clock::Number(unit)) if v.is_finite() => return Ok(v * unit),
            (Cell::Number(v), _) => return Err(format!("{v}: a finite number of seconds is expected")),
            (Cell::Text(cell), _) => cell,
        };
        let unix =
            |t: chrono::DateTime<chrono::Utc>| t.timestamp() as f64 + f64::from(t.timestamp_subsec_nanos()) * 1e-9;
        let explain = |format: &str, e: chrono::ParseError| {
            let hint = if e.kind() == chrono::format::ParseErrorKind::NotEnough {
                " (a time of day needs the source's `date` key)"
            } else {
                ""
            };
            format!("`{cell}` does not match time_format `{format}`: {e}{hint}")
        };
        match self {
            Clock::Number(unit) => match cell.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v * *unit),
                Ok(_) => Err(format!("`{cell}` is not finite; a finite number is expected")),
                Err(_) => Err(format!("`{cell}` is not a number (set time_format for times written as text)")),
            },
            Clock::DateTime { format, zoned: false } => chrono::NaiveDateTime::parse_from_str(cell, format)
                .map(|t| unix(t.and_utc()))
                .map_err(|e| explain(format, e)),
            Clock::DateTime { format, zoned: true } => {
                chrono::DateTime::parse_from_str(cell, format).map(|t| unix(t.to_utc())).map_err(|e| explain(format, e))
            }
            Clock::TimeOfDay { format, day_s, days, last_s } => {
                let t = chrono::NaiveTime::parse_from_str(cell, format).map_err(|e| explain(format, e))?;
                use chrono::Timelike;
                let s = f64::from(t.num_seconds_from_midnight()) + f64::from(t.nanosecond()) * 1e-9;
                if last_s.is_some_and(|last| s < last - 43_200.0) {
                    *days += 1.0;
                }
                *last_s = Some(s);
                Ok(*day_s + *days * 86_400.0 + s)
            }
        }
    }
}

/// What a log's rows are read against: where its files are, its frame, its beacons
/// (fixed, and those with a track) and its geodetic origin.
pub(super) struct Site<'a> {
    pub(super) base: &'a Path,
    pub(super) frame: Frame,
    pub(super) beacons: &'a BTreeMap<u32, Vector3<f64>>,
    pub(super) tracked: &'a BTreeSet<u32>,
    pub(super) geodetic: Option<Geodetic>,
}

impl<'a> SourceRows<'a> {
    pub(super) fn open(log: Site<'a>, source: &'a Source) -> Result<Self, LogError> {
        let table = Table::open(log.base, source)?;
        Self::with_table(log, source, table, false)
    }

    /// The rows of a live topic (`onebeacon ros2`): one per message handed in; times
    /// going back are the session's to screen, as on a stream.
    #[cfg(feature = "ros2")]
    pub(super) fn open_live(log: Site<'a>, source: &'a Source) -> Result<Self, LogError> {
        let table = Table::live(log.base, source)?;
        let mut rows = Self::with_table(log, source, table, true)?;
        if rows.cols.contains_key("lat") && rows.geodetic.is_none() {
            return Err(LogError::File {
                file: rows.table.name().to_string(),
                message: "latitudes and longitudes on a live topic need the description's [origin] (lat_deg, \
                          lon_deg): a node cannot wait for its first fix to place the others"
                    .into(),
            });
        }
        rows.order = TimeOrder::Sort;
        Ok(rows)
    }

    fn with_table(log: Site<'a>, source: &'a Source, mut table: Table, live: bool) -> Result<Self, LogError> {
        let (time, cols) = columns(&mut table, source)?;
        let frame_clockwise = log.frame == Frame::Ned;
        let sense = if source.heading_clockwise.is_some_and(|c| c != frame_clockwise) { -1.0 } else { 1.0 };
        Ok(Self {
            source,
            table,
            time,
            cols,
            beacons: log.beacons,
            tracked: log.tracked,
            geodetic: log.geodetic,
            clock: Clock::new(source),
            order: source.time_order(),
            sense,
            previous: None,
            pending: None,
            ahead: None,
            kept: None,
            dropped: 0,
            kept_rows: 0,
            error: None,
            live,
        })
    }

    /// The next item, None at the end of the file: a log's, for one vehicle.
    pub(super) fn next_item(&mut self) -> Result<Option<Item>, LogError> {
        Ok(self.next_line()?.map(|line| match line {
            Line::Item { vehicle: None, item } => item,
            _ => unreachable!("validated: own fixes and vehicles are live topics'"),
        }))
    }

    /// The next line, None at the end of the file.
    pub(super) fn next_line(&mut self) -> Result<Option<Line>, LogError> {
        if let Some(line) = self.pending.take() {
            return Ok(Some(line));
        }
        let row = if self.order == TimeOrder::Drop { self.next_in_order()? } else { self.read_row()? };
        Ok(row.map(|(line, second)| {
            self.pending = second;
            line
        }))
    }

    /// `time_order = "drop"`: the next row in time order, with one row read ahead so that
    /// a time stamp glitched forward drops its row, not every row after it.
    fn next_in_order(&mut self) -> Result<Option<RowItems>, LogError> {
        loop {
            if let Some(e) = self.error.take() {
                return Err(e);
            }
            let row = match self.ahead.take() {
                Some(row) => row,
                None => match self.read_row()? {
                    Some(row) => row,
                    None => return Ok(None),
                },
            };
            let t = row.0.t_s();
            if self.kept.is_some_and(|k| t < k) {
                self.dropped += 1; // behind the last row kept
                continue;
            }
            match self.read_row() {
                Ok(next) => self.ahead = next,
                Err(e) => self.error = Some(e),
            }
            let next_t = self.ahead.as_ref().map(|(next, _)| next.t_s());
            if next_t.is_some_and(|n| n < t && self.kept.is_none_or(|k| n >= k)) {
                self.dropped += 1; // ahead of both neighbours
                continue;
            }
            self.kept = Some(t);
            self.kept_rows += 1;
            return Ok(Some(row));
        }
    }

    /// The next row's items, None at the end of the file.
    fn read_row(&mut self) -> Result<Option<RowItems>, LogError> {
        let (s, cols, time) = (self.source, &self.cols, self.time);
        let (beacons, tracked, geodetic, sense) = (self.beacons, self.tracked, self.geodetic, self.sense);
        let previous = self.previous;
        if !self.table.next_row()? {
            return Ok(None);
        }
        let row = &self.table;
        let t = self.clock.read(row.cell(time)).map_err(|m| row.error(time, m))? + s.time_offset_s;
        if let Some(p) = previous.filter(|p| t < *p && self.order == TimeOrder::Refuse) {
            return Err(row.error(
                time,
                format!("time {t} is before {p} on the row above; rows must be in time order (or set time_order = \"sort\" or \"drop\" on this source)"),
            ));
        }
        let (len, ang) = (s.length_unit.metres(), s.angle_unit.radians());
        // an acoustic measurement's beacon: its error and its ping's transmit time
        let t_tx = match cols.get("t_tx") {
            Some(&c) => Some(self.clock.read(row.cell(c)).map_err(|m| row.error(c, m))? + s.time_offset_s),
            None => None,
        };
        let beacon_sigma = match cols.get("beacon_sigma") {
            Some(&c) => match row.number(c)? * len {
                v if v >= 0.0 => v,
                v => return Err(row.error(c, format!("{v}: a beacon's position error, m, is >= 0"))),
            },
            None => 0.0,
        };
        let num = |k: &str| row.number(cols[k]);
        let heading = |k: &str| Ok::<_, LogError>(sense * num(k)? * ang + s.heading_offset_deg.to_radians());
        let turn = |k: &str| Ok::<_, LogError>(sense * num(k)? * ang);
        let live = self.live;
        let beacon = || {
            let id = row.beacon_id(cols["beacon"])?;
            let mut b = if live && !beacons.contains_key(&id) {
                crate::nav::BeaconFix::fixed(id, Vector3::repeat(f64::NAN))
            } else {
                resolve_beacon(id, beacons, tracked).map_err(|m| row.error(cols["beacon"], m))?
            };
            (b.sigma_m, b.t_tx_s) = (beacon_sigma, t_tx);
            Ok::<_, LogError>(b)
        };
        let position = || match (cols.get("x").zip(cols.get("y")), geodetic) {
            (Some((&x, &y)), _) => Ok::<_, LogError>((row.number(x)? * len, row.number(y)? * len)),
            (None, Some(geo)) => {
                let unit = s.latlon_unit.radians();
                geo.local(num("lat")? * unit, num("lon")? * unit).map_err(|m| row.error(cols["lat"], m))
            }
            (None, None) => unreachable!("validated: x and y, or lat and lon (which make the origin)"),
        };
        let vehicle = cols.get("vehicle").map(|&c| row.id(c, "vehicle")).transpose()?.map(|v| v as usize);
        let about = |input: Input| Line::Item { vehicle, item: Item { t_s: t, input } };
        let measurement = |m: Kind| about(Input::Measurement(m));
        let mut second = None;
        let line = match s.kind {
            SourceKind::Odometry if s.increment_frame == IncrementFrame::Start => {
                measurement(at_mid_heading(num("distance")? * len, 0.0, turn("heading_change")?))
            }
            SourceKind::Odometry => measurement(Kind::Odometry {
                distance_m: num("distance")? * len,
                heading_change_rad: turn("heading_change")?,
            }),
            SourceKind::BodyOdometry => {
                let (forward, lateral) = (num("forward")? * len, sense * num("lateral")? * len);
                let dpsi = turn("heading_change")?;
                measurement(match s.increment_frame {
                    IncrementFrame::Mid => {
                        Kind::BodyOdometry { forward_m: forward, lateral_m: lateral, heading_change_rad: dpsi }
                    }
                    IncrementFrame::Start => at_mid_heading(forward, lateral, dpsi),
                })
            }
            SourceKind::BodyVelocity => {
                let r = cols.contains_key("yaw_rate").then(|| turn("yaw_rate")).transpose()?.unwrap_or(0.0);
                let (u, v) = (num("forward_speed")? * len, sense * num("lateral_speed")? * len);
                measurement(Kind::BodyVelocity { nu: [u, v, 0.0, 0.0, 0.0, r] })
            }
            SourceKind::Speed => measurement(Kind::Speed { speed_m_s: num("speed")? * len }),
            SourceKind::Heading => measurement(Kind::Heading { heading_rad: heading("heading")? }),
            SourceKind::SpeedHeading => {
                second = Some(measurement(Kind::Heading { heading_rad: heading("heading")? }));
                measurement(Kind::Speed { speed_m_s: num("speed")? * len })
            }
            SourceKind::Depth => measurement(Kind::Depth { depth_m: num("depth")? * len }),
            SourceKind::Range => measurement(Kind::Range { beacon: beacon()?, range_m: num("range")? * len }),
            SourceKind::Doppler => {
                measurement(Kind::Doppler { beacon: beacon()?, radial_speed_m_s: num("radial_speed")? * len })
            }
            SourceKind::BeaconTrack => {
                let beacon_id = row.beacon_id(cols["beacon"])?;
                let z = cols.get("z").map_or(Ok(0.0), |&c| row.number(c))? * len;
                let (x, y) = position()?;
                about(Input::BeaconPosition { beacon_id, position: Vector3::new(x, y, z) })
            }
            SourceKind::GroundTruth => {
                let heading_rad = cols.contains_key("heading").then(|| heading("heading")).transpose()?;
                let (north_m, east_m) = position()?;
                let sigma_m = match cols.get("sigma") {
                    Some(&c) => {
                        let v = row.number(c)? * len;
                        if v < 0.0 || !v.is_finite() {
                            return Err(row.error(c, format!("{v}: a reference's error, m, is >= 0")));
                        }
                        v
                    }
                    None => s.sigma_m.unwrap_or(0.0),
                };
                about(Input::Truth(TruthPose { north_m, east_m, heading_rad, sigma_m }))
            }
            SourceKind::Bearing => measurement(Kind::Bearing {
                station: beacon()?,
                station_heading_rad: heading("station_heading")?,
                azimuth_rad: turn("azimuth")?,
                elevation_rad: num("elevation")? * ang,
            }),
            SourceKind::Report => measurement(Kind::Report {
                heading_rad: heading("heading")?,
                speed_m_s: num("speed")? * len,
                depth_m: num("depth")? * len,
            }),
            SourceKind::Attitude => measurement(Kind::Attitude {
                roll_rad: num("roll")? * ang,
                pitch_rad: num("pitch")? * ang,
                heading_rad: heading("heading")?,
            }),
            // the array's own frame: no heading sense or offset
            SourceKind::ArrayFix => measurement(Kind::ArrayFix {
                beacon: beacon()?,
                range_m: num("range")? * len,
                azimuth_rad: num("azimuth")? * ang,
                inclination_rad: num("inclination")? * ang,
                mode: row.id(cols["mode"], "mode")? as usize,
            }),
            SourceKind::OwnFix => {
                let (x, y) = position()?;
                let fix = OwnFix {
                    position_m: Vector2::new(x, y),
                    heading_rad: heading("heading")?,
                    speed_m_s: num("speed")? * len,
                };
                Line::OwnFix { t_s: t, fix }
            }
        };
        self.previous = Some(t);
        Ok(Some((line, second)))
    }
}

/// The time column and the column of each key of `source` in `table`: the source's
/// own, or a standard message's (a bag's), every key the kind needs present.
pub(super) fn columns(table: &mut Table, source: &Source) -> Result<(usize, BTreeMap<&'static str, usize>), LogError> {
    let time = source.time.clone().or_else(|| table.default_column(source.kind, "time"));
    let time = table.index(time.as_deref().unwrap_or("time"))?;
    let mut cols = BTreeMap::new();
    for k in COLUMN_KEYS {
        if let Some(c) = source.column(k).cloned().or_else(|| table.default_column(source.kind, k)) {
            cols.insert(k, table.index(&c)?);
        }
    }
    let (required, _) = source.kind.columns();
    let position = !source.kind.positioned()
        || cols.contains_key("x") && cols.contains_key("y")
        || cols.contains_key("lat") && cols.contains_key("lon");
    if let Some(k) = required.iter().find(|k| !cols.contains_key(*k)).copied().or((!position).then_some("x")) {
        return Err(LogError::File {
            file: table.name().to_string(),
            message: format!(
                "a {:?} source needs `{k}`: its messages have no standard field for it; name one (`{k} = \"field.path\"`)",
                source.kind
            ),
        });
    }
    Ok((time, cols))
}

/// A start-frame increment (`increment_frame = "start"`: the translation (d, l) at the
/// heading before the turn dpsi) as the body_odometry the navigators compose at the
/// mid-step heading: the same translation turned back by dpsi / 2,
/// (d', l') = R(-dpsi / 2) (d, l), so that R(psi + dpsi / 2) (d', l') = R(psi) (d, l)
/// exactly. In either frame's sense: l and dpsi turn the same way.
fn at_mid_heading(forward_m: f64, lateral_m: f64, heading_change_rad: f64) -> Kind {
    let (s, c) = (heading_change_rad / 2.0).sin_cos();
    Kind::BodyOdometry {
        forward_m: c * forward_m + s * lateral_m,
        lateral_m: -s * forward_m + c * lateral_m,
        heading_change_rad,
    }
}
