//! The one rule turning the interval of a time ratio into words, and how the numbers behind a
//! word are printed so that they read on the side of the threshold that decided it.

use super::estimate::Estimate;
use serde::{Deserialize, Serialize};

/// The rule, as every report states it.
pub const RULE: &str = "Every time is a median with its distribution-free 95 % interval (order statistics of its \
repeats, visited in seeded, counterbalanced interleaved rounds). A is called faster than B only when the whole \
95 % interval of the time ratio A / B (the median of per-round ratios; over frames, of per-frame ratios, its \
interval from order statistics where each frame's camera is an independent draw, from the medians of blocks of \
frames longer than their correlation along a camera path) lies below 0.95, \
slower when it lies above 1.05, and equal within noise otherwise (a difference under 5 % is never called); a \
paper's claim that A is faster is answered yes, no or not clearly by the same interval.";

/// Smallest relative difference a word is given: a time ratio's interval must clear 1 by it.
pub const MARGIN: f64 = 0.05;

/// How close (relative) a bound may come to a threshold of the rule before it is printed with
/// more decimals ([`Estimate::show_ratio`]).
pub const NEAR_THRESHOLD: f64 = 0.01;

/// Most decimals a bound is printed with.
pub const MAX_DIGITS: usize = 6;

impl Estimate {
    /// A time ratio A / B as [`show`](Self::show) prints it, with as many more decimals as it
    /// takes for every bound near the rule's thresholds (1 -/+ [`MARGIN`]) to read on the side
    /// of it that decided the word: `0.946`, not `0.95`, for a bound that did not clear 0.95.
    pub fn show_ratio(&self, digits: usize) -> String {
        self.show(self.deciding_digits(digits, &[1.0 - MARGIN, 1.0 + MARGIN]))
    }

    /// A speed-up B / A, the reciprocal of a time ratio, printed as [`show_ratio`](Self::show_ratio)
    /// prints one: its thresholds are 1 / (1 +/- [`MARGIN`]) (1.0526 is the least speed-up called
    /// faster, so a bound of 1.045 is printed so, never as 1.05).
    pub fn show_speedup(&self, digits: usize) -> String {
        self.show(self.deciding_digits(digits, &[1.0 / (1.0 + MARGIN), 1.0 / (1.0 - MARGIN)]))
    }

    /// The fewest decimals, at least `digits` and at most [`MAX_DIGITS`], at which no bound
    /// within [`NEAR_THRESHOLD`] of a threshold prints as the threshold or across it, and every
    /// such bound gets at least three.
    fn deciding_digits(&self, digits: usize, thresholds: &[f64]) -> usize {
        let round = |v: f64, d: usize| format!("{v:.d$}").parse::<f64>().unwrap_or(v);
        let near: Vec<(f64, f64)> = [self.lo, self.hi]
            .into_iter()
            .filter(|v| v.is_finite())
            .flat_map(|v| thresholds.iter().map(move |&t| (v, t)))
            .filter(|&(v, t)| ((v - t) / t).abs() <= NEAR_THRESHOLD)
            .collect();
        if near.is_empty() {
            return digits;
        }
        let mut d = digits.max(3);
        while d < MAX_DIGITS
            && near.iter().any(|&(v, t)| {
                let (rv, rt) = (round(v, d), round(t, d));
                rv == rt || (rv - t).signum() != (v - t).signum()
            })
        {
            d += 1;
        }
        d
    }
}

/// What the interval of a time ratio A / B says of A against B.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Comparison {
    /// The whole interval lies below 1.
    Faster,
    /// The whole interval lies above 1.
    Slower,
    /// The interval holds 1, or none could be formed.
    Equal,
}

impl Comparison {
    /// The word for a time ratio A / B with its interval ([`RULE`]).
    pub fn of(time_ratio: &Estimate) -> Comparison {
        if time_ratio.hi < 1.0 - MARGIN {
            Comparison::Faster
        } else if time_ratio.lo > 1.0 + MARGIN {
            Comparison::Slower
        } else {
            Comparison::Equal
        }
    }

    /// The word for a speed-up B / A (above 1: A faster) with its interval.
    pub fn of_speedup(speedup: &Estimate) -> Comparison {
        Comparison::of(&speedup.recip())
    }

    /// `faster`, `slower`, `equal within noise`.
    pub fn word(self) -> &'static str {
        match self {
            Comparison::Faster => "faster",
            Comparison::Slower => "slower",
            Comparison::Equal => "equal within noise",
        }
    }

    /// The answer to the claim "A is faster than B": `yes`, `no`, `not clearly`.
    pub fn answer(self) -> &'static str {
        match self {
            Comparison::Faster => "yes",
            Comparison::Slower => "no",
            Comparison::Equal => "not clearly",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::draws;
    use super::*;
    use crate::sampling::Stream;
    use crate::timing::interval::{coverage, paired_ratio};

    /// Two modes at random, as lavapipe's frames: 15 or 29 ms, each half the time, with 2 %
    /// jitter.
    fn bimodal(stream: u32, n: usize) -> Vec<f64> {
        let s = Stream::new(stream, 1, None);
        (0..n as u32)
            .map(|i| if s.unit(2 * i) < 0.5 { 15.0 } else { 29.0 } * (1.0 + 0.02 * (s.unit(2 * i + 1) - 0.5)))
            .collect()
    }

    /// The rule on synthetic timings, at every number of rounds from 5 to 15: identical
    /// distributions (normal-ish with 10 % spread, or two modes) are called different in at
    /// most 1 - coverage(n) of seeded trials before the margin and in at most 1 % with it;
    /// times 20 % apart with 5 % noise read "faster" in every trial; 3 % apart, "equal" (below
    /// the margin).
    #[test]
    fn identical_read_equal_and_separated_read_faster() {
        let trials = 1500u32;
        for n in 5..=15usize {
            let (mut differ, mut words, mut words_bimodal, mut faster, mut close) = (0, 0, 0, 0, 0);
            for t in 0..trials {
                let k = 17 * n as u32 + 7919 * t;
                let (a, b) = (draws(k, n, 50.0, 0.1), draws(k + 1, n, 50.0, 0.1));
                let r = paired_ratio(&a, &b);
                differ += (r.hi < 1.0 || r.lo > 1.0) as u32;
                words += (Comparison::of(&r) != Comparison::Equal) as u32;
                let (x, y) = (bimodal(k + 2, n), bimodal(k + 3, n));
                words_bimodal += (Comparison::of(&paired_ratio(&x, &y)) != Comparison::Equal) as u32;
                let c = draws(k + 4, n, 40.0, 0.05);
                let b5 = draws(k + 5, n, 50.0, 0.05);
                faster += (Comparison::of(&paired_ratio(&c, &b5)) == Comparison::Faster) as u32;
                let (d, e) = (draws(k + 6, n, 48.5, 0.005), draws(k + 7, n, 50.0, 0.005));
                close += (Comparison::of(&paired_ratio(&d, &e)) == Comparison::Equal) as u32;
            }
            let share = |k: u32| k as f64 / trials as f64;
            eprintln!(
                "n = {n}: identical differ in {:.4} (coverage {:.4}), get a word in {:.4} (two modes: {:.4})",
                share(differ),
                coverage(n),
                share(words),
                share(words_bimodal)
            );
            assert!(share(differ) <= 1.0 - coverage(n) + 0.02, "n = {n}: {}", share(differ));
            assert!(share(words) <= 0.01, "n = {n}: {}", share(words));
            assert!(share(words_bimodal) <= 0.01, "n = {n}: {}", share(words_bimodal));
            assert_eq!(faster, trials, "n = {n}");
            assert_eq!(close, trials, "n = {n}");
        }
    }

    #[test]
    fn words_follow_the_interval() {
        let e = |lo, hi| Estimate {
            median: 0.5 * (lo + hi),
            lo,
            hi,
        };
        assert_eq!(Comparison::of(&e(0.8, 0.94)), Comparison::Faster);
        assert_eq!(Comparison::of(&e(1.06, 1.2)), Comparison::Slower);
        assert_eq!(Comparison::of(&e(0.9, 1.1)), Comparison::Equal);
        assert_eq!(Comparison::of(&e(0.96, 0.99)), Comparison::Equal, "under the margin");
        assert_eq!(Comparison::of(&e(1.01, 1.04)), Comparison::Equal, "under the margin");
        assert_eq!(Comparison::of(&Estimate::NAN), Comparison::Equal);
        assert_eq!(Comparison::of_speedup(&e(1.1, 1.3)), Comparison::Faster);
        assert_eq!(Comparison::Faster.answer(), "yes");
        assert_eq!(Comparison::Slower.answer(), "no");
        assert_eq!(Comparison::Equal.answer(), "not clearly");
        assert_eq!(e(1.0, 3.0).show(2), "2.00 [1.00, 3.00]");
        assert_eq!(e(2.0, 4.0).recip().show(2), "0.33 [0.25, 0.50]");
    }

    /// The cases that read wrong at two decimals: a speed-up whose lower bound 1.0450 fell short
    /// of 1.0526 (equal), a time ratio whose upper bound 0.9462 cleared 0.95 (faster), a bound
    /// on the threshold to the fourth decimal; bounds far from any threshold keep their digits.
    #[test]
    fn intervals_print_the_digits_that_decide_their_word() {
        let e = |median: f64, lo: f64, hi: f64| Estimate { median, lo, hi };
        assert_eq!(e(1.05, 1.045, 1.06).show_speedup(2), "1.050 [1.045, 1.060]");
        assert_eq!(Comparison::of_speedup(&e(1.05, 1.045, 1.06)), Comparison::Equal);
        assert_eq!(e(0.94, 0.91, 0.9462).show_ratio(2), "0.940 [0.910, 0.946]");
        assert_eq!(Comparison::of(&e(0.94, 0.91, 0.9462)), Comparison::Faster);
        // 0.94996 clears 0.95: printed to the decimal that shows it.
        assert_eq!(e(0.9, 0.8, 0.94996).show_ratio(2), "0.90000 [0.80000, 0.94996]");
        assert_eq!(e(2.0, 1.5, 3.0).show_speedup(2), "2.00 [1.50, 3.00]");
        assert_eq!(e(1.0, 0.8, 1.2).show_ratio(2), "1.00 [0.80, 1.20]");
        assert_eq!(Estimate::NAN.show_ratio(2), "n/a");
    }
}
