//! Penumbra's scenes handed to the renderers researchers already trust, and their images judged
//! against penumbra's exact reference: "does it agree with Mitsuba?" answered by measurement.
//!
//! [`mitsuba`] writes a scene and one of its views as a Mitsuba 3 scene file (meshes as PLY,
//! [`ply`]); [`view::ExportedView`] records what was exported, so that [`judge`] can score any
//! renderer's EXR of that view (Mitsuba's, penumbra's own, anyone's) with one code path.

pub mod judge;
pub mod mitsuba;
pub mod panel;
pub mod ply;
pub mod view;

use crate::experiment::outputs::{resolve_home, Outputs};
use crate::files::Refused;
use std::path::Path;

/// Replaces the folder `out` with what `write` puts into the folder it is given, in one step:
/// a failed write leaves the earlier folder whole.
pub fn write_folder(out: &Path, write: impl FnOnce(&Path) -> anyhow::Result<()>) -> anyhow::Result<()> {
    let made = crate::files::missing_folders(out);
    let written = (|| {
        let home = resolve_home(out).map_err(Refused)?;
        let set = Outputs::begin(&home)?;
        write(set.dir())?;
        set.commit()
    })();
    if written.is_err() {
        crate::files::remove_empty(&made);
    }
    written
}

/// Writes `files` (plain relative names, bytes) into `dir`.
pub fn write_files(dir: &Path, files: &[(String, Vec<u8>)]) -> anyhow::Result<()> {
    for (name, bytes) in files {
        let path = dir.join(name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)?;
        }
        crate::files::write_atomic(&path, bytes)?;
    }
    Ok(())
}
