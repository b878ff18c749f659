//! The verdict on the soft-shadow paper's claim, computed from the summaries: at the paper's
//! 16 rays and 2 cm light, is the pseudo-random pattern's penumbra wider than uniform sampling's
//! at equal quality, and is the extra width closer to the exact penumbra or a bias? An
//! experiment's `[verdict]` may ask the same of another pair (its own pattern against uniform).
//!
//! Two means are called different only when their 95 % intervals are disjoint; without intervals
//! (fewer than four seeds) nothing is called different, and the verdict says it needs more seeds.

use super::summary::{find, Summary};
use crate::experiment::sweep::axes::Config;
use crate::experiment::sweep::record::Aggregated;
use crate::metrics::stats::MeanCi;
use crate::metrics::BiasVariance;
use crate::output::numbers::{bias2, or_na, with_ci};
use crate::sampling::{DiskScheme, Pattern};

/// A comparison of two means with 95 % CIs.
#[derive(Clone, Copy, Debug)]
pub struct Compare {
    /// First mean and CI half-width.
    pub a: MeanCi,
    /// Second mean and CI half-width.
    pub b: MeanCi,
}

impl Compare {
    fn intervals(&self) -> Option<((f64, f64), (f64, f64))> {
        let ok = |x: MeanCi| x.mean.is_finite() && x.ci95.is_finite();
        (ok(self.a) && ok(self.b)).then_some((
            (self.a.mean - self.a.ci95, self.a.mean + self.a.ci95),
            (self.b.mean - self.b.ci95, self.b.mean + self.b.ci95),
        ))
    }

    /// Whether both means have intervals, so that a difference can be called either way.
    pub fn comparable(&self) -> bool {
        self.intervals().is_some()
    }

    /// Whether both intervals exist and are disjoint with a above b.
    pub fn a_above(&self) -> bool {
        self.intervals().is_some_and(|(a, b)| a.0 > b.1)
    }

    /// Whether both intervals exist and are disjoint with a below b.
    pub fn a_below(&self) -> bool {
        self.intervals().is_some_and(|(a, b)| a.1 < b.0)
    }

    /// a / b.
    pub fn ratio(&self) -> f64 {
        self.a.mean / self.b.mean
    }
}

/// The numbers the verdict rests on.
#[derive(Clone, Debug)]
pub struct Verdict {
    /// Shadow rays per pixel compared.
    pub samples: u32,
    /// The scheme whose claim is judged (the paper's pattern by default) and its baseline.
    pub pair: (DiskScheme, DiskScheme),
    /// Light radius compared (m).
    pub light_radius: f64,
    /// Pattern compared.
    pub pattern: Pattern,
    /// Seeds behind the smaller of the two configurations.
    pub seeds: usize,
    /// Visible extent width, subject vs baseline.
    pub extent: Compare,
    /// 10-90 % width, subject vs baseline.
    pub width_10_90: Compare,
    /// RMSE against the ground truth, subject vs baseline.
    pub rmse: Compare,
    /// RMSE against the exact image, subject vs baseline.
    pub rmse_exact: Compare,
    /// FLIP of the Fig. 2 pictures against the ground-truth picture, subject vs baseline.
    pub flip: Compare,
    /// Squared bias (with interval) and variance per pixel over seeds: subject, baseline.
    pub split: (BiasVariance, BiasVariance),
    /// Exact image's extent width and exact 10-90 width.
    pub exact: (f64, f64),
    /// Closed-form r_p - r_u.
    pub closed_form_width: f64,
}

impl Verdict {
    /// Builds the verdict at configuration `at` (whatever its scheme), if both schemes were swept
    /// there.
    pub fn new(summaries: &[Summary], at: &Config, (subject, baseline): (DiskScheme, DiskScheme)) -> Option<Verdict> {
        let with = |scheme| find(summaries, &Config { scheme, ..at.clone() });
        let (p, u) = (with(subject)?, with(baseline)?);
        let cmp = |m: fn(&Aggregated) -> MeanCi| Compare {
            a: m(&p.metrics),
            b: m(&u.metrics),
        };
        Some(Verdict {
            pair: (subject, baseline),
            samples: at.samples,
            light_radius: at.light_radius,
            pattern: at.pattern,
            seeds: p.seeds.min(u.seeds),
            extent: cmp(|m| m.extent_width),
            width_10_90: cmp(|m| m.width_10_90),
            rmse: cmp(|m| m.rmse),
            rmse_exact: cmp(|m| m.rmse_exact),
            flip: Compare { a: p.flip, b: u.flip },
            split: (p.stats.split, u.stats.split),
            exact: (p.exact_extent_width, p.exact_width_10_90),
            closed_form_width: p.closed_form_width,
        })
    }

    /// Whether the subject's visible penumbra is wider (CIs exist and are disjoint).
    pub fn wider(&self) -> bool {
        self.extent.a_above()
    }

    /// The verdict as markdown sentences, every claim with its numbers.
    pub fn markdown(&self) -> String {
        let ((a, a_short, a_s), (b, b_short, b_s)) = (names(self.pair.0), names(self.pair.1));
        let upper = |x: &str| x[..1].to_uppercase() + &x[1..];
        let big_a_s = upper(&a_s);
        let mm = |x: f64| format!("{:.2} mm", x * 1e3);
        let pm = |x: MeanCi| with_ci(x.mean, x.ci95, mm);
        let mut s = format!(
            "**At {} shadow rays, light radius {} m, {} pattern, {} seeds.**\n\n",
            self.samples, self.light_radius, self.pattern, self.seeds
        );
        if self.seeds < crate::metrics::stats::MIN_VALUES_FOR_INTERVAL {
            s += &format!("- *No verdict:* comparing two configurations needs at least {} seeds each (for an interval over seeds); this sweep has fewer. The numbers below carry no interval.\n", crate::metrics::stats::MIN_VALUES_FOR_INTERVAL);
        }
        let (e, w) = self.exact;
        s += &format!(
            "- *Wider?* The visible penumbra (how far partial shadow reaches, read with a sliding one-pixel annulus) is {} with {a} and {} with {b}; the exact image reads {} (closed form r_p - max(r_u, 0) = {}; the annulus adds 0.9 pixel at an umbra edge). {}\n",
            pm(self.extent.a),
            pm(self.extent.b),
            or_na(e, mm),
            or_na(self.closed_form_width, mm),
            if self.wider() {
                format!("{big_a_s} penumbra is wider (95 % intervals disjoint).")
            } else if self.extent.a_below() {
                format!("{big_a_s} penumbra is narrower (95 % intervals disjoint).")
            } else if self.seeds < crate::metrics::stats::MIN_VALUES_FOR_INTERVAL {
                "Without intervals no difference can be called.".into()
            } else if !self.extent.comparable() {
                "No difference can be called: an extent is missing (no penumbra, or beyond the measured patch).".into()
            } else {
                "The difference is within the seed-to-seed noise.".into()
            }
        );
        let dev = |x: f64| or_na(x / w - 1.0, |d| format!("{:+.1} %", 100.0 * d));
        let (wa, wb) = (self.width_10_90.a, self.width_10_90.b);
        // The paper's departure from exact is called a bias only when it exceeds uniform's by
        // more than both intervals together.
        let departs =
            wa.ci95.is_finite() && wb.ci95.is_finite() && (wa.mean - w).abs() > (wb.mean - w).abs() + wa.ci95 + wb.ci95;
        s += &format!(
            "- *Closer to the truth, or bias?* The 10-90 % width of the mean radial profile is {} ({a_short}, {} vs exact) and {} ({b_short}, {}); exact {}. {}\n",
            pm(wa),
            dev(wa.mean),
            pm(wb),
            dev(wb.mean),
            or_na(w, mm),
            if departs && wa.mean > w {
                format!("{big_a_s} extra width is a departure from the exact profile: a bias, not a truer penumbra.")
            } else if departs {
                format!("{big_a_s} profile is narrower than the exact one by more than {b_s} departs, beyond noise: a bias.")
            } else if self.seeds < crate::metrics::stats::MIN_VALUES_FOR_INTERVAL {
                "Without intervals no difference can be called.".into()
            } else if !self.width_10_90.comparable() || !w.is_finite() {
                "No difference can be called: a 10-90 % width is missing (no penumbra, or beyond the measured patch).".into()
            } else {
                "Neither profile departs from the exact one by more than the other beyond noise.".into()
            }
        );
        let four = |x: f64| format!("{x:.4}");
        let e2 = |x: f64| format!("{x:.2e}");
        s += &format!(
            "- *Equal quality?* RMSE against the ground truth over the penumbra: {} ({a_short}) vs {} ({b_short}), ratio {}; against the exact image {} vs {}. Perceptual error (FLIP, mean over the Fig. 2 picture against the ground-truth picture): {} vs {}{}. Per pixel over seeds, squared bias {} vs {} and variance {} vs {}.\n",
            with_ci(self.rmse.a.mean, self.rmse.a.ci95, four),
            with_ci(self.rmse.b.mean, self.rmse.b.ci95, four),
            or_na(self.rmse.ratio(), |r| format!("{r:.2}")),
            or_na(self.rmse_exact.a.mean, four),
            or_na(self.rmse_exact.b.mean, four),
            with_ci(self.flip.a.mean, self.flip.a.ci95, four),
            with_ci(self.flip.b.mean, self.flip.b.ci95, four),
            if self.flip.a_below() {
                format!(" ({a_s} picture is closer, intervals disjoint)")
            } else if self.flip.a_above() {
                format!(" ({b_s} picture is closer, intervals disjoint)")
            } else {
                String::new()
            },
            bias2(&self.split.0),
            bias2(&self.split.1),
            or_na(self.split.0.variance, e2),
            or_na(self.split.1.variance, e2),
        );
        s
    }
}

/// How the verdict names a scheme: (in a phrase, in parentheses, possessive); the paper's two
/// by what they are, others by name.
fn names(scheme: DiskScheme) -> (String, String, String) {
    match scheme {
        DiskScheme::Paper => ("the paper's pattern".into(), "paper".into(), "the paper's".into()),
        DiskScheme::Uniform => ("uniform sampling".into(), "uniform".into(), "uniform's".into()),
        s => (format!("`{s}`"), s.to_string(), format!("`{s}`'s")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn split() -> BiasVariance {
        BiasVariance {
            seeds: 4,
            bias2: 1e-4,
            bias2_ci: 2e-4,
            variance: 1e-3,
        }
    }

    /// A verdict at 4 seeds with the exact 10-90 width 10 mm; extents and 10-90 widths given as
    /// (paper, uniform) (mean, CI) pairs.
    fn verdict(extent: [(f64, f64); 2], width: [(f64, f64); 2]) -> Verdict {
        let none = Compare {
            a: MeanCi::NAN,
            b: MeanCi::NAN,
        };
        let compare = |[(a, ca), (b, cb)]: [(f64, f64); 2]| Compare {
            a: MeanCi { mean: a, ci95: ca },
            b: MeanCi { mean: b, ci95: cb },
        };
        Verdict {
            pair: (DiskScheme::Paper, DiskScheme::Uniform),
            samples: 16,
            light_radius: 0.02,
            pattern: Pattern::PerPixel,
            seeds: 4,
            extent: compare(extent),
            width_10_90: compare(width),
            rmse: none,
            rmse_exact: none,
            flip: none,
            split: (split(), split()),
            exact: (0.015, 0.010),
            closed_form_width: 0.0149,
        }
    }

    const AT_EXACT: [(f64, f64); 2] = [(0.010, 1e-4), (0.010, 1e-4)];

    #[test]
    fn a_difference_is_called_only_between_disjoint_intervals() {
        let wider = verdict([(0.0150, 1e-4), (0.0145, 1e-4)], AT_EXACT).markdown();
        assert!(
            wider.contains("The paper's penumbra is wider (95 % intervals disjoint)."),
            "{wider}"
        );
        let narrower = verdict([(0.0140, 1e-4), (0.0145, 1e-4)], AT_EXACT).markdown();
        assert!(narrower.contains("is narrower (95 % intervals disjoint)"), "{narrower}");
        let overlap = verdict([(0.0146, 1e-4), (0.0145, 1e-4)], AT_EXACT).markdown();
        assert!(overlap.contains("within the seed-to-seed noise"), "{overlap}");
        let missing = verdict([(f64::NAN, f64::NAN), (0.0145, 1e-4)], AT_EXACT).markdown();
        assert!(missing.contains("an extent is missing"), "{missing}");
        assert!(!missing.contains("NaN") && !missing.contains("within the seed-to-seed noise"));
    }

    #[test]
    fn a_bias_is_called_only_beyond_both_intervals_and_in_its_direction() {
        let extent = [(0.0146, 1e-4), (0.0145, 1e-4)];
        // Paper 6 % wide, uniform at exact, intervals 0.1 mm: a widening bias.
        let wide = verdict(extent, [(0.0106, 1e-4), (0.0100, 1e-4)]).markdown();
        assert!(wide.contains("extra width is a departure"), "{wide}");
        // The same departure inside the intervals: nothing is called.
        let noisy = verdict(extent, [(0.0106, 4e-4), (0.0100, 4e-4)]).markdown();
        assert!(noisy.contains("Neither profile departs"), "{noisy}");
        // Narrower than exact: a bias, but not an extra width.
        let narrow = verdict(extent, [(0.0094, 1e-4), (0.0100, 1e-4)]).markdown();
        assert!(narrow.contains("narrower than the exact one"), "{narrow}");
        assert!(!narrow.contains("extra width"), "{narrow}");
        let missing = verdict(extent, [(0.0106, f64::NAN), (0.0100, 1e-4)]).markdown();
        assert!(missing.contains("a 10-90 % width is missing"), "{missing}");
    }
}
