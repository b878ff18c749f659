//! The sweep's images: every scheme x pattern of the measuring view at the figure ray count with
//! the ground truth and the exact image, and the Fig. 2 pictures, each as EXR (the values) and
//! PNG (what the page shows), gathered into the page's galleries; plus the grids
//! fig2_measure.png (with error maps and their colour bars) and fig2_picture.png. The Fig. 2
//! pictures are shown as a person sees them: tone-mapped with the ground-truth picture's exposure,
//! and each measured against the ground-truth picture with FLIP (Andersson et al. 2020), the
//! perceptual stand-in for the paper's "equal quality".

use super::results::Results;
use super::summary::PictureFlip;
use crate::experiment::sweep::pictures::{Picture, Pictures};
use crate::experiment::sweep::Spec;
use crate::metrics::flip::{flip_mean, PIXELS_PER_DEGREE};
use crate::output::images::{diverging, exposure, grey, tonemap_with, Rgb};
use crate::output::page::{write_shots, Gallery, Shot, Tone};
use crate::output::plots::{image_grid, ColourBar, Tile};
use crate::output::table::cells;
use crate::sampling::{DiskScheme, Pattern};
use std::path::Path;

/// The difference a run's error map shows at full colour.
const RUN_ERROR: f64 = 0.5;
/// The difference the ground truth's error map (against the exact image) shows at full colour.
const TRUTH_ERROR: f64 = 0.005;

/// A file name part for a scheme (`points:NAME` has a colon no file system likes).
fn file_part(scheme: &impl ToString) -> String {
    scheme.to_string().replace(':', "-")
}

/// Writes the images into `dir` (the folder's images/) and returns the page's galleries.
pub fn write_images(r: &Results, dir: &Path) -> anyhow::Result<Vec<Gallery>> {
    let mut galleries = Vec::new();
    if let Some(g) = measuring_view(r)? {
        write_shots(dir.parent().expect("images/ is inside the results folder"), &g)?;
        write_measure_grid(r, &g, &dir.join("fig2_measure.png"))?;
        galleries.push(g);
    }
    if let Some(p) = r.pictures {
        let g = pictures_gallery(r, p)?;
        write_shots(dir.parent().expect("images/ is inside the results folder"), &g)?;
        galleries.push(g);
        write_fig2_picture(r.spec, p, r.spec.axes.seeds[0], &dir.join("fig2_picture.png"))?;
    }
    Ok(galleries)
}

/// The measuring view at the verdict's light radius with every light on: each swept scheme and
/// pattern at the figure ray count (the first swept structure's image; every structure's answers
/// are exact, which the tests check), then the ground truth (the gallery's reference) and the
/// exact image.
fn measuring_view(r: &Results) -> anyhow::Result<Option<Gallery>> {
    let spec = r.spec;
    let radius = spec.verdict_radius();
    let n = spec.figure_samples();
    let lights = *spec.axes.light_counts.iter().max().expect("validated non-empty");
    let Some(reference) = r
        .outcome
        .references
        .iter()
        .find(|x| x.light_radius == radius && x.lights == lights)
    else {
        return Ok(None);
    };
    let mut shots = Vec::new();
    for &scheme in &spec.axes.schemes {
        for &pattern in &spec.axes.patterns {
            let kept = r.outcome.keep.iter().find(|(c, _)| {
                c.scheme == scheme
                    && c.pattern == pattern
                    && c.samples == n
                    && c.light_radius == radius
                    && c.lights == lights
                    && c.accelerator == spec.axes.accelerators[0]
            });
            if let Some((config, img)) = kept {
                let stem = format!("images/{}_{pattern}_{n}", file_part(&scheme));
                shots.push(Shot {
                    label: format!("{scheme} ({pattern}), {n} rays"),
                    exr: format!("{stem}.exr"),
                    png: format!("{stem}.png"),
                    values: img.clone(),
                    key: cells(config)?,
                });
            }
        }
    }
    let plain = |label: String, stem: &str, values: &Vec<f32>| Shot {
        label,
        exr: format!("images/{stem}.exr"),
        png: format!("images/{stem}.png"),
        values: values.clone(),
        key: vec![],
    };
    shots.push(plain(
        format!("ground truth, {} rays", spec.ground_truth.samples),
        "ground_truth",
        &reference.ground_truth,
    ));
    let gt = shots.len() - 1;
    if let Some(exact) = &reference.exact {
        shots.push(plain("exact".into(), "exact", exact));
    }
    Ok(Some(Gallery {
        title: format!("measuring view: {n} rays, light radius {radius} m, {lights} light(s)"),
        width: spec.measure.width,
        height: spec.measure.height,
        tone: Tone::Linear,
        reference: Some(gt),
        against: None,
        shots,
    }))
}

/// fig2_measure.png: the schemes [`shown`] beside the ground truth and the exact image, with
/// their signed errors underneath, each with its colour bar.
fn write_measure_grid(r: &Results, g: &Gallery, path: &Path) -> anyhow::Result<()> {
    let (w, h) = (g.width, g.height);
    let n = r.spec.figure_samples();
    let gt = &g.shots[g.reference.expect("the measuring view has a reference")];
    let mut tiles: Vec<(String, Rgb)> = Vec::new();
    let mut errors: Vec<(String, Rgb, f64)> = Vec::new();
    for (scheme, pattern) in shown(r.spec) {
        let label = format!("{scheme} ({pattern}), {n} rays");
        if let Some(s) = g.shots.iter().find(|s| s.label == label) {
            tiles.push((label, grey(&s.values, w, h)));
            errors.push((
                format!("{scheme} ({pattern}) - ground truth"),
                diverging(&s.values, &gt.values, RUN_ERROR, w, h),
                RUN_ERROR,
            ));
        }
    }
    tiles.push((gt.label.clone(), grey(&gt.values, w, h)));
    if let Some(exact) = g.shots.iter().find(|s| s.label == "exact") {
        tiles.push(("exact".into(), grey(&exact.values, w, h)));
        errors.push((
            "ground truth - exact".into(),
            diverging(&gt.values, &exact.values, TRUTH_ERROR, w, h),
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
    image_grid(path, &all, columns)
}

/// The Fig. 2 pictures at the first seed, tone-mapped with the ground-truth picture's exposure,
/// the ground truth last (the gallery's reference, against which FLIP is measured).
fn pictures_gallery(r: &Results, p: &crate::experiment::sweep::pictures::Pictures) -> anyhow::Result<Gallery> {
    let seed = r.spec.axes.seeds[0];
    let gt = &p.ground_truth;
    let mut shots: Vec<Shot> = p
        .runs
        .iter()
        .filter(|(run, _)| run.seed == seed && run.accelerator == r.spec.axes.accelerators[0])
        .map(|(run, pic)| {
            let stem = format!(
                "images/picture_{}_{}_{}",
                file_part(&run.scheme),
                run.pattern,
                pic.samples
            );
            Shot {
                label: format!("picture: {} ({}), {} rays", run.scheme, run.pattern, pic.samples),
                exr: format!("{stem}.exr"),
                png: format!("{stem}.png"),
                values: pic.radiance.clone(),
                key: vec![],
            }
        })
        .collect();
    shots.push(Shot {
        label: format!("picture: jittered (ground truth), {} rays", gt.samples),
        exr: "images/picture_ground_truth.exr".into(),
        png: "images/picture_ground_truth.png".into(),
        values: gt.radiance.clone(),
        key: vec![],
    });
    Ok(Gallery {
        title: format!("Fig. 2 pictures, seed {seed} (radiance)"),
        width: gt.width,
        height: gt.height,
        tone: Tone::Radiance {
            p99: exposure(&Tone::radiance_stored(&gt.radiance)),
        },
        reference: Some(shots.len() - 1),
        against: None,
        shots,
    })
}

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
