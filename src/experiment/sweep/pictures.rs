//! Fig. 2-style pictures: the picture camera rendered with every swept scheme and pattern at the
//! figure ray count, for every seed, beside a high-sample ground-truth picture. The report shows
//! the first seed's and measures each against the ground truth perceptually (FLIP).

use super::runner::figure_samples;
use super::spec::Spec;
use crate::render::{Backend, Frame, Sampling, View};
use crate::sampling::{DiskScheme, Pattern};

/// One rendered picture.
pub struct Picture {
    /// Scheme.
    pub scheme: DiskScheme,
    /// Pattern.
    pub pattern: Pattern,
    /// Shadow rays per pixel.
    pub samples: u32,
    /// Seed.
    pub seed: u32,
    /// The frame (radiance is what is shown).
    pub frame: Frame,
}

/// The pictures of an experiment with `[figures]`.
pub struct Pictures {
    /// Jittered sampling at the figures' ground-truth ray count.
    pub ground_truth: Picture,
    /// Every swept scheme x pattern x seed at the figure ray count.
    pub runs: Vec<Picture>,
}

/// Renders the pictures; `None` when the experiment has no `[figures]`.
pub fn render_pictures(spec: &Spec, backend: &mut dyn Backend, light_radius: f64) -> anyhow::Result<Option<Pictures>> {
    let Some(f) = &spec.figures else {
        return Ok(None);
    };
    let lights = *spec.axes.light_counts.iter().max().expect("validated non-empty");
    let mut render = |scheme: DiskScheme, pattern: Pattern, samples: u32, seed: u32| -> anyhow::Result<Picture> {
        let scene = spec.scene_with(lights, light_radius, samples);
        let view = View {
            camera: &scene.cameras[&f.camera],
            width: f.width,
            height: f.height,
        };
        let frame = backend.render(&scene, view, Sampling { scheme, pattern, seed })?;
        Ok(Picture {
            scheme,
            pattern,
            samples,
            seed,
            frame,
        })
    };
    let ground_truth = render(
        DiskScheme::Jittered,
        Pattern::PerPixel,
        f.ground_truth_samples,
        super::reference::GROUND_TRUTH_SEED,
    )?;
    let n = figure_samples(spec);
    let mut runs = Vec::new();
    for &scheme in &spec.axes.schemes {
        for &pattern in &spec.axes.patterns {
            for &seed in &spec.axes.seeds {
                runs.push(render(scheme, pattern, n, seed)?);
            }
        }
    }
    Ok(Some(Pictures { ground_truth, runs }))
}
