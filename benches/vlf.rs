//! Visibility field (`accel::vlf`) build and single-thread traversal against the BVH on the
//! dressed-body mesh (32K triangles): ambient-occlusion rays along the stored directions (the
//! paper's Section 7 set-up: every line oriented into the normal's hemisphere, length 4 ball
//! radii, skipping the start triangle), any-hit and closest-hit; `cargo bench --bench vlf`.
//! The build is timed once per split kind (it is seconds, not milliseconds) and its memory is
//! printed from the structure's own `stats()`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;
use penumbra::accel::vlf::{Split, VisibilityField, VlfSettings};
use penumbra::accel::{Accelerator, Bvh, Preset};
use penumbra::sampling::Stream;
use penumbra::scene::Scene;
use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

fn body() -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/scenes/body.toml")).expect("body scene")
}

/// `points` seeded points on the mesh, each with every stored direction oriented into its
/// triangle's front hemisphere: (origin, direction, tmax, skip).
fn ao_rays(field: &VisibilityField, points: u32) -> Vec<(DVec3, DVec3, f64, u32)> {
    let s = Stream::new(11, 0, None);
    let w = &field.world;
    let len = 4.0 * field.frame.radius;
    let dirs = &field.frame.directions;
    let mut out = Vec::new();
    for k in 0..points {
        let i = s.u32(3 * k) as usize % w.len();
        let (mut a, mut b) = (s.unit(3 * k + 1), s.unit(3 * k + 2));
        if a + b > 1.0 {
            (a, b) = (1.0 - a, 1.0 - b);
        }
        let t = &w[i];
        let p = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b;
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        for j in 0..dirs.len() as u32 {
            let d = dirs.direction(j);
            out.push((p, if d.dot(n) >= 0.0 { d } else { -d }, len, i as u32));
        }
    }
    out
}

fn settings(split: Split) -> VlfSettings {
    VlfSettings {
        split,
        ..VlfSettings::default()
    }
}

fn traverse(c: &mut Criterion) {
    let scene = body();
    let bvh = Bvh::build(&scene.triangles, Preset::Medium);
    let configs = [
        ("uniform_d4", settings(Split::Uniform)),
        ("median_d4", settings(Split::Median)),
        (
            "uniform_d2",
            VlfSettings {
                depth: 2,
                ..settings(Split::Uniform)
            },
        ),
    ];
    for (k, (name, config)) in configs.into_iter().enumerate() {
        let start = Instant::now();
        let field = VisibilityField::build(&scene.triangles, config).unwrap();
        eprintln!(
            "build {:.2} s: {}",
            start.elapsed().as_secs_f64(),
            field.stats().description
        );
        let rays = ao_rays(&field, 64);
        let hits = rays.iter().filter(|r| bvh.any_hit(r.0, r.1, r.2, r.3)).count();
        eprintln!(
            "{} AO rays, {:.1} % occluded",
            rays.len(),
            100.0 * hits as f64 / rays.len() as f64
        );
        let mut g = c.benchmark_group(format!("vlf_ao_{name}"));
        g.throughput(Throughput::Elements(rays.len() as u64));
        g.sample_size(10);
        g.bench_function("vlf_any", |b| {
            b.iter(|| rays.iter().filter(|r| field.any_hit(r.0, r.1, r.2, r.3)).count())
        });
        g.bench_function("vlf_closest", |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| field.closest(r.0, r.1, r.2, r.3).is_some())
                    .count()
            })
        });
        if k == 0 {
            g.bench_function("bvh_any", |b| {
                b.iter(|| rays.iter().filter(|r| bvh.any_hit(r.0, r.1, r.2, r.3)).count())
            });
            g.bench_function("bvh_closest", |b| {
                b.iter(|| {
                    rays.iter()
                        .filter(|r| bvh.closest(r.0, r.1, r.2, r.3).is_some())
                        .count()
                })
            });
        }
        g.finish();
    }
}

fn build(c: &mut Criterion) {
    let scene = body();
    let mut g = c.benchmark_group("vlf_build");
    g.sample_size(10);
    g.throughput(Throughput::Elements(scene.triangles.positions.len() as u64));
    g.bench_function("uniform_default", |b| {
        b.iter(|| VisibilityField::build(black_box(&scene.triangles), settings(Split::Uniform)).unwrap())
    });
    g.bench_function("bvh_medium", |b| {
        b.iter(|| Bvh::build(black_box(&scene.triangles), Preset::Medium))
    });
}

/// Dynamic updates on the body: a 512-triangle object (a folded sheet beside the figure) moved
/// back and forth, and removed and inserted again, against the full build timed above.
fn dynamic(c: &mut Criterion) {
    let scene = body();
    let mut field = VisibilityField::build(&scene.triangles, settings(Split::Uniform)).unwrap();
    let c0 = field.frame.centre + DVec3::new(0.25, -0.1, 0.0) * field.frame.radius;
    let h = 0.1 * field.frame.radius / 16.0;
    let mut sheet = Vec::new();
    for i in 0..16 {
        for j in 0..16 {
            let p = |a: f64, b: f64| c0 + DVec3::new(a * h, b * h, 0.3 * h * (a * 0.7).sin());
            let (a, b) = (i as f64, j as f64);
            sheet.push([p(a, b), p(a + 1.0, b), p(a + 1.0, b + 1.0)]);
            sheet.push([p(a, b), p(a + 1.0, b + 1.0), p(a, b + 1.0)]);
        }
    }
    field.insert_object(1000, &sheet).unwrap();
    let mut g = c.benchmark_group("vlf_dynamic");
    g.sample_size(10);
    let mut sign = 1.0;
    g.bench_function("move_512", |b| {
        b.iter(|| {
            sign = -sign;
            field
                .move_object(1000, |p| p + DVec3::new(0.0, 0.0, sign * 1e-3))
                .unwrap()
        })
    });
    g.bench_function("remove_insert_512", |b| {
        b.iter(|| {
            field.remove_object(1000).unwrap();
            field.insert_object(1000, &sheet).unwrap()
        })
    });
}

criterion_group!(benches, traverse, build, dynamic);
criterion_main!(benches);
