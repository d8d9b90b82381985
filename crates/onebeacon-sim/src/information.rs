//! The information the posterior Cramer-Rao bound ([`crate::pcrb`]) adds at each step:
//! an observer that gathers the Fisher information H' R^-1 H of every acoustic
//! measurement each vehicle hears, at the truth, from the navigators' own measurement
//! models and noise (ranges: the 6-DOF filter's; bearings: the matched trackers').

use crate::engine::{Observer, Step, VehicleTruth};
use nalgebra::{DMatrix, SMatrix, SVector};
use onebeacon::measure::{ScalarModel, UsblAngle};
use onebeacon::models::hoff::DIM;
use onebeacon::nav::{Kind, SensorNoise, TrackerNoise};

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

/// For the bound: the Fisher information H' R^-1 H of a bearing, from the world's USBL
/// noise (the matched trackers'), at the truth (None for another kind).
pub(crate) fn bearing_information(noise: TrackerNoise) -> impl FnMut(&Kind, &VehicleTruth) -> Option<DMatrix<f64>> {
    move |kind, truth| {
        let Kind::Bearing { station, station_heading_rad, .. } = *kind else { return None };
        let usbl = noise.usbl(&station, station_heading_rad);
        let mut x = SVector::<f64, DIM>::zeros();
        x.fixed_rows_mut::<3>(0).copy_from(&truth.eta.fixed_rows::<3>(0));
        let info =
            [UsblAngle::Azimuth, UsblAngle::Elevation].iter().fold(SMatrix::<f64, DIM, DIM>::zeros(), |acc, &a| {
                let model = usbl.model(a);
                let h = ScalarModel::<DIM>::jacobian(&model, &x);
                acc + h.transpose() * h / model.variance(&x)
            });
        Some(DMatrix::from_column_slice(DIM, DIM, info.as_slice()))
    }
}

/// For the bound: the Fisher information H' R^-1 H of a range, from the navigators' own
/// range model, at the truth (None for another kind).
pub(crate) fn range_information(noise: SensorNoise) -> impl FnMut(&Kind, &VehicleTruth) -> Option<DMatrix<f64>> {
    move |kind, truth| {
        let Kind::Range { beacon, .. } = kind else { return None };
        let model = noise.range_model(beacon);
        let h = ScalarModel::<6>::jacobian(&model, &truth.eta);
        let info = h.transpose() * h / model.variance(&truth.eta);
        Some(DMatrix::from_column_slice(6, 6, info.as_slice()))
    }
}
