//! Regression thresholds: runs experiments/ci.toml (small, a few seconds on lavapipe) and checks
//! the committed bounds in experiments/ci-thresholds.toml. Times are recorded, never asserted.

mod common;

use penumbra::experiment::{run_sweep, Spec};
use penumbra::metrics::stats::mean_ci;
use penumbra::render::open_backend;
use penumbra::report::summary::{find, summarise};
use penumbra::sampling::{DiskScheme, Pattern};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Thresholds {
    ground_truth: GroundTruth,
    unbiased: Unbiased,
    paper: Paper,
    convergence: Convergence,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GroundTruth {
    max_abs_error: f64,
    max_rmse: f64,
    max_abs_bias: f64,
    extent_tolerance_pixels: f64,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Unbiased {
    schemes: Vec<DiskScheme>,
    max_bias_sigmas: f64,
    bias_floor: f64,
    min_samples: u32,
    width_10_90_tolerance: f64,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Paper {
    min_width_10_90_excess: f64,
    max_width_10_90_excess: f64,
}
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Convergence {
    uniform_rmse_ratio_4_to_64: f64,
    sobol_over_uniform_rmse_at_16: f64,
}

#[test]
fn ci_experiment_stays_within_thresholds() {
    // Hold the shared GPU (if any) so no other test in this binary uses it concurrently.
    let _gpu = common::gpu();
    let spec = Spec::load(&common::repo("experiments/ci.toml")).unwrap();
    let t: Thresholds =
        toml::from_str(&std::fs::read_to_string(common::repo("experiments/ci-thresholds.toml")).unwrap()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut backend = open_backend(spec.backend).unwrap();
    let out = run_sweep(
        &spec,
        backend.as_mut(),
        &dir.path().join("journal"),
        &dir.path().join("cache"),
        true,
    )
    .unwrap();
    assert_eq!(out.failures, 0);
    let mut failures = Vec::new();
    let mut check = |ok: bool, what: String| {
        eprintln!("{} {what}", if ok { "ok  " } else { "FAIL" });
        if !ok {
            failures.push(what);
        }
    };

    for r in &out.references {
        let (gt_max, gt) = (r.gt_max_abs_all.unwrap(), r.gt_vs_exact.unwrap());
        check(
            gt_max <= t.ground_truth.max_abs_error,
            format!(
                "r={}: ground truth max |GT - exact| = {:.2e} <= {}",
                r.light_radius, gt_max, t.ground_truth.max_abs_error
            ),
        );
        check(
            gt.rmse <= t.ground_truth.max_rmse,
            format!(
                "r={}: ground truth RMSE vs exact = {:.2e} <= {}",
                r.light_radius, gt.rmse, t.ground_truth.max_rmse
            ),
        );
        check(
            gt.bias.abs() <= t.ground_truth.max_abs_bias,
            format!(
                "r={}: ground truth mean (GT - exact) = {:+.2e}, |.| <= {}",
                r.light_radius, gt.bias, t.ground_truth.max_abs_bias
            ),
        );
        let o = r.on_axis.as_ref().expect("the CI scene is on-axis");
        let (inner, outer) = r.gt_profile.as_ref().unwrap().extent();
        let tol = t.ground_truth.extent_tolerance_pixels * r.receivers.bin_width;
        check(
            (inner - o.umbra_radius()).abs() <= tol && (outer - o.penumbra_radius()).abs() <= tol,
            format!(
                "r={}: ground-truth extent [{inner:.5}, {outer:.5}] vs closed form [{:.5}, {:.5}] within {tol:.2e}",
                r.light_radius,
                o.umbra_radius(),
                o.penumbra_radius()
            ),
        );
    }

    let summaries = summarise(&out);
    let radius = spec.axes.light_radii[0];
    for &scheme in &t.unbiased.schemes {
        for pattern in [Pattern::PerPixel] {
            for &n in spec.axes.samples.iter().filter(|&&n| n >= t.unbiased.min_samples) {
                let biases: Vec<f64> = out
                    .records
                    .iter()
                    .filter(|r| {
                        r.get("scheme") == scheme.name()
                            && r.get("pattern") == pattern.name()
                            && r.num("samples") == n as f64
                    })
                    .map(|r| r.num("profile_bias"))
                    .collect();
                let (mean, ci) = mean_ci(&biases);
                let se = ci / penumbra::metrics::stats::t975(biases.len() - 1);
                let bound = t.unbiased.max_bias_sigmas * se + t.unbiased.bias_floor;
                check(
                    mean.abs() <= bound,
                    format!("{scheme} ({pattern}) n={n}: mean profile bias {mean:+.2e} within {bound:.2e}"),
                );
                let s = find(&summaries, scheme, pattern, n, radius, 1).unwrap();
                let rel = s.mean("width_10_90") / s.exact_width_10_90 - 1.0;
                check(
                    rel.abs() <= t.unbiased.width_10_90_tolerance,
                    format!(
                        "{scheme} ({pattern}) n={n}: 10-90 width {rel:+.3} relative to exact, within {}",
                        t.unbiased.width_10_90_tolerance
                    ),
                );
            }
        }
    }
    for &n in spec.axes.samples.iter().filter(|&&n| n >= 16) {
        let s = find(&summaries, DiskScheme::Paper, Pattern::PerPixel, n, radius, 1).unwrap();
        let excess = s.mean("width_10_90") / s.exact_width_10_90 - 1.0;
        check(
            excess >= t.paper.min_width_10_90_excess && excess <= t.paper.max_width_10_90_excess,
            format!(
                "paper (per-pixel) n={n}: 10-90 width excess {excess:+.3} in [{}, {}]",
                t.paper.min_width_10_90_excess, t.paper.max_width_10_90_excess
            ),
        );
    }
    let rmse = |s: DiskScheme, n: u32| {
        find(&summaries, s, Pattern::PerPixel, n, radius, 1)
            .unwrap()
            .mean("rmse")
    };
    let ratio = rmse(DiskScheme::Uniform, 64) / rmse(DiskScheme::Uniform, 4);
    check(
        ratio <= t.convergence.uniform_rmse_ratio_4_to_64,
        format!(
            "uniform RMSE(64)/RMSE(4) = {ratio:.3} <= {}",
            t.convergence.uniform_rmse_ratio_4_to_64
        ),
    );
    let ratio = rmse(DiskScheme::Sobol, 16) / rmse(DiskScheme::Uniform, 16);
    check(
        ratio <= t.convergence.sobol_over_uniform_rmse_at_16,
        format!(
            "sobol/uniform RMSE at 16 = {ratio:.3} <= {}",
            t.convergence.sobol_over_uniform_rmse_at_16
        ),
    );

    assert!(failures.is_empty(), "thresholds crossed:\n{}", failures.join("\n"));
}
