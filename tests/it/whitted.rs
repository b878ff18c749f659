//! The visibility-field paper's two walkthrough shadings on the f64 CPU backend and (where an
//! adapter exists) the GPU: OpenGL-like (no rays beyond the camera's, unoccluded local light)
//! against the closed form of a point light over a plane, and Whitted's mirror chains against an
//! independent path: what a flat mirror shows is what a camera mirrored through its plane sees
//! of the scene without the mirror; and the GPU's frames against the CPU's with every structure.

use glam::DVec3;
use penumbra::accel::{AccelSettings, REGISTRY};
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
    with_mirrors_in(scene, quads, mirror, shading, &AccelSettings::default())
}

fn perspective(position: DVec3, look_at: DVec3) -> Camera {
    Camera {
        position,
        look_at,
        up: DVec3::Z,
        projection: Projection::Perspective { fov_y_deg: 60.0 },
    }
}

/// Relative tolerance of a radiance against its exact answer: f64 rounding on the CPU; on the
/// GPU, f32 rounding of the hit point, the light's offset and its square (a few ulps each,
/// 1.2e-7 apiece) in coordinates re-based on the camera's look-at point.
fn tolerance(backend: &str) -> f64 {
    if backend == "cpu" {
        1e-6
    } else {
        2e-5
    }
}

/// Runs `f` with the CPU backend, then with the GPU backend if there is one.
fn on_backends(f: impl Fn(&str, &mut dyn Backend)) {
    f("cpu", &mut CpuBackend::default());
    if let Some(mut g) = common::gpu() {
        g.count_work(true);
        f("gpu", &mut *g);
        g.count_work(false);
    }
}

/// The frame and the work units the backend issued for it (CPU: one loop per pass; GPU: one
/// dispatch per pass, more where the adapter caps loops and a pass is split).
fn render(b: &mut dyn Backend, scene: &Scene, camera: &Camera, w: u32, h: u32) -> (Frame, u64) {
    let view = View {
        camera,
        width: w,
        height: h,
    };
    let before = b.dispatches();
    let frame = b.render(scene, view, SAMPLING).unwrap();
    (frame, b.dispatches() - before)
}

#[test]
fn opengl_shading_is_the_unoccluded_closed_form_and_traces_no_shadow_rays() {
    on_backends(|name, b| opengl_closed_form(name, b));
}

fn opengl_closed_form(name: &str, b: &mut dyn Backend) {
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
    let (frame, dispatches) = render(b, &opengl, &camera, w, h);
    assert!(dispatches == 2, "{name}: one work unit per pass, {dispatches}");
    assert_eq!(frame.rays.shadow_total(), 0, "{name}");
    assert_eq!(frame.rays.total(), (w * h) as u64, "{name}");
    let work = frame.work().expect("a frame read back counts its work");
    assert_eq!(work.queries, (w * h) as u64, "{name}: the camera rays' queries only");
    let (shadowed, _) = render(b, &room(), &camera, w, h);
    let floor: Vec<(usize, f64)> = (0..(w * h) as usize)
        .filter(|&i| frame.hit[i] == 1)
        .map(|i| {
            let ray = camera.ray(i as u32 % w, i as u32 / w, w, h);
            let p = ray.origin + ray.direction * (-ray.origin.z / ray.direction.z);
            let d = LIGHT - p;
            (i, 0.6 / PI * POWER / (4.0 * PI) * d.normalize().z / d.length_squared())
        })
        .collect();
    // The f32 hit point's rounding moves a grazing cosine by more than its own ulps: on the GPU
    // the error is bounded at the image's scale as well (the brightest floor pixel's).
    let brightest = floor.iter().map(|f| f.1).fold(0.0, f64::max);
    let absolute = if name == "cpu" {
        0.0
    } else {
        tolerance(name) * brightest
    };
    let mut in_shadow = 0;
    for &(i, expected) in &floor {
        let got = frame.radiance[i] as f64;
        assert!(
            (got - expected).abs() <= tolerance(name) * expected + absolute,
            "{name}: pixel {i}: {got} vs {expected}"
        );
        in_shadow += (shadowed.radiance[i] == 0.0) as usize;
    }
    let floor = floor.len();
    assert!(floor > 1000, "{name}: {floor} floor pixels");
    assert!(
        in_shadow > 10,
        "the sphere shadows {in_shadow} floor pixels when shadows are on"
    );
}

#[test]
fn a_flat_mirror_shows_what_the_mirrored_camera_sees() {
    on_backends(|name, b| flat_mirror(name, b));
}

fn flat_mirror(name: &str, backend: &mut dyn Backend) {
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
    let (a1, dispatches) = render(backend, &whitted, &camera, w, h);
    // The GPU splits the mirror pass: its one bounce a trace, the light's samples and a step,
    // then the finish. The light's 2 samples take one dispatch on any adapter: a loop cap
    // splits a pass only where a sample's loops (a few hundred iterations in this room) times
    // the samples pass the cap (llvmpipe's is 65535).
    let mirror = if name == "gpu" { 4 } else { 1 };
    assert_eq!(dispatches, 2 + mirror, "{name}: primary, shadow, mirror");
    assert_eq!(a1.mirror_bounces, 1, "{name}");
    // Every chain ends at the diffuse room after one bounce: a depth limit of 8 runs no
    // second bounce (the GPU's gate dispatches none) and changes no pixel.
    let deep = with_mirrors(room(), &[glass], m, Shading::whitted(8));
    let (a8, _) = render(backend, &deep, &camera, w, h);
    assert_eq!(a8.mirror_bounces, 1, "{name}: bounces run under a depth limit of 8");
    assert_eq!(a8.rays, a1.rays, "{name}");
    assert!(a8.radiance == a1.radiance, "{name}: a deeper limit changed the image");
    let (a0, _) = render(backend, &diffuse_only, &camera, w, h);
    let (b, _) = render(backend, &room(), &mirrored, w, h);
    let mirror_id = 2;
    let (mut seen, mut mismatched, mut lit) = (0u64, 0, 0);
    for i in 0..(w * h) as usize {
        let (x, y) = (i as u32 % w, i as u32 / w);
        let reflected = (a1.radiance[i] - a0.radiance[i]) as f64;
        if a1.hit[i] != mirror_id {
            assert_eq!(a1.radiance[i], a0.radiance[i], "{name}: pixel {i} sees no mirror");
            continue;
        }
        seen += 1;
        let j = (y * w + (w - 1 - x)) as usize;
        let expected = m * b.radiance[j] as f64;
        lit += (expected > 0.0) as usize;
        if (reflected - expected).abs() > 10.0 * tolerance(name) * expected.max(0.05) {
            mismatched += 1;
        }
    }
    assert!(
        seen > 1000 && lit > 400,
        "{name}: {seen} mirror pixels, {lit} showing a lit surface"
    );
    // In f32 a reflected ray grazing the sphere's silhouette or the shadow's edge may be decided
    // the other way than the mirrored camera's ray: a handful of pixels, never more.
    let allowed = if name == "cpu" { 0 } else { seen as usize / 200 };
    assert!(
        mismatched <= allowed,
        "{name}: {mismatched} of {seen} mirror pixels differ from the mirrored view"
    );
    assert_eq!(
        a1.rays.reflection, seen,
        "{name}: one reflected ray per mirror pixel at depth 1"
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
    on_backends(|name, b| facing_mirrors(name, b));
}

fn facing_mirrors(name: &str, b: &mut dyn Backend) {
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
        let (f, _) = render(b, &perfect, &camera, w, h);
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
        assert_eq!(f.rays.reflection, depth as u64 * pixels, "{name}");
        assert_eq!(f.mirror_bounces, depth, "{name}: every bounce runs while chains go on");
        assert_eq!(
            f.rays.shadow_total(),
            pixels,
            "{name}: only the camera's hits are shaded"
        );
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
        let (g, _) = render(b, &half, &camera, w, h);
        assert_eq!(g.rays.shadow_total(), (depth as u64 + 1) * pixels, "{name}");
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
        // Each bounce adds the f32 rounding of one more vertex on the GPU.
        let tol = if name == "cpu" {
            1e-5
        } else {
            tolerance(name) * (depth + 1) as f64
        };
        assert!(
            (got - expected).abs() <= tol * expected,
            "{name}: depth {depth}: {got} vs {expected}"
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

/// The GPU's frames against the f64 CPU's for both shadings, a mirror material without
/// reflections and shadowed Whitted chains, with every structure: the same objects seen, radiance
/// within f32 rounding, the same rays, and work counted, except on the few pixels where a ray
/// grazes an edge or a silhouette and f32 decides it the other way.
#[test]
fn the_gpu_renders_both_shadings_as_the_cpu_does_with_every_structure() {
    let Some(mut gpu) = common::gpu() else { return };
    gpu.count_work(true);
    let camera = perspective(DVec3::new(3.0, -2.5, 1.6), DVec3::new(0.0, 0.0, 0.7));
    let (w, h) = (48, 36);
    let view = View {
        camera: &camera,
        width: w,
        height: h,
    };
    let glass = [quad(0.0, [-1.5, 1.5], [0.0, 2.0]), quad(2.8, [-1.5, 0.5], [0.2, 1.8])];
    for r in REGISTRY.iter().filter(|r| r.gpu) {
        let settings = AccelSettings::named(r.name).unwrap();
        for (what, scene) in [
            (
                "opengl",
                with_mirrors_in(room(), &glass, 0.0, Shading::OPENGL, &settings),
            ),
            (
                "opengl mirrors",
                with_mirrors_in(
                    room(),
                    &glass,
                    0.6,
                    Shading {
                        shadows: false,
                        mirror_depth: 3,
                    },
                    &settings,
                ),
            ),
            (
                "mirror material",
                with_mirrors_in(room(), &glass, 0.5, Shading::default(), &settings),
            ),
            (
                "whitted",
                with_mirrors_in(room(), &glass, 0.6, Shading::whitted(3), &settings),
            ),
        ] {
            let c = CpuBackend::default().render(&scene, view, SAMPLING).unwrap();
            let g = gpu.render(&scene, view, SAMPLING).unwrap();
            let label = format!("{} {what}", r.name);
            let hits = c.hit.iter().zip(&g.hit).filter(|(a, b)| a != b).count();
            let off = c
                .radiance
                .iter()
                .zip(&g.radiance)
                .filter(|(a, b)| ((**a - **b) as f64).abs() > 1e-4 * (**a as f64).max(1e-3))
                .count();
            let pixels = (w * h) as usize;
            eprintln!("{label}: {hits} hits and {off} radiances of {pixels} differ");
            assert!(
                hits <= pixels / 500 && off <= pixels / 100,
                "{label}: {hits} hits, {off} radiances differ"
            );
            assert_eq!(g.rays.primary, c.rays.primary, "{label}");
            let near = |a: u64, b: u64| a.abs_diff(b) <= (a / 100).max(2);
            assert!(
                near(g.rays.reflection, c.rays.reflection),
                "{label}: {:?} vs {:?}",
                g.rays,
                c.rays
            );
            assert!(
                near(g.rays.shadow_total(), c.rays.shadow_total()),
                "{label}: {:?} vs {:?}",
                g.rays,
                c.rays
            );
            let (gw, cw) = (g.work().expect("GPU work counted"), c.work().unwrap());
            assert!(near(gw.queries, cw.queries), "{label}: {gw:?} vs {cw:?}");
            assert!(
                gw.primitives > 0 && (r.name == "brute" || gw.nodes > 0),
                "{label}: {gw:?}"
            );
            if what == "opengl" {
                assert_eq!(
                    g.rays.total(),
                    g.rays.primary,
                    "{label}: OpenGL-like shading traces camera rays only"
                );
            }
        }
    }
    gpu.count_work(false);
}

/// [`with_mirrors`] with the mirror mesh in structure `settings`.
fn with_mirrors_in(
    scene: Scene,
    quads: &[[[DVec3; 3]; 2]],
    mirror: f64,
    shading: Shading,
    settings: &AccelSettings,
) -> Scene {
    let positions: Vec<[DVec3; 3]> = quads.iter().flatten().copied().collect();
    let n = positions.len();
    let triangles = Triangles {
        positions,
        object_of: vec![0; n],
    };
    scene
        .with_meshes(vec![mirror_mesh(mirror, n)], triangles, settings.clone())
        .with_shading(shading)
}

use crate::common;

/// Mirror chains under a disk light of many samples (depth 16 x 4096 samples here): the GPU's
/// mirror pass shades each bounce's vertices light by light in the shadow pass's chunks, so an
/// adapter that caps loop iterations (lavapipe: 65535 per loop nest) finishes them as one that
/// does not, and both match the CPU.
#[test]
fn deep_mirror_chains_under_many_samples_match_the_cpu_on_any_adapter() {
    let Some(mut gpu) = common::gpu() else { return };
    let camera = Camera {
        position: DVec3::new(1.0, 0.0, 1.0),
        look_at: DVec3::new(0.0, 0.0, 1.0),
        up: DVec3::Z,
        projection: Projection::Orthographic { width: 1.0 },
    };
    let (w, h) = (4, 4);
    let pair = [quad(0.0, [-5.0, 5.0], [-4.0, 6.0]), quad(2.0, [-5.0, 5.0], [-4.0, 6.0])];
    let light = Light::Disk(penumbra::scene::DiskLight {
        center: DVec3::new(1.0, 0.0, 5.0),
        normal: -DVec3::Z,
        radius: 0.5,
        power: 10.0,
        samples: 4096,
    });
    let scene = with_mirrors(
        Scene::analytic(vec![], vec![], vec![light]),
        &pair,
        0.5,
        Shading::whitted(16),
    );
    let view = View {
        camera: &camera,
        width: w,
        height: h,
    };
    let c = CpuBackend::default().render(&scene, view, SAMPLING).unwrap();
    let g = gpu.render(&scene, view, SAMPLING).unwrap();
    for i in 0..(w * h) as usize {
        let (a, b) = (c.radiance[i] as f64, g.radiance[i] as f64);
        assert!(a > 0.0, "pixel {i}: the chain brings light back");
        assert!((a - b).abs() <= 1e-3 * a, "pixel {i}: cpu {a} gpu {b}");
    }
    assert_eq!(g.rays.shadow_total(), c.rays.shadow_total());
    assert_eq!(g.rays.reflection, c.rays.reflection);
}

/// A reflected ray whose closest-hit walk alone runs past the adapter's loop cap is refused,
/// never answered short: a perfect mirror sends every camera ray back along +x through 100,000
/// slivers in a row, each in a plane that holds the x direction (so no ray hits one) and each
/// with a box that holds every ray, so a BVH walk visits them all. The camera's and the
/// light's rays never reach them: without the mirror pass the frame renders. Where the adapter
/// caps loops (llvmpipe: 65,535 iterations) the mirror pass's cut walk is an error naming it;
/// elsewhere the frame matches the CPU's.
#[test]
fn a_reflected_walk_past_the_loop_cap_is_refused_not_cut_short() {
    let Some(mut gpu) = common::gpu() else { return };
    let n = 100_000;
    let mut positions: Vec<[DVec3; 3]> = quad(0.0, [-1.0, 1.0], [0.0, 2.0]).to_vec();
    for i in 0..n {
        // Planes at 30 to 60 degrees about the x axis through (y, z) = (0, 1), 5 m wide: every
        // ray of the 0.5 m footprint is inside each box and parallel to each plane.
        let a = PI / 6.0 + PI / 6.0 * (i % 97) as f64 / 96.0;
        let u = DVec3::new(0.0, -a.sin(), a.cos()) * 2.5;
        let c = DVec3::new(4.0 + 6.0 * i as f64 / n as f64, 0.0, 1.0);
        let dx = DVec3::new(6.0 / n as f64, 0.0, 0.0);
        positions.push([c + u, c + dx + u, c + 0.5 * dx - u]);
    }
    let mut object_of = vec![0; 2];
    object_of.resize(n + 2, 1);
    let slivers = Mesh {
        source: "slivers".into(),
        mirror: 0.0,
        triangles: n,
        ..mirror_mesh(0.0, n)
    };
    let light = Light::Point {
        position: DVec3::new(3.0, 0.0, 5.0),
        power: 10.0,
    };
    let scene = |depth| {
        Scene::analytic(vec![], vec![], vec![light.clone()])
            .with_meshes(
                vec![mirror_mesh(1.0, 2), slivers.clone()],
                Triangles {
                    positions: positions.clone(),
                    object_of: object_of.clone(),
                },
                AccelSettings::default(),
            )
            .with_shading(Shading::whitted(depth))
    };
    let camera = Camera {
        position: DVec3::new(3.0, 0.0, 1.0),
        look_at: DVec3::new(0.0, 0.0, 1.0),
        up: DVec3::Z,
        projection: Projection::Orthographic { width: 0.5 },
    };
    let view = View {
        camera: &camera,
        width: 8,
        height: 8,
    };
    gpu.render(&scene(0), view, SAMPLING)
        .expect("the camera's and the light's rays never reach the slivers");
    let mirrored = gpu.render(&scene(1), view, SAMPLING);
    match gpu.adapter().loop_cap {
        Some(cap) => {
            assert!(cap < n as u32, "the walk must pass the cap {cap}");
            let e = format!("{:#}", mirrored.expect_err("a cut walk must not be answered"));
            assert!(e.contains("reflected ray's closest-hit walk early"), "{e}");
        }
        None => {
            let cpu = CpuBackend::default().render(&scene(1), view, SAMPLING).unwrap();
            let gpu = mirrored.unwrap();
            assert_eq!(gpu.rays.reflection, cpu.rays.reflection);
            assert!(gpu.radiance == cpu.radiance, "nothing comes back from the slivers");
        }
    }
}
