//! The distribution-free 95 % interval of a median (order statistics), and the median of paired
//! per-round ratios.

use super::estimate::Estimate;
use crate::metrics::stats::median;

/// The rank `k` (1-based) of the distribution-free 95 % interval `[x(k), x(n+1-k)]` of the
/// median of `n` values (order statistics): the largest `k` with `P(Binomial(n, 1/2) < k) <=
/// 0.025`, at least 1. Exact whatever the values' distribution, for independent values.
pub fn interval_rank(n: usize) -> usize {
    if n > 1000 {
        // Normal approximation of the binomial, off by well under one rank here.
        let k = (n as f64 / 2.0 - 1.96 * (n as f64).sqrt() / 2.0).floor() as usize;
        return k.max(1);
    }
    // P(B <= i), i = 0, 1, ..., accumulated in f64 (0.5^1000 ~ 1e-301 still fits).
    let (mut term, mut below) = (0.5f64.powi(n as i32), 0.0);
    let mut k = 0;
    for i in 0..n {
        below += term;
        if below > 0.025 {
            break;
        }
        k = i + 1;
        term *= (n - i) as f64 / (i + 1) as f64;
    }
    k.max(1)
}

/// Coverage of the interval [`interval_rank`] gives for `n` values: `1 - 2 P(B < k)`.
pub fn coverage(n: usize) -> f64 {
    let k = interval_rank(n);
    let (mut term, mut below) = (0.5f64.powi(n.min(1000) as i32), 0.0);
    for i in 0..k.min(n) {
        below += term;
        term *= (n - i) as f64 / (i + 1) as f64;
    }
    1.0 - 2.0 * below
}

/// Median of `values` with its distribution-free 95 % interval (order statistics,
/// [`interval_rank`]); the interval is NaN with fewer than two values or any non-finite value.
pub fn median_interval(values: &[f64]) -> Estimate {
    let m = median(values);
    let n = values.len();
    if n < 2 || values.iter().any(|v| !v.is_finite()) {
        return Estimate {
            median: m,
            lo: f64::NAN,
            hi: f64::NAN,
        };
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let k = interval_rank(n);
    Estimate {
        median: m,
        lo: v[k - 1],
        hi: v[n - k],
    }
}

/// Median of the per-round ratios `a[i] / b[i]` (units visited in the same rounds) with its 95 %
/// interval.
pub fn paired_ratio(a: &[f64], b: &[f64]) -> Estimate {
    assert_eq!(a.len(), b.len(), "paired units share their rounds");
    let ratios: Vec<f64> = a.iter().zip(b).map(|(x, y)| x / y).collect();
    median_interval(&ratios)
}

#[cfg(test)]
mod tests {
    use super::super::draws;
    use super::*;
    use crate::timing::rule::Comparison;
    use crate::timing::schedule::Schedule;

    /// The ranks and coverages of the order-statistic interval: known values of the binomial
    /// (n = 5: [min, max], 1 - 2/32; n = 9: the second smallest and largest, 1 - 2 x 10/512),
    /// at least 95 % from 6 values on, and the normal approximation agreeing at the hand-over.
    #[test]
    fn order_statistic_intervals_have_their_coverage() {
        assert_eq!((interval_rank(5), coverage(5)), (1, 1.0 - 2.0 / 32.0));
        assert_eq!(interval_rank(9), 2);
        assert!((coverage(9) - (1.0 - 20.0 / 512.0)).abs() < 1e-12);
        for n in 6..=1000 {
            assert!(coverage(n) >= 0.95, "n = {n}: {}", coverage(n));
        }
        assert!(interval_rank(1000).abs_diff(interval_rank(1001)) <= 1);
        assert_eq!(
            median_interval(&[5.0, 1.0, 3.0, 2.0, 4.0]),
            Estimate {
                median: 3.0,
                lo: 1.0,
                hi: 5.0
            }
        );
    }

    #[test]
    fn intervals_hold_the_median_and_shrink_with_more_repeats() {
        let few = median_interval(&draws(1, 6, 10.0, 0.1));
        let many = median_interval(&draws(2, 200, 10.0, 0.1));
        for e in [few, many] {
            assert!(e.lo <= e.median && e.median <= e.hi, "{e:?}");
        }
        assert!(many.hi - many.lo < (few.hi - few.lo) / 2.0, "{few:?} {many:?}");
        assert!(many.lo < 10.0 && 10.0 < many.hi, "{many:?}");
        assert!(median_interval(&[4.0]).lo.is_nan());
        assert!(median_interval(&[]).median.is_nan());
        assert!(median_interval(&[1.0, f64::NAN, 2.0]).lo.is_nan());
        assert_eq!(
            median_interval(&[2.0; 6]),
            Estimate {
                median: 2.0,
                lo: 2.0,
                hi: 2.0
            }
        );
    }

    /// A drift within rounds (each visit slower than the last) ranks no two identical units:
    /// the reversed rounds put each pair on both sides.
    #[test]
    fn a_drift_within_rounds_ranks_nothing() {
        let s = Schedule {
            seed: 3,
            warmup: 0,
            repeats: 6,
        };
        let mut clock = 0.0;
        let times = s
            .run(9, |_| {
                clock += 1.0;
                Ok::<_, ()>(100.0 + clock)
            })
            .unwrap();
        for a in &times {
            for b in &times {
                let r = paired_ratio(a, b);
                assert!(r.lo <= 1.0 && r.hi >= 1.0, "{r:?}");
            }
        }
    }

    /// Paired by round, a drift shared by both units cancels; unpaired it would swamp a 10 %
    /// difference.
    #[test]
    fn pairing_by_round_cancels_shared_drift() {
        let drift: Vec<f64> = (0..9).map(|r| 1.0 + 0.5 * r as f64).collect();
        let a: Vec<f64> = drift.iter().map(|d| 0.9 * d).collect();
        let ratio = paired_ratio(&a, &drift);
        assert_eq!(Comparison::of(&ratio), Comparison::Faster, "{ratio:?}");
        assert!((ratio.median - 0.9).abs() < 1e-12);
        let spread = median_interval(&a);
        assert!(spread.hi / spread.lo > 1.5, "unpaired, the drift dominates: {spread:?}");
    }
}
