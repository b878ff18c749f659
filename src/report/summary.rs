//! summary.csv: the runs of each configuration aggregated over seeds, means with 95 % CIs,
//! and the per-pixel bias/variance split of the group.

use crate::experiment::run::num;
use crate::experiment::runner::{GroupStats, Outcome};
use crate::experiment::{Record, Run};
use crate::metrics::stats::mean_ci;
use crate::sampling::{DiskScheme, Pattern};

/// Metrics aggregated as mean and CI half-width.
pub const AGGREGATED: [&str; 14] = [
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
    "frame_ms",
    "rays_per_s",
    "primary_rays_per_s",
    "shadow_rays_per_s",
];

/// One configuration (all axes but the seed) summarised.
#[derive(Clone, Debug)]
pub struct Summary {
    /// The configuration (seed of its first run).
    pub run: Run,
    /// Seeds that rendered.
    pub seeds: usize,
    /// (mean, ci95 half-width) per [`AGGREGATED`] metric.
    pub values: Vec<(f64, f64)>,
    /// Exact 10-90 width and extent width of the configuration's light radius.
    pub exact_width_10_90: f64,
    /// Exact extent width (r_p - r_u from the exact image).
    pub exact_extent_width: f64,
    /// Bias/variance split.
    pub stats: GroupStats,
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
}

fn index(name: &str) -> usize {
    AGGREGATED.iter().position(|m| *m == name).expect("aggregated metric")
}

/// Summaries of every group of the outcome, in canonical order.
pub fn summarise(outcome: &Outcome) -> Vec<Summary> {
    outcome
        .groups
        .iter()
        .map(|g| {
            let rows: Vec<&Record> = outcome
                .records
                .iter()
                .filter(|r| same_config(r, &g.run) && r.get("status") == "ok")
                .collect();
            let values = AGGREGATED
                .iter()
                .map(|m| mean_ci(&rows.iter().map(|r| r.num(m)).collect::<Vec<_>>()))
                .collect();
            let first = |c: &str| rows.first().map_or(f64::NAN, |r| r.num(c));
            Summary {
                run: g.run,
                seeds: rows.len(),
                values,
                exact_width_10_90: first("exact_width_10_90"),
                exact_extent_width: first("exact_extent_width"),
                stats: g.clone(),
            }
        })
        .collect()
}

fn same_config(r: &Record, run: &Run) -> bool {
    r.get("scheme") == run.scheme.name()
        && r.get("pattern") == run.pattern.name()
        && r.num("samples") == run.samples as f64
        && r.num("light_radius") == run.light_radius
        && r.num("lights") == run.lights as f64
}

/// The summary of one configuration, if swept.
pub fn find(
    summaries: &[Summary],
    scheme: DiskScheme,
    pattern: Pattern,
    samples: u32,
    radius: f64,
    lights: u32,
) -> Option<&Summary> {
    summaries.iter().find(|s| {
        let r = &s.run;
        r.scheme == scheme
            && r.pattern == pattern
            && r.samples == samples
            && r.light_radius == radius
            && r.lights == lights
    })
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
    h.extend(["bias2", "variance", "pixel_std"].map(String::from));
    h
}

/// summary.csv row.
pub fn row(s: &Summary) -> Vec<String> {
    let mut r = vec![
        s.run.scheme.to_string(),
        s.run.pattern.to_string(),
        s.run.samples.to_string(),
        num(s.run.light_radius),
        s.run.lights.to_string(),
        s.seeds.to_string(),
        num(s.exact_extent_width),
        num(s.exact_width_10_90),
    ];
    for (m, c) in &s.values {
        r.push(num(*m));
        r.push(num(*c));
    }
    r.extend([num(s.stats.bias2), num(s.stats.variance), num(s.stats.variance.sqrt())]);
    r
}
