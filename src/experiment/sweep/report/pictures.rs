//! The Fig. 2 pictures as a person sees them: tone-mapped with the ground-truth picture's
//! exposure, tiled into fig2_picture.png, and each measured against the ground-truth picture
//! with FLIP (Andersson et al. 2020), the perceptual stand-in for the paper's "equal quality".

use super::summary::PictureFlip;
use crate::experiment::sweep::pictures::{Picture, Pictures};
use crate::experiment::sweep::Spec;
use crate::metrics::flip::{flip_mean, PIXELS_PER_DEGREE};
use crate::output::images::{exposure, tonemap_with, Rgb};
use crate::output::plots::{image_grid, Tile};
use crate::sampling::{DiskScheme, Pattern};
use std::path::Path;

fn display(p: &Picture, p99: f64) -> Rgb {
    tonemap_with(&p.radiance, p.width, p.height, p99)
}

/// Mean FLIP of every picture against the ground-truth picture, per configuration, one value per
/// seed in seed order.
pub fn picture_flip(pictures: &Pictures) -> anyhow::Result<PictureFlip> {
    let gt = &pictures.ground_truth;
    let p99 = exposure(&gt.radiance);
    let reference = display(gt, p99);
    let mut out = PictureFlip::new();
    for (run, p) in &pictures.runs {
        let test = display(p, p99);
        let e = flip_mean(
            &reference.data,
            &test.data,
            reference.width,
            reference.height,
            PIXELS_PER_DEGREE,
        )?;
        let config = run.config();
        match out.iter_mut().find(|(c, _)| *c == config) {
            Some((_, seeds)) => seeds.push(e),
            None => out.push((config, vec![e])),
        }
    }
    Ok(out)
}

/// The (scheme, pattern) pairs the Fig. 2 images show, in order: the verdict's subject
/// (per-pixel, then shared), its baseline, then every other swept scheme per-pixel; only what
/// was swept.
pub fn shown(spec: &Spec) -> Vec<(DiskScheme, Pattern)> {
    let (subject, baseline) = spec.verdict;
    let mut out = vec![
        (subject, Pattern::PerPixel),
        (subject, Pattern::Shared),
        (baseline, Pattern::PerPixel),
    ];
    out.extend(
        spec.axes
            .schemes
            .iter()
            .filter(|&&s| s != subject && s != baseline)
            .map(|&s| (s, Pattern::PerPixel)),
    );
    out.retain(|(s, p)| spec.axes.schemes.contains(s) && spec.axes.patterns.contains(p));
    out
}

/// fig2_picture.png: the [`shown`] schemes at the first seed, and the ground truth, all at the
/// ground truth's exposure.
pub fn write_fig2_picture(spec: &Spec, pictures: &Pictures, seed: u32, path: &Path) -> anyhow::Result<()> {
    let gt = &pictures.ground_truth;
    let p99 = exposure(&gt.radiance);
    let mut tiles: Vec<(String, Rgb)> = Vec::new();
    for (scheme, pattern) in shown(spec) {
        let found = pictures
            .runs
            .iter()
            .find(|(r, _)| r.scheme == scheme && r.pattern == pattern && r.seed == seed);
        if let Some((_, p)) = found {
            tiles.push((format!("{scheme} ({pattern}), {} rays", p.samples), display(p, p99)));
        }
    }
    tiles.push((
        format!("jittered (ground truth), {} rays", gt.samples),
        display(gt, p99),
    ));
    let refs: Vec<Tile> = tiles.iter().map(|(l, i)| Tile::new(l.clone(), i)).collect();
    image_grid(path, &refs, 2)
}
