//! Runs an ambient-occlusion experiment on the f64 CPU backend, where every structure answers
//! exactly (the GPU's f32 walks may decide a grazing ray differently): per mesh, each structure is tuned (the kd-tree's depth and leaf size, the field's
//! tile-BSP depth, timed at a small size), built at the settings kept and renders the AO image
//! once (untimed; every structure's image must equal the first's bit for bit); then the mesh's
//! structures are timed in `repeats` interleaved rounds.

use super::spec::{best_settings, AoMesh, AoSpec};
use crate::accel::kdtree::KdSettings;
use crate::accel::vlf::VlfSettings;
use crate::accel::AccelSettings;
use crate::render::cpu::CpuBackend;
use crate::render::{Backend, Sampling, View};
use crate::sampling::rng::pcg;
use crate::sampling::{DiskScheme, Pattern};
use crate::scene::camera::{Camera, Projection};
use crate::scene::{Mesh, Scene};
use glam::DVec3;
use std::collections::BTreeMap;

/// One mesh and structure, measured.
#[derive(Clone, Debug)]
pub struct AoRow {
    /// Mesh label.
    pub mesh: String,
    /// Its triangles.
    pub triangles: usize,
    /// Structure name.
    pub structure: &'static str,
    /// Its build parameters.
    pub parameters: String,
    /// Build time, seconds.
    pub build_seconds: f64,
    /// Structure bytes beyond the triangles.
    pub memory_bytes: u64,
    /// Timed frames, seconds.
    pub frame_seconds: Vec<f64>,
    /// Camera rays and AO rays of a frame.
    pub rays: (u64, u64),
    /// Pixels that see the mesh.
    pub receivers: usize,
    /// Mean AO over those pixels.
    pub mean_ao: f64,
    /// Whether the AO image equals the first structure's bit for bit.
    pub same_image: bool,
    /// The AO image (receivers in [0, 1], else -1).
    pub image: Vec<f32>,
}

impl AoRow {
    /// Median frame time, seconds.
    pub fn median_seconds(&self) -> f64 {
        crate::metrics::stats::median(&self.frame_seconds)
    }

    /// First and third quartiles of the frame time, seconds.
    pub fn quartile_seconds(&self) -> (f64, f64) {
        let (q1, _, q3) = crate::metrics::stats::quartiles(&self.frame_seconds);
        (q1, q3)
    }

    /// Rays (camera and AO) per second at the median frame time, millions.
    pub fn mrays_per_s(&self) -> f64 {
        (self.rays.0 + self.rays.1) as f64 / self.median_seconds() / 1e6
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
#[derive(Clone, Debug)]
pub struct TuningRow {
    /// Mesh label.
    pub mesh: String,
    /// Structure name.
    pub structure: &'static str,
    /// Its parameters.
    pub parameters: String,
    /// Median frame seconds at the tuning size.
    pub frame_seconds: f64,
    /// Whether this candidate was kept.
    pub chosen: bool,
}

/// The candidates the tuning sweep tries for `structure` (one, untuned, for the others).
fn candidates(spec: &AoSpec, structure: &'static str) -> Vec<AccelSettings> {
    let base = best_settings(structure);
    match structure {
        "kdtree" => spec
            .tuning
            .kdtree_depths
            .iter()
            .flat_map(|&max_depth| {
                spec.tuning.kdtree_leaves.iter().map(move |&leaf_size| AccelSettings {
                    kdtree: KdSettings { max_depth, leaf_size },
                    ..best_settings(structure)
                })
            })
            .collect(),
        "vlf" => spec
            .tuning
            .vlf_depths
            .iter()
            .map(|&depth| AccelSettings {
                vlf: VlfSettings { depth, ..base.vlf },
                ..best_settings(structure)
            })
            .collect(),
        _ => vec![base],
    }
}

/// The fastest of `structure`'s candidates on `mesh` at the tuning size, and every candidate's
/// row (a single candidate is not timed).
fn tune(
    spec: &AoSpec,
    mesh: &AoMesh,
    structure: &'static str,
    backend: &mut CpuBackend,
) -> anyhow::Result<(AccelSettings, Vec<TuningRow>)> {
    let all = candidates(spec, structure);
    if all.len() == 1 {
        return Ok((all[0].clone(), vec![]));
    }
    let mut rows = Vec::new();
    let mut best: Option<(f64, AccelSettings)> = None;
    for settings in all {
        let scene = ao_scene(spec, mesh, settings.clone())?;
        let view = View {
            camera: &scene.cameras["ao"],
            width: spec.tuning.width,
            height: spec.tuning.height,
        };
        let t = crate::metrics::stats::median(&backend.time(&scene, view, SAMPLING, 1, spec.tuning.frames)?.seconds);
        rows.push(TuningRow {
            mesh: mesh.name.clone(),
            structure,
            parameters: scene.accel.as_ref().expect("a structure").stats().parameters,
            frame_seconds: t,
            chosen: false,
        });
        if best.as_ref().is_none_or(|b| t < b.0) {
            best = Some((t, settings));
        }
    }
    let (t, settings) = best.expect("at least one candidate");
    if let Some(r) = rows.iter_mut().find(|r| r.frame_seconds == t) {
        r.chosen = true;
    }
    Ok((settings, rows))
}

/// The AO frames' sampling (the grid needs none; fixed for the record).
const SAMPLING: Sampling = Sampling {
    scheme: DiskScheme::Uniform,
    pattern: Pattern::PerPixel,
    seed: 1,
};

/// The scene of `mesh` indexed by the structure `settings` name, with the experiment's AO pass.
pub fn ao_scene(spec: &AoSpec, mesh: &AoMesh, settings: AccelSettings) -> anyhow::Result<Scene> {
    let descriptor = Mesh {
        source: mesh.path.display().to_string(),
        file_fnv1a: mesh.file_fnv1a,
        albedo: 0.8,
        mirror: 0.0,
        triangles: mesh.triangles.positions.len(),
        skipped: Default::default(),
    };
    let scene = Scene::analytic(vec![], vec![], vec![])
        .with_cameras(BTreeMap::from([("ao".to_string(), camera())]))
        .try_with_meshes(vec![descriptor], mesh.triangles.clone(), settings)?
        .with_ambient(Some(spec.ao.clone()));
    Ok(scene)
}

/// Every mesh x structure of the experiment, in file order, each structure tuned per mesh
/// first; `progress` hears each as it starts.
pub fn run_ao(spec: &AoSpec, progress: &dyn Fn(&str, &str)) -> anyhow::Result<(Vec<AoRow>, Vec<TuningRow>)> {
    let mut backend = CpuBackend::default();
    let sampling = SAMPLING;
    let mut rows = Vec::new();
    let mut tuning = Vec::new();
    for mesh in &spec.meshes {
        let mut first: Option<Vec<f32>> = None;
        let mut scenes = Vec::new();
        for &structure in &spec.structures {
            progress(&mesh.name, structure);
            let (settings, tried) = tune(spec, mesh, structure, &mut backend)?;
            tuning.extend(tried);
            let scene = ao_scene(spec, mesh, settings)?;
            let stats = scene.accel.as_ref().expect("a mesh scene has a structure").stats();
            let view = View {
                camera: &scene.cameras["ao"],
                width: spec.width,
                height: spec.height,
            };
            let frame = backend.render(&scene, view, sampling)?;
            let image = frame.ambient.expect("the scene asks for ambient occlusion");
            let seen: Vec<f64> = image.iter().filter(|&&v| v >= 0.0).map(|&v| v as f64).collect();
            let same_image = first.as_ref().is_none_or(|f| *f == image);
            first.get_or_insert_with(|| image.clone());
            rows.push(AoRow {
                mesh: mesh.name.clone(),
                triangles: mesh.triangles.positions.len(),
                structure,
                parameters: stats.parameters.clone(),
                build_seconds: stats.build_time.as_secs_f64(),
                memory_bytes: stats.memory_bytes,
                frame_seconds: Vec::new(),
                rays: (frame.rays.primary, frame.rays.ambient),
                receivers: seen.len(),
                mean_ao: seen.iter().sum::<f64>() / seen.len().max(1) as f64,
                same_image,
                image,
            });
            scenes.push(scene);
        }
        // Timed in interleaved rounds, each visiting the structures in a fresh seeded order, so a
        // change of machine load falls on all of them alike.
        let base = rows.len() - scenes.len();
        for round in 0..spec.repeats {
            let mut order: Vec<usize> = (0..scenes.len()).collect();
            order.sort_by_key(|&i| pcg(pcg(round) ^ i as u32));
            for i in order {
                let view = View {
                    camera: &scenes[i].cameras["ao"],
                    width: spec.width,
                    height: spec.height,
                };
                let t = backend.time(&scenes[i], view, sampling, 0, 1)?;
                rows[base + i].frame_seconds.extend(t.seconds);
            }
        }
    }
    Ok((rows, tuning))
}
