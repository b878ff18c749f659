//! The shadow images every kind that judges shadows shares: a frame's shadow image from its
//! per-light visibility, and the exact one, by quadrature, where the scene has an exact answer;
//! with the seed of the high-sample render that stands in where it has none.

use crate::metrics::Receivers;
use crate::reference::{visible_fraction_estimate, Integral};
use crate::render::NO_RECEIVER;
use crate::scene::{Light, Scene};
use rayon::prelude::*;

/// Seed of the ground-truth render (independent of the sweep's seeds).
pub const GROUND_TRUTH_SEED: u32 = 0x6a09_e667;

/// The shadow image of a frame: per pixel, the mean visibility over its lights; pixels with no
/// receiver stay [`NO_RECEIVER`].
pub fn shadow_image(visibility: &[Vec<f32>]) -> Vec<f32> {
    let n = visibility.len() as f32;
    (0..visibility[0].len())
        .map(|i| {
            let v0 = visibility[0][i];
            if v0 == NO_RECEIVER {
                NO_RECEIVER
            } else {
                visibility.iter().map(|v| v[i]).sum::<f32>() / n
            }
        })
        .collect()
}

/// The exact reference covers disk lights and analytic shapes (no meshes, no point lights).
pub fn has_exact_answer(scene: &Scene) -> bool {
    crate::reference::occluders(scene).is_some() && scene.lights.iter().all(|l| matches!(l, Light::Disk(_)))
}

/// How accurate an exact image is, from its quadrature's own estimates.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ExactQuality {
    /// Worst error bound of a receiver pixel's visibility.
    pub max_error_bound: f64,
    /// Receiver pixels where some quadrature panel reached the depth limit.
    pub depth_limited_pixels: usize,
}

/// Exact shadow image (mean over the scene's disk lights) at every receiver pixel, with its
/// quadrature's accuracy (rayon; the penumbra dominates the cost).
pub fn exact_image(scene: &Scene, pixels: usize, plane: usize, receivers: &Receivers) -> (Vec<f32>, ExactQuality) {
    let (_, pl) = scene.plane(plane).expect("the measured plane was validated");
    let (spheres, planes) = crate::reference::occluders(scene).expect("an exact answer exists");
    let points: Vec<(usize, glam::DVec3)> = receivers
        .pixels
        .iter()
        .zip(&receivers.points)
        .map(|(&(i, _), &p)| (i, pl.reproject(p)))
        .collect();
    let disks: Vec<_> = scene
        .lights
        .iter()
        .filter_map(|l| if let Light::Disk(d) = l { Some(d) } else { None })
        .collect();
    let values: Vec<(usize, f32, Integral)> = points
        .par_iter()
        .map(|&(i, p)| {
            let e = disks
                .iter()
                .map(|l| visible_fraction_estimate(p, pl.normal, l, &spheres, &planes))
                .fold(Integral::default(), |a, b| a + b);
            let k = disks.len() as f64;
            (
                i,
                (e.value / k) as f32,
                Integral {
                    error: e.error / k,
                    ..e
                },
            )
        })
        .collect();
    let mut image = vec![NO_RECEIVER; pixels];
    let mut quality = ExactQuality::default();
    for (i, v, e) in values {
        image[i] = v;
        quality.max_error_bound = quality.max_error_bound.max(e.error);
        quality.depth_limited_pixels += (e.depth_limited > 0) as usize;
    }
    (image, quality)
}
