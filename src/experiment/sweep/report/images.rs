//! The measuring view's images: fig2_measure.png (the schemes at the figure ray count beside the
//! ground truth and the exact image, with error maps) with EXR files of each, and the Fig. 2
//! picture.

use super::pictures::{shown, write_fig2_picture};
use super::results::Results;
use crate::experiment::sweep::runner::{figure_samples, verdict_radius};
use crate::output::images::{diverging, grey, write_exr, Rgb};
use crate::output::plots::{image_grid, ColourBar, Tile};
use std::path::Path;

/// The difference a run's error map shows at full colour.
const RUN_ERROR: f64 = 0.5;
/// The difference the ground truth's error map (against the exact image) shows at full colour.
const TRUTH_ERROR: f64 = 0.005;

/// Writes the images into `dir`.
pub fn write_images(r: &Results, dir: &Path) -> anyhow::Result<()> {
    let spec = r.spec;
    let radius = verdict_radius(spec);
    let n = figure_samples(spec);
    let (w, h) = (spec.measure.width, spec.measure.height);
    let lights = *spec.axes.light_counts.iter().max().expect("validated non-empty");
    if let Some(reference) = r
        .outcome
        .references
        .iter()
        .find(|x| x.light_radius == radius && x.lights == lights)
    {
        let gt = &reference.ground_truth;
        write_exr(&dir.join("ground_truth.exr"), gt, w, h)?;
        let mut tiles: Vec<(String, Rgb)> = Vec::new();
        let mut errors: Vec<(String, Rgb, f64)> = Vec::new();
        for (scheme, pattern) in shown(spec) {
            // The first swept structure's image (every structure's answers are exact, so the
            // images differ only where a structure is wrong, which the tests catch).
            let kept = r.outcome.keep.iter().find(|(c, _)| {
                c.scheme == scheme
                    && c.pattern == pattern
                    && c.light_radius == radius
                    && c.lights == lights
                    && c.accelerator == spec.axes.accelerators[0]
            });
            if let Some((_, img)) = kept {
                write_exr(
                    &dir.join(format!("{}_{pattern}_{n}.exr", scheme.to_string().replace(':', "-"))),
                    img,
                    w,
                    h,
                )?;
                tiles.push((format!("{scheme} ({pattern}), {n} rays"), grey(img, w, h)));
                errors.push((
                    format!("{scheme} ({pattern}) - ground truth"),
                    diverging(img, gt, RUN_ERROR, w, h),
                    RUN_ERROR,
                ));
            }
        }
        tiles.push((
            format!("ground truth, {} rays", spec.ground_truth.samples),
            grey(gt, w, h),
        ));
        if let Some(exact) = &reference.exact {
            write_exr(&dir.join("exact.exr"), exact, w, h)?;
            tiles.push(("exact".into(), grey(exact, w, h)));
            errors.push((
                "ground truth - exact".into(),
                diverging(gt, exact, TRUTH_ERROR, w, h),
                TRUTH_ERROR,
            ));
        }
        let columns = tiles.len().max(errors.len());
        let all: Vec<Tile> = tiles
            .iter()
            .map(|(l, i)| Tile::new(l.clone(), i))
            .chain(errors.iter().map(|(l, i, scale)| Tile {
                bar: Some(ColourBar {
                    scale: *scale,
                    what: "visibility difference".into(),
                }),
                ..Tile::new(l.clone(), i)
            }))
            .collect();
        image_grid(&dir.join("fig2_measure.png"), &all, columns)?;
    }
    if let Some(p) = r.pictures {
        write_fig2_picture(spec, p, spec.axes.seeds[0], &dir.join("fig2_picture.png"))?;
    }
    Ok(())
}
