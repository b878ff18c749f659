//! The one way every experiment kind times what it compares, and the one rule that turns times
//! into words.
//!
//! **Design.** The units compared (configurations, structures, frames) are visited in `repeats`
//! interleaved rounds; each even round visits them in a fresh order drawn from a recorded seed
//! and the odd round after it in the reverse order (counterbalanced, ABBA), so a slow drift of
//! the machine (clocks, other load), across rounds or within one, falls on every unit alike
//! instead of on whichever ran first. Each visit renders `warmup` untimed frames, then times one.
//!
//! **Estimates.** Every reported time is a median with a 95 % percentile-bootstrap interval over
//! its repeats ([`Estimate`], [`median_interval`]). Two units visited in the same rounds are
//! compared by the median of their per-round time ratios, bootstrapped over rounds
//! ([`paired_ratio`]): pairing by round cancels drift that a round shares. A ratio over a
//! series of correlated units (consecutive frames of a camera path) is bootstrapped in moving
//! blocks whose length the series' own autocorrelation sets ([`series_median`]).
//!
//! **Words.** [`Comparison::of`] reads the 95 % interval of a time ratio A / B: *faster* when the
//! whole interval lies below 1, *slower* when it lies above 1, *equal within noise* otherwise;
//! a claim "A is faster than B" is answered *yes*, *no* or *not clearly* by the same interval.
//! [`RULE`] says so in every report.

use crate::metrics::stats::median;
use crate::sampling::rng::pcg;
use serde::{Deserialize, Serialize};

/// The rule, as every report states it.
pub const RULE: &str = "Every time is a median with its 95 % bootstrap interval over repeats visited in seeded \
interleaved rounds. A is called faster than B only when the whole 95 % interval of the time ratio A / B \
(the median of per-round ratios, bootstrapped over rounds; over frames in moving blocks) lies below 1, \
slower when it lies above 1, and equal within noise otherwise; a paper's claim that A is faster is \
answered yes, no or not clearly by the same interval.";

/// Bootstrap resamples behind every interval.
pub const RESAMPLES: u32 = 2000;

/// Default seed of the visiting order, where an experiment file gives none (recorded in the
/// manifest either way).
pub const DEFAULT_SEED: u32 = 0x510e_527f;

/// How an experiment's timed units are visited.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Schedule {
    /// Seed of the visiting order and of the bootstrap.
    pub seed: u32,
    /// Untimed frames right before each timed one.
    pub warmup: u32,
    /// Interleaved rounds: timed frames per unit.
    pub repeats: u32,
}

impl Schedule {
    /// The order in which round `round` visits `n` units: for an even round a Fisher-Yates
    /// shuffle over a counter-based stream of the seed (the same for the same seed on every
    /// machine), for an odd round the reverse of the round before.
    pub fn order(&self, n: usize, round: u32) -> Vec<usize> {
        if round % 2 == 1 {
            let mut v = self.order(n, round - 1);
            v.reverse();
            return v;
        }
        let mut v: Vec<usize> = (0..n).collect();
        let stream = pcg(self.seed ^ pcg(round));
        for i in (1..n).rev() {
            let j = pcg(stream ^ pcg(i as u32)) as usize % (i + 1);
            v.swap(i, j);
        }
        v
    }

    /// Times `n` units over every round: `visit(unit)` renders the unit's warm-up frames and
    /// returns the seconds of its timed frame. The result holds, per unit, one time per round
    /// in round order (so units are paired by round).
    pub fn run<E>(&self, n: usize, mut visit: impl FnMut(usize) -> Result<f64, E>) -> Result<Vec<Vec<f64>>, E> {
        let mut out = vec![Vec::with_capacity(self.repeats as usize); n];
        for round in 0..self.repeats {
            for unit in self.order(n, round) {
                out[unit].push(visit(unit)?);
            }
        }
        Ok(out)
    }
}

/// A median and its 95 % interval; all NaN when nothing was timed, the interval NaN when one
/// value cannot give one.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// The median.
    pub median: f64,
    /// Lower end of the 95 % interval.
    pub lo: f64,
    /// Upper end of the 95 % interval.
    pub hi: f64,
}

impl Estimate {
    /// Nothing measured.
    pub const NAN: Estimate = Estimate {
        median: f64::NAN,
        lo: f64::NAN,
        hi: f64::NAN,
    };

    /// Every value scaled by `k` (seconds to milliseconds; rays to rays per second...).
    pub fn scaled(self, k: f64) -> Estimate {
        let (a, b) = (self.lo * k, self.hi * k);
        Estimate {
            median: self.median * k,
            lo: a.min(b),
            hi: a.max(b),
        }
    }

    /// The reciprocal (a time ratio as a speed-up), its interval's ends swapped.
    pub fn recip(self) -> Estimate {
        Estimate {
            median: 1.0 / self.median,
            lo: 1.0 / self.hi,
            hi: 1.0 / self.lo,
        }
    }

    /// `1.23 [1.10, 1.41]` with `digits` decimals.
    pub fn show(&self, digits: usize) -> String {
        if self.median.is_nan() {
            return "n/a".into();
        }
        if self.lo.is_nan() {
            return format!("{:.digits$} [n/a]", self.median);
        }
        format!("{:.digits$} [{:.digits$}, {:.digits$}]", self.median, self.lo, self.hi)
    }
}

/// The 2.5 % and 97.5 % percentiles of `stats` (sorted in place).
fn percentiles(stats: &mut [f64]) -> (f64, f64) {
    stats.sort_by(f64::total_cmp);
    let at = |p: f64| stats[((p * stats.len() as f64) as usize).min(stats.len() - 1)];
    (at(0.025), at(0.975))
}

/// Index `k` of a bootstrap draw from `n` values in resample `b`.
fn draw(seed: u32, b: u32, k: usize, n: usize) -> usize {
    pcg(pcg(seed ^ pcg(b)) ^ pcg(k as u32 ^ 0x2545_f491)) as usize % n
}

/// Median of `values` with its 95 % percentile-bootstrap interval (resampled with replacement,
/// [`RESAMPLES`] times, seeded).
pub fn median_interval(values: &[f64], seed: u32) -> Estimate {
    bootstrap(values, seed, 1)
}

/// Median of the per-round ratios `a[i] / b[i]` (units visited in the same rounds) with its 95 %
/// interval, rounds resampled together.
pub fn paired_ratio(a: &[f64], b: &[f64], seed: u32) -> Estimate {
    assert_eq!(a.len(), b.len(), "paired units share their rounds");
    let ratios: Vec<f64> = a.iter().zip(b).map(|(x, y)| x / y).collect();
    bootstrap(&ratios, seed, 1)
}

/// Median of a series of correlated values (e.g. per-frame ratios along a camera path) with its
/// 95 % moving-block bootstrap interval, and the block length used: the first lag at which the
/// series' autocorrelation is no longer significant (|r| < 2 / sqrt(n)), at least n^(1/3), at most
/// n / 4.
pub fn series_median(values: &[f64], seed: u32) -> (Estimate, usize) {
    let block = block_length(values);
    (bootstrap(values, seed, block), block)
}

fn block_length(values: &[f64]) -> usize {
    let n = values.len();
    if n < 8 {
        return 1;
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    let var: f64 = values.iter().map(|v| (v - mean).powi(2)).sum();
    let floor = (n as f64).cbrt().ceil() as usize;
    if var == 0.0 {
        return floor;
    }
    let limit = (2.0 / (n as f64).sqrt(), n / 4);
    let acf = |lag: usize| {
        (0..n - lag)
            .map(|i| (values[i] - mean) * (values[i + lag] - mean))
            .sum::<f64>()
            / var
    };
    let first_insignificant = (1..=limit.1).find(|&lag| acf(lag).abs() < limit.0).unwrap_or(limit.1);
    first_insignificant.max(floor).min(limit.1.max(1))
}

/// Percentile bootstrap of the median, resampling blocks of `block` consecutive values.
fn bootstrap(values: &[f64], seed: u32, block: usize) -> Estimate {
    let n = values.len();
    let m = median(values);
    if n < 2 || values.iter().any(|v| !v.is_finite()) {
        return Estimate {
            median: m,
            lo: f64::NAN,
            hi: f64::NAN,
        };
    }
    let block = block.clamp(1, n);
    let starts = n - block + 1;
    let mut resample = Vec::with_capacity(n);
    let mut stats: Vec<f64> = (0..RESAMPLES)
        .map(|b| {
            resample.clear();
            let mut k = 0;
            while resample.len() < n {
                let s = draw(seed, b, k, starts);
                k += 1;
                resample.extend(values[s..s + block].iter().take(n - resample.len()));
            }
            median(&resample)
        })
        .collect();
    let (lo, hi) = percentiles(&mut stats);
    Estimate { median: m, lo, hi }
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
        if time_ratio.hi < 1.0 {
            Comparison::Faster
        } else if time_ratio.lo > 1.0 {
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
    use super::*;
    use crate::sampling::Stream;

    /// Roughly normal draws (sum of four uniforms) of mean `mean` and relative spread `rel`.
    fn draws(stream: u32, n: usize, mean: f64, rel: f64) -> Vec<f64> {
        let s = Stream::new(stream, 0, None);
        (0..n as u32)
            .map(|i| {
                let u: f64 = (0..4).map(|k| s.unit(4 * i + k)).sum();
                mean * (1.0 + rel * (u - 2.0))
            })
            .collect()
    }

    #[test]
    fn orders_are_seeded_permutations_that_differ_between_rounds() {
        let s = Schedule {
            seed: 7,
            warmup: 0,
            repeats: 5,
        };
        let rounds: Vec<Vec<usize>> = (0..5).map(|r| s.order(50, r)).collect();
        for o in &rounds {
            let mut sorted = o.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..50).collect::<Vec<_>>());
        }
        assert!(rounds.windows(2).all(|w| w[0] != w[1]));
        for pair in rounds.chunks(2).filter(|c| c.len() == 2) {
            assert!(
                pair[0].iter().eq(pair[1].iter().rev()),
                "odd rounds reverse the even ones"
            );
        }
        assert_ne!(rounds[0], rounds[2], "every even round draws afresh");
        assert_eq!(s.order(50, 3), rounds[3]);
        assert_ne!(Schedule { seed: 8, ..s }.order(50, 3), rounds[3], "the seed matters");
        let mut visits = Vec::new();
        let times = s
            .run(3, |u| {
                visits.push(u);
                Ok::<_, ()>(u as f64)
            })
            .unwrap();
        assert_eq!(visits.len(), 15);
        assert_eq!(times, vec![vec![0.0; 5], vec![1.0; 5], vec![2.0; 5]]);
    }

    #[test]
    fn intervals_hold_the_median_and_shrink_with_more_repeats() {
        let few = median_interval(&draws(1, 5, 10.0, 0.1), 3);
        let many = median_interval(&draws(2, 200, 10.0, 0.1), 3);
        for e in [few, many] {
            assert!(e.lo <= e.median && e.median <= e.hi, "{e:?}");
        }
        assert!(many.hi - many.lo < (few.hi - few.lo) / 2.0, "{few:?} {many:?}");
        assert!(many.lo < 10.0 && 10.0 < many.hi, "{many:?}");
        assert!(median_interval(&[4.0], 1).lo.is_nan());
        assert!(median_interval(&[], 1).median.is_nan());
        assert_eq!(
            median_interval(&[2.0; 6], 1),
            Estimate {
                median: 2.0,
                lo: 2.0,
                hi: 2.0
            }
        );
    }

    /// The rule on synthetic timings: identical distributions read "equal" in at least 90 % of
    /// seeded trials at 5 rounds (the percentile interval of a median of 5 is about [min, max]:
    /// wrong only when all five ratios fall on one side, 2 x 1/32); times 20 % apart with 5 %
    /// noise read "faster" in every trial.
    #[test]
    fn identical_read_equal_and_separated_read_faster() {
        let trials = 1000;
        let (mut equal, mut faster) = (0, 0);
        for t in 0..trials {
            let a = draws(10 + 3 * t, 5, 50.0, 0.05);
            let b = draws(11 + 3 * t, 5, 50.0, 0.05);
            equal += (Comparison::of(&paired_ratio(&a, &b, t)) == Comparison::Equal) as u32;
            let c = draws(12 + 3 * t, 5, 40.0, 0.05);
            faster += (Comparison::of(&paired_ratio(&c, &b, t)) == Comparison::Faster) as u32;
        }
        let equal = equal as f64 / trials as f64;
        eprintln!("identical read equal in {equal}; separated read faster in {faster}/{trials}");
        assert!(equal >= 0.9, "{equal}");
        assert_eq!(faster, trials);
    }

    /// A drift within rounds (each visit slower than the last) ranks no two identical units:
    /// the reversed rounds put each pair on both sides.
    #[test]
    fn a_drift_within_rounds_ranks_nothing() {
        let s = Schedule {
            seed: 3,
            warmup: 0,
            repeats: 5,
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
                let r = paired_ratio(a, b, 1);
                assert_eq!(Comparison::of(&r), Comparison::Equal, "{r:?}");
            }
        }
    }

    /// Paired by round, a drift shared by both units cancels; unpaired it would swamp a 5 %
    /// difference.
    #[test]
    fn pairing_by_round_cancels_shared_drift() {
        let drift: Vec<f64> = (0..9).map(|r| 1.0 + 0.5 * r as f64).collect();
        let a: Vec<f64> = drift.iter().map(|d| 0.95 * d).collect();
        let ratio = paired_ratio(&a, &drift, 5);
        assert_eq!(Comparison::of(&ratio), Comparison::Faster, "{ratio:?}");
        assert!((ratio.median - 0.95).abs() < 1e-12);
        let spread = median_interval(&a, 5);
        assert!(spread.hi / spread.lo > 1.5, "unpaired, the drift dominates: {spread:?}");
    }

    /// A slowly varying series is resampled in blocks: its interval is wider than the iid
    /// bootstrap's, which would claim a precision the correlated frames do not have.
    #[test]
    fn correlated_series_get_blocks_and_wider_intervals() {
        let n = 400;
        let noise = draws(40, n, 1.0, 0.02);
        let series: Vec<f64> = (0..n)
            .map(|i| 1.0 + 0.1 * (i as f64 / 40.0).sin() + noise[i] - 1.0)
            .collect();
        let (blocked, block) = series_median(&series, 9);
        let iid = median_interval(&series, 9);
        assert!(block >= 10, "block {block}");
        assert!(
            blocked.hi - blocked.lo > 1.5 * (iid.hi - iid.lo),
            "{blocked:?} vs {iid:?}"
        );
        let (_, white) = series_median(&draws(41, n, 1.0, 0.02), 9);
        assert!(white <= 10, "white noise block {white}");
    }

    #[test]
    fn words_follow_the_interval() {
        let e = |lo, hi| Estimate {
            median: 0.5 * (lo + hi),
            lo,
            hi,
        };
        assert_eq!(Comparison::of(&e(0.8, 0.95)), Comparison::Faster);
        assert_eq!(Comparison::of(&e(1.05, 1.2)), Comparison::Slower);
        assert_eq!(Comparison::of(&e(0.9, 1.1)), Comparison::Equal);
        assert_eq!(Comparison::of(&Estimate::NAN), Comparison::Equal);
        assert_eq!(Comparison::of_speedup(&e(1.1, 1.3)), Comparison::Faster);
        assert_eq!(Comparison::Faster.answer(), "yes");
        assert_eq!(Comparison::Slower.answer(), "no");
        assert_eq!(Comparison::Equal.answer(), "not clearly");
        assert_eq!(e(1.0, 3.0).show(2), "2.00 [1.00, 3.00]");
        assert_eq!(e(2.0, 4.0).recip().show(2), "0.33 [0.25, 0.50]");
    }
}
