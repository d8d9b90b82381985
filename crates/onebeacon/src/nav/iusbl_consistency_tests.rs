//! The iUSBL navigator's covariance against its errors when the heading it levels the
//! array with is off by a slow error that no ping can show.

use super::iusbl::{IusblConfig, IusblNavigator};
use super::{BeaconFix, Kind, Measurement, Navigator};
use crate::dsp::beamform::{azimuth_inclination, direction};
use crate::filter::gauss;
use crate::models::kinematic6dof::rotation;
use nalgebra::Vector3;

/// The mean NEES at the end of 150 pings (a vehicle driving east at 1 m/s past a beacon
/// some 40 m away, fixes with 0.3 m and 2 deg of noise), over 40 runs whose AHRS heading
/// reads one draw of N(0, 3 deg) off, with the heading error's consider term of
/// `heading_bias_sigma_deg`.
fn mean_nees(heading_bias_sigma_deg: f64) -> f64 {
    let runs = 40;
    let mut total = 0.0;
    for run in 0..runs {
        // the fixes weighed with their own noise (the default is the paper's 68 % errors)
        let config = IusblConfig {
            heading_bias_sigma_rad: heading_bias_sigma_deg.to_radians(),
            fix_sigma_range_m: 0.3,
            fix_sigma_angle_rad: 0.035,
            ..Default::default()
        };
        let mut nav = IusblNavigator::new(config, None, run + 1);
        let mut rng = rand_pcg::Pcg64::new(u128::from(run) + 40, 7);
        let bias = gauss(&mut rng, 3f64.to_radians());
        let beacon = Vector3::new(40.0, 60.0, 1.0);
        let heading = std::f64::consts::FRAC_PI_2;
        let mut vehicle = Vector3::zeros();
        for k in 0..150 {
            let t = k as f64;
            vehicle = Vector3::new(0.0, t, 2.5);
            nav.process(&Measurement::new(t, Kind::Depth { depth_m: 2.5 }));
            nav.process(&Measurement::new(t, Kind::Speed { speed_m_s: 1.0 }));
            let read = Kind::Attitude { roll_rad: 0.0, pitch_rad: 0.0, heading_rad: heading + bias };
            nav.process(&Measurement::new(t, read));
            let d = rotation(0.0, 0.0, heading).transpose() * (beacon - vehicle);
            let (az, incl) = azimuth_inclination(&d);
            let (az, incl) = (az + gauss(&mut rng, 0.035), incl + gauss(&mut rng, 0.035));
            debug_assert!(direction(az, incl).norm() > 0.99);
            let fix = Kind::ArrayFix {
                beacon: BeaconFix::fixed(0, beacon),
                range_m: d.norm() + gauss(&mut rng, 0.3),
                azimuth_rad: az,
                inclination_rad: incl,
                mode: 0,
            };
            nav.process(&Measurement::new(t + 0.02, fix));
        }
        let e = nav.estimate();
        let err = e.position_ned_m.xy() - vehicle.xy();
        total += (err.transpose() * e.horizontal_cov_m2.try_inverse().expect("positive") * err)[0];
    }
    total / runs as f64
}

/// With the consider term the NEES is that of 40 chi-square(2) draws, within [1.44, 2.66]
/// (95 %, chi-square(80) / 40); the particle cloud alone is many times too narrow for a
/// 3 deg turn of a 40-70 m relative position.
#[test]
fn the_heading_error_is_in_the_covariance() {
    let with = mean_nees(3.0);
    assert!((1.44..=2.66).contains(&with), "mean NEES {with} with the heading error's term");
    let cloud = mean_nees(0.0);
    assert!(cloud > 10.0, "mean NEES {cloud} of the cloud alone");
}
