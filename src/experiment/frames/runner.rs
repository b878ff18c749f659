//! Runs a frame-time experiment on the f64 CPU backend, where every structure answers exactly
//! and frames can be compared pixel for pixel: per scene, each structure is built once (its
//! build time and memory recorded); then, for each shading and viewpoint, every frame of the
//! path is rendered by every structure in a fresh seeded order (so a change of machine load
//! falls on all alike), each render timed, and each structure's frame compared with the first
//! structure's. With a `[motion]`, one part moves by a step before each frame and each
//! structure is first updated its own way: the field in place (paper Section 8), the BVH by a
//! refit and by rebuilds (its own preset and obvhs' fastest), the kd-tree by a rebuild; the
//! update is timed too. Before each shading and viewpoint every structure renders the first
//! frame once, untimed (warm caches).

use super::spec::{FramesSpec, ShadingName};
use crate::accel::bvh::Bvh;
use crate::accel::vlf::VisibilityField;
use crate::accel::{self, AccelSettings, Accelerator, Preset};
use crate::mesh::Triangles;
use crate::render::cpu::CpuBackend;
use crate::render::{Backend, Frame, Sampling, View};
use crate::sampling::rng::pcg;
use crate::sampling::{DiskScheme, Pattern};
use crate::scene::procedural::Generated;
use crate::scene::Scene;
use glam::DVec3;
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The frames' sampling (point lights need none; fixed for the record).
const SAMPLING: Sampling = Sampling {
    scheme: DiskScheme::Uniform,
    pattern: Pattern::PerPixel,
    seed: 1,
};

/// One frame of one structure, timed.
#[derive(Clone, Debug)]
pub struct FrameRow {
    /// Triangles in the scene.
    pub triangles: usize,
    /// Structure name.
    pub structure: &'static str,
    /// How it follows a moving part (`none` for static scenes).
    pub update: &'static str,
    /// Shading.
    pub shading: ShadingName,
    /// Viewpoint.
    pub viewpoint: String,
    /// Frame index on the path.
    pub frame: u32,
    /// Median render seconds over the repeats.
    pub seconds: f64,
    /// Seconds the update before this frame took (dynamic scenes).
    pub update_seconds: Option<f64>,
    /// Rays the frame traced.
    pub rays: u64,
    /// Pixels whose object or radiance differs from the first structure's frame.
    pub differing_pixels: usize,
}

/// One structure built over one scene.
#[derive(Clone, Debug)]
pub struct BuildRow {
    /// Triangles indexed.
    pub triangles: usize,
    /// Structure name.
    pub structure: &'static str,
    /// Its parameters.
    pub parameters: String,
    /// Build seconds.
    pub build_seconds: f64,
    /// Bytes beyond the triangles.
    pub memory_bytes: u64,
}

/// A frame kept as a picture.
#[derive(Clone, Debug)]
pub struct Picture {
    /// Shading.
    pub shading: ShadingName,
    /// Frame index.
    pub frame: u32,
    /// Radiance, row-major.
    pub radiance: Vec<f32>,
}

/// Everything a run measured.
#[derive(Clone, Debug, Default)]
pub struct FramesOutcome {
    /// Every frame of every structure.
    pub frames: Vec<FrameRow>,
    /// Every build.
    pub builds: Vec<BuildRow>,
    /// The strip: frames of the first viewpoint of the largest scene, by the first structure.
    pub pictures: Vec<Picture>,
    /// The scenes, as their generators describe them.
    pub scenes: Vec<String>,
}

/// How one structure follows the moving part.
enum Follow {
    /// Never (static scenes).
    Static,
    /// The field's own update: remove, move, insert.
    Field(Arc<VisibilityField>),
    /// obvhs' refit of the BVH as built.
    Refit(Arc<Bvh>),
    /// A rebuild from scratch with the structure's settings.
    Rebuild(AccelSettings),
}

/// One structure's scene and how it follows motion.
struct Variant {
    structure: &'static str,
    update: &'static str,
    follow: Follow,
    scene: Scene,
}

impl Variant {
    /// Moves part `object` by `step` in this variant's scene (the scene's triangles become
    /// `moved`) and brings the structure up to date; returns the update's time.
    fn update(&mut self, moved: &Triangles, object: u32, step: DVec3) -> anyhow::Result<Duration> {
        self.scene.accel = None;
        let start = Instant::now();
        let accel: Arc<dyn Accelerator> = match &mut self.follow {
            Follow::Static => unreachable!("static variants are not updated"),
            Follow::Field(f) => {
                Arc::get_mut(f)
                    .expect("the scene's handle was dropped")
                    .move_object(object, |p| p + step)?;
                f.clone()
            }
            Follow::Refit(b) => {
                Arc::get_mut(b).expect("the scene's handle was dropped").refit(moved);
                b.clone()
            }
            Follow::Rebuild(settings) => accel::build(moved, settings)?.expect("the scene has triangles"),
        };
        let took = start.elapsed();
        self.scene.accel = Some(accel);
        self.scene.triangles.positions.clone_from(&moved.positions);
        Ok(took)
    }
}

/// The variants of `generated`: one per structure, or with motion, the ways each follows it.
fn variants(spec: &FramesSpec, generated: &Generated) -> anyhow::Result<(Vec<Variant>, Vec<BuildRow>)> {
    let mut out = Vec::new();
    let mut builds = Vec::new();
    for settings in &spec.structures {
        let scene = generated.scene(BTreeMap::new(), settings.clone())?;
        let stats = scene.accel.as_ref().expect("generated scenes have triangles").stats();
        builds.push(BuildRow {
            triangles: generated.triangle_count(),
            structure: settings.name,
            parameters: stats.parameters,
            build_seconds: stats.build_time.as_secs_f64(),
            memory_bytes: stats.memory_bytes,
        });
        if spec.motion.is_none() {
            out.push(Variant {
                structure: settings.name,
                update: "none",
                follow: Follow::Static,
                scene,
            });
            continue;
        }
        let triangles = generated.triangles();
        let mut follow = vec![("rebuild", Follow::Rebuild(settings.clone()))];
        match settings.name {
            "vlf" => {
                follow = vec![(
                    "update",
                    Follow::Field(Arc::new(VisibilityField::build(&triangles, settings.vlf)?)),
                )]
            }
            "bvh" => {
                // obvhs' fastest build too: the rebuild an engine would choose per frame.
                let fastest = AccelSettings {
                    bvh_preset: Preset::Fastest,
                    ..settings.clone()
                };
                follow.push(("rebuild-fastest", Follow::Rebuild(fastest)));
                follow.push((
                    "refit",
                    Follow::Refit(Arc::new(Bvh::build(&triangles, settings.bvh_preset))),
                ));
            }
            _ => {}
        }
        for (update, follow) in follow {
            let mut scene = scene.clone();
            scene.accel = match &follow {
                Follow::Field(f) => Some(f.clone() as Arc<dyn Accelerator>),
                Follow::Refit(b) => Some(b.clone() as Arc<dyn Accelerator>),
                _ => scene.accel,
            };
            out.push(Variant {
                structure: settings.name,
                update,
                follow,
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

/// Runs the experiment; `progress` hears each scene and shading as it starts.
pub fn run_frames(spec: &FramesSpec, progress: &dyn Fn(&str)) -> anyhow::Result<FramesOutcome> {
    let mut backend = CpuBackend::default();
    let mut outcome = FramesOutcome::default();
    let scenes = spec.scenes();
    let strip = strip_frames(spec.strip, spec.frames);
    for (s, generated) in scenes.iter().enumerate() {
        progress(&format!(
            "{}: building {} structures",
            generated.description,
            spec.structures.len()
        ));
        outcome.scenes.push(generated.description.clone());
        let (mut variants, builds) = variants(spec, generated)?;
        outcome.builds.extend(builds);
        let triangles = generated.triangle_count();
        // A moving part keeps moving through every shading and viewpoint: the structures it
        // updates carry their state along.
        let mut current = generated.triangles();
        let moving = spec.motion.as_ref().map(|m| {
            let (index, _) = generated.part(&m.part).expect("validated part");
            (index as u32, m.step)
        });
        for &(name, shading) in &spec.shadings {
            progress(&format!(
                "{}: {} frames, {} shading",
                generated.description,
                spec.frames,
                name.name()
            ));
            for v in &mut variants {
                v.scene.shading = shading;
            }
            for (vp, viewpoint) in spec.viewpoints.iter().enumerate() {
                // One untimed render per structure first, so no timed frame pays for cold caches.
                let first_camera = spec.camera(viewpoint, 0);
                let first_view = View {
                    camera: &first_camera,
                    width: spec.width,
                    height: spec.height,
                };
                for v in &variants {
                    backend.render(&v.scene, first_view, SAMPLING)?;
                }
                for frame in 0..spec.frames {
                    let camera = spec.camera(viewpoint, frame);
                    let view = View {
                        camera: &camera,
                        width: spec.width,
                        height: spec.height,
                    };
                    if let Some((object, step)) = moving {
                        for (t, &o) in current.positions.iter_mut().zip(&current.object_of) {
                            if o == object {
                                *t = t.map(|p| p + step);
                            }
                        }
                    }
                    let mut order: Vec<usize> = (0..variants.len()).collect();
                    order.sort_by_key(|&i| pcg(pcg(frame ^ ((vp as u32) << 20)) ^ i as u32));
                    let mut rendered: Vec<Option<(Frame, f64, Option<f64>)>> = vec![None; variants.len()];
                    for i in order {
                        let v = &mut variants[i];
                        let update = match moving {
                            Some((object, step)) => Some(v.update(&current, object, step)?.as_secs_f64()),
                            None => None,
                        };
                        let mut times = Vec::new();
                        let mut kept = None;
                        for _ in 0..spec.repeats {
                            let start = Instant::now();
                            let f = backend.render(&v.scene, view, SAMPLING)?;
                            times.push(start.elapsed().as_secs_f64());
                            kept.get_or_insert(f);
                        }
                        rendered[i] = Some((
                            kept.expect("one repeat at least"),
                            crate::metrics::stats::median(&times),
                            update,
                        ));
                    }
                    let rendered: Vec<(Frame, f64, Option<f64>)> = rendered
                        .into_iter()
                        .map(|r| r.expect("every variant rendered"))
                        .collect();
                    let first = &rendered[0].0;
                    for (v, (f, seconds, update_seconds)) in variants.iter().zip(&rendered) {
                        outcome.frames.push(FrameRow {
                            triangles,
                            structure: v.structure,
                            update: v.update,
                            shading: name,
                            viewpoint: viewpoint.clone(),
                            frame,
                            seconds: *seconds,
                            update_seconds: *update_seconds,
                            rays: f.rays.total(),
                            differing_pixels: differing(first, f),
                        });
                    }
                    if s + 1 == scenes.len() && vp == 0 && strip.contains(&frame) {
                        outcome.pictures.push(Picture {
                            shading: name,
                            frame,
                            radiance: first.radiance.clone(),
                        });
                    }
                }
            }
        }
    }
    Ok(outcome)
}
