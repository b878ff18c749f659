//! Runs an ambient-occlusion experiment on the f64 CPU backend, where every structure answers
//! exactly, or on the GPU where asked (`backend = "gpu"`: every structure's f32 walk runs the same
//! triangle test, its direction-major issue one dispatch per direction): per mesh, each structure
//! is tuned over its candidates (timed at a small size in interleaved rounds; the first listed
//! kept unless another is decidedly faster), built at the settings kept, and renders the AO
//! image once (untimed; its rays and work counted; every structure's image must equal the
//! first's bit for bit); then the mesh's structures are timed in the experiment's interleaved
//! rounds.

use super::spec::{AoMesh, AoSpec};
use crate::accel::settings::{registry_name, RegistryName};
use crate::accel::work::Work;
use crate::accel::{AccelSettings, Issue};
use crate::experiment::progress::Progress;
use crate::experiment::tuning::{verdicts, Verdict};
use crate::render::{Backend, Sampling, View};
use crate::sampling::{DiskScheme, Pattern};
use crate::scene::ambient::AmbientOcclusion;
use crate::scene::camera::{Camera, Projection};
use crate::scene::{Mesh, Scene};
use crate::timing::tuning::keep;
use crate::timing::{median_interval, Estimate, Schedule};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One mesh and structure, measured.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AoRow {
    /// Mesh label.
    pub mesh: String,
    /// Its triangles.
    pub triangles: usize,
    /// Structure name.
    #[serde(with = "registry_name")]
    pub structure: RegistryName,
    /// How the AO rays were issued.
    pub issue: Issue,
    /// Its build parameters.
    pub settings: AccelSettings,
    /// Build time, seconds.
    pub build_seconds: f64,
    /// Structure bytes beyond the triangles.
    pub memory_bytes: u64,
    /// Timed frames, seconds, one per round.
    pub frame_seconds: Vec<f64>,
    /// Median frame seconds with its 95 % interval.
    pub frame: Estimate,
    /// Camera rays and AO rays of a frame.
    pub rays: (u64, u64),
    /// What a frame's queries cost.
    pub work: Work,
    /// Pixels that see the mesh.
    pub receivers: usize,
    /// Mean AO over those pixels.
    pub mean_ao: f64,
    /// Whether the AO image equals the reference image (the first exact structure's on the
    /// mesh) bit for bit.
    pub same_image: bool,
    /// Pixels whose AO differs from the reference image's.
    #[serde(default)]
    pub differing_pixels: usize,
    /// Mean AO difference from the reference image over its receivers (this image's minus the
    /// reference's, over pixels that are receivers in both; an inexact structure's extra or
    /// lost occluders in one number).
    #[serde(default)]
    pub ao_difference: f64,
    /// The AO image (receivers in [0, 1], else -1).
    pub image: Vec<f32>,
}

impl AoRow {
    /// The structure, with `bundled` after it where the rays were bundled.
    pub fn label(&self) -> String {
        self.issue.label(self.structure)
    }

    /// Rays (camera and AO) per second at the median frame time.
    pub fn rays_per_s(&self) -> f64 {
        (self.rays.0 + self.rays.1) as f64 / self.frame.median
    }
}

/// The camera every mesh is seen by: 2.6 ball radii away, looking at the ball's centre from
/// above one side, its field of view just holding the unit ball.
pub fn camera() -> Camera {
    let position = DVec3::new(1.2, -2.1, 1.0).normalize() * 2.6;
    Camera {
        position,
        look_at: DVec3::ZERO,
        up: DVec3::Z,
        projection: Projection::Perspective {
            fov_y_deg: 2.0 * (1.0f64 / 2.6).asin().to_degrees() + 2.0,
        },
    }
}

/// One candidate of the tuning sweep, timed.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TuningRow {
    /// Mesh label.
    pub mesh: String,
    /// Structure name.
    #[serde(with = "registry_name")]
    pub structure: RegistryName,
    /// Its parameters.
    pub settings: AccelSettings,
    /// Median frame seconds at the tuning size, with its interval (NaN where reused).
    pub frame: Estimate,
    /// What a frame at the tuning size cost (zero where reused).
    pub work: Work,
    /// How it was judged, and its per-round times.
    pub verdict: Verdict,
    /// Whether this candidate was kept.
    pub chosen: bool,
}

/// The AO frames' sampling (the grid needs none; fixed for the record).
const SAMPLING: Sampling = Sampling {
    scheme: DiskScheme::Uniform,
    pattern: Pattern::PerPixel,
    seed: 1,
    frame: 0,
};

/// The scene of `mesh` indexed by the structure `settings` name, with the experiment's AO pass;
/// a build refused (its leaves past the memory budget) is bad input at the structure's settings.
pub fn ao_scene(spec: &AoSpec, mesh: &AoMesh, settings: AccelSettings) -> anyhow::Result<Scene> {
    let descriptor = Mesh {
        source: mesh.path.display().to_string(),
        file_fnv1a: mesh.file_fnv1a,
        albedo: 0.8,
        mirror: 0.0,
        triangles: mesh.triangles.positions.len(),
        skipped: Default::default(),
    };
    let name = settings.name;
    let scene = Scene::analytic(vec![], vec![], vec![])
        .with_cameras(BTreeMap::from([("ao".to_string(), camera())]))
        .try_with_meshes(vec![descriptor], mesh.triangles.clone(), settings)
        .map_err(|e| spec.places.refused(name, &format!("mesh `{}`", mesh.name), e))?
        .with_ambient(Some(spec.ao.clone()));
    Ok(scene)
}

/// Times `scenes` at `width` x `height` in `schedule`'s interleaved rounds: per scene, its
/// frames in round order.
fn time_scenes(
    scenes: &[Scene],
    (width, height): (u32, u32),
    schedule: &Schedule,
    backend: &mut dyn Backend,
    tick: &dyn Fn(),
) -> anyhow::Result<Vec<Vec<f64>>> {
    schedule.run(scenes.len(), |i| -> anyhow::Result<f64> {
        let view = View {
            camera: &scenes[i].cameras["ao"],
            width,
            height,
        };
        let t = backend.time(&scenes[i], view, SAMPLING, schedule.warmup, 1)?;
        tick();
        Ok(t.seconds[0])
    })
}

/// The candidate of `structure` kept on `mesh` ([`keep`]: the first listed unless another is
/// decidedly faster, all timed at the tuning size in interleaved rounds), and every candidate's
/// row; a single candidate is not timed, and one kept by `--tuning` is taken as it is.
fn tune(
    spec: &AoSpec,
    mesh: &AoMesh,
    (structure, candidates): (&'static str, &[AccelSettings]),
    backend: &mut dyn Backend,
) -> anyhow::Result<(AccelSettings, Vec<TuningRow>)> {
    if candidates.len() == 1 {
        return Ok((candidates[0].clone(), vec![]));
    }
    if let Some(kept) = spec.reused.as_ref().and_then(|r| r.get(&mesh.name, structure)) {
        let candidate = candidates.iter().position(|c| c == kept).expect("checked on reading");
        let row = TuningRow {
            mesh: mesh.name.clone(),
            structure,
            settings: kept.clone(),
            frame: Estimate::NAN,
            work: Work::ZERO,
            verdict: Verdict::reused(candidate),
            chosen: true,
        };
        return Ok((kept.clone(), vec![row]));
    }
    let scenes = candidates
        .iter()
        .map(|s| ao_scene(spec, mesh, s.clone()))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let size = (spec.tuning.width, spec.tuning.height);
    let mut work = Vec::new();
    for scene in &scenes {
        let view = View {
            camera: &scene.cameras["ao"],
            width: size.0,
            height: size.1,
        };
        work.push(backend.render(scene, view, SAMPLING)?.work);
    }
    let schedule = Schedule {
        repeats: spec.tuning.repeats,
        ..spec.header.schedule
    };
    let times = time_scenes(&scenes, size, &schedule, backend, &|| {})?;
    let kept = keep(&times);
    let estimates: Vec<Estimate> = times.iter().map(|t| median_interval(t)).collect();
    let rows = candidates
        .iter()
        .zip(estimates)
        .zip(work)
        .zip(verdicts(&kept, times))
        .map(|(((settings, frame), work), verdict)| TuningRow {
            mesh: mesh.name.clone(),
            structure,
            settings: settings.clone(),
            frame,
            work,
            chosen: verdict.candidate == kept.index,
            verdict,
        })
        .collect();
    Ok((candidates[kept.index].clone(), rows))
}

/// One untimed frame of `scene` (`structure` at `settings`, rays issued as `issue`): its image,
/// rays and work (compared with the reference image by [`compare`]).
fn measure(
    spec: &AoSpec,
    mesh: &AoMesh,
    (structure, settings, issue): (&'static str, &AccelSettings, Issue),
    scene: &Scene,
    backend: &mut dyn Backend,
) -> anyhow::Result<AoRow> {
    let stats = scene.accel.as_ref().expect("a mesh scene has a structure").stats();
    let view = View {
        camera: &scene.cameras["ao"],
        width: spec.width,
        height: spec.height,
    };
    let frame = backend.render(scene, view, SAMPLING)?;
    let image = frame.ambient.expect("the scene asks for ambient occlusion");
    let seen: Vec<f64> = image.iter().filter(|&&v| v >= 0.0).map(|&v| v as f64).collect();
    Ok(AoRow {
        mesh: mesh.name.clone(),
        triangles: mesh.triangles.positions.len(),
        structure,
        issue,
        settings: settings.clone(),
        build_seconds: stats.build_time.as_secs_f64(),
        memory_bytes: stats.memory_bytes,
        frame_seconds: Vec::new(),
        frame: Estimate::NAN,
        rays: (frame.rays.primary, frame.rays.ambient),
        work: frame.work,
        receivers: seen.len(),
        mean_ao: seen.iter().sum::<f64>() / seen.len().max(1) as f64,
        same_image: true,
        differing_pixels: 0,
        ao_difference: 0.0,
        image,
    })
}

/// Compares every row's image of one mesh with the reference, the first exact structure's:
/// every exact structure must equal it bit for bit; an inexact one (Embree's f32 tests) is
/// measured against it. Where no exact structure ran (a run filtered to Embree) nothing is
/// compared: rows keep `same_image` true and no differing pixels, and the report says that no
/// exact image was there to compare with.
pub fn compare(rows: &mut [AoRow]) {
    let Some(reference) = rows
        .iter()
        .find(|r| crate::accel::is_exact(r.structure))
        .map(|r| r.image.clone())
    else {
        return;
    };
    let receivers = reference.iter().filter(|&&v| v >= 0.0).count().max(1) as f64;
    for r in rows {
        r.same_image = r.image == reference;
        r.differing_pixels = r.image.iter().zip(&reference).filter(|(a, b)| a != b).count();
        r.ao_difference = r
            .image
            .iter()
            .zip(&reference)
            .filter(|(&a, &b)| a >= 0.0 && b >= 0.0)
            .map(|(&a, &b)| a as f64 - b as f64)
            .sum::<f64>()
            / receivers;
    }
}

/// What one mesh's unit measured: a row per structure and way of issuing rays, and the tuning
/// candidates timed.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct MeshOutcome {
    /// One row per structure and issue, in the experiment's order.
    pub rows: Vec<AoRow>,
    /// Every tuning candidate timed.
    pub tuning: Vec<TuningRow>,
}

/// Every structure of the experiment on `mesh`, each tuned first, then all of them timed in
/// one schedule's interleaved rounds (a mesh is one unit of work: its times compare only with
/// each other).
pub fn run_mesh(
    spec: &AoSpec,
    mesh: &AoMesh,
    backend: &mut dyn Backend,
    progress: &Progress,
) -> anyhow::Result<MeshOutcome> {
    let schedule = spec.header.schedule;
    let on_gpu = backend.adapter().is_gpu();
    let bar = progress.bar(&format!("{}: structures", mesh.name), spec.structures.len() as u64);
    let mut out = MeshOutcome::default();
    let mut scenes = Vec::new();
    for (structure, candidates) in &spec.structures {
        bar.message(structure.to_string());
        let (settings, tried) = tune(spec, mesh, (structure, candidates), backend)?;
        out.tuning.extend(tried);
        // One build per structure: each way of issuing the rays shares it.
        let built = ao_scene(spec, mesh, settings.clone())?;
        // On the GPU a bundle is an order of dispatch, which every structure can take; on the
        // CPU only a structure with a bundle walk of its own has one.
        let bundles = on_gpu || built.accel.as_ref().is_some_and(|a| a.bundles());
        for &issue in spec.issues.iter().filter(|&&i| i == Issue::Single || bundles) {
            let scene = built.clone().with_ambient(Some(AmbientOcclusion {
                issue,
                ..spec.ao.clone()
            }));
            out.rows
                .push(measure(spec, mesh, (structure, &settings, issue), &scene, backend)?);
            scenes.push(scene);
        }
        bar.inc(1);
    }
    compare(&mut out.rows);
    bar.message(format!("timing {} rounds", schedule.repeats));
    let times = time_scenes(&scenes, (spec.width, spec.height), &schedule, backend, &|| {})?;
    for (row, t) in out.rows.iter_mut().zip(times) {
        row.frame = median_interval(&t);
        row.frame_seconds = t;
    }
    bar.finish();
    Ok(out)
}

/// Every mesh of the experiment in file order, as an unsharded run measures them: the rows and
/// the tuning candidates.
pub fn run_ao(
    spec: &AoSpec,
    backend: &mut dyn Backend,
    progress: &Progress,
) -> anyhow::Result<(Vec<AoRow>, Vec<TuningRow>)> {
    let (mut rows, mut tuning) = (Vec::new(), Vec::new());
    for mesh in &spec.meshes {
        let out = run_mesh(spec, mesh, backend, progress)?;
        rows.extend(out.rows);
        tuning.extend(out.tuning);
    }
    Ok((rows, tuning))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(structure: &'static str, image: Vec<f32>) -> AoRow {
        AoRow {
            mesh: "m".into(),
            triangles: 1,
            structure,
            issue: Issue::Single,
            settings: AccelSettings::named(structure).unwrap(),
            build_seconds: 0.0,
            memory_bytes: 0,
            frame_seconds: vec![],
            frame: Estimate::NAN,
            rays: (0, 0),
            work: Work::ZERO,
            receivers: 0,
            mean_ao: 0.0,
            same_image: true,
            differing_pixels: 0,
            ao_difference: 0.0,
            image,
        }
    }

    /// The reference is the first exact structure's image even where an inexact one comes
    /// first; the difference is taken over pixels that are receivers in both; with no exact
    /// structure nothing is compared.
    #[test]
    fn images_are_compared_with_the_first_exact_structures() {
        let exact = vec![0.5, 0.25, -1.0, 1.0];
        let mut rows = vec![
            row("embree", vec![0.25, 0.25, -1.0, -1.0]),
            row("kdtree", exact.clone()),
            row("bvh", vec![0.5, 0.25, -1.0, 0.75]),
        ];
        compare(&mut rows);
        assert_eq!((rows[0].same_image, rows[0].differing_pixels), (false, 2));
        // Receivers in both: pixels 0 and 1 (pixel 3 is a miss in Embree's image); over the
        // reference's 3 receivers.
        assert!(
            (rows[0].ao_difference - (-0.25 / 3.0)).abs() < 1e-12,
            "{}",
            rows[0].ao_difference
        );
        assert_eq!((rows[1].same_image, rows[1].differing_pixels), (true, 0));
        assert_eq!((rows[2].same_image, rows[2].differing_pixels), (false, 1));
        let mut alone = vec![row("embree", vec![0.25, 0.5]), row("embree", vec![0.5, 0.5])];
        compare(&mut alone);
        assert!(alone.iter().all(|r| r.same_image && r.differing_pixels == 0));
    }
}
