//! "Simulate only what the scene calls for": the plan is derived from the scene, and the rays
//! a frame actually traces are counted and compared with an independent count.

use crate::common;

use glam::DVec3;
use penumbra::accel::AccelSettings;
use penumbra::mesh::Triangles;
use penumbra::render::cpu::CpuBackend;
use penumbra::render::plan::Pass;
use penumbra::render::{Backend, RenderPlan, Sampling, View};
use penumbra::sampling::{DiskScheme, Pattern};
use penumbra::scene::camera::{Camera, Projection};
use penumbra::scene::{DiskLight, Light, Mesh, Plane, Scene, Shape, Sphere};

/// A ground plane seen in perspective up to the horizon, a point light and a disk light above
/// it, and a disk light below it facing up (every receiver is behind that one).
fn scene() -> (Scene, Camera) {
    let camera = Camera {
        position: DVec3::new(0.0, -4.0, 1.0),
        look_at: DVec3::new(0.0, 0.0, 0.6),
        up: DVec3::Z,
        projection: Projection::Perspective { fov_y_deg: 50.0 },
    };
    let scene = Scene::analytic(
        vec![],
        vec![Plane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
            albedo: 0.5,
        }],
        vec![
            Light::Point {
                position: DVec3::new(0.0, 0.0, 3.0),
                power: 10.0,
            },
            Light::Disk(DiskLight {
                center: DVec3::new(1.0, 0.0, 2.0),
                normal: DVec3::NEG_Z,
                radius: 0.3,
                power: 10.0,
                samples: 8,
            }),
            Light::Disk(DiskLight {
                center: DVec3::new(0.0, 0.0, -1.0),
                normal: DVec3::Z,
                radius: 0.3,
                power: 10.0,
                samples: 32,
            }),
        ],
    );
    (scene, camera)
}

#[test]
fn plan_follows_the_scene() {
    let (mut s, cam) = scene();
    let view = View {
        camera: &cam,
        width: 40,
        height: 30,
    };
    let plan = RenderPlan::new(&s, view).unwrap();
    assert_eq!(plan.passes.len(), 4);
    assert_eq!(
        plan.passes[0],
        Pass::Primary {
            rays: 1200,
            shapes: vec!["plane".to_string()]
        }
    );
    assert!(matches!(
        plan.passes[1],
        Pass::Shadow {
            kind: "point",
            rays_per_receiver: 1,
            ..
        }
    ));
    assert!(matches!(
        plan.passes[2],
        Pass::Shadow {
            kind: "disk",
            rays_per_receiver: 8,
            max_rays: 9600,
            ..
        }
    ));
    assert_eq!(plan.max_rays(), 1200 * (1 + 1 + 8 + 32));
    s.lights.clear();
    s.shapes.insert(
        0,
        Shape::Sphere(Sphere {
            center: DVec3::Z,
            radius: 0.5,
            albedo: 0.5,
        }),
    );
    let plan = RenderPlan::new(&s, view).unwrap();
    assert_eq!(
        plan.passes,
        vec![Pass::Primary {
            rays: 1200,
            shapes: vec!["sphere".to_string(), "plane".to_string()]
        }]
    );
    let plan = RenderPlan::new(&with_quad(s), view).unwrap();
    assert_eq!(
        plan.passes,
        vec![Pass::Primary {
            rays: 1200,
            shapes: ["sphere", "plane", "mesh (BVH)"].map(String::from).to_vec()
        }]
    );
}

/// `scene` with a mesh: a 1.2 m square of two triangles, 0.4 m above the ground (below the
/// camera, so its top is seen), indexed by the default acceleration structure.
fn with_quad(scene: Scene) -> Scene {
    let c = |x: f64, y: f64| DVec3::new(x, y, 0.4);
    let triangles = Triangles {
        positions: vec![
            [c(-0.6, -0.6), c(0.6, -0.6), c(0.6, 0.6)],
            [c(-0.6, -0.6), c(0.6, 0.6), c(-0.6, 0.6)],
        ],
        object_of: vec![0, 0],
    };
    let mesh = Mesh {
        source: "quad".into(),
        file_fnv1a: 0,
        albedo: 0.5,
        mirror: 0.0,
        triangles: 2,
        skipped: Default::default(),
    };
    scene.with_meshes(vec![mesh], triangles, AccelSettings::default())
}

/// Receivers (pixels whose ray goes down to the plane) each trace 1 ray to the point light and
/// 8 to the disk above; none to the light below the plane. Counted independently from the
/// camera's rays, with and without a mesh over the plane (whose top faces receive the same).
#[test]
fn traced_rays_match_an_independent_count() {
    let (s, cam) = scene();
    let view = View {
        camera: &cam,
        width: 40,
        height: 30,
    };
    let receivers = (0..30)
        .flat_map(|y| (0..40).map(move |x| (x, y)))
        .filter(|&(x, y)| cam.ray(x, y, 40, 30).direction.z < 0.0)
        .count() as u64;
    assert!(
        receivers > 100 && receivers < 1200,
        "the view must show sky and ground: {receivers}"
    );
    let sampling = Sampling {
        scheme: DiskScheme::Uniform,
        pattern: Pattern::PerPixel,
        seed: 3,
        frame: 0,
    };
    let meshed = with_quad(s.clone());
    let check = |name: &str, b: &mut dyn Backend, s: &Scene| {
        let f = b.render(s, view, sampling).unwrap();
        assert_eq!(f.rays.primary, 1200, "{name}");
        assert_eq!(f.rays.shadow[0], receivers, "{name}: point light");
        assert_eq!(f.rays.shadow[1], 8 * receivers, "{name}: disk light above");
        assert_eq!(f.rays.shadow[2], 0, "{name}: disk light below the receivers");
        let below: Vec<f32> = f.visibility[2].iter().copied().filter(|v| *v >= 0.0).collect();
        assert_eq!(below.len() as u64, receivers);
        assert!(
            below.iter().all(|v| *v == 0.0),
            "{name}: a light facing away is invisible"
        );
        f
    };
    let quad_pixels = |f: &penumbra::render::Frame| f.hit.iter().filter(|&&h| h == 1).count();
    let f = check("cpu", &mut CpuBackend::default(), &meshed);
    assert!(quad_pixels(&f) >= 8, "the mesh must be in view: {}", quad_pixels(&f));
    check("cpu", &mut CpuBackend::default(), &s);
    if let Some(mut g) = common::gpu() {
        check("gpu", &mut *g, &s);
        let f = check("gpu", &mut *g, &meshed);
        assert!(quad_pixels(&f) >= 8, "the mesh must be in view on the GPU");
    }
}

/// Each backend runs exactly the plan's passes: one primary dispatch, and per light one dispatch
/// per sample chunk (every light here fits one chunk on any adapter: at most 32 samples, and a
/// capped adapter's chunk holds dozens even with a mesh). Counted against 1 + lights for the
/// full scene, with a mesh, without lights, and over timed frames.
#[test]
fn each_backend_runs_the_plans_passes_and_nothing_else() {
    let (scene, cam) = scene();
    let view = View {
        camera: &cam,
        width: 16,
        height: 12,
    };
    let sampling = Sampling {
        scheme: DiskScheme::Uniform,
        pattern: Pattern::PerPixel,
        seed: 3,
        frame: 0,
    };
    let check = |name: &str, b: &mut dyn Backend| {
        let mut count = |s: &Scene, frames: u32| {
            let before = b.dispatches();
            if frames == 1 {
                b.render(s, view, sampling).unwrap();
            } else {
                b.time(s, view, sampling, 1, frames - 1).unwrap();
            }
            b.dispatches() - before
        };
        let mut s = scene.clone();
        assert_eq!(count(&s, 1), 1 + 3, "{name}: primary and three lights");
        assert_eq!(count(&with_quad(s.clone()), 1), 1 + 3, "{name}: a mesh adds no pass");
        assert_eq!(
            count(&s, 4),
            4 * (1 + 3),
            "{name}: warm-up and timed frames run the same passes"
        );
        s.lights.truncate(1);
        assert_eq!(count(&s, 1), 1 + 1, "{name}: primary and the point light");
        s.lights.clear();
        assert_eq!(count(&s, 1), 1, "{name}: no light, no shadow pass");
    };
    check("cpu", &mut CpuBackend::default());
    if let Some(mut g) = common::gpu() {
        check("gpu", &mut *g);
    }
}
