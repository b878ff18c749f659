//! Runs a frame-time experiment on the f64 CPU backend, where every structure answers exactly
//! and frames can be compared pixel for pixel, or on the GPU where asked (every structure's f32
//! walk runs the same triangle test, so frames compare there too): per scene, each structure is
//! built once (its build time and memory recorded); then, for each shading and viewpoint, every
//! frame of the path is rendered by every structure in the schedule's interleaved rounds (counterbalanced
//! seeded orders of the structures, so a change of machine load falls on all alike; the median
//! of the rounds is kept, with the frame's rays and work), and each structure's frame is compared
//! with the first structure's. With a `[motion]`, one part moves by a step before each frame and
//! each structure is first brought up to date in every way it offers
//! ([`crate::accel::Accelerator::updates`]); an update changes the structure, so it is timed
//! once per frame. Before each shading and viewpoint every structure renders the path's first
//! frame `warmup` times, untimed (warm caches).

pub use super::spec::SAMPLING;

use super::spec::{FramesSpec, ShadingName};
use crate::accel::settings::{registry_name, RegistryName};
use crate::accel::work::Work;
use crate::accel::{AccelSettings, UpdateMethod, Updated};
use crate::experiment::progress::Progress;
use crate::mesh::Triangles;
use crate::metrics::stats::median;
use crate::render::{Backend, Frame, RayCounts, View};
use crate::scene::procedural::Generated;
use crate::scene::Scene;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// One frame of one structure, timed.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FrameRow {
    /// Triangles in the scene.
    pub triangles: usize,
    /// Structure name.
    #[serde(with = "registry_name")]
    pub structure: RegistryName,
    /// How it follows a moving part (`none` for static scenes).
    #[serde(with = "update_name")]
    pub update: UpdateName,
    /// Shading.
    pub shading: ShadingName,
    /// Viewpoint.
    pub viewpoint: String,
    /// Frame index on the path.
    pub frame: u32,
    /// Median render seconds over the rounds.
    pub seconds: f64,
    /// Seconds of each timed render, in round order.
    pub renders: Vec<f64>,
    /// Seconds the update before this frame took (dynamic scenes).
    pub update_seconds: Option<f64>,
    /// What that update did to the structure.
    pub updated: Option<Updated>,
    /// Rays the frame traced, per pass.
    pub rays: RayCounts,
    /// What the frame's queries cost.
    pub work: Work,
    /// Pixels whose object or radiance differs from the first exact structure's frame.
    pub differing_pixels: usize,
}

/// One structure built over one scene.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BuildRow {
    /// Triangles indexed.
    pub triangles: usize,
    /// Structure name.
    #[serde(with = "registry_name")]
    pub structure: RegistryName,
    /// Its parameters.
    pub settings: AccelSettings,
    /// Build seconds.
    pub build_seconds: f64,
    /// Bytes beyond the triangles.
    pub memory_bytes: u64,
}

/// A frame kept as a picture.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Picture {
    /// Shading.
    pub shading: ShadingName,
    /// Frame index.
    pub frame: u32,
    /// Radiance, row-major.
    pub radiance: Vec<f32>,
}

/// Everything a run (or one block of it) measured.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct FramesOutcome {
    /// Every frame of every structure.
    pub frames: Vec<FrameRow>,
    /// Every build.
    pub builds: Vec<BuildRow>,
    /// The strip: frames of the first viewpoint of the largest scene, by the first structure.
    pub pictures: Vec<Picture>,
    /// The scenes, as their generators describe them.
    pub scenes: Vec<String>,
    /// Every tuning candidate timed, after the block that tuned it ([`Block::label`]).
    #[serde(default)]
    pub tuning: Vec<(String, super::tuning::TuningRow)>,
}

/// How a row names the way its structure follows motion: an [`UpdateMethod`]'s name, or `none`.
pub type UpdateName = &'static str;

/// Serde for [`UpdateName`]: read back as one of the names, or refused.
mod update_name {
    use super::{UpdateMethod, UpdateName};

    pub fn serialize<S: serde::Serializer>(name: &UpdateName, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(name)
    }

    pub fn deserialize<'de, D: serde::Deserializer<'de>>(d: D) -> Result<UpdateName, D::Error> {
        let name = <String as serde::Deserialize>::deserialize(d)?;
        UpdateMethod::ALL
            .iter()
            .map(|m| m.name())
            .chain(["none"])
            .find(|n| *n == name)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown update `{name}`")))
    }
}

/// One structure's scene, and how it follows motion.
struct Variant {
    structure: &'static str,
    /// How the structure follows motion (none for static scenes).
    update: Option<UpdateMethod>,
    scene: Scene,
}

impl Variant {
    /// Moves part `object` by `step` in this variant's scene (the scene's triangles become
    /// `moved`) and brings its structure up to date its own way; returns the update's time and
    /// what the structure says it did.
    fn update(&mut self, moved: &Triangles, object: u32, step: DVec3) -> anyhow::Result<(Duration, Updated)> {
        let mut accel = self.scene.accel.take().expect("generated scenes have triangles");
        let start = Instant::now();
        let did = Arc::get_mut(&mut accel)
            .expect("a variant's structure is its own")
            .update(
                self.update.expect("only variants of a moving scene are updated"),
                moved,
                object,
                step,
            )?;
        let took = start.elapsed();
        self.scene.accel = Some(accel);
        self.scene.triangles.positions.clone_from(&moved.positions);
        Ok((took, did))
    }
}

/// The scene of `generated` indexed by `settings`; a build refused (its leaves past the memory
/// budget) is bad input at the structure's settings in the experiment file.
pub(super) fn build(spec: &FramesSpec, generated: &Generated, settings: &AccelSettings) -> anyhow::Result<Scene> {
    generated
        .scene(BTreeMap::new(), settings.clone())
        .map_err(|e| spec.places.refused(settings.name, &generated.description, e))
}

/// The variants of `generated`: one per structure, or with motion, one per way each structure
/// follows it (each with a structure of its own); and each structure's build.
fn variants(
    spec: &FramesSpec,
    generated: &Generated,
    structures: &[AccelSettings],
) -> anyhow::Result<(Vec<Variant>, Vec<BuildRow>)> {
    let mut out = Vec::new();
    let mut builds = Vec::new();
    for settings in structures {
        let scene = build(spec, generated, settings)?;
        let accel = scene.accel.as_ref().expect("generated scenes have triangles");
        let stats = accel.stats();
        builds.push(BuildRow {
            triangles: generated.triangle_count(),
            structure: settings.name,
            settings: settings.clone(),
            build_seconds: stats.build_time.as_secs_f64(),
            memory_bytes: stats.memory_bytes,
        });
        if spec.motion.is_none() {
            out.push(Variant {
                structure: settings.name,
                update: None,
                scene,
            });
            continue;
        }
        let methods = crate::accel::registered(settings.name).expect("registered").updates;
        for (k, &method) in methods.iter().enumerate() {
            let scene = if k + 1 == methods.len() {
                scene.clone()
            } else {
                build(spec, generated, settings)?
            };
            out.push(Variant {
                structure: settings.name,
                update: Some(method),
                scene,
            });
        }
    }
    Ok((out, builds))
}

/// Pixels where `a` and `b` see different objects or radiance.
fn differing(a: &Frame, b: &Frame) -> usize {
    (0..a.hit.len())
        .filter(|&i| a.hit[i] != b.hit[i] || a.radiance[i].to_bits() != b.radiance[i].to_bits())
        .count()
}

/// The frames kept as pictures: `count` evenly spaced along `frames`.
pub fn strip_frames(count: u32, frames: u32) -> Vec<u32> {
    let count = count.min(frames);
    (0..count).map(|k| k * frames / count.max(1)).collect()
}

/// A unit of a frame-time experiment: frames `frames` of the viewpoints and shadings in their
/// ranges (indices into the spec's lists), on scene `scene`. With `[path] block` a static
/// scene's block is one shading and viewpoint and that many frames; without it (and always
/// for a moving part, which carries its state from frame to frame along each path) a scene is
/// one block.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// Scene index.
    pub scene: usize,
    /// Shading indices.
    pub shadings: std::ops::Range<usize>,
    /// Viewpoint indices.
    pub viewpoints: std::ops::Range<usize>,
    /// Frames of the path.
    pub frames: std::ops::Range<u32>,
}

impl Block {
    /// Whether it is its scene's first block (which records the builds and the scene).
    fn first(&self) -> bool {
        self.shadings.start == 0 && self.viewpoints.start == 0 && self.frames.start == 0
    }

    /// The block as a unit's label names it: its scene, its shading and viewpoint where it has
    /// one of each, and its frames.
    pub fn label(&self, spec: &FramesSpec) -> String {
        let mut label = format!("scene={}", spec.scene_names()[self.scene]);
        if self.shadings.len() == 1 && self.viewpoints.len() == 1 {
            label += &format!(
                " shading={} viewpoint={}",
                spec.shadings[self.shadings.start].0.name(),
                spec.viewpoints[self.viewpoints.start]
            );
        }
        label + &format!(" frames={}..{}", self.frames.start, self.frames.end)
    }

    /// As a unit's coordinates.
    pub fn at(&self) -> Vec<usize> {
        vec![
            self.scene,
            self.shadings.start,
            self.shadings.end,
            self.viewpoints.start,
            self.viewpoints.end,
            self.frames.start as usize,
            self.frames.end as usize,
        ]
    }

    /// From a unit's coordinates ([`Block::at`]).
    pub fn of(at: &[usize]) -> Block {
        Block {
            scene: at[0],
            shadings: at[1]..at[2],
            viewpoints: at[3]..at[4],
            frames: at[5] as u32..at[6] as u32,
        }
    }
}

/// Every block of the experiment, in the order an unsharded run lists its rows: scene, shading,
/// viewpoint, frame.
pub fn blocks(spec: &FramesSpec) -> Vec<Block> {
    let mut out = Vec::new();
    for scene in 0..spec.scene_count() {
        let Some(block) = spec.block.filter(|_| spec.motion.is_none()) else {
            out.push(Block {
                scene,
                shadings: 0..spec.shadings.len(),
                viewpoints: 0..spec.viewpoints.len(),
                frames: 0..spec.frames,
            });
            continue;
        };
        for h in 0..spec.shadings.len() {
            for v in 0..spec.viewpoints.len() {
                for start in (0..spec.frames).step_by(block.max(1) as usize) {
                    out.push(Block {
                        scene,
                        shadings: h..h + 1,
                        viewpoints: v..v + 1,
                        frames: start..(start + block).min(spec.frames),
                    });
                }
            }
        }
    }
    out
}

/// Runs the whole experiment, block after block.
pub fn run_frames(spec: &FramesSpec, backend: &mut dyn Backend, progress: &Progress) -> anyhow::Result<FramesOutcome> {
    let mut outcome = FramesOutcome::default();
    for block in blocks(spec) {
        let o = run_block(spec, &block, backend, progress)?;
        outcome.frames.extend(o.frames);
        outcome.builds.extend(o.builds);
        outcome.pictures.extend(o.pictures);
        outcome.scenes.extend(o.scenes);
        outcome.tuning.extend(o.tuning);
    }
    Ok(outcome)
}

/// Runs one block: builds every structure over its scene, then renders and times its frames.
pub fn run_block(
    spec: &FramesSpec,
    block: &Block,
    backend: &mut dyn Backend,
    progress: &Progress,
) -> anyhow::Result<FramesOutcome> {
    let schedule = spec.header.schedule;
    let mut outcome = FramesOutcome::default();
    let strip = strip_frames(spec.strip, spec.frames);
    let s = block.scene;
    let generated = spec.scenes().nth(s).expect("a block's scene is the experiment's");
    let bar = progress.bar(
        &generated.description,
        (block.shadings.len() * block.viewpoints.len()) as u64 * block.frames.len() as u64,
    );
    bar.message(format!("tuning {} structures", spec.structures.len()));
    let (structures, tuning) = super::tuning::tune(spec, (&spec.scene_names()[s], &generated), backend)?;
    outcome
        .tuning
        .extend(tuning.into_iter().map(|t| (block.label(spec), t)));
    bar.message(format!("building {} structures", spec.structures.len()));
    let (mut variants, builds) = variants(spec, &generated, &structures)?;
    if block.first() {
        outcome.scenes.push(generated.description.clone());
        outcome.builds.extend(builds);
    }
    let triangles = generated.triangle_count();
    let scene_name = &spec.scene_names()[s];
    // A moving part moves along each path from where the scene puts it, the structures it
    // updates built afresh: every path is the same whether or not the others run (a filter on
    // shading or viewpoint keeps the whole run's rows).
    let mut current = generated.triangles();
    let moving = spec.motion.as_ref().map(|m| {
        let (index, _) = generated.part(&m.part).expect("validated part");
        (index as u32, m.step)
    });
    let mut as_built = true;
    for &(name, shading) in &spec.shadings[block.shadings.clone()] {
        bar.message(format!("{} shading", name.name()));
        for vp in block.viewpoints.clone() {
            if moving.is_some() && !as_built {
                bar.message(format!("rebuilding {} structures", spec.structures.len()));
                // The old set goes first: two sets at once would pass the memory check's peak.
                variants.clear();
                variants = self::variants(spec, &generated, &structures)?.0;
                current = generated.triangles();
            }
            as_built = false;
            for v in &mut variants {
                v.scene.shading = shading;
            }
            let viewpoint = &spec.viewpoints[vp];
            let first_camera = spec.camera(viewpoint, block.frames.start);
            let first_view = View {
                camera: &first_camera,
                width: spec.width,
                height: spec.height,
            };
            for v in &variants {
                for _ in 0..schedule.warmup {
                    backend.render(&v.scene, first_view, SAMPLING)?;
                }
            }
            for frame in block.frames.clone() {
                let camera = spec.camera(viewpoint, frame);
                let view = View {
                    camera: &camera,
                    width: spec.width,
                    height: spec.height,
                };
                let mut updates = vec![None; variants.len()];
                if let Some((object, step)) = moving {
                    for (t, &o) in current.positions.iter_mut().zip(&current.object_of) {
                        if o == object {
                            *t = t.map(|p| p + step);
                        }
                    }
                    for (v, u) in variants.iter_mut().zip(&mut updates) {
                        let (took, did) = v.update(&current, object, step).map_err(|e| {
                            spec.places
                                .refused(v.structure, &format!("updating for frame {frame}"), e)
                        })?;
                        *u = Some((took.as_secs_f64(), did));
                    }
                }
                // Every round renders each variant once, in the round's own order; the
                // first render of each gives the frame compared and counted.
                let mut frames: Vec<Option<Frame>> = vec![None; variants.len()];
                let rounds = frame_rounds(&schedule, (scene_name, name.name(), viewpoint, frame));
                let times = rounds.run(variants.len(), |i| -> anyhow::Result<f64> {
                    let start = Instant::now();
                    let f = backend.render(&variants[i].scene, view, SAMPLING)?;
                    let took = start.elapsed().as_secs_f64();
                    frames[i].get_or_insert(f);
                    Ok(took)
                })?;
                let frames: Vec<Frame> = frames
                    .into_iter()
                    .map(|f| f.expect("a frame experiment times every frame at least once"))
                    .collect();
                // Compared with the first exact structure's frame (the first one's where none is).
                let reference = variants
                    .iter()
                    .position(|v| crate::accel::is_exact(v.structure))
                    .unwrap_or(0);
                let first = &frames[reference];
                for (i, v) in variants.iter().enumerate() {
                    outcome.frames.push(FrameRow {
                        triangles,
                        structure: v.structure,
                        update: v.update.map_or("none", UpdateMethod::name),
                        shading: name,
                        viewpoint: viewpoint.clone(),
                        frame,
                        seconds: median(&times[i]),
                        renders: times[i].clone(),
                        update_seconds: updates[i].map(|u| u.0),
                        updated: updates[i].map(|u| u.1),
                        rays: frames[i].rays,
                        work: frames[i].work,
                        differing_pixels: differing(first, &frames[i]),
                    });
                }
                if s + 1 == spec.scene_count() && vp == 0 && strip.contains(&frame) {
                    outcome.pictures.push(Picture {
                        shading: name,
                        frame,
                        radiance: first.radiance.clone(),
                    });
                }
                bar.inc(1);
            }
        }
    }
    bar.finish();
    Ok(outcome)
}

/// The schedule of one frame's interleaved rounds: the experiment's seed, varied by the
/// frame's scene, shading, viewpoint (by name: a filtered run keeps the whole run's orders) and
/// number, so every frame's rounds visit the structures in their own orders.
fn frame_rounds(
    schedule: &crate::timing::Schedule,
    (scene, shading, viewpoint, frame): (&str, &str, &str, u32),
) -> crate::timing::Schedule {
    let at = crate::fingerprint::fnv1a(format!("{scene}|{shading}|{viewpoint}|{frame}").as_bytes());
    let seed = crate::sampling::rng::pcg(schedule.seed ^ crate::sampling::rng::pcg(at as u32 ^ (at >> 32) as u32));
    crate::timing::Schedule { seed, ..*schedule }
}
