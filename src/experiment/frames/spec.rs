//! The frame-time experiment file (`kind = "frames"`): a generated scene walked along its camera
//! path and rendered by each acceleration structure, frame by frame, on the f64 CPU backend (or
//! the GPU, `backend = "gpu"`).
//! One kind serves the visibility-field paper's three frame-time figures: scaling with scene
//! size (Fig. 5: random triangles at several counts, two viewpoints), the classroom walkthrough
//! (Fig. 6: OpenGL-like and Whitted shading) and dynamic scenes (a `[motion]` table: one part
//! moves every frame and each structure is updated before rendering it).

use super::tuning::FramesTuning;
use crate::accel::AccelSettings;
use crate::config::{ConfigError, Seg, Source};
use crate::experiment::comparison::{Claim, Comparison};
use crate::experiment::header::Header;
use crate::key_path;
use crate::scene::load::MAX_EXTENT;
use crate::scene::procedural::{classroom, random, Generated};
use crate::scene::Shading;
use glam::DVec3;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

crate::experiment_file! {
    /// A frame-time experiment's file: the shared header and these keys.
    struct File {
        width: u32,
        height: u32,
        structures: Vec<String>,
        shadings: Vec<ShadingName>,
        #[serde(default = "three")]
        mirror_depth: u32,
        scene: SceneEntry,
        path: PathEntry,
        motion: Option<MotionEntry>,
        claim: Claim,
        #[serde(default)]
        accel: BTreeMap<String, toml::Table>,
        #[serde(default = "six")]
        strip: u32,
        tuning: Option<FramesTuning>,
    }
}

/// Most frames per viewpoint a path may have.
pub const MAX_FRAMES: u32 = 100_000;
/// Most tuning cameras per viewpoint.
pub const MAX_TUNING_CAMERAS: u32 = 64;
/// Most triangles a random-triangle scene may ask for.
pub const MAX_TRIANGLES: usize = 16 << 20;

/// Bytes of one copy of a generated scene per triangle: three f64 corners and an object id.
const SCENE_BYTES_PER_TRIANGLE: u64 = 80;

fn one() -> u32 {
    1
}

fn three() -> u32 {
    3
}

fn six() -> u32 {
    6
}

/// A shading as the experiment names it.
#[derive(Clone, Copy, Debug, Deserialize, serde::Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum ShadingName {
    /// Primary rays, unoccluded local diffuse light.
    Opengl,
    /// Shadow rays to every light at every vertex and mirror chains.
    Whitted,
}

impl ShadingName {
    /// The name in files and tables.
    pub fn name(self) -> &'static str {
        match self {
            ShadingName::Opengl => "opengl",
            ShadingName::Whitted => "whitted",
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneEntry {
    generator: String,
    #[serde(default)]
    triangles: Vec<usize>,
    #[serde(default = "one")]
    seed: u32,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PathEntry {
    frames: u32,
    block: Option<u32>,
    cameras: Option<String>,
    seed: Option<u32>,
    #[serde(default)]
    viewpoints: Vec<String>,
    look_at: Option<[f64; 3]>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MotionEntry {
    part: String,
    step: [f64; 3],
}

/// What a scene of the experiment is made by.
#[derive(Clone, Debug, PartialEq)]
pub enum Generator {
    /// [`classroom::classroom`].
    Classroom,
    /// [`random::random_triangles`] at each count, from one seed.
    RandomTriangles {
        /// Triangle counts, ascending.
        counts: Vec<usize>,
        /// Generator seed.
        seed: u32,
    },
}

/// How a viewpoint's frames place the camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cameras {
    /// Along the viewpoint's path, frame after frame (the paper's walkthrough and orbit):
    /// consecutive frames are correlated, so a median over them takes a moving-block interval.
    Path,
    /// Each frame an independent draw from the viewpoint's cameras, seeded
    /// ([`random::random_camera`], [`classroom::random_camera`]): a median over them takes the
    /// exact order-statistic interval, which decides a claim with far fewer frames.
    Random {
        /// Seed of the draws (`[path] seed`).
        seed: u32,
    },
}

impl Cameras {
    /// `path` or `random`, as the file names it.
    pub fn name(self) -> &'static str {
        match self {
            Cameras::Path => "path",
            Cameras::Random { .. } => "random",
        }
    }
}

/// A part moved by a fixed step every frame, each structure updated in its own way.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// The moving part's name.
    pub part: String,
    /// Translation per frame, metres.
    pub step: DVec3,
}

/// A validated frame-time experiment.
#[derive(Clone, Debug)]
pub struct FramesSpec {
    /// The shared keys (`[timing]`: timed renders of every frame, in interleaved rounds; warm-up
    /// renders of each path's first frame).
    pub header: Header,
    /// Results folder name.
    pub name: String,
    /// The experiment file.
    pub path: PathBuf,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Each structure with its parameters (its first candidate).
    pub structures: Vec<AccelSettings>,
    /// Each structure's candidates, in `structures`' order: more than one where its
    /// `[accel.NAME]` table lists values, and then it is tuned per scene ([`super::tuning`]).
    pub candidates: Vec<Vec<AccelSettings>>,
    /// How candidates are tuned.
    pub tuning: FramesTuning,
    /// Shadings rendered, each over the whole path.
    pub shadings: Vec<(ShadingName, Shading)>,
    /// The claim the verdict answers.
    pub claim: Claim,
    /// The scene generator.
    pub generator: Generator,
    /// Frames per unit of work (`[path] block`): a static scene's path is cut into blocks of
    /// this many frames, each shading and viewpoint apart, so shards can share one long path;
    /// every structure of a block is timed in the same interleaved rounds. Without it a scene is
    /// one unit (its structures built once for every shading and viewpoint; a moving scene's
    /// once per path).
    pub block: Option<u32>,
    /// Frames per viewpoint.
    pub frames: u32,
    /// Viewpoints (random triangles: each a short path; the classroom: its one walk).
    pub viewpoints: Vec<String>,
    /// How each viewpoint's frames place the camera (`[path] cameras`, default `path`).
    pub cameras: Cameras,
    /// A point every camera of the path looks at instead of its own (keeps a moving part in
    /// view).
    pub look_at: Option<DVec3>,
    /// The moving part, for dynamic experiments.
    pub motion: Option<Motion>,
    /// Frames saved as pictures, evenly along the path.
    pub strip: u32,
}

impl FramesSpec {
    /// Reads and validates a frame-time experiment.
    pub fn load(path: &Path) -> Result<FramesSpec, ConfigError> {
        let source = Source::read(path)?;
        FramesSpec::from_source(&source, Header::read(&source)?)
    }

    /// Validates a frame-time experiment read from `source` (shared keys `header`).
    pub fn from_source(source: &Source, header: Header) -> Result<FramesSpec, ConfigError> {
        let f: File = source.parse()?;
        let err = |p: &[Seg], m: String| source.error(p, m);
        source.image_size(&key_path!["width"], &key_path!["height"], f.width, f.height)?;
        if f.mirror_depth == 0 || f.mirror_depth > Shading::MAX_MIRROR_DEPTH {
            return Err(err(
                &key_path!["mirror_depth"],
                format!("must be in 1..={}, got {}", Shading::MAX_MIRROR_DEPTH, f.mirror_depth),
            ));
        }
        let Comparison { names, tables: given } = Comparison::read(source, &f.structures, &f.accel, &f.claim, true)?;
        let candidates: Vec<Vec<AccelSettings>> = names
            .into_iter()
            .map(|name| match given.get(name) {
                Some(listed) => listed.clone(),
                None => vec![AccelSettings::default_for(
                    crate::accel::registered(name).expect("registered"),
                )],
            })
            .collect();
        let structures: Vec<AccelSettings> = candidates.iter().map(|c| c[0].clone()).collect();
        let tuning = f.tuning.unwrap_or_default();
        if !(1..=MAX_TUNING_CAMERAS).contains(&tuning.cameras) {
            return Err(err(
                &key_path!["tuning", "cameras"],
                format!("tuning cameras per viewpoint: must be in 1..={MAX_TUNING_CAMERAS}"),
            ));
        }
        if !(3..=crate::experiment::header::MAX_REPEATS).contains(&tuning.repeats) {
            return Err(err(
                &key_path!["tuning", "repeats"],
                format!(
                    "must be in 3..={} (the rounds behind each candidate's median and its interval)",
                    crate::experiment::header::MAX_REPEATS
                ),
            ));
        }
        if f.tuning.is_some() && candidates.iter().all(|c| c.len() == 1) {
            return Err(err(
                &key_path!["tuning"],
                "no structure lists candidates to tune: list values in an `[accel.NAME]` table or remove `[tuning]`"
                    .into(),
            ));
        }
        // Tuning picks by time, once per unit; blocks of one scene may run on different
        // machines, so their picks could differ and one scene's frames would mix settings.
        if let (Some(_), Some(listed)) = (f.path.block, candidates.iter().find(|c| c.len() > 1)) {
            return Err(err(
                &key_path!["path", "block"],
                format!(
                    "`{}` lists {} candidates to tune, and tuning picks by time once per unit: blocks of one scene \
                     (which may run on different machines) could pick differently; give `[accel.{}]` one value \
                     per key (an unblocked run's tuning.csv says which is fastest) or remove `block`",
                    listed[0].name,
                    listed.len(),
                    listed[0].name
                ),
            ));
        }
        if f.shadings.is_empty() {
            return Err(err(&key_path!["shadings"], "name at least one shading".into()));
        }
        let mut shadings = Vec::new();
        for (i, s) in f.shadings.iter().enumerate() {
            if shadings.iter().any(|(n, _)| n == s) {
                return Err(err(
                    &key_path!["shadings", i],
                    format!("`{}` is listed twice", s.name()),
                ));
            }
            shadings.push((
                *s,
                match s {
                    ShadingName::Opengl => Shading::OPENGL,
                    ShadingName::Whitted => Shading::whitted(f.mirror_depth),
                },
            ));
        }
        let generator = match f.scene.generator.as_str() {
            "classroom" => {
                if !f.scene.triangles.is_empty() {
                    return Err(err(
                        &key_path!["scene", "triangles"],
                        "the classroom has its own triangles; counts apply to random-triangles".into(),
                    ));
                }
                Generator::Classroom
            }
            "random-triangles" => {
                let counts = f.scene.triangles.clone();
                if counts.is_empty() {
                    return Err(err(
                        &key_path!["scene", "triangles"],
                        "list at least one triangle count".into(),
                    ));
                }
                if let Some(i) = (0..counts.len()).find(|&i| counts[i] == 0 || (i > 0 && counts[i] <= counts[i - 1])) {
                    return Err(err(
                        &key_path!["scene", "triangles", i],
                        "counts must be positive and ascending".into(),
                    ));
                }
                if let Some(i) = counts.iter().position(|&n| n > MAX_TRIANGLES) {
                    return Err(err(
                        &key_path!["scene", "triangles", i],
                        format!("at most {MAX_TRIANGLES} triangles"),
                    ));
                }
                Generator::RandomTriangles {
                    counts,
                    seed: f.scene.seed,
                }
            }
            other => {
                return Err(err(
                    &key_path!["scene", "generator"],
                    format!("unknown generator `{other}`; known: classroom, random-triangles"),
                ))
            }
        };
        if !(1..=MAX_FRAMES).contains(&f.path.frames) {
            return Err(err(
                &key_path!["path", "frames"],
                format!("must be in 1..={MAX_FRAMES}"),
            ));
        }
        if let Some(block) = f.path.block {
            if !(1..=f.path.frames).contains(&block) {
                return Err(err(
                    &key_path!["path", "block"],
                    format!("frames per unit of work: must be in 1..={} (`frames`)", f.path.frames),
                ));
            }
            if f.motion.is_some() && block != f.path.frames {
                return Err(err(
                    &key_path!["path", "block"],
                    "a moving part carries its state from frame to frame, so a moving scene's path is one \
                     unit of work: remove `block`"
                        .into(),
                ));
            }
        }
        let viewpoints = match generator {
            Generator::Classroom => {
                if !f.path.viewpoints.is_empty() {
                    return Err(err(
                        &key_path!["path", "viewpoints"],
                        "the classroom has one walk; viewpoints apply to random-triangles".into(),
                    ));
                }
                vec!["walk".to_string()]
            }
            Generator::RandomTriangles { .. } => {
                if f.path.viewpoints.is_empty() {
                    return Err(err(
                        &key_path!["path", "viewpoints"],
                        format!("list viewpoints from: {}", random::VIEWPOINTS.join(", ")),
                    ));
                }
                for (i, v) in f.path.viewpoints.iter().enumerate() {
                    if !random::VIEWPOINTS.contains(&v.as_str()) {
                        return Err(err(
                            &key_path!["path", "viewpoints", i],
                            format!("unknown viewpoint `{v}`; known: {}", random::VIEWPOINTS.join(", ")),
                        ));
                    }
                    if f.path.viewpoints[..i].contains(v) {
                        return Err(err(
                            &key_path!["path", "viewpoints", i],
                            format!("`{v}` is listed twice"),
                        ));
                    }
                }
                f.path.viewpoints.clone()
            }
        };
        let cameras = match (f.path.cameras.as_deref(), f.path.seed) {
            (None | Some("path"), None) => Cameras::Path,
            (None | Some("path"), Some(_)) => {
                return Err(err(
                    &key_path!["path", "seed"],
                    "a seed draws random cameras: set `cameras = \"random\"` or remove it".into(),
                ))
            }
            (Some("random"), seed) => Cameras::Random {
                seed: seed.unwrap_or(1),
            },
            (Some(other), _) => {
                return Err(err(
                    &key_path!["path", "cameras"],
                    format!("unknown `{other}`; known: path, random"),
                ))
            }
        };
        if let Cameras::Random { seed } = cameras {
            // Random cameras are judged as independent draws; a moving part's frames are not:
            // each carries the part (and the structures that follow it) on from the last.
            if f.motion.is_some() {
                return Err(err(
                    &key_path!["path", "cameras"],
                    "a moving part carries its state from frame to frame, so a moving scene's frames are a \
                     path, not independent draws: use cameras = \"path\""
                        .into(),
                ));
            }
            if seed == tuning.seed {
                return Err(err(
                    &key_path!["tuning", "seed"],
                    format!("equals the cameras' seed ({seed}): tuning would run on the frames it is judged on"),
                ));
            }
        }
        let look_at = match f.path.look_at {
            Some(p) if !p.iter().all(|x| x.is_finite()) => {
                return Err(err(&key_path!["path", "look_at"], "coordinates must be finite".into()))
            }
            p => p.map(DVec3::from_array),
        };
        let motion = match &f.motion {
            None => None,
            Some(m) => {
                let probe = match &generator {
                    Generator::Classroom => classroom::classroom(),
                    Generator::RandomTriangles { seed, .. } => random::random_triangles(1, *seed),
                };
                if probe.part(&m.part).is_none() {
                    let names: Vec<&str> = probe.parts.iter().map(|p| p.name.as_str()).collect();
                    return Err(err(
                        &key_path!["motion", "part"],
                        format!("no part `{}`; the scene has: {}", m.part, names.join(", ")),
                    ));
                }
                let step = DVec3::from_array(m.step);
                if !step.is_finite() {
                    return Err(err(&key_path!["motion", "step"], "coordinates must be finite".into()));
                }
                Some(Motion {
                    part: m.part.clone(),
                    step,
                })
            }
        };
        if f.strip == 0 {
            return Err(err(
                &key_path!["strip"],
                "at least one frame in the strip of pictures".into(),
            ));
        }
        let spec = FramesSpec {
            name: header.name.clone(),
            header,
            path: source.path.clone(),
            width: f.width,
            height: f.height,
            structures,
            candidates,
            tuning,
            shadings,
            claim: f.claim,
            generator,
            frames: f.path.frames,
            viewpoints,
            cameras,
            look_at,
            block: f.path.block,
            motion,
            strip: f.strip,
        };
        spec.check_memory(source, &f.accel)?;
        spec.check_path(source)?;
        Ok(spec)
    }

    /// Every camera of the path can look where it is told, and a moving part stays inside the
    /// ball a visibility field is built in (the field cannot follow it out), for every scene.
    fn check_path(&self, source: &Source) -> Result<(), ConfigError> {
        for viewpoint in &self.viewpoints {
            for frame in 0..self.frames {
                let c = self.camera(viewpoint, frame);
                if c.frame().is_none() {
                    let at = if self.look_at.is_some() {
                        key_path!["path", "look_at"]
                    } else {
                        key_path!["path", "frames"]
                    };
                    return Err(source.error(
                        &at,
                        format!(
                            "frame {frame} of viewpoint `{viewpoint}` stands at {} and cannot look at {} with z up",
                            c.position, c.look_at
                        ),
                    ));
                }
            }
        }
        let Some(m) = &self.motion else { return Ok(()) };
        let travel = m.step * self.moving_frames() as f64;
        let far = travel.abs().max_element();
        if far.is_nan() || far > MAX_EXTENT {
            return Err(source.error(
                &key_path!["motion", "step"],
                format!(
                    "over {} frames `{}` would travel {:?} m, beyond the +-{MAX_EXTENT:e} m any coordinate may reach: shorten the step",
                    self.moving_frames(),
                    m.part,
                    travel.to_array()
                ),
            ));
        }
        let bounded: Vec<_> = self
            .structures
            .iter()
            .filter_map(|s| Some((s.name, crate::accel::registered(s.name)?.follows_within?)))
            .collect();
        if bounded.is_empty() {
            return Ok(());
        }
        for g in self.scenes() {
            let t = g.triangles();
            let (index, _) = g.part(&m.part).expect("validated part");
            for (name, within) in &bounded {
                let (centre, radius) = within(&t.positions);
                let out = t
                    .positions
                    .iter()
                    .zip(&t.object_of)
                    .filter(|(_, &o)| o as usize == index)
                    .flat_map(|(p, _)| p.iter())
                    .map(|p| (*p + travel).distance(centre))
                    .fold(0.0, f64::max);
                if out > radius {
                    return Err(source.error(
                        &key_path!["motion", "step"],
                        format!(
                            "over {} frames `{}` travels {:?} m and leaves the ball `{name}` is built in ({:.3} m from its centre, radius {:.3} m), where it cannot follow: shorten the step",
                            self.moving_frames(),
                            m.part,
                            travel.to_array(),
                            out,
                            radius
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Every structure fits in the memory available over every scene size, by its own lower
    /// bound, before anything is generated or built.
    fn check_memory(&self, source: &Source, tables: &BTreeMap<String, toml::Table>) -> Result<(), ConfigError> {
        let counts = match &self.generator {
            Generator::Classroom => vec![classroom::TRIANGLES],
            Generator::RandomTriangles { counts, .. } => counts.clone(),
        };
        let available = crate::accel::memory::available();
        // One scene is held at a time, with its triangle list, a copy per structure and every
        // structure built over it (with a moving part, once per way it follows the part); before
        // that, one structure's tuning candidates together.
        let variants = |s: &AccelSettings| match self.motion {
            Some(_) => crate::accel::registered(s.name).map_or(1, |r| r.updates.len()),
            None => 1,
        };
        for (k, &n) in counts.iter().enumerate() {
            let copies = self
                .structures
                .iter()
                .map(variants)
                .sum::<usize>()
                .max(self.candidates.iter().map(Vec::len).max().unwrap_or(1));
            let scene = (2 + copies) as u64 * SCENE_BYTES_PER_TRIANGLE * n as u64;
            let each = |c: &Vec<AccelSettings>| -> Vec<u64> {
                c.iter().map(|s| crate::accel::memory::estimate(s, n)).collect()
            };
            let kept: u64 = self
                .candidates
                .iter()
                .map(|c| variants(&c[0]) as u64 * each(c).into_iter().max().unwrap_or(0))
                .sum();
            let tuning = self
                .candidates
                .iter()
                .map(|c| each(c).into_iter().sum::<u64>())
                .max()
                .unwrap_or(0);
            let structures = kept.max(tuning);
            if let Some(budget) = available.filter(|b| scene + structures > b.bytes) {
                let at: Vec<Seg> = match self.generator {
                    Generator::Classroom => key_path!["structures"].to_vec(),
                    Generator::RandomTriangles { .. } => key_path!["scene", "triangles", k].to_vec(),
                };
                return Err(source.error(
                    &at,
                    format!(
                        "{n} triangles with every structure built over them need at least {:.1} GB ({:.1} GB of scene copies, {:.1} GB of structures), more than {}",
                        (scene + structures) as f64 / 1e9,
                        scene as f64 / 1e9,
                        structures as f64 / 1e9,
                        budget.describe()
                    ),
                ));
            }
        }
        for (i, s) in self
            .candidates
            .iter()
            .enumerate()
            .flat_map(|(i, c)| c.iter().map(move |s| (i, s)))
        {
            for &n in &counts {
                crate::accel::memory::check(s, n, available).map_err(|e| {
                    let at = if tables.contains_key(s.name) {
                        key_path!["accel", s.name]
                    } else {
                        key_path!["structures", i]
                    };
                    source.error(&at, e)
                })?;
            }
        }
        Ok(())
    }

    /// How many scenes the experiment has.
    pub fn scene_count(&self) -> usize {
        match &self.generator {
            Generator::Classroom => 1,
            Generator::RandomTriangles { counts, .. } => counts.len(),
        }
    }

    /// Every scene of the experiment, generated one at a time as the iterator is advanced (so
    /// only one is held): the classroom once, or random triangles at each count.
    pub fn scenes(&self) -> impl Iterator<Item = Generated> + '_ {
        (0..self.scene_count()).map(|i| match &self.generator {
            Generator::Classroom => classroom::classroom(),
            Generator::RandomTriangles { counts, seed } => random::random_triangles(counts[i], *seed),
        })
    }

    /// The camera of `frame` of `viewpoint`, on its path or drawn at random ([`Cameras`]), looking
    /// at the file's `look_at` where it has one ([`FramesSpec::from_source`] checks every camera
    /// can).
    pub fn camera(&self, viewpoint: &str, frame: u32) -> crate::scene::camera::Camera {
        let mut camera = match (&self.generator, self.cameras) {
            (Generator::Classroom, Cameras::Path) => Some(classroom::camera_path(frame, self.frames)),
            (Generator::Classroom, Cameras::Random { seed }) => Some(classroom::random_camera(seed, frame)),
            (Generator::RandomTriangles { .. }, Cameras::Path) => random::camera_path(viewpoint, frame),
            (Generator::RandomTriangles { .. }, Cameras::Random { seed }) => {
                random::random_camera(viewpoint, seed, frame)
            }
        }
        .expect("viewpoints are validated");
        if let Some(p) = self.look_at {
            camera.look_at = p;
        }
        camera
    }

    /// Frames the moving part moves through: one path's (each shading and viewpoint starts it
    /// again from where the scene puts it).
    pub fn moving_frames(&self) -> u32 {
        self.frames
    }
}
