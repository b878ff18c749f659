//! Summary statistics: means over seeds with 95 % Student-t confidence intervals; medians and
//! quartiles of repeated timings.

/// Two-sided 97.5 % quantiles of Student's t for 1..=30 degrees of freedom.
const T975: [f64; 30] = [
    12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160, 2.145, 2.131, 2.120,
    2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042,
];

/// t quantile for a 95 % two-sided interval; the normal 1.96 beyond 30 degrees of freedom.
pub fn t975(dof: usize) -> f64 {
    match dof {
        0 => f64::NAN,
        d if d <= 30 => T975[d - 1],
        _ => 1.96,
    }
}

/// A mean and the half-width of its 95 % confidence interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeanCi {
    /// The mean.
    pub mean: f64,
    /// Half-width of its 95 % interval.
    pub ci95: f64,
}

impl MeanCi {
    /// Neither known.
    pub const NAN: MeanCi = MeanCi {
        mean: f64::NAN,
        ci95: f64::NAN,
    };
}

/// Fewest values a mean's interval is given from: with two or three, t(0.975) is 12.7 or 4.3
/// and the spread of so few values is itself a guess, so two seeds that happen to agree would
/// print a tight interval ("0.0257 +- 0.0000").
pub const MIN_VALUES_FOR_INTERVAL: usize = 4;

/// Mean and the half-width of its 95 % confidence interval, mean +- t s / sqrt(k); the
/// half-width is NaN with fewer than [`MIN_VALUES_FOR_INTERVAL`] values. One NaN value (a seed whose metric is not
/// measurable, e.g. an extent beyond the patch) makes both NaN: a mean over fewer seeds than the
/// row claims would be another statistic.
pub fn mean_ci(v: &[f64]) -> MeanCi {
    let k = v.len();
    if k == 0 || v.iter().any(|x| x.is_nan()) {
        return MeanCi::NAN;
    }
    let mean = v.iter().sum::<f64>() / k as f64;
    if k < MIN_VALUES_FOR_INTERVAL {
        return MeanCi { mean, ci95: f64::NAN };
    }
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (k - 1) as f64;
    MeanCi {
        mean,
        ci95: t975(k - 1) * (var / k as f64).sqrt(),
    }
}

/// Median (mean of the middle two for an even count); NaN when empty.
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// First quartile, median and third quartile (linear interpolation between order statistics,
/// Hyndman & Fan's type 7, as R and numpy default to); NaN when empty.
pub fn quartiles(values: &[f64]) -> (f64, f64, f64) {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let q = |p: f64| {
        if v.is_empty() {
            return f64::NAN;
        }
        let h = p * (v.len() - 1) as f64;
        let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
        v[lo] + (h - lo as f64) * (v[hi] - v[lo])
    };
    (q(0.25), q(0.5), q(0.75))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ci_of_known_sample() {
        let MeanCi { mean, ci95 } = mean_ci(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(mean, 2.5);
        // s = sqrt(5/3), t(3) = 3.182: h = 3.182 * sqrt(5/12).
        assert!((ci95 - 3.182 * (5.0f64 / 12.0).sqrt()).abs() < 1e-12);
        assert!(mean_ci(&[1.0]).ci95.is_nan());
        assert!(mean_ci(&[1.0, 2.0, 3.0]).ci95.is_nan(), "three values give no interval");
        assert_eq!(mean_ci(&[1.0, 2.0, 3.0]).mean, 2.0);
        let MeanCi { mean, ci95 } = mean_ci(&[f64::NAN, 2.0, 4.0]);
        assert!(mean.is_nan() && ci95.is_nan());
    }

    #[test]
    fn medians() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan());
    }

    #[test]
    fn quartiles_of_known_samples() {
        assert_eq!(quartiles(&[5.0, 1.0, 3.0, 2.0, 4.0]), (2.0, 3.0, 4.0));
        // numpy.percentile([1, 2, 3, 4], [25, 50, 75]) = 1.75, 2.5, 3.25.
        assert_eq!(quartiles(&[4.0, 1.0, 2.0, 3.0]), (1.75, 2.5, 3.25));
        assert_eq!(quartiles(&[7.0]), (7.0, 7.0, 7.0));
        assert!(quartiles(&[]).1.is_nan());
    }
}
