//! A pipeline's identity: the variant it runs on, its scheme and rays, the frames accumulated,
//! how they are accumulated and the filter. Every table and picture of the kind is keyed by it,
//! in this column order; a run adds its seed. The timing unit times a pipeline's parts, keyed
//! by [`Slot`]: a render of (scheme, rays), or a filter.

use super::spec::Variant;
use crate::render::denoise::{Accumulation, Filter};
use crate::sampling::DiskScheme;
use serde::{Deserialize, Serialize};

/// One pipeline at one frame count, as the tables name it (the first columns of runs.csv and
/// summary.csv).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Pipeline {
    /// `static` or `moving`.
    pub variant: String,
    /// Disk scheme (empty for the reference picture).
    pub scheme: String,
    /// Shadow rays per pixel per light per frame.
    pub rays: u32,
    /// Frames accumulated.
    pub frames: u32,
    /// `mean`, `ema` or `clamped`.
    pub accumulation: String,
    /// Reconstruction filter, or [`REFERENCE`] for the reference picture.
    pub filter: String,
}

/// The `filter` of the picture that holds the reference itself (exact, or the high-sample
/// render where the scene has none).
pub const REFERENCE: &str = "reference";

impl Pipeline {
    /// The pipeline of these axis values.
    pub fn new(
        variant: Variant,
        scheme: DiskScheme,
        rays: u32,
        frames: u32,
        accumulation: Accumulation,
        filter: Filter,
    ) -> Pipeline {
        Pipeline {
            variant: variant.name().into(),
            scheme: scheme.name().into(),
            rays,
            frames,
            accumulation: accumulation.name().into(),
            filter: filter.name().into(),
        }
    }

    /// The key of the reference picture of `variant` after `frames`.
    pub fn reference(variant: Variant, frames: u32) -> Pipeline {
        Pipeline {
            variant: variant.name().into(),
            scheme: String::new(),
            rays: 0,
            frames,
            accumulation: String::new(),
            filter: REFERENCE.into(),
        }
    }

    /// The same pipeline on `variant` after `frames`.
    pub fn at(&self, variant: Variant, frames: u32) -> Pipeline {
        Pipeline {
            variant: variant.name().into(),
            frames,
            ..self.clone()
        }
    }

    /// Whether it runs on `variant`.
    pub fn on(&self, variant: Variant) -> bool {
        self.variant == variant.name()
    }

    /// How the report names it: `SCHEME x RAYS ray(s), FRAMES frame(s), ACCUMULATION, FILTER`.
    pub fn label(&self) -> String {
        format!(
            "{} x {} ray(s), {} frame(s), {}, {}",
            self.scheme, self.rays, self.frames, self.accumulation, self.filter
        )
    }
}

/// One timed part of a frame, as timings.csv's first columns name it: a render of (scheme,
/// rays), or a filter.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Slot {
    /// `render` or `filter`.
    pub what: String,
    /// A render's scheme.
    pub scheme: String,
    /// A render's rays per pixel.
    pub rays: u32,
    /// A filter's name.
    pub filter: String,
}

impl Slot {
    /// The render of `rays` rays of `scheme`.
    pub fn render(scheme: &str, rays: u32) -> Slot {
        Slot {
            what: "render".into(),
            scheme: scheme.into(),
            rays,
            filter: String::new(),
        }
    }

    /// The filter `filter`.
    pub fn filter(filter: &str) -> Slot {
        Slot {
            what: "filter".into(),
            scheme: String::new(),
            rays: 0,
            filter: filter.into(),
        }
    }
}
