//! Estimators: the generic extended Kalman filter and consistency statistics.

pub mod consistency;
pub mod ekf;

pub use ekf::{Ekf, FilterError, Gated, MeasurementModel, ProcessModel};
