//! The GPU backend against the f64 CPU backend on the same scene and sample streams, and the
//! WGSL samplers against the Rust ones.

use crate::common;

use penumbra::render::cpu::CpuBackend;
use penumbra::render::{Backend, Frame, Sampling, View};
use penumbra::sampling::{DiskScheme, Pattern};
use penumbra::scene::Scene;

fn compare(a: &Frame, b: &Frame) -> (f64, f64, usize) {
    let (mut sum, mut max, mut differing) = (0.0, 0.0f64, 0);
    for (va, vb) in a.visibility[0].iter().zip(&b.visibility[0]) {
        let d = (va - vb).abs() as f64;
        sum += d;
        max = max.max(d);
        differing += (d > 0.0) as usize;
    }
    (sum / a.visibility[0].len() as f64, max, differing)
}

/// GPU (f32) and CPU (f64) agree on the same sample pattern: the same object hit everywhere but
/// a handful of silhouette pixels, and visibility differing only where a shadow ray grazes the
/// sphere closely enough for f32 rounding to flip it (at most 1 ray in 16, in under 1 % of pixels).
/// A single frame and frame 3 of a temporal sequence alike: both draw frame f's samples.
#[test]
fn gpu_matches_cpu_on_the_sphere_scene() {
    let Some(mut gpu) = common::gpu() else { return };
    let scene = Scene::load(&common::repo("experiments/scenes/sphere.toml")).unwrap();
    for (camera, frame) in [("measure", 0), ("picture", 0), ("measure", 3)] {
        for (scheme, pattern) in [
            (DiskScheme::Uniform, Pattern::PerPixel),
            (DiskScheme::Paper, Pattern::Shared),
            (DiskScheme::Sobol, Pattern::PerPixel),
            (DiskScheme::Pmj02, Pattern::PerPixel),
            (DiskScheme::BluenoiseCp, Pattern::PerPixel),
            (DiskScheme::SobolBluenoise, Pattern::PerPixel),
            (DiskScheme::StbnCp, Pattern::PerPixel),
            (DiskScheme::SobolBluenoiseT, Pattern::PerPixel),
        ] {
            let view = View {
                camera: &scene.cameras[camera],
                width: 96,
                height: 72,
            };
            let s = Sampling {
                scheme,
                pattern,
                seed: 11,
                frame,
            };
            let g = gpu.render(&scene, view, s).unwrap();
            let c = CpuBackend::default().render(&scene, view, s).unwrap();
            let hit_diff = g.hit.iter().zip(&c.hit).filter(|(a, b)| a != b).count();
            assert!(
                hit_diff <= 4,
                "{camera} frame {frame} {scheme}: {hit_diff} pixels hit different objects"
            );
            let (mean, max, differing) = compare(&g, &c);
            assert!(
                mean < 1e-3,
                "{camera} frame {frame} {scheme}/{pattern}: mean |dV| = {mean}"
            );
            assert!(
                max <= 1.0 / 16.0 + 1e-6,
                "{camera} frame {frame} {scheme}/{pattern}: max |dV| = {max}"
            );
            assert!(
                differing * 100 <= g.hit.len(),
                "{camera} frame {frame} {scheme}/{pattern}: {differing} pixels differ"
            );
            assert_eq!(g.rays.primary, c.rays.primary);
            let (gr, cr) = (g.rays.shadow_total() as f64, c.rays.shadow_total() as f64);
            assert!(
                (gr - cr).abs() <= 1e-3 * cr,
                "{camera} frame {frame}: shadow rays {gr} vs {cr}"
            );
            let lit: Vec<_> = (0..g.radiance.len()).filter(|&i| c.radiance[i] > 0.0).collect();
            let rel = lit
                .iter()
                .map(|&i| ((g.radiance[i] - c.radiance[i]) / c.radiance[i]).abs() as f64)
                .sum::<f64>()
                / lit.len() as f64;
            assert!(
                rel < 2e-3,
                "{camera} frame {frame}: mean relative radiance difference {rel}"
            );
        }
    }
}

/// The WGSL sampler returns the points the Rust sampler does, to f32 rounding, for every
/// scheme and several counts including n = 1 and n = 2, in frames 0, 1, 5 and 37 (past the STBN
/// masks' 32 slices, so stbn-cp wraps in time).
/// The tests that call the GPU's test hooks (here, in gpu_resources.rs, mesh_scene.rs and
/// accelerators.rs) exist only with the `test-hooks` feature, which scripts/test.sh enables:
/// without it this test fails rather than letting them vanish.
#[test]
#[cfg(not(feature = "test-hooks"))]
fn test_hooks_are_enabled() {
    panic!("run the tests with `--features test-hooks` (scripts/test.sh does)");
}

#[test]
#[cfg(feature = "test-hooks")]
fn wgsl_samplers_match_rust() {
    let Some(mut gpu) = common::gpu() else { return };
    for scheme in DiskScheme::ALL {
        for n in [1u32, 2, 3, 7, 16, 64, 257] {
            for frame in [0u32, 1, 5, 37] {
                let (seed, pixel) = (1234, 77);
                let g = gpu.disk_points_at(scheme, n, seed, pixel, frame).unwrap();
                let c = scheme.points(n, common::hook_site(seed, pixel, frame));
                assert_eq!(g.len(), c.len(), "{scheme} n={n}: one GPU point per sample");
                for (k, (a, b)) in g.iter().zip(&c).enumerate() {
                    let d = ((a[0] as f64 - b.x).powi(2) + (a[1] as f64 - b.y).powi(2)).sqrt();
                    assert!(d < 2e-6, "{scheme} n={n} frame {frame} k={k}: gpu {a:?} cpu {b}");
                }
            }
        }
    }
}
