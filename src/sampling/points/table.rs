//! The experiment file's side of a points set: its `[points.NAME]` table, checked key by key
//! into [`Settings`] and loaded for every `points:NAME` scheme a sweep lists.

use super::{Domain, Layout, PointSet, PointsId, Settings, MAX_TILE};
use crate::config::{ConfigError, Source};
use crate::key_path;
use crate::sampling::DiskScheme;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A `[points.NAME]` table: the file (relative to the experiment) a `points:NAME` scheme reads
/// and how.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Table {
    /// The points file.
    pub path: PathBuf,
    /// `square` (default; mapped to the disk by the concentric map) or `disk`.
    #[serde(default)]
    pub domain: Option<String>,
    /// `shared` (default), `tile` or `mask`.
    #[serde(default)]
    pub layout: Option<String>,
    /// The tile's side in pixels (`tile` and `mask` layouts).
    pub tile: Option<u32>,
    /// The mask file (`mask` layout), relative to the experiment.
    pub mask: Option<PathBuf>,
}

/// Loads the set of every `points:NAME` in `schemes` from its `[points.NAME]` table (paths
/// relative to the experiment), checking it holds `needed` samples per pixel; a table no scheme
/// names is an error too (a misspelt name would otherwise be silently unused).
pub fn load_all(
    source: &Source,
    schemes: &mut [DiskScheme],
    tables: &BTreeMap<String, Table>,
    needed: u32,
) -> Result<(), ConfigError> {
    let dir = source.path.parent().unwrap_or(Path::new("."));
    for name in tables.keys() {
        let listed = schemes.iter().any(|s| s.to_string() == format!("points:{name}"));
        if !listed {
            return Err(source.error(
                &key_path!["points", name.as_str()],
                format!("no `points:{name}` in sweep.schemes uses this table"),
            ));
        }
    }
    for (i, scheme) in schemes.iter_mut().enumerate() {
        let DiskScheme::Points(_) = scheme else { continue };
        let label = scheme.to_string();
        let name = &label["points:".len()..];
        let Some(t) = tables.get(name) else {
            return Err(source.error(
                &key_path!["sweep", "schemes", i],
                format!("`{label}` needs a [points.{name}] table with the file's `path`"),
            ));
        };
        let at = |key: &str| key_path!["points", name, key];
        let domain = match t.domain.as_deref() {
            None | Some("square") => Domain::Square,
            Some("disk") => Domain::Disk,
            Some(other) => {
                return Err(source.error(&at("domain"), format!("`{other}`: expected \"square\" or \"disk\"")))
            }
        };
        let side = |what: &str| match t.tile {
            Some(side) if (1..=MAX_TILE).contains(&side) => Ok(side),
            Some(side) => Err(source.error(&at("tile"), format!("tile side must be in 1..={MAX_TILE}, got {side}"))),
            None => Err(source.error(
                &at("layout"),
                format!("the {what} layout needs `tile`, the tile's side in pixels"),
            )),
        };
        let layout = match t.layout.as_deref() {
            None | Some("shared") => Layout::Shared,
            Some("tile") => Layout::Tile(side("tile")?),
            Some("mask") => Layout::Mask(side("mask")?),
            Some(other) => {
                return Err(source.error(
                    &at("layout"),
                    format!("`{other}`: expected \"shared\", \"tile\" or \"mask\""),
                ))
            }
        };
        if matches!(layout, Layout::Mask(_)) != t.mask.is_some() {
            return Err(source.error(
                &at("mask"),
                "a mask file goes with layout = \"mask\", and only with it".to_string(),
            ));
        }
        if matches!(layout, Layout::Shared) && t.tile.is_some() {
            return Err(source.error(&at("tile"), "a shared set has no tile".to_string()));
        }
        let settings = Settings {
            path: dir.join(&t.path),
            domain,
            layout,
            mask: t.mask.as_ref().map(|m| dir.join(m)),
        };
        let set = PointSet::load(name, &settings, needed)?;
        *scheme = DiskScheme::Points(PointsId::install(set).map_err(|e| source.error(&at("path"), e))?);
    }
    Ok(())
}
