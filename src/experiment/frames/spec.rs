//! The frame-time experiment file (`kind = "frames"`): a generated scene walked along its camera
//! path and rendered by each acceleration structure, frame by frame, on the f64 CPU backend (or
//! the GPU, `backend = "gpu"`).
//! One kind serves the visibility-field paper's three frame-time figures: scaling with scene
//! size (Fig. 5: random triangles at several counts, two viewpoints), the classroom walkthrough
//! (Fig. 6: OpenGL-like and Whitted shading) and dynamic scenes (a `[motion]` table: one part
//! moves every frame and each structure is updated before rendering it).
//!
//! Files: this one (the file's keys and their checks), [`super::scenes`] (what generates the
//! scenes), [`super::cameras`] (where frames place the camera), [`super::motion`] (a moving part),
//! [`super::memory`] (whether it all fits).

pub use super::cameras::{Cameras, MAX_FRAMES};
pub use super::candidates::{FramesTuning, MAX_TUNING_CAMERAS};
pub use super::motion::Motion;
pub use super::scenes::{Generator, MAX_TRIANGLES};
use crate::experiment::tuning::KeptTuning;

use super::cameras::viewpoints;
use super::candidates::candidates;
use super::memory::check_memory;
use crate::accel::AccelSettings;
use crate::config::{ConfigError, Seg, Source};
use crate::experiment::comparison::{Claim, Comparison, SettingsPlaces};
use crate::experiment::header::Header;
use crate::key_path;
use crate::render::Sampling;
use crate::sampling::{DiskScheme, Pattern};
use crate::scene::procedural::Generated;
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

/// The frames' sampling (point lights need none; fixed for the record).
pub const SAMPLING: Sampling = Sampling {
    scheme: DiskScheme::Uniform,
    pattern: Pattern::PerPixel,
    seed: 1,
    frame: 0,
};

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
    /// Settings kept by an earlier run (`--tuning`), taken instead of tuning again.
    pub reused: Option<KeptTuning>,
    /// Where each structure's settings are, for a build refused mid-run.
    pub places: SettingsPlaces,
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
        let Comparison {
            names,
            tables: given,
            places,
        } = Comparison::read(source, &f.structures, &f.accel, &f.claim, true)?;
        let places = places.with_frame((f.width, f.height), source.error(&key_path!["width"], String::new()));
        let candidates = candidates(names, &given);
        let structures: Vec<AccelSettings> = candidates.iter().map(|c| c[0].clone()).collect();
        let tuning = FramesTuning::read(source, f.tuning, &candidates, f.path.block)?;
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
        let generator = Generator::read(source, &f.scene.generator, &f.scene.triangles, f.scene.seed)?;
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
        let viewpoints = viewpoints(source, &generator, &f.path.viewpoints)?;
        let cameras = Cameras::read(source, f.path.cameras.as_deref(), f.path.seed)?;
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
            Some(m) => Some(Motion::read(source, &generator, &m.part, m.step)?),
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
            reused: None,
            places,
        };
        check_memory(
            source,
            &spec.generator,
            &spec.candidates,
            spec.motion.is_some(),
            &f.accel,
        )?;
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
        match &self.motion {
            Some(m) => m.check_travel(source, self.moving_frames(), &self.structures, &self.generator),
            None => Ok(()),
        }
    }

    /// How many scenes the experiment has.
    pub fn scene_count(&self) -> usize {
        self.generator.count()
    }

    /// Every scene of the experiment, generated one at a time as the iterator is advanced (so
    /// only one is held): the classroom once, or random triangles at each count.
    pub fn scenes(&self) -> impl Iterator<Item = Generated> + '_ {
        (0..self.scene_count()).map(|i| self.generator.scene(i))
    }

    /// The camera of `frame` of `viewpoint`, on its path or drawn at random ([`Cameras`]), looking
    /// at the file's `look_at` where it has one ([`FramesSpec::from_source`] checks every camera
    /// can).
    pub fn camera(&self, viewpoint: &str, frame: u32) -> crate::scene::camera::Camera {
        let mut camera = self
            .cameras
            .camera(&self.generator, viewpoint, frame, self.frames)
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
