//! The settings of rypkema's iUSBL navigator as an `[[estimators]]` table of a log or a
//! stream gives them (`[estimators.iusbl]`), and as a fleet scenario's `navigation`,
//! `dock` and `signal` tables do.

use crate::filter::factored::FactoredSettings;
use crate::nav::IusblConfig;
use serde::{Deserialize, Serialize};

/// The settings of rypkema's iUSBL navigator (`[estimators.iusbl]`); defaults are
/// [`IusblConfig::default`]'s. A fleet scenario gives them from its `navigation`,
/// `dock` and `signal` tables.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IusblKeys {
    pub particles: usize,
    /// Lowest-weighted particles of each domain drawn again uniformly at each update,
    /// and the receiver's largest range, m.
    pub reinitialised: usize,
    pub max_range_m: f64,
    pub sigma_speed_m_s: f64,
    pub sigma_heading_deg: f64,
    /// The heading's slow error that the covariance carries (IusblConfig's
    /// `heading_bias_sigma_rad`), deg.
    pub heading_bias_sigma_deg: f64,
    pub beacon_speed_m_s: f64,
    pub beacon_depth_m: f64,
    pub confirmations: usize,
    pub floor: f64,
    pub beam_exponent: f64,
    /// The noise of an array fix's range (m) and direction (deg) as the filter weighs it.
    pub fix_range_sigma_m: f64,
    pub fix_angle_sigma_deg: f64,
    pub sound_speed_m_s: f64,
}

impl Default for IusblKeys {
    fn default() -> Self {
        let c = IusblConfig::default();
        Self {
            particles: c.filter.particles,
            reinitialised: c.filter.reinitialised,
            max_range_m: c.filter.max_range_m,
            sigma_speed_m_s: c.sigma_speed_m_s,
            sigma_heading_deg: c.sigma_heading_rad.to_degrees(),
            heading_bias_sigma_deg: c.heading_bias_sigma_rad.to_degrees(),
            beacon_speed_m_s: c.beacon_speed_m_s,
            beacon_depth_m: c.beacon_depth_m,
            confirmations: c.confirmations,
            floor: c.floor,
            beam_exponent: c.beam_exponent,
            fix_range_sigma_m: c.fix_sigma_range_m,
            fix_angle_sigma_deg: c.fix_sigma_angle_rad.to_degrees(),
            sound_speed_m_s: c.sound_speed_m_s,
        }
    }
}

impl IusblKeys {
    /// The navigator's configuration, factored or joint.
    pub fn config(&self, factored: bool) -> IusblConfig {
        IusblConfig {
            filter: FactoredSettings {
                particles: self.particles,
                max_range_m: self.max_range_m,
                reinitialised: self.reinitialised,
            },
            factored,
            sigma_speed_m_s: self.sigma_speed_m_s,
            sigma_heading_rad: self.sigma_heading_deg.to_radians(),
            heading_bias_sigma_rad: self.heading_bias_sigma_deg.to_radians(),
            beacon_speed_m_s: self.beacon_speed_m_s,
            beacon_depth_m: self.beacon_depth_m,
            confirmations: self.confirmations,
            floor: self.floor,
            beam_exponent: self.beam_exponent,
            fix_sigma_range_m: self.fix_range_sigma_m,
            fix_sigma_angle_rad: self.fix_angle_sigma_deg.to_radians(),
            sound_speed_m_s: self.sound_speed_m_s,
            ..IusblConfig::default()
        }
    }

    /// The numeric keys with whether each must be > 0 (else >= 0).
    pub(crate) fn numbers(&self) -> [(&'static str, f64, bool); 14] {
        [
            ("particles", self.particles as f64, true),
            ("reinitialised", self.reinitialised as f64, false),
            ("max_range_m", self.max_range_m, true),
            ("sigma_speed_m_s", self.sigma_speed_m_s, true),
            ("sigma_heading_deg", self.sigma_heading_deg, true),
            ("heading_bias_sigma_deg", self.heading_bias_sigma_deg, false),
            ("beacon_speed_m_s", self.beacon_speed_m_s, false),
            ("beacon_depth_m", self.beacon_depth_m, false),
            ("confirmations", self.confirmations as f64, true),
            ("floor", self.floor, false),
            ("beam_exponent", self.beam_exponent, true),
            ("fix_range_sigma_m", self.fix_range_sigma_m, true),
            ("fix_angle_sigma_deg", self.fix_angle_sigma_deg, true),
            ("sound_speed_m_s", self.sound_speed_m_s, true),
        ]
    }
}
