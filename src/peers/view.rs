//! The record an export leaves beside its scene file (`view.toml`): which scene, camera, size
//! and pixel filter an image of the exported view must have, so a judged image is refused when
//! it is not one.

use crate::files::Refused;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// How a renderer turns radiance into a pixel value, which the reference must match: penumbra
/// traces one camera ray through each pixel's centre; Mitsuba's box filter averages uniform
/// positions over the pixel's square.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum PixelFilter {
    /// The value at the pixel's centre.
    Centre,
    /// The mean over the pixel's square.
    Box,
}

impl PixelFilter {
    /// The name the files write (`centre`, `box`).
    pub fn name(self) -> &'static str {
        match self {
            PixelFilter::Centre => "centre",
            PixelFilter::Box => "box",
        }
    }
}

/// What was exported: enough to rebuild the exact reference of the view.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExportedView {
    /// The penumbra scene file, as given to the export (relative paths from the working folder
    /// the export ran in are made absolute).
    pub scene: PathBuf,
    /// FNV-1a of the scene file's bytes at export: a judged image of an edited scene is refused.
    pub scene_fnv1a: String,
    /// The camera's name in the scene.
    pub camera: String,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// The plane whose pixels are judged (counting planes only; 0 is the first).
    pub plane: usize,
    /// The pixel filter the exported renderer applies.
    pub pixel: PixelFilter,
    /// Where the exported renderer starts shadow rays ([`super::judge::Lift`]): `none` (on the
    /// surface, penumbra) or `mitsuba3`; images are judged against the exact answer and, where
    /// this is not `none`, against the answer for their renderer's own lift too.
    pub lift: String,
}

/// File name of the record in an export folder.
pub const FILE: &str = "view.toml";

impl ExportedView {
    /// Reads a record, naming the file and the key of any error.
    pub fn read(path: &Path) -> anyhow::Result<ExportedView> {
        let text = crate::files::read_regular_text_at_most(path, 1 << 16)?;
        toml::from_str(&text).map_err(|e| {
            let at = e
                .span()
                .map(|s| {
                    let line = text[..s.start].matches('\n').count() + 1;
                    format!(", line {line}")
                })
                .unwrap_or_default();
            Refused(format!("{}{at}: {}", path.display(), e.message())).into()
        })
    }

    /// The record as a file's text.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a view serialises")
    }

    /// The scene's fingerprint as recorded.
    pub fn fingerprint(bytes: &[u8]) -> String {
        format!("{:016x}", crate::fingerprint::fnv1a(bytes))
    }
}
