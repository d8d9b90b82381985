//! Guidance of a surface vehicle: where it should be next so that what it gives the
//! underwater vehicles tells the most: the ranges of the beacon it carries (sousa), or
//! the USBL bearings it hears (hoff2024).
//!
//! - [`bearing`]: hoff2024's planner for a surface vehicle listening with a USBL: the
//!   point of a half-annulus around the particle belief whose bearing spreads the
//!   predicted measurements most (eq. 10-12), and its straight legs (eq. 13-16);
//! - [`fim`]: Fisher information of range measurements about the target's horizontal
//!   position (sousa eq. 3.11-3.15);
//! - [`planner`]: the next waypoint inside the ASV's reaching set, by approach A (one
//!   target position, eq. 3.15) or B (current and predicted target, eq. 3.16-3.19),
//!   searched on a polar grid and refined locally;
//! - [`standoff`]: the best initial horizontal distance for a target depth and ASV reach
//!   (sousa Fig. 4.7-4.8), answered with the same planner.

pub mod bearing;
pub mod fim;
pub mod planner;
pub mod standoff;

pub use fim::{det2, range_fim};
pub use planner::{Decision, FimPlanner, Metric, PolarGrid, ReachingSet};
pub use standoff::{Standoff, best_standoff};
