//! summary.csv: the runs of each configuration aggregated over seeds (means with 95 % CIs), its
//! frame time (median and 95 % interval of its interleaved timed frames), the per-pixel bias/variance
//! split of the group, and the perceptual error (FLIP) of its Fig. 2 picture where it has one.

use crate::experiment::sweep::axes::Config;
use crate::experiment::sweep::record::{Aggregated, Metrics, Record, Status};
use crate::experiment::sweep::run::GroupStats;
use crate::experiment::sweep::runner::Outcome;
use crate::experiment::sweep::timing::ConfigTiming;
use crate::metrics::stats::{mean_ci, MeanCi};
use crate::output::table::float;
use crate::sampling::DiskScheme;
use crate::timing::{Estimate, FRAME_S};
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
    /// Median frame time with its 95 % interval, seconds (NaN when untimed).
    pub frame: Estimate,
    /// Rays one frame traced (first seed), where it rendered.
    pub rays: Option<u64>,
    /// What one frame's queries cost (first seed), where the backend counts it.
    pub work: Option<crate::accel::work::Work>,
    /// Rays per second at the median frame time: all, primary, shadow.
    pub rays_per_s: [f64; 3],
    /// FLIP of its pictures over seeds (NaN without pictures).
    pub flip: MeanCi,
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
                frame: outcome
                    .timings
                    .configs
                    .get(&g.key)
                    .map_or(Estimate::NAN, ConfigTiming::frame),
                rays: first.and_then(|r| Some(r.rays.primary_rays? + r.rays.shadow_rays?)),
                work: first.and_then(|r| {
                    let c = &r.rays;
                    Some(crate::accel::work::Work {
                        queries: c.queries?,
                        nodes: c.nodes_visited?,
                        primitives: c.primitive_tests?,
                    })
                }),
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

/// The schemes the summaries hold, in the experiment's order (built-ins and points files alike:
/// every table, plot and picture lists what was swept).
pub fn swept_schemes(summaries: &[Summary]) -> Vec<DiskScheme> {
    let mut out: Vec<DiskScheme> = Vec::new();
    for s in summaries {
        if !out.contains(&s.config.scheme) {
            out.push(s.config.scheme);
        }
    }
    out
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

/// The columns after the frame time.
#[derive(Serialize)]
struct Tail {
    timed_frames: Option<usize>,
    queries: Option<u64>,
    nodes_visited: Option<u64>,
    primitive_tests: Option<u64>,
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
        let split = &self.stats.split;
        let [rays_per_s, primary_rays_per_s, shadow_rays_per_s] = self.rays_per_s;
        let tail = Tail {
            timed_frames: self.timing.as_ref().map(|t| t.frame_seconds.len()),
            queries: self.work.map(|w| w.queries),
            nodes_visited: self.work.map(|w| w.nodes),
            primitive_tests: self.work.map(|w| w.primitives),
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
        (&self.config, head, &self.metrics, self.frame.columns(FRAME_S), tail).serialize(s)
    }
}
