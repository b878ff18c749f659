//! What stands for a manifest in a folder of judged peers' images (`judge`'s output): the
//! build and the scene file that made it, which the freshness check reads as it reads an
//! experiment's manifest; no experiment file made such a folder.

use super::{Build, Input};
use serde::{Deserialize, Serialize};

/// The build and inputs of a judged folder.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Provenance {
    /// The judge's build.
    pub build: Build,
    /// The shadow-ray lifts judged under.
    pub lifts: Vec<String>,
    /// The scene file (the one input in the repository).
    pub inputs: Vec<Input>,
    /// The judged images (made outside the repository, named for the record).
    pub images: Vec<Input>,
}

/// File name of [`Provenance`] in a judged folder.
pub const PROVENANCE: &str = "provenance.toml";
