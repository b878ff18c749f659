//! What each scheme achieves at equal time and what it costs at equal error, read from its
//! error-vs-time curve ([`crate::timing::curve`]): error per seed at every swept count,
//! interpolated in log-log, and time per round at every timed count, fitted as a fixed cost plus
//! a cost per ray, with intervals from resampling seeds and rounds together. A scheme a little
//! slower per ray reaches a little fewer rays in the budget (how many fewer grows with the fixed
//! cost's share of it), never the next swept count down: the answer follows the schemes.

use super::summary::{swept_schemes, Summary};
use crate::experiment::sweep::axes::{Axis, Config, Slice};
use crate::experiment::sweep::record::{Record, Status};
use crate::experiment::sweep::runner::Outcome;
use crate::sampling::{DiskScheme, Pattern};
use crate::timing::curve::{as_measured, bootstrap, Drawn, Measured};
use crate::timing::{Comparison, Estimate};
use std::fmt::Write as _;

/// Bootstrap replicates behind every interval of the section.
pub const REPLICATES: u32 = 1000;

/// The budgets: uniform sampling's frame time at these counts, where timed and strictly inside
/// its timed range (a budget at an end of the range leaves half the schemes outside it).
pub const BUDGET_RAYS: [u32; 3] = [4, 16, 32];

/// The errors a curve is drawn for: name, and how a run's value is read.
type Metric = (&'static str, fn(&Record) -> f64);

const RMSE: Metric = ("RMSE", |r| r.metrics.rmse);
const BLURRED: Metric = ("blurred RMSE", |r| r.metrics.rmse_blurred);

/// The measured counts of `scheme` in the slice of `at` (every axis but the count), sorted by
/// rays: each count's error per seed (NaN for a failed run) and its timed rounds.
fn curve(outcome: &Outcome, summaries: &[Summary], at: &Config, metric: Metric) -> Vec<Measured> {
    let mut rows: Vec<&Summary> = summaries
        .iter()
        .filter(|x| x.config.agrees_except(at, &[Axis::Samples]))
        .collect();
    rows.sort_by_key(|x| x.config.samples);
    rows.iter()
        .map(|x| Measured {
            rays: x.config.samples as f64,
            errors: outcome
                .records
                .iter()
                .filter(|r| r.run.config() == x.config)
                .map(|r| if r.status == Status::Ok { metric.1(r) } else { f64::NAN })
                .collect(),
            seconds: x.timing.as_ref().map_or(vec![], |t| t.frame_seconds.clone()),
        })
        .collect()
}

/// `value [lo, hi]: word` for a ratio, `reference` for uniform's own row, or `n/a` where the
/// curves give no answer.
fn ratio_cell(scheme: DiskScheme, e: &Estimate, word: fn(Comparison) -> &'static str) -> String {
    if scheme == DiskScheme::Uniform {
        return "reference".into();
    }
    if e.median.is_nan() {
        return "n/a".into();
    }
    format!("{}x: {}", e.show_ratio(2), word(Comparison::of(e)))
}

/// The section for one slice: per budget, each scheme's error in uniform's time at that count
/// (and its ratio to uniform's error there); then the time each needs for uniform@`n`'s RMSE.
pub fn section(outcome: &Outcome, summaries: &[Summary], slice: &Slice, n: u32, radius: f64) -> String {
    let at = |scheme: DiskScheme, samples: u32| Config {
        scheme,
        pattern: Pattern::PerPixel,
        samples,
        light_radius: radius,
        ..slice.config.clone()
    };
    let schemes = swept_schemes(summaries);
    let timed: Vec<u32> = summaries
        .iter()
        .filter(|x| x.config.agrees_except(&at(DiskScheme::Uniform, 1), &[Axis::Samples]))
        .filter(|x| x.timing.as_ref().is_some_and(|t| !t.frame_seconds.is_empty()))
        .map(|x| x.config.samples)
        .collect();
    let inside = |b: u32| timed.contains(&b) && timed.iter().any(|&n| n < b) && timed.iter().any(|&n| n > b);
    let budgets: Vec<u32> = BUDGET_RAYS.into_iter().filter(|&b| inside(b)).collect();
    if budgets.is_empty() || schemes.len() < 2 {
        return String::new();
    }
    let seed = outcome.timings.seed;
    let curves = |metric: Metric| -> Vec<(DiskScheme, Vec<Measured>)> {
        schemes
            .iter()
            .map(|&s| (s, curve(outcome, summaries, &at(s, 1), metric)))
            .collect()
    };
    let (rmse, blurred) = (curves(RMSE), curves(BLURRED));
    let uniform = |c: &[(DiskScheme, Vec<Measured>)]| -> Option<Vec<Measured>> {
        c.iter()
            .find(|(s, _)| *s == DiskScheme::Uniform)
            .map(|(_, m)| m.clone())
    };
    let (Some(u_rmse), Some(u_blurred)) = (uniform(&rmse), uniform(&blurred)) else {
        return String::new();
    };
    let worst_fit = rmse
        .iter()
        .filter_map(|(_, c)| as_measured(c).time_model())
        .map(|m| m.worst_residual)
        .fold(0.0, f64::max);
    let rounds: Vec<usize> = summaries
        .iter()
        .filter(|x| {
            x.config
                .agrees_except(&at(DiskScheme::Uniform, 1), &[Axis::Samples, Axis::Scheme])
        })
        .filter_map(|x| x.timing.as_ref().map(|t| t.frame_seconds.len()))
        .filter(|&r| r > 0)
        .collect();
    let mut s = format!(
        "\n### At equal time, from the error-vs-time curves\n\nEach scheme's error (mean over seeds) at every swept count, interpolated linearly in log-log between counts, and its frame time as a fixed cost plus a cost per ray fitted to the medians of its timed counts (every median within {:.1} % of its fit, the worst over schemes); nothing extrapolated: `n/a` outside a scheme's measured range. Budgets: uniform sampling's fitted frame time at {} rays. Intervals: 95 % expanded percentile bootstrap over {REPLICATES} draws of seeds and timing rounds together (rounds paired across schemes at each count, as they were timed; the tails widened for the few seeds), so each word carries both noises; words by the rule (see Timing) on the ratio to uniform's. Timing rounds per configuration: {}.\n",
        100.0 * worst_fit,
        budgets.iter().map(u32::to_string).collect::<Vec<_>>().join(", "),
        match (rounds.iter().min(), rounds.iter().max()) {
            (Some(a), Some(b)) if a == b => a.to_string(),
            (Some(a), Some(b)) => format!("{a}-{b} (rounds stop where the comparisons are decided)"),
            _ => "none".into(),
        }
    );
    let uniform_measured = as_measured(&u_rmse);
    for &b in &budgets {
        let budget_of = |d: &Drawn| d.time_at_rays(b as f64);
        let budget = uniform_measured.time_at_rays(b as f64).unwrap_or(f64::NAN);
        // Rays in a budget are (t - a) / c: a timing change of x moves them by x / share.
        let share = uniform_measured
            .time_model()
            .map_or(f64::NAN, |m| m.per_ray * b as f64 / budget);
        let _ = write!(
            s,
            "\n**Budget: uniform@{b}'s frame time ({:.3} ms; {:.0} % of it spent per ray, so a 5 % change in a scheme's time moves its rays in the budget by {:.0} %).**\n\n| scheme | rays in the budget | RMSE | RMSE / uniform's | blurred RMSE / uniform's |\n|---|---|---|---|---|\n",
            1e3 * budget,
            100.0 * share,
            5.0 / share
        );
        for ((scheme, c), (_, cb)) in rmse.iter().zip(&blurred) {
            let rays = as_measured(c).rays_at_time(budget);
            let error = bootstrap(&[c, &u_rmse], REPLICATES, seed, |d| {
                d[0].error_at_time(budget_of(&d[1])?)
            });
            let ratio = |curve: &[Measured], base: &[Measured]| {
                bootstrap(&[curve, base], REPLICATES, seed, |d| {
                    let budget = budget_of(&d[1])?;
                    Some(d[0].error_at_time(budget)? / d[1].error_at_time(budget)?)
                })
            };
            let _ = writeln!(
                s,
                "| {scheme} | {} | {} | {} | {} |",
                rays.map_or("n/a".into(), |r| format!("{r:.1}")),
                if error.median.is_nan() {
                    "n/a".into()
                } else {
                    error.show(4)
                },
                ratio_cell(*scheme, &ratio(c, &u_rmse), Comparison::error_word),
                ratio_cell(*scheme, &ratio(cb, &u_blurred), Comparison::error_word),
            );
        }
    }
    let _ = write!(
        s,
        "\n**Time to reach uniform@{n}'s RMSE** (the equal-quality question): rays each scheme needs for it on its curve, and that time against uniform@{n}'s.\n\n| scheme | rays needed | time / uniform@{n}'s |\n|---|---|---|\n"
    );
    let target = uniform_measured.error_at_rays(n as f64);
    for (scheme, c) in &rmse {
        let rays = target.and_then(|e| as_measured(c).rays_at_error(e));
        let ratio = bootstrap(&[c, &u_rmse], REPLICATES, seed, |d| {
            let target = d[1].error_at_rays(n as f64)?;
            Some(d[0].time_at_error(target)? / d[1].time_at_rays(n as f64)?)
        });
        let _ = writeln!(
            s,
            "| {scheme} | {} | {} |",
            rays.map_or("n/a".into(), |r| format!("{r:.1}")),
            ratio_cell(*scheme, &ratio, Comparison::word),
        );
    }
    s
}
