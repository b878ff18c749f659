//! Regression thresholds (experiments/ci-thresholds.toml) as checks over a finished sweep. Each
//! check computes its statistic from the images and summaries it is given, so a test can hand it
//! a broken input (a biased ground truth, a biased scheme) and watch it fail.

use super::summary::Summary;
use crate::config::{ConfigError, Source};
use crate::experiment::sweep::reference::Reference;
use crate::metrics::stats::t975;
use crate::sampling::{DiskScheme, Pattern};
use serde::Deserialize;
use std::path::Path;

/// The bounds, each documented in the thresholds file with what it protects.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Thresholds {
    /// Ground truth against the exact answer.
    pub ground_truth: GroundTruthBounds,
    /// Schemes that must estimate visibility without bias.
    pub unbiased: UnbiasedBounds,
    /// The paper's pattern's known bias.
    pub paper: PaperBounds,
    /// Convergence rates.
    pub convergence: ConvergenceBounds,
}

/// Ground truth against the exact quadrature.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundTruthBounds {
    /// Largest |GT - exact| over receiver pixels.
    pub max_abs_error: f64,
    /// RMS of GT - exact over the exact penumbra.
    pub max_rmse: f64,
    /// |mean (GT - exact)| over the exact penumbra.
    pub max_abs_bias: f64,
    /// The GT's extent against the closed-form r_u, r_p, in pixels.
    pub extent_tolerance_pixels: f64,
}

/// Unbiased schemes.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnbiasedBounds {
    /// Schemes held to it.
    pub schemes: Vec<DiskScheme>,
    /// The per-pixel squared bias may exceed 0 by at most this many standard errors...
    pub max_bias2_sigmas: f64,
    /// ...plus this floor (the ground truth's own noise enters the squared bias).
    pub bias2_floor: f64,
    /// The squared bias the check must be able to see: counts whose bound exceeds it are too
    /// noisy to test and are skipped, and a scheme with no count below it fails.
    pub detectable_bias2: f64,
    /// Ray counts from which the checks apply.
    pub min_samples: u32,
    /// Relative tolerance of the 10-90 % width against exact.
    pub width_10_90_tolerance: f64,
}

/// The paper's pattern.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PaperBounds {
    /// Least relative excess of its 10-90 % width over exact.
    pub min_width_10_90_excess: f64,
    /// Most relative excess.
    pub max_width_10_90_excess: f64,
}

/// Convergence.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConvergenceBounds {
    /// Largest RMSE(64) / RMSE(4) for uniform sampling.
    pub uniform_rmse_ratio_4_to_64: f64,
    /// Largest RMSE(sobol) / RMSE(uniform) at 16 rays.
    pub sobol_over_uniform_rmse_at_16: f64,
}

/// One check's outcome.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    /// Whether the bound holds.
    pub ok: bool,
    /// What was compared, with the numbers.
    pub what: String,
}

fn check(ok: bool, what: String) -> Check {
    Check { ok, what }
}

impl Thresholds {
    /// Reads a thresholds file; errors name the file, line and key.
    pub fn load(path: &Path) -> Result<Thresholds, ConfigError> {
        Source::read(path)?.parse()
    }

    /// The ground truth of `r` against its exact image (recomputed from the images).
    pub fn check_ground_truth(&self, r: &Reference) -> Vec<Check> {
        let t = &self.ground_truth;
        let (Some(max), Some(gt), Some(o), Some(p)) = (r.gt_max_abs_all(), r.gt_vs_exact(), &r.on_axis, r.gt_profile())
        else {
            return vec![check(
                false,
                format!("r={}: no exact on-axis reference", r.light_radius),
            )];
        };
        let (inner, outer) = p.extent();
        let tol = t.extent_tolerance_pixels * r.receivers.bin_width;
        let (ru, rp) = (o.inner_radius(), o.penumbra_radius());
        vec![
            check(
                max <= t.max_abs_error,
                format!(
                    "r={}: max |GT - exact| = {max:.2e} <= {}",
                    r.light_radius, t.max_abs_error
                ),
            ),
            check(
                gt.rmse <= t.max_rmse,
                format!(
                    "r={}: GT RMSE vs exact = {:.2e} <= {}",
                    r.light_radius, gt.rmse, t.max_rmse
                ),
            ),
            check(
                gt.bias.abs() <= t.max_abs_bias,
                format!(
                    "r={}: mean (GT - exact) = {:+.2e}, |.| <= {}",
                    r.light_radius, gt.bias, t.max_abs_bias
                ),
            ),
            check(
                (inner - ru).abs() <= tol && (outer - rp).abs() <= tol,
                format!(
                    "r={}: GT extent [{inner:.5}, {outer:.5}] vs closed form [{ru:.5}, {rp:.5}] within {tol:.2e}",
                    r.light_radius
                ),
            ),
        ]
    }

    /// `scheme` (per-pixel) is unbiased at every swept count from `min_samples`: its per-pixel
    /// squared bias over seeds is 0 within `max_bias2_sigmas` jackknife standard errors plus the
    /// floor (a squared statistic: errors of either sign add up instead of cancelling), wherever
    /// that bound is below `detectable_bias2` (and somewhere it must be), and its 10-90 % width
    /// is within the tolerance of exact.
    pub fn check_unbiased(&self, summaries: &[Summary], scheme: DiskScheme, radius: f64) -> Vec<Check> {
        let t = &self.unbiased;
        let mut out = Vec::new();
        let mut bias_checked = false;
        for s in at_counts(summaries, scheme, radius, t.min_samples) {
            let b = &s.stats.split;
            let se = b.bias2_ci / t975(b.seeds.saturating_sub(1));
            let bound = t.max_bias2_sigmas * se + t.bias2_floor;
            // NaN bounds (too few seeds) are not skipped: they fail below.
            if bound.is_nan() || bound <= t.detectable_bias2 {
                bias_checked = true;
                out.push(check(
                    b.bias2 <= bound,
                    format!(
                        "{scheme} n={}: per-pixel squared bias {:.2e} <= {:.1} x {se:.2e} + {:.0e}",
                        s.config.samples, b.bias2, t.max_bias2_sigmas, t.bias2_floor
                    ),
                ));
            }
            let rel = s.metrics.width_10_90.mean / s.exact_width_10_90 - 1.0;
            out.push(check(
                rel.abs() <= t.width_10_90_tolerance,
                format!(
                    "{scheme} n={}: 10-90 width {rel:+.3} relative to exact, within {}",
                    s.config.samples, t.width_10_90_tolerance
                ),
            ));
        }
        if out.is_empty() {
            out.push(not_swept(scheme, radius, t.min_samples));
        } else if !bias_checked {
            out.push(check(
                false,
                format!(
                    "{scheme}: no swept count resolves a squared bias of {:.0e} (more seeds or rays needed)",
                    t.detectable_bias2
                ),
            ));
        }
        out
    }

    /// `scheme` (per-pixel) widens the 10-90 % width by the paper's pattern's known bias at
    /// 16 rays and more.
    pub fn check_paper_width(&self, summaries: &[Summary], scheme: DiskScheme, radius: f64) -> Vec<Check> {
        let t = &self.paper;
        let out: Vec<Check> = at_counts(summaries, scheme, radius, 16)
            .map(|s| {
                let excess = s.metrics.width_10_90.mean / s.exact_width_10_90 - 1.0;
                check(
                    excess >= t.min_width_10_90_excess && excess <= t.max_width_10_90_excess,
                    format!(
                        "{scheme} n={}: 10-90 width excess {excess:+.3} in [{}, {}]",
                        s.config.samples, t.min_width_10_90_excess, t.max_width_10_90_excess
                    ),
                )
            })
            .collect();
        if out.is_empty() {
            return vec![not_swept(scheme, radius, 16)];
        }
        out
    }

    /// `scheme`'s RMSE falls from 4 to 64 rays at least as fast as the bound asks of uniform
    /// sampling, and `better` beats `than` at 16 rays by the Sobol' bound.
    pub fn check_convergence(
        &self,
        summaries: &[Summary],
        scheme: DiskScheme,
        (better, than): (DiskScheme, DiskScheme),
        radius: f64,
    ) -> Vec<Check> {
        let t = &self.convergence;
        let rmse = |s: DiskScheme, n: u32| {
            at_counts(summaries, s, radius, n)
                .find(|x| x.config.samples == n)
                .map_or(f64::NAN, |x| x.metrics.rmse.mean)
        };
        let ratio = rmse(scheme, 64) / rmse(scheme, 4);
        let sobol = rmse(better, 16) / rmse(than, 16);
        vec![
            check(
                ratio <= t.uniform_rmse_ratio_4_to_64,
                format!(
                    "{scheme} RMSE(64)/RMSE(4) = {ratio:.3} <= {}",
                    t.uniform_rmse_ratio_4_to_64
                ),
            ),
            check(
                sobol <= t.sobol_over_uniform_rmse_at_16,
                format!(
                    "{better}/{than} RMSE at 16 = {sobol:.3} <= {}",
                    t.sobol_over_uniform_rmse_at_16
                ),
            ),
        ]
    }

    /// Every check the thresholds file asks for, on a sweep of the on-axis CI scene.
    pub fn check_all(&self, references: &[Reference], summaries: &[Summary], radius: f64) -> Vec<Check> {
        let mut out: Vec<Check> = references.iter().flat_map(|r| self.check_ground_truth(r)).collect();
        for &scheme in &self.unbiased.schemes {
            out.extend(self.check_unbiased(summaries, scheme, radius));
        }
        out.extend(self.check_paper_width(summaries, DiskScheme::Paper, radius));
        out.extend(self.check_convergence(
            summaries,
            DiskScheme::Uniform,
            (DiskScheme::Sobol, DiskScheme::Uniform),
            radius,
        ));
        out
    }
}

/// A bound with nothing to check fails: a thresholds file that names a scheme the sweep lacks
/// protects nothing.
fn not_swept(scheme: DiskScheme, radius: f64, min: u32) -> Check {
    check(
        false,
        format!("{scheme}: not swept per-pixel with one light of radius {radius} m at {min} rays or more"),
    )
}

/// Per-pixel summaries of `scheme` at `radius` with one light, from `min` rays up.
fn at_counts(summaries: &[Summary], scheme: DiskScheme, radius: f64, min: u32) -> impl Iterator<Item = &Summary> {
    summaries.iter().filter(move |s| {
        s.config.scheme == scheme
            && s.config.pattern == Pattern::PerPixel
            && s.config.light_radius == radius
            && s.config.lights == 1
            && s.config.samples >= min
    })
}
