//! Experiments, one module per kind, each with its spec, runner and report: [`sweep`] (sampling
//! schemes swept and measured against a ground truth), [`fps`] (the paper's frame rates),
//! [`ao`] (the visibility-field paper's ambient-occlusion table) and [`frames`] (its frame-time
//! figures: scaling, walkthrough, dynamic scenes). An experiment file names its kind with
//! `kind` ([`kind`]).

pub mod ao;
pub mod fps;
pub mod frames;
pub mod kind;
pub mod sweep;

use crate::config::{ConfigError, Source};
use kind::Kind;
use std::path::Path;

/// An experiment file, read by its kind.
pub enum Experiment {
    /// `kind = "sweep"`, or no `kind`.
    Sweep(Box<sweep::Spec>),
    /// `kind = "fps"`.
    Fps(fps::FpsSpec),
    /// `kind = "ao"`.
    Ao(ao::AoSpec),
    /// `kind = "frames"`.
    Frames(frames::FramesSpec),
}

impl Experiment {
    /// Reads and validates an experiment file of any kind.
    pub fn load(path: &Path) -> Result<Experiment, ConfigError> {
        let source = Source::read(path)?;
        let declared = Kind::declared(&source)?;
        match declared.unwrap_or_default() {
            Kind::Sweep => sweep::Spec::from_source(&source)
                .map(|s| Experiment::Sweep(Box::new(s)))
                .map_err(|e| if declared.is_none() { read_as_sweep(e) } else { e }),
            Kind::Fps => fps::FpsSpec::from_source(&source).map(Experiment::Fps),
            Kind::Ao => ao::AoSpec::from_source(&source).map(Experiment::Ao),
            Kind::Frames => frames::FramesSpec::from_source(&source).map(Experiment::Frames),
        }
    }
}

/// A key a sweep does not know, in a file without `kind`, may be another kind's: says how the
/// file was read.
fn read_as_sweep(mut e: ConfigError) -> ConfigError {
    if e.message.starts_with("unknown field") {
        e.message +=
            " (a file without `kind` is read as kind = \"sweep\"; a frame-rate experiment says kind = \"fps\")";
    }
    e
}

/// The registered structures an experiment's `structures` list names, each once; an unknown or
/// repeated name is an error at its place in the list.
pub(crate) fn structure_names(source: &Source, names: &[String]) -> Result<Vec<&'static str>, ConfigError> {
    if names.is_empty() {
        return Err(source.error(&crate::key_path!["structures"], "name at least one structure"));
    }
    let mut out = Vec::new();
    for (i, s) in names.iter().enumerate() {
        let at = crate::key_path!["structures", i];
        let r = crate::accel::registered(s).ok_or_else(|| {
            source.error(
                &at,
                format!(
                    "unknown acceleration structure `{s}`; known: {}",
                    crate::accel::names().join(", ")
                ),
            )
        })?;
        if out.contains(&r.name) {
            return Err(source.error(&at, format!("`{s}` is listed twice")));
        }
        out.push(r.name);
    }
    Ok(out)
}
