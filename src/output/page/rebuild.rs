//! A results folder's page rebuilt from its files alone (the `page` binary): for a folder written
//! before its kind wrote pages, or after the page itself changed. What the report step knows and
//! the files do not is named from the files instead: each EXR under images/ is an image labelled
//! by its file name, grouped with the others of its size; `ground_truth` (or
//! `picture_ground_truth`) is its group's reference; `picture_*` and `strip_*` hold radiance, the
//! rest values in [0, 1]; each strip's frames (`strip_SHADING_FRAME`) are a group of their own,
//! shown at the exposure of its first frame, as the frames kind drew their PNGs, and set against
//! the next strip of its size and length. A missing PNG beside an EXR is drawn from it.

use super::MAX_TEXT_BYTES;
use super::{files_in, write_stored, Gallery, Page, Shot, Tone};
use crate::files::{read_regular_text_at_most, Refused};
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
        let listed = files_in(dir, sub, suffix)?;
        // Texts the page embeds are read now too: one that is not UTF-8 is refused before any
        // picture is drawn.
        if matches!(suffix, ".csv" | ".svg") {
            for file in &listed {
                read_regular_text_at_most(&dir.join(file), MAX_TEXT_BYTES)?;
            }
        }
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
    let report = read_regular_text_at_most(&dir.join("report.md"), MAX_TEXT_BYTES)?;
    let mut galleries: Vec<Gallery> = Vec::new();
    // Numbers in file names in their order (frame 8 before frame 16).
    let mut exrs = files_in(dir, "images", ".exr")?;
    exrs.sort_by_cached_key(|e| natural(e));
    let stems: Vec<String> = exrs
        .iter()
        .map(|e| e.trim_start_matches("images/").trim_end_matches(".exr").to_string())
        .collect();
    // Each gallery's family: a strip's frames (`strip_SHADING_FRAME`) are one gallery per strip,
    // since each strip's PNGs were drawn at its own exposure; the images that share a prefix
    // with a `PREFIX_brute` or `PREFIX_exact` beside them (one mesh's structures, one variant's
    // filters) are one gallery with it; every other image is grouped by size and kind alone.
    let mut families: Vec<String> = Vec::new();
    for (exr, stem) in exrs.into_iter().zip(&stems) {
        let (values, width, height) = read_exr(&dir.join(&exr))?;
        let radiance = stem.starts_with("picture_") || stem.starts_with("strip_");
        let family = family(stem, &stems);
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
                } else if family.starts_with("strip ") {
                    format!("{family} frames")
                } else {
                    format!("{family}: {width}x{height} images")
                },
                width,
                height,
                tone: if radiance {
                    Tone::Radiance { p99: 1.0 }
                } else {
                    Tone::Linear
                },
                reference: None,
                against: None,
                shots: vec![shot],
            }),
        }
        if families.len() < galleries.len() {
            families.push(family);
        }
    }
    // Each strip's frames against the next strip's (the same frames under the other shading).
    let strips: Vec<usize> = (0..galleries.len())
        .filter(|&i| families[i].starts_with("strip "))
        .collect();
    for (k, &i) in strips.iter().enumerate() {
        let next = strips[(k + 1) % strips.len()];
        let (a, b) = (&galleries[i], &galleries[next]);
        if next != i && b.shots.len() == a.shots.len() && (b.width, b.height) == (a.width, a.height) {
            galleries[i].against = Some(next);
        }
    }
    for (g, family) in galleries.iter_mut().zip(&families) {
        let own = |what: &str| format!("{} {what}", family.replace('_', " "));
        g.reference = g
            .shots
            .iter()
            .position(|s| s.label == "ground truth" || s.label == "picture ground truth")
            .or_else(|| {
                g.shots
                    .iter()
                    .position(|s| !family.is_empty() && (s.label == own("brute") || s.label == own("exact")))
            });
        if let Tone::Radiance { p99 } = &mut g.tone {
            *p99 = exposure(&g.shots[g.reference.unwrap_or(0)].values);
        }
        for s in &g.shots {
            if !dir.join(&s.png).exists() {
                write_png(&dir.join(&s.png), &g.tone.picture(&s.values, g.width, g.height))?;
            }
        }
    }
    // Pictures are stored at half precision where their EXRs are (every value a half float);
    // a folder written before they were keeps its full-precision values, so that the page
    // reads out what the files hold.
    let half: Vec<bool> = galleries
        .iter()
        .map(|g| {
            g.half()
                && g.shots.iter().all(|s| {
                    s.values
                        .iter()
                        .all(|&v| v.is_nan() || half::f16::from_f32(v).to_f32().to_bits() == v.to_bits())
                })
        })
        .collect();
    let name = dir
        .file_name()
        .map_or("results".into(), |n| n.to_string_lossy().into_owned());
    write_stored(
        dir,
        &Page {
            title: format!("{name} (page rebuilt from the folder's files)"),
            report,
            galleries,
        },
        &half,
    )
}

/// An image's family (see [`rebuild`]): `strip SHADING` for a strip's frame, else the longest
/// prefix (cut at an underscore) that has a `PREFIX_brute` or `PREFIX_exact` among `stems`,
/// else none.
fn family(stem: &str, stems: &[String]) -> String {
    if let Some((strip, _)) = stem.strip_prefix("strip_").and_then(|s| s.rsplit_once('_')) {
        return format!("strip {strip}");
    }
    let has = |name: String| stems.contains(&name);
    stem.match_indices('_')
        .map(|(i, _)| &stem[..i])
        .rfind(|p| has(format!("{p}_brute")) || has(format!("{p}_exact")))
        .unwrap_or("")
        .to_string()
}

/// A file name as a sort key in which each run of digits compares as a number.
fn natural(name: &str) -> Vec<(u128, String)> {
    let mut key = Vec::new();
    let mut rest = name;
    while !rest.is_empty() {
        let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
        let (part, tail) = if digits > 0 {
            rest.split_at(digits)
        } else {
            rest.split_at(rest.find(|c: char| c.is_ascii_digit()).unwrap_or(rest.len()))
        };
        key.push(if digits > 0 {
            (part.parse().unwrap_or(u128::MAX), String::new())
        } else {
            (0, part.to_string())
        });
        rest = tail;
    }
    key
}

/// Refuses an EXR whose header promises more than the page could hold, reading the header
/// only: a side or pixel count past what an experiment writes ([`MAX_IMAGE_SIDE`],
/// [`MAX_IMAGE_PIXELS`]), decoded samples, their f32 copy and the picture drawn from them past
/// the memory this process may still take ([`crate::accel::memory::available`]), or a file
/// longer than its declared pixels stored raw, plus an eighth and a MiB (a sparse file of
/// gigabytes behind a small header). A compressed file a few MB long can declare gigabytes of
/// pixels.
fn check_exr_header(path: &Path, file: &std::fs::File) -> anyhow::Result<()> {
    use crate::config::{MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE};
    let meta = exr::meta::MetaData::read_from_buffered(std::io::BufReader::new(file), false)
        .map_err(|e| Refused(format!("{}: not a readable EXR image: {e}", path.display())))?;
    let mut raw = 0u64;
    for header in &meta.headers {
        let (w, h) = (header.layer_size.width() as u64, header.layer_size.height() as u64);
        if w > MAX_IMAGE_SIDE as u64 || h > MAX_IMAGE_SIDE as u64 || w * h > MAX_IMAGE_PIXELS {
            return Err(Refused(format!(
                "{}: a {w} x {h} image; refused before reading (results images are at most \
                 {MAX_IMAGE_SIDE} pixels a side and {MAX_IMAGE_PIXELS} pixels)",
                path.display()
            ))
            .into());
        }
        let stored = w * h * header.channels.bytes_per_pixel as u64;
        raw += stored;
        // Decoded samples, the f32 values and the 8-bit picture drawn from them.
        let need = stored + w * h * (4 + 4);
        if let Some(budget) = crate::accel::memory::available().filter(|b| need > b.bytes) {
            return Err(Refused(format!(
                "{}: a {w} x {h} image needs {} to read, more than {}; refused before reading",
                path.display(),
                crate::accel::memory::bytes(need),
                budget.describe()
            ))
            .into());
        }
    }
    let len = file.metadata()?.len();
    let most = raw + raw / 8 + (1 << 20);
    if len > most {
        return Err(Refused(format!(
            "{}: {len} bytes, more than an EXR of the size its header declares takes ({most}); refused before reading",
            path.display()
        ))
        .into());
    }
    Ok(())
}

/// The first valid layer of the EXR at `path`, every channel, its header checked first
/// ([`check_exr_header`]); a file that is not a readable EXR is refused with its path.
pub(crate) fn read_exr_layer(
    path: &Path,
) -> anyhow::Result<exr::prelude::Image<exr::prelude::Layer<exr::prelude::AnyChannels<exr::prelude::FlatSamples>>>> {
    use exr::prelude::*;
    use std::io::{Read, Seek};
    let mut file = crate::files::open_regular(path)?;
    check_exr_header(path, &file)?;
    let mut bytes = Vec::new();
    file.rewind()
        .and_then(|_| file.read_to_end(&mut bytes))
        .with_context(|| format!("reading {}", path.display()))?;
    read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| Refused(format!("{}: not a readable EXR image: {e}", path.display())).into())
}

/// A one-channel EXR's values, width and height ([`read_exr_layer`]).
fn read_exr(path: &Path) -> anyhow::Result<(Vec<f32>, u32, u32)> {
    let img = read_exr_layer(path)?;
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
