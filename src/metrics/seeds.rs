//! The per-pixel error of one configuration split over its seeds into squared bias and variance
//! (FACTS.md, "Bias vs variance"): MSE = bias^2 + variance.
//!
//! With d_ip = x_ip - ref_p the error of seed i at pixel p and K seeds:
//!
//! - variance = mean_p s_p^2, the unbiased sample variance of d_p over seeds;
//! - bias^2 = mean_p [ (mean_i d_ip)^2 - s_p^2 / K ] = mean_p sum_{i != j} d_ip d_jp / (K (K - 1)),
//!   the unbiased estimator of the squared bias. Being unbiased it can come out negative when the
//!   true bias is small against the noise; its 95 % interval, from the delete-one-seed jackknife
//!   (it is a U-statistic over seeds, so the jackknife applies even when the pixels of a shared
//!   pattern are correlated), says whether it is distinguishable from 0.
//!
//! Exactly, mean_i MSE_i = bias^2 + variance, where MSE_i = mean_p d_ip^2 is seed i's own MSE.

use super::error::PenumbraMask;
use super::stats::t975;

/// Squared bias and variance of one configuration over its seeds.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BiasVariance {
    /// Seeds the split rests on.
    pub seeds: usize,
    /// Unbiased estimate of the mean squared per-pixel bias; NaN with fewer than 2 seeds.
    pub bias2: f64,
    /// Half-width of its 95 % interval (jackknife over seeds); NaN with fewer than 3 seeds.
    pub bias2_ci: f64,
    /// Mean per-pixel variance over seeds; NaN with fewer than 2 seeds.
    pub variance: f64,
}

impl BiasVariance {
    /// Splits the error of `images` (one per seed) against `reference` over `mask`.
    pub fn measure(images: &[Vec<f32>], reference: &[f32], mask: &PenumbraMask) -> BiasVariance {
        let k = images.len();
        let nan = BiasVariance {
            seeds: k,
            bias2: f64::NAN,
            bias2_ci: f64::NAN,
            variance: f64::NAN,
        };
        if k < 2 || mask.pixels.is_empty() {
            return nan;
        }
        let kf = k as f64;
        let (mut bias2, mut variance) = (0.0, 0.0);
        let mut leave_out = vec![0.0; k];
        let mut d = vec![0.0; k];
        for &p in &mask.pixels {
            for (di, im) in d.iter_mut().zip(images) {
                *di = im[p] as f64 - reference[p] as f64;
            }
            let s1: f64 = d.iter().sum();
            let s2: f64 = d.iter().map(|x| x * x).sum();
            bias2 += (s1 * s1 - s2) / (kf * (kf - 1.0));
            variance += (s2 - s1 * s1 / kf) / (kf - 1.0);
            if k >= 3 {
                for (acc, &di) in leave_out.iter_mut().zip(&d) {
                    let (t1, t2) = (s1 - di, s2 - di * di);
                    *acc += (t1 * t1 - t2) / ((kf - 1.0) * (kf - 2.0));
                }
            }
        }
        let n = mask.pixels.len() as f64;
        let bias2 = bias2 / n;
        let bias2_ci = if k >= 3 {
            let jack: Vec<f64> = leave_out.iter().map(|x| x / n).collect();
            let mean = jack.iter().sum::<f64>() / kf;
            let var = (kf - 1.0) / kf * jack.iter().map(|x| (x - mean).powi(2)).sum::<f64>();
            t975(k - 1) * var.sqrt()
        } else {
            f64::NAN
        };
        BiasVariance {
            seeds: k,
            bias2,
            bias2_ci,
            variance: variance / n,
        }
    }

    /// Whether the 95 % interval of the squared bias holds 0 (false when there is no interval).
    pub fn zero_within_noise(&self) -> bool {
        self.bias2_ci.is_finite() && self.bias2.abs() <= self.bias2_ci
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Stream;

    /// Seeded standard normal deviates (Box-Muller over the project's counter-based stream).
    fn normal(stream: Stream, i: u32) -> f64 {
        let (u, v) = (stream.unit(2 * i).max(1e-12), stream.unit(2 * i + 1));
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    /// `seeds` images of `pixels` pixels around a reference of 0.5, with per-pixel bias `b` and
    /// noise of standard deviation `sigma`.
    fn images(seeds: u32, pixels: u32, b: f64, sigma: f64) -> (Vec<Vec<f32>>, Vec<f32>, PenumbraMask) {
        let reference = vec![0.5f32; pixels as usize];
        let ims = (0..seeds)
            .map(|s| {
                let stream = Stream::new(7, s, None);
                (0..pixels)
                    .map(|p| (0.5 + b + sigma * normal(stream, p)) as f32)
                    .collect()
            })
            .collect();
        let mask = PenumbraMask {
            pixels: (0..pixels as usize).collect(),
        };
        (ims, reference, mask)
    }

    #[test]
    fn mse_is_bias2_plus_variance_exactly() {
        let (ims, reference, mask) = images(5, 300, 0.02, 0.1);
        let bv = BiasVariance::measure(&ims, &reference, &mask);
        let mse: f64 = ims
            .iter()
            .map(|im| {
                crate::metrics::ErrorMetrics::measure(im, &reference, &mask)
                    .rmse
                    .powi(2)
            })
            .sum::<f64>()
            / ims.len() as f64;
        assert!((mse - (bv.bias2 + bv.variance)).abs() < 1e-12 * mse, "{mse} vs {bv:?}");
    }

    #[test]
    fn known_bias_and_variance_are_recovered() {
        // b^2 = 9e-4, sigma^2 = 1e-2. The estimator's standard error here is about 3e-5.
        let (ims, reference, mask) = images(8, 20_000, 0.03, 0.1);
        let bv = BiasVariance::measure(&ims, &reference, &mask);
        assert!((bv.variance - 0.01).abs() < 3e-4, "{bv:?}");
        assert!((bv.bias2 - 9e-4).abs() < 1.5e-4, "{bv:?}");
        assert!(bv.bias2_ci > 0.0 && bv.bias2_ci < 3e-4, "{bv:?}");
        assert!(
            (bv.bias2 - 9e-4).abs() <= bv.bias2_ci,
            "interval misses the truth: {bv:?}"
        );
        assert!(!bv.zero_within_noise());
    }

    #[test]
    fn no_bias_is_zero_within_noise_even_when_the_estimate_is_negative() {
        let mut negatives = 0;
        for seed_base in 0..20 {
            let reference = vec![0.5f32; 2000];
            let ims: Vec<Vec<f32>> = (0..4)
                .map(|s| {
                    let stream = Stream::new(11, 4 * seed_base + s, None);
                    (0..2000).map(|p| (0.5 + 0.1 * normal(stream, p)) as f32).collect()
                })
                .collect();
            let mask = PenumbraMask {
                pixels: (0..2000).collect(),
            };
            let bv = BiasVariance::measure(&ims, &reference, &mask);
            negatives += (bv.bias2 < 0.0) as u32;
            assert!(bv.zero_within_noise(), "{bv:?}");
        }
        // The estimator is unbiased, so about half of the unbiased cases come out negative.
        assert!((4..=16).contains(&negatives), "{negatives} of 20 negative");
    }

    #[test]
    fn too_few_seeds_give_no_numbers_rather_than_wrong_ones() {
        let (ims, reference, mask) = images(2, 10, 0.0, 0.1);
        let two = BiasVariance::measure(&ims, &reference, &mask);
        assert!(two.bias2.is_finite() && two.bias2_ci.is_nan() && !two.zero_within_noise());
        let one = BiasVariance::measure(&ims[..1], &reference, &mask);
        assert!(one.bias2.is_nan() && one.variance.is_nan() && one.seeds == 1);
    }
}
