//! Regression thresholds: runs experiments/ci.toml (small, seconds on lavapipe) once and checks
//! the committed bounds in experiments/ci-thresholds.toml; then, for every bound, breaks the
//! property it protects and watches the check fail. Times are recorded, never asserted.

use crate::common;
use penumbra::experiment::progress::Progress;

use penumbra::experiment::sweep::reference::Reference;
use penumbra::experiment::sweep::report::summary::{summarise, Summary};
use penumbra::experiment::sweep::report::thresholds::{Check, Thresholds};
use penumbra::experiment::sweep::{run_sweep, Spec};
use penumbra::render::open_backend;
use penumbra::sampling::DiskScheme;
use std::sync::OnceLock;

struct Ci {
    spec: Spec,
    references: Vec<Reference>,
    summaries: Vec<Summary>,
    thresholds: Thresholds,
}

/// The CI sweep, run once per test binary.
fn ci() -> &'static Ci {
    static CI: OnceLock<Ci> = OnceLock::new();
    CI.get_or_init(|| {
        // Hold the shared GPU (if any) so no other test in this binary uses it concurrently.
        let _gpu = common::gpu();
        let spec = Spec::load(&common::repo("experiments/ci.toml")).unwrap();
        let thresholds = Thresholds::load(&common::repo("experiments/ci-thresholds.toml")).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let mut backend = open_backend(spec.backend).unwrap();
        let out = run_sweep(&spec, backend.as_mut(), dir.path(), true, &Progress::default()).unwrap();
        assert_eq!(out.failures, 0);
        let summaries = summarise(&out, &Default::default());
        Ci {
            spec,
            references: out.references,
            summaries,
            thresholds,
        }
    })
}

fn failures(checks: &[Check]) -> Vec<&Check> {
    for c in checks {
        eprintln!("{} {}", if c.ok { "ok  " } else { "FAIL" }, c.what);
    }
    checks.iter().filter(|c| !c.ok).collect()
}

fn radius() -> f64 {
    ci().spec.axes.light_radii[0]
}

#[test]
fn ci_experiment_stays_within_thresholds() {
    let c = ci();
    let checks = c.thresholds.check_all(&c.references, &c.summaries, radius());
    // Ground truth 4; per scheme a width check at 16 and 64 rays and at least one bias check;
    // paper 2; convergence 2.
    let unbiased = c.thresholds.unbiased.schemes.len();
    assert!(
        checks.len() >= 4 + unbiased * (2 + 1) + 2 + 2,
        "{} checks",
        checks.len()
    );
    let failed = failures(&checks);
    assert!(failed.is_empty(), "thresholds crossed: {failed:#?}");
}

#[test]
fn the_unbiased_check_rejects_the_papers_biased_patterns() {
    let c = ci();
    for scheme in [DiskScheme::Paper, DiskScheme::PaperLiteral] {
        let checks = c.thresholds.check_unbiased(&c.summaries, scheme, radius());
        failures(&checks);
        let bias_checks: Vec<&Check> = checks.iter().filter(|x| x.what.contains("squared bias")).collect();
        assert!(!bias_checks.is_empty());
        assert!(
            bias_checks.iter().all(|x| !x.ok),
            "{scheme} passed an unbiasedness check: {bias_checks:#?}"
        );
    }
}

/// Each ground-truth bound fails for a ground truth broken in the way it guards against.
#[test]
fn the_ground_truth_checks_reject_broken_ground_truths() {
    let c = ci();
    let (w, h) = (c.spec.measure.width as usize, c.spec.measure.height as usize);
    let reference = &c.references[0];
    let failing = |r: &Reference| -> Vec<String> {
        failures(&c.thresholds.check_ground_truth(r))
            .iter()
            .map(|x| x.what.clone())
            .collect()
    };
    assert!(failing(reference).is_empty());
    let on_receivers = |f: &dyn Fn(usize, f32) -> f32| {
        let mut r = reference.clone();
        for &(i, _) in &reference.receivers.pixels {
            r.ground_truth[i] = f(i, reference.ground_truth[i]);
        }
        r
    };
    // The old shadow-ray offset: visibility biased by +7e-4 everywhere in the penumbra.
    let offset = on_receivers(&|_, v| if v > 0.0 && v < 1.0 { v + 7e-4 } else { v });
    assert!(failing(&offset).iter().any(|f| f.contains("mean (GT - exact)")));
    // Too few rays: noise of 0.01 per pixel.
    let noisy = on_receivers(&|i, v| {
        let u = penumbra::sampling::Stream::new(3, 0, None).unit(i as u32);
        (v + 0.02 * (u as f32 - 0.5) * 1.7).clamp(0.0, 1.0)
    });
    assert!(failing(&noisy).iter().any(|f| f.contains("GT RMSE")));
    // One wrong pixel.
    let mid = reference.mask.pixels[reference.mask.pixels.len() / 2];
    let spike = on_receivers(&|i, v| if i == mid { (v - 0.05).max(0.0) } else { v });
    let spiked = failing(&spike);
    assert!(spiked.iter().any(|f| f.contains("max |GT - exact|")), "{spiked:?}");
    // A blurred ground truth (a 7x7 box filter): its penumbra spreads past the closed-form radii.
    let blurred = on_receivers(&|i, _| {
        let (x, y) = ((i % w) as i64, (i / w) as i64);
        let mut sum = (0.0, 0);
        for dy in -3..=3i64 {
            for dx in -3..=3i64 {
                let (u, v) = (x + dx, y + dy);
                if u >= 0 && v >= 0 && (u as usize) < w && (v as usize) < h {
                    let val = reference.ground_truth[v as usize * w + u as usize];
                    if val >= 0.0 {
                        sum = (sum.0 + val, sum.1 + 1);
                    }
                }
            }
        }
        sum.0 / sum.1 as f32
    });
    assert!(failing(&blurred).iter().any(|f| f.contains("GT extent")));
}

#[test]
fn the_paper_width_check_rejects_an_unbiased_scheme() {
    let c = ci();
    let checks = c
        .thresholds
        .check_paper_width(&c.summaries, DiskScheme::Uniform, radius());
    failures(&checks);
    assert!(!checks.is_empty() && checks.iter().all(|x| !x.ok), "{checks:#?}");
}

#[test]
fn the_convergence_checks_reject_a_scheme_that_stops_converging() {
    let c = ci();
    let checks = c.thresholds.check_convergence(
        &c.summaries,
        DiskScheme::PaperLiteral,
        (DiskScheme::Uniform, DiskScheme::Uniform),
        radius(),
    );
    failures(&checks);
    assert!(checks.iter().all(|x| !x.ok), "{checks:#?}");
}

/// Summaries of the CI sweep with `scheme`'s exact 10-90 width scaled by `factor`: as if the
/// scheme's profile were off the exact one by 1/factor - 1.
fn exact_width_scaled(scheme: DiskScheme, factor: f64) -> Vec<Summary> {
    let mut summaries = ci().summaries.clone();
    for s in summaries.iter_mut().filter(|s| s.config.scheme == scheme) {
        s.exact_width_10_90 *= factor;
    }
    summaries
}

#[test]
fn the_unbiased_width_check_rejects_a_profile_off_the_exact_width() {
    let c = ci();
    let tol = c.thresholds.unbiased.width_10_90_tolerance;
    for factor in [1.0 + 2.0 * tol, 1.0 / (1.0 + 2.0 * tol)] {
        let summaries = exact_width_scaled(DiskScheme::Uniform, factor);
        let checks = c.thresholds.check_unbiased(&summaries, DiskScheme::Uniform, radius());
        let width: Vec<&Check> = checks.iter().filter(|x| x.what.contains("10-90 width")).collect();
        failures(&checks);
        assert!(!width.is_empty() && width.iter().all(|x| !x.ok), "{width:#?}");
    }
}

#[test]
fn the_paper_width_check_rejects_too_much_widening() {
    let c = ci();
    let max = c.thresholds.paper.max_width_10_90_excess;
    // The exact width shrunk so that the paper's measured width exceeds it by max + 10 %.
    let paper = |s: &Summary| s.metrics.width_10_90.mean / s.exact_width_10_90 - 1.0;
    let worst = c
        .summaries
        .iter()
        .filter(|s| s.config.scheme == DiskScheme::Paper)
        .map(paper)
        .fold(f64::INFINITY, f64::min);
    let summaries = exact_width_scaled(DiskScheme::Paper, (1.0 + worst) / (1.0 + max + 0.1));
    let checks = c.thresholds.check_paper_width(&summaries, DiskScheme::Paper, radius());
    failures(&checks);
    assert!(!checks.is_empty() && checks.iter().all(|x| !x.ok), "{checks:#?}");
}

#[test]
fn a_bound_on_a_scheme_the_sweep_lacks_fails() {
    let c = ci();
    let without: Vec<Summary> = c
        .summaries
        .iter()
        .filter(|s| s.config.scheme != DiskScheme::Jittered)
        .cloned()
        .collect();
    for checks in [
        c.thresholds.check_unbiased(&without, DiskScheme::Jittered, radius()),
        c.thresholds.check_unbiased(&c.summaries, DiskScheme::Uniform, 0.5),
        c.thresholds.check_paper_width(&c.summaries, DiskScheme::Paper, 0.5),
    ] {
        failures(&checks);
        assert!(checks.len() == 1 && !checks[0].ok, "{checks:#?}");
    }
}

#[test]
fn an_unbiasedness_bound_too_loose_to_see_a_bias_fails() {
    let c = ci();
    let mut strict = c.thresholds.clone();
    strict.unbiased.detectable_bias2 = 1e-9;
    let checks = strict.check_unbiased(&c.summaries, DiskScheme::Uniform, radius());
    failures(&checks);
    assert!(
        checks
            .iter()
            .any(|x| !x.ok && x.what.contains("no swept count resolves")),
        "{checks:#?}"
    );
    assert!(
        !checks.iter().any(|x| x.what.contains("per-pixel squared bias")),
        "{checks:#?}"
    );
}
