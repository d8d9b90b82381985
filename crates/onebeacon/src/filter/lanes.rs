//! Transcendental functions over slices for particle models: sine and cosine, atan2,
//! the logarithm, standard normal draws and the moments of USBL angles, computed in
//! single precision by branchless polynomials (Cephes' sinf, cosf, logf and atanf
//! coefficients, S. L. Moshier) that the compiler vectorises.
//!
//! Each slice function is compiled for AVX-512, for AVX2 and for the baseline (SSE2 on
//! x86-64), and the best [`Level`] the processor has is chosen at run time, or a lower
//! one named by `ONEBEACON_SIMD` (`baseline`, `avx2`, `avx512`): the arithmetic is the
//! same IEEE operations in every version (no fused multiply-add; sums in a fixed number
//! of accumulators), so the three give identical results and a run does not depend on
//! the machine's vector width (the tests compare each level the processor has with the
//! scalar kernels, bit for bit).
//!
//! A particle model writes its own kernels the same way with the [`lanes!`] macro (a
//! block's whole step or likelihood in one function: hoff2024's are
//! [`crate::models::hoff`]'s and [`crate::measure::hoff`]'s), over the particles'
//! single-precision offsets ([`crate::filter::particle`]): 16 particles an instruction
//! with AVX-512, 8 with AVX2, 4 at the baseline.
//!
//! Single precision is far finer than what these values feed: a step of a few metres
//! (relative error 1e-7: under a micrometre), an angle residual against a noise of
//! milliradians, a log-likelihood against a spread of units. At N = 5e5 this is what
//! makes a hoff2024 filter cycle fit its budget (docs/benchmarks.md): libm's scalar atan2
//! and sin_cos cost some 20 ns a call.

use rand::Rng;
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
use std::sync::OnceLock;

/// An instruction set the slice functions are compiled for, from the least to the most.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// What every processor of the target has (SSE2 on x86-64).
    Baseline,
    /// AVX and AVX2 (x86-64).
    Avx2,
    /// AVX-512 F, BW, VL and DQ (x86-64).
    Avx512,
}

impl Level {
    /// The environment variable that caps the level.
    pub const VARIABLE: &'static str = "ONEBEACON_SIMD";

    /// The levels this processor runs, the least first.
    pub fn available() -> Vec<Level> {
        [Level::Baseline, Level::Avx2, Level::Avx512].into_iter().filter(|l| *l <= Self::best()).collect()
    }

    /// The best level this processor runs.
    pub fn best() -> Level {
        static BEST: OnceLock<Level> = OnceLock::new();
        *BEST.get_or_init(Self::detect)
    }

    fn detect() -> Level {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            if has!("avx2") && has!("avx") {
                let avx512 = has!("avx512f") && has!("avx512bw") && has!("avx512vl") && has!("avx512dq");
                return if avx512 { Level::Avx512 } else { Level::Avx2 };
            }
        }
        Level::Baseline
    }

    /// A level by its name in `ONEBEACON_SIMD`.
    pub fn parse(name: &str) -> Result<Level, String> {
        match name.trim() {
            "baseline" => Ok(Level::Baseline),
            "avx2" => Ok(Level::Avx2),
            "avx512" => Ok(Level::Avx512),
            other => Err(format!("{}={other}: expected baseline, avx2 or avx512", Self::VARIABLE)),
        }
    }

    /// The level the slice functions run at: the processor's best, or the one
    /// `ONEBEACON_SIMD` names if lower (a name it does not know is ignored here; the
    /// binary refuses it).
    pub fn current() -> Level {
        static CURRENT: OnceLock<Level> = OnceLock::new();
        *CURRENT.get_or_init(|| {
            let best = Self::best();
            match std::env::var(Self::VARIABLE).ok().map(|v| Self::parse(&v)) {
                Some(Ok(cap)) => cap.min(best),
                _ => best,
            }
        })
    }
}

/// A slice function compiled once per [`Level`]: `name(args)` runs at
/// [`Level::current`], `name::at(level, args)` at a given one (which the processor must
/// run).
macro_rules! lanes {
    ($(#[$doc:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? $body:block) => {
        $(#[$doc])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            $name::at($crate::filter::lanes::Level::current(), $($arg),*)
        }

        pub(crate) mod $name {
            #[allow(unused_imports)]
            use super::*;

            #[inline(always)]
            fn body($($arg: $ty),*) $(-> $ret)? $body

            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512dq,avx2,avx")]
            fn avx512($($arg: $ty),*) $(-> $ret)? {
                body($($arg),*)
            }

            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2,avx")]
            fn avx2($($arg: $ty),*) $(-> $ret)? {
                body($($arg),*)
            }

            /// The function compiled for `level`.
            ///
            /// # Panics
            /// If the processor does not run `level` ([`Level::available`]).
            pub fn at(level: $crate::filter::lanes::Level, $($arg: $ty),*) $(-> $ret)? {
                use $crate::filter::lanes::Level;
                assert!(level <= Level::best(), "{level:?} is beyond this processor");
                match level {
                    #[cfg(target_arch = "x86_64")]
                    // SAFETY: the processor has the features (asserted above)
                    Level::Avx512 => unsafe { avx512($($arg),*) },
                    #[cfg(target_arch = "x86_64")]
                    // SAFETY: as above
                    Level::Avx2 => unsafe { avx2($($arg),*) },
                    _ => body($($arg),*),
                }
            }
        }
    };
}
/// For a particle model's own kernels (a block's whole step or likelihood in one
/// function, so that its arithmetic runs at the level's width with no scratch arrays).
pub(crate) use lanes;

/// x rounded to the nearest integer (|x| < 2^22), as a float and as an integer: added
/// to and taken from 1.5 2^23, whose last bits then hold the integer (in two's
/// complement). Unlike `as`, which saturates lane by lane, the compiler vectorises it.
#[inline(always)]
fn round(x: f32) -> (f32, i32) {
    const MAGIC: f32 = 12_582_912.0;
    let shifted = x + MAGIC;
    (shifted - MAGIC, (shifted.to_bits() as i32).wrapping_sub(MAGIC.to_bits() as i32))
}

/// sin x and cos x for |x| <= 8192: x reduced by pi/2 in three parts (Cephes' sinf: the
/// first two short enough that their products with the quadrant are exact), then
/// [`sin_cos_reduced`].
#[inline(always)]
pub(crate) fn sin_cos1(x: f32) -> (f32, f32) {
    let (q, quadrant) = round(x * std::f32::consts::FRAC_2_PI);
    let r = ((x - q * 1.570_312_5) - q * 4.837_513e-4) - q * 7.549_79e-8;
    sin_cos_reduced(r, quadrant)
}

/// An angle within 3 pi wrapped to (-pi, pi] with one add or subtract.
#[inline(always)]
pub(crate) fn wrap_near(a: f32) -> f32 {
    if a > PI {
        a - 2.0 * PI
    } else if a <= -PI {
        a + 2.0 * PI
    } else {
        a
    }
}

/// sin and cos of quadrant pi / 2 + r, |r| <= pi / 4: Cephes' polynomials in r, the
/// quadrant applied by selects.
#[inline(always)]
fn sin_cos_reduced(r: f32, quadrant: i32) -> (f32, f32) {
    let z = r * r;
    let s = r + r * z * (-1.666_665_5e-1 + z * (8.332_161e-3 + z * -1.951_529_6e-4));
    let c = 1.0 - 0.5 * z + z * z * (4.166_664_6e-2 + z * (-1.388_731_6e-3 + z * 2.443_315_7e-5));
    let (sin, cos) = if quadrant & 1 == 0 { (s, c) } else { (c, s) };
    let sin = if quadrant & 2 == 0 { sin } else { -sin };
    let cos = if (quadrant + 1) & 2 == 0 { cos } else { -cos };
    (sin, cos)
}

/// ln x for a positive normal x: x = m 2^e with m in [sqrt(1/2), sqrt(2)), Cephes' logf
/// polynomial in m - 1, ln 2 in two parts.
#[inline(always)]
pub(crate) fn ln1(x: f32) -> f32 {
    let bits = x.to_bits();
    let mut e = ((bits >> 23) & 0xff) as i32 - 126;
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f00_0000); // in [1/2, 1)
    let low = m < std::f32::consts::FRAC_1_SQRT_2;
    e -= i32::from(low);
    m = if low { m + m - 1.0 } else { m - 1.0 };
    let z = m * m;
    let p = 7.037_683_6e-2;
    let p = p * m - 1.151_461e-1;
    let p = p * m + 1.167_699_9e-1;
    let p = p * m - 1.242_014_1e-1;
    let p = p * m + 1.424_932_3e-1;
    let p = p * m - 1.666_805_8e-1;
    let p = p * m + 2.000_071_4e-1;
    let p = p * m - 2.499_999_4e-1;
    let p = p * m + 3.333_333e-1;
    let e = e as f32;
    let y = m * z * p + e * -2.121_944_4e-4 - 0.5 * z;
    let r = m + y + e * 0.693_359_4;
    // IEEE's special cases, so that an absurd value cannot pass for a likely one
    if x.is_nan() || x < 0.0 {
        f32::NAN
    } else if x == 0.0 {
        f32::NEG_INFINITY
    } else if x == f32::INFINITY {
        f32::INFINITY
    } else {
        r
    }
}

/// e^x for x <= 0 (0 below -87, where single precision ends): x = k ln 2 + r with
/// |r| <= ln 2 / 2 (ln 2 in two parts, Cephes' expf), Cephes' expf polynomial in r, 2^k
/// from its bits.
#[inline(always)]
fn exp1(x: f32) -> f32 {
    let under = x < -87.0;
    let x = x.clamp(-87.0, 0.0);
    let (k, ki) = round(x * std::f32::consts::LOG2_E);
    let r = (x - k * 0.693_359_4) - k * -2.121_944_4e-4;
    let z = r * r;
    let p = 1.987_569_1e-4;
    let p = p * r + 1.398_199_9e-3;
    let p = p * r + 8.333_452e-3;
    let p = p * r + 4.166_579_6e-2;
    let p = p * r + 1.666_666_5e-1;
    let p = p * r + 5e-1;
    let e = (p * z + r + 1.0) * f32::from_bits(((ki + 127) as u32) << 23);
    if under { 0.0 } else { e }
}

/// atan2(y, x) in [-pi, pi]: the angle of the smaller over the larger of |x| and |y|
/// (in [0, 1], reduced about tan(pi/8)), Cephes' atanf polynomial, the octant applied
/// by selects; 0 at the origin.
#[inline(always)]
pub(crate) fn atan2_1(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    let t = if hi > 0.0 { lo / hi } else { 0.0 };
    let mid = t > 0.414_213_57;
    let (t, base) = if mid { ((t - 1.0) / (t + 1.0), FRAC_PI_4) } else { (t, 0.0) };
    let z = t * t;
    let a = base + (((8.053_744_5e-2 * z - 1.387_768_6e-1) * z + 1.997_771_1e-1) * z - 3.333_295e-1) * z * t + t;
    let a = if ay > ax { FRAC_PI_2 - a } else { a };
    let a = if x < 0.0 { PI - a } else { a };
    if y < 0.0 { -a } else { a }
}

lanes! {
    /// sin and cos of every angle of `a` (radians, |a| <= 8192).
    pub fn sin_cos(a: &[f32], sin: &mut [f32], cos: &mut [f32]) {
        let n = a.len();
        let (sin, cos) = (&mut sin[..n], &mut cos[..n]);
        for i in 0..n {
            (sin[i], cos[i]) = sin_cos1(a[i]);
        }
    }
}

lanes! {
    /// atan2(y_i, x_i) for every i, in [-pi, pi].
    pub fn atan2(y: &[f32], x: &[f32], out: &mut [f32]) {
        let n = out.len();
        let (y, x) = (&y[..n], &x[..n]);
        for i in 0..n {
            out[i] = atan2_1(y[i], x[i]);
        }
    }
}

lanes! {
    /// exp(x_i - shift) for every i, and their sum (in a fixed order), for log-weights x_i
    /// at most `shift` (the largest: weights relative to the heaviest); each to single
    /// precision, stored and summed in double.
    pub fn exp_shifted(x: &[f32], shift: f32, out: &mut [f64]) -> f64 {
        let n = out.len();
        let x = &x[..n];
        for i in 0..n {
            out[i] = f64::from(exp1(x[i] - shift));
        }
        // four accumulators: a sum the compiler vectorises
        let mut s = [0.0; 4];
        let chunks = out.chunks_exact(4);
        let tail: f64 = chunks.remainder().iter().sum();
        for c in chunks {
            for j in 0..4 {
                s[j] += c[j];
            }
        }
        (s[0] + s[1]) + (s[2] + s[3]) + tail
    }
}

lanes! {
    /// The largest of `x` (-inf if empty), or NaN if one is NaN: sixteen running maxima
    /// and NaN flags (particle i in lane i mod 16), combined at the end.
    pub fn max_of(x: &[f32]) -> f32 {
        let (mut max, mut nan) = ([f32::NEG_INFINITY; 16], [false; 16]);
        let chunks = x.chunks_exact(16);
        for v in chunks.remainder() {
            (max[0], nan[0]) = (if *v > max[0] { *v } else { max[0] }, nan[0] | v.is_nan());
        }
        for c in chunks {
            for j in 0..16 {
                (max[j], nan[j]) = (if c[j] > max[j] { c[j] } else { max[j] }, nan[j] | c[j].is_nan());
            }
        }
        if nan.iter().any(|n| *n) { f32::NAN } else { max.into_iter().fold(f32::NEG_INFINITY, f32::max) }
    }
}

lanes! {
    /// ln x_i for every i: to single precision for x_i within f32's normal range (1.2e-38
    /// to 3.4e38; a subnormal gives a meaningless result), -inf at 0, +inf at infinity,
    /// NaN for a negative or NaN x_i.
    pub fn ln(x: &[f32], out: &mut [f32]) {
        let n = out.len();
        let x = &x[..n];
        for i in 0..n {
            out[i] = ln1(x[i]);
        }
    }
}

lanes! {
    /// Box-Muller on 32-bit uniform pairs, `n = out.len() / 2` of them: the i-th 64-bit
    /// draw is SplitMix64's output for the counter `key + (i + 1) gamma` (Steele, Lea and
    /// Flood 2014: a mixing of a Weyl sequence that passes BigCrush), computed in lanes. Its
    /// high half gives u1 = (k + 1/2) 2^-32 and the radius sqrt(-2 ln u1); its low half a
    /// uniform angle, as a quadrant (its top two bits) and an offset within it (the other
    /// 30, centred: within +-pi/4), so that no range reduction is needed. The pair gives
    /// draws `out[i]` and `out[n + i]`.
    fn box_muller(key: u64, out: &mut [f32]) {
        // the 64-bit hashes and the single-precision arithmetic each in a loop of its
        // own, at its own vector width (AVX2 has 4 lanes of u64, 8 of f32)
        const PAIRS: usize = 512;
        let n = out.len() / 2;
        let (first, second) = out.split_at_mut(n);
        let second = &mut second[..n];
        let (mut k1, mut k2) = ([0u32; PAIRS], [0u32; PAIRS]);
        for start in (0..n).step_by(PAIRS) {
            let m = PAIRS.min(n - start);
            for j in 0..m {
                (k1[j], k2[j]) = hash1(key, start + j);
            }
            let (first, second) = (&mut first[start..start + m], &mut second[start..start + m]);
            for j in 0..m {
                (first[j], second[j]) = pair1(k1[j], k2[j]);
            }
        }
    }
}

lanes! {
    /// Standard exponential draws -ln u, u = (k + 1/2) 2^-32 with k the high half of
    /// the i-th 64-bit draw of the counter-based stream of [`box_muller`] for `key`
    /// (so up to 22.9, where the mass beyond is 1.2e-10).
    pub fn exponentials(key: u64, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = f64::from(-ln_uniform(hash1(key, i).0));
        }
    }
}

/// The i-th 64-bit draw of [`box_muller`] for `key` (SplitMix64), as its high and low
/// halves.
#[inline(always)]
fn hash1(key: u64, i: usize) -> (u32, u32) {
    const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut z = key.wrapping_add((i as u64 + 1).wrapping_mul(GAMMA));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    ((z >> 32) as u32, z as u32)
}

/// ln u for the uniform u = (k + 1/2) 2^-32 in (0, 1) of 32 random bits `k`.
#[inline(always)]
fn ln_uniform(k: u32) -> f32 {
    ln1((k as f32 + 0.5) * (1.0 / 4_294_967_296.0))
}

/// The pair of normal draws of [`box_muller`] from the halves of one 64-bit draw.
#[inline(always)]
fn pair1(k1: u32, k2: u32) -> (f32, f32) {
    let radius = (-2.0 * ln_uniform(k1)).sqrt();
    let offset = ((k2 & 0x3fff_ffff) as i32 - 0x2000_0000) as f32 * (FRAC_PI_2 / 1_073_741_824.0);
    let (s, c) = sin_cos_reduced(offset, (k2 >> 30) as i32);
    (radius * s, radius * c)
}

lanes! {
    /// The weighted moments of the angles at which a USBL station hears particles
    /// (hoff2024 eq. 1-2, the station's heading 0): particle i at (`north`, `east`,
    /// `down`)_i from a point, the station at the surface `station` (north, east) from
    /// the same point. With a_i its azimuth less `centre[0]` (wrapped to within pi) and
    /// e_i its angle from the vertical less `centre[1]`: [sum w a, sum w e, sum w a^2,
    /// sum w a e, sum w e^2], summed in double precision in 8 accumulators (particle i
    /// in accumulator i mod 8, whatever the vector width), then pairwise.
    pub fn angle_moments(
        north: &[f32],
        east: &[f32],
        down: &[f32],
        weights: &[f32],
        station: [f32; 2],
        centre: [f32; 2],
    ) -> [f64; 5] {
        const CHUNK: usize = 512;
        let n = weights.len();
        let (north, east, down) = (&north[..n], &east[..n], &down[..n]);
        let mut acc = [[0.0f64; MOMENT_LANES]; 5];
        let (mut a, mut e) = ([0.0f32; CHUNK], [0.0f32; CHUNK]);
        for start in (0..n).step_by(CHUNK) {
            let k = CHUNK.min(n - start);
            for i in 0..k {
                (a[i], e[i]) = angles1(north[start + i], east[start + i], down[start + i], station, centre);
            }
            let w = &weights[start..start + k];
            let whole = k / MOMENT_LANES * MOMENT_LANES;
            for c in (0..whole).step_by(MOMENT_LANES) {
                for j in 0..MOMENT_LANES {
                    add_moments(&mut acc, j, a[c + j], e[c + j], w[c + j]);
                }
            }
            for j in 0..k - whole {
                add_moments(&mut acc, j, a[whole + j], e[whole + j], w[whole + j]);
            }
        }
        acc.map(|m| ((m[0] + m[1]) + (m[2] + m[3])) + ((m[4] + m[5]) + (m[6] + m[7])))
    }
}

/// Particles whose products [`add_products`] sums in single precision before adding
/// them in double.
pub(crate) const PRODUCT_BLOCK: usize = 512;

/// The normalised weight below which [`add_products`] counts a particle as 0: far below
/// single precision's share of the sums (1e6 such particles weigh 1e-12), and it keeps
/// the products out of single precision's subnormal range (below 1.2e-38), where each
/// operation costs a hundred cycles.
pub(crate) const NEGLIGIBLE_WEIGHT: f64 = 1e-18;

lanes! {
    /// Adds particles to the weighted products of a particle filter's moments about a
    /// centre: with y_k,i = x_k,i - `centre[k]` (wrapped to within pi for the component
    /// `angle`, if any), `products[p]` += sum_i (w_i y_k,i) y_l,i for the p-th pair (k, l)
    /// of `pairs` (a component of ones, centred at 0, gives the weighted sums). In single
    /// precision within each block of [`PRODUCT_BLOCK`] particles (the weight rounded to
    /// single, or 0 below [`NEGLIGIBLE_WEIGHT`]; particle i of the block in lane i mod 16,
    /// a last partial block padded with zeros; the 16 lanes summed by halves: 8, 4, 2, 1),
    /// then each block's sum added in double precision: the same order whatever the
    /// vector width. No component is shorter than `w`.
    pub fn add_products(
        w: &[f64],
        x: &[&[f32]],
        centre: &[f32],
        angle: Option<usize>,
        pairs: &[(usize, usize)],
        products: &mut [f64],
    ) {
        const B: usize = PRODUCT_BLOCK;
        let n = w.len();
        // the block's centred components and their products by w, padded with zeros
        let (mut yb, mut wy) = (vec![[[0.0f32; 16]; B / 16]; x.len()], vec![[[0.0f32; 16]; B / 16]; x.len()]);
        let mut wf = [0.0f32; B];
        for start in (0..n).step_by(B) {
            let m = B.min(n - start);
            wf[m..].fill(0.0);
            for (v, w) in wf[..m].iter_mut().zip(&w[start..start + m]) {
                *v = if *w < NEGLIGIBLE_WEIGHT { 0.0 } else { *w as f32 };
            }
            for (k, ((xk, ybk), wyk)) in x.iter().zip(yb.iter_mut()).zip(wy.iter_mut()).enumerate() {
                let (ybk, wyk, c) = (ybk.as_flattened_mut(), wyk.as_flattened_mut(), centre[k]);
                ybk[m..].fill(0.0);
                if angle == Some(k) {
                    for (y, x) in ybk[..m].iter_mut().zip(&xk[start..start + m]) {
                        *y = wrap_near(x - c);
                    }
                } else {
                    for (y, x) in ybk[..m].iter_mut().zip(&xk[start..start + m]) {
                        *y = x - c;
                    }
                }
                for ((v, w), y) in wyk.iter_mut().zip(&wf).zip(ybk.iter()) {
                    *v = w * y;
                }
            }
            for (&(k, l), total) in pairs.iter().zip(products.iter_mut()) {
                let (a, b) = (&wy[k], &yb[l]);
                let mut lanes = [0.0f32; 16];
                for c in 0..B / 16 {
                    for j in 0..16 {
                        lanes[j] += a[c][j] * b[c][j];
                    }
                }
                *total += f64::from(halves(lanes));
            }
        }
    }
}

/// The sum of 16 lanes by halves: lane j + lane j + 8, then 4, 2, 1.
#[inline(always)]
fn halves(v: [f32; 16]) -> f32 {
    let h8: [f32; 8] = std::array::from_fn(|j| v[j] + v[j + 8]);
    let h4: [f32; 4] = std::array::from_fn(|j| h8[j] + h8[j + 4]);
    (h4[0] + h4[2]) + (h4[1] + h4[3])
}

/// The azimuth and the angle from the vertical of [`angle_moments`] for one particle.
#[inline(always)]
fn angles1(north: f32, east: f32, down: f32, station: [f32; 2], centre: [f32; 2]) -> (f32, f32) {
    let (dx, dy) = (north - station[0], east - station[1]);
    let a = wrap_near(atan2_1(dy, dx) - centre[0]);
    (a, atan2_1((dx * dx + dy * dy).sqrt(), down) - centre[1])
}

/// The accumulators of [`angle_moments`].
const MOMENT_LANES: usize = 8;

/// One particle's terms of [`angle_moments`] into accumulator `j`.
#[inline(always)]
fn add_moments(acc: &mut [[f64; MOMENT_LANES]; 5], j: usize, a: f32, e: f32, w: f32) {
    let (a, e, w) = (f64::from(a), f64::from(e), f64::from(w));
    let (wa, we) = (w * a, w * e);
    acc[0][j] += wa;
    acc[1][j] += we;
    acc[2][j] += wa * a;
    acc[3][j] += wa * e;
    acc[4][j] += we * e;
}

/// Fills `out` with independent standard normal draws: Box-Muller on pairs of 32-bit
/// uniforms, so that the radius sqrt(-2 ln u1) reaches 6.77 sigma (the mass beyond it,
/// 1.3e-11, is what is left out). One 64-bit draw is taken from `rng` per 2048 normals:
/// the key of a counter-based stream ([`box_muller`]).
pub fn standard_normals<R: Rng + ?Sized>(rng: &mut R, out: &mut [f32]) {
    const BATCH: usize = 2048;
    let mut pairs = [0.0; BATCH];
    for block in out.chunks_mut(BATCH) {
        let key = rng.next_u64();
        if block.len() % 2 == 0 {
            box_muller(key, block);
        } else {
            box_muller(key, &mut pairs[..block.len() + 1]);
            block.copy_from_slice(&pairs[..block.len()]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// Against std's f64 functions on grids that cross every branch (quadrants,
    /// octants, binades): single precision, within a few 1e-7 (relative for ln).
    #[test]
    fn functions_match_std_within_single_precision() {
        let wide = |v: &[f32]| v.iter().map(|x| f64::from(*x)).collect::<Vec<f64>>();
        // angles to +-20 rad, and one near the 8192 the reduction is exact to
        let a: Vec<f32> = (0..2003).map(|i| -20.0 + 0.019_99 * i as f32).chain([8191.7, -8000.3]).collect();
        let (mut s, mut c) = (vec![0.0; a.len()], vec![0.0; a.len()]);
        sin_cos(&a, &mut s, &mut c);
        for i in 0..a.len() {
            let x = f64::from(a[i]);
            let (ds, dc) = (f64::from(s[i]) - x.sin(), f64::from(c[i]) - x.cos());
            assert!(ds.abs() < 4e-7 && dc.abs() < 4e-7, "{x}: {ds} {dc}");
        }
        let y: Vec<f32> = (0..2003).map(|i| ((i as f64 * 0.37).sin() * 10f64.powi(i % 7 - 3)) as f32).collect();
        let x: Vec<f32> = (0..2003).map(|i| ((i as f64 * 0.91).cos() * 10f64.powi(i % 5 - 2)) as f32).collect();
        let mut t = vec![0.0; y.len()];
        atan2(&y, &x, &mut t);
        let (yw, xw, tw) = (wide(&y), wide(&x), wide(&t));
        for i in 0..y.len() {
            assert!((tw[i] - yw[i].atan2(xw[i])).abs() < 4e-7, "atan2({}, {})", y[i], x[i]);
        }
        atan2(&[0.0, 0.0, 1.0, -1.0], &[0.0, -1.0, 0.0, 0.0], &mut t[..4]);
        for (t, expected) in t.iter().zip([0.0, 1.0, 0.5, -0.5]) {
            assert!((f64::from(*t) - expected * std::f64::consts::PI).abs() < 4e-7, "{t}");
        }
        let v: Vec<f32> = (0..2003).map(|i| -100.0 + 0.049_95 * i as f32).collect();
        let mut e = vec![0.0; v.len()];
        let total = exp_shifted(&v, 0.0, &mut e);
        for i in 0..v.len() {
            let x = f64::from(v[i]).exp();
            assert!((e[i] - x).abs() <= 3e-7 * x + 2e-38, "exp {}: {} against {x}", v[i], e[i]);
        }
        assert!((total / e.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        ln(&[0.0, f32::INFINITY, -1.0, f32::NAN], &mut t[..4]);
        assert!(t[0] == f32::NEG_INFINITY && t[1] == f32::INFINITY && t[2].is_nan() && t[3].is_nan());
        let v: Vec<f32> = (0..2003).map(|i| (1e-30 * 1.1f64.powi(i % 1200)) as f32).collect();
        ln(&v, &mut t);
        for i in 0..v.len() {
            let x = f64::from(v[i]).ln();
            assert!((f64::from(t[i]) - x).abs() < 2e-7 * x.abs().max(1.0), "ln {}", v[i]);
        }
    }

    /// Each level the processor runs (forced: `name::at`) gives the same bits as the
    /// scalar kernels called one value at a time (through `black_box`, so not
    /// vectorised), sums in the kernels' order: no result depends on the vector width.
    #[test]
    fn every_level_matches_the_scalar_kernels_bit_for_bit() {
        use std::hint::black_box;
        let n = 4099;
        let a: Vec<f32> = (0..n).map(|i| -40.0 + 0.019_53 * i as f32).collect();
        let b: Vec<f32> = (0..n).map(|i| ((i as f64 * 0.77).cos() * 10f64.powi(i as i32 % 9 - 4)) as f32).collect();
        let positive: Vec<f32> = b.iter().map(|v| v.abs() + 1e-30).collect();
        let weights: Vec<f64> = positive.iter().map(|v| f64::from(*v)).collect();
        let shift = 3.0;
        // particles about a point, a station 30 m off, angles about the point's
        let col = |f: &dyn Fn(f32) -> f32| (0..n).map(|i| f(i as f32)).collect::<Vec<f32>>();
        let (north, east) = (col(&|t| 12.0 * (t * 0.37).sin()), col(&|t| 9.0 * (t * 0.71).cos()));
        let (down, w) = (col(&|t| 30.0 + (t * 0.13).sin()), col(&|t| 1.0 + (t * 0.05).cos().abs()));
        let (station, centre) = ([-30.0, 4.0], [3.0, 0.8]);
        let levels = Level::available();
        eprintln!("levels this processor runs: {levels:?}; current {:?}", Level::current());
        for &level in &levels {
            let (mut s, mut c, mut t) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            sin_cos::at(level, &a, &mut s, &mut c);
            atan2::at(level, &a, &b, &mut t);
            for i in 0..n {
                let (s1, c1) = black_box(sin_cos1(a[i]));
                assert_eq!((s[i].to_bits(), c[i].to_bits()), (s1.to_bits(), c1.to_bits()), "{level:?} sin_cos");
                let t1 = black_box(atan2_1(a[i], b[i]));
                assert_eq!(t[i].to_bits(), t1.to_bits(), "{level:?} atan2 {} {}", a[i], b[i]);
            }
            ln::at(level, &positive, &mut t);
            for i in 0..n {
                assert_eq!(t[i].to_bits(), black_box(ln1(positive[i])).to_bits(), "{level:?} ln");
            }
            let mut wide = vec![0.0; n];
            let total = exp_shifted::at(level, &a, shift, &mut wide);
            let mut sums = [0.0; 4];
            for i in 0..n {
                let e = f64::from(black_box(exp1(a[i] - shift)));
                assert_eq!(wide[i].to_bits(), e.to_bits(), "{level:?} exp");
                sums[i % 4] += if i < n / 4 * 4 { e } else { 0.0 };
            }
            let tail: f64 = wide[n / 4 * 4..].iter().sum();
            assert_eq!(total.to_bits(), ((sums[0] + sums[1]) + (sums[2] + sums[3]) + tail).to_bits());
            let mut pairs = vec![0.0; 2 * 1024];
            box_muller::at(level, 0xDEAD_BEEF, &mut pairs);
            for i in 0..1024 {
                let (k1, k2) = black_box(hash1(0xDEAD_BEEF, i));
                let (z1, z2) = black_box(pair1(k1, k2));
                assert_eq!((pairs[i].to_bits(), pairs[1024 + i].to_bits()), (z1.to_bits(), z2.to_bits()));
            }
            let mut e = vec![0.0; 1001];
            exponentials::at(level, 0xFEED, &mut e);
            for (i, v) in e.iter().enumerate() {
                let k = black_box(hash1(0xFEED, i)).0;
                assert_eq!(v.to_bits(), f64::from(-black_box(ln_uniform(k))).to_bits());
            }
            // the maximum, with a NaN planted or not, against a scalar fold
            let mut v = a.clone();
            assert_eq!(max_of::at(level, &v).to_bits(), a.iter().fold(f32::NEG_INFINITY, |m, x| m.max(*x)).to_bits());
            assert_eq!(
                max_of::at(level, &v[..7]).to_bits(),
                a[..7].iter().fold(f32::NEG_INFINITY, |m, x| m.max(*x)).to_bits()
            );
            v[n - 5] = f32::NAN;
            assert!(max_of::at(level, &v).is_nan() && max_of::at(level, &v[..n - 5]).is_finite());
            let moments = angle_moments::at(level, &north, &east, &down, &w, station, centre);
            let mut acc = [[0.0; MOMENT_LANES]; 5];
            for i in 0..n {
                let (a1, e1) = black_box(angles1(north[i], east[i], down[i], station, centre));
                add_moments(&mut acc, i % MOMENT_LANES, a1, e1, w[i]);
            }
            let expected = acc.map(|m| ((m[0] + m[1]) + (m[2] + m[3])) + ((m[4] + m[5]) + (m[6] + m[7])));
            assert_eq!(moments.map(f64::to_bits), expected.map(f64::to_bits), "{level:?} angle moments");
            // three components (ones among them: sums; the second an angle), six pairs,
            // two blocks and a part
            let m = 2 * PRODUCT_BLOCK + 37;
            let ones = vec![1.0; m];
            let comps = [&a[..m], &b[..m], &ones[..]];
            let (centre, angle) = ([0.5, -3.0, 0.0], Some(1));
            let pairs = [(0, 2), (1, 2), (0, 0), (0, 1), (1, 1), (1, 0)];
            let mut products = [0.25; 6];
            add_products::at(level, &weights[..m], &comps, &centre, angle, &pairs, &mut products);
            let mut expected = [0.25; 6];
            let y = |k: usize, i: usize| {
                let d = comps[k][i] - centre[k];
                if Some(k) == angle { black_box(wrap_near(d)) } else { d }
            };
            for start in (0..m).step_by(PRODUCT_BLOCK) {
                let end = (start + PRODUCT_BLOCK).min(m);
                for (p, &(k, l)) in pairs.iter().enumerate() {
                    let mut lanes = [0.0f32; 16];
                    let wf = |i: usize| if weights[i] < NEGLIGIBLE_WEIGHT { 0.0 } else { weights[i] as f32 };
                    let term = |i: usize| black_box(black_box(wf(i) * y(k, i)) * y(l, i));
                    for i in start..end {
                        lanes[(i - start) % 16] += term(i);
                    }
                    let h8: Vec<f32> = (0..8).map(|j| black_box(lanes[j] + lanes[j + 8])).collect();
                    let h4: Vec<f32> = (0..4).map(|j| black_box(h8[j] + h8[j + 4])).collect();
                    expected[p] += f64::from((h4[0] + h4[2]) + (h4[1] + h4[3]));
                }
            }
            let bits = |p: &[f64]| p.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&products), bits(&expected), "{level:?} products");
        }
    }

    /// The moments of the USBL angles against double precision: atan2 of f64, the sums
    /// in one pass; within what 4e-7 rad per angle can move them (the angles' bound,
    /// `functions_match_std_within_single_precision`), particle by particle.
    #[test]
    fn angle_moments_match_double_precision() {
        let n = 3001;
        let f = |i: usize, k: f64| (i as f64 * k).sin();
        let (north, east): (Vec<f32>, Vec<f32>) =
            (0..n).map(|i| ((15.0 * f(i, 0.3)) as f32, (20.0 * f(i, 0.7)) as f32)).unzip();
        let down: Vec<f32> = (0..n).map(|i| (30.0 + f(i, 0.11)) as f32).collect();
        let w: Vec<f32> = (0..n).map(|i| (1.0 + 0.5 * f(i, 0.05)) as f32).collect();
        // the station across the azimuth's wrap: the angles about pi
        let (station, centre) = ([40.0f32, 0.5], [3.1f32, 0.9]);
        let got = angle_moments(&north, &east, &down, &w, station, centre);
        // the sums, and how far an error of eps in each angle can move them
        let eps = 4e-7 + 1e-7; // the angle's, and the coordinate difference's rounding
        let (mut expected, mut bounds) = ([0.0; 5], [0.0; 5]);
        for i in 0..n {
            let (dx, dy, dz) = (f64::from(north[i] - station[0]), f64::from(east[i] - station[1]), f64::from(down[i]));
            let a = crate::geo::wrap_angle(dy.atan2(dx) - f64::from(centre[0]));
            let e = (dx * dx + dy * dy).sqrt().atan2(dz) - f64::from(centre[1]);
            let wi = f64::from(w[i]);
            let (da, de) = (a.abs() * eps, e.abs() * eps);
            for (k, (v, b)) in
                [(a, eps), (e, eps), (a * a, 2.0 * da), (a * e, da + de), (e * e, 2.0 * de)].into_iter().enumerate()
            {
                expected[k] += wi * v;
                bounds[k] += wi * (b + eps * eps) * 1.001;
            }
        }
        for k in 0..5 {
            assert!((got[k] - expected[k]).abs() <= bounds[k], "moment {k}: {} against {}", got[k], expected[k]);
        }
        assert!(expected[0].abs() > 10.0 * bounds[0], "the azimuths do not cancel out");
    }

    /// 1e6 exponential draws: mean and variance 1 within 5 standard errors (the
    /// variance's is sqrt(8 / n)), and the mass beyond 1, 3 and 10 within 5 binomial
    /// standard errors of e^-x.
    #[test]
    fn exponentials_have_the_standard_moments_and_tail() {
        let n = 1_000_000;
        let mut e = vec![0.0; n];
        exponentials(0x5EED, &mut e);
        let nf = n as f64;
        let mean = e.iter().sum::<f64>() / nf;
        let var = e.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / nf;
        assert!((mean - 1.0).abs() < 5.0 / nf.sqrt(), "mean {mean}");
        assert!((var - 1.0).abs() < 5.0 * (8.0 / nf).sqrt(), "variance {var}");
        for x in [1.0f64, 3.0, 10.0] {
            let p = (-x).exp();
            let beyond = e.iter().filter(|v| **v > x).count() as f64 / nf;
            assert!((beyond - p).abs() < 5.0 * (p * (1.0 - p) / nf).sqrt(), "beyond {x}: {beyond} against {p}");
        }
    }

    /// 1e6 draws against N(0, 1): mean, variance and kurtosis within 5 standard errors,
    /// and the mass beyond 1, 2 and 3 sigma within 5 binomial standard errors of
    /// 2 (1 - Phi).
    #[test]
    fn normals_have_the_standard_moments_and_tails() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        let n = 1_000_001; // odd, and not a whole number of batches
        let mut drawn = vec![0.0f32; n];
        standard_normals(&mut rng, &mut drawn);
        let z: Vec<f64> = drawn.iter().map(|v| f64::from(*v)).collect();
        let nf = n as f64;
        let mean = z.iter().sum::<f64>() / nf;
        let var = z.iter().map(|v| v * v).sum::<f64>() / nf;
        let kurt = z.iter().map(|v| v.powi(4)).sum::<f64>() / nf;
        assert!(mean.abs() < 5.0 / nf.sqrt(), "mean {mean}");
        assert!((var - 1.0).abs() < 5.0 * (2.0 / nf).sqrt(), "variance {var}");
        assert!((kurt - 3.0).abs() < 5.0 * (96.0 / nf).sqrt(), "kurtosis {kurt}");
        for (k, p) in [(1.0, 0.317_310_507_862_914_1), (2.0, 0.045_500_263_896_358_4), (3.0, 0.002_699_796_063_260_2)] {
            let beyond = z.iter().filter(|v| v.abs() > k).count() as f64 / nf;
            assert!((beyond - p).abs() < 5.0 * (p * (1.0 - p) / nf).sqrt(), "beyond {k}: {beyond} against {p}");
        }
        // the two halves of a pair are independent: their correlation within 5 / sqrt(n)
        let pairs = z.len() / 2048 * 1024;
        let r: f64 = z.chunks_exact(2048).map(|b| (0..1024).map(|i| b[i] * b[1024 + i]).sum::<f64>()).sum::<f64>()
            / pairs as f64;
        assert!(r.abs() < 5.0 / (pairs as f64).sqrt(), "pair correlation {r}");
        // the pair's angle is uniform: a quarter of the pairs in each quadrant, and an
        // eighth in each half of one (its offset's sign)
        let mut counts = [0.0; 8];
        for b in z.chunks_exact(2048) {
            for i in 0..1024 {
                let (s, c) = (b[i], b[1024 + i]);
                let octant = (s.atan2(c).rem_euclid(std::f64::consts::TAU) / std::f64::consts::FRAC_PI_4) as usize;
                counts[octant.min(7)] += 1.0 / pairs as f64;
            }
        }
        for c in counts {
            assert!((c - 0.125).abs() < 5.0 * (0.125 * 0.875 / pairs as f64).sqrt(), "octants {counts:?}");
        }
    }

    /// Kolmogorov-Smirnov over 1e7 draws: the largest distance between their empirical
    /// distribution and Phi within the 0.1 % critical value of the KS statistic, 1.949 /
    /// sqrt(n) (6.2e-4; a variance off by 1 % moves it by about 1.2e-3).
    #[test]
    fn normals_pass_kolmogorov_smirnov_over_ten_million_draws() {
        use statrs::distribution::{ContinuousCDF, Normal};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(9);
        let mut z = vec![0.0f32; 10_000_000];
        standard_normals(&mut rng, &mut z);
        z.sort_unstable_by(f32::total_cmp);
        let phi = Normal::standard();
        let n = z.len() as f64;
        let d = z.iter().enumerate().fold(0.0f64, |d, (i, v)| {
            let f = phi.cdf(f64::from(*v));
            d.max(f - i as f64 / n).max((i + 1) as f64 / n - f)
        });
        assert!(d < 1.949 / n.sqrt(), "KS distance {d} against {}", 1.949 / n.sqrt());
    }
}
