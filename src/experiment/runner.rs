//! The sweep: for each (lights on, light radius) pair build the reference once, then render
//! every run, measure it, and stream the records to a journal so an interrupted sweep resumes
//! where it stopped.

use super::journal::Journal;
use super::reference::{shadow_image, Reference};
use super::run::{context_key, expand, num, Group, Record, Run, ADAPTER_COLUMNS, IDENTITY_COLUMNS};
use super::spec::Spec;
use crate::metrics::{stats, ErrorMetrics, RadialProfile};
use crate::render::{Backend, RenderPlan, Sampling, View};
use crate::sampling::{DiskScheme, Pattern};
use anyhow::Context;
use std::collections::BTreeMap;
use std::path::Path;

/// Per-pixel statistics over the seeds of one group, inside the ground truth's penumbra:
/// MSE = bias^2 + variance (known-facts.md, "Bias vs variance").
#[derive(Clone, Debug, PartialEq)]
pub struct GroupStats {
    /// Key of the group's first run.
    pub key: String,
    /// The group's axes (seed of the first run).
    pub run: Run,
    /// Seeds that rendered.
    pub seeds: usize,
    /// mean_p (mean_s V - GT)^2 - variance / K: squared bias, corrected for the seed mean's noise.
    pub bias2: f64,
    /// mean_p of the per-pixel sample variance over seeds.
    pub variance: f64,
}

/// What a finished sweep hands to the report.
pub struct Outcome {
    /// One record per run, in canonical order.
    pub records: Vec<Record>,
    /// Bias/variance per group.
    pub groups: Vec<GroupStats>,
    /// The references, one per (lights on, light radius) pair, in sweep order.
    pub references: Vec<Reference>,
    /// Seed-averaged radial profiles at the figure sample count: (scheme, pattern, reference index).
    pub profiles: BTreeMap<(DiskScheme, Pattern, usize), RadialProfile>,
    /// Measuring-view visibility of the first seed at the figure sample count.
    pub keep: BTreeMap<(DiskScheme, Pattern, usize), Vec<f32>>,
    /// The render plan at the figure sample count with every swept light on, logged with the results.
    pub plan: RenderPlan,
    /// Runs that failed.
    pub failures: usize,
    /// Groups taken from the journal rather than rendered.
    pub resumed: usize,
}

/// Shadow-ray count whose images and profiles are kept for figures (the paper's 16, or the
/// nearest swept count).
pub fn figure_samples(spec: &Spec) -> u32 {
    let want = spec.figures.as_ref().map_or(16, |f| f.samples);
    *spec
        .axes
        .samples
        .iter()
        .min_by_key(|&&n| (n as i64 - want as i64).abs())
        .expect("validated non-empty")
}

/// Runs the sweep. `journal_dir` holds the resumable journal; `fresh` discards it first.
pub fn run_sweep(
    spec: &Spec,
    backend: &mut dyn Backend,
    journal_dir: &Path,
    cache: &Path,
    fresh: bool,
) -> anyhow::Result<Outcome> {
    let context = context_key(spec);
    let groups = expand(spec);
    let mut journal = Journal::open(journal_dir, fresh)?;
    let fig_n = figure_samples(spec);
    let total: u64 = groups.iter().map(|g| g.runs.len() as u64).sum();
    let bar = indicatif::ProgressBar::new(total).with_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} runs, {elapsed} elapsed, ~{eta} left  {msg}")
            .expect("valid template"),
    );
    let mut out = Outcome {
        records: Vec::new(),
        groups: Vec::new(),
        references: Vec::new(),
        profiles: BTreeMap::new(),
        keep: BTreeMap::new(),
        plan: {
            let lights = *spec.axes.light_counts.iter().max().expect("validated non-empty");
            let s = spec.scene_with(lights, spec.axes.light_radii[0], figure_samples(spec));
            RenderPlan::new(
                &s,
                View {
                    camera: &s.cameras[&spec.measure.camera],
                    width: spec.measure.width,
                    height: spec.measure.height,
                },
            )?
        },
        failures: 0,
        resumed: 0,
    };
    let pairs = spec
        .axes
        .light_counts
        .iter()
        .flat_map(|&l| spec.axes.light_radii.iter().map(move |&r| (l, r)));
    for (ri, (lights, radius)) in pairs.enumerate() {
        bar.set_message(format!("reference for {lights} light(s) of radius {radius} m"));
        let reference = Reference::build(spec, backend, lights, radius, cache)?;
        for group in groups
            .iter()
            .filter(|g| g.head().light_radius == radius && g.head().lights == lights)
        {
            let head = *group.head();
            let gkey = head.key(&context);
            let needed_for_figures = head.samples == fig_n;
            if !needed_for_figures {
                if let Some((records, stats)) = journal.completed(&gkey, group, &context) {
                    out.records.extend(records);
                    out.groups.push(stats);
                    out.resumed += 1;
                    bar.inc(group.runs.len() as u64);
                    continue;
                }
            }
            bar.set_message(format!(
                "{} {} n={} r={}",
                head.scheme, head.pattern, head.samples, radius
            ));
            let (records, stats, images) = run_group(spec, backend, group, &reference, &context, &bar);
            if needed_for_figures {
                keep_for_figures(&mut out, &reference, head, ri, &images);
            }
            let failed = records.iter().filter(|r| r.get("status") != "ok").count();
            out.failures += failed;
            if failed == 0 {
                journal.append(&records, &stats)?;
            }
            out.records.extend(records);
            out.groups.push(stats);
        }
        out.references.push(reference);
    }
    bar.finish_and_clear();
    Ok(out)
}

fn keep_for_figures(out: &mut Outcome, reference: &Reference, head: Run, ri: usize, images: &[Vec<f32>]) {
    let Some(first) = images.first() else { return };
    let key = (head.scheme, head.pattern, ri);
    out.keep.insert(key, first.clone());
    if reference.on_axis.is_none() {
        return;
    }
    let mut avg = RadialProfile::new(&reference.receivers, first);
    let profiles: Vec<_> = images
        .iter()
        .map(|im| RadialProfile::new(&reference.receivers, im))
        .collect();
    for (b, m) in avg.mean.iter_mut().enumerate() {
        *m = profiles.iter().map(|p| p.mean[b]).sum::<f64>() / profiles.len() as f64;
    }
    out.profiles.insert(key, avg);
}

/// Renders, times and measures every seed of a group; a failed render becomes a failed record
/// and the sweep goes on.
fn run_group(
    spec: &Spec,
    backend: &mut dyn Backend,
    group: &Group,
    reference: &Reference,
    context: &str,
    bar: &indicatif::ProgressBar,
) -> (Vec<Record>, GroupStats, Vec<Vec<f32>>) {
    let mut records = Vec::new();
    let mut images = Vec::new();
    for run in &group.runs {
        let result = measure_run(spec, backend, run, reference, context);
        match result {
            Ok((record, image)) => {
                records.push(record);
                images.push(image);
            }
            Err(e) => {
                bar.println(format!(
                    "run failed ({} {} n={} r={} seed={}): {e:#}",
                    run.scheme, run.pattern, run.samples, run.light_radius, run.seed
                ));
                records.push(failed_record(spec, backend, run, context, &format!("{e:#}")));
            }
        }
        bar.inc(1);
    }
    let stats = group_stats(group, reference, &images, context);
    (records, stats, images)
}

fn group_stats(group: &Group, reference: &Reference, images: &[Vec<f32>], context: &str) -> GroupStats {
    let k = images.len();
    let (mut bias2, mut variance) = (0.0, 0.0);
    for &i in &reference.mask.pixels {
        let vals: Vec<f64> = images.iter().map(|im| im[i] as f64).collect();
        let mean = vals.iter().sum::<f64>() / k.max(1) as f64;
        let var = if k > 1 {
            vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (k - 1) as f64
        } else {
            f64::NAN
        };
        bias2 += (mean - reference.ground_truth[i] as f64).powi(2) - var / k as f64;
        variance += var;
    }
    let n = reference.mask.pixels.len() as f64;
    GroupStats {
        key: group.head().key(context),
        run: *group.head(),
        seeds: k,
        bias2: bias2 / n,
        variance: variance / n,
    }
}

/// Columns of a record between the run's identity and the adapter's.
const METRIC_COLUMNS: usize = super::run::RUN_COLUMNS.len() - IDENTITY_COLUMNS - ADAPTER_COLUMNS;

fn assemble(
    spec: &Spec,
    backend: &dyn Backend,
    run: &Run,
    context: &str,
    status: &str,
    metrics: &[String],
    error: &str,
) -> Record {
    debug_assert_eq!(metrics.len(), METRIC_COLUMNS);
    let a = backend.adapter();
    let mut row = vec![
        run.key(context),
        status.to_string(),
        run.scheme.to_string(),
        run.pattern.to_string(),
        run.samples.to_string(),
        num(run.light_radius),
        run.lights.to_string(),
        run.seed.to_string(),
        spec.measure.width.to_string(),
        spec.measure.height.to_string(),
    ];
    row.extend_from_slice(metrics);
    row.extend([
        a.backend.clone(),
        a.name.clone(),
        a.driver.clone(),
        a.api.clone(),
        error.to_string(),
    ]);
    Record(row)
}

fn failed_record(spec: &Spec, backend: &dyn Backend, run: &Run, context: &str, error: &str) -> Record {
    assemble(
        spec,
        backend,
        run,
        context,
        "failed",
        &vec![String::new(); METRIC_COLUMNS],
        error,
    )
}

fn measure_run(
    spec: &Spec,
    backend: &mut dyn Backend,
    run: &Run,
    reference: &Reference,
    context: &str,
) -> anyhow::Result<(Record, Vec<f32>)> {
    let scene = spec.scene_with(run.lights, run.light_radius, run.samples);
    let m = &spec.measure;
    let view = View {
        camera: &scene.cameras[&m.camera],
        width: m.width,
        height: m.height,
    };
    let sampling = Sampling {
        scheme: run.scheme,
        pattern: run.pattern,
        seed: run.seed,
    };
    let frame = backend.render(&scene, view, sampling).context("render")?;
    let image = shadow_image(&frame.visibility);
    let rays = frame.rays;
    let t = &spec.timing;
    let (seconds, primary_seconds, clock) = if t.repeats > 0 {
        let timing = backend
            .time(&scene, view, sampling, t.warmup, t.repeats)
            .context("timing")?;
        (
            stats::median(&timing.seconds),
            stats::median(&timing.primary_seconds),
            timing.clock.name().to_string(),
        )
    } else {
        (f64::NAN, f64::NAN, String::new())
    };
    let radial = radial_metrics(&image, reference);
    let vs_gt = ErrorMetrics::measure(&image, &reference.ground_truth, &reference.mask);
    let rmse_exact = reference
        .exact
        .as_ref()
        .map_or(f64::NAN, |e| ErrorMetrics::measure(&image, e, &reference.mask).rmse);
    let (area_ratio, lost) = penumbra_coverage(&image, reference);
    let total_rays = rays.primary + rays.shadow_total();
    let (preset, build_ms, bytes) = match &scene.bvh {
        Some(b) => (
            b.preset.name().to_string(),
            num(b.total_time.as_secs_f64() * 1e3),
            num((b.node_count() * 32 + b.tree.primitive_indices.len() * 48) as f64 / b.world.len() as f64),
        ),
        None => Default::default(),
    };
    let mut metrics = radial;
    metrics.extend([
        num(vs_gt.rmse),
        num(vs_gt.relmse),
        num(vs_gt.bias),
        num(rmse_exact),
        num(area_ratio),
        num(lost),
        rays.primary.to_string(),
        rays.shadow_total().to_string(),
        num(seconds * 1e3),
        num(total_rays as f64 / seconds),
        num(rays.primary as f64 / primary_seconds),
        num(rays.shadow_total() as f64 / (seconds - primary_seconds)),
        clock,
        preset,
        build_ms,
        bytes,
    ]);
    Ok((assemble(spec, backend, run, context, "ok", &metrics, ""), image))
}

/// The on-axis columns (closed-form radii, exact and measured extents and 10-90 widths, profile
/// bias), blank when the scene has no rotationally symmetric exact shadow.
fn radial_metrics(image: &[f32], reference: &Reference) -> Vec<String> {
    let (Some(o), Some(exact)) = (&reference.on_axis, &reference.exact_profile) else {
        return vec![String::new(); 10];
    };
    let profile = RadialProfile::new(&reference.receivers, image);
    let (inner, outer) = profile.extent();
    let (ex_in, ex_out) = exact.extent();
    let (bias, abs_bias) = profile_bias(&profile, exact);
    [
        o.umbra_radius(),
        o.penumbra_radius(),
        ex_out - ex_in,
        exact.width_10_90(),
        inner,
        outer,
        outer - inner,
        profile.width_10_90(),
        bias,
        abs_bias,
    ]
    .map(num)
    .to_vec()
}

/// Penumbra for any scene, against the ground truth's penumbra mask P (eps < V_gt < 1 - eps):
/// the image's penumbra area (pixels with eps < V < 1 - eps) relative to |P|, and the share of P
/// that the image shows as fully lit or fully dark (penumbra the image loses).
pub fn penumbra_coverage(image: &[f32], reference: &Reference) -> (f64, f64) {
    let eps = crate::metrics::error::EPS as f32;
    let n = reference.mask.pixels.len() as f64;
    let area = image.iter().filter(|v| **v > eps && **v < 1.0 - eps).count() as f64;
    let lost = reference
        .mask
        .pixels
        .iter()
        .filter(|&&i| image[i] <= eps || image[i] >= 1.0 - eps)
        .count() as f64;
    (area / n, lost / n)
}

/// Signed and absolute mean of (profile - exact profile) over bins inside the exact penumbra
/// (between the exact image's inner and outer extent).
pub fn profile_bias(profile: &RadialProfile, exact: &RadialProfile) -> (f64, f64) {
    let (lo, hi) = exact.extent();
    let diffs: Vec<f64> = (0..profile.radius.len())
        .filter(|&b| profile.radius[b] >= lo && profile.radius[b] <= hi)
        .map(|b| profile.mean[b] - exact.mean[b])
        .filter(|d| !d.is_nan())
        .collect();
    if diffs.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let n = diffs.len() as f64;
    (
        diffs.iter().sum::<f64>() / n,
        diffs.iter().map(|d| d.abs()).sum::<f64>() / n,
    )
}
