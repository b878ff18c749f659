//! The summary and the verdict, checked against values recomputed by hand from the runs of small
//! CPU sweeps: means and Student-t intervals over seeds, the exact MSE = bias^2 + variance
//! identity through the whole pipeline, and a verdict that never claims what its seeds cannot
//! support and never prints NaN.

use crate::common;
use penumbra::experiment::progress::Progress;

use penumbra::experiment::sweep::axes::Config;
use penumbra::experiment::sweep::report::summary::{find, summarise, Summary};
use penumbra::experiment::sweep::report::verdict::Verdict;
use penumbra::experiment::sweep::{run_sweep, Outcome, Spec};
use penumbra::render::cpu::CpuBackend;
use penumbra::sampling::{DiskScheme, Pattern};

/// `scheme` at the verdict's configuration: 16 rays, 2 cm, per-pixel, one light.
fn at(summaries: &[Summary], scheme: DiskScheme) -> Config {
    let mut c = summaries[0].config.clone();
    (c.scheme, c.pattern, c.samples, c.light_radius, c.lights) = (scheme, Pattern::PerPixel, 16, 0.02, 1);
    c
}

fn sweep(seeds: &str) -> (Outcome, Vec<Summary>) {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| t.replace("seeds = [1, 2]", seeds));
    let spec = Spec::load(&exp).unwrap();
    let mut cpu = CpuBackend::default();
    let out = run_sweep(&spec, &mut cpu, dir.path(), true, &Progress::default()).unwrap();
    let summaries = summarise(&out, &Default::default());
    (out, summaries)
}

#[test]
fn summaries_match_the_runs_recomputed_by_hand() {
    let (out, summaries) = sweep("seeds = [1, 2, 3, 4]");
    for s in &summaries {
        let rows: Vec<_> = out.records.iter().filter(|r| r.run.config() == s.config).collect();
        assert_eq!((rows.len(), s.seeds), (4, 4));
        let x: Vec<f64> = rows.iter().map(|r| r.metrics.rmse).collect();
        let mean = x.iter().sum::<f64>() / 4.0;
        let sd = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 3.0).sqrt();
        assert!((s.metrics.rmse.mean - mean).abs() < 1e-15);
        // Student's t for 3 degrees of freedom: 3.182.
        assert!((s.metrics.rmse.ci95 - 3.182 * sd / 2.0).abs() < 1e-12);
        // Over the same mask, the mean of the runs' MSE is exactly bias^2 + variance.
        let mse = x.iter().map(|v| v * v).sum::<f64>() / 4.0;
        let split = s.stats.split;
        assert!(
            (mse - (split.bias2 + split.variance)).abs() < 1e-6 * mse,
            "{mse} vs {split:?}"
        );
        assert!(split.bias2_ci.is_finite() && split.bias2_ci > 0.0);
        // Untimed (repeats = 0): no frame time, not a zero one.
        assert!(s.frame.median.is_nan() && s.timing.is_none());
    }
}

#[test]
fn the_verdict_needs_four_seeds_and_never_prints_nan() {
    let (_, one) = sweep("seeds = [1, 2, 3]");
    let v = Verdict::new(
        &one,
        &at(&one, DiskScheme::Paper),
        (DiskScheme::Paper, DiskScheme::Uniform),
    )
    .unwrap();
    let text = v.markdown();
    assert!(text.contains("No verdict"), "{text}");
    assert!(
        !text.contains("disjoint") && !text.contains("NaN") && !text.contains("± 0.00"),
        "{text}"
    );
    assert!(text.contains("± n/a"), "{text}");
    assert!(!v.wider() && !v.extent.a_below());

    let (_, four) = sweep("seeds = [1, 2, 3, 4]");
    let v = Verdict::new(
        &four,
        &at(&four, DiskScheme::Paper),
        (DiskScheme::Paper, DiskScheme::Uniform),
    )
    .unwrap();
    let text = v.markdown();
    assert!(!text.contains("No verdict") && !text.contains("NaN"), "{text}");
    // Squared biases read as values with their intervals, never bare (or negative) numbers.
    for scheme in [DiskScheme::Paper, DiskScheme::Uniform] {
        let s = find(&four, &at(&four, scheme)).unwrap();
        let b = penumbra::output::numbers::bias2(&s.stats.split);
        assert!(b.contains(" ± ") && text.contains(&b), "{b} not in {text}");
    }
}
