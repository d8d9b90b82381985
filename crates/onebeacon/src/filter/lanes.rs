//! Transcendental functions over slices for particle models: sine and cosine, atan2,
//! the logarithm and standard normal draws, computed in single precision by branchless
//! polynomials (Cephes' sinf, cosf, logf and atanf coefficients, S. L. Moshier) that
//! the compiler vectorises, and returned in f64.
//!
//! Each slice function is compiled for AVX-512, for AVX2 and for the baseline, and the
//! best the processor has is chosen at run time (`multiversion`): the arithmetic is the
//! same IEEE operations in every version (no fused multiply-add), so the three give
//! identical results and a run does not depend on the machine's vector width.
//!
//! Single precision is far finer than what these values feed: a step of a few metres
//! (relative error 1e-7: under a micrometre), an angle residual against a noise of
//! milliradians, a log-likelihood against a spread of units. At N = 5e5 this is what
//! makes a hoff2024 filter cycle fit its budget (README, Benchmarks): libm's
//! scalar atan2 and sin_cos cost some 20 ns a call.

use multiversion::multiversion;
use rand::Rng;
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// x rounded to the nearest integer (|x| < 2^31), as a float and as an integer: added
/// to and taken from 1.5 2^52, whose last bits then hold the integer (in two's
/// complement). Unlike `as`, which saturates lane by lane, the compiler vectorises it.
#[inline(always)]
fn round(x: f64) -> (f64, i32) {
    const MAGIC: f64 = 6_755_399_441_055_744.0;
    let shifted = x + MAGIC;
    (shifted - MAGIC, shifted.to_bits() as i32)
}

/// sin x and cos x (|x| below some 1e6): x reduced by pi/2 in double precision (so the
/// input's own rounding to single precision does not count), then [`sin_cos_reduced`].
#[inline(always)]
fn sin_cos1(x: f64) -> (f32, f32) {
    let (q, quadrant) = round(x * std::f64::consts::FRAC_2_PI);
    // pi / 2 in two parts (the second, what f64 leaves of it)
    let r = ((x - q * std::f64::consts::FRAC_PI_2) - q * 6.123_233_995_736_766e-17) as f32;
    sin_cos_reduced(r, quadrant)
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
fn ln1(x: f32) -> f32 {
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
/// |r| <= ln 2 / 2, reduced in double precision, Cephes' expf polynomial in r, 2^k from
/// its bits.
#[inline(always)]
fn exp1(x: f64) -> f32 {
    let under = x < -87.0;
    let x = x.clamp(-87.0, 0.0);
    let (k, ki) = round(x * std::f64::consts::LOG2_E);
    let r = (x - k * std::f64::consts::LN_2) as f32;
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
fn atan2_1(y: f32, x: f32) -> f32 {
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

/// sin and cos of every angle of `a` (radians, |a| below some 1e6).
#[multiversion(targets("x86_64+avx512f+avx512bw+avx512vl+avx512dq", "x86_64+avx2+avx", "aarch64+neon"))]
pub fn sin_cos(a: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    let n = a.len();
    let (sin, cos) = (&mut sin[..n], &mut cos[..n]);
    for i in 0..n {
        let (s, c) = sin_cos1(a[i]);
        sin[i] = f64::from(s);
        cos[i] = f64::from(c);
    }
}

/// atan2(y_i, x_i) for every i, in [-pi, pi].
#[multiversion(targets("x86_64+avx512f+avx512bw+avx512vl+avx512dq", "x86_64+avx2+avx", "aarch64+neon"))]
pub fn atan2(y: &[f64], x: &[f64], out: &mut [f64]) {
    let n = out.len();
    let (y, x) = (&y[..n], &x[..n]);
    for i in 0..n {
        out[i] = f64::from(atan2_1(y[i] as f32, x[i] as f32));
    }
}

/// exp(x_i - shift) for every i, and their sum (in a fixed order), for log-weights x_i
/// at most `shift` (the largest: weights relative to the heaviest).
#[multiversion(targets("x86_64+avx512f+avx512bw+avx512vl+avx512dq", "x86_64+avx2+avx", "aarch64+neon"))]
pub fn exp_shifted(x: &[f64], shift: f64, out: &mut [f64]) -> f64 {
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

/// ln x_i for every i: to single precision for x_i within f32's normal range (1.2e-38
/// to 3.4e38; a subnormal gives a meaningless result), -inf at 0, +inf above the range,
/// NaN for a negative or NaN x_i.
#[multiversion(targets("x86_64+avx512f+avx512bw+avx512vl+avx512dq", "x86_64+avx2+avx", "aarch64+neon"))]
pub fn ln(x: &[f64], out: &mut [f64]) {
    let n = out.len();
    let x = &x[..n];
    for i in 0..n {
        out[i] = f64::from(ln1(x[i] as f32));
    }
}

/// Box-Muller on 32-bit uniform pairs, `n = out.len() / 2` of them: the i-th 64-bit
/// draw is SplitMix64's output for the counter `key + (i + 1) gamma` (Steele, Lea and
/// Flood 2014: a mixing of a Weyl sequence that passes BigCrush), computed in lanes. Its
/// high half gives u1 = (k + 1/2) 2^-32 and the radius sqrt(-2 ln u1); its low half a
/// uniform angle, as a quadrant (its top two bits) and an offset within it (the other
/// 30, centred: within +-pi/4), so that no range reduction is needed. The pair gives
/// draws `out[i]` and `out[n + i]`.
#[multiversion(targets("x86_64+avx512f+avx512bw+avx512vl+avx512dq", "x86_64+avx2+avx", "aarch64+neon"))]
fn box_muller(key: u64, out: &mut [f64]) {
    const SCALE: f32 = 1.0 / 4_294_967_296.0;
    const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;
    let n = out.len() / 2;
    let (first, second) = out.split_at_mut(n);
    let second = &mut second[..n];
    for i in 0..n {
        let mut z = key.wrapping_add((i as u64 + 1).wrapping_mul(GAMMA));
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        let (k1, k2) = ((z >> 32) as u32, z as u32);
        let radius = (-2.0 * ln1((k1 as f32 + 0.5) * SCALE)).sqrt();
        let offset = ((k2 & 0x3fff_ffff) as i32 - 0x2000_0000) as f32 * (FRAC_PI_2 / 1_073_741_824.0);
        let (s, c) = sin_cos_reduced(offset, (k2 >> 30) as i32);
        first[i] = f64::from(radius * s);
        second[i] = f64::from(radius * c);
    }
}

/// Fills `out` with independent standard normal draws: Box-Muller on pairs of 32-bit
/// uniforms, so that the radius sqrt(-2 ln u1) reaches 6.77 sigma (the mass beyond it,
/// 1.3e-11, is what is left out). One 64-bit draw is taken from `rng` per 2048 normals:
/// the key of a counter-based stream ([`box_muller`]).
pub fn standard_normals<R: Rng + ?Sized>(rng: &mut R, out: &mut [f64]) {
    const BATCH: usize = 2048;
    let mut pairs = [0.0; BATCH];
    for block in out.chunks_mut(BATCH) {
        let m = block.len() + block.len() % 2;
        box_muller(rng.next_u64(), &mut pairs[..m]);
        block.copy_from_slice(&pairs[..block.len()]);
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
        let a: Vec<f64> = (0..2003).map(|i| -20.0 + 0.019_99 * i as f64).collect();
        let (mut s, mut c) = (vec![0.0; a.len()], vec![0.0; a.len()]);
        sin_cos(&a, &mut s, &mut c);
        for i in 0..a.len() {
            assert!((s[i] - a[i].sin()).abs() < 4e-7 && (c[i] - a[i].cos()).abs() < 4e-7, "{}", a[i]);
        }
        let y: Vec<f64> = (0..2003).map(|i| (i as f64 * 0.37).sin() * 10f64.powi(i % 7 - 3)).collect();
        let x: Vec<f64> = (0..2003).map(|i| (i as f64 * 0.91).cos() * 10f64.powi(i % 5 - 2)).collect();
        let mut t = vec![0.0; y.len()];
        atan2(&y, &x, &mut t);
        for i in 0..y.len() {
            assert!((t[i] - y[i].atan2(x[i])).abs() < 4e-7, "atan2({}, {})", y[i], x[i]);
        }
        atan2(&[0.0, 0.0, 1.0, -1.0], &[0.0, -1.0, 0.0, 0.0], &mut t[..4]);
        for (t, expected) in t.iter().zip([0.0, 1.0, 0.5, -0.5]) {
            assert!((t - expected * std::f64::consts::PI).abs() < 4e-7, "{t}");
        }
        let v: Vec<f64> = (0..2003).map(|i| -100.0 + 0.049_95 * i as f64).collect();
        let total = exp_shifted(&v, 0.0, &mut t);
        for i in 0..v.len() {
            let e = v[i].exp();
            assert!((t[i] - e).abs() <= 3e-7 * e + 2e-38, "exp {}: {} against {e}", v[i], t[i]);
        }
        assert!((total / t.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        ln(&[0.0, 1e39, -1.0, f64::NAN], &mut t[..4]);
        assert!(t[0] == f64::NEG_INFINITY && t[1] == f64::INFINITY && t[2].is_nan() && t[3].is_nan());
        let v: Vec<f64> = (0..2003).map(|i| 1e-30 * 1.1f64.powi(i % 1400)).collect();
        ln(&v, &mut t);
        for i in 0..v.len() {
            assert!((t[i] - v[i].ln()).abs() < 2e-7 * v[i].ln().abs().max(1.0), "ln {}", v[i]);
        }
    }

    /// The dispatched versions (AVX-512 or AVX2 where the processor has them) give the
    /// same bits as the scalar kernels called one value at a time in a loop compiled
    /// for the baseline: no result depends on the vector width.
    #[test]
    fn dispatched_versions_match_the_scalar_kernels_bit_for_bit() {
        let n = 4099;
        let a: Vec<f64> = (0..n).map(|i| -40.0 + 0.019_53 * i as f64).collect();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.77).cos() * 10f64.powi(i as i32 % 9 - 4)).collect();
        let (mut s, mut c, mut t) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        sin_cos(&a, &mut s, &mut c);
        atan2(&a, &b, &mut t);
        for i in 0..n {
            let (s1, c1) = std::hint::black_box(sin_cos1(a[i]));
            assert_eq!(
                (s[i].to_bits(), c[i].to_bits()),
                (f64::from(s1).to_bits(), f64::from(c1).to_bits()),
                "sin_cos {}",
                a[i]
            );
            let t1 = std::hint::black_box(atan2_1(a[i] as f32, b[i] as f32));
            assert_eq!(t[i].to_bits(), f64::from(t1).to_bits(), "atan2 {} {}", a[i], b[i]);
        }
        let positive: Vec<f64> = b.iter().map(|v| v.abs() + 1e-30).collect();
        ln(&positive, &mut t);
        for i in 0..n {
            assert_eq!(t[i].to_bits(), f64::from(std::hint::black_box(ln1(positive[i] as f32))).to_bits());
        }
        let shift = 3.0;
        exp_shifted(&a, shift, &mut t);
        for i in 0..n {
            assert_eq!(t[i].to_bits(), f64::from(std::hint::black_box(exp1(a[i] - shift))).to_bits());
        }
    }

    /// 1e6 draws against N(0, 1): mean, variance and kurtosis within 5 standard errors,
    /// and the mass beyond 1, 2 and 3 sigma within 5 binomial standard errors of
    /// 2 (1 - Phi).
    #[test]
    fn normals_have_the_standard_moments_and_tails() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        let n = 1_000_001; // odd, and not a whole number of batches
        let mut z = vec![0.0; n];
        standard_normals(&mut rng, &mut z);
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
}
