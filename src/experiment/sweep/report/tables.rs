//! The sweep's CSV tables: runs.csv (one record per run), summary.csv (one row per
//! configuration), ground_truth.csv (one row per reference) and timings.csv (one row per timed
//! frame).

use super::results::Results;
use super::summary::Summary;
use crate::experiment::sweep::axes::Config;
use crate::experiment::sweep::timing::ConfigTiming;
use crate::output::table::{float, write_rows};
use serde::Serialize;
use std::path::Path;

/// Writes the four tables under `out` (timings.csv only when something was timed).
pub fn write_tables(r: &Results, summaries: &[Summary], out: &Path) -> anyhow::Result<()> {
    write_rows(&out.join("runs.csv"), &r.outcome.records)?;
    write_rows(&out.join("summary.csv"), summaries)?;
    write_ground_truth(r, out)?;
    write_timings(r, out)
}

/// A row of ground_truth.csv: one reference (lights on, light radius) and its checks.
#[derive(Serialize)]
struct GroundTruthRow {
    lights: u32,
    #[serde(with = "float")]
    light_radius: f64,
    ground_truth_samples: u32,
    #[serde(with = "float")]
    exact_umbra_radius: f64,
    #[serde(with = "float")]
    exact_penumbra_radius: f64,
    #[serde(with = "float")]
    exact_extent_inner: f64,
    #[serde(with = "float")]
    exact_extent_outer: f64,
    #[serde(with = "float")]
    exact_width_10_90: f64,
    #[serde(with = "float")]
    gt_extent_inner: f64,
    #[serde(with = "float")]
    gt_extent_outer: f64,
    #[serde(with = "float")]
    gt_width_10_90: f64,
    #[serde(with = "float")]
    gt_max_abs_error: f64,
    #[serde(with = "float")]
    gt_rmse_penumbra: f64,
    #[serde(with = "float")]
    gt_bias_penumbra: f64,
    penumbra_pixels: usize,
    #[serde(with = "float")]
    exact_max_error_bound: f64,
    exact_depth_limited_pixels: Option<usize>,
}

fn write_ground_truth(r: &Results, out: &Path) -> anyhow::Result<()> {
    let nan2 = (f64::NAN, f64::NAN);
    let rows = r.outcome.references.iter().map(|x| {
        let (ru, rp) = x
            .on_axis
            .as_ref()
            .map_or(nan2, |o| (o.umbra_radius(), o.penumbra_radius()));
        let (ei, eo) = x.exact_profile.as_ref().map_or(nan2, |p| p.extent());
        let (gi, go) = x.gt_profile().map_or(nan2, |p| p.extent());
        GroundTruthRow {
            lights: x.lights,
            light_radius: x.light_radius,
            ground_truth_samples: r.spec.ground_truth.samples,
            exact_umbra_radius: ru,
            exact_penumbra_radius: rp,
            exact_extent_inner: ei,
            exact_extent_outer: eo,
            exact_width_10_90: x.exact_profile.as_ref().map_or(f64::NAN, |p| p.width_10_90()),
            gt_extent_inner: gi,
            gt_extent_outer: go,
            gt_width_10_90: x.gt_profile().map_or(f64::NAN, |p| p.width_10_90()),
            gt_max_abs_error: x.gt_max_abs_all().unwrap_or(f64::NAN),
            gt_rmse_penumbra: x.gt_vs_exact().map_or(f64::NAN, |e| e.rmse),
            gt_bias_penumbra: x.gt_vs_exact().map_or(f64::NAN, |e| e.bias),
            penumbra_pixels: x.mask.pixels.len(),
            exact_max_error_bound: x.exact_quality.map_or(f64::NAN, |q| q.max_error_bound),
            exact_depth_limited_pixels: x.exact_quality.map(|q| q.depth_limited_pixels),
        }
    });
    write_rows(&out.join("ground_truth.csv"), rows)
}

/// A row of timings.csv after its configuration's columns: one timed frame.
#[derive(Serialize)]
struct TimedFrame {
    /// The A/A control's second series of the same configuration.
    control: bool,
    round: usize,
    #[serde(with = "float")]
    frame_s: f64,
    #[serde(with = "float")]
    primary_s: f64,
    clock: String,
}

/// timings.csv: every timed frame, one row each, so the spread behind each median can be seen.
fn write_timings(r: &Results, out: &Path) -> anyhow::Result<()> {
    let t = &r.outcome.timings;
    if t.configs.is_empty() {
        return Ok(());
    }
    let frames = |config: &Config, control: bool, c: &ConfigTiming| {
        c.frame_seconds
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let frame = TimedFrame {
                    control,
                    round: i,
                    frame_s: *s,
                    primary_s: c.primary_seconds.get(i).copied().unwrap_or(f64::NAN),
                    clock: c.clock.clone(),
                };
                (config.clone(), frame)
            })
            .collect::<Vec<_>>()
    };
    let mut all = Vec::new();
    for g in &r.outcome.groups {
        if let Some(c) = t.configs.get(&g.key) {
            all.extend(frames(&g.config, false, c));
        }
    }
    if let Some((config, c)) = &t.noise {
        all.extend(frames(config, true, c));
    }
    write_rows(&out.join("timings.csv"), all)
}
