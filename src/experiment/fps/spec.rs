//! The frame-rate experiment file: scenes x light counts x resolutions, timed at one sampling.

use crate::config::{ConfigError, Source};
use crate::experiment::comparison::SettingsPlaces;
use crate::experiment::header::{plain_name, Header};
use crate::key_path;
use crate::render::Sampling;
use crate::sampling::{DiskScheme, Pattern};
use crate::scene::load::MAX_EXTENT;
use crate::scene::{Light, Scene, MAX_SAMPLES};
use serde::Deserialize;
use std::path::{Path, PathBuf};

crate::experiment_file! {
    /// A frame-rate experiment's file: the shared header and these keys.
    struct File {
        samples: u32,
        light_radius: f64,
        scheme: DiskScheme,
        pattern: Pattern,
        resolutions: Vec<[u32; 2]>,
        scenes: Vec<SceneEntry>,
    }
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
    /// The shared keys; `[timing] repeats` are the interleaved rounds, one timed frame of every
    /// configuration each (the paper timed 100 frames of one).
    pub header: Header,
    /// Results folder name.
    pub name: String,
    /// The experiment file.
    pub path: PathBuf,
    /// Every scene file read.
    pub scene_paths: Vec<PathBuf>,
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
    /// Where each resolution and each scene's structure are set, for refusals known only when
    /// a frame is uploaded.
    pub places: SettingsPlaces,
}

impl FpsSpec {
    /// Reads and validates a frame-rate experiment and its scenes.
    pub fn load(path: &Path) -> Result<FpsSpec, ConfigError> {
        let source = Source::read(path)?;
        FpsSpec::from_source(&source, Header::read(&source)?)
    }

    /// Validates a frame-rate experiment read from its file (`source`, shared keys `header`)
    /// and loads its scenes.
    pub fn from_source(source: &Source, header: Header) -> Result<FpsSpec, ConfigError> {
        let path = source.path.as_path();
        let f: File = source.parse()?;
        if !f.scheme.is_built_in() {
            return Err(source.error(
                &key_path!["scheme"],
                format!(
                    "`{}`: points files are swept by sweep experiments; fps takes a built-in scheme",
                    f.scheme
                ),
            ));
        }
        if f.samples > f.scheme.max_samples() {
            return Err(source.error(
                &key_path!["samples"],
                format!(
                    "{} gives at most {} samples per pixel, got {}",
                    f.scheme,
                    f.scheme.max_samples(),
                    f.samples
                ),
            ));
        }
        if !(1..=MAX_SAMPLES).contains(&f.samples) {
            return Err(source.error(
                &key_path!["samples"],
                format!("must be in 1..={MAX_SAMPLES}, got {}", f.samples),
            ));
        }
        if !(f.light_radius.is_finite() && f.light_radius > 0.0 && f.light_radius <= MAX_EXTENT) {
            return Err(source.error(
                &key_path!["light_radius"],
                format!("must be positive and at most {MAX_EXTENT:e} m, got {}", f.light_radius),
            ));
        }
        if f.resolutions.is_empty() {
            return Err(source.error(&key_path!["resolutions"], "list at least one [width, height]"));
        }
        for (i, r) in f.resolutions.iter().enumerate() {
            source.image_size(
                &key_path!["resolutions", i, 0usize],
                &key_path!["resolutions", i, 1usize],
                r[0],
                r[1],
            )?;
            if f.resolutions[..i].contains(r) {
                return Err(source.error(
                    &key_path!["resolutions", i],
                    format!("{} x {} is listed twice", r[0], r[1]),
                ));
            }
        }
        if f.scenes.is_empty() {
            return Err(source.error(&key_path!["scenes"], "list at least one [[scenes]] table"));
        }
        let mut scenes = Vec::new();
        let mut scene_paths = Vec::new();
        let mut structures = std::collections::BTreeMap::new();
        for (i, e) in f.scenes.iter().enumerate() {
            plain_name(&e.name).map_err(|m| source.error(&key_path!["scenes", i, "name"], m))?;
            if f.scenes[..i].iter().any(|o| o.name == e.name) {
                return Err(source.error(&key_path!["scenes", i, "name"], format!("`{}` is listed twice", e.name)));
            }
            let scene_path = path.parent().unwrap_or(Path::new(".")).join(&e.scene);
            let scene_source = Source::read(&scene_path).map_err(|err| {
                source.error(
                    &key_path!["scenes", i, "scene"],
                    format!("{}: {}", scene_path.display(), err.message),
                )
            })?;
            let scene = Scene::from_source(&scene_source)?;
            structures
                .entry(scene.accel_settings.name)
                .or_insert_with(|| scene_source.error(&key_path!["accelerator"], String::new()));
            scene_paths.push(scene_path);
            if !scene.cameras.contains_key(&e.camera) {
                return Err(source.error(
                    &key_path!["scenes", i, "camera"],
                    format!("no camera `{}` in {}", e.camera, e.scene.display()),
                ));
            }
            if e.lights.is_empty() {
                return Err(source.error(&key_path!["scenes", i, "lights"], "list at least one light count"));
            }
            if e.lights.iter().any(|&k| k == 0 || k as usize > scene.lights.len()) {
                return Err(source.error(
                    &key_path!["scenes", i, "lights"],
                    format!("must be in 1..={}", scene.lights.len()),
                ));
            }
            if let Some(k) = (0..e.lights.len()).find(|&k| e.lights[..k].contains(&e.lights[k])) {
                return Err(source.error(
                    &key_path!["scenes", i, "lights", k],
                    format!("`{}` is listed twice", e.lights[k]),
                ));
            }
            if let Some(k) = e.lights.iter().position(|&n| {
                !scene.lights[..n as usize]
                    .iter()
                    .any(|l| matches!(l, crate::scene::Light::Disk(_)))
            }) {
                return Err(source.error(
                    &key_path!["scenes", i, "lights", k],
                    format!(
                        "the scene's first {} light(s) hold no disk light: nothing would sample the scheme and radius",
                        e.lights[k]
                    ),
                ));
            }
            if e.paper_fps.len() != e.lights.len() {
                return Err(source.error(
                    &key_path!["scenes", i, "paper_fps"],
                    "needs one value per entry of `lights`",
                ));
            }
            if let Some(k) = e.paper_fps.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(source.error(
                    &key_path!["scenes", i, "paper_fps", k],
                    format!("the paper's frames per second must be positive, got {}", e.paper_fps[k]),
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
            name: header.name.clone(),
            header,
            path: path.to_path_buf(),
            scene_paths,
            samples: f.samples,
            light_radius: f.light_radius,
            sampling: Sampling {
                scheme: f.scheme,
                pattern: f.pattern,
                seed: 1,
                frame: 0,
            },
            places: SettingsPlaces::new(
                structures,
                f.resolutions
                    .iter()
                    .enumerate()
                    .map(|(i, r)| ((r[0], r[1]), source.error(&key_path!["resolutions", i], String::new())))
                    .collect(),
            ),
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
