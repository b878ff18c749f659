//! What a finished sweep hands to its report, and its part of manifest.toml.

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

/// The sweep's part of manifest.toml (the driver writes the rest): its runs, seeds,
/// ground-truth settings and the render plan of its fullest run.
pub fn details(r: &Results) -> toml::Table {
    let s = r.spec;
    let mut t = toml::Table::new();
    let mut put = |k: &str, v: toml::Value| {
        t.insert(k.to_string(), v);
    };
    put("runs", (r.outcome.records.len() as i64).into());
    put("failed_runs", (r.outcome.failures as i64).into());
    put(
        "seeds",
        toml::Value::Array(s.axes.seeds.iter().map(|&x| toml::Value::from(x as i64)).collect()),
    );
    put("ground_truth_samples", (s.ground_truth.samples as i64).into());
    put(
        "ground_truth_seed",
        (crate::experiment::sweep::reference::GROUND_TRUTH_SEED as i64).into(),
    );
    put("plan", r.outcome.plan.to_string().trim().to_string().into());
    t
}
