//! Runs an ambient-occlusion experiment on the f64 CPU backend (the GPU backend has no AO pass
//! yet): per mesh, each structure is built at its best settings, renders the AO image once
//! (untimed; every structure's image must equal the first's bit for bit) and is then timed over
//! `repeats` frames.

use super::spec::{best_settings, AoMesh, AoSpec};
use crate::render::cpu::CpuBackend;
use crate::render::{Backend, Sampling, View};
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
        let mut v = self.frame_seconds.clone();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
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

/// The scene of `mesh` indexed by `structure`, with the experiment's AO pass.
pub fn ao_scene(spec: &AoSpec, mesh: &AoMesh, structure: &'static str) -> anyhow::Result<Scene> {
    let descriptor = Mesh {
        source: mesh.path.display().to_string(),
        file_fnv1a: mesh.file_fnv1a,
        albedo: 0.8,
        triangles: mesh.triangles.positions.len(),
        skipped: Default::default(),
    };
    let scene = Scene::analytic(vec![], vec![], vec![])
        .with_cameras(BTreeMap::from([("ao".to_string(), camera())]))
        .try_with_meshes(vec![descriptor], mesh.triangles.clone(), best_settings(structure))?
        .with_ambient(Some(spec.ao.clone()));
    Ok(scene)
}

/// Every mesh x structure of the experiment, in file order; `progress` hears each as it starts.
pub fn run_ao(spec: &AoSpec, progress: &dyn Fn(&str, &str)) -> anyhow::Result<Vec<AoRow>> {
    let mut backend = CpuBackend::default();
    let sampling = Sampling {
        scheme: DiskScheme::Uniform,
        pattern: Pattern::PerPixel,
        seed: 1,
    };
    let mut rows = Vec::new();
    for mesh in &spec.meshes {
        let mut first: Option<Vec<f32>> = None;
        for &structure in &spec.structures {
            progress(&mesh.name, structure);
            let scene = ao_scene(spec, mesh, structure)?;
            let stats = scene.accel.as_ref().expect("a mesh scene has a structure").stats();
            let view = View {
                camera: &scene.cameras["ao"],
                width: spec.width,
                height: spec.height,
            };
            let frame = backend.render(&scene, view, sampling)?;
            let image = frame.ambient.expect("the scene asks for ambient occlusion");
            let seen: Vec<f64> = image.iter().filter(|&&v| v >= 0.0).map(|&v| v as f64).collect();
            let timing = backend.time(&scene, view, sampling, 0, spec.repeats)?;
            let same_image = first.as_ref().is_none_or(|f| *f == image);
            first.get_or_insert_with(|| image.clone());
            rows.push(AoRow {
                mesh: mesh.name.clone(),
                triangles: mesh.triangles.positions.len(),
                structure,
                parameters: stats.parameters.clone(),
                build_seconds: stats.build_time.as_secs_f64(),
                memory_bytes: stats.memory_bytes,
                frame_seconds: timing.seconds,
                rays: (frame.rays.primary, frame.rays.ambient),
                receivers: seen.len(),
                mean_ao: seen.iter().sum::<f64>() / seen.len().max(1) as f64,
                same_image,
                image,
            });
        }
    }
    Ok(rows)
}
