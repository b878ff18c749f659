//! Each structure tuned per scene before its frames are timed, as the visibility-field paper
//! tuned both of its methods per scene (Table 1 gives each one's best depth) and as the ao kind
//! does: a structure whose `[accel.NAME]` table lists several values is built at every
//! combination, each candidate renders the tuning cameras at the experiment's own resolution
//! ([`tuning_shading`]) in interleaved rounds, and the first listed is kept unless a later one
//! is decidedly faster than the one kept so far ([`keep`]). The tuning cameras are
//! drawn at random from every viewpoint with their own seed, never the frames measured, so the
//! choice is not fitted to the frames it is judged on. A structure with one candidate is not
//! timed. Candidates of one structure are held together and dropped before the next is tuned.

pub use super::candidates::FramesTuning;

use super::spec::{FramesSpec, Generator, ShadingName, SAMPLING};
use crate::accel::settings::{registry_name, RegistryName};
use crate::accel::work::Work;
use crate::accel::AccelSettings;
use crate::experiment::tuning::{verdicts, Verdict};
use crate::render::{Backend, View};
use crate::scene::camera::Camera;
use crate::scene::procedural::{classroom, random, Generated};
use crate::timing::tuning::keep;
use crate::timing::{median_interval, Estimate, Schedule};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// One candidate of the tuning sweep, timed: a row of tuning.csv.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TuningRow {
    /// The scene, as the `scene` axis names it.
    pub scene: String,
    /// Triangles in the scene.
    pub triangles: usize,
    /// Structure name.
    #[serde(with = "registry_name")]
    pub structure: RegistryName,
    /// Its parameters.
    pub settings: AccelSettings,
    /// Median seconds to render every tuning camera once, with its interval over rounds (NaN
    /// where reused).
    pub seconds: Estimate,
    /// What rendering every tuning camera once cost.
    pub work: Work,
    /// Build seconds.
    pub build_seconds: f64,
    /// How it was judged, and its per-round times.
    pub verdict: Verdict,
    /// Whether this candidate was kept.
    pub chosen: bool,
}

/// The shading candidates are timed under: Whitted where the experiment renders it (its shadow
/// and mirror rays are most of the work), else the first listed.
pub fn tuning_shading(spec: &FramesSpec) -> ShadingName {
    let listed = |n| spec.shadings.iter().any(|(s, _)| *s == n);
    if listed(ShadingName::Whitted) {
        ShadingName::Whitted
    } else {
        spec.shadings[0].0
    }
}

/// The tuning cameras of `spec`: `cameras` draws from each viewpoint with the tuning seed.
fn tuning_cameras(spec: &FramesSpec) -> Vec<Camera> {
    let t = &spec.tuning;
    spec.viewpoints
        .iter()
        .flat_map(|v| {
            (0..t.cameras).map(move |k| {
                let mut c = match spec.generator {
                    Generator::Classroom => classroom::random_camera(t.seed, k),
                    Generator::RandomTriangles { .. } => {
                        random::random_camera(v, t.seed, k).expect("viewpoints are validated")
                    }
                };
                if let Some(p) = spec.look_at {
                    c.look_at = p;
                }
                c
            })
        })
        .collect()
}

/// The settings each structure of `spec` renders `generated` (the scene named `scene`) with:
/// the candidate [`keep`] keeps, the one `--tuning` kept, or its one; and every candidate's row.
pub fn tune(
    spec: &FramesSpec,
    (scene, generated): (&str, &Generated),
    backend: &mut dyn Backend,
) -> anyhow::Result<(Vec<AccelSettings>, Vec<TuningRow>)> {
    let cameras = tuning_cameras(spec);
    let shading = spec
        .shadings
        .iter()
        .find(|(n, _)| *n == tuning_shading(spec))
        .expect("the tuning shading is listed")
        .1;
    let (mut chosen, mut rows) = (Vec::new(), Vec::new());
    for candidates in &spec.candidates {
        if candidates.len() == 1 {
            chosen.push(candidates[0].clone());
            continue;
        }
        if let Some(kept) = spec.reused.as_ref().and_then(|r| r.get(scene, candidates[0].name)) {
            let candidate = candidates.iter().position(|c| c == kept).expect("checked on reading");
            rows.push(TuningRow {
                scene: scene.to_string(),
                triangles: generated.triangle_count(),
                structure: kept.name,
                settings: kept.clone(),
                seconds: Estimate::NAN,
                work: Work::ZERO,
                build_seconds: f64::NAN,
                verdict: Verdict::reused(candidate),
                chosen: true,
            });
            chosen.push(kept.clone());
            continue;
        }
        let mut scenes = Vec::new();
        for c in candidates {
            let mut scene = super::runner::build(spec, generated, c)?;
            scene.shading = shading;
            scenes.push(scene);
        }
        let view = |camera| View {
            camera,
            width: spec.width,
            height: spec.height,
        };
        let mut work = vec![Work::ZERO; scenes.len()];
        for (scene, w) in scenes.iter().zip(&mut work) {
            for c in &cameras {
                *w += backend.render(scene, view(c), SAMPLING)?.work;
            }
        }
        let schedule = Schedule {
            repeats: spec.tuning.repeats,
            warmup: 0,
            seed: spec.tuning.seed ^ spec.header.schedule.seed,
        };
        let times = schedule.run(scenes.len(), |i| -> anyhow::Result<f64> {
            let start = Instant::now();
            for c in &cameras {
                backend.render(&scenes[i], view(c), SAMPLING)?;
            }
            Ok(start.elapsed().as_secs_f64())
        })?;
        let kept = keep(&times);
        let estimates: Vec<Estimate> = times.iter().map(|t| median_interval(t)).collect();
        for ((c, seconds), ((w, built), verdict)) in candidates
            .iter()
            .zip(estimates)
            .zip(work.into_iter().zip(&scenes).zip(verdicts(&kept, times)))
        {
            rows.push(TuningRow {
                scene: scene.to_string(),
                triangles: generated.triangle_count(),
                structure: c.name,
                settings: c.clone(),
                seconds,
                work: w,
                build_seconds: built.accel.as_ref().map_or(0.0, |a| a.stats().build_time.as_secs_f64()),
                chosen: verdict.candidate == kept.index,
                verdict,
            });
        }
        chosen.push(candidates[kept.index].clone());
    }
    Ok((chosen, rows))
}
