//! Timing a frame-rate experiment: every configuration rendered once (its rays and work counted),
//! then timed one frame per interleaved round, the one way every kind times.

use super::spec::{timed_scene, FpsSpec};
use crate::accel::work::Work;
use crate::experiment::progress::Progress;
use crate::render::{Backend, Clock, RenderPlan, View};
use crate::scene::Scene;
use crate::timing::{median_interval, Estimate};
use anyhow::Context;

/// One timed configuration: a row of fps.csv.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct FpsRow {
    /// Scene label.
    pub scene: String,
    /// Lights on.
    pub lights: u32,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Seconds of each timed frame, one per round.
    pub frame_seconds: Vec<f64>,
    /// Median frame seconds with its 95 % interval.
    pub frame: Estimate,
    /// Shadow rays per frame.
    pub shadow_rays: u64,
    /// Camera rays per frame.
    pub primary_rays: u64,
    /// What a frame's queries cost, where the backend counts it.
    pub work: Option<Work>,
    /// The clock.
    pub clock: Clock,
    /// The paper's frames per second for this scene and light count (its resolution unknown).
    pub paper_fps: f64,
}

impl FpsRow {
    /// Frames per second with its interval, from the frame time's.
    pub fn fps(&self) -> Estimate {
        self.frame.recip()
    }

    /// Shadow rays per second at the median frame time.
    pub fn shadow_rays_per_s(&self) -> f64 {
        self.shadow_rays as f64 / self.frame.median
    }
}

/// One configuration: its scene and view size.
struct Unit {
    scene: Scene,
    camera: String,
    width: u32,
    height: u32,
}

/// Every configuration of every scene, all timed in one schedule.
pub fn run_fps(spec: &FpsSpec, backend: &mut dyn Backend, progress: &Progress) -> anyhow::Result<Vec<FpsRow>> {
    let all: Vec<usize> = (0..spec.scenes.len()).collect();
    run_scenes(spec, &all, backend, progress)
}

/// Renders every configuration of the scenes at `which` once, then times them all in the
/// schedule's interleaved rounds.
pub fn run_scenes(
    spec: &FpsSpec,
    which: &[usize],
    backend: &mut dyn Backend,
    progress: &Progress,
) -> anyhow::Result<Vec<FpsRow>> {
    let mut units = Vec::new();
    let mut rows = Vec::new();
    for s in which.iter().map(|&i| &spec.scenes[i]) {
        for (&lights, &paper_fps) in s.lights.iter().zip(&s.paper_fps) {
            let scene = timed_scene(spec, s, lights);
            for &[width, height] in &spec.resolutions {
                let view = View {
                    camera: &scene.cameras[&s.camera],
                    width,
                    height,
                };
                let frame = backend
                    .render(&scene, view, spec.sampling)
                    .with_context(|| format!("rendering {}", s.name))?;
                rows.push(FpsRow {
                    scene: s.name.clone(),
                    lights,
                    width,
                    height,
                    frame_seconds: Vec::new(),
                    frame: Estimate::NAN,
                    shadow_rays: frame.rays.shadow_total(),
                    primary_rays: frame.rays.primary,
                    work: frame.work(),
                    clock: Clock::WallClock,
                    paper_fps,
                });
                units.push(Unit {
                    scene: scene.clone(),
                    camera: s.camera.clone(),
                    width,
                    height,
                });
            }
        }
    }
    let schedule = spec.header.schedule;
    let bar = progress.bar("timed frames", units.len() as u64 * schedule.repeats as u64);
    let mut clocks = vec![Clock::WallClock; units.len()];
    let times = schedule.run(units.len(), |i| -> anyhow::Result<f64> {
        let u = &units[i];
        let view = View {
            camera: &u.scene.cameras[&u.camera],
            width: u.width,
            height: u.height,
        };
        let t = backend.time(&u.scene, view, spec.sampling, schedule.warmup, 1)?;
        clocks[i] = t.clock;
        bar.inc(1);
        Ok(t.seconds[0])
    })?;
    bar.finish();
    for ((row, seconds), clock) in rows.iter_mut().zip(times).zip(clocks) {
        row.frame = median_interval(&seconds);
        row.frame_seconds = seconds;
        row.clock = clock;
    }
    Ok(rows)
}

/// What `--dry-run` prints: the render plan of every configuration of the scenes at `which`.
pub fn dry_run(spec: &FpsSpec, which: &[usize]) -> anyhow::Result<String> {
    let mut out = String::new();
    for s in which.iter().map(|&i| &spec.scenes[i]) {
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
