//! The settings each structure of a frame-time experiment is tried at (`[accel.NAME]` lists
//! candidates), and how candidates are tuned (`[tuning]`).

use crate::accel::AccelSettings;
use crate::config::{ConfigError, Seg, Source};
use crate::key_path;
use serde::Deserialize;
use std::collections::BTreeMap;

/// Most tuning cameras per viewpoint.
pub const MAX_TUNING_CAMERAS: u32 = 64;

/// Each structure of `names`, in order, with its candidates: the settings its `[accel.NAME]`
/// table lists (`given`), or its defaults.
pub fn candidates(names: Vec<&'static str>, given: &BTreeMap<&str, Vec<AccelSettings>>) -> Vec<Vec<AccelSettings>> {
    names
        .into_iter()
        .map(|name| match given.get(name) {
            Some(listed) => listed.clone(),
            None => vec![AccelSettings::default_for(
                crate::accel::registered(name).expect("registered"),
            )],
        })
        .collect()
}

/// How a frame-time experiment tunes (`[tuning]`; used only where a structure lists
/// candidates).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(deny_unknown_fields)]
pub struct FramesTuning {
    /// Tuning cameras drawn per viewpoint.
    #[serde(default = "two")]
    pub cameras: u32,
    /// Interleaved rounds per candidate: at least six, the fewest whose order-statistic
    /// interval covers 95 % (the rule's words need it, [`crate::timing::tuning::keep`]).
    #[serde(default = "six")]
    pub repeats: u32,
    /// Seed of the tuning cameras' draws.
    #[serde(default = "tuning_seed")]
    pub seed: u32,
}

impl Default for FramesTuning {
    fn default() -> Self {
        FramesTuning {
            cameras: two(),
            repeats: six(),
            seed: tuning_seed(),
        }
    }
}

fn two() -> u32 {
    2
}

fn six() -> u32 {
    6
}

/// The tuning cameras' seed when the file gives none: apart from any `[path] seed` a file is
/// likely to use.
fn tuning_seed() -> u32 {
    0x7475_6e65
}

impl FramesTuning {
    /// `[tuning]` (`given`, its defaults where absent) for `candidates`, checked; `block` is
    /// `[path] block`.
    pub fn read(
        source: &Source,
        given: Option<FramesTuning>,
        candidates: &[Vec<AccelSettings>],
        block: Option<u32>,
    ) -> Result<FramesTuning, ConfigError> {
        let err = |p: &[Seg], m: String| source.error(p, m);
        let tuning = given.unwrap_or_default();
        if !(1..=MAX_TUNING_CAMERAS).contains(&tuning.cameras) {
            return Err(err(
                &key_path!["tuning", "cameras"],
                format!("tuning cameras per viewpoint: must be in 1..={MAX_TUNING_CAMERAS}"),
            ));
        }
        if !(6..=crate::experiment::header::MAX_REPEATS).contains(&tuning.repeats) {
            return Err(err(
                &key_path!["tuning", "repeats"],
                format!(
                    "must be in 6..={} (the rounds behind each candidate's median and its 95 % interval: fewer cannot give one)",
                    crate::experiment::header::MAX_REPEATS
                ),
            ));
        }
        if given.is_some() && candidates.iter().all(|c| c.len() == 1) {
            return Err(err(
                &key_path!["tuning"],
                "no structure lists candidates to tune: list values in an `[accel.NAME]` table or remove `[tuning]`"
                    .into(),
            ));
        }
        // Tuning times candidates once per unit; blocks of one scene may run on different
        // machines, so what they keep could differ and one scene's frames would mix settings.
        if let (Some(_), Some(listed)) = (block, candidates.iter().find(|c| c.len() > 1)) {
            return Err(err(
                &key_path!["path", "block"],
                format!(
                    "`{}` lists {} candidates to tune, and tuning times them once per unit: blocks of one scene \
                 (which may run on different machines) could keep different ones; give `[accel.{}]` one value \
                 per key (an unblocked run's tuning.csv says which it kept) or remove `block`",
                    listed[0].name,
                    listed.len(),
                    listed[0].name
                ),
            ));
        }
        Ok(tuning)
    }
}
