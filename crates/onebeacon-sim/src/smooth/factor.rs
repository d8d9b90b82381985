//! The smoother's factors: what each measurement says about the poses and calibration
//! variables it touches, as a whitened residual (residual over its standard deviation)
//! and its Jacobian. A node holds a pose (north, east, heading, the heading kept
//! continuous along the trajectory) for a vehicle that measures its motion, or a
//! position and velocity (north, east, vN, vE) for a craft tracked with a
//! constant-velocity model ([`Node`]). Ranges, Doppler speeds and bearings are the
//! filters' measurement models (`onebeacon::measure`), read at the factor's variables.

use nalgebra::{SVector, Vector3};
use onebeacon::geo::wrap_angle;
use onebeacon::measure::{LineOfSightSpeed, ScalarModel, SlantRange, Usbl};
use onebeacon::nav::tracking::white_acceleration_noise;

/// Most variables one factor touches: two poses and four calibration variables.
pub(crate) const MAX_VARS: usize = 10;

/// A factor's whitened linearisation: `m` residuals over `n` variables (global indices
/// `vars`), row-major Jacobian.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Linear {
    pub m: usize,
    pub n: usize,
    pub vars: [usize; MAX_VARS],
    pub r: [f64; 3],
    pub j: [[f64; MAX_VARS]; 3],
}

/// Which calibration variables a factor reads (global indices), `None` where the
/// smoother does not estimate that one (its nominal value is used: scale 1, offset 0).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct CalVars {
    pub scale: Option<usize>,
    pub offset: Option<usize>,
    pub drift: Option<usize>,
}

/// What a graph's nodes hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Node {
    /// North, east, heading: a vehicle whose motion rows join its nodes.
    Pose,
    /// North, east, vN, vE: a craft without motion rows, joined by a constant-velocity
    /// model.
    Track,
}

impl Node {
    /// Variables per node.
    pub(crate) fn size(self) -> usize {
        match self {
            Node::Pose => 3,
            Node::Track => 4,
        }
    }
}

/// Where an acoustic measurement sits between two nodes: the position at its time is
/// (1 - alpha) p_k + alpha p_(k+1) (alpha 0 with no later node).
#[derive(Debug, Clone, Copy)]
pub(crate) struct At {
    pub k: usize,
    pub alpha: f64,
    /// The node after k exists (alpha and the interval's velocity apply).
    pub next: bool,
    /// Seconds between nodes k and k + 1.
    pub dt_s: f64,
    pub node: Node,
}

impl At {
    /// Pushes the variables a measurement here reads: node k's position, node k + 1's
    /// when `next`, then node k's velocity when asked and the nodes hold one.
    fn push_vars(&self, push: &mut dyn FnMut(usize), velocity: bool) {
        let s = self.node.size();
        push(s * self.k);
        push(s * self.k + 1);
        if self.next {
            push(s * (self.k + 1));
            push(s * (self.k + 1) + 1);
        }
        if velocity && self.node == Node::Track {
            push(s * self.k + 2);
            push(s * self.k + 3);
        }
    }

    /// How many local variables the positions take.
    fn positions(&self) -> usize {
        if self.next { 4 } else { 2 }
    }
}

#[derive(Debug, Clone)]
pub(crate) enum Factor {
    /// A Gaussian prior on pose k (the start).
    PosePrior { k: usize, mean: [f64; 3], sigma: [f64; 3] },
    /// A Gaussian prior on one variable (a calibration variable, a track's start).
    Prior { var: usize, mean: f64, sigma: f64 },
    /// Motion from node k to k + 1: body-frame forward and lateral distance along the
    /// mid-step heading (psi_k + psi_(k+1)) / 2, and the heading change (times the turn
    /// scale); `turn` None: no turn measured (a weak zero-mean turn, `sigma[2]`).
    Motion {
        k: usize,
        forward_m: f64,
        lateral_m: f64,
        turn_rad: Option<f64>,
        sigma: [f64; 3],
        turn_scale: Option<usize>,
        distance_scale: Option<usize>,
    },
    /// An absolute heading (compass, AHRS) at node k.
    Heading { k: usize, heading_rad: f64, sigma: f64 },
    /// Constant velocity from track node k to k + 1 on one axis (0 north, 1 east):
    /// position and velocity after `dt_s` of white acceleration of spectral density `q`
    /// ((m/s^2)^2 s), p1 - p0 - dt v0 and v1 - v0 weighed by its covariance, the
    /// tracker's [`white_acceleration_noise`].
    ConstantVelocity { k: usize, axis: usize, dt_s: f64, q: f64 },
    /// A range: z = s |p(t) - b| + offset + drift (t - t0), the distance slant with the
    /// vertical offset `dz_m` between vehicle and beacon: the filters' [`SlantRange`]
    /// (scale s = 1 + k) with the offset's drift.
    Range { at: At, beacon: [f64; 2], dz_m: f64, range_m: f64, sigma: f64, cal: CalVars, t_rel_s: f64 },
    /// A Doppler radial speed, positive when closing (garin2024 eq. 13): -u . v, u the
    /// unit vector from the beacon to p(t), v the velocity over the node interval (a
    /// track node's own velocity): [`LineOfSightSpeed`].
    Doppler { at: At, beacon: [f64; 2], dz_m: f64, speed_m_s: f64, sigma: f64 },
    /// A USBL bearing on a station (hoff2024 eq. 1-2): azimuth from the station's
    /// heading and elevation from the vertical, as [`Usbl::angles`] gives them.
    Bearing { at: At, station: [f64; 3], station_heading_rad: f64, depth_m: f64, az_el: [f64; 2], sigma: f64 },
}

impl Factor {
    /// Whether a heavy-tailed kernel and a gate apply (the acoustic measurements and
    /// heading fixes; motion and priors are Gaussian).
    pub(crate) fn is_measurement(&self) -> bool {
        matches!(self, Factor::Heading { .. } | Factor::Range { .. } | Factor::Doppler { .. } | Factor::Bearing { .. })
    }

    /// The variables this factor reads, in the order of its local vector.
    pub(crate) fn vars(&self) -> ([usize; MAX_VARS], usize) {
        let mut v = [0; MAX_VARS];
        let mut n = 0;
        let mut push = |i: usize| {
            v[n] = i;
            n += 1;
        };
        let pose = |push: &mut dyn FnMut(usize), k: usize| (0..3).for_each(|i| push(3 * k + i));
        match self {
            Factor::PosePrior { k, .. } | Factor::Heading { k, .. } => pose(&mut push, *k),
            Factor::Prior { var, .. } => push(*var),
            Factor::Motion { k, turn_scale, distance_scale, .. } => {
                pose(&mut push, *k);
                pose(&mut push, k + 1);
                turn_scale.iter().chain(distance_scale).for_each(|&i| push(i));
            }
            Factor::ConstantVelocity { k, axis, .. } => {
                let (a, b) = (4 * k + axis, 4 * (k + 1) + axis);
                [a, a + 2, b, b + 2].into_iter().for_each(push);
            }
            Factor::Range { at, cal, .. } => {
                at.push_vars(&mut push, false);
                cal.scale.iter().chain(&cal.offset).chain(&cal.drift).for_each(|&i| push(i));
            }
            Factor::Doppler { at, .. } => at.push_vars(&mut push, true),
            Factor::Bearing { at, .. } => at.push_vars(&mut push, false),
        }
        (v, n)
    }

    /// The whitened residuals at the local values `x` (in the order of [`Factor::vars`]).
    pub(crate) fn residual(&self, x: &[f64]) -> ([f64; 3], usize) {
        match self {
            Factor::PosePrior { mean, sigma, .. } => {
                ([(x[0] - mean[0]) / sigma[0], (x[1] - mean[1]) / sigma[1], wrap_angle(x[2] - mean[2]) / sigma[2]], 3)
            }
            Factor::Prior { mean, sigma, .. } => ([(x[0] - mean) / sigma, 0.0, 0.0], 1),
            Factor::Heading { heading_rad, sigma, .. } => ([wrap_angle(x[2] - heading_rad) / sigma, 0.0, 0.0], 1),
            Factor::Motion { forward_m, lateral_m, turn_rad, sigma, turn_scale, distance_scale, .. } => {
                let mut i = 6;
                let mut next = |on: bool| {
                    if on {
                        i += 1;
                        x[i - 1]
                    } else {
                        1.0
                    }
                };
                let (kt, kd) = (next(turn_scale.is_some()), next(distance_scale.is_some()));
                let (f, l, dpsi) = body_motion(x);
                (
                    [
                        (f - kd * forward_m) / sigma[0],
                        (l - kd * lateral_m) / sigma[1],
                        (dpsi - kt * turn_rad.unwrap_or(0.0)) / sigma[2],
                    ],
                    3,
                )
            }
            Factor::ConstantVelocity { dt_s, q, .. } => {
                let (w, _) = white_acceleration(*dt_s, *q, [x[2] - x[0] - dt_s * x[1], x[3] - x[1]]);
                ([w[0], w[1], 0.0], 2)
            }
            Factor::Range { at, beacon, dz_m, range_m, sigma, cal, t_rel_s } => {
                let r = range(at, *beacon, *dz_m, cal, x);
                ([(r.predicted() + r.drift * t_rel_s - range_m) / sigma, 0.0, 0.0], 1)
            }
            Factor::Doppler { at, beacon, dz_m, speed_m_s, sigma } => match closing_speed(at, *beacon, *dz_m, x) {
                Some((model, state)) => {
                    ([(ScalarModel::<4>::predict(&model, &state) - speed_m_s) / sigma, 0.0, 0.0], 1)
                }
                None => ([0.0; 3], 1),
            },
            Factor::Bearing { at, station, station_heading_rad, depth_m, az_el, sigma } => {
                let p = position(at, x);
                let usbl = Usbl::exact(Vector3::from(*station), *station_heading_rad, 0.0);
                // hoff2024 eq. 1-2: azimuth from the station's heading, elevation from the vertical
                let (az, el, _) = usbl.angles(&Vector3::new(p[0], p[1], *depth_m));
                ([wrap_angle(az - az_el[0]) / sigma, (el - az_el[1]) / sigma, 0.0], 2)
            }
        }
    }

    /// The whitened residuals and Jacobian at the global state `x`: analytic for the
    /// priors, motion, ranges and Doppler speeds (all but a few factors of a log),
    /// central differences for bearings.
    pub(crate) fn linearize(&self, x: &[f64]) -> Linear {
        let (vars, n, mut local) = self.local(x);
        let (r, m) = self.residual(&local[..n]);
        let mut lin = Linear { m, n, vars, r, j: [[0.0; MAX_VARS]; 3] };
        if !self.jacobian(&local[..n], &mut lin.j) {
            numeric_jacobian(self, &mut local, n, &mut lin.j);
        }
        lin
    }

    /// The whitened residuals at the global state `x`, and how many.
    pub(crate) fn whitened(&self, x: &[f64]) -> ([f64; 3], usize) {
        let (_, n, local) = self.local(x);
        self.residual(&local[..n])
    }

    /// A range's slant distance at the global state `x` (its scale, offset and drift
    /// aside), with the range and its sigma; None for other factors.
    pub(crate) fn range_slant(&self, x: &[f64]) -> Option<(f64, f64, f64)> {
        let Factor::Range { at, beacon, dz_m, range_m, sigma, .. } = self else { return None };
        let (_, _, local) = self.local(x);
        let slant = range(at, *beacon, *dz_m, &CalVars::default(), &local).predicted();
        Some((slant, *range_m, *sigma))
    }

    /// This factor's variables and their values gathered from the global state.
    fn local(&self, x: &[f64]) -> ([usize; MAX_VARS], usize, [f64; MAX_VARS]) {
        let (vars, n) = self.vars();
        let mut local = [0.0; MAX_VARS];
        for (l, &v) in local.iter_mut().zip(&vars[..n]) {
            *l = x[v];
        }
        (vars, n, local)
    }

    /// Writes the analytic Jacobian where this factor has one (false: none).
    fn jacobian(&self, x: &[f64], j: &mut [[f64; MAX_VARS]; 3]) -> bool {
        match self {
            Factor::PosePrior { sigma, .. } => (0..3).for_each(|i| j[i][i] = 1.0 / sigma[i]),
            Factor::Prior { sigma, .. } => j[0][0] = 1.0 / sigma,
            Factor::Heading { sigma, .. } => j[0][2] = 1.0 / sigma,
            Factor::ConstantVelocity { dt_s, q, .. } => {
                // d(p1 - p0 - dt v0) and d(v1 - v0) over (p0, v0, p1, v1), whitened
                let (_, l) = white_acceleration(*dt_s, *q, [0.0, 0.0]);
                let de = [[-1.0, -dt_s, 1.0, 0.0], [0.0, -1.0, 0.0, 1.0]];
                for c in 0..4 {
                    j[0][c] = de[0][c] / l[0];
                    j[1][c] = (de[1][c] - l[1] * j[0][c]) / l[2];
                }
            }
            Factor::Motion { forward_m, lateral_m, turn_rad, sigma, turn_scale, distance_scale, .. } => {
                let (f, l, _) = body_motion(x);
                let psi_m = 0.5 * (x[2] + x[5]);
                let (c, s) = (psi_m.cos(), psi_m.sin());
                // forward f = c dn + s de, lateral l = -s dn + c de; d f / d psi_m = l, d l / d psi_m = -f
                let rows = [[c, s, 0.5 * l], [-s, c, -0.5 * f]];
                for (row, r) in rows.iter().enumerate() {
                    j[row][..3].copy_from_slice(&[-r[0] / sigma[row], -r[1] / sigma[row], r[2] / sigma[row]]);
                    j[row][3..6].copy_from_slice(&[r[0] / sigma[row], r[1] / sigma[row], r[2] / sigma[row]]);
                }
                j[2][2] = -1.0 / sigma[2];
                j[2][5] = 1.0 / sigma[2];
                let mut i = 6;
                if turn_scale.is_some() {
                    j[2][i] = -turn_rad.unwrap_or(0.0) / sigma[2];
                    i += 1;
                }
                if distance_scale.is_some() {
                    j[0][i] = -forward_m / sigma[0];
                    j[1][i] = -lateral_m / sigma[1];
                }
            }
            Factor::Range { at, beacon, dz_m, sigma, cal, t_rel_s, .. } => {
                let (gradient, d_scale) = range(at, *beacon, *dz_m, cal, x).gradient(at);
                let mut i = at.positions();
                for (c, gc) in gradient.iter().enumerate().take(i) {
                    j[0][c] = gc / sigma;
                }
                // d/d offset: 1; d/d drift: t
                let d_cal =
                    [(cal.scale.is_some(), d_scale), (cal.offset.is_some(), 1.0), (cal.drift.is_some(), *t_rel_s)];
                for (on, d) in d_cal {
                    if on {
                        j[0][i] = d / sigma;
                        i += 1;
                    }
                }
            }
            Factor::Doppler { at, beacon, dz_m, sigma, .. } => {
                if let Some((model, state)) = closing_speed(at, *beacon, *dz_m, x) {
                    for (c, gc) in closing_speed_gradient(at, &model, &state).iter().enumerate() {
                        j[0][c] = gc / sigma;
                    }
                }
            }
            Factor::Bearing { .. } => return false,
        }
        true
    }
}

/// Central differences of the whitened residual (step 1e-6 of each variable's scale).
fn numeric_jacobian(f: &Factor, x: &mut [f64; MAX_VARS], n: usize, j: &mut [[f64; MAX_VARS]; 3]) {
    for c in 0..n {
        let x0 = x[c];
        let h = 1e-6 * x0.abs().max(1.0);
        x[c] = x0 + h;
        let (up, m) = f.residual(&x[..n]);
        x[c] = x0 - h;
        let (down, _) = f.residual(&x[..n]);
        x[c] = x0;
        for row in 0..m {
            j[row][c] = (up[row] - down[row]) / (2.0 * h);
        }
    }
}

/// The motion between two poses (local x = pose k, pose k + 1) in the frame of the
/// mid-step heading: forward, lateral, heading change.
fn body_motion(x: &[f64]) -> (f64, f64, f64) {
    let (dn, de) = (x[3] - x[0], x[4] - x[1]);
    let psi_m = 0.5 * (x[2] + x[5]);
    let (c, s) = (psi_m.cos(), psi_m.sin());
    (c * dn + s * de, -s * dn + c * de, x[5] - x[2])
}

/// The horizontal position at a measurement's time, interpolated between its nodes
/// (local x: node k's position, then node k + 1's).
fn position(at: &At, x: &[f64]) -> [f64; 2] {
    if !at.next {
        return [x[0], x[1]];
    }
    let a = at.alpha;
    [(1.0 - a) * x[0] + a * x[2], (1.0 - a) * x[1] + a * x[3]]
}

/// A constant-velocity residual e (position, velocity on one axis) whitened by the
/// Cholesky factor L = [l11 0; l21 l22] of [`white_acceleration_noise`]: L^-1 e, and
/// (l11, l21, l22).
fn white_acceleration(dt_s: f64, q: f64, e: [f64; 2]) -> ([f64; 2], [f64; 3]) {
    let c = white_acceleration_noise(q, dt_s);
    let l11 = c[0][0].sqrt();
    let l21 = c[1][0] / l11;
    let l22 = (c[1][1] - l21 * l21).sqrt();
    let w0 = e[0] / l11;
    ([w0, (e[1] - l21 * w0) / l22], [l11, l21, l22])
}

/// The gradient over the local variables of a quantity read at the interpolated
/// position ([`position`]), from its gradient `h` over the position.
fn through_position(at: &At, h: [f64; 2]) -> [f64; MAX_VARS] {
    let mut g = [0.0; MAX_VARS];
    for (node, w) in [1.0 - at.alpha, at.alpha].into_iter().enumerate().take(if at.next { 2 } else { 1 }) {
        g[2 * node] = w * h[0];
        g[2 * node + 1] = w * h[1];
    }
    g
}

/// A range factor's reading of the filters' [`SlantRange`] at its local values: the
/// model at the state (position, scale error s - 1, offset; the scale and offset the
/// estimated variables or their nominal 1 and 0), and the offset's drift read (0 when
/// not estimated).
struct RangeReading {
    model: SlantRange,
    state: SVector<f64, 4>,
    drift: f64,
}

impl RangeReading {
    /// s |p - b| + offset.
    fn predicted(&self) -> f64 {
        ScalarModel::<4>::predict(&self.model, &self.state)
    }

    /// Its gradient over the local position variables, and its derivative in the scale
    /// (the slant).
    fn gradient(&self, at: &At) -> ([f64; MAX_VARS], f64) {
        let h = ScalarModel::<4>::jacobian(&self.model, &self.state);
        (through_position(at, [h[0], h[1]]), h[2])
    }
}

/// A range factor's reading at the local values `x`.
fn range(at: &At, beacon: [f64; 2], dz_m: f64, cal: &CalVars, x: &[f64]) -> RangeReading {
    let mut i = at.positions();
    let mut take = |on: bool, nominal: f64| {
        if on {
            i += 1;
            x[i - 1]
        } else {
            nominal
        }
    };
    let (s, b, drift) =
        (take(cal.scale.is_some(), 1.0), take(cal.offset.is_some(), 0.0), take(cal.drift.is_some(), 0.0));
    let p = position(at, x);
    // the vehicle dz_m below a beacon at 0
    let model = SlantRange {
        beacon: Vector3::new(beacon[0], beacon[1], 0.0),
        depth_m: dz_m,
        bias: Some(3),
        scale: Some(2),
        var: 1.0,
    };
    RangeReading { model, state: SVector::<f64, 4>::from([p[0], p[1], s - 1.0, b]), drift }
}

/// A Doppler factor's reading of the filters' [`LineOfSightSpeed`] at the local values
/// `x`: the model at the interpolated position with the interval's velocity (a track
/// node's own); None for a pose without a later node (no velocity).
fn closing_speed(at: &At, beacon: [f64; 2], dz_m: f64, x: &[f64]) -> Option<(LineOfSightSpeed, SVector<f64, 4>)> {
    let np = at.positions();
    let v = match (at.node, at.next) {
        (Node::Track, _) => [x[np], x[np + 1]],
        (Node::Pose, true) => [(x[2] - x[0]) / at.dt_s, (x[3] - x[1]) / at.dt_s],
        (Node::Pose, false) => return None,
    };
    let p = position(at, x);
    let model = LineOfSightSpeed { beacon: Vector3::new(beacon[0], beacon[1], 0.0), depth_m: dz_m, var: 1.0 };
    Some((model, SVector::<f64, 4>::from([p[0], p[1], v[0], v[1]])))
}

/// The closing speed's gradient over the local variables, through the interpolated
/// position and the velocity ([`closing_speed`]).
fn closing_speed_gradient(at: &At, model: &LineOfSightSpeed, state: &SVector<f64, 4>) -> [f64; MAX_VARS] {
    let h = ScalarModel::<4>::jacobian(model, state);
    let mut g = through_position(at, [h[0], h[1]]);
    let np = at.positions();
    match at.node {
        Node::Track => (g[np], g[np + 1]) = (h[2], h[3]),
        Node::Pose => {
            // v = (p_(k+1) - p_k) / dt
            let (gn, ge) = (h[2] / at.dt_s, h[3] / at.dt_s);
            (g[0], g[1], g[2], g[3]) = (g[0] - gn, g[1] - ge, g[2] + gn, g[3] + ge);
        }
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every analytic Jacobian against central differences, at a generic state with
    /// every calibration variable on (Doppler speeds' too, analytic since they read the
    /// filters' model).
    #[test]
    fn analytic_jacobians_match_central_differences() {
        let at = At { k: 0, alpha: 0.3, next: true, dt_s: 2.0, node: Node::Pose };
        let cal = CalVars { scale: Some(6), offset: Some(7), drift: Some(8) };
        let factors = [
            Factor::PosePrior { k: 0, mean: [1.0, 2.0, 0.3], sigma: [0.5, 0.4, 0.1] },
            Factor::Heading { k: 0, heading_rad: 0.2, sigma: 0.05 },
            Factor::Motion {
                k: 0,
                forward_m: 1.1,
                lateral_m: 0.2,
                turn_rad: Some(0.4),
                sigma: [0.1, 0.2, 0.03],
                turn_scale: Some(6),
                distance_scale: Some(7),
            },
            Factor::Range { at, beacon: [10.0, -4.0], dz_m: 3.0, range_m: 12.0, sigma: 1.5, cal, t_rel_s: 40.0 },
            Factor::ConstantVelocity { k: 0, axis: 1, dt_s: 1.7, q: 0.04 },
            // the interval's velocity between two poses, and a track node's own
            Factor::Doppler { at, beacon: [10.0, -4.0], dz_m: 3.0, speed_m_s: 0.3, sigma: 0.1 },
            Factor::Doppler {
                at: At { node: Node::Track, ..at },
                beacon: [10.0, -4.0],
                dz_m: 3.0,
                speed_m_s: 0.3,
                sigma: 0.1,
            },
        ];
        let x = [1.2, 2.1, 0.35, 2.0, 2.9, 0.8, 1.05, 0.7, 0.01, 0.0];
        for f in &factors {
            let lin = f.linearize(&x);
            let (_, n) = f.vars();
            let mut local = [0.0; MAX_VARS];
            let mut j = [[0.0; MAX_VARS]; 3];
            for (i, &v) in f.vars().0[..n].iter().enumerate() {
                local[i] = x[v];
            }
            numeric_jacobian(f, &mut local, n, &mut j);
            for (row, (a, b)) in lin.j.iter().zip(&j).take(lin.m).enumerate() {
                for (c, (x, y)) in a.iter().zip(b).take(n).enumerate() {
                    assert!((x - y).abs() < 1e-6, "{f:?}: row {row} col {c}: {x} vs {y}");
                }
            }
        }
    }
}
