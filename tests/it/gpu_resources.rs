//! GPU resources and adapter quirks: the scene's geometry is uploaded once and reused only while
//! it is unchanged; the loop-iteration cap is detected by a probe, and the dispatch split that
//! works around it is needed exactly where the probe says so; Rust and WGSL share one list of
//! scheme ids and one integer square root.

use crate::common;

use penumbra::render::cpu::CpuBackend;
use penumbra::render::gpu::{scheme_prelude, GpuBackend};
use penumbra::render::{Backend, Sampling, View};
use penumbra::sampling::{DiskScheme, Pattern};
use penumbra::scene::{Light, Scene};

fn scene(file: &str) -> Scene {
    Scene::load(&common::repo(file)).unwrap()
}

fn sampling(seed: u32) -> Sampling {
    Sampling {
        scheme: DiskScheme::Uniform,
        pattern: Pattern::PerPixel,
        seed,
        frame: 0,
    }
}

/// The split frame traces exactly the CPU's shadow rays; and where the adapter caps loops, the
/// same frame as one undivided dispatch per light is cut short, which the renderer reports
/// instead of returning a frame with rays missing (the check has teeth).
fn split_traces_the_cpus_rays(gpu: &mut GpuBackend, s: &Scene, view: View, sampling: Sampling) {
    let cpu = CpuBackend::default().render(s, view, sampling).unwrap();
    let split = gpu.render(s, view, sampling).unwrap();
    assert_eq!(split.rays.shadow_total(), cpu.rays.shadow_total());
    let cap = gpu.loop_cap();
    if cap.is_some() {
        gpu.set_loop_cap(None);
        let whole = gpu.render(s, view, sampling);
        gpu.set_loop_cap(cap);
        match whole {
            Err(e) => assert!(e.to_string().contains("ended a loop early"), "{e:#}"),
            Ok(f) => panic!("the undivided frame came back as whole, {} rays", f.rays.shadow_total()),
        }
    }
}

#[test]
fn geometry_is_uploaded_once_per_scene_and_again_when_it_changes() {
    let Some(mut gpu) = common::gpu() else { return };
    let (a, mut b) = (
        scene("experiments/scenes/sphere.toml"),
        scene("experiments/scenes/sphere.toml"),
    );
    b.spheres_mut().next().unwrap().radius = 0.3;
    fn view(s: &Scene) -> View<'_> {
        View {
            camera: &s.cameras["measure"],
            width: 32,
            height: 32,
        }
    }
    // The shared backend may hold `a`'s content from another test (the same scene and camera):
    // make `b` resident first, so that `a`'s first render must upload.
    gpu.render(&b, view(&b), sampling(1)).unwrap();
    let start = gpu.static_uploads();
    let first_a = gpu.render(&a, view(&a), sampling(1)).unwrap();
    gpu.time(&a, view(&a), sampling(1), 2, 3).unwrap();
    let again_a = gpu.render(&a, view(&a), sampling(2)).unwrap();
    assert_eq!(gpu.static_uploads(), start + 1, "one scene, one upload");
    assert_ne!(first_a.visibility, again_a.visibility, "another seed renders anew");
    // Alternating scenes: each is re-uploaded, and renders as it did the first time.
    let first_b = gpu.render(&b, view(&b), sampling(1)).unwrap();
    let second_a = gpu.render(&a, view(&a), sampling(1)).unwrap();
    let second_b = gpu.render(&b, view(&b), sampling(1)).unwrap();
    assert_eq!(gpu.static_uploads(), start + 4);
    assert_eq!(first_a.visibility, second_a.visibility);
    assert_eq!(first_b.visibility, second_b.visibility);
    assert_ne!(
        first_a.visibility, first_b.visibility,
        "the larger sphere casts another shadow"
    );
}

/// Where the probe finds a cap, one undivided 1024-ray dispatch over a mesh is cut short (the
/// reason for the split); with the split the GPU traces exactly the CPU's rays.
#[test]
fn the_loop_cap_probe_finds_what_the_split_works_around() {
    let Some(mut gpu) = common::gpu() else { return };
    let name = gpu.adapter().name.clone();
    let cap = gpu.loop_cap();
    eprintln!("{name}: loop cap {cap:?}");
    if name.contains("llvmpipe") {
        // 65535 iterations per invocation, the outer loop's counted with the inner's.
        assert!(cap.is_some_and(|c| (60_000..=65_535).contains(&c)), "{cap:?}");
    }
    assert_eq!(gpu.adapter().loop_cap, cap);
    let mut s = scene("experiments/scenes/body.toml");
    s.lights.truncate(1);
    if let Light::Disk(d) = &mut s.lights[0] {
        d.samples = 1024;
    }
    let view = View {
        camera: &s.cameras["measure"],
        width: 16,
        height: 16,
    };
    split_traces_the_cpus_rays(&mut gpu, &s, view, sampling(1));
}

/// An analytic scene with many spheres: each shadow sample loops over all of them, so the
/// samples per dispatch must shrink with the sphere count (a fixed 1024 exceeds llvmpipe's cap
/// past about 60 spheres and drops rays without a word).
#[test]
fn many_spheres_keep_every_shadow_ray_under_the_loop_cap() {
    let Some(mut gpu) = common::gpu() else { return };
    let mut s = scene("experiments/scenes/sphere.toml");
    // Below the ground plane: every shadow ray tests them, none is blocked by them.
    for i in 0..120 {
        s.shapes.push(penumbra::scene::Shape::Sphere(penumbra::scene::Sphere {
            center: glam::DVec3::new(0.1 * i as f64 - 6.0, 0.0, -3.0),
            radius: 0.04,
            albedo: 0.5,
        }));
    }
    if let Light::Disk(d) = &mut s.lights[0] {
        d.samples = 1024;
    }
    let view = View {
        camera: &s.cameras["measure"],
        width: 12,
        height: 12,
    };
    split_traces_the_cpus_rays(&mut gpu, &s, view, sampling(4));
}

/// A mesh whose walks outrun the split's budget: 2000 needles between random points of the space
/// between receiver and light, whose boxes overlap so much that a shadow ray enters hundreds of
/// leaves. The shader reports loops cut short, the renderer halves its split until the frame is
/// whole, and the GPU traces exactly the CPU's rays.
#[test]
fn walks_longer_than_their_budget_are_caught_and_split_again() {
    let Some(mut gpu) = common::gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    let stream = penumbra::sampling::Stream::new(21, 0, None);
    let mut next = 0u32;
    let mut point = || {
        let mut u = || {
            next += 1;
            stream.unit(next)
        };
        [2.0 * u() - 1.0, 2.0 * u() - 1.0, 0.6 + 0.9 * u()]
    };
    let mut obj = String::new();
    for k in 0..2000 {
        let (a, b) = (point(), point());
        obj += &format!("v {} {} {}\nv {} {} {}\n", a[0], a[1], a[2], b[0], b[1], b[2]);
        obj += &format!(
            "v {} {} {}\nf {} {} {}\n",
            b[0] + 1e-4,
            b[1],
            b[2],
            3 * k + 1,
            3 * k + 2,
            3 * k + 3
        );
    }
    std::fs::write(dir.path().join("needles.obj"), obj).unwrap();
    let path = dir.path().join("needles.toml");
    std::fs::write(&path, common::mesh_over_plane("needles.obj", 0.05)).unwrap();
    let mut s = Scene::load(&path).unwrap();
    if let Light::Disk(d) = &mut s.lights[0] {
        d.samples = 64;
    }
    let view = View {
        camera: &s.cameras["measure"],
        width: 8,
        height: 8,
    };
    let cpu = CpuBackend::default().render(&s, view, sampling(5)).unwrap();
    let frame = gpu.render(&s, view, sampling(5)).unwrap();
    assert_eq!(frame.rays.shadow_total(), cpu.rays.shadow_total());
    let timed = gpu.time(&s, view, sampling(5), 0, 1).unwrap();
    assert_eq!(timed.seconds.len(), 1);
    if gpu.loop_cap().is_some() {
        assert!(
            gpu.chunk_divisor() > 1,
            "the walks fit the budget: the test lost its teeth"
        );
    }
}

#[test]
fn scheme_ids_come_from_one_list_and_unknown_ids_give_nan() {
    let prelude = scheme_prelude();
    for s in DiskScheme::ALL {
        let line = format!(
            "const SCHEME_{}: u32 = {}u;",
            s.name().to_uppercase().replace('-', "_"),
            s.gpu_id()
        );
        assert!(prelude.contains(&line), "{line} missing from\n{prelude}");
    }
    // The built-ins and the one id every points file shares.
    let points = format!("const SCHEME_POINTS: u32 = {}u;", penumbra::sampling::POINTS_GPU_ID);
    assert!(prelude.contains(&points), "{points} missing from\n{prelude}");
    let ids = prelude.lines().filter(|l| l.starts_with("const SCHEME_")).count();
    assert_eq!(ids, DiskScheme::ALL.len() + 1, "{prelude}");
    #[cfg(feature = "test-hooks")]
    {
        let Some(mut gpu) = common::gpu() else { return };
        let unloaded = gpu
            .disk_points_of_id(penumbra::sampling::POINTS_GPU_ID, 8, 1, 0)
            .unwrap();
        assert!(
            unloaded.iter().all(|p| p[0].is_nan() && p[1].is_nan()),
            "no set packed: {unloaded:?}"
        );
        let unknown = penumbra::sampling::POINTS_GPU_ID + 1;
        let pts = gpu.disk_points_of_id(unknown, 8, 1, 0).unwrap();
        assert!(pts.iter().all(|p| p[0].is_nan() && p[1].is_nan()), "{pts:?}");
    }
}

/// Jittered strata from the integer square root agree between WGSL and Rust at perfect squares,
/// one below and one above them, and at primes.
#[test]
#[cfg(feature = "test-hooks")]
fn strata_agree_at_squares_and_their_neighbours() {
    let Some(mut gpu) = common::gpu() else { return };
    for n in [
        3u32, 8, 9, 10, 15, 16, 17, 63, 64, 65, 97, 255, 256, 1023, 1024, 4095, 4096,
    ] {
        let (rows, cols) = penumbra::sampling::strata(n);
        assert_eq!(rows * cols, n);
        let g = gpu.disk_points(DiskScheme::Jittered, n, 9, 3).unwrap();
        let c = DiskScheme::Jittered.points(n, common::hook_site(9, 3, 0));
        for (k, (a, b)) in g.iter().zip(&c).enumerate() {
            let d = ((a[0] as f64 - b.x).powi(2) + (a[1] as f64 - b.y).powi(2)).sqrt();
            assert!(d < 2e-6, "n={n} k={k}: gpu {a:?} cpu {b}");
        }
    }
}
