//! Fig. 2-style pictures: the picture camera rendered with uniform and the paper's pattern at
//! the figure sample count, beside a high-sample reference.

use super::spec::Spec;
use crate::render::{Backend, Frame, Sampling, View};
use crate::sampling::{DiskScheme, Pattern};

/// (label, frame) for each picture; empty when the experiment has no `[figures]`.
pub fn render_pictures(
    spec: &Spec,
    backend: &mut dyn Backend,
    light_radius: f64,
) -> anyhow::Result<Vec<(String, Frame)>> {
    let Some(f) = &spec.figures else {
        return Ok(vec![]);
    };
    let seed = spec.axes.seeds[0];
    let mut out = Vec::new();
    for (scheme, pattern, n) in [
        (DiskScheme::Uniform, Pattern::PerPixel, f.samples),
        (DiskScheme::Paper, Pattern::Shared, f.samples),
        (DiskScheme::Paper, Pattern::PerPixel, f.samples),
        (DiskScheme::Jittered, Pattern::PerPixel, f.ground_truth_samples),
    ] {
        let lights = *spec.axes.light_counts.iter().max().expect("validated non-empty");
        let scene = spec.scene_with(lights, light_radius, n);
        let view = View {
            camera: &scene.cameras[&f.camera],
            width: f.width,
            height: f.height,
        };
        let frame = backend.render(&scene, view, Sampling { scheme, pattern, seed })?;
        out.push((format!("{scheme} ({pattern}), {n} rays"), frame));
    }
    Ok(out)
}
