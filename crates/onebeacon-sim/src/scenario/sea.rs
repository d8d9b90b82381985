//! The `[sea]` table: error sources of the real sea a world can switch on, all off by
//! default (the reproductions run without them). So far the clocks of the one-way
//! travel-time worlds (fixed_beacon, moving_beacon).

use super::validate::{Rule, Violation, check};
use crate::acoustics::clock::ClockErrors;
use serde::{Deserialize, Serialize};

/// The sound speed a fixed_beacon world, which times no ping, turns a clock error into
/// a range error with, m/s.
pub const FIXED_BEACON_SOUND_SPEED_M_S: f64 = 1500.0;

/// `[sea]`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Sea {
    /// `[sea.clocks]`: every vehicle's and the beacon's clock draw these errors.
    pub clocks: ClockErrors,
}

impl Sea {
    pub(super) fn check(&self) -> Result<(), Violation> {
        let c = &self.clocks;
        for (key, v) in [
            ("sea.clocks.offset_sigma_s", c.offset_sigma_s),
            ("sea.clocks.drift_sigma_ppm", c.drift_sigma_ppm),
            ("sea.clocks.walk_s_per_sqrt_s", c.walk_s_per_sqrt_s),
        ] {
            check(key, v, Rule::NonNegative)?;
        }
        Ok(())
    }
}
