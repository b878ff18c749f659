//! The verdict on the soft-shadow paper's claim, computed from the summaries: at the paper's
//! 16 rays and 2 cm light, is the pseudo-random pattern's penumbra wider than uniform sampling's
//! at equal quality, and is the extra width closer to the exact penumbra or a bias?

use super::summary::{find, Summary};
use crate::sampling::{DiskScheme, Pattern};

/// A comparison of two means with 95 % CIs.
#[derive(Clone, Copy, Debug)]
pub struct Compare {
    /// First mean and CI half-width.
    pub a: (f64, f64),
    /// Second mean and CI half-width.
    pub b: (f64, f64),
}

impl Compare {
    /// Whether the intervals are disjoint with a above b.
    pub fn a_above(&self) -> bool {
        self.a.0 - ci(self.a.1) > self.b.0 + ci(self.b.1)
    }
    /// Whether the intervals are disjoint with a below b.
    pub fn a_below(&self) -> bool {
        self.a.0 + ci(self.a.1) < self.b.0 - ci(self.b.1)
    }
    /// a / b.
    pub fn ratio(&self) -> f64 {
        self.a.0 / self.b.0
    }
}

fn ci(x: f64) -> f64 {
    if x.is_nan() {
        0.0
    } else {
        x
    }
}

/// The numbers the verdict rests on.
#[derive(Clone, Debug)]
pub struct Verdict {
    /// Shadow rays per pixel compared.
    pub samples: u32,
    /// Light radius compared (m).
    pub light_radius: f64,
    /// Pattern compared.
    pub pattern: Pattern,
    /// Visible extent width, paper vs uniform.
    pub extent: Compare,
    /// 10-90 % width, paper vs uniform.
    pub width_10_90: Compare,
    /// RMSE against the ground truth, paper vs uniform.
    pub rmse: Compare,
    /// RMSE against the exact image, paper vs uniform.
    pub rmse_exact: Compare,
    /// Squared bias (per pixel, over seeds), paper and uniform.
    pub bias2: (f64, f64),
    /// Per-pixel variance over seeds, paper and uniform.
    pub variance: (f64, f64),
    /// Exact extent width (r_p - r_u) and exact 10-90 width.
    pub exact: (f64, f64),
}

impl Verdict {
    /// Builds the verdict for one pattern, if both schemes were swept there.
    pub fn new(summaries: &[Summary], samples: u32, light_radius: f64, pattern: Pattern) -> Option<Verdict> {
        let p = find(summaries, DiskScheme::Paper, pattern, samples, light_radius, 1)?;
        let u = find(summaries, DiskScheme::Uniform, pattern, samples, light_radius, 1)?;
        let cmp = |m: &str| Compare {
            a: (p.mean(m), p.ci(m)),
            b: (u.mean(m), u.ci(m)),
        };
        Some(Verdict {
            samples,
            light_radius,
            pattern,
            extent: cmp("extent_width"),
            width_10_90: cmp("width_10_90"),
            rmse: cmp("rmse"),
            rmse_exact: cmp("rmse_exact"),
            bias2: (p.stats.bias2, u.stats.bias2),
            variance: (p.stats.variance, u.stats.variance),
            exact: (p.exact_extent_width, p.exact_width_10_90),
        })
    }

    /// Whether the paper's visible penumbra is wider (CIs disjoint).
    pub fn wider(&self) -> bool {
        self.extent.a_above()
    }

    /// The verdict as markdown sentences, every claim with its numbers.
    pub fn markdown(&self) -> String {
        let mm = |x: f64| format!("{:.2} mm", x * 1e3);
        let pm = |(m, c): (f64, f64)| {
            if c.is_nan() {
                mm(m)
            } else {
                format!("{} ± {}", mm(m), mm(c))
            }
        };
        let mut s = String::new();
        let (e, w) = self.exact;
        s += &format!(
            "**At {} shadow rays, light radius {} m, {} pattern.**\n\n",
            self.samples, self.light_radius, self.pattern
        );
        s += &format!(
            "- *Wider?* The visible penumbra (how far partial shadow reaches) is {} with the paper's pattern and {} with uniform sampling; the exact extent is {}. {}\n",
            pm(self.extent.a),
            pm(self.extent.b),
            mm(e),
            if self.wider() {
                "The paper's penumbra is wider (95 % intervals disjoint)."
            } else if self.extent.a_below() {
                "The paper's penumbra is narrower (95 % intervals disjoint)."
            } else {
                "The difference is within the seed-to-seed noise."
            }
        );
        let dev = |x: f64| format!("{:+.1} %", 100.0 * (x / w - 1.0));
        s += &format!(
            "- *Closer to the truth, or bias?* The 10-90 % width of the mean radial profile is {} (paper, {} vs exact) and {} (uniform, {}); exact {}. {}\n",
            pm(self.width_10_90.a),
            dev(self.width_10_90.a.0),
            pm(self.width_10_90.b),
            dev(self.width_10_90.b.0),
            mm(w),
            if (self.width_10_90.a.0 - w).abs() > (self.width_10_90.b.0 - w).abs() + ci(self.width_10_90.a.1) + ci(self.width_10_90.b.1) {
                "The paper's extra width is a departure from the exact profile: a bias, not a truer penumbra."
            } else {
                "Neither profile departs from the exact one by more than the other beyond noise."
            }
        );
        s += &format!(
            "- *Equal quality?* RMSE against the ground truth over the penumbra: {:.4} (paper) vs {:.4} (uniform), ratio {:.2}; against the exact image {:.4} vs {:.4}. Per pixel over seeds, squared bias {:.2e} vs {:.2e} and variance {:.2e} vs {:.2e}.\n",
            self.rmse.a.0,
            self.rmse.b.0,
            self.rmse.ratio(),
            self.rmse_exact.a.0,
            self.rmse_exact.b.0,
            self.bias2.0,
            self.bias2.1,
            self.variance.0,
            self.variance.1
        );
        s
    }
}
