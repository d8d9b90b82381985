//! Integral line-of-sight path following (hoff2024 sec. 4.2; Fossen et al. 2015,
//! eq. 28-29): the along- and cross-track errors of a position from a planar path
//! (hoff2024 eq. 20-21), the heading command
//!
//! ```text
//! psi_d = theta_p - atan((e2 + kappa y_int) / Delta),
//! y_int' = Delta e2 / (Delta^2 + (e2 + kappa y_int)^2),
//! ```
//!
//! whose integral term removes the steady cross-track error a current causes, and
//! the circle's path parameter law (eq. 23).

use super::autopilot::Command;
use nalgebra::Vector2;

/// A planar path gamma(s) with its derivative.
pub trait PlanarPath {
    fn point(&self, s: f64) -> Vector2<f64>;
    fn tangent(&self, s: f64) -> Vector2<f64>;
}

/// The straight line from `from` (s = 0) to `to` (s = 1) (hoff2024 eq. 24).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    pub from: Vector2<f64>,
    pub to: Vector2<f64>,
}

impl PlanarPath for Line {
    fn point(&self, s: f64) -> Vector2<f64> {
        self.from + (self.to - self.from) * s
    }
    fn tangent(&self, _s: f64) -> Vector2<f64> {
        self.to - self.from
    }
}

/// The circle of radius R about `centre`, gamma(s) = centre + R (cos a, sin a) with a =
/// s clockwise seen from above (north toward east; hoff2024 eq. 22, the paper's p_c
/// taken as the centre), a = -s otherwise; run with s increasing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    pub centre: Vector2<f64>,
    pub radius_m: f64,
    pub clockwise: bool,
}

impl Circle {
    fn sense(&self) -> f64 {
        if self.clockwise { 1.0 } else { -1.0 }
    }

    /// The path parameter of the point at angle `a` about the centre (from north).
    pub fn parameter_at(&self, a: f64) -> f64 {
        self.sense() * a
    }
}

impl PlanarPath for Circle {
    fn point(&self, s: f64) -> Vector2<f64> {
        let a = self.sense() * s;
        self.centre + Vector2::new(a.cos(), a.sin()) * self.radius_m
    }
    fn tangent(&self, s: f64) -> Vector2<f64> {
        let a = self.sense() * s;
        Vector2::new(-a.sin(), a.cos()) * (self.sense() * self.radius_m)
    }
}

/// The path-tangential angle and the along- and cross-track errors of `p` from
/// `path` at `s` (eq. 20-21): e2 > 0 to the right of the path (NED, looking along it).
pub fn track_errors(path: &impl PlanarPath, s: f64, p: &Vector2<f64>) -> (f64, f64, f64) {
    let t = path.tangent(s);
    let theta = t.y.atan2(t.x); // eq. 20
    let d = p - path.point(s);
    let (c, sn) = (theta.cos(), theta.sin());
    (theta, d.x * c + d.y * sn, d.y * c - d.x * sn) // eq. 21
}

/// ILOS with lookahead `delta_m` and integral gain `kappa` (0: plain LOS), and its
/// integral state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ilos {
    pub delta_m: f64,
    pub kappa: f64,
    pub y_int: f64,
}

impl Ilos {
    /// MSS's defaults (vehicles.md): Delta 10 m, kappa 0.001.
    pub fn new(delta_m: f64, kappa: f64) -> Self {
        Self { delta_m, kappa, y_int: 0.0 }
    }

    /// The heading command for path angle `theta` and cross-track error `e2`, and the
    /// integral state advanced over `dt` (explicit Euler: the state moves slowly).
    pub fn heading(&mut self, theta: f64, e2: f64, dt: f64) -> f64 {
        let shifted = e2 + self.kappa * self.y_int;
        let psi_d = theta - (shifted / self.delta_m).atan();
        self.y_int += dt * self.delta_m * e2 / (self.delta_m * self.delta_m + shifted * shifted);
        psi_d
    }
}

/// The circle's path-parameter rate (eq. 23): the desired speed `u_d` along it, slowed
/// by the cross-track error, plus `mu` times the along-track error to pull the
/// parameter to the vehicle.
pub fn circle_parameter_rate(u_d: f64, delta_m: f64, radius_m: f64, e1: f64, e2: f64, mu: f64) -> f64 {
    u_d * delta_m / (radius_m * (delta_m * delta_m + e2 * e2).sqrt()) + mu * e1
}

/// ILOS on a circle with the path parameter of eq. 23: the heading (and the speed and
/// depth held) a vehicle is commanded at each step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CircleFollower {
    pub circle: Circle,
    pub ilos: Ilos,
    /// The path parameter, and the gain mu of eq. 23 (1/(m s)).
    pub s: f64,
    pub mu: f64,
    pub speed_m_s: f64,
    pub depth_m: Option<f64>,
}

impl CircleFollower {
    /// The command for a vehicle at `p`, and its cross-track error; the ILOS integral
    /// and the path parameter advanced over `h`.
    pub fn command(&mut self, p: &Vector2<f64>, h: f64) -> (Command, f64) {
        let (theta, e1, e2) = track_errors(&self.circle, self.s, p);
        let heading_rad = self.ilos.heading(theta, e2, h);
        self.s += h * circle_parameter_rate(self.speed_m_s, self.ilos.delta_m, self.circle.radius_m, e1, e2, self.mu);
        (Command { heading_rad, speed_m_s: self.speed_m_s, depth_m: self.depth_m }, e2)
    }
}

/// A dynamic vehicle made by `make(start, heading)` follows the 500 m circle at `u_d`
/// (ILOS with Delta 10 m, integral gain `kappa`, mu 0.01) for two laps in a 0.2 m/s
/// current from the west, at `depth` (None: on the surface): the RMS of its cross-track
/// error over the second lap.
#[cfg(test)]
pub(crate) fn circle_cross_track_rms<P: super::autopilot::Piloted>(
    make: impl Fn(nalgebra::Vector3<f64>, f64) -> P,
    depth: Option<f64>,
    u_d: f64,
    kappa: f64,
    h: f64,
) -> f64 {
    let circle = Circle { centre: Vector2::zeros(), radius_m: 500.0, clockwise: true };
    let mut follower =
        CircleFollower { circle, ilos: Ilos::new(10.0, kappa), s: 0.0, mu: 0.01, speed_m_s: u_d, depth_m: depth };
    let mut p = make(nalgebra::Vector3::new(500.0, 0.0, depth.unwrap_or(0.0)), std::f64::consts::FRAC_PI_2);
    let current = nalgebra::Vector3::new(0.0, 0.2, 0.0);
    let lap = std::f64::consts::TAU * 500.0 / u_d;
    let (mut sum, mut count) = (0.0, 0.0);
    for k in 0..(2.0 * lap / h) as usize {
        let (command, e2) = follower.command(&p.body().position_ned_m.xy(), h);
        if k as f64 * h > lap {
            sum += e2 * e2;
            count += 1.0;
        }
        p.step(&command, &current, h);
    }
    (sum / count).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vehicle at speed U steered by (I)LOS on the line north, pushed east by a cross
    /// current V (kinematic: p' = U (cos psi, sin psi) + (0, V), the heading taken at
    /// once). Plain LOS settles where the current balances the cut-in angle: e2 =
    /// Delta tan(asin(V / U)) (ILOS without its integral, a closed form); ILOS drives
    /// e2 to zero.
    #[test]
    fn the_integral_removes_the_steady_cross_track_error_of_a_current() {
        let line = Line { from: Vector2::zeros(), to: Vector2::new(1000.0, 0.0) };
        let (u, v, delta) = (1.5, 0.2, 10.0);
        let run = |kappa: f64| {
            let mut p = Vector2::new(0.0, -20.0);
            let mut ilos = Ilos::new(delta, kappa);
            let dt = 0.05;
            for _ in 0..(2000.0 / dt) as usize {
                let s = p.x / 1000.0;
                let (theta, _, e2) = track_errors(&line, s, &p);
                let psi = ilos.heading(theta, e2, dt);
                p += (Vector2::new(psi.cos(), psi.sin()) * u + Vector2::new(0.0, v)) * dt;
            }
            p.y
        };
        let expected = delta * (v / u).asin().tan();
        assert!((run(0.0) - expected).abs() < 1e-3, "LOS: {} against {expected}", run(0.0));
        assert!(run(0.5).abs() < 0.01, "ILOS: {}", run(0.5));
    }

    /// On the circle the path angle is s + pi/2 and a point of it has no error; a point
    /// 3 m outside at s = 0 (north of the circle, where the path heads east: to its
    /// left) has e1 = 0 and e2 = -3; on the path, the parameter advances at u_d / R.
    #[test]
    fn circle_errors_and_parameter_rate() {
        let c = Circle { centre: Vector2::new(10.0, -5.0), radius_m: 500.0, clockwise: true };
        let (theta, e1, e2) = track_errors(&c, 0.3, &c.point(0.3));
        assert!((theta - (0.3 + std::f64::consts::FRAC_PI_2)).abs() < 1e-12 && e1.abs() < 1e-9 && e2.abs() < 1e-9);
        let outside = c.point(0.0) + Vector2::new(3.0, 0.0); // further north at s = 0
        let (_, e1, e2) = track_errors(&c, 0.0, &outside);
        assert!(e1.abs() < 1e-12 && (e2 + 3.0).abs() < 1e-12, "{e1} {e2}");
        assert!((circle_parameter_rate(1.5, 10.0, 500.0, 0.0, 0.0, 0.1) - 1.5 / 500.0).abs() < 1e-15);
        // counter-clockwise: the point at angle a (from north) is at s = -a, the path
        // heads a - pi/2 there (west at the north point), and s still increases along it
        let ccw = Circle { clockwise: false, ..c };
        let s = ccw.parameter_at(0.0);
        let (theta, e1, e2) = track_errors(&ccw, s, &ccw.point(s));
        assert!(
            (theta.abs() - std::f64::consts::FRAC_PI_2).abs() < 1e-12
                && theta < 0.0
                && e1.abs() < 1e-9
                && e2.abs() < 1e-9
        );
        let ahead = ccw.point(s + 0.01) - ccw.point(s);
        assert!(ahead.y < 0.0 && (ccw.point(ccw.parameter_at(0.3)) - c.point(0.3)).norm() < 1e-9);
    }
}
