//! Acoustic propagation between moving ends (sousa 4.1.2): a ping leaves the beacon at
//! t_tx and reaches the receiver when the spherical wavefront, growing at the speed of
//! sound, meets the receiver's path. The arrival is solved exactly within a step for a
//! receiver moving in a straight line during the step, not quantised to the step.

use nalgebra::Vector3;

/// A ping in flight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ping {
    pub t_tx: f64,
    /// Where it left (true position of the transducer).
    pub origin: Vector3<f64>,
}

impl Ping {
    /// The reception time within the step from (t0, p0) to (t1, p1) of a receiver
    /// moving linearly between them, if the wavefront reaches it in (t0, t1].
    /// Solves |p(t) - origin| = c (t - t_tx), a quadratic in t - t0.
    pub fn arrival(&self, c: f64, t0: f64, p0: &Vector3<f64>, t1: f64, p1: &Vector3<f64>) -> Option<f64> {
        let dt = t1 - t0;
        let d0 = p0 - self.origin;
        let v = (p1 - p0) / dt;
        let a0 = t0 - self.t_tx; // time already in flight at t0
        let g = |tau: f64| (d0 + v * tau).norm() - c * (a0 + tau);
        if g(0.0) <= 0.0 || g(dt) > 0.0 {
            return None; // arrived before this step, or not yet
        }
        // (v.v - c^2) tau^2 + 2 (d0.v - c^2 a0) tau + (d0.d0 - c^2 a0^2) = 0
        let qa = v.dot(&v) - c * c;
        let qb = 2.0 * (d0.dot(&v) - c * c * a0);
        let qc = d0.dot(&d0) - c * c * a0 * a0;
        let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
        // numerically stable roots; keep the one in (0, dt]
        let q = -0.5 * (qb + qb.signum() * disc);
        let roots = [q / qa, if q != 0.0 { qc / q } else { f64::NAN }];
        roots
            .into_iter()
            .filter(|tau| tau.is_finite() && *tau > 0.0 && *tau <= dt * (1.0 + 1e-12))
            .map(|tau| t0 + tau.min(dt))
            .reduce(f64::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// A receiver moving radially away at speed v from 100 m: it hears the ping sent at
    /// t = 0 when c t = 100 + v t, i.e. t = 100 / (c - v).
    #[test]
    fn radial_motion_matches_the_analytic_arrival() {
        let (c, v) = (1500.0, 3.0);
        let ping = Ping { t_tx: 0.0, origin: Vector3::zeros() };
        let dir = Vector3::new(0.6, 0.0, 0.8);
        let pos = |t: f64| dir * (100.0 + v * t);
        let expected = 100.0 / (c - v);
        let dt = 0.1;
        let mut found = None;
        let mut t = 0.0;
        while found.is_none() && t < 1.0 {
            found = ping.arrival(c, t, &pos(t), t + dt, &pos(t + dt));
            t += dt;
        }
        assert_relative_eq!(found.unwrap(), expected, max_relative = 1e-12);
        // and toward the transducer
        let pos = |t: f64| dir * (100.0 - v * t);
        let arrival = ping.arrival(c, 0.0, &pos(0.0), 0.1, &pos(0.1)).unwrap();
        assert_relative_eq!(arrival, 100.0 / (c + v), max_relative = 1e-12);
    }

    #[test]
    fn no_arrival_outside_the_step() {
        let ping = Ping { t_tx: 0.0, origin: Vector3::zeros() };
        let p = Vector3::new(300.0, 0.0, 0.0); // 0.2 s away at 1500 m/s
        assert!(ping.arrival(1500.0, 0.0, &p, 0.1, &p).is_none());
        assert!(ping.arrival(1500.0, 0.1, &p, 0.2, &p).is_some());
        assert!(ping.arrival(1500.0, 0.2, &p, 0.3, &p).is_none());
    }
}
