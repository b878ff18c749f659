//! The sweep expanded into groups of runs, and the keys that tell runs apart across sweeps.

use super::axes::Config;
pub use super::axes::Run;
use super::spec::Spec;
use crate::fingerprint::{build_id, fnv1a};
use crate::metrics::BiasVariance;
use crate::render::AdapterInfo;

/// Runs that differ only by seed: their images give the per-pixel bias/variance split.
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    /// The runs, one per seed, in the experiment's seed order.
    pub runs: Vec<Run>,
}

impl Group {
    /// The group's runs share everything but the seed; this is the first.
    pub fn head(&self) -> &Run {
        &self.runs[0]
    }

    /// The configuration the group's runs share.
    pub fn config(&self) -> Config {
        self.head().config()
    }

    /// Journal key of the group's statistics: a hash of every run's key, so that another seed
    /// list (whose bias/variance split differs) is never taken for this one.
    pub fn key(&self, context: &str) -> String {
        let keys: Vec<String> = self.runs.iter().map(|r| r.key(context)).collect();
        format!("{:016x}", fnv1a(keys.join(",").as_bytes()))
    }
}

/// The per-pixel bias/variance split of one group (the runs of a configuration over its seeds).
#[derive(Clone, Debug, PartialEq)]
pub struct GroupStats {
    /// Key of the group's first run.
    pub key: String,
    /// The group's configuration.
    pub config: Config,
    /// Squared bias with its interval, and variance, over the ground truth's penumbra.
    pub split: BiasVariance,
}

/// The sweep in canonical order (the axes' expansion order, seeds innermost and grouped). The
/// order fixes the row order of runs.csv whatever order work was done in.
pub fn expand(spec: &Spec) -> Vec<Group> {
    spec.axes
        .configs()
        .iter()
        .map(|c| Group {
            runs: spec.axes.seeds.iter().map(|&seed| c.with_seed(seed)).collect(),
        })
        .collect()
}

/// Everything besides the run's own axes that determines its result: the scene file and the
/// content of every file it reads, the measuring view, the ground truth, and the device that
/// renders (another backend or adapter never resumes this one's rows). Timing settings key the
/// timing journal instead (see `timing`), so changing them re-times without re-rendering.
pub fn context_key(spec: &Spec, adapter: &AdapterInfo) -> String {
    let meshes: Vec<String> = spec.scene.meshes().map(|m| format!("{:016x}", m.file_fnv1a)).collect();
    format!(
        "scene={:016x};meshes=[{}];measure={:?};gt={};plane={};device={:?};build={:016x}",
        fnv1a(spec.scene_text.as_bytes()),
        meshes.join(","),
        (&spec.measure.camera, spec.measure.width, spec.measure.height),
        spec.ground_truth.samples,
        spec.measure.plane,
        (&adapter.backend, &adapter.name, &adapter.driver, &adapter.api),
        build_id(),
    )
}

impl Run {
    /// Hash of the run's configuration (scene text, measuring view, ground truth and axes),
    /// keying resumed work: a changed scene or view gives new keys.
    pub fn key(&self, context: &str) -> String {
        let text = format!("{context};{}", self.key_text());
        format!("{:016x}", fnv1a(text.as_bytes()))
    }
}
