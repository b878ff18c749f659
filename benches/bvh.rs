//! BVH build per obvhs preset and CPU traversal (closest hit for camera rays, any hit for
//! shadow rays) on the dressed-body mesh, so that later changes can be compared:
//! `cargo bench --bench bvh`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;
use penumbra::accel::{Bvh, Preset};
use penumbra::sampling::Stream;
use penumbra::scene::Scene;
use std::hint::black_box;
use std::path::Path;

fn body() -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/scenes/body.toml")).expect("body scene")
}

fn rays(bvh: &Bvh, n: u32) -> Vec<(DVec3, DVec3)> {
    let s = Stream::new(7, 0, None);
    let target = |k: u32| bvh.world[(s.u32(3 * k) as usize) % bvh.world.len()][0];
    (0..n)
        .map(|k| {
            let o = DVec3::new(s.unit(3 * k + 1) * 4.0 - 2.0, -3.0, s.unit(3 * k + 2) * 2.0 + 0.2);
            (o, (target(k) - o).normalize())
        })
        .collect()
}

fn build(c: &mut Criterion) {
    let scene = body();
    let triangles = scene.triangles.clone();
    let mut g = c.benchmark_group("bvh_build");
    g.sample_size(10);
    g.throughput(Throughput::Elements(triangles.positions.len() as u64));
    for preset in Preset::ALL {
        g.bench_function(preset.name(), |b| b.iter(|| Bvh::build(black_box(&triangles), preset)));
    }
}

fn traverse(c: &mut Criterion) {
    let scene = body();
    let bvh = Bvh::build(
        &scene.triangles,
        scene.accel_settings.typed::<penumbra::accel::bvh::BvhSettings>().preset,
    );
    let rays = rays(&bvh, 4096);
    let mut g = c.benchmark_group("bvh_traverse");
    g.throughput(Throughput::Elements(rays.len() as u64));
    g.bench_function("closest", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|(o, d)| bvh.closest(*o, *d, f64::INFINITY, u32::MAX).is_some())
                .count()
        })
    });
    g.bench_function("any", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|(o, d)| bvh.any_hit(*o, *d, f64::INFINITY, u32::MAX))
                .count()
        })
    });
}

criterion_group!(benches, build, traverse);
criterion_main!(benches);
