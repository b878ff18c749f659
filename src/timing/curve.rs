//! Equal time from error-vs-time curves, not from the nearest swept ray count.
//!
//! A scheme is measured at several ray counts: an error per seed at each, a time per round at
//! those that were timed. Error is read as a smooth function of rays by linear interpolation in
//! log-log between measured counts (error ~ rays^-b is close to straight there); time by the
//! least-squares fit of a fixed cost plus a cost per ray, `t = a + c rays`, to the measured
//! medians (relative residuals minimised; the largest is reported as the fit's check), which is
//! increasing wherever `c > 0`, so a budget maps to one ray count and a small change in a
//! measured time moves an answer continuously, never by a jump to another count (how far: rays
//! in a budget are (t - a) / c, so a 5 % change in time moves them by 5 % / (1 - a / t), much more
//! where the fixed cost dominates the budget, as at a few rays on lavapipe). Two questions are
//! answered: the error each scheme reaches in a given time (the budget), and the time each needs
//! to reach a given error. Nothing is extrapolated: a budget outside a scheme's timed range, or
//! an error outside its measured range, has no answer.
//!
//! The interval of an answer comes from resampling seeds and timing rounds together (a
//! bootstrap): each replicate draws the seeds with replacement, once for every scheme and count
//! (seeds pair across them), and each count's rounds with replacement, the same round indices
//! for every scheme at that count (rounds pair across schemes as they were timed: the drift a
//! round shares cancels in a ratio), recomputes every curve and the answer; so a word carries
//! both noises. A plain percentile interval of a mean over few seeds covers well under its
//! nominal 95 % (about 80-90 % with four), so the interval is the expanded percentile one
//! (Hesterberg 2015, "What teachers should know about the bootstrap", Sec. 4.4): its tail
//! probability is `Phi(-sqrt(n / (n - 1)) t(n - 1, 0.975))` for `n` seeds instead of 2.5 %
//! ([`expanded_tail`]); with one seed there is no seed noise to resample, and no interval.

use super::Estimate;
use crate::metrics::stats::median;
use crate::sampling::Stream;

/// One measured ray count of one curve.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// Rays per pixel.
    pub rays: f64,
    /// Error per seed, in the experiment's seed order (NaN where a seed failed).
    pub errors: Vec<f64>,
    /// Seconds per timing round, in round order (empty where the count was not timed).
    pub seconds: Vec<f64>,
}

/// A curve as one draw of seeds and rounds sees it: error per measured count, and the time
/// model fitted to the timed counts.
#[derive(Clone, Debug, PartialEq)]
pub struct Drawn {
    errors: Vec<(f64, f64)>,
    time: Option<TimeModel>,
}

/// Frame time as a fixed cost plus a cost per ray, fitted to measured (rays, seconds) medians by
/// least squares on the relative residuals; valid over the timed range of rays only.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeModel {
    /// Fixed cost, seconds.
    pub fixed: f64,
    /// Cost per ray per pixel, seconds.
    pub per_ray: f64,
    /// Timed range of rays.
    pub range: (f64, f64),
    /// Largest relative residual of a measured median: the fit's check.
    pub worst_residual: f64,
}

impl TimeModel {
    /// The fit through `points` (rays, seconds): `None` with fewer than two distinct counts, a
    /// non-positive time, or a cost per ray that is not positive.
    pub fn fit(points: &[(f64, f64)]) -> Option<TimeModel> {
        if points.iter().any(|p| !(p.1 > 0.0 && p.1.is_finite())) {
            return None;
        }
        // Minimise sum ((a + c n) / t - 1)^2: least squares on rows [1/t, n/t] . [a, c] = 1.
        let (mut s11, mut s12, mut s22, mut b1, mut b2) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for &(n, t) in points {
            let (x1, x2) = (1.0 / t, n / t);
            s11 += x1 * x1;
            s12 += x1 * x2;
            s22 += x2 * x2;
            b1 += x1;
            b2 += x2;
        }
        let det = s11 * s22 - s12 * s12;
        if det.is_nan() || det.abs() <= 1e-12 * s11 * s22 {
            return None;
        }
        let fixed = (b1 * s22 - b2 * s12) / det;
        let per_ray = (s11 * b2 - s12 * b1) / det;
        if per_ray.is_nan() || per_ray <= 0.0 {
            return None;
        }
        let worst_residual = points
            .iter()
            .map(|&(n, t)| ((fixed + per_ray * n) / t - 1.0).abs())
            .fold(0.0, f64::max);
        let range = (points.first()?.0, points.last()?.0);
        Some(TimeModel {
            fixed,
            per_ray,
            range,
            worst_residual,
        })
    }

    /// Seconds at `rays` within the timed range.
    pub fn at(&self, rays: f64) -> Option<f64> {
        (rays >= self.range.0 && rays <= self.range.1).then_some(self.fixed + self.per_ray * rays)
    }

    /// Rays whose time is `seconds`, within the timed range.
    pub fn rays(&self, seconds: f64) -> Option<f64> {
        let n = (seconds - self.fixed) / self.per_ray;
        // The ends are exact: a budget taken at a timed end maps back onto it.
        let n = if (n - self.range.0).abs() <= 1e-9 * self.range.0 {
            self.range.0
        } else if (n - self.range.1).abs() <= 1e-9 * self.range.1 {
            self.range.1
        } else {
            n
        };
        (n >= self.range.0 && n <= self.range.1).then_some(n)
    }
}

/// Linear interpolation of `y` in `x` through the points (sorted by `x`) in log-log, exact at
/// the points themselves; `None` outside their range or where a value is not positive.
pub fn loglog(points: &[(f64, f64)], x: f64) -> Option<f64> {
    let first = points.first()?;
    let last = points.last()?;
    let positive = |p: &(f64, f64)| p.0 > 0.0 && p.1 > 0.0;
    if !(x >= first.0 && x <= last.0) {
        return None;
    }
    if let Some(p) = points.iter().find(|p| p.0 == x) {
        return positive(p).then_some(p.1);
    }
    let k = points.windows(2).position(|w| x <= w[1].0).unwrap_or(0);
    let (a, b) = (points[k], points[k + 1]);
    if !(positive(&a) && positive(&b)) {
        return None;
    }
    let t = (x.ln() - a.0.ln()) / (b.0.ln() - a.0.ln());
    Some((a.1.ln() + t * (b.1.ln() - a.1.ln())).exp())
}

/// Where the curve through `points` (sorted by `x`, `y` made monotone by the caller) reaches
/// `y`, by the same log-log interpolation: the first segment holding it.
fn inverse(points: &[(f64, f64)], y: f64) -> Option<f64> {
    let swapped: Vec<(f64, f64)> = points.iter().map(|&(x, v)| (v, x)).collect();
    if let [only] = swapped.as_slice() {
        return (only.0 == y).then_some(only.1);
    }
    swapped.windows(2).find_map(|w| {
        let (lo, hi) = (w[0].0.min(w[1].0), w[0].0.max(w[1].0));
        if !(y >= lo && y <= hi) {
            return None;
        }
        if lo == hi {
            return Some(w[0].1);
        }
        let mut seg = [w[0], w[1]];
        seg.sort_by(|a, b| a.0.total_cmp(&b.0));
        loglog(&seg, y)
    })
}

impl Drawn {
    /// Error at `rays`.
    pub fn error_at_rays(&self, rays: f64) -> Option<f64> {
        loglog(&self.errors, rays)
    }

    /// Time at `rays`, from the fitted time model.
    pub fn time_at_rays(&self, rays: f64) -> Option<f64> {
        self.time?.at(rays)
    }

    /// Rays whose time is `seconds`, from the fitted time model.
    pub fn rays_at_time(&self, seconds: f64) -> Option<f64> {
        self.time?.rays(seconds)
    }

    /// The fitted time model, if the counts timed give one.
    pub fn time_model(&self) -> Option<TimeModel> {
        self.time
    }

    /// Rays whose error is `error`: the error curve made non-increasing (a running minimum) and
    /// inverted.
    pub fn rays_at_error(&self, error: f64) -> Option<f64> {
        let mut low = f64::INFINITY;
        let monotone: Vec<(f64, f64)> = self
            .errors
            .iter()
            .map(|&(n, e)| {
                low = low.min(e);
                (n, low)
            })
            .collect();
        inverse(&monotone, error)
    }

    /// The error the curve reaches in `seconds` (the equal-time question).
    pub fn error_at_time(&self, seconds: f64) -> Option<f64> {
        self.error_at_rays(self.rays_at_time(seconds)?)
    }

    /// The time the curve needs to reach `error` (the equal-quality question).
    pub fn time_at_error(&self, error: f64) -> Option<f64> {
        self.time_at_rays(self.rays_at_error(error)?)
    }
}

/// Which seeds and rounds one replicate draws: seed indices, and a stream whose uniforms pick
/// each count's rounds (`None`: every round as measured).
struct Draw {
    seeds: Vec<usize>,
    rounds: Option<Rounds>,
}

/// How a replicate draws rounds: from `stream`, at each ray count (its index in `counts`) among
/// the rounds every curve compared there was timed in (its shared prefix: sequential timing
/// stops a configuration's rounds on its own, and round `i` is the same time slot in every
/// series), the same indices for every curve, so the drift a round shares cancels in a ratio.
struct Rounds {
    stream: Stream,
    /// Each ray count of any curve, sorted, with the rounds every curve timed there.
    counts: Vec<(f64, usize)>,
}

impl Rounds {
    /// `stream`'s draw over `curves`.
    fn over(stream: Stream, curves: &[&[Measured]]) -> Rounds {
        let mut counts: Vec<(f64, usize)> = Vec::new();
        for p in curves.iter().flat_map(|c| c.iter()).filter(|p| !p.seconds.is_empty()) {
            match counts.iter_mut().find(|(rays, _)| *rays == p.rays) {
                Some((_, n)) => *n = (*n).min(p.seconds.len()),
                None => counts.push((p.rays, p.seconds.len())),
            }
        }
        counts.sort_by(|a, b| a.0.total_cmp(&b.0));
        Rounds { stream, counts }
    }

    /// The median of `seconds` (timed at `rays`) over this replicate's rounds.
    fn median(&self, rays: f64, seconds: &[f64]) -> f64 {
        let (k, n) = self
            .counts
            .iter()
            .enumerate()
            .find(|(_, (r, _))| *r == rays)
            .map(|(k, (_, n))| (k as u32, *n))
            .expect("every timed count is listed");
        let stride = stride(self.counts.iter().map(|c| c.1).max().unwrap_or(0));
        let drawn: Vec<f64> = (0..n as u32)
            .map(|i| seconds[((self.stream.unit(stride * k + i) * n as f64) as usize).min(n - 1)])
            .collect();
        median(&drawn)
    }
}

impl Draw {
    fn curve(&self, points: &[Measured]) -> Drawn {
        // Failed seeds (NaN) are left out of the mean; a count with none left has no error.
        let mean = |errors: &[f64]| {
            let picked: Vec<f64> = self
                .seeds
                .iter()
                .filter_map(|&s| errors.get(s).copied())
                .filter(|v| v.is_finite())
                .collect();
            picked.iter().sum::<f64>() / picked.len() as f64
        };
        let timed: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| !p.seconds.is_empty())
            .map(|p| {
                let t = match &self.rounds {
                    None => median(&p.seconds),
                    Some(rounds) => rounds.median(p.rays, &p.seconds),
                };
                (p.rays, t)
            })
            .collect();
        Drawn {
            // A count whose every seed failed has no error and is left out of the curve, so
            // both directions (error at rays, rays at error) see the same gap.
            errors: points
                .iter()
                .map(|p| (p.rays, mean(&p.errors)))
                .filter(|p| p.1.is_finite())
                .collect(),
            time: TimeModel::fit(&timed),
        }
    }
}

/// Spacing of the uniforms one replicate draws per seed list or per count: 64, or more where a
/// list is longer, so that no two draws share a uniform.
fn stride(n: usize) -> u32 {
    n.max(64) as u32
}

/// Least share of replicates that must answer for an interval to be given.
pub const MIN_ANSWERED: f64 = 0.95;

/// The curves as measured: every seed, every round.
pub fn as_measured(points: &[Measured]) -> Drawn {
    let seeds = points.iter().map(|p| p.errors.len()).max().unwrap_or(0);
    Draw {
        seeds: (0..seeds).collect(),
        rounds: None,
    }
    .curve(points)
}

/// A statistic of several curves (each a list of measured counts sorted by rays) with its 95 %
/// percentile-bootstrap interval over `replicates` seeded draws of seeds and rounds. The
/// statistic's value on the curves as measured is the estimate; the interval is NaN with fewer
/// than two seeds, or where fewer than [`MIN_ANSWERED`] of the replicates have an answer (the
/// answer sits at the edge of a measured range).
pub fn bootstrap(
    curves: &[&[Measured]],
    replicates: u32,
    seed: u32,
    stat: impl Fn(&[Drawn]) -> Option<f64>,
) -> Estimate {
    let seeds = curves
        .iter()
        .flat_map(|c| c.iter().map(|p| p.errors.len()))
        .max()
        .unwrap_or(0);
    let point = stat(&curves.iter().map(|c| as_measured(c)).collect::<Vec<_>>()).unwrap_or(f64::NAN);
    let stream = Stream::new(seed, 0x0b00_7575, None);
    let mut values = Vec::with_capacity(replicates as usize);
    for r in 0..replicates {
        let seeds_drawn: Vec<usize> = (0..seeds)
            .map(|i| ((stream.unit(r * stride(seeds) + i as u32) * seeds as f64) as usize).min(seeds - 1))
            .collect();
        // Seeds pair across curves, and so do the rounds drawn at each count.
        let draw = Draw {
            seeds: seeds_drawn,
            rounds: Some(Rounds::over(Stream::new(seed ^ r, 0x0b00_7576, None), curves)),
        };
        let drawn: Vec<Drawn> = curves.iter().map(|c| draw.curve(c)).collect();
        values.extend(stat(&drawn).filter(|v| v.is_finite()));
    }
    if point.is_nan() || seeds < 2 || (values.len() as f64) < MIN_ANSWERED * replicates as f64 {
        return Estimate {
            median: point,
            lo: f64::NAN,
            hi: f64::NAN,
        };
    }
    values.sort_by(f64::total_cmp);
    // The k-th smallest and k-th largest, k = ceil(tail m) (at least the first): symmetric ranks.
    let m = values.len();
    let k = ((expanded_tail(seeds) * m as f64).ceil() as usize).clamp(1, m.div_ceil(2));
    Estimate {
        median: point,
        lo: values[k - 1].min(point),
        hi: values[m - k].max(point),
    }
}

/// The tail probability of the expanded percentile interval for a mean of `n` values
/// (Hesterberg 2015, Sec. 4.4): `Phi(-sqrt(n / (n - 1)) t(n - 1, 0.975))`, which widens a
/// percentile interval to correct its small-sample narrowness; 0.025 in the limit.
pub fn expanded_tail(n: usize) -> f64 {
    if n < 2 {
        return f64::NAN;
    }
    let n = n as f64;
    normal_cdf(-(n / (n - 1.0)).sqrt() * student_t_975(n - 1.0))
}

/// The 97.5 % quantile of Student's t with `df` degrees of freedom: tabulated for 1-30, the
/// Cornish-Fisher expansion (Abramowitz & Stegun 26.7.5) beyond, within 1e-4 there.
fn student_t_975(df: f64) -> f64 {
    const TABLE: [f64; 30] = [
        12.7062, 4.3027, 3.1824, 2.7764, 2.5706, 2.4469, 2.3646, 2.3060, 2.2622, 2.2281, 2.2010, 2.1788, 2.1604,
        2.1448, 2.1314, 2.1199, 2.1098, 2.1009, 2.0930, 2.0860, 2.0796, 2.0739, 2.0687, 2.0639, 2.0595, 2.0555, 2.0518,
        2.0484, 2.0452, 2.0423,
    ];
    let d = df.round() as usize;
    if (1..=30).contains(&d) {
        return TABLE[d - 1];
    }
    let z: f64 = 1.959964;
    let (z3, z5) = (z.powi(3), z.powi(5));
    z + (z3 + z) / (4.0 * df) + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * df * df)
}

/// The standard normal distribution function, from the complementary error function
/// (Abramowitz & Stegun 7.1.26 on |x|, absolute error under 1.5e-7).
fn normal_cdf(x: f64) -> f64 {
    let t = x.abs() / std::f64::consts::SQRT_2;
    let k = 1.0 / (1.0 + 0.3275911 * t);
    let poly = k * (0.254829592 + k * (-0.284496736 + k * (1.421413741 + k * (-1.453152027 + k * 1.061405429))));
    let erfc = poly * (-t * t).exp();
    if x >= 0.0 {
        1.0 - 0.5 * erfc
    } else {
        0.5 * erfc
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::timing::Comparison;

    /// A curve with error `c / sqrt(rays)` (times a per-seed factor) and time `a + b rays`
    /// (times a per-round factor).
    fn curve(c: f64, a: f64, b: f64, rays: &[f64], seed_noise: &[f64], round_noise: &[f64]) -> Vec<Measured> {
        rays.iter()
            .map(|&n| Measured {
                rays: n,
                errors: seed_noise.iter().map(|f| c / n.sqrt() * f).collect(),
                seconds: round_noise.iter().map(|f| (a + b * n) * f).collect(),
            })
            .collect()
    }

    const RAYS: [f64; 8] = [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0];

    #[test]
    fn interpolation_is_exact_on_power_laws_and_refuses_to_extrapolate() {
        let pts: Vec<(f64, f64)> = RAYS.iter().map(|&n| (n, 3.0 * n.powf(-0.5))).collect();
        for x in [1.0, 1.5, 12.0, 100.0, 128.0] {
            let y = loglog(&pts, x).unwrap();
            assert!((y - 3.0 * x.powf(-0.5)).abs() < 1e-12, "{x}: {y}");
        }
        assert_eq!(loglog(&pts, 0.5), None);
        assert_eq!(loglog(&pts, 129.0), None);
        assert_eq!(loglog(&[(1.0, 0.0), (2.0, 1.0)], 1.5), None, "a zero has no log");
        assert_eq!(loglog(&[(4.0, 2.0)], 4.0), Some(2.0));
    }

    /// Two schemes with the same error law, one 20 % slower per ray: at the other's time it
    /// reaches fewer rays, and its error is higher by exactly the interpolated amount; the time
    /// it needs for the other's error is 1.2x where the fixed cost is negligible. Exact inputs
    /// (no noise) give intervals that collapse on the value.
    #[test]
    fn equal_time_and_equal_error_follow_the_curves() {
        let ones = [1.0; 4];
        let fast = curve(1.0, 0.0, 1e-3, &RAYS, &ones, &ones);
        let slow = curve(1.0, 0.0, 1.2e-3, &RAYS, &ones, &ones);
        let budget = 16e-3;
        let at = |c: &[Measured]| as_measured(c).error_at_time(budget).unwrap();
        let expected = 1.0 / (16.0f64 / 1.2).sqrt();
        assert!((at(&slow) - expected).abs() < 1e-9, "{} vs {expected}", at(&slow));
        assert!((at(&fast) - 0.25).abs() < 1e-12);
        let t = as_measured(&slow).time_at_error(0.25).unwrap();
        assert!((t / budget - 1.2).abs() < 1e-9, "{t}");
        let ratio = bootstrap(&[&slow, &fast], 200, 1, |d| {
            Some(d[0].error_at_time(budget)? / d[1].error_at_time(budget)?)
        });
        assert!((ratio.median - 1.2f64.sqrt()).abs() < 1e-9 && (ratio.hi - ratio.lo).abs() < 1e-9);
        assert_eq!(Comparison::of(&ratio), Comparison::Slower);
        assert_eq!(as_measured(&fast).error_at_time(1e-4), None, "under one ray's time");
    }

    /// A 5 % timing difference moves the equal-time error by about 2.5 % (error ~ t^-1/2), not
    /// by a whole ray count; with seed and round noise (8 seeds) the expanded percentile
    /// interval holds the truth in at least 90 % of seeded trials, and the slower scheme is
    /// never called better.
    #[test]
    fn a_small_timing_gap_moves_the_answer_a_little_and_the_interval_covers_it() {
        let truth = 1.05f64.sqrt();
        let (mut covered, mut direction) = (0, 0);
        let trials = 60u32;
        for t in 0..trials {
            let s = Stream::new(t, 9, None);
            let noise = |k: u32, n: usize, rel: f64| -> Vec<f64> {
                (0..n as u32)
                    .map(|i| 1.0 + rel * (s.unit(k * 100 + i) - 0.5) * 2.0 * 3f64.sqrt())
                    .collect()
            };
            let a = curve(1.0, 2e-3, 1e-3, &RAYS, &noise(1, 8, 0.05), &noise(2, 9, 0.03));
            let b = curve(1.0, 2.1e-3, 1.05e-3, &RAYS, &noise(3, 8, 0.05), &noise(4, 9, 0.03));
            let budget_rays = 16.0;
            let ratio = bootstrap(&[&b, &a], 300, t, |d| {
                let budget = d[1].time_at_rays(budget_rays)?;
                Some(d[0].error_at_time(budget)? / d[1].error_at_rays(budget_rays)?)
            });
            covered += (ratio.lo <= truth && truth <= ratio.hi) as u32;
            direction += matches!(Comparison::of(&ratio), Comparison::Faster) as u32;
        }
        eprintln!("covered {covered} of {trials}, called better {direction}");
        assert!(covered as f64 >= 0.9 * trials as f64, "{covered}");
        assert_eq!(direction, 0, "a slower scheme is never called better at equal time");
    }

    /// The curve as measured takes each count's median over all its own rounds, whatever the
    /// other counts' round numbers.
    #[test]
    fn the_measured_curve_uses_every_round_of_each_count() {
        let points = vec![
            Measured {
                rays: 1.0,
                errors: vec![1.0],
                seconds: vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
            },
            Measured {
                rays: 2.0,
                errors: vec![0.5],
                seconds: (1..=24).map(|i| 10.0 + i as f64).collect(),
            },
        ];
        let d = as_measured(&points);
        let near = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 1e-9);
        assert!(near(d.time_at_rays(1.0), 3.5), "{:?}", d.time_at_rays(1.0));
        assert!(near(d.time_at_rays(2.0), 22.5), "{:?}", d.time_at_rays(2.0));
    }

    /// Medians that are not increasing (2 rays 9.37 ms, 4 rays 9.36 ms) give a time model that
    /// is: a budget a hair larger maps to a hair more rays, never to the next count; the fit
    /// reports its worst residual.
    #[test]
    fn the_time_model_is_increasing_and_continuous() {
        let pts = [(1.0, 7.33e-3), (2.0, 9.37e-3), (4.0, 9.36e-3), (8.0, 10.92e-3)];
        let m = TimeModel::fit(&pts).unwrap();
        assert!(
            m.per_ray > 0.0 && m.worst_residual > 0.01 && m.worst_residual < 0.2,
            "{m:?}"
        );
        let (a, b) = (m.rays(9.370e-3).unwrap(), m.rays(9.371e-3).unwrap());
        assert!(b > a && b - a < 0.01, "{a} {b}");
        // Exact on a straight line, and refuses to extrapolate.
        let line = [(1.0, 3e-3), (4.0, 6e-3), (16.0, 18e-3)];
        let m = TimeModel::fit(&line).unwrap();
        assert!((m.fixed - 2e-3).abs() < 1e-12 && (m.per_ray - 1e-3).abs() < 1e-12 && m.worst_residual < 1e-9);
        assert_eq!(m.rays(1e-3), None);
        assert_eq!(m.at(17.0), None);
        assert!(
            TimeModel::fit(&[(1.0, 5e-3), (2.0, 4e-3)]).is_none(),
            "more rays cheaper: no model"
        );
        assert!(TimeModel::fit(&[(4.0, 5e-3)]).is_none(), "one count: no model");
    }

    /// A failed seed (NaN) leaves its count's mean to the others and no other count's answer;
    /// one seed has no seed noise to resample and gets no interval.
    #[test]
    fn failed_seeds_and_single_seeds() {
        let mut c = curve(1.0, 0.0, 1e-3, &RAYS, &[1.0, 1.02, 0.98, 1.0], &[1.0; 6]);
        c[7].errors[2] = f64::NAN;
        let d = as_measured(&c);
        assert!(d.error_at_rays(4.0).is_some() && d.error_at_rays(128.0).is_some());
        let one = curve(1.0, 0.0, 1e-3, &RAYS, &[1.0], &[1.0, 1.01, 0.99, 1.0, 1.0, 1.0]);
        let e = bootstrap(&[&one], 100, 1, |d| d[0].error_at_time(16e-3));
        assert!(e.median.is_finite() && e.lo.is_nan(), "{e:?}");
    }

    /// The expanded tail against values computed independently (the t quantile by bisection on
    /// Simpson's rule over the t density, then `erfc`): 4 seeds 1.1903e-4, 8 seeds 5.7375e-3,
    /// 50 seeds 2.1179e-2; 0.025 in the limit; none for one seed.
    #[test]
    fn the_expanded_tail_matches_its_closed_form() {
        for (n, want) in [(4, 1.1903e-4), (8, 5.7375e-3), (50, 2.1179e-2)] {
            let got = expanded_tail(n);
            assert!((got - want).abs() < 2e-3 * want, "n = {n}: {got} vs {want}");
        }
        assert!((expanded_tail(100_000) - 0.025).abs() < 1e-4);
        assert!(expanded_tail(1).is_nan());
        assert!((normal_cdf(0.0) - 0.5).abs() < 1e-9 && (normal_cdf(1.959964) - 0.975).abs() < 1e-6);
    }

    /// Rounds pair across curves: two curves with the same per-round times up to a constant
    /// factor (round drift shared) give a ratio whose interval collapses on the factor, where
    /// drawing each curve's rounds apart would spread it by the drift.
    #[test]
    fn rounds_pair_across_curves_at_each_count() {
        let ones = [1.0; 4];
        let drift = [0.8, 1.0, 1.3, 0.9, 1.1, 1.25];
        let a = curve(1.0, 0.0, 1e-3, &RAYS, &ones, &drift);
        let b = curve(1.0, 0.0, 1.1e-3, &RAYS, &ones, &drift);
        let ratio = bootstrap(&[&b, &a], 300, 5, |d| {
            Some(d[0].time_at_rays(16.0)? / d[1].time_at_rays(16.0)?)
        });
        assert!((ratio.median - 1.1).abs() < 1e-9, "{ratio:?}");
        assert!(ratio.hi - ratio.lo < 1e-9, "unpaired rounds: {ratio:?}");
    }

    #[test]
    fn an_answer_at_the_edge_of_the_range_has_no_interval() {
        let ones = [1.0; 4];
        let c = curve(1.0, 0.0, 1e-3, &RAYS, &ones, &[0.9, 1.0, 1.1, 1.0, 0.95, 1.05]);
        // The 128-ray time is the largest measured: half the replicates fall outside.
        let e = bootstrap(&[&c], 200, 3, |d| d[0].error_at_time(128e-3));
        assert!(e.median.is_finite() && e.lo.is_nan(), "{e:?}");
        assert_eq!(Comparison::of(&e), Comparison::Undecided);
    }
}
