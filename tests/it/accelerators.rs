//! Every registered acceleration structure answers the same as brute force, on both backends:
//! a frame of a scene with meshes is the same whichever structure the scene names.

use crate::common;

use glam::DVec3;
use penumbra::accel::{self, AccelSettings, REGISTRY};
use penumbra::config::ConfigError;
use penumbra::mesh::Triangles;
use penumbra::render::cpu::CpuBackend;
use penumbra::render::{Backend, Frame, Sampling, View};
use penumbra::sampling::{DiskScheme, Pattern, Stream};
use penumbra::scene::camera::{Camera, Projection};
use penumbra::scene::{DiskLight, Light, Mesh, Plane, Scene, Shape, Sphere};

fn mesh(name: &str, albedo: f64, triangles: usize) -> Mesh {
    Mesh {
        source: name.into(),
        file_fnv1a: 0,
        albedo,
        mirror: 0.0,
        triangles,
        skipped: Default::default(),
    }
}

/// Two meshes of different albedo (a tilted square and a tent of two faces sharing an edge)
/// over a ground plane, with a sphere listed after the plane, under a disk light.
fn scene(name: &'static str) -> Scene {
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let triangles = Triangles {
        positions: vec![
            [p(-0.3, -0.3, 0.5), p(0.0, -0.3, 0.6), p(0.0, 0.0, 0.6)],
            [p(-0.3, -0.3, 0.5), p(0.0, 0.0, 0.6), p(-0.3, 0.0, 0.5)],
            [p(0.1, 0.1, 0.2), p(0.4, 0.1, 0.2), p(0.25, 0.25, 0.45)],
            [p(0.1, 0.4, 0.2), p(0.4, 0.4, 0.2), p(0.25, 0.25, 0.45)],
        ],
        object_of: vec![0, 0, 1, 1],
    };
    let mut s = Scene::analytic(
        vec![],
        vec![Plane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
            albedo: 0.8,
        }],
        vec![Light::Disk(DiskLight {
            center: p(0.0, 0.0, 2.0),
            normal: DVec3::NEG_Z,
            radius: 0.2,
            power: 50.0,
            samples: 16,
        })],
    );
    s.shapes.push(Shape::Sphere(Sphere {
        center: p(0.2, -0.25, 0.15),
        radius: 0.1,
        albedo: 0.4,
    }));
    s.with_meshes(
        vec![mesh("square", 0.3, 2), mesh("tent", 0.6, 2)],
        triangles,
        AccelSettings::named(name).expect("a registered structure"),
    )
}

fn camera() -> Camera {
    Camera {
        position: DVec3::new(0.3, -1.5, 1.6),
        look_at: DVec3::new(0.0, 0.0, 0.2),
        up: DVec3::Z,
        projection: Projection::Perspective { fov_y_deg: 45.0 },
    }
}

fn view(cam: &Camera) -> View<'_> {
    View {
        camera: cam,
        width: 48,
        height: 40,
    }
}

fn sampling() -> Sampling {
    Sampling {
        scheme: DiskScheme::Jittered,
        pattern: Pattern::PerPixel,
        seed: 5,
        frame: 0,
    }
}

fn render(b: &mut dyn Backend, s: &Scene, cam: &Camera) -> Frame {
    b.render(s, view(cam), sampling()).unwrap()
}

/// The structure's CPU queries against `accel::brute_force` on seeded rays through the meshes'
/// bounding box: same triangle, same t; any-hit agrees with a closest hit existing. (An
/// inexact structure, Embree's f32 tests, is held to brute force but for edge grazes by its own
/// tests.)
#[test]
fn every_structure_matches_brute_force_on_the_cpu() {
    for r in REGISTRY.iter().filter(|r| r.exact) {
        let s = scene(r.name);
        let a = s.accel.as_ref().unwrap();
        assert_eq!(a.name(), r.name);
        let stream = Stream::new(7, 0, None);
        for k in 0..2000 {
            let u = |i: u32| stream.unit(6 * k + i);
            let target = DVec3::new(u(0) * 0.8 - 0.4, u(1) * 0.8 - 0.4, u(2) * 0.6);
            let d = DVec3::new(u(3) - 0.5, u(4) - 0.5, u(5) - 0.5).normalize_or(DVec3::Z);
            let o = target - d * 2.0;
            let (got, want) = (
                a.closest(o, d, f64::INFINITY, u32::MAX),
                accel::brute_force(&s.triangles, o, d),
            );
            assert_eq!(got.map(|h| h.triangle), want.map(|h| h.triangle), "{} ray {k}", r.name);
            assert_eq!(got.map(|h| h.t), want.map(|h| h.t), "{} ray {k}", r.name);
            assert_eq!(
                a.any_hit(o, d, f64::INFINITY, u32::MAX),
                want.is_some(),
                "{} ray {k}",
                r.name
            );
        }
    }
}

/// Rays aimed exactly at mesh vertices (hits on shared edges and corners, where f32 box tests
/// are decided by rounding) from inside and outside the body mesh's bounds: every structure
/// finds brute force's distance.
#[test]
fn vertex_aimed_rays_on_the_body_match_brute_force() {
    let body = Scene::load(&common::repo("experiments/scenes/body.toml")).unwrap();
    let t = &body.triangles;
    let stream = Stream::new(1, 0, None);
    for r in REGISTRY.iter().filter(|r| r.exact) {
        let s = body.clone().with_accelerator(AccelSettings::default_for(r));
        let a = s.accel.as_ref().unwrap();
        let mut wrong = 0;
        for k in 0..3000 {
            let u = |i: u32| stream.unit(6 * k + i);
            let p = t.positions[(u(0) * t.positions.len() as f64) as usize % t.positions.len()][(k % 3) as usize];
            let d = (DVec3::new(u(1), u(2), u(3)) - 0.5).normalize();
            let o = p - d * (0.5 + 20.0 * u(4));
            let want = accel::brute_force(t, o, d).map(|h| h.t);
            wrong += (a.closest(o, d, f64::INFINITY, u32::MAX).map(|h| h.t) != want) as u32;
            wrong += (a.any_hit(o, d, f64::INFINITY, u32::MAX) != want.is_some()) as u32;
        }
        assert_eq!(wrong, 0, "{}: {wrong} answers differ from brute force", r.name);
    }
}

/// An inexact structure's frame (Embree's f32 triangle tests) against the exact one: the same
/// surface seen in every pixel but 1 %, and shadows that differ in at most 1 % of the
/// visibility samples' worth (a ray grazing an edge decided the other way).
fn inexact_frame_is_close(name: &str, got: &Frame, want: &Frame) {
    let n = want.hit.len();
    let hits = got.hit.iter().zip(&want.hit).filter(|(a, b)| a != b).count();
    assert!(hits * 100 <= n, "{name}: {hits} of {n} pixels see another surface");
    for (light, (g, w)) in got.visibility.iter().zip(&want.visibility).enumerate() {
        let moved: f64 = g.iter().zip(w).map(|(a, b)| (a - b).abs() as f64).sum();
        assert!(
            moved <= 0.01 * n as f64,
            "{name}: light {light}'s visibility moved by {moved} over {n} pixels"
        );
    }
}

/// Frames rendered through each structure are identical to the default structure's, on the
/// CPU and on the GPU: hits, visibility and radiance, bit for bit (both walk the same f32 or f64
/// triangles and the meshes' faces meet only along edges of equal normal or not at all).
#[test]
fn frames_do_not_depend_on_the_structure() {
    let cam = camera();
    let reference = scene(REGISTRY[0].name);
    let check = |name: &str, b: &mut dyn Backend| {
        let want = render(b, &reference, &cam);
        let meshes_seen = want.hit.iter().filter(|&&h| h >= 2 && h != u32::MAX).count();
        assert!(
            meshes_seen > 50,
            "{name}: the meshes must be in view ({meshes_seen} pixels)"
        );
        for r in &REGISTRY[1..] {
            if name == "gpu" && !r.gpu {
                let e = b.render(&scene(r.name), view(&cam), sampling()).unwrap_err();
                assert!(format!("{e:#}").contains(&format!("`{}`", r.name)), "{e:#}");
                continue;
            }
            let got = render(b, &scene(r.name), &cam);
            if !r.exact {
                inexact_frame_is_close(r.name, &got, &want);
                continue;
            }
            assert_eq!(got.hit, want.hit, "{name}: {} hits", r.name);
            assert_eq!(got.visibility, want.visibility, "{name}: {} visibility", r.name);
            assert_eq!(got.radiance, want.radiance, "{name}: {} radiance", r.name);
            assert_eq!(got.rays, want.rays, "{name}: {} rays", r.name);
        }
    };
    check("cpu", &mut CpuBackend::default());
    if let Some(mut g) = common::gpu() {
        check("gpu", &mut *g);
    }
}

/// Each structure's WGSL queries against the CPU's brute force on the same seeded rays: the same
/// triangle and t within f32 rounding, and any-hit agreeing, except where the ray passes
/// within f32 rounding of an edge.
#[test]
#[cfg(feature = "test-hooks")]
fn every_structure_matches_brute_force_on_the_gpu() {
    let Some(mut gpu) = common::gpu() else { return };
    for r in REGISTRY.iter().filter(|r| r.gpu) {
        let mut s = scene(r.name);
        s.cameras.insert("c".into(), camera());
        let stream = Stream::new(11, 0, None);
        let rays: Vec<_> = (0..4000)
            .map(|k| {
                let u = |i: u32| stream.unit(6 * k + i);
                let target = DVec3::new(u(0) * 0.8 - 0.4, u(1) * 0.8 - 0.4, u(2) * 0.6);
                let d = DVec3::new(u(3) - 0.5, u(4) - 0.5, u(5) - 0.5).normalize_or(DVec3::Z);
                (target - d * 2.0, d, f64::INFINITY)
            })
            .collect();
        let got = gpu.probe(&s, &rays).unwrap();
        let mut differ = 0;
        for ((o, d, _), g) in rays.iter().zip(&got) {
            let want = accel::brute_force(&s.triangles, *o, *d);
            match (g.closest, want) {
                (Some((t, tri)), Some(w)) if tri == w.triangle => {
                    assert!((t - w.t).abs() < 1e-5 * w.t.max(1.0), "{}: t {t} vs {}", r.name, w.t)
                }
                (None, None) => {}
                _ => differ += 1,
            }
            assert_eq!(g.any, g.closest.is_some(), "{}: any-hit and closest disagree", r.name);
        }
        let hits = got.iter().filter(|g| g.closest.is_some()).count();
        assert!(hits > 400, "{}: the rays must meet the meshes ({hits} hits)", r.name);
        assert!(
            differ <= 4,
            "{}: {differ} of {} rays differ from brute force",
            r.name,
            rays.len()
        );
    }
}

/// An unknown structure name in a scene file is an error naming the file, the key and the
/// known names.
#[test]
fn unknown_structure_is_a_located_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    let text = format!(
        "accelerator = \"kd-tree\"\n[cameras.c]\nprojection = \"orthographic\"\nposition = [0.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\nwidth = 1.0\n{}",
        common::plane_and_light(0.1)
    );
    std::fs::write(&path, text).unwrap();
    let e = Scene::load(&path).unwrap_err().to_string();
    assert!(e.contains("scene.toml:1") && e.contains("accelerator"), "{e}");
    assert!(e.contains("kd-tree") && e.contains("bvh") && e.contains("brute"), "{e}");
}

/// The sweep's `accelerator` axis: a mesh scene swept over every registered structure gives one
/// row per structure per run, and (every structure being exact) the same measurements in each;
/// an unregistered name is an error at its place in the list.
#[test]
fn sweeping_the_structure_changes_only_its_columns() {
    // A structure without a GPU form is swept only where the sweep runs on the CPU.
    let gpu = common::gpu();
    let swept: Vec<_> = REGISTRY.iter().filter(|r| r.gpu || gpu.is_none()).collect();
    let dir = tempfile::tempdir().unwrap();
    let names: Vec<String> = swept.iter().map(|r| format!("\"{}\"", r.name)).collect();
    let exp = common::tiny_experiment(dir.path(), |t| {
        t.replace(
            "seeds = [1, 2]",
            &format!("seeds = [1, 2]\naccelerators = [{}]", names.join(", ")),
        )
        .replace("samples = [4, 16]", "samples = [4]")
    });
    let tent = "v -0.1 -0.1 0.5\nv 0.1 -0.1 0.5\nv 0.0 0.1 0.5\nv 0.0 0.0 0.7\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
    std::fs::write(dir.path().join("scenes/tent.obj"), tent).unwrap();
    let mut text = std::fs::read_to_string(dir.path().join("scenes/sphere.toml")).unwrap();
    text += "\n[[meshes]]\npath = \"tent.obj\"\nalbedo = 0.5\n";
    std::fs::write(dir.path().join("scenes/sphere.toml"), text).unwrap();
    let out = dir.path().join("out");
    let (code, stderr) = common::sweep(&[exp.as_os_str(), "--out".as_ref(), out.as_os_str()]);
    assert_eq!(code, 0, "{stderr}");
    let mut rows = csv::Reader::from_path(out.join("runs.csv")).unwrap();
    let header = rows.headers().unwrap().clone();
    let col = |k: &str| header.iter().position(|h| h == k).unwrap();
    let (acc, key) = (col("accelerator"), col("run_key"));
    let parameter_columns = penumbra::accel::settings::parameter_columns();
    let structure_columns = [
        "run_key",
        "accelerator",
        "build_s",
        "gpu_bytes_per_triangle",
        "nodes_visited",
        "primitive_tests",
    ];
    let is_parameter = |h: &str| parameter_columns.iter().any(|c| c.name == h);
    assert!(
        !header.iter().any(|h| h == "parameters"),
        "one value per column: {header:?}"
    );
    let timing = |h: &str| h.contains("frame_s") || h.contains("rays_per_s") || h == "timed_frames";
    let mut by_structure: std::collections::BTreeMap<String, Vec<Vec<String>>> = Default::default();
    for r in rows.records() {
        let r = r.unwrap();
        assert_eq!(r.get(col("status")), Some("ok"), "{r:?}");
        let kept = r
            .iter()
            .zip(header.iter())
            .filter(|(_, h)| !structure_columns.contains(h) && !is_parameter(h) && !timing(h))
            .map(|(v, _)| v.to_string())
            .collect();
        assert!(!r[key].is_empty());
        // Each run was rendered with its own structure: its parameter columns hold that
        // structure's defaults (empty for a key its defaults leave out, such as a median
        // kd-tree's SAH costs), every other structure's are empty (brute force has none).
        let structure = accel::registered(&r[acc]).unwrap();
        let settings = AccelSettings::default_for(structure);
        for c in parameter_columns {
            let expected = if c.structure == structure.name {
                settings.value(&c.key).unwrap_or_default()
            } else {
                String::new()
            };
            assert_eq!(r[col(&c.name)], expected, "{} of a {} run", c.name, structure.name);
        }
        by_structure.entry(r[acc].to_string()).or_default().push(kept);
    }
    assert_eq!(by_structure.len(), swept.len(), "{:?}", by_structure.keys());
    let first = by_structure.values().next().unwrap();
    assert_eq!(first.len(), 2 * 2 * 2);
    for (name, rows) in &by_structure {
        assert_eq!(rows, first, "{name}'s measurements differ");
    }
    assert!(
        header.iter().any(|h| h == "image_fnv1a"),
        "runs.csv carries each image's hash"
    );
    // The report sets each structure beside the first: 2 schemes x 2 patterns x 2 seeds each.
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    let others = 8 * (swept.len() - 1);
    assert!(report.contains("## What the acceleration structure costs"), "{report}");
    assert!(
        report.contains(&format!(
            "Identical shadow images in {others} of {others} runs compared."
        )),
        "{report}"
    );
    assert!(!report.contains("NaN"), "{report}");

    let bad = common::tiny_experiment(dir.path(), |t| {
        t.replace("seeds = [1, 2]", "seeds = [1, 2]\naccelerators = [\"bvh\", \"kd\"]")
    });
    let (code, stderr) = common::sweep(&[bad.as_os_str(), "--out".as_ref(), dir.path().join("bad").as_os_str()]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("tiny.toml:15:") && stderr.contains("sweep.accelerators[1]") && stderr.contains("`kd`"),
        "{stderr}"
    );
}

/// A one-triangle scene in `dir` (scene.toml) indexed by `structure`, whose table of the same
/// name holds `parameters` (line 3 on).
fn with_parameters(dir: &std::path::Path, structure: &str, parameters: &str) -> Result<Scene, ConfigError> {
    let path = dir.join("scene.toml");
    std::fs::write(dir.join("tri.obj"), "v 0 0 0.5\nv 1 0 0.5\nv 0 1 0.5\nf 1 2 3\n").unwrap();
    let text = format!(
        "accelerator = \"{structure}\"\n[accel.{structure}]\n{parameters}\n[cameras.c]\nprojection = \"orthographic\"\nposition = [0.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\nwidth = 1.0\n[[meshes]]\npath = \"tri.obj\"\n{}",
        common::plane_and_light(0.1)
    );
    std::fs::write(&path, text).unwrap();
    Scene::load(&path)
}

/// The visibility field's parameters in a scene file: out-of-range values and unknown keys are
/// errors naming the file, line and key; valid ones reach the structure.
#[test]
fn visibility_field_parameters_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let load = |vlf: &str| with_parameters(dir.path(), "vlf", vlf);
    for (vlf, key) in [
        ("tiles = 0", "accel.vlf.tiles"),
        ("depth = 9", "accel.vlf.depth"),
        ("level = 0", "accel.vlf.level"),
        ("split = \"mean\"", "split"),
        ("tile = 64", "tile"),
    ] {
        let e = load(vlf).unwrap_err().to_string();
        assert!(e.contains("scene.toml:3") && e.contains(key), "{vlf}: {e}");
    }
    let s = load("tiles = 16\ndepth = 2\nsplit = \"median\"\nlevel = 4").unwrap();
    let stats = s.accel.as_ref().unwrap().stats();
    assert!(
        stats.parameters.contains("level 4")
            && stats.parameters.contains("16x16")
            && stats.parameters.contains("median"),
        "{}",
        stats.parameters
    );
}

/// The kd-tree's parameters in a scene file: out-of-range values and unknown keys are errors
/// naming the file, line and key; valid ones reach the structure.
#[test]
fn kd_tree_parameters_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let load = |kd: &str| with_parameters(dir.path(), "kdtree", kd);
    for (kd, key) in [
        ("max_depth = 61", "accel.kdtree.max_depth"),
        ("leaf_size = 70000", "accel.kdtree.leaf_size"),
        ("depth = 3", "depth"),
        ("split = \"mean\"", "accel.kdtree.split"),
        ("traversal_cost = 0.0\nsplit = \"sah\"", "accel.kdtree.traversal_cost"),
        ("intersection_cost = -1.0", "accel.kdtree.intersection_cost"),
        ("empty_factor = 1.5\nsplit = \"sah\"", "accel.kdtree.empty_factor"),
    ] {
        let e = load(kd).unwrap_err().to_string();
        assert!(e.contains("scene.toml:3") && e.contains(key), "{kd}: {e}");
    }
    let s = load("max_depth = 7\nleaf_size = 1").unwrap();
    let stats = s.accel.as_ref().unwrap().stats();
    assert_eq!(stats.parameters, "depth 7 leaf 1");
    let s = load("split = \"sah\"\nmax_depth = 7\nleaf_size = 1\ntraversal_cost = 5.0").unwrap();
    let stats = s.accel.as_ref().unwrap().stats();
    assert_eq!(stats.parameters, "sah depth 7 leaf 1 K_T 5 K_I 20 lambda 0.8");
    assert!(stats.description.contains("SAH planes"), "{}", stats.description);
}

/// The work counters are exact and deterministic: with brute force and no light, each pixel asks
/// one query that tests the two analytic shapes and all four triangles; every structure's counts
/// are the same on one thread as on two; and every structure asks the same queries (the same
/// rays) as brute force.
#[test]
fn work_counts_are_exact_and_do_not_depend_on_threads() {
    let cam = camera();
    let mut dark = scene("brute");
    dark.lights.clear();
    let f = render(&mut CpuBackend::default(), &dark, &cam);
    let pixels = 48 * 40;
    let w = f.work().expect("the CPU counts");
    assert_eq!((w.queries, w.nodes, w.primitives), (pixels, 0, pixels * (2 + 4)));
    let on = |threads: usize, s: &Scene| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| render(&mut CpuBackend::default(), s, &cam))
            .work()
            .unwrap()
    };
    let brute = on(2, &scene("brute"));
    for r in REGISTRY {
        let s = scene(r.name);
        let (one, two) = (on(1, &s), on(2, &s));
        assert_eq!(one, two, "{}: counts depend on the thread count", r.name);
        assert_eq!(two.queries, brute.queries, "{} asks other queries", r.name);
        assert!(
            two.primitives <= brute.primitives,
            "{} tests more than brute force",
            r.name
        );
    }
}

/// The GPU's work counters against the CPU's, frame for frame, with every structure. Each ray is
/// one query on either backend (its closest or any hit over shapes and structure), so queries
/// equal rays traced on both. Brute force tests every triangle for a closest hit and those up to
/// the first blocker for an any hit on both, so its primitive tests agree but for the rays f32
/// and f64 decide differently; the other structures' counts are their own GPU walks' (the BVH
/// pops nodes where obvhs' CPU walk tests child pairs, the CWBVH tests a node's children in slot
/// order rather than obvhs' octant order) and are printed beside the CPU's; the kd-trees and the
/// field walk as their CPU twins do on this scene of few triangles. (On large meshes they part:
/// the GPU field tests every entry of a leaf where the CPU skips those whose footprint box misses
/// the ray, about 2x the triangle tests in AO on the cow; the GPU kd-tree's shadow rays in the
/// classroom test 3.4x the CPU's triangles, its lights lying inside the f32 walk's thicker split
/// planes under the lamps' fans: tests/it/kdtree_work_counts.rs.)
/// Counting is off until switched on.
#[test]
fn gpu_work_counters_count_what_the_cpu_counts_where_the_walks_are_the_same() {
    let Some(mut gpu) = common::gpu() else { return };
    let cam = camera();
    let s = scene("bvh");
    assert!(
        gpu.render(&s, view(&cam), sampling()).unwrap().work().is_none(),
        "off by default"
    );
    gpu.count_work(true);
    for r in REGISTRY.iter().filter(|r| r.gpu) {
        let s = scene(r.name);
        let g = gpu.render(&s, view(&cam), sampling()).unwrap();
        let c = CpuBackend::default().render(&s, view(&cam), sampling()).unwrap();
        let (gw, cw) = (g.work().expect("GPU frames count when switched on"), c.work().unwrap());
        eprintln!(
            "{}: GPU {gw:?}, CPU {cw:?}; nodes x{:.3}, primitives x{:.3}",
            r.name,
            gw.nodes as f64 / cw.nodes.max(1) as f64,
            gw.primitives as f64 / cw.primitives.max(1) as f64
        );
        assert_eq!(gw.queries, g.rays.total(), "{}: GPU queries are its rays", r.name);
        assert_eq!(cw.queries, c.rays.total(), "{}: CPU queries are its rays", r.name);
        assert!(gw.nodes > 0 || r.name == "brute", "{}: {gw:?}", r.name);
        if r.name == "brute" {
            assert_eq!((gw.nodes, cw.nodes), (0, 0));
            let off = gw.primitives.abs_diff(cw.primitives) as f64 / cw.primitives as f64;
            assert!(off < 1e-3, "brute: {gw:?} vs {cw:?}");
        }
        if r.name == "vlf" {
            // The same tiles and leaves as the CPU's walk (an empty tile is no leaf on either),
            // but where f32 decides a tile's edge differently: within a few percent.
            let near = |a: u64, b: u64| a.abs_diff(b) as f64 <= 0.05 * b as f64;
            assert!(
                near(gw.nodes, cw.nodes) && near(gw.primitives, cw.primitives),
                "vlf: {gw:?} vs {cw:?}"
            );
        }
        if r.name.starts_with("kdtree") {
            // The same walk as the CPU's (near child first, the same thick planes), so the same
            // counts but where f32 decides a plane differently from f64.
            let near = |a: u64, b: u64| a.abs_diff(b) as f64 <= 0.01 * b as f64;
            assert!(
                near(gw.nodes, cw.nodes) && near(gw.primitives, cw.primitives),
                "{}: {gw:?} vs {cw:?}",
                r.name
            );
        }
    }
    gpu.count_work(false);
}
