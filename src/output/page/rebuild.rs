//! A results folder's page rebuilt from its files alone (the `page` binary): for a folder written
//! before its kind wrote pages, or after the page itself changed. What the report step knows and
//! the files do not is named from the files instead: each EXR under images/ is an image labelled
//! by its file name, grouped with the others of its size; `ground_truth` (or
//! `picture_ground_truth`) is its group's reference; `picture_*` and `strip_*` hold radiance, the
//! rest values in [0, 1]; each strip's frames (`strip_SHADING_FRAME`) are a group of their own,
//! shown at the exposure of its first frame, as the frames kind drew their PNGs. A missing PNG
//! beside an EXR is drawn from it.

use super::{files_in, write, Gallery, Page, Shot, Tone};
use crate::files::{read_regular, read_regular_text, Refused};
use crate::output::images::{exposure, write_png};
use anyhow::Context;
use std::path::Path;

/// Rebuilds `dir`/index.html and page_data.js from the folder's files.
pub fn rebuild(dir: &Path) -> anyhow::Result<()> {
    if std::fs::symlink_metadata(dir.join("report.md")).is_err() {
        return Err(Refused(format!("{}: no report.md (is this a results folder?)", dir.display())).into());
    }
    // Everything the page will read is checked before anything is written.
    for (sub, suffix) in [
        ("", ".csv"),
        ("images", ".exr"),
        ("images", ".png"),
        ("plots", ".png"),
        ("plots", ".svg"),
    ] {
        files_in(dir, sub, suffix)?;
    }
    for written in ["index.html", "page_data.js"] {
        if std::fs::symlink_metadata(dir.join(written)).is_ok_and(|m| m.is_dir()) {
            return Err(Refused(format!(
                "{}: a folder where the page is written; refused",
                dir.join(written).display()
            ))
            .into());
        }
    }
    let report = read_regular_text(&dir.join("report.md"))?;
    let mut galleries: Vec<Gallery> = Vec::new();
    // Each gallery's family: a strip's frames (`strip_SHADING_FRAME`) are one gallery per strip,
    // since each strip's PNGs were drawn at its own exposure; every other image is grouped by
    // size and kind alone.
    let mut families: Vec<String> = Vec::new();
    for exr in files_in(dir, "images", ".exr")? {
        let (values, width, height) = read_exr(&dir.join(&exr))?;
        let stem = exr.trim_start_matches("images/").trim_end_matches(".exr").to_string();
        let radiance = stem.starts_with("picture_") || stem.starts_with("strip_");
        let family = match stem.strip_prefix("strip_").and_then(|s| s.rsplit_once('_')) {
            Some((strip, _)) => format!("strip {strip}"),
            None => String::new(),
        };
        let shot = Shot {
            label: stem.replace('_', " "),
            png: exr.replace(".exr", ".png"),
            exr,
            values,
            key: vec![],
        };
        match galleries.iter_mut().zip(&families).find(|(g, f)| {
            g.width == width
                && g.height == height
                && matches!(g.tone, Tone::Radiance { .. }) == radiance
                && **f == family
        }) {
            Some((g, _)) => g.shots.push(shot),
            None => galleries.push(Gallery {
                title: if family.is_empty() {
                    format!("{width}x{height} images")
                } else {
                    format!("{family} frames")
                },
                width,
                height,
                tone: if radiance {
                    Tone::Radiance { p99: 1.0 }
                } else {
                    Tone::Linear
                },
                reference: None,
                shots: vec![shot],
            }),
        }
        if families.len() < galleries.len() {
            families.push(family);
        }
    }
    for g in &mut galleries {
        g.reference = g
            .shots
            .iter()
            .position(|s| s.label == "ground truth" || s.label == "picture ground truth");
        if let Tone::Radiance { p99 } = &mut g.tone {
            *p99 = exposure(&g.shots[g.reference.unwrap_or(0)].values);
        }
        for s in &g.shots {
            if !dir.join(&s.png).exists() {
                write_png(&dir.join(&s.png), &g.tone.picture(&s.values, g.width, g.height))?;
            }
        }
    }
    let name = dir
        .file_name()
        .map_or("results".into(), |n| n.to_string_lossy().into_owned());
    write(
        dir,
        &Page {
            title: format!("{name} (page rebuilt from the folder's files)"),
            report,
            galleries,
        },
    )
}

/// A one-channel EXR's values, width and height.
fn read_exr(path: &Path) -> anyhow::Result<(Vec<f32>, u32, u32)> {
    use exr::prelude::*;
    let bytes = read_regular(path)?;
    let img = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| Refused(format!("{}: not a readable EXR image: {e}", path.display())))?;
    let size = img.layer_data.size;
    let channel = img
        .layer_data
        .channel_data
        .list
        .first()
        .with_context(|| format!("{}: no channel", path.display()))?;
    Ok((
        channel.sample_data.values_as_f32().collect(),
        size.width() as u32,
        size.height() as u32,
    ))
}
