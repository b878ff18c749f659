//! summary.csv: the runs of each configuration aggregated over seeds (means with 95 % CIs), its
//! frame time (median and quartiles of its interleaved timed frames), the per-pixel bias/variance
//! split of the group, and the perceptual error (FLIP) of its Fig. 2 picture where it has one.

use crate::experiment::sweep::axes::Config;
use crate::experiment::sweep::run::num;
use crate::experiment::sweep::run::GroupStats;
use crate::experiment::sweep::runner::Outcome;
use crate::experiment::sweep::timing::ConfigTiming;
use crate::experiment::sweep::Record;
use crate::metrics::stats::mean_ci;

/// Metrics aggregated over seeds as mean and CI half-width.
pub const AGGREGATED: [&str; 10] = [
    "extent_width",
    "width_10_90",
    "profile_bias",
    "profile_abs_bias",
    "rmse",
    "relmse",
    "bias",
    "rmse_exact",
    "penumbra_area_ratio",
    "penumbra_lost_share",
];

/// FLIP of each seed's picture, per configuration that has pictures.
pub type PictureFlip = Vec<(Config, Vec<f64>)>;

/// One configuration (all axes but the seed) summarised.
#[derive(Clone, Debug)]
pub struct Summary {
    /// The configuration.
    pub config: Config,
    /// Seeds that rendered.
    pub seeds: usize,
    /// (mean, ci95 half-width) per [`AGGREGATED`] metric.
    pub values: Vec<(f64, f64)>,
    /// Exact 10-90 width of the configuration's light radius.
    pub exact_width_10_90: f64,
    /// Exact extent width (from the exact image, read with the same annulus as the runs).
    pub exact_extent_width: f64,
    /// Closed-form penumbra width r_p - max(r_u, 0) (on-axis scenes; no umbra: from the axis).
    pub closed_form_width: f64,
    /// Bias/variance split.
    pub stats: GroupStats,
    /// Timed frames of the configuration, if timed.
    pub timing: Option<ConfigTiming>,
    /// Rays per second at the median frame time: all, primary, shadow.
    pub rays_per_s: [f64; 3],
    /// Mean and 95 % CI half-width of the FLIP of its pictures over seeds (NaN without pictures).
    pub flip: (f64, f64),
}

impl Summary {
    /// Mean of metric `name`.
    pub fn mean(&self, name: &str) -> f64 {
        self.values[index(name)].0
    }

    /// 95 % CI half-width of metric `name`.
    pub fn ci(&self, name: &str) -> f64 {
        self.values[index(name)].1
    }

    /// First quartile, median and third quartile of the frame time (ms); NaN when untimed.
    pub fn frame_ms(&self) -> (f64, f64, f64) {
        self.timing
            .as_ref()
            .map_or((f64::NAN, f64::NAN, f64::NAN), ConfigTiming::frame_ms)
    }
}

fn index(name: &str) -> usize {
    AGGREGATED.iter().position(|m| *m == name).expect("aggregated metric")
}

/// Summaries of every group of the outcome, in canonical order; `flip` gives the picture errors
/// of the configurations that have pictures.
pub fn summarise(outcome: &Outcome, flip: &PictureFlip) -> Vec<Summary> {
    outcome
        .groups
        .iter()
        .map(|g| {
            let rows: Vec<&Record> = outcome
                .records
                .iter()
                .filter(|r| same_config(r, &g.config) && r.get("status") == "ok")
                .collect();
            let values = AGGREGATED
                .iter()
                .map(|m| mean_ci(&rows.iter().map(|r| r.num(m)).collect::<Vec<_>>()))
                .collect();
            let first = |c: &str| rows.first().map_or(f64::NAN, |r| r.num(c));
            let flip = flip
                .iter()
                .find(|(c, _)| *c == g.config)
                .map_or((f64::NAN, f64::NAN), |(_, v)| mean_ci(v));
            Summary {
                config: g.config.clone(),
                seeds: rows.len(),
                values,
                exact_width_10_90: first("exact_width_10_90"),
                exact_extent_width: first("exact_extent_width"),
                closed_form_width: first("exact_penumbra_radius") - first("exact_umbra_radius").max(0.0),
                stats: g.clone(),
                timing: outcome.timings.configs.get(&g.key).cloned(),
                rays_per_s: ["rays_per_s", "primary_rays_per_s", "shadow_rays_per_s"].map(first),
                flip,
            }
        })
        .collect()
}

fn same_config(r: &Record, run: &Config) -> bool {
    r.get("scheme") == run.scheme.name()
        && r.get("pattern") == run.pattern.name()
        && r.num("samples") == run.samples as f64
        && r.num("light_radius") == run.light_radius
        && r.num("lights") == run.lights as f64
}

/// The summary of `config`, if swept.
pub fn find<'a>(summaries: &'a [Summary], config: &Config) -> Option<&'a Summary> {
    summaries.iter().find(|s| s.config == *config)
}

/// summary.csv header.
pub fn header() -> Vec<String> {
    let mut h: Vec<String> = [
        "scheme",
        "pattern",
        "samples",
        "light_radius",
        "lights",
        "seeds",
        "exact_extent_width",
        "exact_width_10_90",
    ]
    .map(String::from)
    .to_vec();
    for m in AGGREGATED {
        h.push(format!("{m}_mean"));
        h.push(format!("{m}_ci95"));
    }
    h.extend(
        [
            "frame_ms_median",
            "frame_ms_q1",
            "frame_ms_q3",
            "timed_frames",
            "rays_per_s",
            "primary_rays_per_s",
            "shadow_rays_per_s",
            "bias2",
            "bias2_ci95",
            "variance",
            "pixel_std",
            "flip_mean",
            "flip_ci95",
        ]
        .map(String::from),
    );
    h
}

/// summary.csv row.
pub fn row(s: &Summary) -> Vec<String> {
    let mut r = vec![
        s.config.scheme.to_string(),
        s.config.pattern.to_string(),
        s.config.samples.to_string(),
        num(s.config.light_radius),
        s.config.lights.to_string(),
        s.seeds.to_string(),
        num(s.exact_extent_width),
        num(s.exact_width_10_90),
    ];
    for (m, c) in &s.values {
        r.push(num(*m));
        r.push(num(*c));
    }
    let (q1, med, q3) = s.frame_ms();
    let split = &s.stats.split;
    r.extend([
        num(med),
        num(q1),
        num(q3),
        s.timing
            .as_ref()
            .map_or(String::new(), |t| t.frame_seconds.len().to_string()),
    ]);
    r.extend(s.rays_per_s.map(num));
    r.extend([
        num(split.bias2),
        num(split.bias2_ci),
        num(split.variance),
        num(split.variance.sqrt()),
        num(s.flip.0),
        num(s.flip.1),
    ]);
    r
}
