//! Seeds: every random stream of a run is derived from (base seed, run index, stream),
//! so a run is a pure function of its inputs and does not depend on scheduling.

use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

/// The random streams of one run. Separate streams keep, for example, the IMU noise of
/// run i identical across sweep cells that change only the acoustic schedule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u64)]
pub enum Stream {
    Initial = 1,
    Imu = 2,
    Heading = 3,
    Acoustic = 4,
    /// The water's current (its slow variation).
    Current = 5,
    /// A moving beacon's own GPS (the fleet world's boat).
    BeaconGps = 6,
    /// A vehicle's clock.
    Clock = 7,
    /// The beacon's clock.
    BeaconClock = 8,
    /// A receiver's acoustic link: its losses and outliers.
    Link = 9,
    /// A USBL head's sea (its carrier's waves) and attitude sensor.
    Waves = 10,
    /// A vehicle's drifting sensors (`[sea.sensors]`).
    Sensors = 11,
    /// A reference's own errors (a fleet's LBL fixes, `[reference]`).
    Reference = 12,
}

/// SplitMix64 finaliser: a bijective mixing of 64 bits.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A zero-mean Gaussian draw of standard deviation `sigma` (the models' own draw).
pub use onebeacon::filter::gauss;

/// The generator of stream `stream` of run `run` under base seed `seed`.
pub fn rng(seed: u64, run: u64, stream: Stream) -> Pcg64Mcg {
    vehicle_rng(seed, run, 0, stream)
}

/// The generator of stream `stream` of underwater vehicle `vehicle` (vehicle 0's are
/// the run's own streams, so adding a vehicle to a world changes no draw of the first).
pub fn vehicle_rng(seed: u64, run: u64, vehicle: usize, stream: Stream) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(mix(seed ^ mix(run ^ mix(stream as u64 + 16 * vehicle as u64))))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    #[test]
    fn streams_differ_and_repeat() {
        let a: u64 = rng(1, 0, Stream::Imu).random();
        let b: u64 = rng(1, 0, Stream::Imu).random();
        let c: u64 = rng(1, 1, Stream::Imu).random();
        let d: u64 = rng(1, 0, Stream::Heading).random();
        let e: u64 = rng(2, 0, Stream::Imu).random();
        assert_eq!(a, b);
        let f: u64 = vehicle_rng(1, 0, 1, Stream::Imu).random();
        let g: u64 = vehicle_rng(1, 0, 0, Stream::Imu).random();
        assert!(a != c && a != d && a != e && c != d);
        assert!(f != a && g == a);
    }
}
