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
}

/// The guides of one scene state.
pub struct Guides {
    /// Depth, normal, footprint.
    pub gbuffer: GBuffer,
    /// The surface each pixel sees.
    pub receivers: Vec<Option<Receiver>>,
}

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

    /// The reference at frame `f` of `variant`; a scene without an exact answer renders one
    /// with `spec.reference_samples` jittered rays per light on `backend`.
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
        let image = if exact {
            exact_image(&scene, view.pixels(), spec.plane, &receivers).0
        } else {
            let dense = RealtimeSpec::with_rays(&scene, spec.reference_samples);
            let sampling = Sampling {
                scheme: DiskScheme::Jittered,
                pattern: Pattern::PerPixel,
                seed: GROUND_TRUTH_SEED,
                frame: 0,
            };
            let frame = backend.render(&dense, view, sampling)?;
            let all = shadow_image(&frame.visibility);
            let mut image = vec![NO_RECEIVER; all.len()];
            for &(i, _) in &receivers.pixels {
                image[i] = all[i];
            }
            image
        };
        let mask = PenumbraMask::new(&image, &receivers);
        let edge = EdgeProfile::new(&image, spec.width, spec.height, REACH);
        let width_px = edge.width_10_90(&image);
        let r = Arc::new(RefFrame {
            image,
            receivers,
            mask,
            edge,
            width_px,
            exact,
        });
        self.frames.lock().expect("not poisoned").insert(key, r.clone());
        Ok(r)
    }
}
