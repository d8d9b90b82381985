//! Beacon-relative behaviours (rypkema sec. 4.1) and the command modes that select
//! them (sec. 4.2): every behaviour is defined in the beacon-centred frame (NED axes,
//! origin at the beacon), so moving the beacon moves the fleet. Semantics from
//! ../shared/vehicles.md (MOOS-IvP's documented behaviour semantics, re-implemented).
//!
//! A vehicle's [`Autonomy`] holds one [`Behaviour`] per mode; each step it takes the
//! confirmed mode and the navigator's beacon-relative position and returns a
//! [`Setpoint`] (heading, speed, depth; speed 0 stops the propeller, and a vehicle with
//! slight positive buoyancy then floats up).

use crate::geo::wrap_angle;
use nalgebra::Vector2;

use super::{Phase, Setpoint};

/// One beacon-relative behaviour. Positions are offsets from the beacon, NED, m;
/// headings from north toward east, rad.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Behaviour {
    /// A circle of `radius_m` about `centre_m`, clockwise or not (seen from above,
    /// north up), re-acquired when off it.
    Loiter { centre_m: Vector2<f64>, radius_m: f64, clockwise: bool },
    /// Back and forth along a line of `length_m` through `centre_m` at `heading_rad`;
    /// the vehicle steers back to the line only once it has drifted `buffer_m` off it,
    /// and holds the line's heading inside (what stops the oscillation a noisy relative
    /// position would cause).
    Trackline { centre_m: Vector2<f64>, heading_rad: f64, length_m: f64, buffer_m: f64 },
    /// Sprint and drift: drive to `offset_m`, stop the propeller there and float; drive
    /// again when more than `buffer_m` away or shallower than `ceiling_m` (then leave and
    /// circle back at depth).
    OffsetFollow { offset_m: Vector2<f64>, buffer_m: f64, ceiling_m: f64 },
    /// Along a line of `length_m` at `heading_rad` ending at `end_m`, from the nearest
    /// point on it; at the end stop and float up.
    Return { end_m: Vector2<f64>, heading_rad: f64, length_m: f64 },
    /// Stop and float up.
    Abort,
}

/// Settings common to every behaviour of a vehicle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AutonomySettings {
    /// Transit speed and depth (rypkema: 1 m/s, 2.5 m).
    pub speed_m_s: f64,
    pub depth_m: f64,
    /// Look-ahead distance of line and circle following, m (ours: 10).
    pub lead_m: f64,
    /// Arrival: within the capture radius, or moving away after passing within the slip
    /// radius (MOOS-IvP defaults 3 m, 15 m).
    pub capture_m: f64,
    pub slip_m: f64,
}

impl Default for AutonomySettings {
    fn default() -> Self {
        Self { speed_m_s: 1.0, depth_m: 2.5, lead_m: 10.0, capture_m: 3.0, slip_m: 15.0 }
    }
}

/// The state a behaviour keeps between steps.
#[derive(Debug, Clone, Copy, PartialEq)]
enum State {
    None,
    /// Trackline: travelling along (+1) or against (-1) the line's heading, and whether
    /// steering back to it.
    Track {
        forward: bool,
        centring: bool,
    },
    /// Offset follow: drifting, or driving (closest approach so far, and whether first
    /// leaving the point to circle back at depth).
    Follow {
        drifting: bool,
        closest_m: f64,
        leaving: bool,
    },
    /// Return: reached the end.
    Return {
        done: bool,
    },
}

/// One vehicle's behaviours by mode, and the state of the active one.
#[derive(Debug, Clone, PartialEq)]
pub struct Autonomy {
    pub settings: AutonomySettings,
    modes: Vec<Option<Behaviour>>,
    active: Option<usize>,
    state: State,
}

impl Autonomy {
    /// `modes[i]`: the behaviour of mode i (None: mode i keeps the current behaviour).
    pub fn new(settings: AutonomySettings, modes: Vec<Option<Behaviour>>) -> Self {
        Self { settings, modes, active: None, state: State::None }
    }

    /// The mode whose behaviour is running.
    pub fn active(&self) -> Option<usize> {
        self.active
    }

    /// The setpoint for this step from the confirmed `mode`, the vehicle's position
    /// relative to the beacon `rel` (NED, m), its depth and heading.
    pub fn step(
        &mut self,
        mode: Option<usize>,
        rel: Vector2<f64>,
        depth_m: f64,
        heading_rad: f64,
    ) -> (Setpoint, Phase) {
        if let Some(m) = mode.filter(|&m| self.modes.get(m).is_some_and(Option::is_some))
            && self.active != Some(m)
        {
            self.active = Some(m);
            self.state = State::None;
        }
        let s = self.settings;
        let drive = |heading: f64| Setpoint { heading_rad: heading, speed_m_s: s.speed_m_s, depth_m: s.depth_m };
        let stop = Setpoint { heading_rad, speed_m_s: 0.0, depth_m: 0.0 };
        let Some(behaviour) = self.active.and_then(|m| self.modes[m]) else {
            return (drive(heading_rad), Phase::Waiting);
        };
        match behaviour {
            Behaviour::Loiter { centre_m, radius_m, clockwise } => {
                (drive(loiter_heading(rel - centre_m, radius_m, clockwise, s.lead_m)), Phase::Driving)
            }
            Behaviour::Trackline { centre_m, heading_rad: line, length_m, buffer_m } => {
                let (mut forward, mut centring) = match self.state {
                    State::Track { forward, centring } => (forward, centring),
                    _ => (true, false),
                };
                let d = rel - centre_m;
                let h = Vector2::new(line.cos(), line.sin());
                let along = d.dot(&h);
                if forward && along > length_m / 2.0 {
                    forward = false;
                } else if !forward && along < -length_m / 2.0 {
                    forward = true;
                }
                let course = if forward { line } else { wrap_angle(line + std::f64::consts::PI) };
                // cross-track error to the right of the direction of travel
                let cross = d.dot(&Vector2::new(-course.sin(), course.cos()));
                if cross.abs() > buffer_m {
                    centring = true;
                } else if cross.abs() < (buffer_m / 4.0).max(1.0) {
                    centring = false;
                }
                self.state = State::Track { forward, centring };
                let heading = if centring { course - (cross / s.lead_m).atan() } else { course };
                (drive(wrap_angle(heading)), Phase::Driving)
            }
            Behaviour::OffsetFollow { offset_m, buffer_m, ceiling_m } => {
                let (mut drifting, mut closest, mut leaving) = match self.state {
                    State::Follow { drifting, closest_m, leaving } => (drifting, closest_m, leaving),
                    _ => (false, f64::INFINITY, false),
                };
                let to = offset_m - rel;
                let d = to.norm();
                if drifting && (d > buffer_m || depth_m < ceiling_m) {
                    drifting = false;
                    leaving = depth_m < ceiling_m && d < 2.0 * s.capture_m;
                    closest = f64::INFINITY;
                }
                if !drifting {
                    if leaving && d > 2.0 * s.capture_m {
                        leaving = false;
                    }
                    if !leaving {
                        closest = closest.min(d);
                        let arrived = d < s.capture_m || (closest < s.slip_m && d > closest + 1.0);
                        if arrived && depth_m >= ceiling_m {
                            drifting = true;
                        }
                    }
                }
                self.state = State::Follow { drifting, closest_m: closest, leaving };
                if drifting {
                    (stop, Phase::Drifting)
                } else if leaving {
                    (drive(heading_rad), Phase::Driving)
                } else {
                    (drive(to.y.atan2(to.x)), Phase::Driving)
                }
            }
            Behaviour::Return { end_m, heading_rad: line, length_m } => {
                let done = matches!(self.state, State::Return { done: true });
                let h = Vector2::new(line.cos(), line.sin());
                let start = end_m - h * length_m;
                let along = (rel - start).dot(&h);
                let done = done || (rel - end_m).norm() < s.capture_m || along >= length_m;
                self.state = State::Return { done };
                if done {
                    return (stop, Phase::Surfacing);
                }
                let foot = start + h * along.clamp(0.0, length_m);
                let target = foot + h * s.lead_m.min(length_m - along.clamp(0.0, length_m)).max(0.0);
                let to = target - rel;
                let heading = if to.norm() > 1e-9 { to.y.atan2(to.x) } else { line };
                (drive(heading), Phase::Driving)
            }
            Behaviour::Abort => (stop, Phase::Surfacing),
        }
    }
}

/// The heading of a circle's guidance field at offset `d` from its centre: the tangent
/// in the direction of travel, turned toward the circle by atan((rho - R) / lead).
/// Heading from north toward east: seen from above with north up, clockwise travel
/// increases the polar angle atan2(east, north).
pub fn loiter_heading(d: Vector2<f64>, radius_m: f64, clockwise: bool, lead_m: f64) -> f64 {
    let theta = d.y.atan2(d.x);
    let err = ((d.norm() - radius_m) / lead_m).atan();
    let half = std::f64::consts::FRAC_PI_2;
    wrap_angle(if clockwise { theta + half + err } else { theta - half - err })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On the circle the field is the tangent; far outside it points at the centre.
    #[test]
    fn loiter_field_geometry() {
        let h = loiter_heading(Vector2::new(18.0, 0.0), 18.0, true, 10.0);
        assert!((h - std::f64::consts::FRAC_PI_2).abs() < 1e-12); // north of centre, clockwise: east
        let h = loiter_heading(Vector2::new(18.0, 0.0), 18.0, false, 10.0);
        assert!((h + std::f64::consts::FRAC_PI_2).abs() < 1e-12); // counter-clockwise: west
        let h = loiter_heading(Vector2::new(1e6, 0.0), 18.0, true, 10.0);
        assert!((wrap_angle(h - std::f64::consts::PI)).abs() < 1e-4); // toward the centre (south)
    }

    /// A return ends within the capture radius of its end and stays stopped; before
    /// that it heads along the line toward the end.
    #[test]
    fn return_follows_its_line_and_stops() {
        let end = Vector2::new(0.0, 5.0);
        let b = Behaviour::Return { end_m: end, heading_rad: 0.0, length_m: 150.0 };
        let mut a = Autonomy::new(AutonomySettings::default(), vec![Some(b)]);
        let (sp, phase) = a.step(Some(0), Vector2::new(-100.0, 5.0), 2.5, 1.0);
        assert_eq!(phase, Phase::Driving);
        assert!(sp.heading_rad.abs() < 1e-9 && sp.speed_m_s > 0.0);
        let (_, phase) = a.step(Some(0), end + Vector2::new(-1.0, 1.0), 2.5, 0.0);
        assert_eq!(phase, Phase::Surfacing);
        let (sp, phase) = a.step(Some(0), Vector2::new(-50.0, 0.0), 1.0, 0.0);
        assert_eq!((phase, sp.speed_m_s), (Phase::Surfacing, 0.0));
    }
}
