//! The worlds the [engine](crate::engine) runs: each moves its truth and says who heard
//! what, when; nothing else.

mod fixed_beacon;
mod fleet;
mod moving_beacon;
mod passive_usbl;

pub(crate) use fixed_beacon::FixedBeaconWorld;
pub(crate) use fleet::FleetWorld;
pub use moving_beacon::TruthPath;
pub(crate) use moving_beacon::{MovingBeaconWorld, range_information};
pub(crate) use passive_usbl::{PassiveUsblWorld, bearing_information};

use crate::engine::{Observer, Step, VehicleTruth};
use nalgebra::DMatrix;
use onebeacon::nav::Kind;

/// For a bound: the Fisher information of every acoustic measurement each vehicle
/// hears, at the truth, as `of` gives it (None: not one the bound counts), with the
/// vehicle and the step it was heard in.
pub(crate) struct Information<F> {
    of: F,
    info: Vec<(usize, usize, DMatrix<f64>)>,
}

impl<F: FnMut(&Kind, &VehicleTruth) -> Option<DMatrix<f64>>> Information<F> {
    pub(crate) fn new(of: F) -> Self {
        Self { of, info: Vec::new() }
    }

    pub(crate) fn into_inner(self) -> Vec<(usize, usize, DMatrix<f64>)> {
        self.info
    }
}

impl<F: FnMut(&Kind, &VehicleTruth) -> Option<DMatrix<f64>>> Observer for Information<F> {
    fn step(&mut self, s: &Step<'_>) {
        for (v, (heard, truth)) in s.heard.iter().zip(s.truth).enumerate() {
            for m in heard {
                if let Some(i) = (self.of)(&m.kind, truth) {
                    self.info.push((v, s.k, i));
                }
            }
        }
    }
}
