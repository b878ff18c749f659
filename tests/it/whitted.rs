//! The visibility-field paper's two walkthrough shadings on the CPU backend: OpenGL-like (no
//! rays beyond the camera's, unoccluded local light) against the closed form of a point light
//! over a plane, and Whitted's mirror chains against an independent path: what a flat mirror
//! shows is what a camera mirrored through its plane sees of the scene without the mirror.

use glam::DVec3;
use penumbra::accel::AccelSettings;
use penumbra::mesh::Triangles;
use penumbra::render::cpu::CpuBackend;
use penumbra::render::plan::Pass;
use penumbra::render::{Backend, Frame, RenderPlan, Sampling, View};
use penumbra::sampling::{DiskScheme, Pattern};
use penumbra::scene::camera::{Camera, Projection};
use penumbra::scene::{Light, Mesh, Plane, Scene, Shading, Sphere};
use std::f64::consts::PI;

const SAMPLING: Sampling = Sampling {
    scheme: DiskScheme::Uniform,
    pattern: Pattern::PerPixel,
    seed: 7,
    frame: 0,
};

const LIGHT: DVec3 = DVec3::new(2.0, -1.0, 3.0);
const POWER: f64 = 50.0;

/// Floor z = 0 (albedo 0.6), a diffuse sphere and a point light, all at x > 0.
fn room() -> Scene {
    Scene::analytic(
        vec![Sphere {
            center: DVec3::new(1.5, 0.5, 0.5),
            radius: 0.5,
            albedo: 0.9,
        }],
        vec![Plane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
            albedo: 0.6,
        }],
        vec![Light::Point {
            position: LIGHT,
            power: POWER,
        }],
    )
}

fn quad(x: f64, y: [f64; 2], z: [f64; 2]) -> [[DVec3; 3]; 2] {
    let c = |y: f64, z: f64| DVec3::new(x, y, z);
    [
        [c(y[0], z[0]), c(y[1], z[0]), c(y[1], z[1])],
        [c(y[0], z[0]), c(y[1], z[1]), c(y[0], z[1])],
    ]
}

fn mirror_mesh(mirror: f64, triangles: usize) -> Mesh {
    Mesh {
        source: "mirror".into(),
        file_fnv1a: 0,
        albedo: 0.5,
        mirror,
        triangles,
        skipped: Default::default(),
    }
}

/// `scene` with one mirror mesh of weight `mirror` made of `quads`, under `shading`.
fn with_mirrors(scene: Scene, quads: &[[[DVec3; 3]; 2]], mirror: f64, shading: Shading) -> Scene {
    let positions: Vec<[DVec3; 3]> = quads.iter().flatten().copied().collect();
    let n = positions.len();
    let triangles = Triangles {
        positions,
        object_of: vec![0; n],
    };
    scene
        .with_meshes(vec![mirror_mesh(mirror, n)], triangles, AccelSettings::default())
        .with_shading(shading)
}

fn perspective(position: DVec3, look_at: DVec3) -> Camera {
    Camera {
        position,
        look_at,
        up: DVec3::Z,
        projection: Projection::Perspective { fov_y_deg: 60.0 },
    }
}

fn render(scene: &Scene, camera: &Camera, w: u32, h: u32) -> (Frame, u64) {
    let mut b = CpuBackend::default();
    let view = View {
        camera,
        width: w,
        height: h,
    };
    let frame = b.render(scene, view, SAMPLING).unwrap();
    (frame, b.dispatches())
}

#[test]
fn opengl_shading_is_the_unoccluded_closed_form_and_traces_no_shadow_rays() {
    let camera = perspective(DVec3::new(4.0, -3.0, 2.5), DVec3::new(1.0, 0.5, 0.0));
    let (w, h) = (64, 48);
    let opengl = room().with_shading(Shading::OPENGL);
    let view = View {
        camera: &camera,
        width: w,
        height: h,
    };
    let plan = RenderPlan::new(&opengl, view).unwrap();
    assert!(matches!(
        plan.passes[..],
        [Pass::Primary { .. }, Pass::Direct { lights: 1 }]
    ));
    let (frame, dispatches) = render(&opengl, &camera, w, h);
    assert_eq!(dispatches, 2, "one loop per pass");
    assert_eq!(frame.rays.shadow_total(), 0);
    assert_eq!(frame.rays.total(), (w * h) as u64);
    let (shadowed, _) = render(&room(), &camera, w, h);
    let (mut floor, mut in_shadow) = (0, 0);
    for i in 0..(w * h) as usize {
        if frame.hit[i] != 1 {
            continue;
        }
        let ray = camera.ray(i as u32 % w, i as u32 / w, w, h);
        let p = ray.origin + ray.direction * (-ray.origin.z / ray.direction.z);
        let d = LIGHT - p;
        let expected = 0.6 / PI * POWER / (4.0 * PI) * d.normalize().z / d.length_squared();
        let got = frame.radiance[i] as f64;
        assert!(
            (got - expected).abs() <= 1e-6 * expected,
            "pixel {i}: {got} vs {expected}"
        );
        floor += 1;
        in_shadow += (shadowed.radiance[i] == 0.0) as usize;
    }
    assert!(floor > 1000, "{floor} floor pixels");
    assert!(
        in_shadow > 10,
        "the sphere shadows {in_shadow} floor pixels when shadows are on"
    );
}

#[test]
fn a_flat_mirror_shows_what_the_mirrored_camera_sees() {
    let (w, h) = (64, 48);
    let glass = quad(0.0, [-1.5, 1.5], [0.0, 2.0]);
    let camera = perspective(DVec3::new(3.0, -0.5, 1.2), DVec3::new(0.0, 0.0, 0.8));
    let mirrored = perspective(DVec3::new(-3.0, -0.5, 1.2), DVec3::new(0.0, 0.0, 0.8));
    let m = 0.5;
    let whitted = with_mirrors(room(), &[glass], m, Shading::whitted(1));
    let diffuse_only = with_mirrors(room(), &[glass], m, Shading::whitted(0));
    let view = View {
        camera: &camera,
        width: w,
        height: h,
    };
    let plan = RenderPlan::new(&whitted, view).unwrap();
    assert!(matches!(
        plan.passes.last(),
        Some(Pass::Mirror {
            max_depth: 1,
            rays_per_bounce: 2,
            ..
        })
    ));
    assert!(!RenderPlan::new(&diffuse_only, view)
        .unwrap()
        .passes
        .iter()
        .any(|p| matches!(p, Pass::Mirror { .. })));
    let (a1, dispatches) = render(&whitted, &camera, w, h);
    assert_eq!(dispatches, 3, "primary, shadow, mirror");
    let (a0, _) = render(&diffuse_only, &camera, w, h);
    let (b, _) = render(&room(), &mirrored, w, h);
    let mirror_id = 2;
    let (mut seen, mut mismatched, mut lit) = (0u64, 0, 0);
    for i in 0..(w * h) as usize {
        let (x, y) = (i as u32 % w, i as u32 / w);
        let reflected = (a1.radiance[i] - a0.radiance[i]) as f64;
        if a1.hit[i] != mirror_id {
            assert_eq!(a1.radiance[i], a0.radiance[i], "pixel {i} sees no mirror");
            continue;
        }
        seen += 1;
        let j = (y * w + (w - 1 - x)) as usize;
        let expected = m * b.radiance[j] as f64;
        lit += (expected > 0.0) as usize;
        if (reflected - expected).abs() > 1e-5 * expected.max(0.05) {
            mismatched += 1;
        }
    }
    assert!(
        seen > 1000 && lit > 400,
        "{seen} mirror pixels, {lit} showing a lit surface"
    );
    assert_eq!(
        mismatched, 0,
        "{mismatched} of {seen} mirror pixels differ from the mirrored view"
    );
    assert_eq!(
        a1.rays.reflection, seen,
        "one reflected ray per mirror pixel at depth 1"
    );
    assert_eq!(a0.rays.reflection, 0);
    assert!(
        a1.rays.total() <= plan.max_rays(),
        "{:?} within the plan's {}",
        a1.rays,
        plan.max_rays()
    );
}

#[test]
fn facing_mirrors_trace_exactly_the_depth_asked_and_shadow_rays_only_at_diffuse_vertices() {
    let camera = Camera {
        position: DVec3::new(1.0, 0.0, 1.0),
        look_at: DVec3::new(0.0, 0.0, 1.0),
        up: DVec3::Z,
        projection: Projection::Orthographic { width: 1.0 },
    };
    let (w, h) = (16, 16);
    let pair = [quad(0.0, [-5.0, 5.0], [-4.0, 6.0]), quad(2.0, [-5.0, 5.0], [-4.0, 6.0])];
    let light = Light::Point {
        position: DVec3::new(1.0, 0.0, 5.0),
        power: 10.0,
    };
    for depth in [1, 3, 16] {
        let perfect = with_mirrors(
            Scene::analytic(vec![], vec![], vec![light.clone()]),
            &pair,
            1.0,
            Shading::whitted(depth),
        );
        let (f, _) = render(&perfect, &camera, w, h);
        let pixels = (w * h) as u64;
        let view = View {
            camera: &camera,
            width: w,
            height: h,
        };
        let plan = RenderPlan::new(&perfect, view).unwrap();
        assert!(
            matches!(plan.passes.last(), Some(Pass::Mirror { max_rays, .. }) if *max_rays == pixels * depth as u64 * 2)
        );
        assert!(f.rays.total() <= plan.max_rays());
        assert_eq!(f.rays.reflection, depth as u64 * pixels);
        assert_eq!(f.rays.shadow_total(), pixels, "only the camera's hits are shaded");
        assert!(
            f.radiance.iter().all(|&r| r == 0.0),
            "perfect mirrors with nothing diffuse in sight are black"
        );
        // Half-silvered: each vertex also shades its diffuse half, the chain's weight halving.
        let half = with_mirrors(
            Scene::analytic(vec![], vec![], vec![light.clone()]),
            &pair,
            0.5,
            Shading::whitted(depth),
        );
        let (g, _) = render(&half, &camera, w, h);
        assert_eq!(g.rays.shadow_total(), (depth as u64 + 1) * pixels);
        // The centre pixel's chain bounces straight between x = 0 and x = 2 at one height, and
        // vertex k adds 0.5^k x (1 - 0.5) x albedo / pi x E(vertex k).
        let p0 = camera.ray(w / 2, h / 2, w, h);
        let hit = p0.origin + p0.direction * p0.origin.x;
        let e = |p: DVec3| {
            let d = DVec3::new(1.0, 0.0, 5.0) - p;
            10.0 / (4.0 * PI) * (d.normalize().dot(DVec3::X).abs()) / d.length_squared()
        };
        let (mut expected, mut weight, mut at) = (0.0, 1.0, hit);
        for _ in 0..=depth {
            expected += weight * 0.5 * 0.5 / PI * e(at);
            weight *= 0.5;
            at.x = 2.0 - at.x;
        }
        let got = g.radiance[(h / 2 * w + w / 2) as usize] as f64;
        assert!(
            (got - expected).abs() <= 1e-5 * expected,
            "depth {depth}: {got} vs {expected}"
        );
    }
}

#[test]
fn scene_files_declare_shading_and_mirror_weights_with_located_errors() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("quad.obj"),
        "v 0 -1 0\nv 0 1 0\nv 0 1 2\nv 0 -1 2\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let write = |body: &str| {
        let p = dir.path().join("scene.toml");
        std::fs::write(
            &p,
            format!(
                "[cameras.c]\nprojection = \"perspective\"\nposition = [3.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 1.0]\nfov_y = 50.0\n\n{body}"
            ),
        )
        .unwrap();
        p
    };
    let ok = Scene::load(&write(
        "[shading]\nshadows = false\nmirror_depth = 3\n\n[[meshes]]\npath = \"quad.obj\"\nmirror = 0.25\n",
    ))
    .unwrap();
    assert_eq!(
        ok.shading,
        Shading {
            shadows: false,
            mirror_depth: 3
        }
    );
    assert_eq!(ok.shapes[0].mirror(), 0.25);
    assert_eq!(Scene::load(&write("")).unwrap().shading, Shading::default());
    let e = Scene::load(&write("[[meshes]]\npath = \"quad.obj\"\nmirror = 1.5\n"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("scene.toml:9") && e.contains("meshes[0].mirror") && e.contains("[0, 1]"),
        "{e}"
    );
    let e = Scene::load(&write("[shading]\nmirror_depth = 17\n"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("shading.mirror_depth") && e.contains("at most 16"), "{e}");
    let e = Scene::load(&write("[shading]\nreflections = 2\n"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("reflections"), "{e}");
}

#[test]
fn the_gpu_backend_refuses_passes_it_has_no_kernel_for() {
    let Some(mut gpu) = common::gpu() else { return };
    let camera = perspective(DVec3::new(3.0, -0.5, 1.2), DVec3::new(0.0, 0.0, 0.8));
    let view = View {
        camera: &camera,
        width: 8,
        height: 8,
    };
    let e = gpu
        .render(&room().with_shading(Shading::OPENGL), view, SAMPLING)
        .unwrap_err();
    assert!(format!("{e:#}").contains("direct pass"), "{e:#}");
    let whitted = with_mirrors(room(), &[quad(0.0, [-1.5, 1.5], [0.0, 2.0])], 0.5, Shading::whitted(2));
    let e = gpu.render(&whitted, view, SAMPLING).unwrap_err();
    assert!(format!("{e:#}").contains("mirror pass"), "{e:#}");
    let unreflected = with_mirrors(room(), &[quad(0.0, [-1.5, 1.5], [0.0, 2.0])], 0.5, Shading::default());
    let e = gpu.render(&unreflected, view, SAMPLING).unwrap_err();
    assert!(format!("{e:#}").contains("mirror materials"), "{e:#}");
}

use crate::common;
