//! The one rule turning the interval of a time ratio into words, and how the numbers behind a
//! word are printed so that they read on the side of the threshold that decided it.

use super::estimate::Estimate;
use serde::{Deserialize, Serialize};

/// The rule, as every report states it.
pub const RULE: &str = "Every time is a median with its distribution-free 95 % interval (order statistics of its \
repeats, visited in seeded, counterbalanced interleaved rounds). A ratio A / B (of times: the median of per-round \
ratios; over frames, of per-frame ratios, its interval from order statistics where each frame's camera is an \
independent draw, from the medians of blocks of frames longer than their correlation along a camera path) gets \
one of three words from its 95 % interval and a margin of 5 %: *faster* (or *better*, of errors) when the whole \
interval lies below 1 / 1.05, *slower* (*worse*) when it lies above 1.05, *equivalent* when it lies wholly \
inside [1 / 1.05, 1.05] (two one-sided tests at the margin), and *undecided* otherwise. A direction is never \
given to a difference the interval cannot place beyond the margin, and an interval reaching past the margin is \
never called equivalent; a paper's claim that A is faster is answered yes, no or undecided by the same words.";

/// Equivalence margin of the rule: a ratio's interval inside [1 / (1 + MARGIN), 1 + MARGIN] is
/// *equivalent*; a direction needs the whole interval beyond it.
pub const MARGIN: f64 = 0.05;

/// The band of ratios the rule calls equivalent: [1 / (1 + [`MARGIN`]), 1 + [`MARGIN`]],
/// symmetric in log ratio so that A / B and B / A get mirrored words.
pub fn band() -> (f64, f64) {
    (1.0 / (1.0 + MARGIN), 1.0 + MARGIN)
}

/// How close (relative) a bound may come to a threshold of the rule before it is printed with
/// more decimals ([`Estimate::show_ratio`]).
pub const NEAR_THRESHOLD: f64 = 0.01;

/// Most decimals a bound is printed with.
pub const MAX_DIGITS: usize = 6;

impl Estimate {
    /// A ratio A / B as [`show`](Self::show) prints it, with as many more decimals as it takes
    /// for every bound near the rule's thresholds (the ends of [`band`]) to read on the side of
    /// it that decided the word: `0.9520`, not `0.95`, for a bound that did not clear 1 / 1.05.
    /// The band is symmetric in log ratio, so a speed-up (the reciprocal) prints the same way.
    pub fn show_ratio(&self, digits: usize) -> String {
        let (lo, hi) = band();
        self.show(self.deciding_digits(digits, &[lo, hi]))
    }

    /// A speed-up B / A, the reciprocal of a time ratio, printed as [`show_ratio`](Self::show_ratio)
    /// prints one (1.05 is the least speed-up called faster, so a bound of 1.045 is printed so).
    pub fn show_speedup(&self, digits: usize) -> String {
        self.show_ratio(digits)
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

/// What the interval of a ratio A / B (of times, or of errors) says of A against B ([`RULE`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Comparison {
    /// The whole interval lies below the equivalence band: A takes less (time or error).
    Faster,
    /// The whole interval lies above the band.
    Slower,
    /// The whole interval lies inside the band.
    Equivalent,
    /// The interval reaches past the band on one side without clearing it, or none could be
    /// formed.
    Undecided,
}

impl Comparison {
    /// Every word, in the order tallies list them.
    pub const ALL: [Comparison; 4] = [
        Comparison::Faster,
        Comparison::Slower,
        Comparison::Equivalent,
        Comparison::Undecided,
    ];

    /// The word for a ratio A / B with its interval ([`RULE`]).
    pub fn of(ratio: &Estimate) -> Comparison {
        let (lo, hi) = band();
        if !(ratio.lo.is_finite() && ratio.hi.is_finite()) {
            Comparison::Undecided
        } else if ratio.hi < lo {
            Comparison::Faster
        } else if ratio.lo > hi {
            Comparison::Slower
        } else if ratio.lo >= lo && ratio.hi <= hi {
            Comparison::Equivalent
        } else {
            Comparison::Undecided
        }
    }

    /// The word for a speed-up B / A (above 1: A faster) with its interval.
    pub fn of_speedup(speedup: &Estimate) -> Comparison {
        Comparison::of(&speedup.recip())
    }

    /// Whether the word is final: a direction or equivalence, not undecided.
    pub fn decided(self) -> bool {
        self != Comparison::Undecided
    }

    /// `faster`, `slower`, `equivalent`, `undecided`: the word for a time ratio.
    pub fn word(self) -> &'static str {
        match self {
            Comparison::Faster => "faster",
            Comparison::Slower => "slower",
            Comparison::Equivalent => "equivalent",
            Comparison::Undecided => "undecided",
        }
    }

    /// `better`, `worse`, `equivalent`, `undecided`: the word for a ratio of errors (less is
    /// better).
    pub fn error_word(self) -> &'static str {
        match self {
            Comparison::Faster => "better",
            Comparison::Slower => "worse",
            other => other.word(),
        }
    }

    /// The answer to the claim "A is faster than B": `yes`, `no`, `no (equivalent)`,
    /// `undecided`.
    pub fn answer(self) -> &'static str {
        match self {
            Comparison::Faster => "yes",
            Comparison::Slower => "no",
            Comparison::Equivalent => "no (equivalent)",
            Comparison::Undecided => "undecided",
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
    /// most 1 - coverage(n) of seeded trials before the margin and given a direction in at most
    /// 1 % with it; times 20 % apart with 5 % noise read "faster" in every trial; 3 % apart with
    /// 0.5 % noise, "equivalent" (inside the margin, though the interval excludes 1); 10 % apart
    /// are never called equivalent.
    #[test]
    fn identical_read_undecided_or_equivalent_and_separated_read_faster() {
        let trials = 1500u32;
        for n in 5..=15usize {
            let (mut differ, mut words, mut words_bimodal, mut faster, mut close, mut false_equivalent) =
                (0, 0, 0, 0, 0, 0);
            for t in 0..trials {
                let k = 17 * n as u32 + 7919 * t;
                let (a, b) = (draws(k, n, 50.0, 0.1), draws(k + 1, n, 50.0, 0.1));
                let r = paired_ratio(&a, &b);
                differ += (r.hi < 1.0 || r.lo > 1.0) as u32;
                let direction = |c: Comparison| matches!(c, Comparison::Faster | Comparison::Slower);
                words += direction(Comparison::of(&r)) as u32;
                let (x, y) = (bimodal(k + 2, n), bimodal(k + 3, n));
                words_bimodal += direction(Comparison::of(&paired_ratio(&x, &y))) as u32;
                let c = draws(k + 4, n, 40.0, 0.05);
                let b5 = draws(k + 5, n, 50.0, 0.05);
                faster += (Comparison::of(&paired_ratio(&c, &b5)) == Comparison::Faster) as u32;
                let (d, e) = (draws(k + 6, n, 48.5, 0.005), draws(k + 7, n, 50.0, 0.005));
                close += (Comparison::of(&paired_ratio(&d, &e)) == Comparison::Equivalent) as u32;
                let (f, g) = (draws(k + 8, n, 55.0, 0.1), draws(k + 9, n, 50.0, 0.1));
                false_equivalent += (Comparison::of(&paired_ratio(&f, &g)) == Comparison::Equivalent) as u32;
            }
            let share = |k: u32| k as f64 / trials as f64;
            eprintln!(
                "n = {n}: identical differ in {:.4} (coverage {:.4}), get a direction in {:.4} (two modes: {:.4}); 10 % apart equivalent in {:.4}",
                share(differ),
                coverage(n),
                share(words),
                share(words_bimodal),
                share(false_equivalent)
            );
            assert!(share(differ) <= 1.0 - coverage(n) + 0.02, "n = {n}: {}", share(differ));
            assert!(share(words) <= 0.01, "n = {n}: {}", share(words));
            assert!(share(words_bimodal) <= 0.01, "n = {n}: {}", share(words_bimodal));
            assert!(share(false_equivalent) <= 0.01, "n = {n}: {}", share(false_equivalent));
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
        assert_eq!(Comparison::of(&e(0.9, 1.1)), Comparison::Undecided);
        assert_eq!(
            Comparison::of(&e(0.96, 0.99)),
            Comparison::Equivalent,
            "inside the margin"
        );
        assert_eq!(Comparison::of(&e(0.96, 1.04)), Comparison::Equivalent);
        assert_eq!(
            Comparison::of(&e(0.94, 0.98)),
            Comparison::Undecided,
            "wholly below 1 but not beyond the margin: never equal"
        );
        assert_eq!(
            Comparison::of(&e(0.951, 0.97)),
            Comparison::Undecided,
            "0.951 < 1 / 1.05"
        );
        assert_eq!(Comparison::of(&e(1.02, 1.06)), Comparison::Undecided);
        assert_eq!(Comparison::of(&Estimate::NAN), Comparison::Undecided);
        assert_eq!(Comparison::of_speedup(&e(1.1, 1.3)), Comparison::Faster);
        // Mirrored: B / A gets the mirrored word.
        for (lo, hi) in [(0.8, 0.94), (0.96, 0.99), (0.94, 0.98), (1.06, 1.2)] {
            let (a, b) = (Comparison::of(&e(lo, hi)), Comparison::of(&e(1.0 / hi, 1.0 / lo)));
            let mirrored = match a {
                Comparison::Faster => Comparison::Slower,
                Comparison::Slower => Comparison::Faster,
                same => same,
            };
            assert_eq!(b, mirrored, "[{lo}, {hi}]");
        }
        assert_eq!(Comparison::Faster.answer(), "yes");
        assert_eq!(Comparison::Slower.answer(), "no");
        assert_eq!(Comparison::Undecided.answer(), "undecided");
        assert_eq!(Comparison::Faster.error_word(), "better");
        assert_eq!(Comparison::Equivalent.error_word(), "equivalent");
        assert_eq!(e(1.0, 3.0).show(2), "2.00 [1.00, 3.00]");
        assert_eq!(e(2.0, 4.0).recip().show(2), "0.33 [0.25, 0.50]");
    }

    /// The cases that read wrong at two decimals: a speed-up whose lower bound 1.045 fell short
    /// of 1.05 (undecided), a time ratio whose upper bound 0.9522 cleared 1 / 1.05 =
    /// 0.95238 (printed to four decimals, where three would read 0.952), one whose 0.9525 did not
    /// (0.953 reads on its side at three); bounds far from any threshold keep their digits.
    #[test]
    fn intervals_print_the_digits_that_decide_their_word() {
        let e = |median: f64, lo: f64, hi: f64| Estimate { median, lo, hi };
        assert_eq!(e(1.05, 1.045, 1.06).show_speedup(2), "1.050 [1.045, 1.060]");
        assert_eq!(Comparison::of_speedup(&e(1.05, 1.045, 1.06)), Comparison::Undecided);
        assert_eq!(e(0.94, 0.91, 0.9522).show_ratio(2), "0.9400 [0.9100, 0.9522]");
        assert_eq!(Comparison::of(&e(0.94, 0.91, 0.9522)), Comparison::Faster);
        assert_eq!(e(0.94, 0.91, 0.9525).show_ratio(2), "0.940 [0.910, 0.953]");
        assert_eq!(Comparison::of(&e(0.94, 0.91, 0.9525)), Comparison::Undecided);
        assert_eq!(e(2.0, 1.5, 3.0).show_speedup(2), "2.00 [1.50, 3.00]");
        assert_eq!(e(1.0, 0.8, 1.2).show_ratio(2), "1.00 [0.80, 1.20]");
        assert_eq!(Estimate::NAN.show_ratio(2), "n/a");
    }
}
