//! The particle likelihoods of hoff2024's model ([`crate::models::hoff`]): the AUV's
//! INS report (eq. 8) and the USBL bearing heard at the surface vehicle (eq. 6-7),
//! computed over the particles' columns in lanes.

use super::Robust;
use super::Usbl;
use crate::filter::lanes;
use crate::filter::particle::ParticleLikelihood;
use crate::geo::{wrap_angle, wrap_near};
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

impl ParticleLikelihood for InsReport {
    fn add_log_likelihood(&self, x: &[&[f64]], log_w: &mut [f64]) {
        let (kh, ku, kz) = (
            -0.5 / (self.sigma_heading_rad * self.sigma_heading_rad),
            -0.5 / (self.sigma_speed_m_s * self.sigma_speed_m_s),
            -0.5 / (self.sigma_depth_m * self.sigma_depth_m),
        );
        // particles' headings are in (-pi, pi] (after a first step; within 3 pi at the
        // start): a difference from a wrapped heading wraps with one add or subtract
        let heading = wrap_angle(self.heading_rad);
        let n = log_w.len();
        let (psi, u, z) = (&x[idx::PSI][..n], &x[idx::U][..n], &x[idx::Z][..n]);
        for (i, lw) in log_w.iter_mut().enumerate() {
            let dh = wrap_near(psi[i] - heading);
            let (du, dz) = (u[i] - self.speed_m_s, z[i] - self.depth_m);
            *lw += kh * dh * dh + ku * du * du + kz * dz * dz; // eq. 8
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

impl ParticleLikelihood for UsblBearing {
    /// Each residual is the angle between the measured direction and the particle's,
    /// one atan2 of their cross and dot products: for the azimuth, of the horizontal
    /// unit vector at the measured world bearing alpha + psi_ASV and the particle's
    /// (dx, dy); for the elevation, of (cos phi, sin phi) and (dz, h). It equals the
    /// wrapped difference of the angles (eq. 6), with no wrap and no atan2 of the
    /// particle's own angles. A state that carries the head's yaw misalignment m
    /// ([`crate::models::hoff::MisalignedProcess`]) reads the azimuth as measured plus
    /// its particle's m (a head turned by m reads azimuths m less).
    fn add_log_likelihood(&self, x: &[&[f64]], log_w: &mut [f64]) {
        let u = &self.usbl;
        let (sb, cb) = (self.azimuth_rad + u.heading_rad).sin_cos();
        let (se, ce) = self.elevation_rad.sin_cos();
        let (g2, c2) = (u.position_sigma_m * u.position_sigma_m, u.heading_sigma_rad * u.heading_sigma_rad);
        let o = u.position_ned_m;
        let [px, py, pz, ..] = x else { panic!("hoff2024's state has {DIM} components") };
        let n = log_w.len();
        let misalignment = x.get(idx::MISALIGNMENT);
        let (mut cross_a, mut dot_a, mut cross_e, mut dot_e) = ([0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]);
        let (mut var_a, mut var_e, mut prod) = ([0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]);
        let (mut da, mut de, mut ln_prod) = ([0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]);
        for start in (0..n).step_by(BLOCK) {
            let m = BLOCK.min(n - start);
            let (bx, by, bz) = (&px[start..start + m], &py[start..start + m], &pz[start..start + m]);
            for j in 0..m {
                let (dx, dy, dz) = (bx[j] - o.x, by[j] - o.y, bz[j] - o.z);
                let h2 = dx * dx + dy * dy;
                let h = h2.sqrt();
                let r2 = h2 + dz * dz;
                cross_a[j] = sb * dx - cb * dy; // sin(measured - particle's azimuth), times h
                dot_a[j] = cb * dx + sb * dy;
                cross_e[j] = se * dz - ce * h; // the same for the elevation (eq. 2), times r
                dot_e[j] = ce * dz + se * h;
                // eq. 3, plus the station's pose errors to first order (Usbl::variances)
                let base = u.base_variance(r2).max(1e-12);
                var_a[j] = base + g2 / h2.max(1e-12) + c2;
                var_e[j] = base + g2 * dz * dz / (r2 * r2).max(1e-24);
                prod[j] = var_a[j] * var_e[j];
            }
            lanes::atan2(&cross_a[..m], &dot_a[..m], &mut da[..m]);
            if let Some(mis) = misalignment {
                for (d, yaw) in da[..m].iter_mut().zip(&mis[start..start + m]) {
                    *d = wrap_near(*d + yaw);
                }
            }
            lanes::atan2(&cross_e[..m], &dot_e[..m], &mut de[..m]);
            lanes::ln(&prod[..m], &mut ln_prod[..m]);
            let block = log_w[start..start + m].iter_mut().enumerate();
            match self.robust {
                None => {
                    for (j, lw) in block {
                        // eq. 6, the two angles
                        *lw += -da[j] * da[j] / (2.0 * var_a[j]) - de[j] * de[j] / (2.0 * var_e[j]) - 0.5 * ln_prod[j];
                    }
                }
                Some(r) => {
                    for (j, lw) in block {
                        let (d2a, d2e) = (da[j] * da[j] / var_a[j], de[j] * de[j] / var_e[j]);
                        *lw += r.log_density(d2a) + r.log_density(d2e) - 0.5 * ln_prod[j];
                    }
                }
            }
        }
    }
}
