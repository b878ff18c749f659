//! Shapes in any order: object ids and per-mesh albedo when shapes are not in sphere/plane/mesh
//! order, ties between shapes, CPU/GPU agreement, the accelerator name in scene files, the exact
//! reference with meshes, transformed scenes, the GPU's static-buffer and pipeline caches across
//! scenes with and without meshes, and the GPU's errors for buffers and structures.

use crate::common;

use glam::DVec3;
use penumbra::accel::AccelSettings;
use penumbra::experiment::sweep::reference::has_exact_answer;
use penumbra::mesh::Triangles;
use penumbra::reference::OnAxis;
use penumbra::render::cpu::CpuBackend;
use penumbra::render::{Backend, Frame, Sampling, View, NO_HIT};
use penumbra::sampling::{DiskScheme, Pattern};
use penumbra::scene::camera::{Camera, Projection};
use penumbra::scene::{Light, Mesh, Plane, Scene, Shape, Sphere};
use std::f64::consts::PI;

const SAMPLING: Sampling = Sampling {
    scheme: DiskScheme::Uniform,
    pattern: Pattern::PerPixel,
    seed: 3,
    frame: 0,
};

fn top_down(width: f64) -> Camera {
    Camera {
        position: DVec3::new(0.0, 0.0, 5.0),
        look_at: DVec3::ZERO,
        up: DVec3::Y,
        projection: Projection::Orthographic { width },
    }
}

fn quad(cx: f64, cy: f64, z: f64, h: f64) -> [[DVec3; 3]; 2] {
    let c = |x: f64, y: f64| DVec3::new(cx + x, cy + y, z);
    [[c(-h, -h), c(h, -h), c(h, h)], [c(-h, -h), c(h, h), c(-h, h)]]
}

fn mesh(albedo: f64, triangles: usize) -> Mesh {
    Mesh {
        source: "quad".into(),
        file_fnv1a: 0,
        albedo,
        mirror: 0.0,
        triangles,
        skipped: Default::default(),
    }
}

const POWER: f64 = 50.0;
const LIGHT: DVec3 = DVec3::new(0.0, 0.0, 4.0);

/// Shapes in the order [plane, sphere, mesh A, mesh B, sphere]: ids 0..5, none in the
/// sphere/plane/mesh order the loader produces.
fn out_of_order() -> Scene {
    let ground = Plane {
        point: DVec3::ZERO,
        normal: DVec3::Z,
        albedo: 0.3,
    };
    let mut s = Scene::analytic(
        vec![],
        vec![ground],
        vec![Light::Point {
            position: LIGHT,
            power: POWER,
        }],
    );
    s.shapes.push(Shape::Sphere(Sphere {
        center: DVec3::new(-1.0, -1.0, 0.5),
        radius: 0.4,
        albedo: 0.6,
    }));
    let mut positions = quad(1.0, -1.0, 1.0, 0.4).to_vec();
    positions.extend(quad(1.0, 1.0, 1.5, 0.4));
    let triangles = Triangles {
        positions,
        object_of: vec![0, 0, 1, 1],
    };
    let mut s = s.with_meshes(vec![mesh(0.2, 2), mesh(0.9, 2)], triangles, AccelSettings::default());
    s.shapes.push(Shape::Sphere(Sphere {
        center: DVec3::new(-1.0, 1.0, 0.5),
        radius: 0.4,
        albedo: 0.45,
    }));
    s
}

/// (expected object id, expected albedo and shading point) under the ray origin (x, y) of a
/// top-down orthographic pixel, or None near an edge.
fn expected(x: f64, y: f64) -> Option<(u32, f64, DVec3)> {
    let inside = |cx: f64, cy: f64, h: f64| (x - cx).abs() < h && (y - cy).abs() < h;
    let near = |cx: f64, cy: f64, _r: f64| ((x - cx).powi(2) + (y - cy).powi(2)).sqrt();
    if inside(1.0, -1.0, 0.35) {
        Some((2, 0.2, DVec3::new(x, y, 1.0)))
    } else if inside(1.0, 1.0, 0.35) {
        Some((3, 0.9, DVec3::new(x, y, 1.5)))
    } else if near(-1.0, -1.0, 0.4) < 0.35 {
        Some((1, 0.6, DVec3::NAN))
    } else if near(-1.0, 1.0, 0.4) < 0.35 {
        Some((4, 0.45, DVec3::NAN))
    } else if [(1.0, -1.0), (1.0, 1.0)].iter().all(|&(cx, cy)| !inside(cx, cy, 0.45))
        && [(-1.0, -1.0), (-1.0, 1.0)]
            .iter()
            .all(|&(cx, cy)| near(cx, cy, 0.4) > 0.45)
    {
        Some((0, 0.3, DVec3::new(x, y, 0.0)))
    } else {
        None
    }
}

fn check_out_of_order(name: &str, f: &Frame, cam: &Camera, n: u32) {
    let mut seen = [0u32; 5];
    for i in 0..(n * n) as usize {
        let o = cam.ray(i as u32 % n, i as u32 / n, n, n).origin;
        let Some((id, albedo, p)) = expected(o.x, o.y) else {
            continue;
        };
        assert_eq!(f.hit[i], id, "{name}: pixel {i} at ({}, {})", o.x, o.y);
        seen[id as usize] += 1;
        // Lit, upward-facing flat receivers (meshes, ground outside every shadow): radiance
        // from the point light by hand, with each mesh's own albedo.
        if p.is_finite() && id != 0 {
            let d = LIGHT - p;
            let e = POWER / (4.0 * PI) * d.normalize().z / d.length_squared();
            let want = albedo / PI * e;
            let got = f.radiance[i] as f64;
            assert!(
                (got - want).abs() < 1e-4 * want,
                "{name}: pixel {i} (object {id}): {got} vs {want}"
            );
        }
    }
    assert!(seen.iter().all(|&c| c > 4), "{name}: every object seen: {seen:?}");
}

/// Object ids and per-mesh albedo with the shapes out of kind order, on both backends, checked
/// against the scene's geometry rather than against each other.
#[test]
fn ids_and_albedo_follow_the_shape_list_on_both_backends() {
    let s = out_of_order();
    let cam = top_down(4.0);
    let n = 48;
    let view = View {
        camera: &cam,
        width: n,
        height: n,
    };
    let cpu = CpuBackend::default().render(&s, view, SAMPLING).unwrap();
    check_out_of_order("cpu", &cpu, &cam, n);
    if let Some(mut g) = common::gpu() {
        let gpu = g.render(&s, view, SAMPLING).unwrap();
        check_out_of_order("gpu", &gpu, &cam, n);
        let differ = gpu.hit.iter().zip(&cpu.hit).filter(|(a, b)| a != b).count();
        assert!(differ <= 4, "{differ} pixels hit different objects");
    }
}

/// A plane listed before a sphere that touches it from below: the camera ray down the axis meets
/// both at exactly t = 5 (exact in f64 and, in the GPU's local frame, in f32). The CPU breaks
/// the tie by id ("the first of equal distances wins"): the plane, id 0. The GPU must agree.
#[test]
fn a_tie_between_a_plane_listed_first_and_a_sphere_goes_to_the_same_object() {
    let plane = Plane {
        point: DVec3::ZERO,
        normal: DVec3::Z,
        albedo: 0.3,
    };
    let mut s = Scene::analytic(vec![], vec![plane], vec![]);
    s.shapes.push(Shape::Sphere(Sphere {
        center: DVec3::new(0.0, 0.0, -1.0),
        radius: 1.0,
        albedo: 0.7,
    }));
    let cam = top_down(1.0);
    let view = View {
        camera: &cam,
        width: 1,
        height: 1,
    };
    let cpu = CpuBackend::default().render(&s, view, SAMPLING).unwrap();
    assert_eq!(cpu.hit[0], 0, "cpu: the first of equal distances, the plane");
    let Some(mut g) = common::gpu() else { return };
    let gpu = g.render(&s, view, SAMPLING).unwrap();
    assert_eq!(gpu.hit[0], cpu.hit[0], "gpu and cpu pick different objects on a tie");
}

/// `accelerator = "..."` naming no registered structure: an error located at the key.
#[test]
fn an_unknown_accelerator_is_a_located_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.toml");
    std::fs::write(
        &path,
        "accelerator = \"octree\"\n\n[accel.bvh]\npreset = \"medium\"\n\n[cameras.c]\nprojection = \"orthographic\"\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nwidth = 4\n",
    )
    .unwrap();
    let e = Scene::load(&path).unwrap_err();
    let text = e.to_string();
    assert!(text.contains("s.toml:1:"), "{text}");
    assert!(text.contains("key `accelerator`"), "{text}");
    assert!(text.contains("octree") && text.contains("kdtree"), "{text}");
}

/// The exact answer exists without triangles (a mesh whose triangles were all dropped counts as
/// none), and not with them; nor does the on-axis closed form, which knows nothing of a mesh's
/// shadow, even one far from the measured area.
#[test]
fn exact_reference_and_on_axis_with_meshes() {
    let base = Scene::load(&common::repo("experiments/scenes/sphere.toml")).unwrap();
    assert!(has_exact_answer(&base));
    let on_axis = OnAxis::detect(&base, 0, 0);
    assert!(on_axis.is_some());
    let empty = base
        .clone()
        .with_meshes(vec![mesh(0.5, 0)], Triangles::default(), AccelSettings::default());
    assert!(empty.accel.is_none());
    assert!(has_exact_answer(&empty), "a mesh with no triangles left");
    assert_eq!(OnAxis::detect(&empty, 0, 0).is_some(), on_axis.is_some());
    let far = Triangles {
        positions: quad(50.0, 50.0, 0.5, 0.1).to_vec(),
        object_of: vec![0, 0],
    };
    let with = base
        .clone()
        .with_meshes(vec![mesh(0.5, 2)], far, AccelSettings::default());
    assert!(!has_exact_answer(&with), "no closed form covers triangles");
    assert!(
        OnAxis::detect(&with, 0, 0).is_none(),
        "the closed form ignores triangles"
    );
}

/// Translating or scaling keeps every triangle's owner and rebuilds the structure over the
/// moved triangles; the moved scene renders the same object ids.
#[test]
fn transformed_scenes_keep_owners_and_rebuild_the_structure() {
    let s = out_of_order();
    let cam0 = top_down(4.0);
    let view0 = View {
        camera: &cam0,
        width: 24,
        height: 24,
    };
    let orig = CpuBackend::default().render(&s, view0, SAMPLING).unwrap();
    let offset = DVec3::new(1e4, -3e3, 7.0);
    let moved_cam = Camera {
        position: cam0.position + offset,
        look_at: cam0.look_at + offset,
        ..cam0.clone()
    };
    let scaled_cam = Camera {
        position: cam0.position * 1e-3,
        look_at: cam0.look_at * 1e-3,
        projection: Projection::Orthographic { width: 4e-3 },
        ..cam0.clone()
    };
    type Case = (Scene, Camera, Box<dyn Fn(DVec3) -> DVec3>);
    let cases: [Case; 2] = [
        (s.translated(offset), moved_cam, Box::new(move |p| p + offset)),
        (s.scaled(1e-3), scaled_cam, Box::new(|p| p * 1e-3)),
    ];
    for (t, cam, f) in cases {
        assert_eq!(t.triangles.object_of, s.triangles.object_of);
        let a = t.accel.as_ref().unwrap();
        for (i, tri) in s.triangles.positions.iter().enumerate() {
            let c = (tri[0] + tri[1] * 2.0 + tri[2]) / 4.0;
            let h = a
                .closest(f(c + DVec3::Z * 3.0), DVec3::NEG_Z, f64::INFINITY, NO_HIT)
                .unwrap();
            assert_eq!(h.triangle as usize, i);
        }
        let view = View { camera: &cam, ..view0 };
        let moved = CpuBackend::default().render(&t, view, SAMPLING).unwrap();
        let differ = moved.hit.iter().zip(&orig.hit).filter(|(a, b)| a != b).count();
        assert!(differ <= 2, "{differ} pixels changed object");
    }
}

/// Switching between scenes with and without meshes on one GPU backend: each switch uploads,
/// the pipelines of each structure are reused, and every frame is what it was the first time.
#[test]
fn gpu_switches_between_scenes_with_and_without_meshes() {
    let Some(mut g) = common::gpu() else { return };
    let meshed = out_of_order();
    let mut plain = out_of_order();
    plain.shapes.truncate(2);
    plain.triangles = Triangles::default();
    let plain = plain.with_accelerator(AccelSettings::default());
    assert!(plain.accel.is_none());
    let cam = top_down(4.0);
    let view = View {
        camera: &cam,
        width: 24,
        height: 24,
    };
    let start = g.static_uploads();
    let a1 = g.render(&meshed, view, SAMPLING).unwrap();
    let b1 = g.render(&plain, view, SAMPLING).unwrap();
    let a2 = g.render(&meshed, view, SAMPLING).unwrap();
    let b2 = g.render(&plain, view, SAMPLING).unwrap();
    assert_eq!(g.static_uploads(), start + 4);
    assert_eq!(a1.hit, a2.hit);
    assert_eq!(a1.radiance, a2.radiance);
    assert_eq!(b1.hit, b2.hit);
    assert_eq!(b1.radiance, b2.radiance);
    assert!(a1.hit.contains(&2) && a1.hit.contains(&3));
    assert!(!b1.hit.contains(&2) && !b1.hit.contains(&3));
}

/// Buffer-limit errors name the buffer once ("a hit buffer of N bytes").
#[test]
fn a_buffer_over_the_limit_is_named() {
    let Some(mut g) = common::gpu() else { return };
    let s = out_of_order();
    let cam = top_down(4.0);
    let view = View {
        camera: &cam,
        width: 1 << 14,
        height: 1 << 14,
    };
    let e = g.render(&s, view, SAMPLING).unwrap_err().to_string();
    assert!(e.contains("hit buffer of"), "{e}");
    assert!(!e.contains("buffer buffer"), "{e}");
}

/// A structure whose `Accelerator::name` is not a registry name (the two are written
/// separately): the GPU must refuse with a message naming the structure, not render without it.
#[derive(Debug)]
struct Renamed(std::sync::Arc<dyn penumbra::accel::Accelerator>);

impl penumbra::accel::Accelerator for Renamed {
    fn name(&self) -> &'static str {
        "bvh-renamed"
    }
    fn closest(&self, o: DVec3, d: DVec3, tmax: f64, skip: u32) -> Option<penumbra::accel::TriHit> {
        self.0.closest(o, d, tmax, skip)
    }
    fn any_hit(&self, o: DVec3, d: DVec3, tmax: f64, skip: u32) -> bool {
        self.0.any_hit(o, d, tmax, skip)
    }
    fn stats(&self) -> penumbra::accel::BuildStats {
        self.0.stats()
    }
    fn gpu(&self, frame: &penumbra::geometry::LocalFrame) -> anyhow::Result<penumbra::accel::GpuStructure> {
        self.0.gpu(frame)
    }
    fn update(
        &mut self,
        _: penumbra::accel::UpdateMethod,
        _: &penumbra::mesh::Triangles,
        _: u32,
        _: DVec3,
    ) -> anyhow::Result<penumbra::accel::Updated> {
        anyhow::bail!("a test double does not move")
    }
}

#[test]
fn a_structure_missing_from_the_registry_is_named_by_the_gpu() {
    let Some(mut g) = common::gpu() else { return };
    let mut s = out_of_order();
    s.accel = Some(std::sync::Arc::new(Renamed(s.accel.clone().unwrap())));
    let cam = top_down(4.0);
    let view = View {
        camera: &cam,
        width: 16,
        height: 16,
    };
    match g.render(&s, view, SAMPLING) {
        Ok(f) => assert!(f.hit.contains(&2), "the meshes vanished without an error"),
        Err(e) => assert!(format!("{e:#}").contains("not registered"), "{e:#}"),
    }
}

/// `has_exact_answer` must follow the triangles the scene actually holds, not the `triangles`
/// count written in each `Mesh` (with_meshes never checks one against the other).
#[test]
fn exact_answer_follows_the_scenes_triangles_not_the_mesh_metadata() {
    let base = Scene::load(&common::repo("experiments/scenes/sphere.toml")).unwrap();
    let over_the_receiver = Triangles {
        positions: quad(0.0, 0.0, 0.3, 0.5).to_vec(),
        object_of: vec![0, 0],
    };
    let s = base.with_meshes(vec![mesh(0.5, 0)], over_the_receiver, AccelSettings::default());
    assert!(s.accel.is_some());
    assert!(
        !has_exact_answer(&s),
        "a scene whose structure holds triangles has no exact answer"
    );
}
