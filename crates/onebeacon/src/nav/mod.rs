//! Navigators: a process model, measurement models and a filter put together, fed with
//! sensor samples as they arrive on the vehicle.

pub mod planar;
pub mod range_6dof;
pub mod single_beacon;

pub use planar::{Measurement, Outcome, PlanarConfig, PlanarEstimate, PlanarNavigator, PlanarNoise};
pub use range_6dof::{OwttRange, Range6DofEkf, SensorNoise};
pub use single_beacon::{Aiding, CommFrame, EkfTuning, Proprioceptive, SingleBeaconEkf};
