//! Timing a frame-rate experiment: each configuration's frames over the same GPU resources.

use super::spec::{timed_scene, FpsSpec};
use crate::metrics::stats::median;
use crate::render::{Backend, Clock, RenderPlan, View};
use anyhow::Context;
use std::time::Instant;

/// One timed configuration: a row of fps.csv.
#[derive(Clone, Debug)]
pub struct FpsRow {
    /// Scene label.
    pub scene: String,
    /// Lights on.
    pub lights: u32,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Frames timed.
    pub frames: usize,
    /// Median seconds per frame.
    pub median_s: f64,
    /// Fastest and slowest frame.
    pub min_s: f64,
    /// Slowest frame.
    pub max_s: f64,
    /// Shadow rays per frame.
    pub shadow_rays: u64,
    /// Camera rays per frame.
    pub primary_rays: u64,
    /// The clock.
    pub clock: Clock,
    /// The paper's frames per second for this scene and light count (its resolution unknown).
    pub paper_fps: f64,
}

impl FpsRow {
    /// Frames per second from the median frame time.
    pub fn fps(&self) -> f64 {
        1.0 / self.median_s
    }

    /// Shadow rays per second.
    pub fn shadow_rays_per_s(&self) -> f64 {
        self.shadow_rays as f64 / self.median_s
    }
}

/// Timed frames for a configuration whose frames take `per_frame` seconds: as many as fit in
/// `max_seconds`, at least 3, at most `frames`.
fn frames_within(spec: &FpsSpec, per_frame: f64) -> u32 {
    let fit = (spec.max_seconds / per_frame.max(1e-9)).floor().min(u32::MAX as f64) as u32;
    fit.clamp(3.min(spec.frames), spec.frames)
}

/// Times every configuration; one row each.
pub fn run_fps(spec: &FpsSpec, backend: &mut dyn Backend) -> anyhow::Result<Vec<FpsRow>> {
    let mut rows = Vec::new();
    for s in &spec.scenes {
        for (&lights, &paper_fps) in s.lights.iter().zip(&s.paper_fps) {
            let scene = timed_scene(spec, s, lights);
            for &[width, height] in &spec.resolutions {
                let view = View {
                    camera: &scene.cameras[&s.camera],
                    width,
                    height,
                };
                tracing::info!("timing {} with {lights} light(s) at {width}x{height}", s.name);
                let frame = backend
                    .render(&scene, view, spec.sampling)
                    .with_context(|| format!("rendering {}", s.name))?;
                // One call times every frame over the same resources; a first frame sizes the
                // run to the time budget.
                let start = Instant::now();
                let first = backend.time(&scene, view, spec.sampling, spec.warmup, 1)?;
                let per_frame = start.elapsed().as_secs_f64() / (spec.warmup + 1) as f64;
                let more = frames_within(spec, per_frame).saturating_sub(1);
                let rest = backend.time(&scene, view, spec.sampling, 1, more)?;
                let clock = rest.clock;
                let seconds: Vec<f64> = first.seconds.into_iter().chain(rest.seconds).collect();
                rows.push(FpsRow {
                    scene: s.name.clone(),
                    lights,
                    width,
                    height,
                    frames: seconds.len(),
                    median_s: median(&seconds),
                    min_s: seconds.iter().copied().fold(f64::INFINITY, f64::min),
                    max_s: seconds.iter().copied().fold(0.0, f64::max),
                    shadow_rays: frame.rays.shadow_total(),
                    primary_rays: frame.rays.primary,
                    clock,
                    paper_fps,
                });
            }
        }
    }
    Ok(rows)
}

/// What `--dry-run` prints: the render plan of every configuration.
pub fn dry_run(spec: &FpsSpec) -> anyhow::Result<String> {
    let mut out = String::new();
    for s in &spec.scenes {
        for &lights in &s.lights {
            let scene = timed_scene(spec, s, lights);
            for &[width, height] in &spec.resolutions {
                let view = View {
                    camera: &scene.cameras[&s.camera],
                    width,
                    height,
                };
                out += &format!("{} with {lights} light(s) at {width}x{height}:\n", s.name);
                out += &RenderPlan::new(&scene, view)?.to_string();
            }
        }
    }
    Ok(out)
}
