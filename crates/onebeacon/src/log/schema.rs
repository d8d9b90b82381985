//! The log description's schema: the TOML keys of a log (its sources and their columns,
//! units, clocks, beacons, start and limits), deserialised and documented.

pub use super::geodesy::{LatLonUnit, Origin};
use crate::config::builder::VehicleModel;
use crate::config::controller::ControllerSpec;
use crate::config::estimator::EstimatorSpec;
pub use crate::config::stream::{FrameKey, HeadingFrom, Initial, InitialFrom};
use crate::nav::limits::Limits;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// What a CSV source holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SourceKind {
    Odometry,
    BodyOdometry,
    /// Body-frame speeds (a DVL): forward, lateral, optional yaw rate, held until the
    /// next.
    BodyVelocity,
    Speed,
    Heading,
    SpeedHeading,
    Depth,
    Range,
    Doppler,
    BeaconTrack,
    GroundTruth,
    /// A USBL's bearing to a vehicle (hoff2024 sec. 2.1, eq. 1-2): the station's beacon
    /// id (its position a beacon track), its heading, the azimuth from that heading and
    /// the elevation from the vertical.
    Bearing,
    /// What a vehicle reports of itself in an acoustic message (hoff2024 sec. 2.2): its
    /// heading, speed over ground and depth.
    Report,
    /// Roll, pitch and heading from an AHRS (a 6-dof or an AUV's stream).
    Attitude,
    /// One ping reduced by the vehicle's own receiver (rypkema sec. 3.2): the beacon, the
    /// slant range, the direction toward the beacon in the array frame (azimuth from x
    /// toward y, inclination from +z down) and the command mode the chirp carries
    /// (sec. 4.2, an index into the controller's modes).
    ArrayFix,
    /// The computer's own vehicle's fix (a surface vehicle's GNSS): its position, heading
    /// and speed, on which a controller decides; a live topic's only (`onebeacon ros2`).
    OwnFix,
}

impl SourceKind {
    /// The column keys this kind needs, and those it may have.
    pub(crate) fn columns(self) -> (&'static [&'static str], &'static [&'static str]) {
        match self {
            SourceKind::Odometry => (&["distance", "heading_change"], &[]),
            SourceKind::BodyOdometry => (&["forward", "lateral", "heading_change"], &[]),
            SourceKind::BodyVelocity => (&["forward_speed", "lateral_speed"], &["yaw_rate"]),
            SourceKind::Speed => (&["speed"], &[]),
            SourceKind::Heading => (&["heading"], &[]),
            SourceKind::SpeedHeading => (&["speed", "heading"], &[]),
            SourceKind::Depth => (&["depth"], &[]),
            SourceKind::Range => (&["beacon", "range"], &[]),
            SourceKind::Doppler => (&["beacon", "radial_speed"], &[]),
            SourceKind::BeaconTrack => (&["beacon"], &["z"]),
            SourceKind::GroundTruth => (&[], &["heading", "sigma"]),
            SourceKind::Bearing => (&["beacon", "station_heading", "azimuth", "elevation"], &[]),
            SourceKind::Report => (&["heading", "speed", "depth"], &[]),
            SourceKind::OwnFix => (&["heading", "speed"], &[]),
            SourceKind::Attitude => (&["roll", "pitch", "heading"], &[]),
            SourceKind::ArrayFix => (&["beacon", "range", "azimuth", "inclination", "mode"], &[]),
        }
    }

    /// Whether its rows may name the vehicle they are about (`vehicle`, for a computer
    /// that tracks several): all but a beacon's track and the computer's own fix.
    pub(crate) fn about_a_vehicle(self) -> bool {
        !matches!(self, SourceKind::BeaconTrack | SourceKind::OwnFix)
    }

    /// Whether it is an acoustic measurement from a beacon, whose rows may give the
    /// beacon's position error (`beacon_sigma`) and the ping's transmit time (`t_tx`).
    pub(crate) fn heard(self) -> bool {
        matches!(self, SourceKind::Range | SourceKind::Doppler | SourceKind::Bearing | SourceKind::ArrayFix)
    }

    /// Whether the kind holds a position: `x` and `y`, or `lat` and `lon`.
    pub(crate) fn positioned(self) -> bool {
        matches!(self, SourceKind::BeaconTrack | SourceKind::GroundTruth | SourceKind::OwnFix)
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
    pub(super) fn metres(self) -> f64 {
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
    pub(super) fn radians(self) -> f64 {
        match self {
            AngleUnit::Rad => 1.0,
            AngleUnit::Deg => std::f64::consts::PI / 180.0,
        }
    }
}

/// The unit of a numeric time column (`time_unit`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeUnit {
    #[default]
    S,
    Ms,
    Us,
    Ns,
}

impl TimeUnit {
    pub(super) fn seconds(self) -> f64 {
        match self {
            TimeUnit::S => 1.0,
            TimeUnit::Ms => 1e-3,
            TimeUnit::Us => 1e-6,
            TimeUnit::Ns => 1e-9,
        }
    }
}

/// What to do with a row whose time is before the row above (`time_order`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeOrder {
    /// Stop with an error naming the line (the default).
    Refuse,
    /// Read the whole file and sort it by time (a log written out of order).
    Sort,
    /// Drop the rows out of order, counted in the replay's summary: a row behind the
    /// last row kept, or a row ahead of both its neighbours (a glitched time stamp).
    Drop,
}

/// Which heading an odometry increment's translation is expressed at
/// (`increment_frame`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IncrementFrame {
    /// The heading halfway through the turn (the default): the chord of an arc sampled
    /// by wheel odometry or an INS, p' = p + R(psi + dpsi / 2) (d, l).
    #[default]
    Mid,
    /// The heading at the start of the increment, then the turn: a factor-graph edge
    /// (GTSAM's `BetweenFactor`, g2o's `EDGE_SE2`), p' = p + R(psi) (d, l).
    Start,
}

/// One CSV file: its kind, the time column and the column of each quantity.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Source {
    pub kind: SourceKind,
    /// A CSV file, relative to the log description's directory (or `bag`).
    pub file: Option<PathBuf>,
    /// A ROS 2 bag (an `.mcap` or `.db3` file, or a rosbag2 directory), relative to the
    /// description's directory, and the `topic` read from it; the column keys then name
    /// field paths of its messages (`twist.linear.x`), or take a standard message's.
    pub bag: Option<PathBuf>,
    pub topic: Option<String>,
    /// A live topic's ROS 2 type (`geometry_msgs/msg/TwistStamped`), for `onebeacon
    /// ros2`: a source with a `topic`, no `file` and no `bag`; a type that is not a
    /// standard message needs its `definition`, a `.msg` file (relative to the
    /// description), the types it uses after `MSG: pkg/Type` lines as a bag has them.
    pub r#type: Option<String>,
    pub definition: Option<PathBuf>,
    /// The time column: a number (seconds since any origin, or a UNIX epoch) in
    /// `time_unit`, or text read with `time_format`. In a bag: a field path
    /// (`header.stamp` by default when the message has a header) or `log_time`, when
    /// the recorder received it.
    pub time: Option<String>,
    #[serde(default)]
    pub time_unit: TimeUnit,
    /// A strftime pattern for times written as text (`%H:%M:%S%.f` with `date`, or
    /// `%Y-%m-%dT%H:%M:%S%.fZ`): times become UNIX seconds, UTC unless the pattern has
    /// `%z`.
    pub time_format: Option<String>,
    /// `YYYY-MM-DD`, the day of the first row when `time_format` has no date; a time more
    /// than 12 h before the row above is on the next day.
    pub date: Option<String>,
    /// Added to every time of this file, s.
    #[serde(default)]
    pub time_offset_s: f64,
    /// Rows out of time order: `refuse` (default), `sort` or `drop`.
    pub time_order: Option<TimeOrder>,
    #[serde(default)]
    pub length_unit: LengthUnit,
    #[serde(default)]
    pub angle_unit: AngleUnit,
    /// `sort = true` is `time_order = "sort"` (the older key).
    #[serde(default)]
    pub sort: bool,
    /// Headings of this file in the log's frame: `heading_offset_deg` plus the column
    /// turned the frame's way, or the other way when `heading_clockwise` says so (a
    /// compass, clockwise from north, in an ENU log: `heading_clockwise = true`,
    /// `heading_offset_deg = 90`). Heading changes and the lateral axis follow the sense.
    #[serde(default)]
    pub heading_offset_deg: f64,
    pub heading_clockwise: Option<bool>,
    #[serde(default)]
    pub latlon_unit: LatLonUnit,
    /// odometry and body_odometry: the heading each increment's translation is at.
    #[serde(default)]
    pub increment_frame: IncrementFrame,
    pub distance: Option<String>,
    pub heading_change: Option<String>,
    pub forward: Option<String>,
    pub lateral: Option<String>,
    pub forward_speed: Option<String>,
    pub lateral_speed: Option<String>,
    pub yaw_rate: Option<String>,
    pub speed: Option<String>,
    pub heading: Option<String>,
    pub depth: Option<String>,
    pub beacon: Option<String>,
    pub range: Option<String>,
    pub radial_speed: Option<String>,
    /// bearing: the USBL station's heading, the azimuth from it (turning with the
    /// headings' sense) and the elevation from the vertical (hoff2024 eq. 1-2).
    pub station_heading: Option<String>,
    pub azimuth: Option<String>,
    pub elevation: Option<String>,
    /// attitude: roll and pitch as the AHRS gives them (the heading as `heading`).
    pub roll: Option<String>,
    pub pitch: Option<String>,
    /// array_fix: the inclination from +z down, and the command mode (an index).
    pub inclination: Option<String>,
    pub mode: Option<String>,
    /// An acoustic measurement's beacon: its position's own error, m (a standard
    /// deviation on each axis, in `length_unit`), and when it sent the ping (a time read
    /// as `time` is, a one-way travel time's start).
    pub beacon_sigma: Option<String>,
    pub t_tx: Option<String>,
    /// The vehicle a measurement is about, for a computer that tracks several
    /// (`[[tracked]]`: its index, or a name ending in it such as `auv_1`); live topics only.
    pub vehicle: Option<String>,
    pub x: Option<String>,
    pub y: Option<String>,
    pub z: Option<String>,
    pub lat: Option<String>,
    pub lon: Option<String>,
    /// ground_truth: the reference's own error, a standard deviation on each horizontal
    /// axis, m, per row (`sigma`, in `length_unit`) or for every row (`sigma_m`); an LBL or
    /// USBL fix is not the truth. NEES then counts it; the summary states the floor it
    /// puts under RMSE.
    pub sigma: Option<String>,
    pub sigma_m: Option<f64>,
}

impl Source {
    /// The policy for rows out of time order.
    pub fn time_order(&self) -> TimeOrder {
        self.time_order.unwrap_or(if self.sort { TimeOrder::Sort } else { TimeOrder::Refuse })
    }

    pub(crate) fn column(&self, key: &str) -> Option<&String> {
        match key {
            "distance" => self.distance.as_ref(),
            "heading_change" => self.heading_change.as_ref(),
            "forward" => self.forward.as_ref(),
            "lateral" => self.lateral.as_ref(),
            "forward_speed" => self.forward_speed.as_ref(),
            "lateral_speed" => self.lateral_speed.as_ref(),
            "yaw_rate" => self.yaw_rate.as_ref(),
            "speed" => self.speed.as_ref(),
            "heading" => self.heading.as_ref(),
            "depth" => self.depth.as_ref(),
            "beacon" => self.beacon.as_ref(),
            "range" => self.range.as_ref(),
            "radial_speed" => self.radial_speed.as_ref(),
            "station_heading" => self.station_heading.as_ref(),
            "azimuth" => self.azimuth.as_ref(),
            "elevation" => self.elevation.as_ref(),
            "roll" => self.roll.as_ref(),
            "pitch" => self.pitch.as_ref(),
            "inclination" => self.inclination.as_ref(),
            "mode" => self.mode.as_ref(),
            "vehicle" => self.vehicle.as_ref(),
            "beacon_sigma" => self.beacon_sigma.as_ref(),
            "t_tx" => self.t_tx.as_ref(),
            "x" => self.x.as_ref(),
            "y" => self.y.as_ref(),
            "z" => self.z.as_ref(),
            "lat" => self.lat.as_ref(),
            "lon" => self.lon.as_ref(),
            "sigma" => self.sigma.as_ref(),
            _ => None,
        }
    }
}

pub(crate) const COLUMN_KEYS: [&str; 29] = [
    "distance",
    "heading_change",
    "forward",
    "lateral",
    "forward_speed",
    "lateral_speed",
    "yaw_rate",
    "speed",
    "heading",
    "depth",
    "beacon",
    "range",
    "radial_speed",
    "station_heading",
    "azimuth",
    "elevation",
    "roll",
    "pitch",
    "inclination",
    "mode",
    "vehicle",
    "beacon_sigma",
    "t_tx",
    "x",
    "y",
    "z",
    "lat",
    "lon",
    "sigma",
];

/// Fixed beacon positions from a CSV file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeaconTable {
    pub file: PathBuf,
    pub id: String,
    /// `x` and `y`, or `lat` and `lon` (in `latlon_unit`).
    pub x: Option<String>,
    pub y: Option<String>,
    pub lat: Option<String>,
    pub lon: Option<String>,
    pub z: Option<String>,
    #[serde(default)]
    pub length_unit: LengthUnit,
    #[serde(default)]
    pub latlon_unit: LatLonUnit,
}

/// One fixed beacon given inline.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeaconEntry {
    pub id: u32,
    /// `x_m` and `y_m`, or `lat_deg` and `lon_deg`.
    pub x_m: Option<f64>,
    pub y_m: Option<f64>,
    pub lat_deg: Option<f64>,
    pub lon_deg: Option<f64>,
    #[serde(default)]
    pub z_m: f64,
}

/// The log description file: the keys of a stream configuration
/// ([`crate::config::stream::StreamConfig`], which documents them) and where the
/// log's data are (its sources, its beacons' file or positions in latitude and
/// longitude, the origin); [`LogDescription::stream_config`] gives the former.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LogDescription {
    pub name: String,
    #[serde(default)]
    pub description: String,
    #[serde(default)]
    pub frame: FrameKey,
    /// The estimators' vehicle model: `"planar"` (default; a log's sources are planar
    /// odometry) or `"6dof"` (stream: sousa's filter on body_velocity, attitude and depth
    /// lines).
    #[serde(default)]
    pub model: VehicleModel,
    /// Where latitudes and longitudes are 0 m north and east.
    pub origin: Option<Origin>,
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
    /// Noise keys every estimator takes unless it gives its own (`[noise]`): one place
    /// for what the sensors are, the estimators differing in what they estimate. Its
    /// keys are [`crate::config::estimator::NOISE_KEYS`].
    #[serde(default)]
    pub noise: BTreeMap<String, f64>,
    /// What an item must respect before any estimator sees it.
    #[serde(default)]
    pub limits: Limits,
    /// The vehicle's controller (stream): a surface vehicle's planner or an AUV's
    /// behaviours, deciding on its estimators' beliefs.
    pub controller: Option<ControllerSpec>,
    /// `[[tracked]]` (stream): the vehicles a surface vehicle tracks, one `[initial]`
    /// table each (a line's `vehicle` is its index); without it, one vehicle from
    /// `[initial]`.
    #[serde(default)]
    pub tracked: Vec<Initial>,
}
