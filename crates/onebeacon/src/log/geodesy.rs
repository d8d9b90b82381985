//! Latitudes and longitudes in a log: their units, the origin, the WGS-84 tangent plane
//! they become local north and east on (`map_3d`), and where a point may lie.

use crate::geo::Frame;
use nalgebra::Vector3;
use serde::Deserialize;

/// How latitudes and longitudes are written (`latlon_unit`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LatLonUnit {
    #[default]
    Deg,
    /// Integers of 1e-7 degree (degrees times 1e7), as many GNSS receivers write them.
    Deg1e7,
    Rad,
}

impl LatLonUnit {
    pub(crate) fn radians(self) -> f64 {
        match self {
            LatLonUnit::Deg => std::f64::consts::PI / 180.0,
            LatLonUnit::Deg1e7 => std::f64::consts::PI / 180.0 * 1e-7,
            LatLonUnit::Rad => 1.0,
        }
    }
}

/// The point about which latitudes and longitudes become local north and east
/// (`[origin]`); without it, the log's first latitude and longitude.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Origin {
    pub lat_deg: f64,
    pub lon_deg: f64,
}

/// Latitude and longitude to the log's local frame: north and east on the plane tangent
/// to the WGS-84 ellipsoid at the origin (through ECEF, `map_3d`), in the log's frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Geodetic {
    lat0_rad: f64,
    lon0_rad: f64,
    frame: Frame,
}

impl Geodetic {
    /// The tangent plane at (`lat0_rad`, `lon0_rad`), its axes those of `frame`.
    pub(crate) fn new(lat0_rad: f64, lon0_rad: f64, frame: Frame) -> Self {
        Self { lat0_rad, lon0_rad, frame }
    }

    /// (x, y) in the log's frame of a point at (lat, lon) radians, on the ellipsoid; why
    /// not where the point is no place on Earth ([`check_latlon`]).
    pub(crate) fn local(&self, lat_rad: f64, lon_rad: f64) -> Result<(f64, f64), String> {
        check_latlon(lat_rad, lon_rad)?;
        let (n, e, _) =
            map_3d::geodetic2ned(lat_rad, lon_rad, 0.0, self.lat0_rad, self.lon0_rad, 0.0, map_3d::Ellipsoid::WGS84);
        let (x, y, _) = self.frame.from_ned(&Vector3::new(n, e, 0.0));
        Ok((x, y))
    }
}

/// Whether a latitude and a longitude, degrees, name a place on Earth: a latitude in
/// [-90, 90] and a longitude in [-180, 360] (`[origin]` and every row alike).
pub(crate) fn on_earth(lat_deg: f64, lon_deg: f64) -> bool {
    (-90.0..=90.0).contains(&lat_deg) && (-180.0..=360.0).contains(&lon_deg)
}

/// [`on_earth`] for a latitude and a longitude in radians (within 1e-9 deg of the
/// bounds, for the round trip through radians): why not, in one line.
pub(crate) fn check_latlon(lat_rad: f64, lon_rad: f64) -> Result<(), String> {
    const SLACK: f64 = 1e-9;
    let (lat, lon) = (lat_rad.to_degrees(), lon_rad.to_degrees());
    let snap = |v: f64, lo: f64, hi: f64| if (lo - SLACK..=hi + SLACK).contains(&v) { v.clamp(lo, hi) } else { v };
    if on_earth(snap(lat, -90.0, 90.0), snap(lon, -180.0, 360.0)) {
        return Ok(());
    }
    Err(format!(
        "latitude {lat} deg, longitude {lon} deg is no place on Earth: a latitude in [-90, 90] and a longitude in \
         [-180, 360] degrees are allowed (check `latlon_unit`)"
    ))
}
