//! What each unit of a sweep yields, as journaled by the experiment core: a configuration's
//! runs over every seed ([`GroupOutcome`]), the Fig. 2 pictures
//! ([`super::pictures::Pictures`]), or every configuration's frame times ([`TimingOutcome`]).

use super::pictures::Pictures;
use super::record::{Record, Status};
use super::timing::ConfigTiming;
use crate::metrics::BiasVariance;
use crate::output::table::{csv_text, f32_hex};
use serde::{Deserialize, Serialize};

/// One unit's outcome.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum UnitOutcome {
    /// A configuration measured over its seeds.
    Group(GroupOutcome),
    /// The Fig. 2 pictures (none without `[figures]`).
    Pictures(Option<Pictures>),
    /// The timing phase.
    Timing(TimingOutcome),
}

/// A configuration measured over every seed: its runs.csv rows, the per-pixel bias/variance
/// split of its images, and what the figures keep of it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GroupOutcome {
    /// One record per seed, in seed order; failed runs included.
    #[serde(with = "csv_text")]
    pub records: Vec<Record>,
    /// Squared bias and variance over the seeds that rendered.
    pub split: BiasVariance,
    /// At the figures' ray count, when any seed rendered.
    pub figure: Option<Figure>,
}

impl GroupOutcome {
    /// Runs that failed.
    pub fn failed(&self) -> usize {
        self.records.iter().filter(|r| r.status != Status::Ok).count()
    }
}

/// What the report's figures take from a group at the figures' ray count: the measuring image
/// of its first rendered seed and, on on-axis scenes, the bin means of its seed-averaged radial
/// profile (the rest of a profile follows from the image and the receivers).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Figure {
    /// Measuring-view visibility of the first rendered seed.
    #[serde(with = "f32_hex")]
    pub image: Vec<f32>,
    /// [`crate::metrics::RadialProfile::mean`] over the group's seeds, on on-axis scenes.
    pub profile_means: Option<Vec<f64>>,
}

/// Every configuration timed in one interleaved phase, in the sweep's canonical order, and the
/// A/A control: the configuration (an index into that order) timed a second time per round.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct TimingOutcome {
    /// Per configuration, in canonical order.
    pub configs: Vec<ConfigTiming>,
    /// The A/A control's configuration index and its second series of frames.
    pub noise: Option<(usize, ConfigTiming)>,
}
