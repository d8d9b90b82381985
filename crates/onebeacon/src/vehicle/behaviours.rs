//! rypkema's AUV (sec. 4.1-4.2): the command mode its navigator confirmed from the
//! beacon's chirps selects a beacon-relative behaviour, which steers on where the
//! navigator puts the vehicle relative to the beacon.

use super::autonomy::Autonomy;
use super::{Command, Controller, DecideError, Decided, Situation, need};
use crate::nav::Navigator;
use crate::nav::capability::Capability;

/// The controller: the vehicle's behaviours by mode, driven by its first navigator.
#[derive(Debug, Clone)]
pub struct Behaviours {
    autonomy: Autonomy,
}

impl Behaviours {
    pub fn new(autonomy: Autonomy) -> Self {
        Self { autonomy }
    }
}

impl Controller for Behaviours {
    /// The setpoint of the behaviour of the confirmed mode (the last one's, or holding
    /// heading at depth before any), from the navigator's beacon-relative position and
    /// heading; [`DecideError::Lacks`] for a navigator that has none.
    fn decide(&mut self, _situation: &Situation, beliefs: &[&dyn Navigator]) -> Result<Decided, DecideError> {
        need(beliefs, 1)?;
        let belief = beliefs[0];
        let relative = belief.beacon_relative().ok_or(DecideError::Lacks(Capability::BeaconRelative))?;
        let (mode, rel) = (relative.command_mode(), relative.beacon_relative_ned_m());
        let (setpoint, phase) = self.autonomy.step(mode, rel.xy(), rel.z, belief.estimate().heading_rad());
        Ok(Decided::from(Command::Setpoint { setpoint, mode, phase }))
    }
}
