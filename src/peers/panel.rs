//! A set of images of one exported view judged together against each reference asked for (one
//! per pixel filter the images' exports record and shadow-ray lift), with what the judge
//! writes: judge.csv (one row per image and lift), groups.csv (per group of seeds), profile.csv
//! and profile.png (mean signed error across the exact edge), report.md, the references as
//! EXRs, and provenance.toml ([`Provenance`]: the build and the scene file that made it).

use super::judge::{error_profile, judge, read_radiance, summarise, GroupSummary, Judgement, Lift, Reference};
use super::view::{ExportedView, PixelFilter, FILE};
use crate::experiment::manifest::{Build, Input, Provenance, PROVENANCE};
use crate::files::Refused;
use crate::output::plots::{line_panels, Axes, Panel as PlotPanel, Point, Series, LOOKS};
use crate::scene::Scene;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// One group of seeds under one reference: the reference's index in [`Panel::references`], the
/// summary, and the mean signed error across the exact edge ([`error_profile`]).
pub type Group = (usize, GroupSummary, Vec<(f64, f64)>);

/// Every image judged, under every lift.
pub struct Panel {
    /// The view all images share.
    pub view: ExportedView,
    /// The lifts judged under: none, and each image's renderer's own.
    pub lifts: Vec<Lift>,
    /// One reference per (filter, lift) used.
    pub references: Vec<(PixelFilter, Lift, Reference)>,
    /// Per image and lift: the reference's index, the scores and the image as a visible fraction.
    pub judged: Vec<(usize, Judgement, Vec<f32>)>,
    /// The scene file as read.
    pub scene_input: Input,
    /// The images as read.
    pub image_inputs: Vec<Input>,
}

impl Panel {
    /// Judges `images` (each beside its export's view.toml; one scene, camera and size; no file
    /// or file name twice, since a name is a seed of its group) against the exact answer and,
    /// where an image's export records a shadow-ray lift, against the answer for that lift too.
    pub fn judge(images: &[PathBuf]) -> anyhow::Result<Panel> {
        let mut views = Vec::new();
        let mut lifts = vec![Lift::None];
        let mut seen: Vec<(PathBuf, std::ffi::OsString)> = Vec::new();
        for image in images {
            let canonical = image.canonicalize().unwrap_or_else(|_| image.clone());
            let name = image.file_name().map(|n| n.to_os_string()).unwrap_or_default();
            if let Some((earlier, _)) = seen.iter().find(|(c, n)| *c == canonical || *n == name) {
                return Err(Refused(format!(
                    "{}: given twice, or named as {} is (an image's name is a seed of its group); give each image once, named apart",
                    image.display(),
                    earlier.display()
                ))
                .into());
            }
            seen.push((canonical, name));
            let record = image.parent().unwrap_or(Path::new(".")).join(FILE);
            if !record.is_file() {
                return Err(Refused(format!(
                    "{}: no {FILE} beside it; judge images in the folder of the export that made their view",
                    image.display()
                ))
                .into());
            }
            let view = ExportedView::read(&record)?;
            let lift: Lift = view
                .lift
                .parse()
                .map_err(|e| Refused(format!("{}: `lift`: {e}", record.display())))?;
            if !lifts.contains(&lift) {
                lifts.push(lift);
            }
            views.push((view, lift));
        }
        let own_lifts: Vec<Lift> = views.iter().map(|v| v.1).collect();
        let views: Vec<ExportedView> = views.into_iter().map(|v| v.0).collect();
        let first = views
            .first()
            .cloned()
            .ok_or_else(|| Refused("no images to judge".into()))?;
        for (v, image) in views.iter().zip(images) {
            let same = (&v.scene, &v.scene_fnv1a, &v.camera, v.width, v.height, v.plane)
                == (
                    &first.scene,
                    &first.scene_fnv1a,
                    &first.camera,
                    first.width,
                    first.height,
                    first.plane,
                );
            if !same {
                return Err(Refused(format!(
                    "{}: its view ({}, camera `{}`, {} x {}) is not {}'s ({}, camera `{}`, {} x {}); judge one view at a time",
                    image.display(),
                    v.scene.display(),
                    v.camera,
                    v.width,
                    v.height,
                    images[0].display(),
                    first.scene.display(),
                    first.camera,
                    first.width,
                    first.height
                ))
                .into());
            }
        }
        let bytes = crate::files::read_regular(&first.scene)?;
        if ExportedView::fingerprint(&bytes) != first.scene_fnv1a {
            return Err(Refused(format!(
                "{}: changed since the export (FNV-1a {} then, {} now); export and render the view again",
                first.scene.display(),
                first.scene_fnv1a,
                ExportedView::fingerprint(&bytes)
            ))
            .into());
        }
        let scene = Scene::load(&first.scene)?;
        let mut radiance = Vec::new();
        for image in images {
            radiance.push(read_radiance(image, &first)?);
        }
        let mut references: Vec<(PixelFilter, Lift, Reference)> = Vec::new();
        let mut judged = Vec::new();
        for &lift in &lifts {
            for (((v, image), l), own) in views.iter().zip(images).zip(&radiance).zip(&own_lifts) {
                if lift != Lift::None && lift != *own {
                    continue;
                }
                let k = match references.iter().position(|(f, g, _)| *f == v.pixel && *g == lift) {
                    Some(k) => k,
                    None => {
                        references.push((v.pixel, lift, Reference::exact(&scene, &first, v.pixel, lift)?));
                        references.len() - 1
                    }
                };
                let reference = &references[k].2;
                let name = image
                    .file_name()
                    .map_or_else(|| image.display().to_string(), |n| n.to_string_lossy().into_owned());
                let fraction = reference.fraction_of(l, &image.display().to_string())?;
                judged.push((k, judge(reference, v.pixel, lift, &name, &fraction)?, fraction));
            }
        }
        Ok(Panel {
            scene_input: Input::read(&first.scene)?,
            image_inputs: images.iter().map(|i| Input::read(i)).collect::<std::io::Result<_>>()?,
            view: first,
            lifts,
            references,
            judged,
        })
    }

    /// Per reference, its groups' summaries and error profiles, in the order images were given.
    pub fn groups(&self) -> Vec<Group> {
        let mut out = Vec::new();
        for (k, (_, _, reference)) in self.references.iter().enumerate() {
            let of: Vec<(Judgement, Vec<f32>)> = self
                .judged
                .iter()
                .filter(|(r, _, _)| *r == k)
                .map(|(_, j, f)| (j.clone(), f.clone()))
                .collect();
            for s in summarise(reference, &of) {
                let fractions: Vec<&[f32]> = of
                    .iter()
                    .filter(|(j, _)| j.group == s.group)
                    .map(|(_, f)| f.as_slice())
                    .collect();
                let profile = error_profile(reference, &fractions);
                out.push((k, s, profile));
            }
        }
        out
    }

    /// The report: what was judged and one table row per group and reference.
    pub fn report(&self, groups: &[Group]) -> String {
        let v = &self.view;
        let mut r = format!(
            "# Judged against the exact reference\n\nScene `{}` (FNV-1a {}), camera `{}`, {} x {} pixels, plane {}. Each image's \
             radiance is divided by the exact unoccluded radiance of its pixel and compared with the exact fraction \
             (irradiance-weighted), under the pixel filter its export records, for shadow rays from the surface (lift `none`, \
             as penumbra traces them) and, for a renderer whose export records one, from its own lift \
             (`mitsuba3`: Mitsuba 3's offset along the normal). The penumbra is the \
             exact image's (fraction strictly between 0.001 and 0.999); widths are across the exact edge, in pixels; FLIP is \
             LDR (8-bit grey) at 67.02 pixels per degree; intervals are 95 % over seeds. The mean signed error's shape across \
             the edge is in profile.csv (profile.png).\n\n",
            self.scene_input.path, v.scene_fnv1a, v.camera, v.width, v.height, v.plane
        );
        r.push_str(
            "| group | filter | lift | seeds | penumbra RMSE | mean signed error | 10-90 % width (px) | exact width (px) | lit level | FLIP | bias^2 | variance |\n",
        );
        r.push_str("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
        for (k, s, _) in groups {
            let (filter, lift, _) = &self.references[*k];
            let _ = writeln!(
                r,
                "| {} | {} | {} | {} | {:.5} +- {:.5} | {:+.5} +- {:.5} | {:.3} +- {:.3} | {:.3} | {:.5} | {:.4} | {:.2e} +- {:.1e} | {:.2e} |",
                s.group,
                filter.name(),
                lift.describe(),
                s.seeds,
                s.penumbra_rmse,
                s.penumbra_rmse_ci95,
                s.penumbra_bias,
                s.penumbra_bias_ci95,
                s.width_10_90_px,
                s.width_10_90_px_ci95,
                s.exact_width_10_90_px,
                s.lit_mean,
                s.flip_ldr_67ppd,
                s.bias2,
                s.bias2_ci95,
                s.variance
            );
        }
        r.push('\n');
        for (filter, lift, reference) in &self.references {
            let _ = writeln!(
                r,
                "Reference under the {} filter, lift {}: {} pixels judged; {} point evaluations reached the quadrature's depth limit.\n",
                filter.name(),
                lift.describe(),
                reference.judged().len(),
                reference.depth_limited
            );
        }
        r
    }

    /// Writes everything into `dir` (a staging folder), with the panel's [`Panel::groups`].
    pub fn write(&self, dir: &Path, groups: &[Group]) -> anyhow::Result<()> {
        let mut rows = csv::Writer::from_writer(Vec::new());
        for (_, j, _) in &self.judged {
            rows.serialize(j)?;
        }
        let mut summary = csv::Writer::from_writer(Vec::new());
        let mut profile = csv::Writer::from_writer(Vec::new());
        profile.write_record([
            "group",
            "pixel_filter",
            "shadow_origin_lift",
            "distance_px",
            "mean_error",
        ])?;
        // One panel per reference; a group keeps its look (by its first appearance) in each,
        // and the plot draws the first LOOKS groups (profile.csv holds every one).
        let mut names: Vec<&str> = Vec::new();
        let mut panels: Vec<PlotPanel> = Vec::new();
        for (k, s, curve) in groups {
            let (filter, lift, _) = &self.references[*k];
            for (d, e) in curve {
                profile.write_record([
                    s.group.clone(),
                    filter.name().into(),
                    lift.describe(),
                    format!("{d:.4}"),
                    format!("{e:.6e}"),
                ])?;
            }
            summary.serialize(s)?;
            let look = match names.iter().position(|n| *n == s.group) {
                Some(i) => i,
                None => {
                    names.push(&s.group);
                    names.len() - 1
                }
            };
            if look >= LOOKS {
                continue;
            }
            let title = format!("{} filter, lift {}", filter.name(), lift.describe());
            let series = Series {
                name: s.group.clone(),
                look,
                points: curve.iter().map(|&(d, e)| Point::bare(d, e)).collect(),
            };
            match panels.iter_mut().find(|p| p.title == title) {
                Some(p) => p.series.push(series),
                None => panels.push(PlotPanel {
                    title,
                    series: vec![series],
                }),
            }
        }
        let provenance = Provenance {
            build: Build::current(),
            lifts: self.lifts.iter().map(|l| l.describe()).collect(),
            inputs: vec![self.scene_input.clone()],
            images: self.image_inputs.clone(),
        };
        super::write_files(
            dir,
            &[
                ("judge.csv".into(), rows.into_inner()?),
                ("groups.csv".into(), summary.into_inner()?),
                ("profile.csv".into(), profile.into_inner()?),
                ("report.md".into(), self.report(groups).into_bytes()),
                (PROVENANCE.into(), toml::to_string(&provenance)?.into_bytes()),
            ],
        )?;
        for (filter, lift, r) in &self.references {
            let name = format!(
                "reference-{}-lift-{}.exr",
                filter.name(),
                lift.describe().replace(' ', "")
            );
            super::write_files(
                dir,
                &[(name, crate::output::images::exr_bytes(&r.fraction, r.width, r.height)?)],
            )?;
        }
        // Across the exact penumbra and as far again on each side; outside it the error is 0.
        let reach = self.judged.first().map_or(f64::NAN, |(_, j, _)| j.exact_extent_px);
        line_panels(
            &dir.join("profile.png"),
            &Axes {
                x_range: reach.is_finite().then_some((-reach, reach)),
                ..Axes::new(
                    "Mean signed error across the exact edge",
                    "distance to the exact 50 % contour (px, umbra < 0)",
                    "image - exact",
                    false,
                    false,
                )
            },
            &panels,
            &[],
        )
    }
}
