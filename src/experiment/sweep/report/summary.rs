//! summary.csv: the runs of each configuration aggregated over seeds (means with 95 % CIs), its
//! frame time (median and quartiles of its interleaved timed frames), the per-pixel bias/variance
//! split of the group, and the perceptual error (FLIP) of its Fig. 2 picture where it has one.

use crate::experiment::sweep::axes::Config;
use crate::experiment::sweep::record::{Aggregated, Metrics, Record, Status};
use crate::experiment::sweep::run::GroupStats;
use crate::experiment::sweep::runner::Outcome;
use crate::experiment::sweep::timing::ConfigTiming;
use crate::metrics::stats::{mean_ci, MeanCi};
use crate::output::table::float;
use serde::{Serialize, Serializer};

/// FLIP of each seed's picture, per configuration that has pictures.
pub type PictureFlip = Vec<(Config, Vec<f64>)>;

/// One configuration (all axes but the seed) summarised: a row of summary.csv.
#[derive(Clone, Debug)]
pub struct Summary {
    /// The configuration.
    pub config: Config,
    /// Seeds that rendered.
    pub seeds: usize,
    /// The runs' metrics over those seeds.
    pub metrics: Aggregated,
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
    /// FLIP of its pictures over seeds (NaN without pictures).
    pub flip: MeanCi,
}

impl Summary {
    /// First quartile, median and third quartile of the frame time (ms); NaN when untimed.
    pub fn frame_ms(&self) -> (f64, f64, f64) {
        self.timing
            .as_ref()
            .map_or((f64::NAN, f64::NAN, f64::NAN), ConfigTiming::frame_ms)
    }
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
                .filter(|r| r.status == Status::Ok && r.run.config() == g.config)
                .collect();
            let metrics: Vec<&Metrics> = rows.iter().map(|r| &r.metrics).collect();
            let first = rows.first();
            let radial = |f: fn(&Record) -> f64| first.map_or(f64::NAN, |r| f(r));
            let flip = flip
                .iter()
                .find(|(c, _)| *c == g.config)
                .map_or(MeanCi::NAN, |(_, v)| mean_ci(v));
            Summary {
                config: g.config.clone(),
                seeds: rows.len(),
                metrics: Metrics::aggregate(&metrics),
                exact_width_10_90: radial(|r| r.radial.exact_width_10_90),
                exact_extent_width: radial(|r| r.radial.exact_extent_width),
                closed_form_width: radial(|r| r.radial.exact_penumbra_radius)
                    - radial(|r| r.radial.exact_umbra_radius).max(0.0),
                stats: g.clone(),
                timing: outcome.timings.configs.get(&g.key).cloned(),
                rays_per_s: [
                    radial(|r| r.time.rays_per_s),
                    radial(|r| r.time.primary_rays_per_s),
                    radial(|r| r.time.shadow_rays_per_s),
                ],
                flip,
            }
        })
        .collect()
}

/// The summary of `config`, if swept.
pub fn find<'a>(summaries: &'a [Summary], config: &Config) -> Option<&'a Summary> {
    summaries.iter().find(|s| s.config == *config)
}

/// The columns after the configuration's.
#[derive(Serialize)]
struct Head {
    seeds: usize,
    #[serde(with = "float")]
    exact_extent_width: f64,
    #[serde(with = "float")]
    exact_width_10_90: f64,
}

/// The columns after the aggregated metrics.
#[derive(Serialize)]
struct Tail {
    #[serde(with = "float")]
    frame_ms_median: f64,
    #[serde(with = "float")]
    frame_ms_q1: f64,
    #[serde(with = "float")]
    frame_ms_q3: f64,
    timed_frames: Option<usize>,
    #[serde(with = "float")]
    rays_per_s: f64,
    #[serde(with = "float")]
    primary_rays_per_s: f64,
    #[serde(with = "float")]
    shadow_rays_per_s: f64,
    #[serde(with = "float")]
    bias2: f64,
    #[serde(with = "float")]
    bias2_ci95: f64,
    #[serde(with = "float")]
    variance: f64,
    #[serde(with = "float")]
    pixel_std: f64,
    #[serde(with = "float")]
    flip_mean: f64,
    #[serde(with = "float")]
    flip_ci95: f64,
}

/// A row of summary.csv: the configuration's axes, then the summary's columns.
impl Serialize for Summary {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let head = Head {
            seeds: self.seeds,
            exact_extent_width: self.exact_extent_width,
            exact_width_10_90: self.exact_width_10_90,
        };
        let (q1, med, q3) = self.frame_ms();
        let split = &self.stats.split;
        let [rays_per_s, primary_rays_per_s, shadow_rays_per_s] = self.rays_per_s;
        let tail = Tail {
            frame_ms_median: med,
            frame_ms_q1: q1,
            frame_ms_q3: q3,
            timed_frames: self.timing.as_ref().map(|t| t.frame_seconds.len()),
            rays_per_s,
            primary_rays_per_s,
            shadow_rays_per_s,
            bias2: split.bias2,
            bias2_ci95: split.bias2_ci,
            variance: split.variance,
            pixel_std: split.variance.sqrt(),
            flip_mean: self.flip.mean,
            flip_ci95: self.flip.ci95,
        };
        (&self.config, head, &self.metrics, tail).serialize(s)
    }
}
