//! The experiment file: which scene, what to measure, which axes to sweep. Validated into a
//! [`Spec`] with every error located in the file.

pub use super::axes::Axes;
use crate::accel::Accelerator;
use crate::config::{ConfigError, Source};
use crate::experiment::comparison::SettingsPlaces;
use crate::experiment::header::Header;
use crate::key_path;
use crate::render::{BackendChoice, RenderPlan, View};
use crate::sampling::points;
use crate::sampling::DiskScheme;
use crate::scene::camera::Projection;
use crate::scene::{Light, Scene, MAX_SAMPLES};
use crate::timing::Schedule;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

crate::experiment_file! {
    /// A sweep's file: the shared header and these keys.
    struct File {
        scene: PathBuf,
        measure: Measure,
        sweep: Axes,
        ground_truth: GroundTruth,
        figures: Option<Figures>,
        #[serde(default)]
        points: BTreeMap<String, points::Table>,
        verdict: Option<VerdictPair>,
        timed: Option<Timed>,
    }
}

/// `[timed]`: which swept ray counts are timed (default: all). The equal-time curves
/// interpolate between timed counts only, so leaving out the costliest count (half of all the
/// frames at 128 rays of a 1-128 sweep) halves the timing and narrows only the budgets that
/// would need it.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Timed {
    /// Shadow-ray counts timed, each one of `sweep.samples`.
    pub samples: Vec<u32>,
}

/// `[verdict]`: the two schemes the verdict compares (default: the paper's pattern against
/// uniform sampling, the 2012 paper's claim).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct VerdictPair {
    /// The scheme whose claim is judged.
    pub subject: DiskScheme,
    /// What it is judged against.
    pub baseline: DiskScheme,
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

/// Largest swept light radius, in multiples of the lowest swept disk light's height over the
/// measured plane.
pub const MAX_RADIUS_PER_HEIGHT: f64 = 100.0;

/// Most runs one sweep expands to (the product of its axes' lengths): every run is held in
/// memory, keyed and journaled.
pub const MAX_RUNS: usize = 1_000_000;

/// A validated experiment.
#[derive(Clone, Debug)]
pub struct Spec {
    /// The shared keys.
    pub header: Header,
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
    /// How configurations are timed (`[timing]`; `repeats = 0` times nothing).
    pub timing: Schedule,
    /// Optional pictures.
    pub figures: Option<Figures>,
    /// The verdict's (subject, baseline).
    pub verdict: (DiskScheme, DiskScheme),
    /// The ray counts timed (`[timed]`; default every swept count).
    pub timed_samples: Vec<u32>,
    /// Where each swept structure (and the scene's own, which renders the ground truths) and
    /// the measured and figures' frame sizes are set, for refusals known only when a frame is
    /// uploaded.
    pub places: SettingsPlaces,
}

impl Spec {
    /// Reads and validates an experiment file and the scene it names (relative to it).
    pub fn load(path: &Path) -> Result<Spec, ConfigError> {
        let source = Source::read(path)?;
        Spec::from_source(&source, Header::read(&source)?)
    }

    /// Validates a sweep read from its file (`source`, whose shared keys are `header`) and
    /// loads the scene it names.
    pub fn from_source(source: &Source, header: Header) -> Result<Spec, ConfigError> {
        let path = source.path.as_path();
        let f: File = source.parse().map_err(|e| read_as_sweep(e, &header))?;
        let err = |p: &[crate::config::Seg], m: String| source.error(p, m);
        let scene_path = path.parent().unwrap_or(Path::new(".")).join(&f.scene);
        let scene_source = Source::read(&scene_path)
            .map_err(|e| err(&key_path!["scene"], format!("{}: {}", scene_path.display(), e.message)))?;
        let scene = Scene::from_source(&scene_source)?;
        // The ground truths and the figures' reference render with the scene's own structure.
        let scene_structure = scene_source.error(&key_path!["accelerator"], String::new());
        let scene_text = scene_source.text;
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
        source.image_size(
            &key_path!["measure", "width"],
            &key_path!["measure", "height"],
            m.width,
            m.height,
        )?;
        let mut axes = f.sweep;
        if axes.light_counts.is_empty() {
            axes.light_counts = vec![scene.lights.len() as u32];
        }
        if axes.accelerators.is_empty() {
            axes.accelerators = vec![scene.accel_settings.name.to_string()];
        }
        // The lists are checked before anything is built or expanded over them.
        let lists = axes.texts();
        let mut runs = 1u128;
        for (axis, values) in &lists {
            if values.is_empty() {
                return Err(err(
                    &key_path!["sweep", axis.list_key()],
                    "must list at least one value".into(),
                ));
            }
            let mut seen = std::collections::HashSet::new();
            if let Some(i) = values.iter().position(|v| !seen.insert(v)) {
                return Err(err(
                    &key_path!["sweep", axis.list_key(), i],
                    format!("`{}` is listed twice", values[i]),
                ));
            }
            runs *= values.len() as u128;
        }
        if runs > MAX_RUNS as u128 {
            return Err(err(
                &key_path!["sweep"],
                format!("the axes multiply to {runs} runs, more than the {MAX_RUNS} one sweep may hold; split it with --filter or shorten the lists"),
            ));
        }
        let mut structures = BTreeMap::new();
        let mut places = BTreeMap::new();
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
            let settings = scene.settings_for(r);
            let built = if settings == scene.accel_settings {
                scene.accel.clone()
            } else {
                crate::accel::build(&scene.triangles, &settings)
                    .map_err(|e| err(&key_path!["sweep", "accelerators", i], format!("{e:#}")))?
            };
            structures.insert(name.clone(), built);
            places.insert(r.name, err(&key_path!["sweep", "accelerators", i], String::new()));
        }
        places.entry(scene.accel_settings.name).or_insert(scene_structure);
        let mut frames = vec![((m.width, m.height), err(&key_path!["measure", "width"], String::new()))];
        if let Some(fig) = &f.figures {
            frames.push((
                (fig.width, fig.height),
                err(&key_path!["figures", "width"], String::new()),
            ));
        }
        let places = SettingsPlaces::new(places, frames);
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
            // Rows would name a scheme and a radius that nothing sampled.
            if !scene.lights[..k as usize].iter().any(|l| matches!(l, Light::Disk(_))) {
                return Err(err(
                    &key_path!["sweep", "light_counts", i],
                    format!("the scene's first {k} light(s) hold no disk light: nothing would sample the swept schemes and radii"),
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
        for (i, &n) in a.samples.iter().enumerate() {
            if !(1..=MAX_SAMPLES).contains(&n) {
                return Err(err(
                    &key_path!["sweep", "samples", i],
                    format!("shadow-ray count must be in 1..={MAX_SAMPLES}, got {n}"),
                ));
            }
            if let Some(s) = a.schemes.iter().find(|s| s.is_built_in() && n > s.max_samples()) {
                return Err(err(
                    &key_path!["sweep", "samples", i],
                    format!("{s} gives at most {} samples per pixel, got {n}", s.max_samples()),
                ));
            }
        }
        // A disk light far larger than its height over the measured plane is no light over
        // this scene (and would only exhaust the exact answer's quadrature).
        let (_, measured) = scene.plane(m.plane).expect("checked above");
        let lowest = scene
            .lights
            .iter()
            .take(*a.light_counts.iter().max().unwrap_or(&1) as usize)
            .filter_map(|l| match l {
                Light::Disk(d) => Some((d.center - measured.point).dot(measured.normal).abs()),
                _ => None,
            })
            .fold(f64::INFINITY, f64::min);
        for (i, &r) in a.light_radii.iter().enumerate() {
            if !(r.is_finite() && r > 0.0) {
                return Err(err(
                    &key_path!["sweep", "light_radii", i],
                    format!("light radius must be positive, got {r}"),
                ));
            }
            if r > MAX_RADIUS_PER_HEIGHT * lowest {
                return Err(err(
                    &key_path!["sweep", "light_radii", i],
                    format!(
                        "a {r} m light is more than {MAX_RADIUS_PER_HEIGHT} times its {lowest:.3} m height over the measured plane"
                    ),
                ));
            }
        }
        if !(1..=MAX_SAMPLES).contains(&f.ground_truth.samples) {
            return Err(err(
                &key_path!["ground_truth", "samples"],
                format!("must be in 1..={MAX_SAMPLES}"),
            ));
        }
        if let Some(fig) = &f.figures {
            if !scene.cameras.contains_key(&fig.camera) {
                return Err(err(
                    &key_path!["figures", "camera"],
                    format!("no camera `{}` in the scene", fig.camera),
                ));
            }
            source.image_size(
                &key_path!["figures", "width"],
                &key_path!["figures", "height"],
                fig.width,
                fig.height,
            )?;
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
            if let Some(s) = a
                .schemes
                .iter()
                .find(|s| s.is_built_in() && fig.samples > s.max_samples())
            {
                return Err(err(
                    &key_path!["figures", "samples"],
                    format!(
                        "{s} gives at most {} samples per pixel, got {}",
                        s.max_samples(),
                        fig.samples
                    ),
                ));
            }
        }
        let needed = a
            .samples
            .iter()
            .chain(f.figures.as_ref().map(|f| &f.samples))
            .copied()
            .max()
            .unwrap_or(1);
        points::load_all(source, &mut axes.schemes, &f.points, needed)?;
        let verdict = match &f.verdict {
            None => (DiskScheme::Paper, DiskScheme::Uniform),
            Some(v) => {
                for (key, scheme) in [("subject", v.subject), ("baseline", v.baseline)] {
                    if !axes.schemes.contains(&scheme) {
                        return Err(err(
                            &key_path!["verdict", key],
                            format!("`{scheme}` is not in sweep.schemes"),
                        ));
                    }
                }
                if v.subject == v.baseline {
                    return Err(err(
                        &key_path!["verdict", "baseline"],
                        "the verdict compares two different schemes".into(),
                    ));
                }
                (v.subject, v.baseline)
            }
        };
        let timed_samples = match &f.timed {
            None => axes.samples.clone(),
            Some(t) => {
                if t.samples.is_empty() {
                    return Err(err(
                        &key_path!["timed", "samples"],
                        "name at least one swept ray count to time (or leave [timed] out to time every count)".into(),
                    ));
                }
                for (i, n) in t.samples.iter().enumerate() {
                    if !axes.samples.contains(n) {
                        return Err(err(
                            &key_path!["timed", "samples", i],
                            format!("{n} is not in sweep.samples {:?}", axes.samples),
                        ));
                    }
                    if t.samples[..i].contains(n) {
                        return Err(err(&key_path!["timed", "samples", i], format!("{n} is listed twice")));
                    }
                }
                t.samples.clone()
            }
        };
        Ok(Spec {
            timed_samples,
            verdict,
            name: header.name.clone(),
            path: path.to_path_buf(),
            scene_path,
            scene_text,
            scene,
            backend: header.backend.unwrap_or(BackendChoice::Auto),
            timing: header.schedule,
            header,
            measure: f.measure,
            axes,
            structures,
            ground_truth: f.ground_truth,
            figures: f.figures,
            places,
        })
    }

    /// Shadow-ray count whose images and profiles are kept for figures (the paper's 16, or the
    /// nearest swept count).
    pub fn figure_samples(&self) -> u32 {
        let want = self.figures.as_ref().map_or(16, |f| f.samples);
        *self
            .axes
            .samples
            .iter()
            .min_by_key(|&&n| (n as i64 - want as i64).abs())
            .expect("validated non-empty")
    }

    /// The render plan of the sweep's fullest run (most lights, first radius, the figures' ray
    /// count, first swept structure): logged with every sweep and printed by `--dry-run`.
    pub fn plan(&self) -> anyhow::Result<RenderPlan> {
        let lights = *self.axes.light_counts.iter().max().expect("validated non-empty");
        let s = self.scene_with(
            lights,
            self.axes.light_radii[0],
            self.figure_samples(),
            &self.axes.accelerators[0],
        );
        let view = View {
            camera: &s.cameras[&self.measure.camera],
            width: self.measure.width,
            height: self.measure.height,
        };
        RenderPlan::new(&s, view)
    }

    /// The light radius the verdict is read at: the paper's 2 cm if swept, else the nearest.
    pub fn verdict_radius(&self) -> f64 {
        *self
            .axes
            .light_radii
            .iter()
            .min_by(|a, b| (*a - 0.02).abs().total_cmp(&(*b - 0.02).abs()))
            .expect("validated non-empty")
    }

    /// Every points file the sweep reads, for the manifest.
    pub fn points_files(&self) -> Vec<PathBuf> {
        self.axes
            .schemes
            .iter()
            .filter_map(|s| match s {
                DiskScheme::Points(id) => id.set().map(|set| set.files.clone()),
                _ => None,
            })
            .flatten()
            .collect()
    }

    /// The scene with its first `lights` lights on, every disk light among them set to `radius`
    /// and `samples`, its triangles indexed by the swept structure `accelerator`.
    pub fn scene_with(&self, lights: u32, radius: f64, samples: u32, accelerator: &str) -> Scene {
        let mut scene = self.scene.clone();
        if let (Some(s), Some(r)) = (self.structures.get(accelerator), crate::accel::registered(accelerator)) {
            scene.accel = s.clone();
            scene.accel_settings = self.scene.settings_for(r);
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

/// A key a sweep does not know, in a file without `kind`, may be another kind's: says how the
/// file was read.
fn read_as_sweep(mut e: ConfigError, header: &Header) -> ConfigError {
    if !header.kind_declared && e.message.starts_with("unknown field") {
        e.message +=
            " (a file without `kind` is read as kind = \"sweep\"; a frame-rate experiment says kind = \"fps\")";
    }
    e
}
