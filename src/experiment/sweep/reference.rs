//! Per light radius: the ground-truth render, the exact visibility of every receiver pixel, and
//! how far the ground truth is from the exact answer (the check that lets it judge the runs).

use super::spec::Spec;
pub use crate::experiment::shadow::{exact_image, has_exact_answer, shadow_image, ExactQuality, GROUND_TRUTH_SEED};
use crate::fingerprint::fnv1a;
use crate::metrics::{ErrorMetrics, PenumbraMask, RadialProfile, Receivers};
use crate::reference::OnAxis;
use crate::render::{Backend, Sampling, View};
use crate::sampling::{DiskScheme, Pattern};
use anyhow::Context;

/// Everything the runs of one (lights on, light radius) pair are judged against.
#[derive(Clone)]
pub struct Reference {
    /// Lights on.
    pub lights: u32,
    /// Light radius (m).
    pub light_radius: f64,
    /// Ground-truth shadow image: per pixel, the mean visibility of the lights in use
    /// (jittered, thousands of rays per pixel per light).
    pub ground_truth: Vec<f32>,
    /// Exact shadow image of receiver-plane pixels ([`crate::render::NO_RECEIVER`] elsewhere), when the scene
    /// has an exact answer: disk lights and analytic shapes only.
    pub exact: Option<Vec<f32>>,
    /// The exact image's quadrature accuracy, when there is an exact image.
    pub exact_quality: Option<ExactQuality>,
    /// Receiver-plane pixels and their radii from the shadow's centre.
    pub receivers: Receivers,
    /// Penumbra pixels of the ground truth on the receiver, of any light in use (not those
    /// where one light is wholly hidden and another wholly seen, whose mean alone is partial):
    /// every run is judged over these.
    pub mask: PenumbraMask,
    /// Closed-form radii, when one light is on and the scene is on-axis.
    pub on_axis: Option<OnAxis>,
    /// Radial profile of the exact image (on-axis scenes).
    pub exact_profile: Option<RadialProfile>,
}

impl Reference {
    /// Renders (or loads from `cache`, a folder held for the write) the ground truth and
    /// computes the exact image if any.
    pub fn build(
        spec: &Spec,
        backend: &mut dyn Backend,
        lights: u32,
        radius: f64,
        cache: &crate::files::Folder,
        context: &str,
    ) -> anyhow::Result<Reference> {
        let scene = spec.scene_with(
            lights,
            radius,
            spec.ground_truth.samples,
            spec.scene.accel_settings.name,
        );
        let m = &spec.measure;
        let camera = &scene.cameras[&m.camera];
        let view = View {
            camera,
            width: m.width,
            height: m.height,
        };
        // The context holds the build id: a changed renderer never reuses a cached ground truth.
        let key = format!("{context};lights={lights};r={radius:e}");
        let file = format!("ground-truth-{:016x}.bin", fnv1a(key.as_bytes()));
        let (per_light, hit) = match load_cached(cache, &file, view, lights as usize)? {
            Some(cached) => cached,
            None => {
                let sampling = Sampling {
                    scheme: DiskScheme::Jittered,
                    pattern: Pattern::PerPixel,
                    seed: GROUND_TRUTH_SEED,
                    frame: 0,
                };
                let f = backend
                    .render(&scene, view, sampling)
                    .context("rendering the ground truth")?;
                let rendered = (f.visibility, f.hit);
                save_cached(cache, &file, &rendered)?;
                rendered
            }
        };
        let ground_truth = shadow_image(&per_light);
        let on_axis = if lights == 1 {
            OnAxis::detect(&scene, 0, m.plane)
        } else {
            None
        };
        let centre = on_axis.as_ref().map_or(camera.look_at, |o| o.foot);
        let bin = match camera.projection {
            crate::scene::camera::Projection::Orthographic { width } => width / m.width as f64,
            crate::scene::camera::Projection::Perspective { .. } => unreachable!("validated orthographic"),
        };
        let receivers = Receivers::new(&scene, view, m.plane, &hit, centre, bin);
        let (exact, exact_quality) = match has_exact_answer(&scene) {
            true => {
                let (image, quality) = exact_image(&scene, view.pixels(), m.plane, &receivers);
                (Some(image), Some(quality))
            }
            false => (None, None),
        };
        let mask = PenumbraMask::union(&per_light, &receivers);
        let exact_profile = exact
            .as_deref()
            .filter(|_| on_axis.is_some())
            .map(|e| RadialProfile::new(&receivers, e));
        Ok(Reference {
            lights,
            light_radius: radius,
            exact_profile,
            ground_truth,
            exact,
            exact_quality,
            receivers,
            mask,
            on_axis,
        })
    }

    /// Ground truth against exact over the exact image's penumbra (on the receiver).
    pub fn gt_vs_exact(&self) -> Option<ErrorMetrics> {
        let e = self.exact.as_ref()?;
        Some(ErrorMetrics::measure(
            &self.ground_truth,
            e,
            &PenumbraMask::new(e, &self.receivers),
        ))
    }

    /// Largest |ground truth - exact| over every receiver pixel.
    pub fn gt_max_abs_all(&self) -> Option<f64> {
        let e = self.exact.as_ref()?;
        Some(
            self.receivers
                .pixels
                .iter()
                .map(|&(i, _)| (self.ground_truth[i] - e[i]).abs() as f64)
                .fold(0.0, f64::max),
        )
    }

    /// Radial profile of the ground truth (on-axis scenes).
    pub fn gt_profile(&self) -> Option<RadialProfile> {
        self.on_axis
            .as_ref()
            .map(|_| RadialProfile::new(&self.receivers, &self.ground_truth))
    }
}

impl Reference {
    /// What the log must say about this reference's own accuracy: where the exact quadrature
    /// reached its depth limit with an error bound past its tolerance.
    pub fn warnings(&self) -> Vec<String> {
        // Round-off at a tangency also stops the recursion: only a bound past the tolerance is
        // worth a warning (the count is recorded in ground_truth.csv either way).
        let tolerance = crate::reference::visibility::TOLERANCE;
        let Some(q) = self
            .exact_quality
            .filter(|q| q.depth_limited_pixels > 0 && q.max_error_bound > tolerance)
        else {
            return vec![];
        };
        vec![format!(
            "{} light(s) of radius {} m: the exact quadrature reached its depth limit ({}) at {} of {} receiver pixels (a silhouette tangency or a discontinuity); worst error bound {:.1e} (tolerance {:.0e}), in ground_truth.csv",
            self.lights,
            self.light_radius,
            crate::reference::quadrature::MAX_DEPTH,
            q.depth_limited_pixels,
            self.receivers.pixels.len(),
            q.max_error_bound,
            tolerance
        )]
    }
}

const MAGIC: &[u8; 8] = b"PNBRGT02";

/// A ground-truth render as cached: each light's visibility image, then the hit ids.
type Cached = (Vec<Vec<f32>>, Vec<u32>);

/// A cached ground truth: each light's visibility image, then the hit ids; none where there is
/// none or its bytes are not one of this size (rendered again), and a refusal where a link, a
/// folder or another non-file holds its name (before the render it would be written over).
fn load_cached(cache: &crate::files::Folder, name: &str, view: View, lights: usize) -> anyhow::Result<Option<Cached>> {
    let Some(bytes) = cache.read(name)? else {
        return Ok(None);
    };
    let n = view.pixels();
    if bytes.len() != 8 + 4 * n * (lights + 1) || &bytes[..8] != MAGIC {
        return Ok(None);
    }
    let vis = (0..lights)
        .map(|l| bytemuck::pod_collect_to_vec(&bytes[8 + 4 * n * l..8 + 4 * n * (l + 1)]))
        .collect();
    let hit: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes[8 + 4 * n * lights..]);
    Ok(Some((vis, hit)))
}

fn save_cached(cache: &crate::files::Folder, name: &str, (vis, hit): &Cached) -> anyhow::Result<()> {
    let mut bytes = MAGIC.to_vec();
    for v in vis {
        bytes.extend_from_slice(bytemuck::cast_slice(v));
    }
    bytes.extend_from_slice(bytemuck::cast_slice(hit));
    cache.write_atomic(name, &bytes)
}
