//! The registry of kinds: [`load`] reads an experiment file's shared header, and its `kind`
//! ([`Kind`]) picks the kind that reads the rest. The one place that names every kind.

use super::contract::Experiment;
use super::header::Header;
use super::kind::Kind;
use super::{ao, core, fps, frames, realtime, sweep};
use crate::config::{ConfigError, Source};
use std::path::Path;

/// Reads an experiment file of any kind: the shared header first, then the kind's own keys.
pub fn load(path: &Path) -> Result<Box<dyn Experiment>, ConfigError> {
    let source = Source::read(path)?;
    let header = Header::read(&source)?;
    Ok(match header.kind {
        Kind::Sweep => Box::new(core::Declared(sweep::Sweep::new(sweep::Spec::from_source(
            &source, header,
        )?))),
        Kind::Fps => Box::new(core::Declared(fps::FpsSpec::from_source(&source, header)?)),
        Kind::Ao => Box::new(core::Declared(ao::AoSpec::from_source(&source, header)?)),
        Kind::Frames => Box::new(core::Declared(frames::FramesSpec::from_source(&source, header)?)),
        Kind::Realtime => Box::new(core::Declared(realtime::Realtime::new(
            realtime::RealtimeSpec::from_source(&source, header)?,
        ))),
    })
}
