//! The sweep: for each (lights on, light radius) pair build the reference once, then render
//! every run, measure it, and stream the records to a journal so an interrupted sweep resumes
//! where it stopped; then time every configuration in interleaved rounds (see [`super::timing`]).

use super::axes::Config;
use super::journal::{Figure, Journal};
use super::measure::{failed_record, measure_run};
use super::record::{FrameTime, Record, Status};
use super::reference::Reference;
use super::run::{context_key, expand, Group, GroupStats};
use super::spec::Spec;
use super::timing::{self, ConfigTiming, Timings};
use crate::experiment::progress::{Bar, Progress};
use crate::metrics::throughput::rays_per_second;
use crate::metrics::{BiasVariance, RadialProfile};
use crate::render::{Backend, RenderPlan, View};
use crate::sampling::DiskScheme;
use std::collections::HashMap;
use std::path::Path;

/// What a finished sweep hands to the report.
pub struct Outcome {
    /// One record per run, in canonical order.
    pub records: Vec<Record>,
    /// Bias/variance per group.
    pub groups: Vec<GroupStats>,
    /// The references, one per (lights on, light radius) pair, in sweep order.
    pub references: Vec<Reference>,
    /// Seed-averaged radial profiles of the configurations at the figure sample count (on-axis
    /// scenes).
    pub profiles: Vec<(Config, RadialProfile)>,
    /// Measuring-view visibility of the first seed of each configuration at the figure sample
    /// count.
    pub keep: Vec<(Config, Vec<f32>)>,
    /// The render plan at the figure sample count with every swept light on, logged with the results.
    pub plan: RenderPlan,
    /// Frame times per configuration (empty when the experiment times nothing).
    pub timings: Timings,
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

/// The render plan of the sweep's fullest run (most lights, first radius, the figures' ray
/// count, first swept structure): logged with every sweep and printed by `--dry-run`.
pub fn sweep_plan(spec: &Spec) -> anyhow::Result<RenderPlan> {
    let lights = *spec.axes.light_counts.iter().max().expect("validated non-empty");
    let s = spec.scene_with(
        lights,
        spec.axes.light_radii[0],
        figure_samples(spec),
        &spec.axes.accelerators[0],
    );
    let view = View {
        camera: &s.cameras[&spec.measure.camera],
        width: spec.measure.width,
        height: spec.measure.height,
    };
    RenderPlan::new(&s, view)
}

/// The light radius the verdict is read at: the paper's 2 cm if swept, else the nearest.
pub fn verdict_radius(spec: &Spec) -> f64 {
    *spec
        .axes
        .light_radii
        .iter()
        .min_by(|a, b| (*a - 0.02).abs().total_cmp(&(*b - 0.02).abs()))
        .expect("validated non-empty")
}

/// Runs the sweep. `journal_dir` holds the resumable journal; `fresh` discards it first.
pub fn run_sweep(
    spec: &Spec,
    backend: &mut dyn Backend,
    journal_dir: &Path,
    cache: &Path,
    fresh: bool,
    progress: &Progress,
) -> anyhow::Result<Outcome> {
    let context = context_key(spec, backend.adapter());
    let groups = expand(spec);
    let mut journal = Journal::open(journal_dir, fresh)?;
    let mut out = render_groups(spec, backend, &groups, &mut journal, cache, &context, progress)?;
    time_phase(spec, backend, &groups, &mut out, &context, &mut journal, progress)?;
    Ok(out)
}

/// An outcome with nothing in it yet but the sweep's plan.
pub(super) fn empty_outcome(spec: &Spec) -> anyhow::Result<Outcome> {
    Ok(Outcome {
        records: Vec::new(),
        groups: Vec::new(),
        references: Vec::new(),
        profiles: Vec::new(),
        keep: Vec::new(),
        plan: sweep_plan(spec)?,
        timings: Timings::default(),
        failures: 0,
        resumed: 0,
    })
}

/// Renders and measures `groups` (all of a sweep, or a shard's share), taking completed groups
/// from the journal; no timing. Records come reference by reference ([`by_reference`]), as an
/// unsharded sweep lists them.
pub(super) fn render_groups(
    spec: &Spec,
    backend: &mut dyn Backend,
    groups: &[Group],
    journal: &mut Journal,
    cache: &Path,
    context: &str,
    progress: &Progress,
) -> anyhow::Result<Outcome> {
    let fig_n = figure_samples(spec);
    if spec.axes.schemes.contains(&DiskScheme::SobolBluenoise) {
        let mut counts = spec.axes.samples.clone();
        counts.extend(spec.figures.as_ref().map(|f| f.samples));
        crate::sampling::bluenoise::prepare(&counts);
    }
    let bar = progress.bar("runs", groups.iter().map(|g| g.runs.len() as u64).sum());
    let mut out = empty_outcome(spec)?;
    for ((lights, radius), share) in by_reference(groups) {
        bar.message(format!("reference for {lights} light(s) of radius {radius} m"));
        let reference = Reference::build(spec, backend, lights, radius, cache, context)?;
        for warning in reference.warnings() {
            // `println` on a hidden bar (stderr not a terminal, as in CI logs) prints nothing.
            bar.suspend(|| tracing::warn!("{warning}"));
        }
        for group in share {
            let group_key = group.key(context);
            let figure = (group.head().samples == fig_n).then(|| journal.figure(&group_key));
            if let (Some((records, stats)), None | Some(Some(_))) = (journal.completed(group, context), &figure) {
                if let Some(Some(f)) = figure {
                    keep_figure(&mut out, &reference, group.config(), f);
                }
                out.records.extend(records);
                out.groups.push(stats);
                out.resumed += 1;
                bar.inc(group.runs.len() as u64);
                continue;
            }
            bar.message(group.config().to_string());
            let (records, stats, images) = run_group(spec, backend, group, &reference, context, &bar);
            if figure.is_some() {
                if let Some(f) = figure_of(&reference, &images) {
                    journal.save_figure(&group_key, &f)?;
                    keep_figure(&mut out, &reference, group.config(), f);
                }
            }
            let failed = records.iter().filter(|r| r.status != Status::Ok).count();
            out.failures += failed;
            if failed == 0 {
                journal.append(&group_key, &records, &stats)?;
                #[cfg(feature = "test-hooks")]
                crate::experiment::core::declared::die_after_journaled();
            }
            out.records.extend(records);
            out.groups.push(stats);
        }
        out.references.push(reference);
    }
    bar.finish();
    Ok(out)
}

/// `groups` by the reference they are judged against, (lights on, light radius) pairs in order
/// of first appearance: the order runs are rendered in and records listed.
pub(super) fn by_reference(groups: &[Group]) -> Vec<((u32, f64), Vec<&Group>)> {
    let mut pairs: Vec<((u32, f64), Vec<&Group>)> = Vec::new();
    for g in groups {
        let pair = (g.head().lights, g.head().light_radius);
        match pairs.iter_mut().find(|(p, _)| *p == pair) {
            Some((_, share)) => share.push(g),
            None => pairs.push((pair, vec![g])),
        }
    }
    pairs
}

/// The timing phase over every group of the sweep that rendered, when the experiment times
/// anything; fills the records' timing columns.
pub(super) fn time_phase(
    spec: &Spec,
    backend: &mut dyn Backend,
    groups: &[Group],
    out: &mut Outcome,
    context: &str,
    journal: &mut Journal,
    progress: &Progress,
) -> anyhow::Result<()> {
    if spec.timing.repeats > 0 {
        out.timings = time_sweep(spec, backend, groups, out, context, journal, progress)?;
        fill_timing_columns(out, groups, context);
    }
    Ok(())
}

/// The timing phase: every configuration whose runs all rendered, and the noise probe, timed in
/// interleaved rounds (or taken from the journal under the same timing settings).
fn time_sweep(
    spec: &Spec,
    backend: &mut dyn Backend,
    groups: &[Group],
    out: &Outcome,
    context: &str,
    journal: &mut Journal,
    progress: &Progress,
) -> anyhow::Result<Timings> {
    let settings = timing::settings_key(&spec.timing);
    let rendered: Vec<&Group> = groups
        .iter()
        .filter(|g| {
            let key = g.head().key(context);
            out.records.iter().any(|r| r.run_key == key && r.status == Status::Ok)
        })
        .collect();
    let probe = timing::noise_probe(&rendered, figure_samples(spec), verdict_radius(spec));
    let mut result = Timings {
        seed: spec.timing.seed,
        ..Timings::default()
    };
    let mut todo = Vec::new();
    for g in &rendered {
        let key = g.head().key(context);
        match journal.timing(&key, &settings) {
            Some(t) => {
                result.configs.insert(key, t.clone());
            }
            None => todo.push(*g),
        }
    }
    let noise_key = probe.map(|g| timing::noise_key(&g.head().key(context)));
    let mut journaled_noise = noise_key.as_ref().and_then(|k| journal.timing(k, &settings)).cloned();
    // Times are compared only within one interleaved phase: if anything must be timed, all is
    // timed again, so no ranking sets frames from two processes (and two machine loads) apart.
    if !todo.is_empty() || (probe.is_some() && journaled_noise.is_none()) {
        todo = rendered.clone();
        result.configs.clear();
        journaled_noise = None;
    }
    let noise_todo = if journaled_noise.is_none() { probe } else { None };
    if !todo.is_empty() || noise_todo.is_some() {
        let visits =
            (todo.len() as u64 + noise_todo.map_or(0, |_| timing::NOISE_VISITS as u64)) * spec.timing.repeats as u64;
        let bar = progress.bar("timed frames", visits);
        bar.message(format!("{} warm-up each, interleaved rounds", spec.timing.warmup));
        let (timed, noise) = timing::time_groups(spec, backend, &todo, noise_todo, &|| bar.inc(1))?;
        bar.finish();
        let mut new: Vec<(String, ConfigTiming)> = todo.iter().map(|g| g.head().key(context)).zip(timed).collect();
        if let (Some(k), Some(n)) = (&noise_key, &noise) {
            new.push((k.clone(), n.clone()));
        }
        journal.append_timings(&settings, &new)?;
        result.noise = noise.map(|n| (probe.expect("noise probe").config(), n));
        result
            .configs
            .extend(new.into_iter().filter(|(k, _)| Some(k) != noise_key.as_ref()));
    }
    if let (Some(g), Some(n)) = (probe, journaled_noise) {
        result.noise = Some((g.config(), n));
    }
    Ok(result)
}

/// Writes each configuration's timing into the records of all its seeds (a configuration is
/// timed once, with its first seed): median frame time and its 95 % interval, frames timed, the
/// clock, and rays per second from the median and the timed run's ray counts.
fn fill_timing_columns(out: &mut Outcome, groups: &[Group], context: &str) {
    let group_of: HashMap<String, String> = groups
        .iter()
        .flat_map(|g| {
            let gk = g.head().key(context);
            g.runs.iter().map(move |r| (r.key(context), gk.clone()))
        })
        .collect();
    let count = |n: Option<u64>| n.map_or(f64::NAN, |n| n as f64);
    let rays: HashMap<String, (f64, f64)> = out
        .records
        .iter()
        .map(|r| {
            (
                r.run_key.clone(),
                (count(r.rays.primary_rays), count(r.rays.shadow_rays)),
            )
        })
        .collect();
    for r in out.records.iter_mut().filter(|r| r.status == Status::Ok) {
        let Some(gk) = group_of.get(&r.run_key) else {
            continue;
        };
        let Some(t) = out.timings.configs.get(gk) else { continue };
        let frame = t.frame();
        let (primary, shadow) = rays[gk];
        let [rays_per_s, primary_rays_per_s, shadow_rays_per_s] =
            rays_per_second(primary, shadow, frame.median, t.primary_median());
        r.time = FrameTime {
            frame_s: frame.median,
            frame_s_lo: frame.lo,
            frame_s_hi: frame.hi,
            timed_frames: Some(t.frame_seconds.len()),
            rays_per_s,
            primary_rays_per_s,
            shadow_rays_per_s,
            clock: Some(t.clock.clone()),
        };
    }
}

/// What the figures keep of a group's images (none when every seed failed).
fn figure_of(reference: &Reference, images: &[Vec<f32>]) -> Option<Figure> {
    let first = images.first()?;
    let profile_means = reference
        .on_axis
        .is_some()
        .then(|| RadialProfile::mean_over(&reference.receivers, images).mean);
    Some(Figure {
        image: first.clone(),
        profile_means,
    })
}

/// Adds a group's figure to the outcome: its image, and its profile on on-axis scenes.
pub(super) fn keep_figure(out: &mut Outcome, reference: &Reference, config: Config, figure: Figure) {
    if let Some(means) = figure.profile_means {
        let mut profile = RadialProfile::new(&reference.receivers, &figure.image);
        profile.mean = means;
        out.profiles.push((config.clone(), profile));
    }
    out.keep.push((config, figure.image));
}

/// Renders and measures every seed of a group; a failed render becomes a failed record and the
/// sweep goes on.
fn run_group(
    spec: &Spec,
    backend: &mut dyn Backend,
    group: &Group,
    reference: &Reference,
    context: &str,
    bar: &Bar,
) -> (Vec<Record>, GroupStats, Vec<Vec<f32>>) {
    let mut records = Vec::new();
    let mut images = Vec::new();
    for run in &group.runs {
        match measure_run(spec, backend, run, reference, context) {
            Ok((record, image)) => {
                records.push(record);
                images.push(image);
            }
            Err(e) => {
                bar.suspend(|| tracing::error!("run failed ({} seed={}): {e:#}", run.config(), run.seed));
                records.push(failed_record(spec, backend, run, context, &format!("{e:#}")));
            }
        }
        bar.inc(1);
    }
    let stats = GroupStats {
        key: group.head().key(context),
        config: group.config(),
        split: BiasVariance::measure(&images, &reference.ground_truth, &reference.mask),
    };
    (records, stats, images)
}

/// What `--dry-run` prints: every configuration with its seeds, then the render plan.
pub fn dry_run(spec: &Spec) -> anyhow::Result<String> {
    let groups = expand(spec);
    let runs: usize = groups.iter().map(|g| g.runs.len()).sum();
    let mut out = format!("{}: {runs} runs in {} configurations\n", spec.name, groups.len());
    for g in &groups {
        let seeds: Vec<String> = g.runs.iter().map(|r| r.seed.to_string()).collect();
        out += &format!("  {} seeds=[{}]\n", g.config(), seeds.join(", "));
    }
    out += &format!("render plan of a run:\n{}", sweep_plan(spec)?);
    Ok(out)
}
