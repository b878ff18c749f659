//! The part of an experiment that sets acceleration structures against one another, read the
//! same way by every kind that has one (ao, frames): the `structures` list, each structure's
//! `[accel.NAME]` table and the paper's `[claim]`.

use crate::accel::settings::read_tables;
use crate::accel::AccelSettings;
use crate::config::{ConfigError, Source};
use crate::key_path;
use crate::render::limit::{DeviceLimit, Part};
use serde::Deserialize;
use std::collections::BTreeMap;

/// The paper's claim the verdict answers: `subject` is faster than `baseline` (both among
/// `structures`); every other structure is set against `subject` too.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Claim {
    /// The structure the paper proposes.
    pub subject: String,
    /// The paper's baseline.
    pub baseline: String,
}

/// The structures an experiment compares, read and checked together.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// The registered structures, in the order listed.
    pub names: Vec<&'static str>,
    /// The `[accel.NAME]` tables given, each a listed structure's settings (with `lists`, every
    /// candidate its lists spell out).
    pub tables: BTreeMap<&'static str, Vec<AccelSettings>>,
    /// Where each structure's settings are written.
    pub places: SettingsPlaces,
}

/// Where each compared structure's settings are in the experiment file (its `[accel.NAME]`
/// table, or its place in `structures` where it has none), and the keys that set the sizes of
/// the frames it renders, so a refusal known only while the run goes is bad input located there:
/// a kd-tree whose leaves outgrow the memory budget is known only while it builds, a visibility
/// field or frame past the device's binding limit only when it is uploaded, and the file's keys
/// are what to change.
#[derive(Clone, Debug, Default)]
pub struct SettingsPlaces {
    structures: BTreeMap<&'static str, ConfigError>,
    /// Each frame size rendered, with the key that sets it (the first where two keys set one
    /// size): a frame refused is located at the key of its own size, not at another frame's.
    frames: Vec<((u32, u32), ConfigError)>,
}

impl SettingsPlaces {
    /// Each structure's place, and each frame size's ([`SettingsPlaces::with_frame`]).
    pub fn new(
        structures: BTreeMap<&'static str, ConfigError>,
        frames: Vec<((u32, u32), ConfigError)>,
    ) -> SettingsPlaces {
        SettingsPlaces { structures, frames }
    }

    /// These places, with frames of `size` (width, height) set at `place`.
    pub fn with_frame(mut self, size: (u32, u32), place: ConfigError) -> SettingsPlaces {
        self.frames.push((size, place));
        self
    }

    /// The error of a build of `name` refused with `e` (on `what`: a mesh, a scene), at the
    /// place of `name`'s settings; `e` itself where `name` is not compared here.
    pub fn refused(&self, name: &str, what: &str, e: anyhow::Error) -> anyhow::Error {
        match self.error(name, format!("{what}: {e:#}")) {
            Some(located) => located.into(),
            None => e,
        }
    }

    /// The place of `name`'s settings, with `message`.
    pub fn error(&self, name: &str, message: String) -> Option<ConfigError> {
        self.structures.get(name).map(|place| ConfigError {
            message,
            ..place.clone()
        })
    }

    /// The first of `names` without a GPU form ([`crate::accel::Registered::gpu`]), located at
    /// its place in the file: what the GPU backend cannot run ([`crate::experiment::Experiment::gpu_gap`]).
    pub fn gpu_gap<'a>(&self, names: impl IntoIterator<Item = &'a str>) -> Option<String> {
        let name = names
            .into_iter()
            .find(|n| crate::accel::registered(n).is_some_and(|r| !r.gpu))?;
        let message = format!("`{name}` has no GPU form (it runs on the CPU backend only)");
        Some(self.error(name, message.clone()).map_or(message, |e| e.to_string()))
    }

    /// `e` located where it is a device's refusal ([`DeviceLimit`]): a structure's at its
    /// settings, a frame's at the key that set its size; any other error as it is.
    pub fn locate(&self, e: anyhow::Error) -> anyhow::Error {
        match DeviceLimit::part_of(&e) {
            Some(Part::Structure(name)) => self.refused(name, "on this GPU", e),
            Some(Part::Frame { width, height }) => match self.frames.iter().find(|(s, _)| *s == (width, height)) {
                Some((_, place)) => ConfigError {
                    message: format!("{e:#}"),
                    ..place.clone()
                }
                .into(),
                None => e,
            },
            _ => e,
        }
    }
}

impl Comparison {
    /// Reads `structures` (registered names, each once), the `[accel]` tables (each naming a
    /// listed structure; with `lists`, values may be lists of candidates to tune over) and checks
    /// that `claim` names two different listed structures; every error at its key.
    pub fn read(
        source: &Source,
        structures: &[String],
        accel: &BTreeMap<String, toml::Table>,
        claim: &Claim,
        lists: bool,
    ) -> Result<Comparison, ConfigError> {
        let tables = read_tables(source, &key_path!["accel"], accel, lists)?;
        let names = structure_names(source, structures)?;
        if let Some(extra) = tables.keys().find(|k| !names.contains(k)) {
            return Err(source.error(
                &key_path!["accel", *extra],
                format!("`{extra}` is not among `structures`"),
            ));
        }
        for (k, v) in [("subject", &claim.subject), ("baseline", &claim.baseline)] {
            if !names.contains(&v.as_str()) {
                return Err(source.error(&key_path!["claim", k], format!("`{v}` is not among `structures`")));
            }
        }
        if claim.subject == claim.baseline {
            return Err(source.error(&key_path!["claim", "baseline"], "must differ from `subject`"));
        }
        let places = names
            .iter()
            .enumerate()
            .map(|(i, &name)| {
                let at = if tables.contains_key(name) {
                    key_path!["accel", name]
                } else {
                    key_path!["structures", i]
                };
                (name, source.error(&at, String::new()))
            })
            .collect();
        Ok(Comparison {
            names,
            tables,
            places: SettingsPlaces::new(places, vec![]),
        })
    }
}

/// The registered structures a `structures` list names, each once; an unknown or repeated name
/// is an error at its place in the list.
fn structure_names(source: &Source, names: &[String]) -> Result<Vec<&'static str>, ConfigError> {
    if names.is_empty() {
        return Err(source.error(&key_path!["structures"], "name at least one structure"));
    }
    let mut out = Vec::new();
    for (i, s) in names.iter().enumerate() {
        let at = key_path!["structures", i];
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
