//! Fig. 2-style pictures: the picture camera rendered with every swept configuration at the
//! figure ray count, for every seed, beside a high-sample ground-truth picture. The report shows
//! the first seed's and measures each against the ground truth perceptually (FLIP).

use super::run::{expand, Run};
use super::spec::Spec;
use crate::output::table::f32_hex;
use crate::render::{Backend, Sampling, View};
use crate::sampling::{DiskScheme, Pattern};
use serde::{Deserialize, Serialize};

/// One rendered picture: what is shown of its frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Picture {
    /// Shadow rays per pixel.
    pub samples: u32,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Outgoing radiance, row-major ([`crate::render::Frame::radiance`]).
    #[serde(with = "f32_hex")]
    pub radiance: Vec<f32>,
}

/// The pictures of an experiment with `[figures]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pictures {
    /// Jittered sampling at the figures' ground-truth ray count.
    pub ground_truth: Picture,
    /// Every run at the figure ray count, `light_radius` and every swept light on, in sweep order.
    pub runs: Vec<(Run, Picture)>,
}

/// Renders the pictures; `None` when the experiment has no `[figures]`.
pub fn render_pictures(spec: &Spec, backend: &mut dyn Backend, light_radius: f64) -> anyhow::Result<Option<Pictures>> {
    let Some(f) = &spec.figures else {
        return Ok(None);
    };
    let lights = *spec.axes.light_counts.iter().max().expect("validated non-empty");
    let mut render =
        |scheme: DiskScheme, pattern: Pattern, samples: u32, seed: u32, accelerator: &str| -> anyhow::Result<Picture> {
            let scene = spec.scene_with(lights, light_radius, samples, accelerator);
            let view = View {
                camera: &scene.cameras[&f.camera],
                width: f.width,
                height: f.height,
            };
            let frame = backend.render(
                &scene,
                view,
                Sampling {
                    scheme,
                    pattern,
                    seed,
                    frame: 0,
                },
            )?;
            Ok(Picture {
                samples,
                width: frame.width,
                height: frame.height,
                radiance: frame.radiance,
            })
        };
    let ground_truth = render(
        DiskScheme::Jittered,
        Pattern::PerPixel,
        f.ground_truth_samples,
        super::reference::GROUND_TRUTH_SEED,
        spec.scene.accel_settings.name,
    )?;
    let n = spec.figure_samples();
    let mut runs = Vec::new();
    for group in expand(spec) {
        for run in group.runs {
            if run.samples == n && run.light_radius == light_radius && run.lights == lights {
                let picture = render(run.scheme, run.pattern, n, run.seed, &run.accelerator)?;
                runs.push((run, picture));
            }
        }
    }
    Ok(Some(Pictures { ground_truth, runs }))
}
