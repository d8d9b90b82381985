//! The REMUS 100 AUV (hoff2024's AUV) as a prolate spheroid of length 1.6 m and
//! diameter 0.19 m (../shared/vehicles.md): its displaced mass, and the added mass of a
//! prolate spheroid of eccentricity e by Lamb's k-factors (Lamb 1932, from alpha_0 and
//! beta_0; the added mass of a spheroid in Fossen 2021, ch. 6); the hull's damping,
//! cross-flow drag, tail fins and propeller ([`Remus100`]), and its heading, depth and
//! speed autopilots ([`Remus100Pilot`]).

use super::autopilot::{AngleLoop, Command, Piloted, SpeedLoop};
use super::rigid_body::{BodyState, G, Inertia, Vessel, restoring, rigid_body_mass, rk4_step};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

/// Sea water density used for the REMUS, kg/m^3.
pub const RHO: f64 = 1026.0;

/// A prolate spheroid's half axes a (along) and b (across), m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spheroid {
    pub a_m: f64,
    pub b_m: f64,
}

impl Spheroid {
    /// REMUS 100's hull: L = 1.6 m, D = 0.19 m.
    pub fn remus100() -> Self {
        Self { a_m: 0.8, b_m: 0.095 }
    }

    /// Its displaced mass (neutrally buoyant: the vehicle's mass), kg.
    pub fn mass_kg(&self) -> f64 {
        RHO * 4.0 / 3.0 * std::f64::consts::PI * self.a_m * self.b_m * self.b_m
    }

    /// Lamb's k-factors (k1 surge, k2 sway and heave, k' pitch and yaw).
    pub fn lamb_k(&self) -> (f64, f64, f64) {
        let e2 = 1.0 - (self.b_m / self.a_m).powi(2);
        let e = e2.sqrt();
        let log = ((1.0 + e) / (1.0 - e)).ln();
        let alpha0 = 2.0 * (1.0 - e2) / (e * e2) * (0.5 * log - e);
        let beta0 = 1.0 / e2 - (1.0 - e2) / (2.0 * e * e2) * log;
        let k1 = alpha0 / (2.0 - alpha0);
        let k2 = beta0 / (2.0 - beta0);
        let kp = e2 * e2 * (beta0 - alpha0) / ((2.0 - e2) * (2.0 * e2 - (2.0 - e2) * (beta0 - alpha0)));
        (k1, k2, kp)
    }
}

/// REMUS 100 as a [`Vessel`] (vehicles.md, hoff2024 sec. 4.1): the spheroid hull,
/// neutrally buoyant at the stated mass, its centre of gravity `cg_below_cb_m` under the
/// centre of buoyancy (the origin); linear damping from time constants (surge, sway,
/// heave 20 s; yaw 1 s) and damping ratios of the restoring oscillation (roll 0.3,
/// pitch 0.8); quadratic surge drag; cross-flow drag by strip theory; a rudder pair and
/// a stern-plane pair at the tail; the propeller. Its actuators are [rudder (rad),
/// stern planes (rad), propeller (rev/s)]: a positive rudder turns to starboard, positive
/// stern planes pitch the nose up.
#[derive(Debug, Clone, PartialEq)]
pub struct Remus100 {
    pub hull: Spheroid,
    /// The vehicle's mass (kg) and its buoyancy's equal (neutral).
    pub mass_kg: f64,
    pub cg_below_cb_m: f64,
    pub fins: Fins,
    pub propeller: Propeller,
    /// Parasitic (surge) drag coefficient on the frontal area pi b^2 (Allen et al. 2000:
    /// 0.42), and the two-dimensional cross-flow drag coefficient of a circular section
    /// (Hoerner 1965: 1.2, subcritical).
    pub cd_surge: f64,
    pub cd_cross: f64,
    inertia: Inertia,
    /// The added mass in surge, sway and heave (diagonal), kg.
    added_linear: Vector3<f64>,
    damping: Vector6<f64>,
}

/// A pair of tail fins (rudders or stern planes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fins {
    /// Area of one fin, m^2 (two per pair), and where the pairs act, m (body x).
    pub area_m2: f64,
    pub x_m: f64,
    /// Lift slopes of the rudder and stern-plane pairs, 1/rad.
    pub cl_rudder: f64,
    pub cl_stern: f64,
    /// Deflection limit, and the angle of attack beyond which the lift stops growing
    /// (stall: our choice, vehicles.md gives none), rad.
    pub max_rad: f64,
    pub stall_rad: f64,
}

/// The propeller: thrust and torque coefficients linear in the advance ratio J = Va /
/// (n D), fitted to the Wageningen B-series (3 blades, blade-area ratio 0.718) at J = 0
/// and J_max = 0.6632 (Fossen's REMUS 100 parameters: K_T 0.4566 -> 0.1798, K_Q 0.0700 ->
/// 0.0312), Va = (1 - w) u_r with wake fraction w = 0.056, thrust deduction t = 0.1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Propeller {
    pub diameter_m: f64,
    pub kt: [f64; 2],
    pub kq: [f64; 2],
    pub j_max: f64,
    pub wake: f64,
    pub deduction: f64,
    /// Shaft speed limit, rev/s (1525 rpm).
    pub n_max: f64,
}

impl Default for Fins {
    fn default() -> Self {
        Self {
            area_m2: 0.00665,
            x_m: -0.8,
            cl_rudder: 0.5,
            cl_stern: 0.7,
            max_rad: 20f64.to_radians(),
            stall_rad: 20f64.to_radians(),
        }
    }
}

impl Fins {
    /// The lift of a pair at dynamic pressure `q` (Pa) and angle of attack `alpha`,
    /// linear up to stall, flat beyond.
    fn lift(&self, q: f64, cl: f64, alpha: f64) -> f64 {
        q * 2.0 * self.area_m2 * cl * alpha.clamp(-self.stall_rad, self.stall_rad)
    }
}

impl Default for Propeller {
    fn default() -> Self {
        Self {
            diameter_m: 0.14,
            kt: [0.4566, 0.1798],
            kq: [0.0700, 0.0312],
            j_max: 0.6632,
            wake: 0.056,
            deduction: 0.1,
            n_max: 1525.0 / 60.0,
        }
    }
}

impl Propeller {
    /// The surge force (thrust less its deduction) and the torque on the hull at shaft
    /// speed `n` (rev/s) and relative surge speed `u_r`: K_T n |n| + slope (Va / D) |n|
    /// ahead, K_T0 n |n| astern.
    pub fn force(&self, n: f64, u_r: f64) -> (f64, f64) {
        let d = self.diameter_m;
        let va = (1.0 - self.wake) * u_r.max(0.0);
        let (kt, kq) = if n > 0.0 {
            let (st, sq) = ((self.kt[1] - self.kt[0]) / self.j_max, (self.kq[1] - self.kq[0]) / self.j_max);
            (self.kt[0] * n * n + st * va / d * n, self.kq[0] * n * n + sq * va / d * n)
        } else {
            (self.kt[0] * n * n.abs(), self.kq[0] * n * n.abs())
        };
        ((1.0 - self.deduction) * RHO * d.powi(4) * kt, RHO * d.powi(5) * kq)
    }

    /// The shaft speed (rev/s) that gives surge force `x` at relative surge speed `u_r`:
    /// the inverse of [`Propeller::force`], clamped to the limits.
    pub fn shaft_for(&self, x: f64, u_r: f64) -> f64 {
        let d = self.diameter_m;
        let c = (1.0 - self.deduction) * RHO * d.powi(4);
        let n = if x > 0.0 {
            let va = (1.0 - self.wake) * u_r.max(0.0);
            let (a, b) = (c * self.kt[0], c * (self.kt[1] - self.kt[0]) / self.j_max * va / d);
            (-b + (b * b + 4.0 * a * x).sqrt()) / (2.0 * a)
        } else {
            -(-x / (c * self.kt[0])).sqrt()
        };
        n.clamp(-self.n_max, self.n_max)
    }
}

impl Remus100 {
    pub fn new(hull: Spheroid, mass_kg: f64, cg_below_cb_m: f64) -> Self {
        let (a, b) = (hull.a_m, hull.b_m);
        let inertia_of = |m: f64| {
            Matrix3::from_diagonal(&Vector3::new(0.4 * m * b * b, 0.2 * m * (a * a + b * b), 0.2 * m * (a * a + b * b)))
        };
        // the vehicle's inertia from its mass on the spheroid's shape; the added mass
        // from the water the spheroid displaces
        let inertia = inertia_of(mass_kg);
        let (displaced, fluid) = (hull.mass_kg(), inertia_of(hull.mass_kg()));
        let (k1, k2, kp) = hull.lamb_k();
        let added =
            Vector6::new(k1 * displaced, k2 * displaced, k2 * displaced, 0.0, kp * fluid[(1, 1)], kp * fluid[(2, 2)]);
        let m =
            rigid_body_mass(mass_kg, &Vector3::new(0.0, 0.0, cg_below_cb_m), &inertia) + Matrix6::from_diagonal(&added);
        // roll and pitch: the restoring stiffness W BG and the damping ratio's share of
        // the critical damping 2 sqrt(K M)
        let stiffness = mass_kg * G * cg_below_cb_m;
        let critical = |k: usize| 2.0 * (stiffness * m[(k, k)]).sqrt();
        let damping = Vector6::new(
            m[(0, 0)] / 20.0,
            m[(1, 1)] / 20.0,
            m[(2, 2)] / 20.0,
            0.3 * critical(3),
            0.8 * critical(4),
            m[(5, 5)] / 1.0,
        );
        Self {
            hull,
            mass_kg,
            cg_below_cb_m,
            fins: Fins::default(),
            propeller: Propeller::default(),
            cd_surge: 0.42,
            cd_cross: 1.2,
            inertia: Inertia::new(m),
            added_linear: added.fixed_rows::<3>(0).into_owned(),
            damping,
        }
    }

    /// The linear damping coefficient of degree of freedom `k` (positive).
    pub fn damping(&self, k: usize) -> f64 {
        self.damping[k]
    }

    /// The drag in surge at relative speed `u_r` (positive against the motion): linear
    /// and quadratic on the frontal area.
    pub fn surge_drag(&self, u_r: f64) -> f64 {
        let area = std::f64::consts::PI * self.hull.b_m * self.hull.b_m;
        self.damping[0] * u_r + 0.5 * RHO * self.cd_surge * area * u_r * u_r.abs()
    }

    /// The moment per radian of a fin pair (rudder: yaw, stern planes: pitch) at
    /// relative surge speed `u_r`, N m / rad, before stall.
    pub fn fin_moment_per_rad(&self, cl: f64, u_r: f64) -> f64 {
        0.5 * RHO * u_r * u_r * 2.0 * self.fins.area_m2 * cl * self.fins.x_m.abs()
    }

    /// Cross-flow drag by strip theory over the spheroid (Fossen 2021, sec. 6.8; Hoerner):
    /// each strip of diameter D(x) = 2 b sqrt(1 - x^2 / a^2) sees the cross flow (v + x r,
    /// w - x q); sway and heave forces, and their pitch and yaw moments.
    fn cross_flow(&self, nu_r: &Vector6<f64>) -> Vector6<f64> {
        const STRIPS: usize = 16;
        let (a, b) = (self.hull.a_m, self.hull.b_m);
        let dx = 2.0 * a / STRIPS as f64;
        let mut f = Vector6::zeros();
        for i in 0..STRIPS {
            let x = -a + (i as f64 + 0.5) * dx;
            let diameter = 2.0 * b * (1.0 - (x / a).powi(2)).sqrt();
            let (vl, wl) = (nu_r[1] + x * nu_r[5], nu_r[2] - x * nu_r[4]);
            let k = 0.5 * RHO * self.cd_cross * diameter * dx * (vl * vl + wl * wl).sqrt();
            let (fy, fz) = (-k * vl, -k * wl);
            f[1] += fy;
            f[2] += fz;
            f[4] -= x * fz;
            f[5] += x * fy;
        }
        f
    }
}

impl Default for Remus100 {
    /// The 1.6 x 0.19 m spheroid at vehicles.md's stated 31.9 kg (the spheroid itself
    /// displaces 31.0 kg: the hull's free-flooding parts and its foam make up the rest),
    /// the centre of gravity 0.02 m under the centre of buoyancy.
    fn default() -> Self {
        Self::new(Spheroid::remus100(), 31.9, 0.02)
    }
}

impl Vessel for Remus100 {
    fn inertia(&self) -> &Inertia {
        &self.inertia
    }

    fn forces(&self, state: &BodyState, nu_r: &Vector6<f64>, actuators: &[f64]) -> Vector6<f64> {
        let w = self.mass_kg * G;
        let g = restoring(&state.attitude, w, w, &Vector3::new(0.0, 0.0, self.cg_below_cb_m), &Vector3::zeros());
        let mut d = self.damping.component_mul(nu_r);
        d[0] = self.surge_drag(nu_r[0]);
        let (rudder, stern, n) = (actuators[0], actuators[1], actuators[2]);
        // the fins at the tail: angle of attack = deflection + the local flow angle
        let fins = &self.fins;
        let u_r = nu_r[0];
        let q_dyn = 0.5 * RHO * u_r * u_r;
        let (v_f, w_f) = (nu_r[1] + fins.x_m * nu_r[5], nu_r[2] - fins.x_m * nu_r[4]);
        let lateral = -fins.lift(q_dyn, fins.cl_rudder, rudder + v_f.atan2(u_r.abs().max(1e-3)));
        let vertical = -fins.lift(q_dyn, fins.cl_stern, w_f.atan2(u_r.abs().max(1e-3)) - stern);
        let (thrust, torque) = self.propeller.force(n, u_r);
        let tau = Vector6::new(thrust, lateral, vertical, -torque, -fins.x_m * vertical, fins.x_m * lateral);
        // the hull's lift cancels the Munk moment v x (M_A v) of its added mass in pitch
        // and yaw (the assumption of Fossen 2021's REMUS 100 model: without it the bare
        // spheroid is directionally unstable and these small fins cannot hold it)
        let v = nu_r.fixed_rows::<3>(0).into_owned();
        let munk = v.cross(&self.added_linear.component_mul(&v));
        let lift = Vector6::new(0.0, 0.0, 0.0, 0.0, munk.y, munk.z);
        tau + lift + self.cross_flow(nu_r) - d - g
    }
}

/// REMUS 100's autopilots (hoff2024 sec. 4.3: a PI on depth, a PID on heading):
/// - heading: [`AngleLoop`] on the yaw inertia (wn = 2 rad/s, zeta = 1, reference rate
///   limited to 5 deg/s as vehicles.md), its yaw moment turned into a rudder angle by the
///   rudder's moment per radian at the present speed (gain scheduling);
/// - depth: a PI from the depth error to a pitch command (vehicles.md: Kp_z = 0.1 rad/m,
///   T_z = 100 s; limited to 20 deg, the integral frozen while limited), the pitch held by
///   an [`AngleLoop`] on the pitch inertia (wn = 3 rad/s, zeta = 1; reference rate
///   limited to 10 deg/s) with the restoring
///   moment W BG sin(theta_d) fed forward, through the stern planes likewise;
/// - speed: the drag at the commanded speed fed forward, a PI on the surge speed error
///   (time constant 1 s), turned into a shaft speed by inverting the propeller's thrust.
///
/// Fins follow their commands with a 0.1 s lag (vehicles.md), the shaft with 1 s (our
/// choice); fins are limited to 20 deg, the shaft to 1525 rpm. The bandwidths are our
/// choice (vehicles.md's MSS gains are for another fin model), tuned on the step
/// responses and the circle in a current of the tests below: at wn = 1 rad/s the heading
/// lagged the circle's turn enough that ILOS made the cross-track error worse (2.8 ->
/// 4.2 m RMS), at 2 rad/s it removes it (1.0 -> 0.28 m).
#[derive(Debug, Clone, PartialEq)]
pub struct Remus100Pilot {
    pub remus: Remus100,
    pub state: BodyState,
    /// Rudder, stern planes (rad), shaft (rev/s), as they are.
    pub actuators: [f64; 3],
    pub heading: AngleLoop,
    pub pitch: AngleLoop,
    pub kp_z: f64,
    pub t_z_s: f64,
    pub max_pitch_rad: f64,
    depth_integral: f64,
    speed: SpeedLoop,
}

impl Remus100Pilot {
    /// At `state`, its actuators at rest.
    pub fn new(remus: Remus100, state: BodyState) -> Self {
        let (_, theta, psi) = state.euler();
        Self {
            remus,
            state,
            actuators: [0.0; 3],
            heading: AngleLoop::new(psi, 2.0, 1.0, 5f64.to_radians()),
            pitch: AngleLoop::new(theta, 3.0, 1.0, 10f64.to_radians()),
            kp_z: 0.1,
            t_z_s: 100.0,
            max_pitch_rad: 20f64.to_radians(),
            depth_integral: 0.0,
            speed: SpeedLoop::default(),
        }
    }

    /// Level at `position` heading `psi` at surge speed `u` through still water, the
    /// shaft at the speed that holds it.
    pub fn cruising(remus: Remus100, position: Vector3<f64>, psi: f64, u: f64) -> Self {
        let mut state = BodyState::at_rest(position, psi);
        state.nu[0] = u;
        let mut p = Self::new(remus, state);
        p.actuators[2] = p.remus.propeller.shaft_for(p.remus.surge_drag(u), u);
        p
    }
}

impl Piloted for Remus100Pilot {
    fn step(&mut self, command: &Command, current_ned: &Vector3<f64>, h: f64) {
        let m = &self.remus.inertia().m;
        let (m11, m55, m66) = (m[(0, 0)], m[(4, 4)], m[(5, 5)]);
        let (_, theta, psi) = self.state.euler();
        let nu = self.state.nu;
        let u_r = nu[0] - self.state.attitude.inverse_transform_vector(current_ned).x;
        let fin_speed = u_r.max(0.3); // below it the fins' authority is not worth scheduling on
        // heading
        let n_cmd = self.heading.moment(psi, nu[5], command.heading_rad, m66, self.remus.damping(5), h);
        let rudder = n_cmd / self.remus.fin_moment_per_rad(self.remus.fins.cl_rudder, fin_speed);
        // depth -> pitch -> stern planes
        let z = self.state.position_ned_m.z;
        let ez = command.depth_m.map_or(0.0, |zd| z - zd);
        let theta_d = self.kp_z * (ez + self.depth_integral / self.t_z_s);
        let limited = theta_d.abs() > self.max_pitch_rad;
        let theta_d = theta_d.clamp(-self.max_pitch_rad, self.max_pitch_rad);
        if !limited {
            self.depth_integral += ez * h;
        }
        let restoring = self.remus.mass_kg * G * self.remus.cg_below_cb_m;
        let m_cmd = self.pitch.moment(theta, nu[4], theta_d, m55, self.remus.damping(4), h) + restoring * theta_d.sin();
        let stern = m_cmd / self.remus.fin_moment_per_rad(self.remus.fins.cl_stern, fin_speed);
        // speed
        let u_d = command.speed_m_s;
        let x_cmd = self.speed.force(nu[0], u_d, self.remus.surge_drag(u_d), m11, h);
        let shaft = self.remus.propeller.shaft_for(x_cmd, u_r);
        let max = self.remus.fins.max_rad;
        let cmd = [rudder.clamp(-max, max), stern.clamp(-max, max), shaft];
        for ((a, c), lag) in self.actuators.iter_mut().zip(cmd).zip([0.1, 0.1, 1.0]) {
            *a = c + (*a - c) * (-h / lag).exp();
        }
        self.state = rk4_step(&self.remus, &self.state, &self.actuators, current_ned, h);
    }

    fn body(&self) -> &BodyState {
        &self.state
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Neutrally buoyant and level at rest, it stays put: 10 min at 0.05 s, under 1e-12
    /// m and rad.
    #[test]
    fn at_rest_it_stays_put() {
        let remus = Remus100::default();
        let start = BodyState::at_rest(Vector3::new(5.0, -3.0, 30.0), 0.7);
        let mut s = start;
        for _ in 0..12_000 {
            s = rk4_step(&remus, &s, &[0.0; 3], &Vector3::zeros(), 0.05);
        }
        assert!((s.position_ned_m - start.position_ned_m).norm() < 1e-12);
        assert!(s.attitude.angle_to(&start.attitude) < 1e-12 && s.nu.norm() < 1e-12);
    }

    /// Yaw and heave are decoupled on this hull (no products of inertia, the centre of
    /// gravity straight under the origin), so without the cross-flow drag (quadratic) a
    /// yaw rate or a heave speed decays as exp(-t / T) with the time constant their
    /// linear damping is defined by (1 s and 20 s): within 1e-8 after 3 s and 60 s.
    #[test]
    fn linear_damping_time_constants_match_their_definitions() {
        let remus = Remus100 { cd_cross: 0.0, ..Remus100::default() };
        for (k, t) in [(5, 1.0), (2, 20.0)] {
            let mut s = BodyState::at_rest(Vector3::new(0.0, 0.0, 30.0), 0.0);
            s.nu[k] = 0.2;
            let h = 0.01;
            for _ in 0..(3.0 * t / h) as usize {
                s = rk4_step(&remus, &s, &[0.0; 3], &Vector3::zeros(), h);
            }
            let expected = 0.2 * (-3.0f64).exp();
            assert!((s.nu[k] - expected).abs() < 1e-8, "{k}: {} against {expected}", s.nu[k]);
        }
    }

    /// Lamb's k-factors of REMUS 100's spheroid against vehicles.md's k1 ~ 0.027,
    /// k2 ~ 0.949, k' ~ 0.851 (to the last digit printed); a sphere's are 1/2, 1/2, 0
    /// (the limit e -> 0, approached at b = 0.999 a).
    #[test]
    fn lamb_factors_match_the_printed_values() {
        let (k1, k2, kp) = Spheroid::remus100().lamb_k();
        assert!((k1 - 0.027).abs() < 5e-4 && (k2 - 0.949).abs() < 5e-4 && (kp - 0.851).abs() < 5e-4, "{k1} {k2} {kp}");
        let (k1, k2, kp) = Spheroid { a_m: 1.0, b_m: 0.999 }.lamb_k();
        assert!((k1 - 0.5).abs() < 2e-3 && (k2 - 0.5).abs() < 2e-3 && kp.abs() < 2e-3, "{k1} {k2} {kp}");
    }

    fn cmd(heading_deg: f64, speed_m_s: f64, depth_m: f64) -> Command {
        Command { heading_rad: heading_deg.to_radians(), speed_m_s, depth_m: Some(depth_m) }
    }

    /// At 1525 rpm (the shaft's limit) from rest, the fins at zero: the speed settles
    /// where the propeller's thrust (K_T linear in J) equals the drag (linear from the 20
    /// s time constant, quadratic from Cd 0.42 on the frontal area), the root of that
    /// balance written out here, within 1e-3 m/s; vehicles.md says about 2.5 m/s (within
    /// 5 %).
    #[test]
    fn full_shaft_speed_reaches_the_top_speed() {
        let remus = Remus100::default();
        let n = 1525.0 / 60.0;
        let mut s = BodyState::at_rest(Vector3::new(0.0, 0.0, 30.0), 0.0);
        for _ in 0..(300.0 / 0.05) as usize {
            s = rk4_step(&remus, &s, &[0.0, 0.0, n], &Vector3::zeros(), 0.05);
        }
        // 0.9 rho D^4 (0.4566 n^2 + (0.1798 - 0.4566) / 0.6632 * 0.944 u n / D) = d u + c u^2
        let (rho, d) = (1026.0, 0.14f64);
        let m11 = remus.inertia().m[(0, 0)];
        let c = 0.5 * rho * 0.42 * std::f64::consts::PI * 0.095f64.powi(2);
        let thrust0 = 0.9 * rho * d.powi(4) * 0.4566 * n * n;
        let slope = 0.9 * rho * d.powi(3) * (0.1798 - 0.4566) / 0.6632 * 0.944 * n;
        let lin = m11 / 20.0 - slope;
        let u = (-lin + (lin * lin + 4.0 * c * thrust0).sqrt()) / (2.0 * c);
        let (_, theta, _) = s.euler();
        eprintln!(
            "REMUS 100 at 1525 rpm: {:.3} m/s (balance {u:.3}), roll {:.1} deg from the propeller's torque",
            s.nu[0],
            s.euler().0.to_degrees()
        );
        assert!((s.nu[0] - u).abs() < 1e-3 && (u / 2.5 - 1.0).abs() < 0.05, "{} against {u}", s.nu[0]);
        assert!(theta.abs() < 1e-3);
    }

    /// Full rudder (20 deg) at 1525 rpm, the stern planes at zero: the steady turning
    /// circle's diameter over the third lap (printed; no printed value to test it
    /// against), a clockwise turn whose diameter is many body lengths (the fins' lift
    /// against the hull's yaw damping).
    #[test]
    fn turning_circle_at_full_rudder() {
        let remus = Remus100::default();
        let mut s = BodyState::at_rest(Vector3::new(0.0, 0.0, 30.0), 0.0);
        s.nu[0] = 2.5;
        let act = [20f64.to_radians(), 0.0, 1525.0 / 60.0];
        let (mut north, mut east) = ((f64::INFINITY, f64::NEG_INFINITY), (f64::INFINITY, f64::NEG_INFINITY));
        let (mut t, mut yaw) = (0.0, 0.0);
        let mut last_psi = 0.0;
        while yaw < 3.0 * std::f64::consts::TAU {
            s = rk4_step(&remus, &s, &act, &Vector3::zeros(), 0.05);
            t += 0.05;
            let psi = s.euler().2;
            yaw += onebeacon::geo::wrap_angle(psi - last_psi);
            last_psi = psi;
            if yaw > 2.0 * std::f64::consts::TAU {
                let p = s.position_ned_m;
                north = (north.0.min(p.x), north.1.max(p.x));
                east = (east.0.min(p.y), east.1.max(p.y));
            }
            assert!(t < 2000.0, "no turn: yaw {yaw}");
        }
        let (dn, de) = (north.1 - north.0, east.1 - east.0);
        eprintln!(
            "REMUS 100 full rudder at 1525 rpm: turning diameter {dn:.2} m (north) / {de:.2} m (east), {:.2} m/s, yaw rate {:.2} deg/s, depth change {:.2} m",
            s.nu[0],
            s.nu[5].to_degrees(),
            s.position_ned_m.z - 30.0
        );
        assert!(s.nu[5] > 0.0 && (dn / de - 1.0).abs() < 0.02 && dn > 3.0 * 1.6, "{dn} {de}");
    }

    /// The autopilots' step responses at 1.5 m/s, RK4 at 0.05 s (printed): a 30 deg
    /// heading step settles within 0.5 deg in 60 s with under 10 % overshoot; a 10 m depth
    /// step (30 -> 40 m) settles within 0.2 m in 300 s with under 10 % overshoot, the
    /// heading held meanwhile; the speed stays within 0.05 m/s of its command.
    #[test]
    fn autopilot_step_responses() {
        let start = || Remus100Pilot::cruising(Remus100::default(), Vector3::new(0.0, 0.0, 30.0), 0.0, 1.5);
        let (h, still) = (0.05, Vector3::zeros());
        let mut p = start();
        let target = 30f64.to_radians();
        let (mut rise, mut peak) = (f64::NAN, 0.0f64);
        for i in 0..(60.0 / h) as usize {
            p.step(&cmd(30.0, 1.5, 30.0), &still, h);
            let psi = p.state.euler().2;
            if rise.is_nan() && psi >= 0.9 * target {
                rise = i as f64 * h;
            }
            peak = peak.max(psi);
        }
        let overshoot = (peak - target) / target;
        eprintln!("REMUS 100 heading 30 deg: rise (to 90 %) {rise:.2} s, overshoot {:.1} %", 100.0 * overshoot);
        assert!((p.state.euler().2 - target).abs() < 0.5f64.to_radians() && overshoot < 0.1);

        let mut p = start();
        let (mut rise, mut peak, mut speed_dev, mut heading_dev) = (f64::NAN, 0.0f64, 0.0f64, 0.0f64);
        for i in 0..(300.0 / h) as usize {
            p.step(&cmd(0.0, 1.5, 40.0), &still, h);
            let z = p.state.position_ned_m.z - 30.0;
            if rise.is_nan() && z >= 9.0 {
                rise = i as f64 * h;
            }
            peak = peak.max(z);
            if i as f64 * h > 20.0 {
                speed_dev = speed_dev.max((p.state.nu[0] - 1.5).abs());
            }
            heading_dev = heading_dev.max(p.state.euler().2.abs());
        }
        let overshoot = (peak - 10.0) / 10.0;
        eprintln!(
            "REMUS 100 depth 30 -> 40 m: rise (to 90 %) {rise:.1} s, overshoot {:.1} %; speed within {speed_dev:.3} m/s, heading within {:.2} deg",
            100.0 * overshoot,
            heading_dev.to_degrees()
        );
        assert!((p.state.position_ned_m.z - 40.0).abs() < 0.2 && overshoot < 0.1, "{}", p.state.position_ned_m.z);
        assert!(speed_dev < 0.05, "{speed_dev}");
    }

    /// ILOS on the 500 m circle at 30 m and 1.5 m/s in a 0.2 m/s current from the west
    /// (printed for the closing note): as for the Otter, the integral must cut the RMS
    /// cross-track error over the second lap to half that of plain LOS, which must exceed
    /// 0.5 m (the current acts).
    #[test]
    fn ilos_on_the_circle_in_a_current() {
        use crate::vehicles::ilos::circle_cross_track_rms;
        let rms = |kappa: f64| {
            circle_cross_track_rms(
                |at, psi| Remus100Pilot::cruising(Remus100::default(), at, psi, 1.5),
                Some(30.0),
                1.5,
                kappa,
                0.05,
            )
        };
        let (los, with) = (rms(0.0), rms(0.1));
        eprintln!(
            "REMUS 100, 500 m circle, 0.2 m/s current: cross-track RMS over the second lap {los:.3} m (LOS), {with:.3} m (ILOS, kappa 0.1)"
        );
        assert!(los > 0.5 && with < 0.5 * los, "{with} against {los}");
    }
}
