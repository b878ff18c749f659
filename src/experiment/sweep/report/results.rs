//! What a finished sweep hands to its report.

use crate::experiment::sweep::pictures::Pictures;
use crate::experiment::sweep::runner::Outcome;
use crate::experiment::sweep::Spec;
use crate::render::AdapterInfo;

/// Everything a sweep produced, ready to write.
pub struct Results<'a> {
    /// The experiment.
    pub spec: &'a Spec,
    /// The sweep's outcome.
    pub outcome: &'a Outcome,
    /// Fig. 2-style pictures, when the experiment has `[figures]`.
    pub pictures: Option<&'a Pictures>,
    /// The device.
    pub adapter: &'a AdapterInfo,
    /// Seconds the run has taken so far.
    pub seconds: f64,
}
