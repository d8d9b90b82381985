//! The particle likelihoods of hoff2024's model ([`crate::models::hoff`]): the AUV's
//! INS report (eq. 8) and the USBL bearing heard at the surface vehicle (eq. 6-7), each
//! a kernel over a block of the particles' single-precision columns, compiled once per
//! instruction-set level ([`crate::filter::lanes`]).

use super::Robust;
use super::Usbl;
use crate::filter::lanes::{atan2_1, lanes, ln1, wrap_near};
use crate::filter::particle::ParticleLikelihood;
use crate::geo::wrap_angle;
use crate::models::hoff::{BLOCK, DIM, idx};

/// The AUV's INS report (eq. 8): heading, speed and depth with the filter's assumed
/// standard deviations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InsReport {
    pub heading_rad: f64,
    pub speed_m_s: f64,
    pub depth_m: f64,
    pub sigma_heading_rad: f64,
    pub sigma_speed_m_s: f64,
    pub sigma_depth_m: f64,
}

impl InsReport {
    /// What [`ins_report`] reads for particles stored from `origin`: eq. 8's weights,
    /// and each residual's constant part, the origin less the report (a particle's
    /// heading differs from the wrapped report by less than 2 pi after a first step,
    /// within 3 pi at the start: one add or subtract wraps it).
    pub(crate) fn terms(&self, origin: &[f64]) -> [f32; 6] {
        let k = |s: f64| (-0.5 / (s * s)) as f32;
        [
            k(self.sigma_heading_rad),
            k(self.sigma_speed_m_s),
            k(self.sigma_depth_m),
            (origin[idx::PSI] - wrap_angle(self.heading_rad)) as f32,
            (origin[idx::U] - self.speed_m_s) as f32,
            (origin[idx::Z] - self.depth_m) as f32,
        ]
    }
}

#[cfg(test)]
impl InsReport {
    /// A report the tests weigh particles by: heading 0.3 rad, 1.5 m/s, 30 m deep.
    pub(crate) fn example() -> Self {
        Self {
            heading_rad: 0.3,
            speed_m_s: 1.5,
            depth_m: 30.0,
            sigma_heading_rad: 0.1,
            sigma_speed_m_s: 0.2,
            sigma_depth_m: 0.4,
        }
    }
}

impl ParticleLikelihood for InsReport {
    fn add_log_likelihood(&self, x: &[&[f32]], origin: &[f64], log_w: &mut [f32]) {
        let n = log_w.len();
        ins_report(&x[idx::PSI][..n], &x[idx::U][..n], &x[idx::Z][..n], self.terms(origin), log_w);
    }
}

lanes! {
    /// Eq. 8 over particles' heading, speed and depth offsets: `c` holds the three
    /// weights -1 / (2 sigma^2) and the three residuals' constant parts.
    pub(crate) fn ins_report(psi: &[f32], u: &[f32], z: &[f32], c: [f32; 6], log_w: &mut [f32]) {
        let n = log_w.len();
        let (psi, u, z) = (&psi[..n], &u[..n], &z[..n]);
        for i in 0..n {
            let dh = wrap_near(psi[i] + c[3]);
            let (du, dz) = (u[i] + c[4], z[i] + c[5]);
            log_w[i] += c[0] * dh * dh + c[1] * du * du + c[2] * dz * dz; // eq. 8
        }
    }
}

/// A USBL bearing (azimuth, elevation) measured by the surface vehicle (eq. 6-7). The
/// noise grows with each particle's range (eq. 3), so the normalising term ln sigma^2
/// differs between particles and is kept. With `robust`, each angle's Gaussian
/// exponent is replaced by a heavy-tailed one ([`Robust::log_density`]), so that an
/// outlier (a reflected path, a false detection) does not wipe out the particles near
/// the truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UsblBearing {
    pub usbl: Usbl,
    pub azimuth_rad: f64,
    pub elevation_rad: f64,
    pub robust: Option<Robust>,
}

/// A [`UsblBearing`] as its kernel reads it: the station's offset from the particles'
/// origin, the measured directions' sines and cosines, eq. 3's terms (the variance's
/// floor, its coefficient on r^2 and on r) and the station's pose errors' variances.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BearingTerms {
    station: [f32; 3],
    azimuth: [f32; 2],
    elevation: [f32; 2],
    floor: f32,
    per_r2: f32,
    per_r: f32,
    position_var: f32,
    heading_var: f32,
    /// The misalignment's origin (its particles' offsets are added to it).
    misalignment: f32,
    robust: Option<Robust>,
}

impl ParticleLikelihood for UsblBearing {
    /// Each residual is the angle between the measured direction and the particle's,
    /// one atan2 of their cross and dot products: for the azimuth, of the horizontal
    /// unit vector at the measured world bearing alpha + psi_ASV and the particle's
    /// (dx, dy); for the elevation, of (cos phi, sin phi) and (dz, h). It equals the
    /// wrapped difference of the angles (eq. 6), with no wrap and no atan2 of the
    /// particle's own angles. A state that carries the head's yaw misalignment m
    /// ([`crate::models::hoff::MisalignedProcess`]) reads the azimuth as measured plus
    /// its particle's m (a head turned by m reads azimuths m less).
    fn add_log_likelihood(&self, x: &[&[f32]], origin: &[f64], log_w: &mut [f32]) {
        let t = bearing_terms(self, origin);
        let [px, py, pz, ..] = x else { panic!("hoff2024's state has {DIM} components") };
        let misalignment = x.get(idx::MISALIGNMENT);
        let n = log_w.len();
        for start in (0..n).step_by(BLOCK) {
            let r = start..(start + BLOCK).min(n);
            let mis = misalignment.map_or(&[][..], |m| &m[r.clone()]);
            usbl_bearing(&px[r.clone()], &py[r.clone()], &pz[r.clone()], mis, &t, &mut log_w[r]);
        }
    }
}

/// What [`usbl_bearing`] reads of `b` for particles stored from `origin`.
pub(crate) fn bearing_terms(b: &UsblBearing, origin: &[f64]) -> BearingTerms {
    let u = &b.usbl;
    let (sb, cb) = (b.azimuth_rad + u.heading_rad).sin_cos();
    let (se, ce) = b.elevation_rad.sin_cos();
    let o = u.position_ned_m;
    let sigma = u.sigma_rad_per_m;
    BearingTerms {
        station: [(o.x - origin[idx::X]) as f32, (o.y - origin[idx::Y]) as f32, (o.z - origin[idx::Z]) as f32],
        azimuth: [sb as f32, cb as f32],
        elevation: [se as f32, ce as f32],
        floor: (u.floor_rad * u.floor_rad) as f32,
        // eq. 6 as printed puts sigma r where a variance belongs; eq. 3 squared
        per_r2: if u.as_printed { 0.0 } else { (sigma * sigma) as f32 },
        per_r: if u.as_printed { sigma as f32 } else { 0.0 },
        position_var: (u.position_sigma_m * u.position_sigma_m) as f32,
        heading_var: (u.heading_sigma_rad * u.heading_sigma_rad) as f32,
        misalignment: origin.get(idx::MISALIGNMENT).map_or(0.0, |m| *m as f32),
        robust: b.robust,
    }
}

lanes! {
    /// Eq. 6-7 over a block of at most [`BLOCK`] particles' position offsets (and their
    /// misalignments' offsets, or none): the residuals' atan2, the variances (eq. 3, plus
    /// the station's pose errors to first order, as [`Usbl::variances`]) and the log of
    /// their product, in single precision.
    pub(crate) fn usbl_bearing(px: &[f32], py: &[f32], pz: &[f32], mis: &[f32], t: &BearingTerms, log_w: &mut [f32]) {
        let m = log_w.len();
        let (px, py, pz) = (&px[..m], &py[..m], &pz[..m]);
        let (mut da, mut de, mut var_a, mut var_e) = ([0.0f32; BLOCK], [0.0f32; BLOCK], [0.0f32; BLOCK], [0.0f32; BLOCK]);
        let mut ln_prod = [0.0f32; BLOCK];
        let ([sb, cb], [se, ce]) = (t.azimuth, t.elevation);
        for j in 0..m {
            let (dx, dy, dz) = (px[j] - t.station[0], py[j] - t.station[1], pz[j] - t.station[2]);
            let h2 = dx * dx + dy * dy;
            let h = h2.sqrt();
            let r2 = h2 + dz * dz;
            // sin(measured - particle's azimuth) times h, and the same for the elevation
            // (eq. 2) times r, over their cosines
            da[j] = atan2_1(sb * dx - cb * dy, cb * dx + sb * dy);
            de[j] = atan2_1(se * dz - ce * h, ce * dz + se * h);
            let base = (t.floor + t.per_r2 * r2 + t.per_r * r2.sqrt()).max(1e-12);
            var_a[j] = base + t.position_var / h2.max(1e-12) + t.heading_var;
            var_e[j] = base + t.position_var * dz * dz / (r2 * r2).max(1e-24);
            ln_prod[j] = ln1(var_a[j] * var_e[j]);
        }
        if !mis.is_empty() {
            let mis = &mis[..m];
            for j in 0..m {
                da[j] = wrap_near(da[j] + (t.misalignment + mis[j]));
            }
        }
        match t.robust {
            None => {
                for j in 0..m {
                    // eq. 6, the two angles
                    log_w[j] += -da[j] * da[j] / (2.0 * var_a[j]) - de[j] * de[j] / (2.0 * var_e[j]) - 0.5 * ln_prod[j];
                }
            }
            Some(r) => {
                for j in 0..m {
                    let (d2a, d2e) = (da[j] * da[j] / var_a[j], de[j] * de[j] / var_e[j]);
                    let l = r.log_density(f64::from(d2a)) + r.log_density(f64::from(d2e));
                    log_w[j] += l as f32 - 0.5 * ln_prod[j];
                }
            }
        }
    }
}
