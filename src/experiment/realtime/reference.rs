//! What every frame of a variant is judged against, made once per scene state and shared by the
//! units of one process: the exact image of the receiver plane (or, where the scene has no exact
//! answer, a high-sample render), its penumbra mask and half-shadow contour, and the guides
//! (G-buffer, receivers) the filters and the blocker estimate read.

use super::spec::{RealtimeSpec, Variant};
use crate::experiment::shadow::{exact_image, has_exact_answer, shadow_image, GROUND_TRUTH_SEED};
use crate::metrics::edge::EdgeProfile;
use crate::metrics::{PenumbraMask, Receivers};
use crate::render::denoise::gbuffer::{self, GBuffer};
use crate::render::shading::Receiver;
use crate::render::{Backend, Sampling, View, NO_HIT, NO_RECEIVER};
use crate::sampling::{DiskScheme, Pattern};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// The reference of one scene state.
pub struct RefFrame {
    /// Exact (or high-sample) visibility of receiver-plane pixels, [`NO_RECEIVER`] elsewhere.
    pub image: Vec<f32>,
    /// The receiver-plane pixels.
    pub receivers: Receivers,
    /// Its penumbra: every error is taken over it.
    pub mask: PenumbraMask,
    /// Its half-shadow contour, across which widths are read.
    pub edge: EdgeProfile,
    /// Its own 10-90 % width, pixels.
    pub width_px: f64,
    /// Whether `image` is exact (quadrature) rather than rendered.
    pub exact: bool,
    /// The rendered reference's own noise: the variance of `image` about the renderer's
    /// expected value, averaged over `mask`, estimated from its two independent halves (0 where
    /// exact; NaN over an empty penumbra). A pipeline's MSE against the reference counts it once
    /// on top of its own. It says nothing of a bias the renderer might have, which the tests
    /// check against exact images.
    pub noise_mse: f64,
}

/// The guides of one scene state.
pub struct Guides {
    /// Depth, normal, footprint.
    pub gbuffer: GBuffer,
    /// The surface each pixel sees.
    pub receivers: Vec<Option<Receiver>>,
}

/// Seeds of the reference's two renders; no pipeline may run on them.
pub const REFERENCE_SEEDS: [u32; 2] = [GROUND_TRUTH_SEED, GROUND_TRUTH_SEED.wrapping_add(1)];

/// How far from the contour (pixels) widths are read.
pub const REACH: f64 = 48.0;

/// What is made once per (variant, scene state) and shared by the units of one process.
type Cache<T> = Arc<Mutex<HashMap<(Variant, u32), Arc<T>>>>;

/// References and guides made on first use, keyed by variant and scene state.
#[derive(Clone, Default)]
pub struct References {
    frames: Cache<RefFrame>,
    guides: Cache<Guides>,
}

impl std::fmt::Debug for References {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("References")
    }
}

/// Which scene state frame `f` of `variant` shows: the occluder stops moving after its frames.
fn state(spec: &RealtimeSpec, variant: Variant, f: u32) -> u32 {
    match (variant, &spec.motion) {
        (Variant::Moving, Some(m)) => f.min(m.frames),
        _ => 0,
    }
}

impl References {
    /// The guides at frame `f` of `variant`.
    pub fn guides(&self, spec: &RealtimeSpec, variant: Variant, f: u32) -> anyhow::Result<Arc<Guides>> {
        let key = (variant, state(spec, variant, f));
        if let Some(g) = self.guides.lock().expect("not poisoned").get(&key) {
            return Ok(g.clone());
        }
        let scene = spec.scene_at(variant, f);
        let view = View {
            camera: &scene.cameras[&spec.camera],
            width: spec.width,
            height: spec.height,
        };
        let receivers = gbuffer::receivers(&scene, view);
        let g = Arc::new(Guides {
            gbuffer: GBuffer::from_receivers(view, &receivers),
            receivers,
        });
        self.guides.lock().expect("not poisoned").insert(key, g.clone());
        Ok(g)
    }

    /// The reference at frame `f` of `variant`; a scene without an exact answer renders two
    /// of `spec.reference_samples` jittered rays per light on `backend` with independent seeds
    /// and takes their mean, whose noise their difference measures ([`RefFrame::noise_mse`]).
    pub fn reference(
        &self,
        spec: &RealtimeSpec,
        variant: Variant,
        f: u32,
        backend: &mut dyn Backend,
    ) -> anyhow::Result<Arc<RefFrame>> {
        let key = (variant, state(spec, variant, f));
        if let Some(r) = self.frames.lock().expect("not poisoned").get(&key) {
            return Ok(r.clone());
        }
        let guides = self.guides(spec, variant, f)?;
        let scene = spec.scene_at(variant, f);
        let view = View {
            camera: &scene.cameras[&spec.camera],
            width: spec.width,
            height: spec.height,
        };
        let hit: Vec<u32> = guides
            .receivers
            .iter()
            .map(|r| r.map_or(NO_HIT, |r| r.object))
            .collect();
        let receivers = Receivers::new(&scene, view, spec.plane, &hit, view.camera.look_at, 1.0);
        let exact = has_exact_answer(&scene);
        let (image, halves) = if exact {
            (exact_image(&scene, view.pixels(), spec.plane, &receivers).0, None)
        } else {
            let dense = RealtimeSpec::with_rays(&scene, spec.reference_samples);
            let mut render = |seed: u32| -> anyhow::Result<Vec<f32>> {
                let sampling = Sampling {
                    scheme: DiskScheme::Jittered,
                    pattern: Pattern::PerPixel,
                    seed,
                    frame: 0,
                };
                Ok(shadow_image(&backend.render(&dense, view, sampling)?.visibility))
            };
            let (a, b) = (render(REFERENCE_SEEDS[0])?, render(REFERENCE_SEEDS[1])?);
            let mut image = vec![NO_RECEIVER; a.len()];
            for &(i, _) in &receivers.pixels {
                image[i] = 0.5 * (a[i] + b[i]);
            }
            (image, Some((a, b)))
        };
        let mask = PenumbraMask::new(&image, &receivers);
        let noise_mse = halves.map_or(0.0, |(a, b)| mean_of_two_noise(&a, &b, &mask.pixels));
        let edge = EdgeProfile::new(&image, spec.width, spec.height, REACH);
        let width_px = edge.width_10_90(&image);
        let r = Arc::new(RefFrame {
            image,
            receivers,
            mask,
            edge,
            width_px,
            exact,
            noise_mse,
        });
        self.frames.lock().expect("not poisoned").insert(key, r.clone());
        Ok(r)
    }
}

/// The variance of the mean of two independent, identically distributed estimates `a` and `b`
/// at `pixels`, averaged over them (NaN without pixels): each pixel's (a - b)^2 has expectation
/// 2 var, the mean's variance is var / 2, so (a - b)^2 / 4. The mask is chosen from the noisy
/// mean, which biases the estimate near the penumbra's ends; negligible at thousands of rays,
/// not at tens.
pub fn mean_of_two_noise(a: &[f32], b: &[f32], pixels: &[usize]) -> f64 {
    if pixels.is_empty() {
        return f64::NAN;
    }
    let sum: f64 = pixels
        .iter()
        .map(|&i| {
            let d = f64::from(a[i]) - f64::from(b[i]);
            d * d / 4.0
        })
        .sum();
    sum / pixels.len() as f64
}

#[cfg(test)]
mod tests {
    use super::mean_of_two_noise;
    use crate::sampling::rng::Seeded;

    /// Two estimates of a known image with independent uniform noise of known variance: the
    /// estimate recovers the mean's variance (var / 2) within its sampling error.
    #[test]
    fn the_noise_of_a_mean_of_two_is_read_from_their_difference() {
        let n = 200_000;
        let truth: Vec<f32> = (0..n).map(|i| (i % 97) as f32 / 97.0).collect();
        let mut rng = Seeded(7);
        let half_range = 0.1_f32;
        let mut noisy = || -> Vec<f32> {
            truth
                .iter()
                .map(|&t| t + half_range * rng.range(-1.0, 1.0) as f32)
                .collect()
        };
        let (a, b) = (noisy(), noisy());
        let pixels: Vec<usize> = (0..n).collect();
        let estimate = mean_of_two_noise(&a, &b, &pixels);
        let var = f64::from(half_range * half_range) / 3.0;
        let actual: f64 = pixels
            .iter()
            .map(|&i| {
                let e = 0.5 * (f64::from(a[i]) + f64::from(b[i])) - f64::from(truth[i]);
                e * e
            })
            .sum::<f64>()
            / n as f64;
        assert!(
            (estimate / (var / 2.0) - 1.0).abs() < 0.02,
            "estimate {estimate}, var/2 {}",
            var / 2.0
        );
        assert!(
            (estimate / actual - 1.0).abs() < 0.02,
            "estimate {estimate}, actual {actual}"
        );
        assert_eq!(mean_of_two_noise(&a, &a, &pixels), 0.0);
        assert!(mean_of_two_noise(&a, &b, &[]).is_nan());
    }
}
