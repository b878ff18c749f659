//! The experiment file: which scene, what to measure, which axes to sweep. Validated into a
//! [`Spec`] with every error located in the file.

pub use super::axes::Axes;
use crate::accel::{AccelSettings, Accelerator};
use crate::config::{ConfigError, Source};
use crate::experiment::kind::Kind;
use crate::key_path;
use crate::render::BackendChoice;
use crate::scene::camera::Projection;
use crate::scene::{Light, Scene, MAX_SAMPLES};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    #[serde(default)]
    kind: Kind,
    name: String,
    scene: PathBuf,
    #[serde(default = "default_backend")]
    backend: BackendChoice,
    measure: Measure,
    sweep: Axes,
    ground_truth: GroundTruth,
    #[serde(default)]
    timing: TimingSpec,
    figures: Option<Figures>,
}

fn default_backend() -> BackendChoice {
    BackendChoice::Auto
}

/// The measuring view: an orthographic camera over the receiver plane.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Measure {
    /// Camera name in the scene; must be orthographic.
    pub camera: String,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Index of the receiver plane (radial profiles and exact references are taken on it).
    #[serde(default)]
    pub plane: usize,
}

/// The high-sample reference image.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GroundTruth {
    /// Jittered shadow rays per pixel (thousands).
    pub samples: u32,
}

/// Frame timing (see [`super::timing`]).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TimingSpec {
    /// Untimed frames rendered right before each timed frame.
    pub warmup: u32,
    /// Interleaved rounds, one timed frame per configuration each; the median and quartiles
    /// are reported. 0 disables timing (runs.csv is then byte-reproducible: times are the only
    /// values that vary between identical runs); otherwise at least [`MIN_TIMED_REPEATS`].
    pub repeats: u32,
}

/// Fewest timed frames per configuration that give a median and an interquartile range.
pub const MIN_TIMED_REPEATS: u32 = 5;

impl Default for TimingSpec {
    fn default() -> Self {
        TimingSpec { warmup: 1, repeats: 5 }
    }
}

/// Fig. 2-style pictures: the same view rendered with several schemes at one shadow-ray count.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Figures {
    /// Camera name in the scene.
    pub camera: String,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Shadow rays per pixel of the compared images (the paper: 16).
    pub samples: u32,
    /// Shadow rays per pixel of the reference picture.
    pub ground_truth_samples: u32,
}

/// A validated experiment.
#[derive(Clone, Debug)]
pub struct Spec {
    /// Experiment name (the results folder's name).
    pub name: String,
    /// The experiment file.
    pub path: PathBuf,
    /// The scene file.
    pub scene_path: PathBuf,
    /// The scene's text, hashed into run keys so that editing the scene invalidates results.
    pub scene_text: String,
    /// The scene.
    pub scene: Scene,
    /// Renderer choice.
    pub backend: BackendChoice,
    /// Measuring view.
    pub measure: Measure,
    /// Swept axes.
    pub axes: Axes,
    /// Each swept acceleration structure, built once over the scene's triangles (None without
    /// triangles).
    pub structures: BTreeMap<String, Option<Arc<dyn Accelerator>>>,
    /// Ground-truth settings.
    pub ground_truth: GroundTruth,
    /// Timing settings.
    pub timing: TimingSpec,
    /// Optional pictures.
    pub figures: Option<Figures>,
}

impl Spec {
    /// Reads and validates an experiment file and the scene it names (relative to it).
    pub fn load(path: &Path) -> Result<Spec, ConfigError> {
        Spec::from_source(&Source::read(path)?)
    }

    /// Validates an experiment read from its file (`source`) and loads the scene it names.
    pub fn from_source(source: &Source) -> Result<Spec, ConfigError> {
        let path = source.path.as_path();
        let f: File = source.parse()?;
        let err = |p: &[crate::config::Seg], m: String| source.error(p, m);
        if f.kind != Kind::Sweep {
            return Err(err(&key_path!["kind"], "a sweep has kind = \"sweep\" (or none)".into()));
        }
        let scene_path = path.parent().unwrap_or(Path::new(".")).join(&f.scene);
        if !scene_path.is_file() {
            return Err(err(
                &key_path!["scene"],
                format!("scene file {} does not exist", scene_path.display()),
            ));
        }
        let scene = Scene::load(&scene_path)?;
        let scene_text = std::fs::read_to_string(&scene_path).unwrap_or_default();
        if f.name.is_empty()
            || !f
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        {
            return Err(err(
                &key_path!["name"],
                "must be non-empty letters, digits, '-' or '_'".into(),
            ));
        }
        let m = &f.measure;
        match scene.cameras.get(&m.camera) {
            None => {
                return Err(err(
                    &key_path!["measure", "camera"],
                    format!("no camera `{}` in {}", m.camera, scene_path.display()),
                ))
            }
            Some(c) if !matches!(c.projection, Projection::Orthographic { .. }) => {
                return Err(err(
                    &key_path!["measure", "camera"],
                    "the measuring camera must be orthographic".into(),
                ))
            }
            _ => {}
        }
        for (k, v) in [("width", m.width), ("height", m.height)] {
            if !(1..=16384).contains(&v) {
                return Err(err(&key_path!["measure", k], format!("must be in 1..=16384, got {v}")));
            }
        }
        let mut axes = f.sweep;
        if axes.light_counts.is_empty() {
            axes.light_counts = vec![scene.lights.len() as u32];
        }
        if axes.accelerators.is_empty() {
            axes.accelerators = vec![scene.accel_settings.name.to_string()];
        }
        let mut structures = BTreeMap::new();
        for (i, name) in axes.accelerators.iter().enumerate() {
            let Some(r) = crate::accel::registered(name) else {
                return Err(err(
                    &key_path!["sweep", "accelerators", i],
                    format!(
                        "unknown acceleration structure `{name}`; known: {}",
                        crate::accel::names().join(", ")
                    ),
                ));
            };
            let settings = AccelSettings {
                name: r.name,
                ..scene.accel_settings.clone()
            };
            let built = if settings == scene.accel_settings {
                scene.accel.clone()
            } else {
                crate::accel::build(&scene.triangles, &settings)
                    .map_err(|e| err(&key_path!["sweep", "accelerators", i], format!("{e:#}")))?
            };
            structures.insert(name.clone(), built);
        }
        if scene.triangles.positions.is_empty() {
            // Nothing for a structure to index: every structure would render the same frames,
            // and rows would name a structure that answered no ray.
            if let Some(i) = axes.accelerators.iter().position(|n| n != scene.accel_settings.name) {
                return Err(err(
                    &key_path!["sweep", "accelerators", i],
                    format!(
                        "the scene has no triangle meshes for `{}` to index; sweep structures over a scene with meshes",
                        axes.accelerators[i]
                    ),
                ));
            }
        }
        if !scene.lights.iter().any(|l| matches!(l, Light::Disk(_))) {
            return Err(err(
                &key_path!["scene"],
                format!("{} has no disk light to sweep", scene_path.display()),
            ));
        }
        for (i, &k) in axes.light_counts.iter().enumerate() {
            if k == 0 || k as usize > scene.lights.len() {
                return Err(err(
                    &key_path!["sweep", "light_counts", i],
                    format!("must be in 1..={}, the scene's lights", scene.lights.len()),
                ));
            }
        }
        if scene.plane(m.plane).is_none() {
            return Err(err(
                &key_path!["measure", "plane"],
                format!("the scene has {} planes", scene.planes().count()),
            ));
        }
        let a = &axes;
        let lists = a.texts();
        for (axis, values) in &lists {
            if values.is_empty() {
                return Err(err(
                    &key_path!["sweep", axis.list_key()],
                    "must list at least one value".into(),
                ));
            }
        }
        for (i, &n) in a.samples.iter().enumerate() {
            if !(1..=MAX_SAMPLES).contains(&n) {
                return Err(err(
                    &key_path!["sweep", "samples", i],
                    format!("shadow-ray count must be in 1..={MAX_SAMPLES}, got {n}"),
                ));
            }
        }
        for (i, &r) in a.light_radii.iter().enumerate() {
            if !(r.is_finite() && r > 0.0) {
                return Err(err(
                    &key_path!["sweep", "light_radii", i],
                    format!("light radius must be positive, got {r}"),
                ));
            }
        }
        for (axis, values) in &lists {
            for (i, v) in values.iter().enumerate() {
                if values[..i].contains(v) {
                    return Err(err(
                        &key_path!["sweep", axis.list_key(), i],
                        format!("`{v}` is listed twice"),
                    ));
                }
            }
        }
        if !(1..=MAX_SAMPLES).contains(&f.ground_truth.samples) {
            return Err(err(
                &key_path!["ground_truth", "samples"],
                format!("must be in 1..={MAX_SAMPLES}"),
            ));
        }
        let t = &f.timing;
        if t.repeats != 0 && !(MIN_TIMED_REPEATS..=1000).contains(&t.repeats) {
            return Err(err(
                &key_path!["timing", "repeats"],
                format!(
                    "must be 0 (no timing) or in {MIN_TIMED_REPEATS}..=1000 (a median and quartiles need at least {MIN_TIMED_REPEATS} frames), got {}",
                    t.repeats
                ),
            ));
        }
        if t.warmup > 100 {
            return Err(err(
                &key_path!["timing", "warmup"],
                format!("must be in 0..=100, got {}", t.warmup),
            ));
        }
        if let Some(fig) = &f.figures {
            if !scene.cameras.contains_key(&fig.camera) {
                return Err(err(
                    &key_path!["figures", "camera"],
                    format!("no camera `{}` in the scene", fig.camera),
                ));
            }
            for (k, v) in [("width", fig.width), ("height", fig.height)] {
                if !(1..=8192).contains(&v) {
                    return Err(err(&key_path!["figures", k], format!("must be in 1..=8192, got {v}")));
                }
            }
            for (k, v) in [
                ("samples", fig.samples),
                ("ground_truth_samples", fig.ground_truth_samples),
            ] {
                if !(1..=MAX_SAMPLES).contains(&v) {
                    return Err(err(
                        &key_path!["figures", k],
                        format!("must be in 1..={MAX_SAMPLES}, got {v}"),
                    ));
                }
            }
        }
        Ok(Spec {
            name: f.name,
            path: path.to_path_buf(),
            scene_path,
            scene_text,
            scene,
            backend: f.backend,
            measure: f.measure,
            axes,
            structures,
            ground_truth: f.ground_truth,
            timing: f.timing,
            figures: f.figures,
        })
    }

    /// The scene with its first `lights` lights on, every disk light among them set to `radius`
    /// and `samples`, its triangles indexed by the swept structure `accelerator`.
    pub fn scene_with(&self, lights: u32, radius: f64, samples: u32, accelerator: &str) -> Scene {
        let mut scene = self.scene.clone();
        if let (Some(s), Some(r)) = (self.structures.get(accelerator), crate::accel::registered(accelerator)) {
            scene.accel = s.clone();
            scene.accel_settings.name = r.name;
        }
        scene.lights.truncate(lights as usize);
        for l in &mut scene.lights {
            if let Light::Disk(d) = l {
                d.radius = radius;
                d.samples = samples;
            }
        }
        scene
    }
}
