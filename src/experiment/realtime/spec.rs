//! The real-time experiment file: one scene, a static and optionally a moving variant, and the
//! axes of a real-time shadow pipeline (scheme x rays x frames x accumulation x filter x seed).

use crate::config::{ConfigError, Source};
use crate::experiment::comparison::SettingsPlaces;
use crate::experiment::header::Header;
use crate::key_path;
use crate::render::denoise::{Accumulation, Filter, FilterSettings};
use crate::sampling::DiskScheme;
use crate::scene::{Light, Scene, Shape, MAX_SAMPLES};
use glam::DVec3;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

crate::experiment_file! {
    /// A real-time experiment's file: the shared header and these keys.
    struct File {
        scene: PathBuf,
        measure: MeasureTable,
        motion: Option<MotionTable>,
        sweep: SweepTable,
        filters: Option<FilterSettings>,
        reference: Option<ReferenceTable>,
        verdict: Option<VerdictTable>,
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MeasureTable {
    camera: String,
    width: u32,
    height: u32,
    plane: usize,
    lights: Option<usize>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MotionTable {
    shape: usize,
    step: [f64; 3],
    frames: u32,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SweepTable {
    variants: Vec<String>,
    schemes: Vec<DiskScheme>,
    rays: Vec<u32>,
    frames: Vec<u32>,
    accumulations: Vec<String>,
    ema_alpha: f64,
    /// The clamped history's gamma ([`Accumulation::Clamped`]).
    #[serde(default = "default_gamma")]
    clamp_gamma: f64,
    filters: Vec<String>,
    seeds: Vec<u32>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ReferenceTable {
    samples: u32,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct VerdictTable {
    width_tolerance: Option<f64>,
    lag_tolerance: Option<f64>,
    max_lag: Option<u32>,
    budget_schemes: Option<Vec<(DiskScheme, u32)>>,
}

/// Variance clipping's usual gamma: the history within one standard deviation of the
/// neighbourhood's mean (Salvi 2016).
fn default_gamma() -> f64 {
    1.0
}

/// The frame-time budgets when the file names none: one raw frame of the paper's 16 rays, and of
/// uniform sampling at 4 rays.
pub const DEFAULT_BUDGETS: [(DiskScheme, u32); 2] = [(DiskScheme::Paper, 16), (DiskScheme::Uniform, 4)];

/// The moving variant: one shape translated by `step` each frame for `frames` frames, then still.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// Index of the moving shape in the scene.
    pub shape: usize,
    /// Translation per frame (m).
    pub step: DVec3,
    /// Frames it moves before it stops.
    pub frames: u32,
}

/// A scene variant: still, or with its occluder moving.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Variant {
    /// Nothing moves: accumulation converges.
    Static,
    /// The [`Motion`]: accumulation lags.
    Moving,
}

impl Variant {
    /// The name in files and tables.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Static => "static",
            Variant::Moving => "moving",
        }
    }
}

/// A validated real-time experiment.
#[derive(Clone, Debug)]
pub struct RealtimeSpec {
    /// The shared keys; `[timing] repeats` interleaved rounds time every render and filter.
    pub header: Header,
    /// The experiment file.
    pub path: PathBuf,
    /// The scene file.
    pub scene_path: PathBuf,
    /// The scene.
    pub scene: Scene,
    /// Where the scene's structure and the measuring frame's size are set, for refusals known
    /// only when a frame is uploaded.
    pub places: SettingsPlaces,
    /// Measuring camera and size.
    pub camera: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The receiver plane the metrics are taken over (index among the scene's planes).
    pub plane: usize,
    /// The moving variant's motion.
    pub motion: Option<Motion>,
    /// Variants run.
    pub variants: Vec<Variant>,
    /// Disk schemes.
    pub schemes: Vec<DiskScheme>,
    /// Shadow rays per pixel per light per frame.
    pub rays: Vec<u32>,
    /// Frame counts at which the pipeline is judged (ascending).
    pub frames: Vec<u32>,
    /// Accumulations.
    pub accumulations: Vec<Accumulation>,
    /// Filters.
    pub filters: Vec<Filter>,
    /// Filter parameters.
    pub settings: FilterSettings,
    /// Seeds.
    pub seeds: Vec<u32>,
    /// Rays per pixel of each of the two renders whose mean is the reference where the scene
    /// has no exact answer.
    pub reference_samples: u32,
    /// Largest |width / exact width - 1| a pipeline may show and stay eligible (the 2 %).
    pub width_tolerance: f64,
    /// Lag: frames after the occluder stops until the moving run's penumbra width is within this
    /// share of the exact width (0.05).
    pub lag_tolerance: f64,
    /// Most frames of lag a pipeline may show and still answer a budget, where the moving
    /// variant runs: moving scenes decide as much as still ones.
    pub max_lag: u32,
    /// The frame-time budgets: (scheme, rays) whose raw single frame sets each.
    pub budgets: Vec<(DiskScheme, u32)>,
}

impl RealtimeSpec {
    /// Reads and validates a real-time experiment file and its scene.
    pub fn load(path: &Path) -> Result<RealtimeSpec, ConfigError> {
        let source = Source::read(path)?;
        RealtimeSpec::from_source(&source, Header::read(&source)?)
    }

    /// The frames rendered per seed: the largest frame count.
    pub fn max_frames(&self) -> u32 {
        *self.frames.last().expect("validated non-empty")
    }

    /// The scene at frame `f` (0-based) of `variant`.
    pub fn scene_at(&self, variant: Variant, f: u32) -> Scene {
        let mut scene = self.scene.clone();
        if let (Variant::Moving, Some(m)) = (variant, &self.motion) {
            let offset = m.step * f.min(m.frames) as f64;
            scene.shapes[m.shape] = scene.shapes[m.shape].transformed(&|p| p + offset, 1.0);
        }
        scene
    }

    /// The scene with `rays` shadow rays per light.
    pub fn with_rays(scene: &Scene, rays: u32) -> Scene {
        let mut s = scene.clone();
        for l in &mut s.lights {
            if let Light::Disk(d) = l {
                d.samples = rays;
            }
        }
        s
    }

    /// Validates a real-time experiment read from its file.
    pub fn from_source(source: &Source, header: Header) -> Result<RealtimeSpec, ConfigError> {
        let path = source.path.as_path();
        let f: File = source.parse()?;
        let scene_path = path.parent().unwrap_or(Path::new(".")).join(&f.scene);
        let scene_source = Source::read(&scene_path)
            .map_err(|e| source.error(&key_path!["scene"], format!("{}: {}", scene_path.display(), e.message)))?;
        let mut scene = Scene::from_source(&scene_source)?;
        let m = &f.measure;
        let places = SettingsPlaces::new(
            BTreeMap::from([(
                scene.accel_settings.name,
                scene_source.error(&key_path!["accelerator"], String::new()),
            )]),
            vec![(
                (m.width, m.height),
                source.error(&key_path!["measure", "width"], String::new()),
            )],
        );
        if let Some(n) = m.lights {
            if n == 0 || n > scene.lights.len() {
                return Err(source.error(
                    &key_path!["measure", "lights"],
                    format!("must be in 1..={} (the scene's lights), got {n}", scene.lights.len()),
                ));
            }
            scene.lights.truncate(n);
        }
        if !scene.cameras.contains_key(&m.camera) {
            return Err(source.error(
                &key_path!["measure", "camera"],
                format!("no camera `{}` in {}", m.camera, f.scene.display()),
            ));
        }
        source.image_size(
            &key_path!["measure", "width"],
            &key_path!["measure", "height"],
            m.width,
            m.height,
        )?;
        if scene.plane(m.plane).is_none() {
            return Err(source.error(
                &key_path!["measure", "plane"],
                format!("the scene has no plane {}", m.plane),
            ));
        }
        if !scene.lights.iter().any(|l| matches!(l, Light::Disk(_))) {
            return Err(source.error(&key_path!["scene"], "the scene has no disk light to sample"));
        }
        let s = &f.sweep;
        let nonempty = |key: &'static str, empty: bool| {
            if empty {
                Err(source.error(&key_path!["sweep", key], "list at least one value"))
            } else {
                Ok(())
            }
        };
        nonempty("variants", s.variants.is_empty())?;
        nonempty("schemes", s.schemes.is_empty())?;
        nonempty("rays", s.rays.is_empty())?;
        nonempty("frames", s.frames.is_empty())?;
        nonempty("accumulations", s.accumulations.is_empty())?;
        nonempty("filters", s.filters.is_empty())?;
        nonempty("seeds", s.seeds.is_empty())?;
        let mut variants = Vec::new();
        for (i, v) in s.variants.iter().enumerate() {
            let variant = match v.as_str() {
                "static" => Variant::Static,
                "moving" => Variant::Moving,
                _ => {
                    return Err(source.error(
                        &key_path!["sweep", "variants", i],
                        format!("unknown variant `{v}`; one of static, moving"),
                    ))
                }
            };
            if variants.contains(&variant) {
                return Err(source.error(&key_path!["sweep", "variants", i], format!("`{v}` is listed twice")));
            }
            variants.push(variant);
        }
        let motion = match &f.motion {
            Some(mt) => {
                if !matches!(scene.shapes.get(mt.shape), Some(Shape::Sphere(_))) {
                    return Err(source.error(
                        &key_path!["motion", "shape"],
                        format!("shape {} is not a sphere of the scene (spheres move; meshes would need their structure updated)", mt.shape),
                    ));
                }
                let step = DVec3::from_array(mt.step);
                if !step.is_finite() || step.length() > 1e3 {
                    return Err(source.error(&key_path!["motion", "step"], "must be finite, at most 1 km per frame"));
                }
                Some(Motion {
                    shape: mt.shape,
                    step,
                    frames: mt.frames,
                })
            }
            None => None,
        };
        if variants.contains(&Variant::Moving) && motion.is_none() {
            return Err(source.error(
                &key_path!["sweep", "variants"],
                "`moving` needs a [motion] table (shape, step, frames)",
            ));
        }
        for (i, &r) in s.rays.iter().enumerate() {
            if !(1..=MAX_SAMPLES).contains(&r) || (i > 0 && r <= s.rays[i - 1]) {
                return Err(source.error(
                    &key_path!["sweep", "rays", i],
                    format!("ray counts must be in 1..={MAX_SAMPLES} and ascending, got {r}"),
                ));
            }
        }
        for (i, &n) in s.frames.iter().enumerate() {
            if !(1..=1024).contains(&n) || (i > 0 && n <= s.frames[i - 1]) {
                return Err(source.error(
                    &key_path!["sweep", "frames", i],
                    format!("frame counts must be in 1..=1024 and ascending, got {n}"),
                ));
            }
        }
        let max_frames = *s.frames.last().expect("non-empty");
        if let Some(mt) = &motion {
            if variants.contains(&Variant::Moving) && mt.frames >= max_frames {
                return Err(source.error(
                    &key_path!["motion", "frames"],
                    format!(
                        "the occluder must stop before the last frame ({max_frames}) for lag to be measured, got {}",
                        mt.frames
                    ),
                ));
            }
        }
        for (i, scheme) in s.schemes.iter().enumerate() {
            let most = s.rays.iter().max().copied().unwrap_or(1) as u64 * max_frames as u64;
            if !scheme.is_built_in() || s.schemes[..i].contains(scheme) {
                return Err(source.error(
                    &key_path!["sweep", "schemes", i],
                    format!("`{scheme}`: list built-in schemes, each once"),
                ));
            }
            if most > scheme.max_samples() as u64 {
                return Err(source.error(
                    &key_path!["sweep", "schemes", i],
                    format!(
                        "{scheme} gives at most {} samples per pixel; {max_frames} frames of {} rays need {most}",
                        scheme.max_samples(),
                        most / max_frames as u64
                    ),
                ));
            }
        }
        if !(s.ema_alpha > 0.0 && s.ema_alpha <= 1.0) {
            return Err(source.error(
                &key_path!["sweep", "ema_alpha"],
                format!("must be in (0, 1], got {}", s.ema_alpha),
            ));
        }
        if !(s.clamp_gamma.is_finite() && s.clamp_gamma >= 0.0 && s.clamp_gamma <= 100.0) {
            return Err(source.error(
                &key_path!["sweep", "clamp_gamma"],
                format!("must be in [0, 100], got {}", s.clamp_gamma),
            ));
        }
        let mut accumulations = Vec::new();
        for (i, a) in s.accumulations.iter().enumerate() {
            let parsed = a
                .parse::<Accumulation>()
                .map_err(|e| source.error(&key_path!["sweep", "accumulations", i], e))?;
            let parsed = match parsed {
                Accumulation::Ema(_) => Accumulation::Ema(s.ema_alpha),
                Accumulation::Clamped { .. } => Accumulation::Clamped {
                    alpha: s.ema_alpha,
                    gamma: s.clamp_gamma,
                },
                m => m,
            };
            if accumulations.contains(&parsed) {
                return Err(source.error(
                    &key_path!["sweep", "accumulations", i],
                    format!("`{a}` is listed twice"),
                ));
            }
            accumulations.push(parsed);
        }
        let mut filters = Vec::new();
        for (i, name) in s.filters.iter().enumerate() {
            let filter: Filter = name
                .parse()
                .map_err(|e: String| source.error(&key_path!["sweep", "filters", i], e))?;
            if filters.contains(&filter) {
                return Err(source.error(&key_path!["sweep", "filters", i], format!("`{name}` is listed twice")));
            }
            filters.push(filter);
        }
        for (i, seed) in s.seeds.iter().enumerate() {
            if s.seeds[..i].contains(seed) {
                return Err(source.error(&key_path!["sweep", "seeds", i], format!("{seed} is listed twice")));
            }
            // A pipeline on the reference's own rays would read as nearly exact.
            if super::reference::REFERENCE_SEEDS.contains(seed) {
                return Err(source.error(
                    &key_path!["sweep", "seeds", i],
                    format!("{seed} is a seed of the reference's renders; choose another"),
                ));
            }
        }
        let settings = f.filters.unwrap_or_default();
        settings
            .check()
            .map_err(|(key, message)| source.error(&key_path!["filters", key], message))?;
        let reference_samples = f.reference.as_ref().map_or(1024, |r| r.samples);
        if !(16..=MAX_SAMPLES).contains(&reference_samples) {
            return Err(source.error(
                &key_path!["reference", "samples"],
                format!("must be in 16..={MAX_SAMPLES}, got {reference_samples}"),
            ));
        }
        let v = f.verdict.as_ref();
        let width_tolerance = v.and_then(|v| v.width_tolerance).unwrap_or(0.02);
        if !(width_tolerance > 0.0 && width_tolerance < 1.0) {
            return Err(source.error(&key_path!["verdict", "width_tolerance"], "must be in (0, 1)"));
        }
        let lag_tolerance = v.and_then(|v| v.lag_tolerance).unwrap_or(0.05);
        if !(lag_tolerance > 0.0 && lag_tolerance < 1.0) {
            return Err(source.error(
                &key_path!["verdict", "lag_tolerance"],
                format!("must be in (0, 1), got {lag_tolerance}"),
            ));
        }
        let max_lag = v.and_then(|v| v.max_lag).unwrap_or(4);
        let swept = |&(scheme, rays): &(DiskScheme, u32)| s.schemes.contains(&scheme) && s.rays.contains(&rays);
        // The defaults are the paper's 16 raw rays and uniform at 4, where swept; a file that
        // names its budgets must sweep them.
        let budgets = match v.and_then(|v| v.budget_schemes.clone()) {
            Some(b) => b,
            None => DEFAULT_BUDGETS.iter().copied().filter(swept).collect(),
        };
        for (i, (scheme, rays)) in budgets.iter().enumerate() {
            if budgets[..i].contains(&(*scheme, *rays)) {
                return Err(source.error(
                    &key_path!["verdict", "budget_schemes", i],
                    format!("{scheme} at {rays} rays is listed twice"),
                ));
            }
            if !swept(&(*scheme, *rays)) {
                return Err(source.error(
                    &key_path!["verdict", "budget_schemes", i],
                    format!(
                        "{scheme} at {rays} rays sets a budget but is not swept (add it to [sweep] schemes and rays)"
                    ),
                ));
            }
        }
        Ok(RealtimeSpec {
            header,
            path: path.to_path_buf(),
            scene_path,
            scene,
            places,
            camera: m.camera.clone(),
            width: m.width,
            height: m.height,
            plane: m.plane,
            motion,
            variants,
            schemes: s.schemes.clone(),
            rays: s.rays.clone(),
            frames: s.frames.clone(),
            accumulations,
            filters,
            settings,
            seeds: s.seeds.clone(),
            reference_samples,
            width_tolerance,
            lag_tolerance,
            max_lag,
            budgets,
        })
    }
}
