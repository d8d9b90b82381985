//! What a particle filter says of its particles: a systematic subsample for a planner,
//! and the weighted mean and covariance as the estimate.

use super::{CHUNK, ParticleFilter};
use crate::filter::resample::weight_before_chunks;
use crate::par::*;
use nalgebra::{SMatrix, SVector};

impl<const D: usize> ParticleFilter<D> {
    /// `m` particles drawn systematically in proportion to their weights (offset one
    /// half: no random draw), for a planner that scores a belief on a subsample; each
    /// stands for 1 / m of the weight. Components `k` of each. By chunks of particles
    /// in parallel: each takes the points within its share of the cumulative weight
    /// (from the sums of the chunks before it) and walks them along its particles.
    pub fn subsample<const K: usize>(&self, m: usize, k: [usize; K]) -> Vec<[f64; K]> {
        let w = self.normalised();
        let offsets = weight_before_chunks(w);
        let point = |j: usize| (j as f64 + 0.5) / m as f64;
        // the first point at or past cumulative weight `c` (the last chunk takes the rest)
        let first_at = |c: f64| {
            let mut j = ((c * m as f64 - 0.5).ceil().max(0.0) as usize).min(m);
            while j > 0 && point(j - 1) >= c {
                j -= 1;
            }
            while j < m && point(j) < c {
                j += 1;
            }
            j
        };
        let (chunks, n, x, origin) = (offsets.len(), self.len(), &self.x, &self.origin);
        let picked: Vec<Vec<[f64; K]>> = (0..chunks)
            .into_par_iter()
            .map(|c| {
                let (lo, hi) = (first_at(offsets[c]), if c + 1 == chunks { m } else { first_at(offsets[c + 1]) });
                let (first, w) = (c * CHUNK, &w[c * CHUNK..((c + 1) * CHUNK).min(n)]);
                let (mut i, mut cum) = (0, offsets[c] + w[0]);
                (lo..hi)
                    .map(|j| {
                        while point(j) >= cum && i + 1 < w.len() {
                            i += 1;
                            cum += w[i];
                        }
                        k.map(|comp| origin[comp] + f64::from(x[comp][first + i]))
                    })
                    .collect()
            })
            .collect();
        picked.concat()
    }

    /// The weighted mean and covariance of the particles, in one pass.
    pub fn mean_covariance(&self) -> (SVector<f64, D>, SMatrix<f64, D, D>) {
        self.mean_covariance_with_angle(None)
    }

    /// [`ParticleFilter::mean_covariance`] with component `angle` (when given) an angle
    /// in (-pi, pi]: taken as its difference from the heaviest particle's, wrapped, so
    /// that a cloud across +-pi has its mean and spread where they are (for a spread
    /// well below pi). The mean angle is wrapped. The moments are those of the offsets
    /// less the heaviest particle's (single precision within blocks of
    /// [`crate::filter::lanes::PRODUCT_BLOCK`], double across them), the origin and that
    /// particle added to the mean.
    pub fn mean_covariance_with_angle(&self, angle: Option<usize>) -> (SVector<f64, D>, SMatrix<f64, D, D>) {
        let w = self.normalised();
        let x = &self.x;
        // the moments are taken about the heaviest particle (in single precision a cloud
        // off the origin by more than its spread would otherwise lose its covariance to
        // E[x x'] - m m')
        // the first of the largest weights: each chunk's first, then the first of those
        let first_largest = |b: (usize, f64), (i, v): (usize, f64)| if v > b.1 { (i, v) } else { b };
        let heaviest = (0..w.len().div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let start = c * CHUNK;
                let chunk = &w[start..(start + CHUNK).min(w.len())];
                chunk.iter().enumerate().map(|(i, v)| (start + i, *v)).fold((start, f64::MIN), first_largest)
            })
            .collect::<Vec<_>>()
            .into_iter()
            .fold((0, f64::MIN), first_largest)
            .0;
        let centre: Vec<f32> = (0..D).map(|k| x[k].get(heaviest).copied().unwrap_or(0.0)).chain([0.0]).collect();
        // per chunk: sum w y_k (w y_k times a component of ones) and sum w y_k y_l
        // (k <= l), y the offsets less the centre, in the lanes (single precision within
        // blocks, double across them), reduced in chunk order
        let pairs: Vec<(usize, usize)> =
            (0..D).map(|k| (k, D)).chain((0..D).flat_map(|k| (k..D).map(move |l| (k, l)))).collect();
        let ones = vec![1.0f32; CHUNK.min(w.len())];
        let partial: Vec<(SVector<f64, D>, SMatrix<f64, D, D>)> = (0..w.len().div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let (start, end) = (c * CHUNK, ((c + 1) * CHUNK).min(w.len()));
                let w = &w[start..end];
                let comps: Vec<&[f32]> = x.iter().map(|xk| &xk[start..end]).chain([&ones[..w.len()]]).collect();
                let mut products = vec![0.0; pairs.len()];
                crate::filter::lanes::add_products(w, &comps, &centre, angle, &pairs, &mut products);
                let (mut s, mut ss) = (SVector::<f64, D>::zeros(), SMatrix::<f64, D, D>::zeros());
                for (&(k, l), total) in pairs.iter().zip(products) {
                    if l == D {
                        s[k] = total;
                    } else {
                        (ss[(k, l)], ss[(l, k)]) = (total, total);
                    }
                }
                (s, ss)
            })
            .collect();
        let (mut mean, mut second) = (SVector::zeros(), SMatrix::zeros());
        for (s, ss) in partial {
            mean += s;
            second += ss;
        }
        let cov = second - mean * mean.transpose();
        for k in 0..D {
            mean[k] += self.origin[k] + f64::from(centre[k]);
        }
        if let Some(k) = angle {
            mean[k] = crate::geo::wrap_angle(mean[k]);
        }
        (mean, cov)
    }
}
