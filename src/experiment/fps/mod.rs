//! Frame-rate experiments: the soft-shadow paper's Table 1 (frames per second over 100 frames,
//! 16 shadow rays per pixel, sphere and dressed body, one and two lights) on today's adapter,
//! with the paper's numbers beside ours.

pub mod report;

use crate::config::{ConfigError, Source};
use crate::key_path;
use crate::metrics::stats::median;
use crate::render::{AdapterInfo, Backend, Clock, Sampling, View};
use crate::sampling::{DiskScheme, Pattern};
use crate::scene::{Light, Scene, MAX_SAMPLES};
use anyhow::Context;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    kind: String,
    name: String,
    frames: u32,
    warmup: u32,
    max_seconds: f64,
    samples: u32,
    light_radius: f64,
    scheme: DiskScheme,
    pattern: Pattern,
    resolutions: Vec<[u32; 2]>,
    scenes: Vec<SceneEntry>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneEntry {
    name: String,
    scene: PathBuf,
    camera: String,
    lights: Vec<u32>,
    paper_fps: Vec<f64>,
}

/// One scene of a frame-rate experiment, loaded.
#[derive(Clone, Debug)]
pub struct FpsScene {
    /// Label.
    pub name: String,
    /// The scene.
    pub scene: Scene,
    /// Camera name.
    pub camera: String,
    /// Light counts to time.
    pub lights: Vec<u32>,
    /// The paper's frames per second for each light count.
    pub paper_fps: Vec<f64>,
}

/// A validated frame-rate experiment.
#[derive(Clone, Debug)]
pub struct FpsSpec {
    /// Results folder name.
    pub name: String,
    /// The experiment file.
    pub path: PathBuf,
    /// Frames timed per configuration (the paper: 100), unless `max_seconds` runs out first.
    pub frames: u32,
    /// Untimed frames first.
    pub warmup: u32,
    /// Time budget per configuration; at least 3 frames are timed whatever it says.
    pub max_seconds: f64,
    /// Shadow rays per pixel per light (the paper: 16).
    pub samples: u32,
    /// Disk light radius (the paper: 0.02 m).
    pub light_radius: f64,
    /// Sampling scheme and pattern (the paper: its own, precomputed and shared).
    pub sampling: Sampling,
    /// Image sizes.
    pub resolutions: Vec<[u32; 2]>,
    /// Scenes.
    pub scenes: Vec<FpsScene>,
}

/// Whether a TOML file is a frame-rate experiment (`kind = "fps"`).
pub fn is_fps(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok())
        .is_some_and(|t| t.get("kind").and_then(|k| k.as_str()) == Some("fps"))
}

impl FpsSpec {
    /// Reads and validates a frame-rate experiment and its scenes.
    pub fn load(path: &Path) -> Result<FpsSpec, ConfigError> {
        let source = Source::read(path)?;
        let f: File = source.parse()?;
        if f.kind != "fps" {
            return Err(source.error(&key_path!["kind"], "a frame-rate experiment has kind = \"fps\""));
        }
        for (k, v) in [("frames", f.frames), ("samples", f.samples)] {
            if !(1..=MAX_SAMPLES).contains(&v) {
                return Err(source.error(&key_path![k], format!("must be in 1..={MAX_SAMPLES}, got {v}")));
            }
        }
        if !(f.max_seconds.is_finite() && f.max_seconds > 0.0) {
            return Err(source.error(&key_path!["max_seconds"], "must be positive"));
        }
        if !(f.light_radius.is_finite() && f.light_radius > 0.0) {
            return Err(source.error(&key_path!["light_radius"], "must be positive"));
        }
        for (i, r) in f.resolutions.iter().enumerate() {
            if r.iter().any(|&x| !(1..=16384).contains(&x)) {
                return Err(source.error(&key_path!["resolutions", i], "width and height must be in 1..=16384"));
            }
        }
        let mut scenes = Vec::new();
        for (i, e) in f.scenes.iter().enumerate() {
            let scene = Scene::load(&path.parent().unwrap_or(Path::new(".")).join(&e.scene))?;
            if !scene.cameras.contains_key(&e.camera) {
                return Err(source.error(
                    &key_path!["scenes", i, "camera"],
                    format!("no camera `{}` in {}", e.camera, e.scene.display()),
                ));
            }
            if e.lights.iter().any(|&k| k == 0 || k as usize > scene.lights.len()) {
                return Err(source.error(
                    &key_path!["scenes", i, "lights"],
                    format!("must be in 1..={}", scene.lights.len()),
                ));
            }
            if e.paper_fps.len() != e.lights.len() {
                return Err(source.error(
                    &key_path!["scenes", i, "paper_fps"],
                    "needs one value per entry of `lights`",
                ));
            }
            scenes.push(FpsScene {
                name: e.name.clone(),
                scene,
                camera: e.camera.clone(),
                lights: e.lights.clone(),
                paper_fps: e.paper_fps.clone(),
            });
        }
        Ok(FpsSpec {
            name: f.name,
            path: path.to_path_buf(),
            frames: f.frames,
            warmup: f.warmup,
            max_seconds: f.max_seconds,
            samples: f.samples,
            light_radius: f.light_radius,
            sampling: Sampling {
                scheme: f.scheme,
                pattern: f.pattern,
                seed: 1,
            },
            resolutions: f.resolutions,
            scenes,
        })
    }
}

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

/// The scene `s` as timed with `lights` lights on: each disk light at the experiment's radius
/// and ray count.
pub fn timed_scene(spec: &FpsSpec, s: &FpsScene, lights: u32) -> Scene {
    let mut scene = s.scene.clone();
    scene.lights.truncate(lights as usize);
    for l in &mut scene.lights {
        if let Light::Disk(d) = l {
            d.radius = spec.light_radius;
            d.samples = spec.samples;
        }
    }
    scene
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

/// fps.csv header.
pub const FPS_COLUMNS: [&str; 18] = [
    "scene",
    "lights",
    "width",
    "height",
    "samples",
    "frames",
    "median_ms",
    "min_ms",
    "max_ms",
    "fps",
    "paper_fps",
    "primary_rays",
    "shadow_rays",
    "shadow_rays_per_s",
    "clock",
    "adapter",
    "driver",
    "api",
];

/// fps.csv row.
pub fn fps_row(spec: &FpsSpec, r: &FpsRow, a: &AdapterInfo) -> Vec<String> {
    use crate::experiment::sweep::run::num;
    vec![
        r.scene.clone(),
        r.lights.to_string(),
        r.width.to_string(),
        r.height.to_string(),
        spec.samples.to_string(),
        r.frames.to_string(),
        num(r.median_s * 1e3),
        num(r.min_s * 1e3),
        num(r.max_s * 1e3),
        num(r.fps()),
        num(r.paper_fps),
        r.primary_rays.to_string(),
        r.shadow_rays.to_string(),
        num(r.shadow_rays_per_s()),
        r.clock.name().to_string(),
        a.name.clone(),
        a.driver.clone(),
        a.api.clone(),
    ]
}
