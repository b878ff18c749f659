//! The sweep's units measured, what each yields ([`UnitOutcome`], journaled by the experiment
//! core), and their outcomes put together for the report: a group renders
//! every seed of one configuration against its (lights on, light radius) reference; the timing
//! unit times every configuration in interleaved rounds ([`super::timing`]); the outcomes, in
//! canonical order, become the [`Outcome`] the report reads, records listed reference by
//! reference.

use super::axes::Config;
use super::measure::{failed_record, measure_run};
use super::pictures::Pictures;
use super::record::{FrameTime, Record, Status};
use super::reference::Reference;
use super::run::{context_key, expand, Group, GroupStats};
use super::spec::Spec;
use super::timing::{self, ConfigTiming, Timings};
use crate::experiment::progress::Progress;
use crate::metrics::throughput::rays_per_second;
use crate::metrics::{BiasVariance, RadialProfile};
use crate::output::table::{csv_text, f32_hex};
use crate::render::limit::DeviceLimit;
use crate::render::{AdapterInfo, Backend, RenderPlan};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::sync::Arc;

/// One unit's outcome.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum UnitOutcome {
    /// A configuration measured over its seeds.
    Group(GroupOutcome),
    /// The Fig. 2 pictures (none without `[figures]`).
    Pictures(Option<Pictures>),
    /// The timing phase.
    Timing(TimingOutcome),
}

/// A configuration measured over every seed: its runs.csv rows, the per-pixel bias/variance
/// split of its images, and what the figures keep of it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GroupOutcome {
    /// One record per seed, in seed order; failed runs included.
    #[serde(with = "csv_text")]
    pub records: Vec<Record>,
    /// Squared bias and variance over the seeds that rendered.
    pub split: BiasVariance,
    /// At the figures' ray count, when any seed rendered.
    pub figure: Option<Figure>,
}

impl GroupOutcome {
    /// Runs that failed.
    pub fn failed(&self) -> usize {
        self.records.iter().filter(|r| r.status != Status::Ok).count()
    }
}

/// What the report's figures take from a group at the figures' ray count: the measuring image
/// of its first rendered seed and, on on-axis scenes, the bin means of its seed-averaged radial
/// profile (the rest of a profile follows from the image and the receivers).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Figure {
    /// Measuring-view visibility of the first rendered seed.
    #[serde(with = "f32_hex")]
    pub image: Vec<f32>,
    /// [`crate::metrics::RadialProfile::mean`] over the group's seeds, on on-axis scenes.
    pub profile_means: Option<Vec<f64>>,
}

/// Every configuration timed in one interleaved phase, in the sweep's canonical order, and the
/// A/A control: the configuration (an index into that order) timed a second time per round.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct TimingOutcome {
    /// Per configuration, in canonical order.
    pub configs: Vec<ConfigTiming>,
    /// The A/A control's configuration index and its second series of frames.
    pub noise: Option<(usize, ConfigTiming)>,
}

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
    pub pictures: Option<Pictures>,
    /// Runs that failed.
    pub failures: usize,
}

/// Renders and measures every seed of `group` against `reference`; a failed render becomes a
/// failed record and the group goes on, except a frame the device cannot bind
/// ([`DeviceLimit`]): bad input, which every later run would meet too.
pub fn measure_group(
    spec: &Spec,
    backend: &mut dyn Backend,
    group: &Group,
    reference: &Reference,
) -> anyhow::Result<GroupOutcome> {
    let context = context_key(spec, backend.adapter());
    let mut records = Vec::new();
    let mut images = Vec::new();
    for run in &group.runs {
        match measure_run(spec, backend, run, reference, &context) {
            Ok((record, image)) => {
                records.push(record);
                images.push(image);
            }
            Err(e) if DeviceLimit::part_of(&e).is_some() => return Err(e),
            Err(e) => {
                tracing::error!("run failed ({} seed={}): {e:#}", run.config(), run.seed);
                records.push(failed_record(spec, backend, run, &context, &format!("{e:#}")));
            }
        }
    }
    let figure = (group.head().samples == spec.figure_samples())
        .then(|| figure_of(reference, &images))
        .flatten();
    Ok(GroupOutcome {
        records,
        split: BiasVariance::measure(&images, &reference.ground_truth, &reference.mask),
        figure,
    })
}

/// The timing unit: every configuration of the sweep at a timed ray count (`[timed]`), and the
/// A/A control, timed in the schedule's blocked sequential rounds (nothing when the experiment
/// times nothing); configurations off the timing grid get no frames.
pub fn time_all(spec: &Spec, backend: &mut dyn Backend, progress: &Progress) -> anyhow::Result<TimingOutcome> {
    if spec.timing.repeats == 0 {
        return Ok(TimingOutcome::default());
    }
    let groups = expand(spec);
    let timed: Vec<usize> = (0..groups.len())
        .filter(|&i| spec.timed_samples.contains(&groups[i].head().samples))
        .collect();
    let subset: Vec<Group> = timed.iter().map(|&i| groups[i].clone()).collect();
    let probe = timing::noise_probe(&subset, spec.figure_samples(), spec.verdict_radius());
    let bar = progress.bar("timing rounds (at most)", spec.timing.repeats as u64);
    bar.message(format!(
        "{} configurations, {} warm-up frame(s) before each timed one",
        subset.len() + probe.map_or(0, |_| timing::NOISE_VISITS as usize),
        spec.timing.warmup
    ));
    let (configs, noise) = timing::time_groups(spec, backend, &subset, probe, &|r| {
        bar.message(format!(
            "{} comparisons undecided, {} configurations still timed",
            r.open, r.units
        ));
        bar.inc(1);
    })?;
    bar.finish();
    let mut all = vec![ConfigTiming::empty(); groups.len()];
    for (&i, c) in timed.iter().zip(configs) {
        all[i] = c;
    }
    Ok(TimingOutcome {
        configs: all,
        noise: probe.map(|p| timed[p]).zip(noise),
    })
}

/// Puts the units' outcomes (canonical order: groups, pictures, timing) together for the
/// report: each reference built again, from the ground-truth cache where a unit left it.
pub fn assemble(
    spec: &Spec,
    adapter: &AdapterInfo,
    mut reference_for: impl FnMut(u32, f64) -> anyhow::Result<Arc<Reference>>,
    outcomes: Vec<UnitOutcome>,
) -> anyhow::Result<Outcome> {
    let groups = expand(spec);
    let context = context_key(spec, adapter);
    let mut out = Outcome {
        records: Vec::new(),
        groups: Vec::new(),
        references: Vec::new(),
        profiles: Vec::new(),
        keep: Vec::new(),
        plan: spec.plan()?,
        timings: Timings {
            seed: spec.timing.seed,
            looks: crate::timing::Looks::up_to(spec.timing.repeats),
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
        let reference = reference_for(lights, radius)?;
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
            if !t.frame_seconds.is_empty() {
                out.timings.configs.insert(g.head().key(&context), t);
            }
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
