//! Outputs of a real-time experiment: runs.csv (one row per pipeline, frame count and seed),
//! summary.csv (means with 95 % intervals over seeds, lag, frame time), timings.csv (each
//! render and filter's median time), rounds.csv (its time in every round), a plot of
//! error against frames, report.md with the verdict at fixed frame-time budgets, and the page
//! with every filter's picture beside the exact image.

use super::pipeline::{Pipeline, Slot, REFERENCE};
use super::runner::{Outcome, Picture, Row, Run, Series, Timed, FLICKER_FRAMES};
use super::spec::{RealtimeSpec, Variant};
use crate::experiment::contract::RunContext;
use crate::experiment::shadow::has_exact_answer;
use crate::files::write_atomic;
use crate::metrics::stats::{mean_ci, MeanCi};
use crate::output::page::{self, Gallery, Page, Shot, Tone};
use crate::output::plots::{line_panels, scheme_look, Axes, Panel, Point, Series as PlotSeries};
use crate::output::table::{cells, write_rows};
use crate::sampling::DiskScheme;
use crate::timing::{median_interval, paired_ratio, Comparison, Estimate, FRAME_S, RULE};
use serde::Serialize;
use std::fmt::Write as _;

/// One pipeline at one frame count over its seeds: a row of summary.csv, the pipeline's columns
/// then its statistics'.
#[derive(Clone, Debug)]
pub struct Summary {
    /// The pipeline.
    pub pipeline: Pipeline,
    /// What its seeds measured.
    pub stats: Stats,
}

impl Summary {
    /// The parts whose fields are summary.csv's columns, in order.
    pub fn columns(&self) -> (&Pipeline, &Stats) {
        (&self.pipeline, &self.stats)
    }
}

/// A pipeline's measures over its seeds.
#[derive(Clone, Debug, Serialize)]
pub struct Stats {
    /// Seeds behind the means.
    pub seeds: usize,
    /// Mean RMSE against the exact image over its penumbra.
    pub rmse: f64,
    /// Half-width of its 95 % interval.
    pub rmse_ci95: f64,
    /// Mean FLIP against the exact picture.
    pub flip: f64,
    /// Half-width of its 95 % interval.
    pub flip_ci95: f64,
    /// Mean 10-90 % width over the exact width.
    pub width_ratio: f64,
    /// Half-width of its 95 % interval.
    pub width_ratio_ci95: f64,
    /// Mean penumbra area over the exact one's.
    pub area_ratio: f64,
    /// Mean share of the exact penumbra shown fully lit or dark.
    pub lost_share: f64,
    /// Mean RMS frame-to-frame change where the exact image holds still.
    pub stability: f64,
    /// Half-width of its 95 % interval.
    pub stability_ci95: f64,
    /// Mean flicker at the last frame ([`Run::flicker`]).
    pub flicker: f64,
    /// Half-width of its 95 % interval.
    pub flicker_ci95: f64,
    /// Moving variant: mean over seeds of the ghost's energy ([`ghosts`]; NaN at one frame, which
    /// keeps no history).
    pub ghost: f64,
    /// Half-width of its 95 % interval.
    pub ghost_ci95: f64,
    /// Moving variant: the most frames any seed took after the stop until its width came within
    /// the lag tolerance ([`lag`]); NaN when a seed never did (censored at the last frame).
    pub lag_frames: f64,
    /// Seeds that never came within the bound.
    pub lag_censored: usize,
    /// Render plus filter per frame, median over rounds (s).
    pub frame_s: f64,
    /// Lower end of its 95 % interval.
    pub frame_s_lo: f64,
    /// Upper end of its 95 % interval.
    pub frame_s_hi: f64,
    /// Shadow rays per frame.
    pub shadow_rays: u64,
    /// Filter taps per pixel with a receiver.
    pub taps_per_pixel: f64,
}

/// A timed slot's columns of timings.csv after its frame time.
#[derive(Serialize)]
struct TimingColumns<'a> {
    timed_frames: usize,
    work: u64,
    work_unit: &'a str,
}

/// One timed round of a slot: a row of rounds.csv, from which every time, ratio and budget
/// decision of the report recomputes.
#[derive(Serialize)]
struct RoundRow {
    round: usize,
    frame_s: f64,
}

/// Everything the units measured.
struct Measured {
    rows: Vec<Row>,
    series: Vec<Series>,
    pictures: Vec<Picture>,
    slots: Vec<Timed>,
}

fn gather(outcomes: Vec<Outcome>) -> Measured {
    let mut m = Measured {
        rows: vec![],
        series: vec![],
        pictures: vec![],
        slots: vec![],
    };
    for o in outcomes {
        match o {
            Outcome::Measured { rows, series, pictures } => {
                m.rows.extend(rows);
                m.series.extend(series);
                m.pictures.extend(pictures);
            }
            Outcome::Timed { slots } => m.slots.extend(slots),
        }
    }
    m
}

impl Measured {
    /// Per-round seconds of a pipeline's frame: its render plus its filter (none: nothing).
    fn frame_seconds(&self, scheme: &str, rays: u32, filter: &str) -> Option<Vec<f64>> {
        let seconds = |slot: Slot| self.slots.iter().find(|s| s.slot == slot).map(|s| &s.seconds);
        let render = seconds(Slot::render(scheme, rays))?;
        if filter == "none" {
            return Some(render.clone());
        }
        let f = seconds(Slot::filter(filter))?;
        Some(render.iter().zip(f).map(|(a, b)| a + b).collect())
    }
}

/// summary.csv's rows, in runs.csv's order of first appearance.
fn summarise(spec: &RealtimeSpec, m: &Measured) -> Vec<Summary> {
    let mut keys: Vec<&Pipeline> = Vec::new();
    for r in &m.rows {
        if !keys.contains(&&r.pipeline) {
            keys.push(&r.pipeline);
        }
    }
    keys.into_iter()
        .map(|p| {
            let runs: Vec<&Run> = m.rows.iter().filter(|r| r.pipeline == *p).map(|r| &r.run).collect();
            let col = |f: fn(&Run) -> f64| runs.iter().map(|r| f(r)).collect::<Vec<f64>>();
            let (rmse, flip) = (mean_ci(&col(|r| r.rmse)), mean_ci(&col(|r| r.flip)));
            let width = mean_ci(&col(|r| r.width_px / r.exact_width_px));
            let stability = mean_ci(&col(|r| r.stability));
            let flicker = mean_ci(&col(|r| r.flicker));
            let (lag_frames, lag_censored) = match p.on(Variant::Moving) {
                true => lag(spec, m, p),
                false => (f64::NAN, 0),
            };
            let ghost = match p.on(Variant::Moving) && p.frames > 1 {
                true => mean_ci(&ghosts(spec, m, p)),
                false => mean_ci(&[]),
            };
            let time = m
                .frame_seconds(&p.scheme, p.rays, &p.filter)
                .map_or(Estimate::NAN, |s| median_interval(&s));
            Summary {
                pipeline: p.clone(),
                stats: Stats {
                    seeds: runs.len(),
                    rmse: rmse.mean,
                    rmse_ci95: rmse.ci95,
                    flip: flip.mean,
                    flip_ci95: flip.ci95,
                    width_ratio: width.mean,
                    width_ratio_ci95: width.ci95,
                    area_ratio: mean_ci(&col(|r| r.area_ratio)).mean,
                    lost_share: mean_ci(&col(|r| r.lost_share)).mean,
                    stability: stability.mean,
                    stability_ci95: stability.ci95,
                    flicker: flicker.mean,
                    flicker_ci95: flicker.ci95,
                    ghost: ghost.mean,
                    ghost_ci95: ghost.ci95,
                    lag_frames,
                    lag_censored,
                    frame_s: time.median,
                    frame_s_lo: time.lo,
                    frame_s_hi: time.hi,
                    shadow_rays: runs.first().map_or(0, |r| r.shadow_rays),
                    taps_per_pixel: runs.first().map_or(0.0, |r| r.taps_per_pixel),
                },
            }
        })
        .collect()
}

/// Frames after the stop whose swept-region error makes the ghost's energy.
pub const GHOST_FRAMES: usize = 8;

/// Per seed of a moving pipeline, the ghost's energy ([`Stats::ghost`]): over the first
/// [`GHOST_FRAMES`] frames after the stop, the swept region's mean squared error in excess of
/// the same pipeline's settled noise (its mean squared error over the penumbra on the still
/// scene at the last frame count, same seed), so that a noisier pipeline does not read as
/// more ghosted.
fn ghosts(spec: &RealtimeSpec, m: &Measured, pipeline: &Pipeline) -> Vec<f64> {
    let last = spec.max_frames();
    let (moving, still) = (pipeline.at(Variant::Moving, last), pipeline.at(Variant::Static, last));
    m.series
        .iter()
        .filter(|s| s.pipeline == moving)
        .map(|s| {
            let floor = m
                .rows
                .iter()
                .find(|r| r.pipeline == still && r.run.seed == s.seed)
                .map_or(0.0, |r| r.run.rmse * r.run.rmse);
            s.swept.iter().take(GHOST_FRAMES).map(|&e| (e - floor).max(0.0)).sum()
        })
        .collect()
}

/// Lag of a moving pipeline: per seed, the frames after the occluder stops until its 10-90 %
/// width comes within `lag_tolerance` of where the same pipeline settles on the still scene
/// (its width over exact at the last frame count, same seed; exact where the still scene did
/// not run) and stays there to the last frame, so that neither a filter's own width bias nor a
/// noisy pass through the band reads as lag; the most over seeds, and how many seeds never got
/// there. Frame 0 is the first frame at the final position. A one-frame pipeline keeps no
/// history: its lag is 0.
fn lag(spec: &RealtimeSpec, m: &Measured, pipeline: &Pipeline) -> (f64, usize) {
    if pipeline.frames == 1 {
        return (0.0, 0);
    }
    let last = spec.max_frames();
    let (moving, still) = (pipeline.at(Variant::Moving, last), pipeline.at(Variant::Static, last));
    let (mut worst, mut censored, mut any) = (0.0f64, 0usize, false);
    for s in m.series.iter().filter(|s| s.pipeline == moving) {
        any = true;
        let target = m
            .rows
            .iter()
            .find(|r| r.pipeline == still && r.run.seed == s.seed)
            .map_or(1.0, |r| r.run.width_px / r.run.exact_width_px);
        let within = |r: f64| (r / target - 1.0).abs() <= spec.lag_tolerance;
        match s.width.iter().rposition(|&r| !within(r)) {
            None => {}
            Some(k) if k + 1 < s.width.len() => worst = worst.max((k + 1) as f64),
            Some(_) => censored += 1,
        }
    }
    match (any, censored) {
        (false, _) => (f64::NAN, 0),
        (true, 0) => (worst, 0),
        (true, c) => (f64::NAN, c),
    }
}

/// A mean with its 95 % half-width at `digits` decimals (`n/a` for NaN).
pub(super) fn show(m: f64, ci: f64, digits: usize) -> String {
    if m.is_nan() {
        "n/a".into()
    } else if ci.is_nan() {
        format!("{m:.digits$}")
    } else {
        format!("{m:.digits$} +- {ci:.digits$}")
    }
}

/// The verdict at one budget: the least-error static pipeline that is not slower than the budget
/// frame and keeps its width within the tolerance.
fn budget_section(spec: &RealtimeSpec, m: &Measured, summary: &[Summary], scheme: &str, rays: u32) -> String {
    let mut out = String::new();
    let Some(budget) = m.frame_seconds(scheme, rays, "none") else {
        return format!("- budget {scheme} x {rays} raw: not run (filtered out)\n");
    };
    let b = median_interval(&budget).scaled(1e3);
    let _ = writeln!(
        out,
        "\n### Budget: one raw frame of {scheme} x {rays} ray(s), {} ms [{:.3}, {:.3}]\n",
        show(b.median, f64::NAN, 3),
        b.lo,
        b.hi
    );
    let mut eligible: Vec<(&Summary, Estimate)> = summary
        .iter()
        .filter(|s| s.pipeline.on(Variant::Static))
        .filter_map(|s| {
            let t = m.frame_seconds(&s.pipeline.scheme, s.pipeline.rays, &s.pipeline.filter)?;
            let ratio = paired_ratio(&t, &budget);
            (Comparison::of(&ratio) != Comparison::Slower).then_some((s, ratio))
        })
        .collect();
    // The same pipeline on the moving scene: its lag there must be short too, where it ran.
    let moving = |s: &Summary| {
        let p = s.pipeline.at(Variant::Moving, s.pipeline.frames);
        summary.iter().find(|m| m.pipeline == p)
    };
    let moves = spec.variants.contains(&Variant::Moving);
    let keeps_up = |s: &Summary| {
        !moves || moving(s).is_some_and(|m| m.stats.lag_censored == 0 && m.stats.lag_frames <= spec.max_lag as f64)
    };
    // Within the tolerance only when the whole seed interval is: a mean inside it by luck is not.
    let width_ok = |s: &Summary| (s.stats.width_ratio - 1.0).abs() + s.stats.width_ratio_ci95 <= spec.width_tolerance;
    let within = |s: &Summary| width_ok(s) && keeps_up(s);
    eligible.sort_by(|a, b| a.0.stats.rmse.total_cmp(&b.0.stats.rmse));
    let _ = writeln!(
        out,
        "Pipelines on the still scene whose frame (render + filter) is not decidedly over the budget by the timing rule (time / budget: *faster* or *equivalent* fit it; *undecided* may or may not: the timing cannot tell), least RMSE first; `ok` where the whole 95 % seed interval of the width lies within {:.0} % of exact and, where the moving scene ran, the same pipeline's lag there is at most {} frame(s) (moving scenes decide too):\n",
        100.0 * spec.width_tolerance,
        spec.max_lag
    );
    let _ = writeln!(
        out,
        "| pipeline | RMSE | FLIP | width / exact | moving: lag, ghost | time / budget | ok |"
    );
    let _ = writeln!(out, "| --- | --- | --- | --- | --- | --- | --- |");
    for (s, ratio) in eligible.iter().take(8) {
        let motion = match moving(s) {
            Some(m) => format!("{}, {}", lag_word(m), show(m.stats.ghost, f64::NAN, 4)),
            None => "-".into(),
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {motion} | {}: {} | {} |",
            s.pipeline.label(),
            show(s.stats.rmse, s.stats.rmse_ci95, 4),
            show(s.stats.flip, s.stats.flip_ci95, 4),
            show(s.stats.width_ratio, s.stats.width_ratio_ci95, 3),
            ratio.show_ratio(2),
            Comparison::of(ratio).word(),
            if within(s) { "ok" } else { "no" }
        );
    }
    let fits = |ratio: &Estimate| Comparison::of(ratio) != Comparison::Undecided;
    let undecided_first: Vec<String> = eligible
        .iter()
        .filter(|(s, _)| within(s))
        .take_while(|(_, ratio)| !fits(ratio))
        .map(|(s, ratio)| format!("{} ({}x the budget)", s.pipeline.label(), ratio.show_ratio(2)))
        .collect();
    let undecided = if undecided_first.is_empty() {
        String::new()
    } else {
        format!(
            " With less RMSE, the width within tolerance, and a time the rule cannot place within or beyond the budget (**undecided**): {}.",
            undecided_first.join(", ")
        )
    };
    match eligible.iter().find(|(s, ratio)| within(s) && fits(ratio)) {
        Some((s, ratio)) => {
            let _ = writeln!(
                out,
                "\n**Answer:** at this budget the least error with the width within {:.0} % (and the lag bounded) among the pipelines the rule places within the budget (faster, or equivalent: at most 5 % over) is **{}**: RMSE {}, width {} of exact, time {} of the budget ({}).{undecided}",
                100.0 * spec.width_tolerance,
                s.pipeline.label(),
                show(s.stats.rmse, s.stats.rmse_ci95, 4),
                show(s.stats.width_ratio, s.stats.width_ratio_ci95, 3),
                ratio.show_ratio(2),
                Comparison::of(ratio).word()
            );
        }
        None => {
            let _ = writeln!(
                out,
                "\n**Answer:** no pipeline the rule places within this budget keeps the width within {:.0} % of exact by its whole seed interval (or the width could not be measured).{undecided}",
                100.0 * spec.width_tolerance
            );
        }
    }
    out
}

/// The rule's word for blue noise against the paper from the paired per-seed RMSE difference
/// `d` (blue - paper, mean with its 95 % half-width) read as a ratio to the paper's mean RMSE:
/// `1 + d / paper`, so the margin is relative, as for every ratio ([`crate::timing::RULE`]).
fn paired_word(d: MeanCi, paper: f64) -> String {
    if d.ci95.is_nan() || paper.is_nan() || paper <= 0.0 {
        return "undecided (too few seeds for an interval)".into();
    }
    let ratio = Estimate {
        median: 1.0 + d.mean / paper,
        lo: 1.0 + (d.mean - d.ci95) / paper,
        hi: 1.0 + (d.mean + d.ci95) / paper,
    };
    match Comparison::of(&ratio) {
        Comparison::Faster => "blue noise better".into(),
        Comparison::Slower => "paper better".into(),
        other => other.error_word().into(),
    }
}

/// The paper's claim restated: 16 raw rays of its pattern in one frame against 1-4 rays of blue
/// noise accumulated and filtered, per frame count: paired differences over the same seeds.
fn claim_section(spec: &RealtimeSpec, m: &Measured, summary: &[Summary]) -> String {
    let mut out = String::from("\n## The paper's claim restated\n\n");
    let first_acc = spec.accumulations.first().map(|a| a.name()).unwrap_or("mean");
    let paper_pipeline = Pipeline {
        variant: Variant::Static.name().into(),
        scheme: "paper".into(),
        rays: 16,
        frames: 1,
        accumulation: first_acc.into(),
        filter: "none".into(),
    };
    let paper: Vec<&Run> = m
        .rows
        .iter()
        .filter(|r| r.pipeline == paper_pipeline)
        .map(|r| &r.run)
        .collect();
    if paper.is_empty() {
        out += "Not answered: the paper's pipeline (paper x 16 rays, 1 frame, no filter) is not in this run.\n";
        return out;
    }
    let blue = ["bluenoise-cp", "sobol-bluenoise", "stbn-cp", "sobol-bluenoise-t"];
    let _ = writeln!(
        out,
        "Does 16 raw rays of the paper's pattern (one frame, no filter) beat 1-4 rays of blue noise accumulated and filtered? For each frame count, the blue-noise pipeline with the least mean RMSE (any scheme of {}, rays <= 4, any accumulation and filter) against the paper's, by the paired per-seed difference (blue noise - paper) with its 95 % interval, read as a ratio 1 + difference / the paper's mean RMSE by the rule below: *better* or *worse* beyond the 5 % margin, *equivalent* inside it, else *undecided*. (The candidate is chosen on the same seeds it is judged on, which favours it slightly.)\n",
        blue.join(", ")
    );
    let _ = writeln!(out, "Each frame count is asked twice: at any cost, and among the pipelines whose frame (render + filter) the timing rule places at or under the paper's raw frame (faster, or equivalent: at most 5 % over; an undecided time is not admitted).\n");
    let _ = writeln!(out, "| frames | cost | blue-noise pipeline | time / paper's | RMSE difference | quality | width / exact (blue; paper) | closer to the exact width |");
    let _ = writeln!(out, "| --- | --- | --- | --- | --- | --- | --- | --- |");
    let paper_width = mean_ci(&paper.iter().map(|r| r.width_px / r.exact_width_px).collect::<Vec<_>>());
    let paper_time = m.frame_seconds("paper", 16, "none");
    let cost = |s: &Summary| -> Option<Estimate> {
        let t = m.frame_seconds(&s.pipeline.scheme, s.pipeline.rays, &s.pipeline.filter)?;
        Some(paired_ratio(&t, paper_time.as_ref()?))
    };
    // At most the paper's cost: the rule places the time within it (faster, or equivalent).
    let within_cost = |r: &Estimate| matches!(Comparison::of(r), Comparison::Faster | Comparison::Equivalent);
    let (mut unplaced, mut absent) = (Vec::new(), Vec::new());
    let mut answered = 0;
    for (&frames, equal_cost) in spec.frames.iter().flat_map(|f| [(f, false), (f, true)]) {
        let candidates = || {
            summary.iter().filter(move |s| {
                s.pipeline.on(Variant::Static)
                    && blue.contains(&s.pipeline.scheme.as_str())
                    && s.pipeline.rays <= 4
                    && s.pipeline.frames == frames
            })
        };
        let best = candidates()
            .filter(|s| !equal_cost || cost(s).is_some_and(|r| within_cost(&r)))
            .min_by(|a, b| a.stats.rmse.total_cmp(&b.stats.rmse));
        if equal_cost {
            // Less error, but a time the rule calls undecided against the paper's: said beside
            // the table, never answered with.
            let bound = best.map_or(f64::INFINITY, |b| b.stats.rmse);
            let closer = candidates()
                .filter(|s| s.stats.rmse < bound)
                .filter_map(|s| Some((s, cost(s)?)))
                .filter(|(_, r)| Comparison::of(r) == Comparison::Undecided)
                .min_by(|a, b| a.0.stats.rmse.total_cmp(&b.0.stats.rmse));
            if let Some((s, r)) = closer {
                unplaced.push(format!(
                    "at {frames} frame(s), {}{} (RMSE {}, {}x the paper's time: undecided)",
                    if best.is_none() {
                        "where none is placed within the paper's cost, "
                    } else {
                        ""
                    },
                    s.pipeline.label(),
                    show(s.stats.rmse, s.stats.rmse_ci95, 4),
                    r.show_ratio(2)
                ));
            }
        }
        let Some(best) = best else {
            if equal_cost {
                absent.push(frames.to_string());
            }
            continue;
        };
        let time = match cost(best) {
            Some(r) => format!("{}: {}", r.show_ratio(2), Comparison::of(&r).word()),
            None => "n/a".into(),
        };
        let diffs: Vec<f64> = paper
            .iter()
            .filter_map(|p| {
                m.rows
                    .iter()
                    .find(|r| r.pipeline == best.pipeline && r.run.seed == p.seed)
                    .map(|r| r.run.rmse - p.rmse)
            })
            .collect();
        let d = mean_ci(&diffs);
        let word = paired_word(d, mean_ci(&paper.iter().map(|r| r.rmse).collect::<Vec<_>>()).mean);
        // Closer only when the intervals of the two distances from exact do not overlap.
        let (db, dp) = ((best.stats.width_ratio - 1.0).abs(), (paper_width.mean - 1.0).abs());
        let wider = if db + best.stats.width_ratio_ci95 < dp - paper_width.ci95 {
            "blue noise"
        } else if dp + paper_width.ci95 < db - best.stats.width_ratio_ci95 {
            "paper"
        } else {
            "undecided"
        };
        answered += 1;
        let _ = writeln!(
            out,
            "| {frames} | {} | {} | {time} | {} | {word} | {}; {} | {wider} |",
            if equal_cost { "at most the paper's" } else { "any" },
            best.pipeline.label(),
            show(d.mean, d.ci95, 4),
            show(best.stats.width_ratio, best.stats.width_ratio_ci95, 3),
            show(paper_width.mean, paper_width.ci95, 3),
        );
    }
    if answered == 0 {
        out += "\nNot answered: no blue-noise scheme at 4 rays or fewer is in this run.\n";
    }
    if !absent.is_empty() {
        let _ = writeln!(
            out,
            "\nAt {} frame(s) no blue-noise pipeline's time is placed at or under the paper's (faster or equivalent), so the table has no row at the paper's cost there.",
            absent.join(", ")
        );
    }
    if !unplaced.is_empty() {
        let _ = writeln!(
            out,
            "\nWith less RMSE than the row at the paper's cost (or where there is none), but a time the rule calls undecided against the paper's (its interval reaches past the 5 % margin or could not be formed; so not answered with): {}.",
            unplaced.join("; ")
        );
    }
    out
}

/// Writes every output into the run's staging folder.
pub fn write(spec: &RealtimeSpec, outcomes: Vec<Outcome>, run: &RunContext) -> anyhow::Result<toml::Table> {
    let dir = run.out.dir();
    let m = gather(outcomes);
    write_rows(&dir.join("runs.csv"), m.rows.iter().map(Row::columns))?;
    let summary = summarise(spec, &m);
    write_rows(&dir.join("summary.csv"), summary.iter().map(Summary::columns))?;
    write_rows(
        &dir.join("timings.csv"),
        m.slots.iter().map(|s| {
            let columns = TimingColumns {
                timed_frames: s.seconds.len(),
                work: s.work,
                work_unit: &s.work_unit,
            };
            (&s.slot, s.time.columns(FRAME_S), columns)
        }),
    )?;
    write_rows(
        &dir.join("rounds.csv"),
        m.slots.iter().flat_map(|s| {
            s.seconds
                .iter()
                .enumerate()
                .map(move |(round, &frame_s)| (&s.slot, RoundRow { round, frame_s }))
        }),
    )?;
    plot(spec, &summary, dir)?;
    let adapter = run.backend.adapter().clone();
    let mut md = format!(
        "# Real-time soft shadows: {}\n\n{} at {} x {} px on {} ({}); {} seed(s); frames judged at {:?}; EMA alpha {}; clamped history gamma {}; filters: {}.\n",
        spec.header.name,
        spec.scene_path.display(),
        spec.width,
        spec.height,
        adapter.name,
        adapter.backend,
        spec.seeds.len(),
        spec.frames,
        spec.accumulations
            .iter()
            .find_map(|a| match a {
                crate::render::denoise::Accumulation::Ema(alpha) | crate::render::denoise::Accumulation::Clamped { alpha, .. } => {
                    Some(alpha.to_string())
                }
                _ => None,
            })
            .unwrap_or("-".into()),
        spec.accumulations
            .iter()
            .find_map(|a| match a {
                crate::render::denoise::Accumulation::Clamped { gamma, .. } => Some(gamma.to_string()),
                _ => None,
            })
            .unwrap_or("-".into()),
        spec.filters.iter().map(|f| f.name()).collect::<Vec<_>>().join(", ")
    );
    md += "\nErrors are against the exact image of the current frame (quadrature) over its penumbra, or against a high-sample render where the scene has no exact answer; width is the 10-90 % width across the exact half-shadow contour (metrics::edge); means +- 95 % intervals over seeds. Frame time = render + filter, medians over interleaved rounds with 95 % intervals; it leaves out what still runs on the CPU beside them: the blocker distances the penumbra filter is sized by (traced apart from the render), the accumulation and the G-buffer. ";
    md += RULE;
    md += &reference_noise_paragraph(spec, &m, &summary);
    md += "\n\n## Verdict at a fixed frame-time budget\n";
    for (scheme, rays) in &spec.budgets {
        md += &budget_section(spec, &m, &summary, scheme.name(), *rays);
    }
    md += &claim_section(spec, &m, &summary);
    md += &cost_section(&m);
    md += &super::temporal::section(spec, &summary);
    md += &lag_section(spec, &summary);
    md += "\n![RMSE against frames](plots/rmse_frames.svg)\n";
    write_atomic(&dir.join("report.md"), md.as_bytes())?;
    let galleries = galleries(spec, &m)?;
    for g in &galleries {
        page::write_shots(dir, g)?;
    }
    page::write(
        dir,
        &Page {
            title: format!("{} (realtime)", spec.header.name),
            report: md,
            galleries,
        },
    )?;
    let mut details = toml::Table::new();
    details.insert("rows".into(), (m.rows.len() as i64).into());
    details.insert("timed_slots".into(), (m.slots.len() as i64).into());
    Ok(details)
}

/// Largest share of the least-error pipeline's own MSE the reference's noise may be (the bound
/// issue 52 sets).
pub const REFERENCE_NOISE_SHARE: f64 = 0.05;

/// How much the reference's own noise weighs against the best pipeline's error. A rendered
/// reference's noise ([`Run::reference_noise_mse`]) is independent of every pipeline's, so it
/// adds the same expected amount to every measured MSE: it reorders nothing on average, but
/// inflates every RMSE and pulls differences and ratios of errors towards 0 and 1. Its share is
/// given of the own MSE (measured less the noise) of the pipeline with the least mean RMSE, on
/// the still scene where there is one, over that pipeline's rows.
fn reference_noise_paragraph(spec: &RealtimeSpec, m: &Measured, summary: &[Summary]) -> String {
    if has_exact_answer(&spec.scene) {
        return "\n\nThe reference is exact (quadrature): no part of any error is its noise.".into();
    }
    let finite = || summary.iter().filter(|s| s.stats.rmse.is_finite());
    let least =
        |it: &mut dyn Iterator<Item = &Summary>| it.min_by(|a, b| a.stats.rmse.total_cmp(&b.stats.rmse)).cloned();
    let best = least(&mut finite().filter(|s| s.pipeline.on(Variant::Static))).or_else(|| least(&mut finite()));
    let Some(best) = best else {
        return "\n\nNo pipeline measured a finite error, so the reference's noise is weighed against none.".into();
    };
    let runs: Vec<&Run> = m
        .rows
        .iter()
        .filter(|r| r.pipeline == best.pipeline)
        .map(|r| &r.run)
        .collect();
    let n = runs.len() as f64;
    let noise = runs.iter().map(|r| r.reference_noise_mse).sum::<f64>() / n;
    let measured = runs.iter().map(|r| r.rmse * r.rmse).sum::<f64>() / n;
    let own = measured - noise;
    let intro = format!(
        "\n\nThe reference is the mean of two renders of {} jittered rays per light with independent seeds; a quarter of their squared difference puts its noise over the penumbra at MSE {:.3e}. Against the least-error pipeline ({}: measured MSE {:.3e}, its own {:.3e} once the reference's noise is taken off)",
        spec.reference_samples,
        noise,
        best.pipeline.label(),
        measured,
        own,
    );
    if !noise.is_finite() || own <= 0.0 {
        return format!("{intro} the noise cannot be weighed: it is as large as the measured error or unmeasured (an empty penumbra). Raise [reference] samples.");
    }
    let share = noise / own;
    let verdict = if share <= REFERENCE_NOISE_SHARE {
        format!("within the {:.0} % bound", 100.0 * REFERENCE_NOISE_SHARE)
    } else {
        format!(
            "over the {:.0} % bound: it adds the same amount to every pipeline's MSE, so it reorders none on average, but every RMSE reads high and every difference or ratio of errors is pulled towards 0 or 1 (raise [reference] samples)",
            100.0 * REFERENCE_NOISE_SHARE
        )
    };
    format!("{intro} it is {:.1} % of the own MSE, {verdict}.", 100.0 * share)
}

fn cost_section(m: &Measured) -> String {
    let mut out = String::from("\n## Cost per frame\n\n| what | median ms [95 %] | work |\n| --- | --- | --- |\n");
    for s in &m.slots {
        let t = s.time.scaled(1e3);
        let slot = &s.slot;
        let name = match slot.what.as_str() {
            "render" => format!("render {} x {} ray(s)", slot.scheme, slot.rays),
            _ => format!("filter {}", slot.filter),
        };
        let _ = writeln!(out, "| {name} | {} | {} {} |", t.show(3), s.work, s.work_unit);
    }
    out
}

fn lag_section(spec: &RealtimeSpec, summary: &[Summary]) -> String {
    let Some(motion) = &spec.motion else {
        return String::new();
    };
    let last = spec.max_frames();
    let rows: Vec<&Summary> = summary
        .iter()
        .filter(|s| s.pipeline.on(Variant::Moving) && s.pipeline.frames == last)
        .collect();
    if rows.is_empty() {
        return String::new();
    }
    let mut out = format!(
        "\n## Moving occluder: lag, ghost, flicker\n\nThe sphere moves {:.4} m per frame for {} frames, then stops. Lag: frames after the stop (0: the first frame at the final position) until the 10-90 % width across the current contour comes within {:.0} % of where the same pipeline settles on the still scene and stays there (most over seeds; `never` when a seed is not there by frame {last}). Ghost: the mean squared error over the swept region (every pixel in the exact penumbra of some position the sphere passed through) in excess of the same pipeline's settled error on the still scene, summed over the first {} frames after the stop. Flicker: the RMS over the penumbra of each pixel's temporal standard deviation over the last {FLICKER_FRAMES} frames, where they all follow the stop (`n/a` otherwise).\n\n| pipeline | lag (frames) | ghost | flicker | RMSE at {last} |\n| --- | --- | --- | --- | --- |\n",
        motion.step.length(),
        motion.frames,
        100.0 * spec.lag_tolerance,
        GHOST_FRAMES.min((last - motion.frames) as usize)
    );
    for s in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} |",
            s.pipeline.label(),
            lag_word(s),
            show(s.stats.ghost, s.stats.ghost_ci95, 4),
            show(s.stats.flicker, s.stats.flicker_ci95, 4),
            show(s.stats.rmse, s.stats.rmse_ci95, 4)
        );
    }
    out
}

/// A moving pipeline's lag as the tables show it.
fn lag_word(s: &Summary) -> String {
    match s.stats.lag_censored {
        0 => show(s.stats.lag_frames, f64::NAN, 0),
        c => format!("never ({c} seed(s))"),
    }
}

/// RMSE against frames on the static variant at the fewest rays, at the first accumulation:
/// one panel per filter on shared axes, one line per scheme in each, a scheme in the look it
/// has in every sweep plot.
fn plot(spec: &RealtimeSpec, summary: &[Summary], dir: &std::path::Path) -> anyhow::Result<()> {
    let acc = spec.accumulations.first().map(|a| a.name()).unwrap_or("mean");
    let rays = spec.rays[0];
    let shown: Vec<&Summary> = summary
        .iter()
        .filter(|s| s.pipeline.on(Variant::Static) && s.pipeline.accumulation == acc && s.pipeline.rays == rays)
        .collect();
    let mut panels: Vec<Panel> = Vec::new();
    for s in &shown {
        let at = match panels.iter().position(|p| p.title == s.pipeline.filter) {
            Some(i) => i,
            None => {
                panels.push(Panel {
                    title: s.pipeline.filter.clone(),
                    series: vec![],
                });
                panels.len() - 1
            }
        };
        let point = Point::ci(s.pipeline.frames as f64, s.stats.rmse, s.stats.rmse_ci95);
        let series = &mut panels[at].series;
        match series.iter_mut().find(|l| l.name == s.pipeline.scheme) {
            Some(l) => l.points.push(point),
            None => series.push(PlotSeries {
                name: s.pipeline.scheme.clone(),
                look: s
                    .pipeline
                    .scheme
                    .parse::<DiskScheme>()
                    .map_or(series.len(), |d| scheme_look(d, &spec.schemes)),
                points: vec![point],
            }),
        }
    }
    for p in &mut panels {
        p.title = format!("filter: {}", p.title);
    }
    std::fs::create_dir_all(dir.join("plots"))?;
    line_panels(
        &dir.join("plots/rmse_frames.svg"),
        &Axes {
            interval: "95 % interval over seeds",
            ..Axes::new(
                &format!("static, {rays} ray(s) a frame: RMSE against exact over the penumbra ({acc})"),
                "frames accumulated",
                "RMSE",
                true,
                true,
            )
        },
        &panels,
        &[],
    )
}

/// Per variant: the exact image, then every picture the units kept (first seed, first
/// accumulation, at the first and last frame counts).
fn galleries(spec: &RealtimeSpec, m: &Measured) -> anyhow::Result<Vec<Gallery>> {
    let mut out = Vec::new();
    for &variant in &spec.variants {
        let of_variant = |p: &&Picture| p.pipeline.on(variant);
        let Some(reference) = m
            .pictures
            .iter()
            .filter(of_variant)
            .find(|p| p.pipeline.filter == REFERENCE)
        else {
            continue;
        };
        let exact = has_exact_answer(&spec.scene);
        let mut shots = vec![Shot {
            label: format!("exact ({})", if exact { "quadrature" } else { "high-sample render" }),
            exr: format!("images/{}_exact.exr", variant.name()),
            png: format!("images/{}_exact.png", variant.name()),
            values: reference.values.clone(),
            key: vec![("variant".into(), variant.name().into())],
        }];
        for p in m
            .pictures
            .iter()
            .filter(of_variant)
            .filter(|p| p.pipeline.filter != REFERENCE)
        {
            let k = &p.pipeline;
            let stem = format!(
                "{}_{}_{}_{}f_{}_{}",
                k.variant, k.scheme, k.rays, k.frames, k.accumulation, k.filter
            );
            shots.push(Shot {
                label: format!(
                    "{} x {}, {} frame(s), {}, {}",
                    k.scheme, k.rays, k.frames, k.accumulation, k.filter
                ),
                exr: format!("images/{stem}.exr"),
                png: format!("images/{stem}.png"),
                values: p.values.clone(),
                key: cells(k)?,
            });
        }
        out.push(Gallery {
            title: format!(
                "{}: receiver plane, seed {}: the fewest rays after every frame with each filter, and one raw frame of the most rays",
                variant.name(),
                spec.seeds[0]
            ),
            width: spec.width,
            height: spec.height,
            tone: Tone::Linear,
            reference: Some(0),
            against: None,
            shots,
        });
    }
    Ok(out)
}
