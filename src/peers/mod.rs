//! Penumbra's scenes handed to the renderers researchers already trust, and their images judged
//! against penumbra's exact reference: "does it agree with Mitsuba?" answered by measurement.
//!
//! [`mitsuba`] and [`pbrt`] write a scene and one of its views as a Mitsuba 3 or pbrt-v4 scene
//! file (meshes as PLY, [`ply`]; what both share in [`export`]); [`view::ExportedView`] records what was exported, so that [`judge`] can score any
//! renderer's EXR of that view (Mitsuba's, penumbra's own, anyone's) with one code path.

pub mod export;
pub mod judge;
pub mod mitsuba;
pub mod panel;
pub mod pbrt;
pub mod ply;
pub mod view;

use crate::experiment::outputs::{resolve_home, Outputs};
use crate::files::Refused;
use crate::scene::Scene;
use std::path::Path;

/// Refuses effects beyond direct lighting with shadows (mirrors, ambient occlusion, shading
/// without shadow rays): an exported file would simulate them otherwise than penumbra, and the
/// exact reference has no answer for them.
pub fn refuse_unmatched_effects(scene: &Scene, name: &Path) -> anyhow::Result<()> {
    let unmatched = if scene.has_mirrors() {
        Some("mirror reflections (a mirror weight above zero)")
    } else if scene.ambient.is_some() {
        Some("ambient occlusion")
    } else if !scene.shading.shadows {
        Some("shading without shadow rays")
    } else {
        None
    };
    match unmatched {
        Some(what) => Err(Refused(format!(
            "{}: asks for {what}, which neither an exported file nor the exact reference simulates as penumbra does; export and judge scenes of direct lighting with shadows",
            name.display()
        ))
        .into()),
        None => Ok(()),
    }
}

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
