//! The experiment file's `kind` key, read with the shared header before the rest of the file to
//! pick the kind that reads it. A file without `kind` is a sweep, the one kind there was before
//! `kind` existed; the shipped files all say theirs.

use serde::{Deserialize, Serialize};

/// An experiment kind, as `kind` names it.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// Sampling schemes swept and measured against a ground truth ([`super::sweep`]).
    #[default]
    Sweep,
    /// Frame rates timed ([`super::fps`]).
    Fps,
    /// Ambient occlusion timed per acceleration structure ([`super::ao`]).
    Ao,
    /// Frames along a camera path timed per acceleration structure ([`super::frames`]).
    Frames,
    /// Real-time pipelines (few rays, accumulated, filtered) judged on the penumbra
    /// ([`super::realtime`]).
    Realtime,
}

impl Kind {
    /// The name in files.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Sweep => "sweep",
            Kind::Fps => "fps",
            Kind::Ao => "ao",
            Kind::Frames => "frames",
            Kind::Realtime => "realtime",
        }
    }

    /// Fewest interleaved rounds behind a reported median: six give a 95 % interval of the
    /// median (its range, 96.9 % coverage; five would cover 93.75 %); a frame-time experiment
    /// takes the median of three per frame and its intervals over frames.
    pub fn min_repeats(self) -> u32 {
        match self {
            Kind::Frames => 3,
            _ => 6,
        }
    }

    /// Rounds when `[timing]` gives none.
    pub fn default_repeats(self) -> u32 {
        self.min_repeats()
    }

    /// Whether `repeats = 0` (nothing timed) is allowed: only for a sweep, whose errors stand
    /// without times (and whose runs.csv is then byte-reproducible); the other kinds exist to
    /// compare times.
    pub fn may_skip_timing(self) -> bool {
        matches!(self, Kind::Sweep)
    }
}
