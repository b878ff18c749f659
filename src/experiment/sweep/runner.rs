//! The sweep's units measured, and their outcomes put together for the report: a group renders
//! every seed of one configuration against its (lights on, light radius) reference; the timing
//! unit times every configuration in interleaved rounds ([`super::timing`]); the outcomes, in
//! canonical order, become the [`Outcome`] the report reads, records listed reference by
//! reference.

use super::axes::Config;
use super::experiment::Sweep;
use super::measure::{failed_record, measure_run};
use super::record::{FrameTime, Record, Status};
use super::reference::Reference;
use super::run::{context_key, expand, Group, GroupStats};
use super::spec::Spec;
use super::timing::{self, Timings};
use super::units::{Figure, GroupOutcome, TimingOutcome, UnitOutcome};
use crate::experiment::core::measure_whole;
use crate::experiment::progress::Progress;
use crate::metrics::throughput::rays_per_second;
use crate::metrics::{BiasVariance, RadialProfile};
use crate::render::{Backend, RenderPlan, View};
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
    /// The Fig. 2 pictures, when the experiment has `[figures]`.
    pub pictures: Option<super::pictures::Pictures>,
    /// Runs that failed.
    pub failures: usize,
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

/// Runs the whole sweep in this process with the core's unit journal and the ground-truth cache
/// under `home` (`fresh` discards the journal first), and puts its outcomes together.
pub fn run_sweep(
    spec: &Spec,
    backend: &mut dyn Backend,
    home: &Path,
    fresh: bool,
    progress: &Progress,
) -> anyhow::Result<Outcome> {
    let mut sweep = Sweep::new(spec.clone());
    crate::experiment::core::Declaration::keep_state_in(&mut sweep, home);
    let measured = measure_whole(&sweep, home, fresh, backend, progress)?;
    assemble(&sweep, backend, measured.outcomes)
}

/// Renders and measures every seed of `group` against `reference`; a failed render becomes a
/// failed record and the group goes on.
pub fn measure_group(spec: &Spec, backend: &mut dyn Backend, group: &Group, reference: &Reference) -> GroupOutcome {
    let context = context_key(spec, backend.adapter());
    let mut records = Vec::new();
    let mut images = Vec::new();
    for run in &group.runs {
        match measure_run(spec, backend, run, reference, &context) {
            Ok((record, image)) => {
                records.push(record);
                images.push(image);
            }
            Err(e) => {
                tracing::error!("run failed ({} seed={}): {e:#}", run.config(), run.seed);
                records.push(failed_record(spec, backend, run, &context, &format!("{e:#}")));
            }
        }
    }
    let figure = (group.head().samples == figure_samples(spec))
        .then(|| figure_of(reference, &images))
        .flatten();
    GroupOutcome {
        records,
        split: BiasVariance::measure(&images, &reference.ground_truth, &reference.mask),
        figure,
    }
}

/// The timing unit: every configuration of the sweep, and the A/A control, timed in the
/// schedule's interleaved rounds (nothing when the experiment times nothing).
pub fn time_all(spec: &Spec, backend: &mut dyn Backend, progress: &Progress) -> anyhow::Result<TimingOutcome> {
    if spec.timing.repeats == 0 {
        return Ok(TimingOutcome::default());
    }
    let groups = expand(spec);
    let probe = timing::noise_probe(&groups, figure_samples(spec), verdict_radius(spec));
    let visits = (groups.len() as u64 + probe.map_or(0, |_| timing::NOISE_VISITS as u64)) * spec.timing.repeats as u64;
    let bar = progress.bar("timed frames", visits);
    bar.message(format!("{} warm-up each, interleaved rounds", spec.timing.warmup));
    let (configs, noise) = timing::time_groups(spec, backend, &groups, probe.map(|i| &groups[i]), &|| bar.inc(1))?;
    bar.finish();
    Ok(TimingOutcome {
        configs,
        noise: probe.zip(noise),
    })
}

/// Puts the units' outcomes (canonical order: groups, pictures, timing) together for the
/// report: each reference built again, from the ground-truth cache where a unit left it.
pub fn assemble(sweep: &Sweep, backend: &mut dyn Backend, outcomes: Vec<UnitOutcome>) -> anyhow::Result<Outcome> {
    let spec = &sweep.spec;
    let groups = expand(spec);
    let context = context_key(spec, backend.adapter());
    let mut out = Outcome {
        records: Vec::new(),
        groups: Vec::new(),
        references: Vec::new(),
        profiles: Vec::new(),
        keep: Vec::new(),
        plan: sweep_plan(spec)?,
        timings: Timings {
            seed: spec.timing.seed,
            ..Timings::default()
        },
        pictures: None,
        failures: 0,
    };
    let mut measured: Vec<Option<GroupOutcome>> = Vec::new();
    let mut timing = TimingOutcome::default();
    for o in outcomes {
        match o {
            UnitOutcome::Group(g) => measured.push(Some(g)),
            UnitOutcome::Pictures(p) => out.pictures = p,
            UnitOutcome::Timing(t) => timing = t,
        }
    }
    anyhow::ensure!(
        measured.len() == groups.len(),
        "{} group outcomes for {} configurations",
        measured.len(),
        groups.len()
    );
    for ((lights, radius), share) in by_reference(&groups) {
        let reference = sweep.reference(backend, lights, radius)?;
        for (i, g) in share {
            let o = measured[i].take().expect("each group once");
            if let Some(f) = o.figure {
                keep_figure(&mut out, &reference, g.config(), f);
            }
            out.failures += o.records.iter().filter(|r| r.status != Status::Ok).count();
            out.records.extend(o.records);
            out.groups.push(GroupStats {
                key: g.head().key(&context),
                config: g.config(),
                split: o.split,
            });
        }
        out.references.push((*reference).clone());
    }
    if !timing.configs.is_empty() {
        for (g, t) in groups.iter().zip(timing.configs) {
            out.timings.configs.insert(g.head().key(&context), t);
        }
        out.timings.noise = timing.noise.map(|(i, t)| (groups[i].config(), t));
        fill_timing_columns(&mut out, &groups, &context);
    }
    Ok(out)
}

/// The groups (with their indices) judged against one reference: its (lights on, light radius)
/// pair, and them.
pub type ReferenceShare<'a> = ((u32, f64), Vec<(usize, &'a Group)>);

/// `groups` (with their indices) by the reference they are judged against, (lights on, light
/// radius) pairs in order of first appearance: the order records are listed in.
pub fn by_reference(groups: &[Group]) -> Vec<ReferenceShare<'_>> {
    let mut pairs: Vec<ReferenceShare> = Vec::new();
    for (i, g) in groups.iter().enumerate() {
        let pair = (g.head().lights, g.head().light_radius);
        match pairs.iter_mut().find(|(p, _)| *p == pair) {
            Some((_, share)) => share.push((i, g)),
            None => pairs.push((pair, vec![(i, g)])),
        }
    }
    pairs
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
        let Some(t) = out.timings.configs.get(gk) else {
            continue;
        };
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
fn keep_figure(out: &mut Outcome, reference: &Reference, config: Config, figure: Figure) {
    if let Some(means) = figure.profile_means {
        let mut profile = RadialProfile::new(&reference.receivers, &figure.image);
        profile.mean = means;
        out.profiles.push((config.clone(), profile));
    }
    out.keep.push((config, figure.image));
}
