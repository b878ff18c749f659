//! Hard cases stay numerically stable, on the CPU backend and (where an adapter exists) the GPU
//! backend: each case states its expected value and tolerance.

use crate::common;

use glam::DVec3;
use penumbra::reference::{visible_fraction, OnAxis};
use penumbra::render::cpu::CpuBackend;
use penumbra::render::{Backend, Frame, Sampling, View, NO_RECEIVER};
use penumbra::sampling::{DiskScheme, Pattern};
use penumbra::scene::camera::{Camera, Projection};
use penumbra::scene::{DiskLight, Light, Scene, Shape, Sphere};

fn sphere_scene() -> Scene {
    Scene::load(&common::repo("experiments/scenes/sphere.toml")).unwrap()
}

fn disk(scene: &mut Scene) -> &mut DiskLight {
    match &mut scene.lights[0] {
        Light::Disk(d) => d,
        Light::Point { .. } => unreachable!(),
    }
}

/// Runs `f` with the CPU backend, then with the GPU backend if there is one.
fn on_backends(f: impl Fn(&str, &mut dyn Backend)) {
    f("cpu", &mut CpuBackend::default());
    if let Some(mut g) = common::gpu() {
        f("gpu", &mut *g);
    }
}

fn render(b: &mut dyn Backend, scene: &Scene, camera: &Camera, size: u32, scheme: DiskScheme) -> Frame {
    let view = View {
        camera,
        width: size,
        height: size,
    };
    b.render(
        scene,
        view,
        Sampling {
            scheme,
            pattern: Pattern::PerPixel,
            seed: 5,
            frame: 0,
        },
    )
    .unwrap()
}

/// An orthographic 1x1 view whose single pixel centre is the ground point `p`.
fn probe(p: DVec3) -> Camera {
    Camera {
        position: p + DVec3::Z * 3.0,
        look_at: p,
        up: DVec3::Y,
        projection: Projection::Orthographic { width: 1e-4 },
    }
}

/// Per-pixel exact visibility of light 0 over the receiver pixels of a frame.
fn exact_of(scene: &Scene, camera: &Camera, size: u32, frame: &Frame) -> Vec<Option<f64>> {
    let Light::Disk(l) = &scene.lights[0] else {
        unreachable!()
    };
    let (plane_id, pl) = scene.plane(0).unwrap();
    let spheres: Vec<Sphere> = scene.spheres().copied().collect();
    (0..size * size)
        .map(|i| {
            (frame.hit[i as usize] == plane_id).then(|| {
                let r = camera.ray(i % size, i / size, size, size);
                let t = pl.t(r.origin, r.direction).unwrap();
                visible_fraction(r.origin + r.direction * t, pl.normal, l, &spheres, &[])
            })
        })
        .collect()
}

fn max_error(frame: &Frame, exact: &[Option<f64>]) -> f64 {
    exact
        .iter()
        .zip(&frame.visibility[0])
        .filter_map(|(e, v)| e.map(|e| (e - *v as f64).abs()))
        .fold(0.0, f64::max)
}

#[test]
fn vanishing_light_converges_to_the_point_light_shadow() {
    let mut small = sphere_scene();
    disk(&mut small).radius = 1e-7;
    let mut point = small.clone();
    point.lights[0] = Light::Point {
        position: disk(&mut small).center,
        power: 60.0,
    };
    let cam = small.cameras["measure"].clone();
    on_backends(|name, b| {
        let (a, p) = (
            render(b, &small, &cam, 64, DiskScheme::Uniform),
            render(b, &point, &cam, 64, DiskScheme::Uniform),
        );
        let differ = a.visibility[0]
            .iter()
            .zip(&p.visibility[0])
            .filter(|(x, y)| x != y)
            .count();
        // Only pixels within a hair (1e-7 m light -> ~2e-8 m penumbra) of the edge may differ.
        assert!(differ <= 2, "{name}: {differ} pixels differ from the hard shadow");
        assert!(p.visibility[0].iter().all(|v| *v == 0.0 || *v == 1.0));
    });
}

#[test]
fn light_much_larger_than_the_occluder_has_no_umbra() {
    let mut s = sphere_scene();
    disk(&mut s).radius = 2.0;
    disk(&mut s).samples = 1024;
    let o = OnAxis::detect(&s, 0, 0).unwrap();
    assert!(o.umbra_radius() < 0.0, "no umbra expected: r_u = {}", o.umbra_radius());
    let cam = Camera {
        position: DVec3::new(0.0, 0.0, 3.0),
        look_at: DVec3::ZERO,
        up: DVec3::Y,
        projection: Projection::Orthographic { width: 1.6 },
    };
    on_backends(|name, b| {
        let f = render(b, &s, &cam, 24, DiskScheme::Jittered);
        let exact = exact_of(&s, &cam, 24, &f);
        // 1024 jittered rays: the error is below 1/32 per pixel.
        let e = max_error(&f, &exact);
        assert!(e < 1.0 / 32.0, "{name}: max |V - exact| = {e}");
        assert!(
            f.visibility[0].iter().filter(|v| **v >= 0.0).all(|v| *v > 0.0),
            "{name}: some pixel is in umbra"
        );
    });
}

#[test]
fn light_inside_or_touching_the_sphere() {
    let mut inside = sphere_scene();
    disk(&mut inside).center = DVec3::new(0.0, 0.0, 0.6);
    let mut touching = sphere_scene();
    disk(&mut touching).center = DVec3::new(0.0, 0.0, 0.75);
    disk(&mut touching).samples = 1024;
    let cam = Camera {
        position: DVec3::new(0.2, 0.0, 3.0),
        look_at: DVec3::new(0.2, 0.0, 0.0),
        up: DVec3::Y,
        projection: Projection::Orthographic { width: 2.0 },
    };
    on_backends(|name, b| {
        let f = render(b, &inside, &cam, 16, DiskScheme::Uniform);
        assert!(
            f.visibility[0].iter().all(|v| *v == 0.0 || *v == NO_RECEIVER),
            "{name}: a light inside the sphere leaks"
        );
        let f = render(b, &touching, &cam, 16, DiskScheme::Jittered);
        let e = max_error(&f, &exact_of(&touching, &cam, 16, &f));
        assert!(e < 1.0 / 32.0, "{name}: touching light, max |V - exact| = {e}");
    });
}

#[test]
fn light_facing_away_gives_no_light_and_no_rays() {
    let mut s = sphere_scene();
    disk(&mut s).normal = DVec3::Z;
    let cam = s.cameras["picture"].clone();
    on_backends(|name, b| {
        let f = render(b, &s, &cam, 32, DiskScheme::Uniform);
        assert_eq!(f.rays.shadow_total(), 0, "{name}");
        assert!(f.visibility[0].iter().all(|v| *v == 0.0 || *v == NO_RECEIVER), "{name}");
        assert!(f.radiance.iter().all(|v| *v == 0.0), "{name}");
    });
}

#[test]
fn contact_shadow_of_a_sphere_resting_on_the_plane() {
    let mut s = sphere_scene();
    let sphere = s.spheres_mut().next().unwrap();
    sphere.center.z = sphere.radius;
    disk(&mut s).samples = 1024;
    // A patch around the contact point, seen from above at a slant so the sphere hides little.
    let cam = Camera {
        position: DVec3::new(0.3, 0.0, 3.0),
        look_at: DVec3::new(0.3, 0.0, 0.0),
        up: DVec3::Y,
        projection: Projection::Orthographic { width: 0.2 },
    };
    on_backends(|name, b| {
        let f = render(b, &s, &cam, 24, DiskScheme::Jittered);
        let exact = exact_of(&s, &cam, 24, &f);
        assert!(
            exact.iter().flatten().count() > 100,
            "{name}: the patch must show the ground"
        );
        let e = max_error(&f, &exact);
        assert!(e < 1.0 / 32.0, "{name}: contact shadow max |V - exact| = {e}");
    });
}

#[test]
fn receivers_exactly_on_the_umbra_and_penumbra_radii() {
    let mut s = sphere_scene();
    disk(&mut s).samples = 4096;
    let o = OnAxis::detect(&s, 0, 0).unwrap();
    let Light::Disk(l) = s.lights[0].clone() else {
        unreachable!()
    };
    for (r, expected) in [(o.umbra_radius(), 0.0), (o.penumbra_radius(), 1.0)] {
        let p = o.point_at(r);
        let v = visible_fraction(p, DVec3::Z, &l, &s.spheres().copied().collect::<Vec<_>>(), &[]);
        assert!((v - expected).abs() < 1e-9, "exact V at r = {r}: {v}");
        let cam = probe(p);
        on_backends(|name, b| {
            let f = render(b, &s, &cam, 1, DiskScheme::Jittered);
            // One stratum of 64 x 64 may straddle the tangency: 1/4096 per ray, a few rays.
            assert!(
                (f.visibility[0][0] as f64 - expected).abs() <= 4.0 / 4096.0,
                "{name}: V at r = {r}: {}",
                f.visibility[0][0]
            );
        });
    }
}

#[test]
fn grazing_light_and_grazing_camera_rays() {
    // A vertical light centred on the receiver's horizon: exactly half of it is above.
    let mut s = sphere_scene();
    s.shapes.retain(|x| !matches!(x, Shape::Sphere(_)));
    *disk(&mut s) = DiskLight {
        center: DVec3::new(3.0, 0.0, 0.0),
        normal: DVec3::NEG_X,
        radius: 0.3,
        power: 10.0,
        samples: 4096,
    };
    let cam = probe(DVec3::ZERO);
    on_backends(|name, b| {
        let f = render(b, &s, &cam, 1, DiskScheme::Jittered);
        // The horizon cuts 64 strata of 4096: at most 64 rays off, well under 1/64.
        assert!(
            (f.visibility[0][0] - 0.5).abs() < 1.0 / 64.0,
            "{name}: V = {}",
            f.visibility[0][0]
        );
    });
    // Camera rays at grazing incidence on an unoccluded plane: no self-shadowing anywhere.
    let mut g = sphere_scene();
    g.shapes.retain(|x| !matches!(x, Shape::Sphere(_)));
    let low = Camera {
        position: DVec3::new(-5.0, 0.0, 1e-3),
        look_at: DVec3::new(10.0, 0.0, 0.0),
        up: DVec3::Z,
        projection: Projection::Perspective { fov_y_deg: 1.0 },
    };
    on_backends(|name, b| {
        let f = render(b, &g, &low, 32, DiskScheme::Uniform);
        let receivers: Vec<f32> = f.visibility[0].iter().copied().filter(|v| *v != NO_RECEIVER).collect();
        assert!(receivers.len() > 100, "{name}");
        assert!(
            receivers.iter().all(|v| *v == 1.0),
            "{name}: grazing receivers self-shadow"
        );
    });
}

/// Translating the scene by 1e4 or 1e5 m, or scaling it by 1e-3 or 1e3, leaves the visibility
/// image unchanged: at most 1 % of pixels change, by at most one ray in 16 (a shadow ray grazing
/// the silhouette can flip), and the mean change stays under 1e-3.
#[test]
fn translated_and_scaled_scenes_give_the_same_image() {
    let base = sphere_scene();
    let variants = [
        ("+1e4 m", base.translated(DVec3::new(1e4, -1e4, 1e4))),
        ("+1e5 m", base.translated(DVec3::new(1e5, 1e5, -1e5))),
        ("x1e-3", base.scaled(1e-3)),
        ("x1e3", base.scaled(1e3)),
    ];
    on_backends(|name, b| {
        let reference = render(b, &base, &base.cameras["measure"], 64, DiskScheme::Uniform);
        for (what, s) in &variants {
            let f = render(b, s, &s.cameras["measure"], 64, DiskScheme::Uniform);
            let diffs: Vec<f64> = f.visibility[0]
                .iter()
                .zip(&reference.visibility[0])
                .map(|(a, b)| (a - b).abs() as f64)
                .collect();
            let changed = diffs.iter().filter(|d| **d > 0.0).count();
            let max = diffs.iter().copied().fold(0.0, f64::max);
            let mean = diffs.iter().sum::<f64>() / diffs.len() as f64;
            assert!(
                changed * 100 <= diffs.len() && max <= 1.0 / 16.0 + 1e-6 && mean < 1e-3,
                "{name} {what}: {changed} pixels changed, max {max}, mean {mean}"
            );
        }
    });
}

/// n = 1, 2, 3 and 4096 rays: defined on every scheme, GPU and CPU agreeing, and 4096 jittered
/// rays within 1/64 of the exact answer everywhere.
#[test]
fn extreme_ray_counts() {
    let cam = sphere_scene().cameras["measure"].clone();
    for n in [1u32, 2, 3] {
        let mut s = sphere_scene();
        disk(&mut s).samples = n;
        for scheme in DiskScheme::ALL {
            let c = render(&mut CpuBackend::default(), &s, &cam, 32, scheme);
            assert!(c.visibility[0].iter().all(|v| (0.0..=1.0).contains(v)));
            if let Some(mut g) = common::gpu() {
                let f = render(&mut *g, &s, &cam, 32, scheme);
                let differ = f.visibility[0]
                    .iter()
                    .zip(&c.visibility[0])
                    .filter(|(a, b)| a != b)
                    .count();
                assert!(
                    differ <= 10,
                    "{scheme} n={n}: {differ} pixels differ between GPU and CPU"
                );
            }
        }
    }
    let mut s = sphere_scene();
    disk(&mut s).samples = 4096;
    on_backends(|name, b| {
        let f = render(b, &s, &cam, 24, DiskScheme::Jittered);
        let e = max_error(&f, &exact_of(&s, &cam, 24, &f));
        assert!(e < 1.0 / 64.0, "{name}: 4096 jittered rays, max |V - exact| = {e}");
    });
}
