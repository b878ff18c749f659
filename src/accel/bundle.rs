//! Ray bundles: coherent any-hit queries issued together, so a structure can share the work of
//! rays that visit the same nodes (the visibility-field paper's open question, Section 9: both
//! algorithms with ray bundling). Ambient occlusion along the field's grid lines issues one
//! stored direction for many receivers at once ([`crate::render::ambient`]); each structure
//! answers a bundle its own way ([`super::Accelerator::any_hits`]), with the same answers as
//! one ray at a time.

use glam::DVec3;

/// One any-hit query of a bundle: a segment `origin + t dir`, `0 < t < tmax`, ignoring
/// triangle `skip`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Query {
    /// Origin.
    pub origin: DVec3,
    /// Unit direction.
    pub dir: DVec3,
    /// End of the segment.
    pub tmax: f64,
    /// A triangle to ignore (the receiver's own), or `u32::MAX`.
    pub skip: u32,
}

/// How a pass issues its rays: one receiver's rays after another, or as bundles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Issue {
    /// Each receiver's rays in turn, one query at a time (the paper's measurement).
    #[default]
    Single,
    /// Direction-major bundles: for each direction, that direction's rays of many receivers,
    /// answered by [`super::Accelerator::any_hits`].
    Bundled,
}

impl Issue {
    /// `single` or `bundled`, as files and tables write it.
    pub fn name(self) -> &'static str {
        match self {
            Issue::Single => "single",
            Issue::Bundled => "bundled",
        }
    }

    /// `structure` as tables and legends name it with its rays issued this way.
    pub fn label(self, structure: &str) -> String {
        match self {
            Issue::Single => structure.to_string(),
            Issue::Bundled => format!("{structure} bundled"),
        }
    }
}
