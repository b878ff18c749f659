//! What a scene asks of ambient occlusion (the visibility-field paper's Section 7 workload): how
//! many directions per camera hit, how they are chosen, how they are weighted and how far they
//! look. Only a scene with an `[ambient_occlusion]` table gets the pass.

use crate::accel::vlf::directions::Directions;
use crate::sampling::DiskScheme;
use glam::DVec3;
use serde::Deserialize;
use std::sync::Arc;

/// How the directions are weighted into one value per receiver.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Weighting {
    /// The fraction of unoccluded directions, uniform by solid angle: the paper's AO. Next to
    /// a sphere it is cos(alpha) (FACTS.md).
    #[default]
    Plain,
    /// The cosine-weighted unoccluded fraction, (1/pi) of the integral of V cos: the diffuse
    /// view of the sky.
    Cosine,
}

impl Weighting {
    /// Its name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Weighting::Plain => "plain",
            Weighting::Cosine => "cosine",
        }
    }
}

/// Where the directions come from.
#[derive(Clone, Debug)]
pub enum AoDirections {
    /// The visibility field's own direction set (level L: 2 L^2 + 1 lines; 16 gives the paper's
    /// 513), each line oriented into the receiver normal's hemisphere.
    Grid {
        /// Subdivision level.
        level: u32,
        /// The unit directions (z >= 0), in the field's order.
        lines: Arc<Vec<DVec3>>,
    },
    /// Points of a disk scheme lifted to the hemisphere: Malley's vertical projection
    /// (cosine-distributed) for cosine weighting, the equal-area lift (uniform by solid angle)
    /// for plain weighting, so each weighting is a plain mean of its rays.
    Disk(DiskScheme),
}

impl AoDirections {
    /// The grid of `level`.
    pub fn grid(level: u32) -> AoDirections {
        let d = Directions::new(level);
        let lines = (0..d.len() as u32).map(|k| d.direction(k)).collect();
        AoDirections::Grid {
            level,
            lines: Arc::new(lines),
        }
    }

    /// A few words for plans and reports.
    pub fn describe(&self) -> String {
        match self {
            AoDirections::Grid { level, lines } => format!("grid level {level} ({} lines)", lines.len()),
            AoDirections::Disk(s) => format!("{s} lifted"),
        }
    }
}

/// The ambient-occlusion pass a scene asks for.
#[derive(Clone, Debug)]
pub struct AmbientOcclusion {
    /// Where the directions come from.
    pub directions: AoDirections,
    /// Rays per receiver (the grid's line count for a grid).
    pub rays: u32,
    /// How they are weighted.
    pub weighting: Weighting,
    /// Occluders farther than this do not count (infinite: no limit).
    pub max_distance: f64,
    /// How the rays are issued: receiver by receiver, or a grid line's rays of many receivers
    /// as one bundle on the CPU and one dispatch per direction on the GPU
    /// ([`crate::accel::Issue`]). The image is the same either way.
    pub issue: crate::accel::Issue,
}

/// Level of the grid with `rays` lines (`2 L^2 + 1`), if any in 1..=64.
pub fn grid_level(rays: u32) -> Option<u32> {
    (1..=64).find(|l| 2 * l * l + 1 == rays)
}
