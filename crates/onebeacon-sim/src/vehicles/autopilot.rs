//! What the dynamic vehicles' autopilots share: a rate-limited third-order reference
//! model of a commanded angle, and the PID that makes one degree of freedom track it
//! through a moment command, with gains placed from the degree's inertia and damping
//! (Fossen 2021, sec. 15.3: pole placement of m x'' + d x' = tau, with the reference's
//! acceleration and rate fed forward). And the interface a world drives a vehicle by.

use super::rigid_body::BodyState;
use nalgebra::Vector3;
use onebeacon::geo::wrap_angle;

/// A third-order reference model of an angle (Fossen 2021, eq. 15.151): critically
/// damped at bandwidth `w`, its rate limited to `rate_max`:
///
/// ```text
/// x''' = w^3 (x_d - x) - 3 w x'' - 3 w^2 x'
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceModel {
    /// The reference angle, its rate and its acceleration.
    pub state: [f64; 3],
    pub w: f64,
    pub rate_max: f64,
}

impl ReferenceModel {
    pub fn new(angle: f64, w: f64, rate_max: f64) -> Self {
        Self { state: [angle, 0.0, 0.0], w, rate_max }
    }

    /// The reference now, then advanced over `h` toward `target` (explicit Euler, the
    /// model being much slower than the step). At the rate limit the acceleration that
    /// pushes past it is dropped (no windup).
    pub fn advance(&mut self, target: f64, h: f64) -> [f64; 3] {
        let now = self.state;
        let [x, rate, acc] = now;
        let w = self.w;
        let jerk = w.powi(3) * wrap_angle(target - x) - 3.0 * w * acc - 3.0 * w * w * rate;
        let rate_next = (rate + h * acc).clamp(-self.rate_max, self.rate_max);
        let acc_next = acc + h * jerk;
        let acc_next = if rate_next.abs() >= self.rate_max && acc_next * rate_next > 0.0 { 0.0 } else { acc_next };
        self.state = [wrap_angle(x + h * rate), rate_next, acc_next];
        now
    }
}

/// The PID of one rotational degree of freedom with inertia `m` and linear damping `d`
/// tracking a reference: the moment
///
/// ```text
/// tau = m a_r + d r_r - Kp e - Kd (r - r_r) - Ki int e,   e = x - x_r,
/// Kp = m wn^2,  Kd = 2 zeta wn m - d,  Ki = Kp wn / 10,
/// ```
///
/// the integral taken only within `band` of the reference (conditional integration:
/// no windup while a large step saturates the actuators).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleLoop {
    pub reference: ReferenceModel,
    pub wn: f64,
    pub zeta: f64,
    pub band: f64,
    integral: f64,
}

impl AngleLoop {
    /// Tracking `angle` now, the reference at bandwidth wn / 3 (our choice: the
    /// reference three times slower than the closed loop), rate-limited to `rate_max`.
    pub fn new(angle: f64, wn: f64, zeta: f64, rate_max: f64) -> Self {
        Self { reference: ReferenceModel::new(angle, wn / 3.0, rate_max), wn, zeta, band: 0.2, integral: 0.0 }
    }

    /// The moment toward `target` for angle `x` and rate `r`, the reference and the
    /// integral advanced over `h`.
    pub fn moment(&mut self, x: f64, r: f64, target: f64, m: f64, d: f64, h: f64) -> f64 {
        let [x_r, r_r, a_r] = self.reference.advance(target, h);
        let e = wrap_angle(x - x_r);
        let (kp, kd) = (m * self.wn * self.wn, 2.0 * self.zeta * self.wn * m - d);
        let ki = kp * self.wn / 10.0;
        let tau = m * a_r + d * r_r - kp * e - kd * (r - r_r) - ki * self.integral;
        if e.abs() < self.band {
            self.integral += e * h;
        }
        tau
    }
}

/// The PI on surge speed of both vehicles: the drag at the commanded speed fed forward
/// (`drag_at_command`), a proportional term of time constant 1 s and an integral of 10 s
/// on the surge inertia `m11`; the surge force asked of the propulsion.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SpeedLoop {
    integral: f64,
}

impl SpeedLoop {
    pub fn force(&mut self, u: f64, u_d: f64, drag_at_command: f64, m11: f64, h: f64) -> f64 {
        let eu = u - u_d;
        let x = drag_at_command - m11 * eu - 0.1 * m11 * self.integral;
        self.integral += eu * h;
        x
    }
}

/// What a world asks of a vehicle's autopilots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    pub heading_rad: f64,
    /// Surge speed, m/s.
    pub speed_m_s: f64,
    /// Depth, m (None for a surface craft).
    pub depth_m: Option<f64>,
}

/// A vehicle with its dynamics and autopilots, driven by commands.
pub trait Piloted {
    /// One step of `h` s toward `command`, in the current `current_ned` (m/s), which
    /// the autopilots are not told.
    fn step(&mut self, command: &Command, current_ned: &Vector3<f64>, h: f64);
    fn body(&self) -> &BodyState;
}

/// The dynamic vehicles' integration step in the worlds, at most (RK4; MSS uses 0.05 s).
pub const MAX_STEP_S: f64 = 0.05;

/// Steps `vehicle` over `dt` toward `command` in sub-steps of at most `h_max`.
pub fn step_over(vehicle: &mut dyn Piloted, command: &Command, current_ned: &Vector3<f64>, dt: f64, h_max: f64) {
    let sub = (dt / h_max).ceil().max(1.0) as usize;
    for _ in 0..sub {
        vehicle.step(command, current_ned, dt / sub as f64);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without the rate limit, a step of the reference model follows the closed form of
    /// three real poles at -w: x(t) = 1 - (1 + w t + (w t)^2 / 2) exp(-w t), within the
    /// Euler step's error.
    #[test]
    fn reference_model_step_is_the_triple_pole_response() {
        let (w, h) = (0.5, 1e-3);
        let mut m = ReferenceModel::new(0.0, w, f64::INFINITY);
        for k in 0..20_000 {
            let t = k as f64 * h;
            let x = m.advance(1.0, h)[0];
            let wt = w * t;
            let expected = 1.0 - (1.0 + wt + wt * wt / 2.0) * (-wt).exp();
            assert!((x - expected).abs() < 2e-3, "t {t}: {x} against {expected}");
        }
    }

    /// The rate limit holds through a large step, and the reference still arrives.
    #[test]
    fn reference_rate_is_limited() {
        let mut m = ReferenceModel::new(0.0, 0.5, 0.1);
        let mut peak = 0.0f64;
        for _ in 0..4000 {
            let [_, r, _] = m.advance(2.0, 0.01);
            peak = peak.max(r.abs());
        }
        assert!(peak <= 0.1 + 1e-12 && (m.state[0] - 2.0).abs() < 1e-3, "{peak} {:?}", m.state);
    }
}
