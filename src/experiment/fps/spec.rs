//! The frame-rate experiment file: scenes x light counts x resolutions, timed at one sampling.

use crate::config::{ConfigError, Source};
use crate::experiment::kind::Kind;
use crate::key_path;
use crate::render::Sampling;
use crate::sampling::{DiskScheme, Pattern};
use crate::scene::{Light, Scene, MAX_SAMPLES};
use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    kind: Kind,
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

impl FpsSpec {
    /// Reads and validates a frame-rate experiment and its scenes.
    pub fn load(path: &Path) -> Result<FpsSpec, ConfigError> {
        FpsSpec::from_source(&Source::read(path)?)
    }

    /// Validates a frame-rate experiment read from its file (`source`) and loads its scenes.
    pub fn from_source(source: &Source) -> Result<FpsSpec, ConfigError> {
        let path = source.path.as_path();
        let f: File = source.parse()?;
        if f.kind != Kind::Fps {
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
