//! One real-time unit measured: every seed's frames rendered in sequence (frame f draws the
//! scheme's samples at f), accumulated, filtered at each judged frame count and measured against
//! the exact image of the current frame; or the timing unit, every render and filter timed in
//! interleaved rounds.

use super::pipeline::{Pipeline, Slot};
use super::reference::{RefFrame, References};
use super::spec::{RealtimeSpec, Variant};
use crate::experiment::progress::Progress;
use crate::experiment::shadow::shadow_image;
use crate::metrics::flip::{flip_mean, PIXELS_PER_DEGREE};
use crate::metrics::{penumbra_coverage, ErrorMetrics};
use crate::output::images::grey;
use crate::render::denoise::penumbra::{blocker_distance, kernel_sigma};
use crate::render::denoise::{Accumulation, Accumulator, BlockerHistory, Filter, GBuffer, Input};
use crate::render::shading::Receiver;
use crate::render::{Backend, Sampling, View};
use crate::sampling::{DiskScheme, Pattern, Site};
use crate::scene::{Light, Scene};
use crate::timing::{median_interval, Estimate};
use anyhow::Context;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// One pipeline at one frame count and seed: a row of runs.csv, the pipeline's columns then the
/// run's ([`Row::columns`]).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Row {
    /// The pipeline.
    pub pipeline: Pipeline,
    /// Its seed and what it measured.
    pub run: Run,
}

impl Row {
    /// The parts whose fields are runs.csv's columns, in order.
    pub fn columns(&self) -> (&Pipeline, &Run) {
        (&self.pipeline, &self.run)
    }
}

/// One seed's run of a pipeline: its seed and what it measured.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Run {
    /// Seed of the sequence.
    pub seed: u32,
    /// RMSE against the current frame's exact image over its penumbra.
    pub rmse: f64,
    /// Mean FLIP of the grey picture against the exact one.
    pub flip: f64,
    /// 10-90 % width across the exact half-shadow contour, pixels ([`crate::metrics::edge`]).
    pub width_px: f64,
    /// The exact image's.
    pub exact_width_px: f64,
    /// The reference's own noise over this frame's penumbra, as a mean-squared error
    /// ([`super::reference::RefFrame::noise_mse`]; 0 where the reference is exact).
    pub reference_noise_mse: f64,
    /// Penumbra area (EPS < V < 1 - EPS) over the exact image's.
    pub area_ratio: f64,
    /// Share of the exact penumbra shown fully lit or dark.
    pub lost_share: f64,
    /// RMS change from the previous frame's output over the penumbra where the exact image did
    /// not change (NaN at one frame).
    pub stability: f64,
    /// Flicker: the RMS over the exact penumbra of each pixel's temporal standard deviation over
    /// the last [`FLICKER_FRAMES`] frames, where the exact image is the same at both ends of
    /// them (NaN before the last frame, and where the occluder moves within them).
    pub flicker: f64,
    /// Shadow rays per frame.
    pub shadow_rays: u64,
    /// Filter taps per pixel with a receiver (every surface the view sees).
    pub taps_per_pixel: f64,
    /// The device that rendered and filtered (its f32 rounding is in every number).
    pub adapter: String,
    /// Its driver.
    pub driver: String,
}

/// A moving run after the occluder stops, one value per frame (frames stop + 1, ..., the last):
/// what lag and ghosting are read from.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Series {
    /// The pipeline on the moving variant, through the last frame.
    pub pipeline: Pipeline,
    /// Seed of the sequence.
    pub seed: u32,
    /// RMSE over the current penumbra.
    pub rmse: Vec<f64>,
    /// 10-90 % width across the current contour over the exact one's.
    pub width: Vec<f64>,
    /// Mean squared error over the swept region: the union of the exact penumbrae of every
    /// scene state the occluder passed through, where its ghost lies.
    pub swept: Vec<f64>,
}

/// Frames over which flicker is read, ending at the last.
pub const FLICKER_FRAMES: u32 = 8;

/// Per pixel, whether frame `f`'s surface differs from frame `f - 1`'s (another object or
/// triangle, or a depth change over 0.1 %): a disocclusion, whose history is dropped.
fn disoccluded(
    before: &[Option<Receiver>],
    now: &[Option<Receiver>],
    depth_before: &[f32],
    depth_now: &[f32],
) -> Vec<bool> {
    (0..now.len())
        .map(|i| match (&before[i], &now[i]) {
            (Some(a), Some(b)) => {
                (a.object, a.triangle) != (b.object, b.triangle)
                    || (depth_now[i] - depth_before[i]).abs() > 1e-3 * depth_before[i].abs()
            }
            (a, b) => a.is_some() != b.is_some(),
        })
        .collect()
}

/// An output image kept for the page (first seed, first accumulation): at the fewest rays after
/// the last frame count with each filter, and one raw frame at the most rays (the paper's use).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Picture {
    /// Whose output it is ([`Pipeline::reference`] for the reference itself).
    pub pipeline: Pipeline,
    /// Visibility on the receiver plane, row-major.
    pub values: Vec<f32>,
}

/// One timed slot: a render of (scheme, rays) or a filter.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Timed {
    /// What it times.
    pub slot: Slot,
    /// Seconds per round.
    pub seconds: Vec<f64>,
    /// Their median and 95 % interval.
    pub time: Estimate,
    /// Shadow rays of a render; taps of a filter.
    pub work: u64,
    /// What `work` counts.
    pub work_unit: String,
}

/// What a unit yields.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum Outcome {
    /// A measured (variant, scheme, rays) unit.
    Measured {
        /// One per pipeline, judged frame count and seed.
        rows: Vec<Row>,
        /// The moving variant's errors after the stop.
        series: Vec<Series>,
        /// Images kept for the page.
        pictures: Vec<Picture>,
    },
    /// The timing unit.
    Timed {
        /// Every render and filter timed.
        slots: Vec<Timed>,
    },
}

/// Per light, per pixel: the mean distance to the blockers the frame's shadow rays meet (NaN
/// where none meets one), over the same targets the render drew. A GPU renderer would return
/// these with its shadow rays (a closest hit instead of any hit); here the CPU traces them
/// beside the render, for both backends alike, outside the frame time.
fn blockers(scene: &Scene, receivers: &[Option<Receiver>], sampling: Sampling, rays: u32, width: u32) -> Vec<Vec<f64>> {
    use rayon::prelude::*;
    scene
        .lights
        .iter()
        .enumerate()
        .map(|(l, light)| {
            let Light::Disk(d) = light else {
                return vec![f64::NAN; receivers.len()];
            };
            let (u, v) = d.basis();
            receivers
                .par_iter()
                .enumerate()
                .map(|(i, r)| {
                    let Some(r) = r else { return f64::NAN };
                    let p = i as u32;
                    let site = Site::pixel(sampling.seed, l as u32, [p % width, p / width], p, sampling.frame);
                    let (mut sum, mut n) = (0.0, 0u32);
                    for k in 0..rays {
                        let s = sampling.scheme.point(rays, k, site);
                        let target = d.center + d.radius * (u * s.x + v * s.y);
                        if let Some(t) = blocker_distance(scene, r, target) {
                            (sum, n) = (sum + t, n + 1);
                        }
                    }
                    if n == 0 {
                        f64::NAN
                    } else {
                        sum / n as f64
                    }
                })
                .collect()
        })
        .collect()
}

/// The reference pixels only: everything else [`crate::render::NO_RECEIVER`], so metrics see
/// the receiver plane.
fn on_receivers(image: &[f32], reference: &RefFrame) -> Vec<f32> {
    let mut out = vec![crate::render::NO_RECEIVER; image.len()];
    for &(i, _) in &reference.receivers.pixels {
        out[i] = image[i];
    }
    out
}

/// What one seed's pipeline state holds per accumulation.
struct History {
    accumulation: Accumulation,
    image: Accumulator,
    /// One per light, for the blocker estimate.
    blockers: Vec<BlockerHistory>,
}

/// Measures one (variant, scheme, rays) unit over every seed.
pub fn measure(
    spec: &RealtimeSpec,
    refs: &References,
    variant: Variant,
    scheme: DiskScheme,
    rays: u32,
    backend: &mut dyn Backend,
    progress: &Progress,
) -> anyhow::Result<Outcome> {
    let (w, h) = (spec.width, spec.height);
    let last = spec.max_frames();
    let stop = match variant {
        Variant::Moving => spec.motion.as_ref().map_or(0, |m| m.frames),
        Variant::Static => u32::MAX,
    };
    let penumbra = spec.filters.contains(&Filter::Penumbra);
    let swept = match variant {
        Variant::Moving => Some(swept_region(spec, refs, stop, backend)?),
        Variant::Static => None,
    };
    let (mut rows, mut series, mut pictures) = (Vec::new(), Vec::new(), Vec::new());
    let bar = progress.bar(
        &format!("{} {scheme} {rays} rays", variant.name()),
        spec.seeds.len() as u64 * last as u64,
    );
    for &seed in &spec.seeds {
        let mut histories: Vec<History> = spec
            .accumulations
            .iter()
            .map(|&a| History {
                accumulation: a,
                image: Accumulator::new(a, w, h),
                blockers: spec.scene.lights.iter().map(|_| BlockerHistory::new(a, w, h)).collect(),
            })
            .collect();
        // Per (accumulation, filter): the previous frame's output, what is measured after the stop
        // and the flicker window's per-pixel sums.
        let slots = histories.len() * spec.filters.len();
        let mut previous: Vec<Option<Vec<f32>>> = vec![None; slots];
        let mut after_stop = vec![Settling::default(); slots];
        let mut window: Vec<(Vec<f64>, Vec<f64>)> =
            vec![(vec![0.0; (w * h) as usize], vec![0.0; (w * h) as usize]); slots];
        let flicker_from = last.saturating_sub(FLICKER_FRAMES);
        // Flicker only over frames that all show the final scene.
        let held_still = variant == Variant::Static || flicker_from >= stop;
        for f in 0..last {
            let frames = f + 1;
            let scene = RealtimeSpec::with_rays(&spec.scene_at(variant, f), rays);
            let view = View {
                camera: &scene.cameras[&spec.camera],
                width: w,
                height: h,
            };
            let sampling = Sampling {
                scheme,
                pattern: Pattern::PerPixel,
                seed,
                frame: f,
            };
            let frame = backend
                .render(&scene, view, sampling)
                .with_context(|| format!("frame {f}"))?;
            let image = shadow_image(&frame.visibility);
            let guides = refs.guides(spec, variant, f)?;
            if f > 0 {
                let before = refs.guides(spec, variant, f - 1)?;
                if !Arc::ptr_eq(&before, &guides) {
                    let changed = disoccluded(
                        &before.receivers,
                        &guides.receivers,
                        &before.gbuffer.depth,
                        &guides.gbuffer.depth,
                    );
                    for hist in &mut histories {
                        hist.image.forget(&changed);
                        hist.blockers.iter_mut().for_each(|b| b.forget(&changed));
                    }
                }
            }
            let blocker = match penumbra {
                true => blockers(&scene, &guides.receivers, sampling, rays, w),
                false => vec![vec![f64::NAN; image.len()]; scene.lights.len()],
            };
            for hist in &mut histories {
                hist.image.add(&image);
                for (acc, b) in hist.blockers.iter_mut().zip(&blocker) {
                    acc.add(&image, b);
                }
            }
            let judged = spec.frames.contains(&frames);
            let before_judged = spec.frames.contains(&(frames + 1)) && frames >= 1;
            let settled = frames > stop;
            let flickering = f >= flicker_from;
            if !(judged || before_judged || settled || flickering) {
                bar.inc(1);
                continue;
            }
            let reference = refs.reference(spec, variant, f, backend)?;
            let receiving = image.iter().filter(|&&v| v != crate::render::NO_RECEIVER).count();
            for (a, hist) in histories.iter().enumerate() {
                let accumulated = hist.image.image();
                let variance = hist.image.variance_or_spatial(w, h);
                let sigma = match penumbra {
                    true => pixel_sigma(spec, &scene, &guides.gbuffer, &hist.blockers),
                    false => vec![0.0; accumulated.len()],
                };
                for (k, &filter) in spec.filters.iter().enumerate() {
                    let input = Input {
                        width: w,
                        height: h,
                        image: &accumulated,
                        variance: &variance,
                        gbuffer: &guides.gbuffer,
                        sigma: &sigma,
                        settings: spec.settings,
                    };
                    let (out, _) = backend
                        .reconstruct(filter, &input)
                        .with_context(|| format!("filter {filter}"))?;
                    let slot = a * spec.filters.len() + k;
                    let measured = on_receivers(&out.image, &reference);
                    let rmse = ErrorMetrics::measure(&measured, &reference.image, &reference.mask).rmse;
                    if settled {
                        let s = &mut after_stop[slot];
                        s.rmse.push(rmse);
                        s.width.push(reference.edge.width_10_90(&measured) / reference.width_px);
                        s.swept.push(swept_error(&measured, &reference, swept.as_deref()));
                    }
                    if flickering {
                        let (s1, s2) = &mut window[slot];
                        for (i, &v) in measured.iter().enumerate() {
                            (s1[i], s2[i]) = (s1[i] + v as f64, s2[i] + (v as f64).powi(2));
                        }
                    }
                    let pipeline = Pipeline::new(variant, scheme, rays, frames, hist.accumulation, filter);
                    if judged {
                        let stability = match (&previous[slot], f) {
                            (Some(prev), f) if f > 0 => {
                                let before = refs.reference(spec, variant, f - 1, backend)?;
                                stability(&measured, prev, &reference, &before)
                            }
                            _ => f64::NAN,
                        };
                        let (area_ratio, lost_share) =
                            penumbra_coverage(&measured, &reference.mask, &reference.receivers);
                        let flip = flip_mean(
                            &grey(&reference.image, w, h).data,
                            &grey(&measured, w, h).data,
                            w,
                            h,
                            PIXELS_PER_DEGREE,
                        )?;
                        rows.push(Row {
                            pipeline: pipeline.clone(),
                            run: Run {
                                seed,
                                rmse,
                                flip,
                                width_px: reference.edge.width_10_90(&measured),
                                exact_width_px: reference.width_px,
                                reference_noise_mse: reference.noise_mse,
                                area_ratio,
                                lost_share,
                                stability,
                                flicker: match frames == last && held_still {
                                    true => {
                                        let start = refs.reference(spec, variant, flicker_from, backend)?;
                                        flicker(&window[slot], last - flicker_from, &reference, &start)
                                    }
                                    false => f64::NAN,
                                },
                                shadow_rays: frame.rays.shadow_total(),
                                taps_per_pixel: out.taps as f64 / receiving.max(1) as f64,
                                adapter: backend.adapter().name.clone(),
                                driver: backend.adapter().driver.clone(),
                            },
                        });
                    }
                    if seed == spec.seeds[0] && a == 0 && k == 0 && frames == last {
                        pictures.push(Picture {
                            pipeline: Pipeline::reference(variant, frames),
                            values: reference.image.clone(),
                        });
                    }
                    let fewest = rays == spec.rays[0] && frames == last;
                    let raw = rays == *spec.rays.last().expect("validated") && frames == 1 && filter == Filter::None;
                    let kept = seed == spec.seeds[0] && a == 0 && (fewest || raw);
                    if judged && kept {
                        pictures.push(Picture {
                            pipeline,
                            values: measured.clone(),
                        });
                    }
                    previous[slot] = Some(measured);
                }
            }
            bar.inc(1);
        }
        if variant == Variant::Moving {
            for (a, hist) in histories.iter().enumerate() {
                for (k, &filter) in spec.filters.iter().enumerate() {
                    let s = std::mem::take(&mut after_stop[a * spec.filters.len() + k]);
                    series.push(Series {
                        pipeline: Pipeline::new(variant, scheme, rays, last, hist.accumulation, filter),
                        seed,
                        rmse: s.rmse,
                        width: s.width,
                        swept: s.swept,
                    });
                }
            }
        }
    }
    bar.finish();
    Ok(Outcome::Measured { rows, series, pictures })
}

/// The penumbra filter's per-pixel sigmas: the widest any light's blocker estimate asks for.
fn pixel_sigma(spec: &RealtimeSpec, scene: &Scene, gbuffer: &GBuffer, blockers: &[BlockerHistory]) -> Vec<f32> {
    let mut sigma = vec![0f32; gbuffer.depth.len()];
    for (light, acc) in scene.lights.iter().zip(blockers) {
        let Light::Disk(d) = light else { continue };
        let s = kernel_sigma(acc.blocker(), gbuffer, d, spec.width, spec.height, &spec.settings);
        for (a, b) in sigma.iter_mut().zip(s) {
            *a = a.max(b);
        }
    }
    sigma
}

/// What one pipeline measures after the stop, frame by frame ([`Series`]).
#[derive(Clone, Default)]
struct Settling {
    rmse: Vec<f64>,
    width: Vec<f64>,
    swept: Vec<f64>,
}

/// The swept region of a moving variant: every pixel in the exact penumbra of some scene state
/// up to the stop.
fn swept_region(
    spec: &RealtimeSpec,
    refs: &References,
    stop: u32,
    backend: &mut dyn Backend,
) -> anyhow::Result<Vec<usize>> {
    let mut pixels = std::collections::BTreeSet::new();
    for f in 0..=stop {
        pixels.extend(
            refs.reference(spec, Variant::Moving, f, backend)?
                .mask
                .pixels
                .iter()
                .copied(),
        );
    }
    Ok(pixels.into_iter().collect())
}

/// Mean squared error of `image` against the reference over `region` (NaN without one).
fn swept_error(image: &[f32], reference: &RefFrame, region: Option<&[usize]>) -> f64 {
    match region {
        Some(r) if !r.is_empty() => {
            r.iter()
                .map(|&i| (image[i] as f64 - reference.image[i] as f64).powi(2))
                .sum::<f64>()
                / r.len() as f64
        }
        _ => f64::NAN,
    }
}

/// Flicker from a window's per-pixel sums over `frames` frames ([`Run::flicker`]).
fn flicker(sums: &(Vec<f64>, Vec<f64>), frames: u32, reference: &RefFrame, start: &RefFrame) -> f64 {
    let n = frames as f64;
    let (mut sum, mut count) = (0.0, 0usize);
    for &i in &reference.mask.pixels {
        if reference.image[i] == start.image[i] && frames > 1 {
            let mean = sums.0[i] / n;
            sum += (sums.1[i] / n - mean * mean).max(0.0) * n / (n - 1.0);
            count += 1;
        }
    }
    if count == 0 {
        f64::NAN
    } else {
        (sum / count as f64).sqrt()
    }
}

/// RMS of the change between two outputs over the current penumbra where the exact image did not
/// change between their frames; NaN where nothing qualifies.
fn stability(now: &[f32], before: &[f32], reference: &RefFrame, earlier: &RefFrame) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for &i in &reference.mask.pixels {
        if reference.image[i] == earlier.image[i] {
            sum += (now[i] as f64 - before[i] as f64).powi(2);
            n += 1;
        }
    }
    if n == 0 {
        f64::NAN
    } else {
        (sum / n as f64).sqrt()
    }
}

/// The timing unit: every (scheme, rays) render of the static scene and every filter on a
/// four-frame accumulation, one timed call each per interleaved round.
pub fn time(
    spec: &RealtimeSpec,
    refs: &References,
    backend: &mut dyn Backend,
    progress: &Progress,
) -> anyhow::Result<Outcome> {
    let (w, h) = (spec.width, spec.height);
    let schedule = spec.header.schedule;
    let guides = refs.guides(spec, Variant::Static, 0)?;
    let rays0 = spec.rays[0];
    let scene0 = RealtimeSpec::with_rays(&spec.scene, rays0);
    let mut image = Accumulator::new(Accumulation::Mean, w, h);
    let mut blocker_accs = vec![];
    for f in 0..4 {
        let sampling = Sampling {
            scheme: spec.schemes[0],
            pattern: Pattern::PerPixel,
            seed: spec.seeds[0],
            frame: f,
        };
        let view = View {
            camera: &scene0.cameras[&spec.camera],
            width: w,
            height: h,
        };
        let frame = backend.render(&scene0, view, sampling)?;
        let shadow = shadow_image(&frame.visibility);
        let b = blockers(&scene0, &guides.receivers, sampling, rays0, w);
        image.add(&shadow);
        if blocker_accs.is_empty() {
            blocker_accs = b
                .iter()
                .map(|_| BlockerHistory::new(Accumulation::Mean, w, h))
                .collect();
        }
        for (acc, bl) in blocker_accs.iter_mut().zip(&b) {
            acc.add(&shadow, bl);
        }
    }
    let accumulated = image.image();
    let variance = image.variance_or_spatial(w, h);
    let sigma = pixel_sigma(spec, &scene0, &guides.gbuffer, &blocker_accs);
    let input = Input {
        width: w,
        height: h,
        image: &accumulated,
        variance: &variance,
        gbuffer: &guides.gbuffer,
        sigma: &sigma,
        settings: spec.settings,
    };
    let mut slots = Vec::new();
    let mut renders = Vec::new();
    for &scheme in &spec.schemes {
        for &rays in &spec.rays {
            let scene = RealtimeSpec::with_rays(&spec.scene, rays);
            let view = View {
                camera: &scene.cameras[&spec.camera],
                width: w,
                height: h,
            };
            let sampling = Sampling {
                scheme,
                pattern: Pattern::PerPixel,
                seed: spec.seeds[0],
                frame: 0,
            };
            let shadow_rays = backend.render(&scene, view, sampling)?.rays.shadow_total();
            slots.push(Timed {
                slot: Slot::render(scheme.name(), rays),
                seconds: vec![],
                time: Estimate::NAN,
                work: shadow_rays,
                work_unit: "shadow rays".into(),
            });
            renders.push((scene, sampling));
        }
    }
    let filters: Vec<Filter> = spec.filters.iter().copied().filter(|&f| f != Filter::None).collect();
    for &filter in &filters {
        slots.push(Timed {
            slot: Slot::filter(filter.name()),
            seconds: vec![],
            time: Estimate::NAN,
            work: input.taps(filter),
            work_unit: "taps".into(),
        });
    }
    let bar = progress.bar(
        "timed renders and filters",
        slots.len() as u64 * schedule.repeats as u64,
    );
    let times = schedule.run(slots.len(), |i| -> anyhow::Result<f64> {
        let seconds = if i < renders.len() {
            let (scene, sampling) = &renders[i];
            let view = View {
                camera: &scene.cameras[&spec.camera],
                width: w,
                height: h,
            };
            backend.time(scene, view, *sampling, schedule.warmup, 1)?.seconds[0]
        } else {
            let filter = filters[i - renders.len()];
            for _ in 0..schedule.warmup {
                backend.reconstruct(filter, &input)?;
            }
            backend.reconstruct(filter, &input)?.1
        };
        bar.inc(1);
        Ok(seconds)
    })?;
    bar.finish();
    for (slot, seconds) in slots.iter_mut().zip(times) {
        slot.time = median_interval(&seconds);
        slot.seconds = seconds;
    }
    Ok(Outcome::Timed { slots })
}
