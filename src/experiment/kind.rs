//! The experiment file's `kind` key, read before the rest of the file to pick the kind that
//! reads it. A file without `kind` is a sweep, the one kind there was before `kind` existed; the
//! shipped files all say theirs.

use crate::config::{ConfigError, Source};
use serde::Deserialize;

/// An experiment kind, as `kind` names it.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
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
}

impl Kind {
    /// The kind `source` declares, if it has a `kind` key; an unknown kind is an error located
    /// at that key.
    pub fn declared(source: &Source) -> Result<Option<Kind>, ConfigError> {
        #[derive(Deserialize)]
        struct Header {
            kind: Option<Kind>,
        }
        Ok(source.parse::<Header>()?.kind)
    }
}
