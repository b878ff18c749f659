//! How numbers read in a report: never NaN; a missing value or interval reads "n/a", never 0;
//! a squared bias is a value with its interval, "0 within noise" where the interval holds 0.

use crate::metrics::BiasVariance;

/// `f(x)`, or "n/a" for a non-finite value.
pub fn or_na(x: f64, f: impl Fn(f64) -> String) -> String {
    if x.is_finite() {
        f(x)
    } else {
        "n/a".into()
    }
}

/// "mean ± half-width" in the same format, "mean ± n/a" without an interval, "n/a" without a mean.
pub fn with_ci(mean: f64, ci: f64, f: impl Fn(f64) -> String) -> String {
    if !mean.is_finite() {
        return "n/a".into();
    }
    format!("{} ± {}", f(mean), or_na(ci, &f))
}

/// A squared bias with its 95 % interval: "0 within noise (-6.5e-5 ± 1.2e-4)" where the interval
/// holds 0, else "7.5e-4 ± 1.1e-4"; with two seeds the value and why it has no interval; "n/a"
/// with fewer.
pub fn bias2(split: &BiasVariance) -> String {
    let e = |x: f64| format!("{x:.2e}");
    if !split.bias2.is_finite() {
        return "n/a".into();
    }
    if !split.bias2_ci.is_finite() {
        // Two seeds: a value, but no interval to read it against; the unbiased estimator can
        // fall below zero, which would otherwise read as a wrong number.
        return format!(
            "{} (no interval below 3 seeds; the unbiased estimator can be negative)",
            e(split.bias2)
        );
    }
    let text = with_ci(split.bias2, split.bias2_ci, e);
    if split.zero_within_noise() {
        format!("0 within noise ({text})")
    } else {
        text
    }
}

/// A count with thin spaces between its thousands (`12 345`), for titles and axis notes.
pub fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push('\u{2009}');
        }
        out.push(c);
    }
    out
}

/// Bytes per triangle of a structure, the figure that compares structures across scene sizes
/// (a CWBVH's ~12 B against a field's kilobytes): three significant digits, "n/a" for no
/// triangles.
pub fn per_triangle(bytes: u64, triangles: usize) -> String {
    if triangles == 0 {
        return "n/a".into();
    }
    let b = bytes as f64 / triangles as f64;
    match b {
        b if b >= 100.0 => thousands(b.round() as usize),
        b if b >= 10.0 => format!("{b:.1}"),
        b => format!("{b:.2}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn split(bias2: f64, bias2_ci: f64) -> BiasVariance {
        BiasVariance {
            seeds: 4,
            bias2,
            bias2_ci,
            variance: 1e-3,
        }
    }

    #[test]
    fn missing_numbers_read_na_never_nan_or_zero() {
        let mm = |x: f64| format!("{:.2} mm", x * 1e3);
        assert_eq!(with_ci(0.014, f64::NAN, mm), "14.00 mm ± n/a");
        assert_eq!(with_ci(f64::NAN, 0.001, mm), "n/a");
        assert_eq!(with_ci(0.014, 0.0004, mm), "14.00 mm ± 0.40 mm");
        assert_eq!(per_triangle(6_455_044_812, 1_024_000), "6\u{2009}304");
        assert_eq!(per_triangle(14_780_480, 1_024_000), "14.4");
        assert_eq!(per_triangle(1, 3), "0.33");
        assert_eq!(per_triangle(5, 0), "n/a");
        assert_eq!(or_na(f64::INFINITY, |x| x.to_string()), "n/a");
    }

    #[test]
    fn thousands_are_set_apart() {
        assert_eq!(thousands(7), "7");
        assert_eq!(thousands(5804), "5\u{2009}804");
        assert_eq!(thousands(1_234_567), "1\u{2009}234\u{2009}567");
    }

    #[test]
    fn squared_bias_reads_with_its_interval() {
        assert_eq!(bias2(&split(-6.47e-5, 1.2e-4)), "0 within noise (-6.47e-5 ± 1.20e-4)");
        assert_eq!(bias2(&split(7.5e-4, 1.1e-4)), "7.50e-4 ± 1.10e-4");
        assert_eq!(
            bias2(&split(-4.61e-5, f64::NAN)),
            "-4.61e-5 (no interval below 3 seeds; the unbiased estimator can be negative)"
        );
        assert_eq!(bias2(&split(f64::NAN, f64::NAN)), "n/a");
    }
}
