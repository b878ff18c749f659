//! Meshes: the dressed-body scene loads, its BVH agrees with brute force and with the GPU's
//! WGSL traversal on seeded random rays, and the two backends render it alike.

use crate::common;

use glam::DVec3;
use penumbra::render::cpu::CpuBackend;
use penumbra::render::{Backend, Sampling, View};
use penumbra::sampling::{rng::Stream, DiskScheme, Pattern};
use penumbra::scene::Scene;

fn body() -> Scene {
    Scene::load(&common::repo("experiments/scenes/body.toml")).unwrap()
}

/// Seeded rays from a sphere around the figure towards random points of its bounding box.
fn rays(scene: &Scene, n: u32) -> Vec<(DVec3, DVec3, f64)> {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in scene.triangles.positions.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let s = Stream::new(99, 0, None);
    (0..n)
        .map(|k| {
            let u = |i: u32| s.unit(6 * k + i);
            let target = lo + (hi - lo) * DVec3::new(u(0), u(1), u(2));
            let dir = DVec3::new(u(3) - 0.5, u(4) - 0.5, u(5) - 0.5).normalize_or(DVec3::Z);
            (target - dir * 3.0, dir, f64::INFINITY)
        })
        .collect()
}

#[test]
fn body_scene_loads_about_32k_triangles() {
    let s = body();
    assert_eq!(s.accel.as_ref().map(|a| a.name()), Some("bvh"));
    assert_eq!(s.meshes().count(), 1);
    // 13,378 + 2,650 quads = 32,056 triangles, less any degenerate ones (reported).
    let m = s.meshes().next().unwrap();
    assert_eq!(m.triangles + m.skipped.degenerate + m.skipped.non_finite, 32_056);
    assert_eq!(s.triangles.positions.len(), m.triangles);
    let min_z = s
        .triangles
        .positions
        .iter()
        .flatten()
        .map(|p| p.z)
        .fold(f64::INFINITY, f64::min);
    assert!(min_z.abs() < 1e-3, "the soles rest on the ground: min z = {min_z}");
}

/// The visibility-field scenes' OFF meshes load whole: vertex and triangle counts as recorded in
/// assets/meshes/PROVENANCE.md, every corner a listed vertex.
#[test]
fn shipped_off_meshes_load_whole() {
    for (name, vertices, triangles) in [
        ("cow", 2_904, 5_804),
        ("mech-holes-shark", 5_246, 10_192),
        ("bull", 6_200, 12_396),
        ("camel", 9_770, 19_536),
        ("man", 17_495, 34_986),
    ] {
        let path = common::repo(&format!("assets/meshes/{name}.off"));
        let m = penumbra::mesh::load(&path).unwrap();
        assert_eq!(m.triangles.len(), triangles, "{name}");
        let mut corners: Vec<[u64; 3]> = m.triangles.iter().flatten().map(|c| c.map(f64::to_bits)).collect();
        corners.sort_unstable();
        corners.dedup();
        assert!(corners.len() <= vertices, "{name}: {} distinct corners", corners.len());
        assert!(
            corners.len() * 100 >= vertices * 99,
            "{name}: {} of {vertices} vertices used",
            corners.len()
        );
    }
}

/// A scene places an OFF mesh like an OBJ one; an unknown extension is an error naming the file.
#[test]
fn scenes_read_off_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let cow = common::repo("assets/meshes/cow.off");
    let scene = |path: &std::path::Path| {
        format!(
            "[cameras.c]\nprojection = \"perspective\"\nposition = [0.0, -3.0, 1.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 40.0\n\n[[meshes]]\npath = \"{}\"\nalbedo = 0.5\n",
            path.display()
        )
    };
    let file = dir.path().join("cow.toml");
    std::fs::write(&file, scene(&cow)).unwrap();
    let s = Scene::load(&file).unwrap();
    assert_eq!(
        s.triangles.positions.len() + s.meshes().next().unwrap().skipped.degenerate,
        5_804
    );
    let ply = dir.path().join("cow.ply");
    std::fs::write(&ply, "ply\n").unwrap();
    std::fs::write(&file, scene(&ply)).unwrap();
    let e = Scene::load(&file).unwrap_err().to_string();
    assert!(
        e.contains("cow.ply") && e.contains("unknown mesh format") && e.contains("meshes[0].path"),
        "{e}"
    );
}

/// obvhs' CPU traversal and a brute-force loop over all triangles find the same closest
/// triangle at the same distance for every ray.
#[test]
fn cpu_traversal_matches_brute_force() {
    let s = body();
    let bvh = s.accel.as_ref().unwrap();
    for (o, d, _) in rays(&s, 1500) {
        let (a, b) = (
            bvh.closest(o, d, f64::INFINITY, u32::MAX),
            penumbra::accel::brute_force(&s.triangles, o, d),
        );
        assert_eq!(a.map(|h| h.triangle), b.map(|h| h.triangle), "o={o} d={d}");
        if let (Some(a), Some(b)) = (a, b) {
            assert!((a.t - b.t).abs() < 1e-12);
        }
        assert_eq!(bvh.any_hit(o, d, f64::INFINITY, u32::MAX), b.is_some());
    }
}

/// The WGSL traversal (f32, in the frame's local coordinates) against obvhs' (f64 triangle
/// tests): same hit or miss and the same triangle for all but 0.5 % of rays (grazing an edge
/// between two triangles, where f32 rounding may pick the neighbour), distance within 1e-4
/// relative when the triangle agrees, and any-hit agreeing with closest-hit on each backend.
#[test]
#[cfg(feature = "test-hooks")]
fn gpu_traversal_matches_cpu() {
    let Some(mut gpu) = common::gpu() else { return };
    let s = body();
    let bvh = s.accel.as_ref().unwrap();
    let rays = rays(&s, 20_000);
    let g = gpu.probe(&s, &rays).unwrap();
    let mut disagree = 0;
    for ((o, d, _), gh) in rays.iter().zip(&g) {
        let c = bvh.closest(*o, *d, f64::INFINITY, u32::MAX);
        assert_eq!(gh.any, gh.closest.is_some());
        match (gh.closest, c) {
            (Some((t, tri)), Some(c)) if tri == c.triangle => {
                assert!((t - c.t).abs() <= 1e-4 * c.t, "t {t} vs {}", c.t)
            }
            (None, None) => {}
            _ => disagree += 1,
        }
    }
    let hits = g.iter().filter(|h| h.closest.is_some()).count();
    eprintln!(
        "{disagree} of {} rays disagree between GPU and CPU traversal; {hits} hit the body",
        rays.len()
    );
    assert!(hits > 5_000, "too few rays hit the body: {hits}");
    assert!(
        disagree * 200 <= rays.len(),
        "{disagree} of {} rays disagree",
        rays.len()
    );
}

/// GPU and CPU render the body scene alike: the same object hit in all but 0.5 % of pixels,
/// and mean |dV| < 5e-3 for both lights.
#[test]
fn backends_render_the_body_alike() {
    let Some(mut gpu) = common::gpu() else { return };
    let s = body();
    for camera in ["measure", "picture"] {
        let view = View {
            camera: &s.cameras[camera],
            width: 64,
            height: 48,
        };
        let sampling = Sampling {
            scheme: DiskScheme::Sobol,
            pattern: Pattern::PerPixel,
            seed: 3,
            frame: 0,
        };
        let (g, c) = (
            gpu.render(&s, view, sampling).unwrap(),
            CpuBackend::default().render(&s, view, sampling).unwrap(),
        );
        let hit_diff = g.hit.iter().zip(&c.hit).filter(|(a, b)| a != b).count();
        assert!(
            hit_diff * 200 <= g.hit.len(),
            "{camera}: {hit_diff} pixels hit different objects"
        );
        for l in 0..2 {
            let mean = g.visibility[l]
                .iter()
                .zip(&c.visibility[l])
                .map(|(a, b)| (a - b).abs() as f64)
                .sum::<f64>()
                / g.hit.len() as f64;
            assert!(mean < 5e-3, "{camera} light {l}: mean |dV| = {mean}");
        }
    }
}

/// Degenerate, zero-area and NaN/Inf triangles are skipped with a count and never hit.
#[test]
fn degenerate_triangles_are_skipped_and_never_hit() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 2 0\nv nan 0 0\nv inf 0 0\nv 0.5 0.5 0\n\
               f 1 2 3\nf 1 2 4\nf 1 1 1\nf 5 2 3\nf 6 2 3\nf 1 7 4\n";
    std::fs::write(dir.path().join("m.obj"), obj).unwrap();
    std::fs::write(
        dir.path().join("s.toml"),
        "[cameras.c]\nprojection = \"orthographic\"\nposition = [0.2, 0.2, 5]\nlook_at = [0.2, 0.2, 0]\nup = [0, 1, 0]\nwidth = 4\n\n[[meshes]]\npath = \"m.obj\"\n",
    )
    .unwrap();
    let s = Scene::load(&dir.path().join("s.toml")).unwrap();
    let m = s.meshes().next().unwrap();
    assert_eq!((m.triangles, m.skipped.degenerate, m.skipped.non_finite), (2, 2, 2));
    let bvh = s.accel.as_ref().unwrap();
    // A ray along the line the degenerate triangles lie on, and one through the valid ones.
    let along = bvh.closest(
        DVec3::new(-1.0, -1.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0).normalize(),
        f64::INFINITY,
        u32::MAX,
    );
    assert!(along.is_none_or(|h| h.triangle < 2));
    assert!(bvh
        .closest(DVec3::new(0.2, 0.2, 1.0), DVec3::NEG_Z, f64::INFINITY, u32::MAX)
        .is_some());
}

#[test]
fn mesh_errors_name_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 9\n").unwrap();
    let scene = "[cameras.c]\nprojection = \"orthographic\"\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nwidth = 4\n\n[[meshes]]\npath = \"bad.obj\"\n";
    std::fs::write(dir.path().join("s.toml"), scene).unwrap();
    let e = Scene::load(&dir.path().join("s.toml")).unwrap_err().to_string();
    assert!(
        e.contains("s.toml:9") && e.contains("meshes[0].path") && e.contains("bad.obj:3:"),
        "{e}"
    );
    std::fs::write(dir.path().join("s.toml"), scene.replace("bad.obj", "missing.obj")).unwrap();
    let e = Scene::load(&dir.path().join("s.toml")).unwrap_err().to_string();
    assert!(e.contains("missing.obj") && e.contains("cannot read"), "{e}");
    std::fs::write(
        dir.path().join("s.toml"),
        format!("{scene}groups = [\"hair\"]\n").replace("bad.obj", "../../../../dev/null"),
    )
    .unwrap();
    assert!(Scene::load(&dir.path().join("s.toml")).is_err());
}

/// Long shadow-ray loops over a mesh run to the end on the GPU: the same number of rays as the
/// CPU at 1024 rays per pixel, and the same visibility to within a few rays. (lavapipe caps
/// loop iterations per invocation; the renderer splits the sample loop into dispatches.)
#[test]
fn long_shadow_loops_run_to_the_end() {
    let Some(mut gpu) = common::gpu() else { return };
    let mut s = body();
    s.lights.truncate(1);
    if let penumbra::scene::Light::Disk(d) = &mut s.lights[0] {
        d.samples = 1024;
    }
    let view = View {
        camera: &s.cameras["measure"],
        width: 16,
        height: 16,
    };
    let sampling = Sampling {
        scheme: DiskScheme::Uniform,
        pattern: Pattern::PerPixel,
        seed: 1,
        frame: 0,
    };
    let (g, c) = (
        gpu.render(&s, view, sampling).unwrap(),
        CpuBackend::default().render(&s, view, sampling).unwrap(),
    );
    assert_eq!(g.rays.shadow_total(), c.rays.shadow_total());
    let worst = g.visibility[0]
        .iter()
        .zip(&c.visibility[0])
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f32::max);
    assert!(worst <= 4.0 / 1024.0, "max |dV| = {worst}");
}

/// `accelerator = "vlf"` renders the body scene exactly as the BVH does, on each backend: the
/// same object in every pixel, the same visibility of both lights and the same ray counts, for
/// the measuring and the perspective camera.
#[test]
fn the_visibility_field_renders_the_body_as_the_bvh_does() {
    let bvh = body();
    let vlf = bvh
        .clone()
        .with_accelerator(penumbra::accel::AccelSettings::named("vlf").expect("registered"));
    let mut cpu = CpuBackend::default();
    let mut gpu = common::gpu();
    let mut backends: Vec<(&str, &mut dyn Backend)> = vec![("cpu", &mut cpu)];
    if let Some(g) = gpu.as_mut() {
        backends.push(("gpu", &mut **g));
    }
    for (backend, b) in backends {
        for camera in ["measure", "picture"] {
            let view = View {
                camera: &bvh.cameras[camera],
                width: 48,
                height: 36,
            };
            let sampling = Sampling {
                scheme: DiskScheme::Paper,
                pattern: Pattern::PerPixel,
                seed: 5,
                frame: 0,
            };
            let (a, b) = (
                b.render(&bvh, view, sampling).unwrap(),
                b.render(&vlf, view, sampling).unwrap(),
            );
            let shadowed = a.visibility.iter().flatten().filter(|&&v| v < 1.0).count();
            assert!(
                shadowed > 50,
                "{backend} {camera}: the body's shadow is in view ({shadowed} pixels)"
            );
            assert_eq!(a.hit, b.hit, "{backend} {camera}: objects hit");
            assert_eq!(a.visibility, b.visibility, "{backend} {camera}: visibility");
            assert_eq!(a.rays, b.rays, "{backend} {camera}: rays");
        }
    }
}

/// body.toml measures both lights: each light's penumbra covers hundreds of the measuring
/// view's receiver pixels, and each light carries a real share of a run's error over the sweep's
/// mask (the union of the lights' penumbrae): sampling a light exactly instead removes at least
/// 15 % of the squared error. Where a light casts no penumbra in view (the earlier view: the
/// second light's shadow fell elsewhere), it carries none, and the two-light error is the
/// one-light error rescaled.
#[test]
fn both_lights_carry_a_share_of_the_measured_error() {
    use penumbra::metrics::error::PenumbraMask;
    use penumbra::metrics::profile::Receivers;
    let scene = body();
    let camera = &scene.cameras["measure"];
    let view = View {
        camera,
        width: 96,
        height: 96,
    };
    let with_samples = |n: u32| {
        let mut s = scene.clone();
        for l in &mut s.lights {
            if let penumbra::scene::Light::Disk(d) = l {
                d.samples = n;
            }
        }
        s
    };
    let render = |s: &Scene, scheme: DiskScheme, seed: u32| {
        let sampling = Sampling {
            scheme,
            pattern: Pattern::PerPixel,
            seed,
            frame: 0,
        };
        CpuBackend::default().render(s, view, sampling).unwrap()
    };
    let gt = render(&with_samples(128), DiskScheme::Jittered, 1);
    let run = render(&with_samples(16), DiskScheme::Uniform, 2);
    let receivers = Receivers::new(&scene, view, 0, &gt.hit, camera.look_at, 0.7 / 96.0);
    assert!(receivers.pixels.len() > 90 * 90, "the view sees the floor");
    let (g, v) = (&gt.visibility, &run.visibility);
    for light in 0..2 {
        let own = PenumbraMask::union(&g[light..light + 1], &receivers);
        assert!(
            own.pixels.len() >= 300,
            "light {light}: {} penumbra pixels",
            own.pixels.len()
        );
    }
    let mask = PenumbraMask::union(g, &receivers);
    let squared = |a0: &[f32], a1: &[f32]| -> f64 {
        mask.pixels
            .iter()
            .map(|&i| (((a0[i] + a1[i]) - (g[0][i] + g[1][i])) as f64 / 2.0).powi(2))
            .sum::<f64>()
    };
    let both = squared(&v[0], &v[1]);
    for (light, without) in [(0, squared(&g[0], &v[1])), (1, squared(&v[0], &g[1]))] {
        let share = 1.0 - without / both;
        assert!(share >= 0.15, "light {light} carries {share:.3} of the squared error");
    }
}
