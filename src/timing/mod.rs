//! The one way every experiment kind times what it compares, and the one rule that turns times
//! into words.
//!
//! **Design.** The units compared (configurations, structures, frames) are visited in `repeats`
//! interleaved rounds; each even round visits them in a fresh order drawn from a recorded seed
//! and the odd round after it in the reverse order (counterbalanced, ABBA), so a slow drift of
//! the machine (clocks, other load), across rounds or within one, falls on every unit alike
//! instead of on whichever ran first. Each visit renders `warmup` untimed frames, then times one
//! (a frame-time experiment, whose units are the frames of a path, renders each path's first
//! frame `warmup` times instead: consecutive frames warm each other).
//!
//! **Estimates.** Every reported time is a median with a distribution-free 95 % interval over
//! its repeats: the order statistics `[x(k), x(n+1-k)]` with `k` from the binomial
//! distribution, exact for a median whatever the timings' distribution (a percentile bootstrap
//! of a median over a few repeats only picks order statistics too, with a coverage that swings
//! with `n`: 87.5 % at 7 repeats). [`Estimate`], [`median_interval`]. Two units visited in the
//! same rounds are compared by the median of their per-round time ratios ([`paired_ratio`]):
//! pairing by round cancels drift that a round shares. A ratio over a series of correlated
//! units (consecutive frames of a camera path) takes its interval from the medians of blocks of
//! frames longer than the series' correlation ([`series_median`]).
//!
//! **Words.** [`Comparison::of`] reads the 95 % interval of a ratio A / B (of times, or of
//! errors) against an equivalence band of [`MARGIN`] = 5 % ([`band`]): *faster* (*better*)
//! when the whole interval lies below the band, *slower* (*worse*) when above it, *equivalent*
//! when it lies wholly inside it (two one-sided tests), *undecided* otherwise; a claim "A is
//! faster than B" is answered *yes*, *no* or *undecided* by the same words. An interval wholly
//! on one side of 1 that reaches into the band is undecided, never equal: a direction needs a
//! difference the interval places beyond 5 %, which a device whose frames fall in two modes
//! (lavapipe's take 15 or 29 ms at random) rarely fakes. [`RULE`] says so in every report.

//! Files: [`schedule`] (the visiting order), [`sequential`] (blocked rounds that stop when
//! every stated comparison is decided), [`curve`] (equal time from error-vs-time curves, with
//! bootstrap intervals over seeds and rounds), [`estimate`] (a median with its interval),
//! [`interval`] (order-statistic intervals, paired ratios), [`series`] (a correlated series'
//! interval from block medians), [`rule`] (the words and how the numbers behind them print),
//! [`tuning`] (which candidate setting a structure keeps: the default unless another is faster).

pub mod curve;
pub mod estimate;
pub mod interval;
pub mod rule;
pub mod schedule;
pub mod sequential;
pub mod series;
pub mod tuning;

pub use estimate::{Estimate, EstimateColumns, FRAME_S};
pub use interval::{coverage, interval_rank, median_interval, paired_ratio};
pub use rule::{band, Comparison, MARGIN, MAX_DIGITS, NEAR_THRESHOLD, RULE};
pub use schedule::{Schedule, DEFAULT_SEED};
pub use sequential::{decide, Decided, Looks, Pair, RoundDone, SequentialTimes};
pub use series::{series_median, MIN_BLOCKS};

/// Roughly normal draws (sum of four uniforms) of mean `mean` and relative spread `rel`.
#[cfg(test)]
fn draws(stream: u32, n: usize, mean: f64, rel: f64) -> Vec<f64> {
    let s = crate::sampling::Stream::new(stream, 0, None);
    (0..n as u32)
        .map(|i| {
            let u: f64 = (0..4).map(|k| s.unit(4 * i + k)).sum();
            mean * (1.0 + rel * (u - 2.0))
        })
        .collect()
}
