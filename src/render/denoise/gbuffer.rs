//! The guides a real-time filter reads per pixel: depth, normal and footprint of the surface
//! the camera sees. A rasteriser writes these for free; here the CPU casts the camera rays in
//! f64 once per view, so both backends filter with the same guides; a caller that has cast them
//! already (for the surfaces its shadow rays leave from) makes the guides from those hits.

use crate::render::cpu::closest_hit;
use crate::render::shading::Receiver;
use crate::render::View;
use crate::scene::Scene;
use glam::DVec3;
use rayon::prelude::*;

/// Per-pixel guides of one view, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct GBuffer {
    /// Distance from the camera ray's origin to the surface (infinite where none).
    pub depth: Vec<f32>,
    /// Unit normal facing the camera (zero where none).
    pub normal: Vec<[f32; 3]>,
    /// Side of the pixel's footprint on the surface's tangent plane, metres (0 where none): what
    /// turns a penumbra width in metres into pixels.
    pub footprint: Vec<f32>,
    /// The surface point (NaN where none), where the blocker estimate measures the light from.
    pub point: Vec<DVec3>,
}

impl GBuffer {
    /// Casts every camera ray of `view` into `scene`.
    pub fn new(scene: &Scene, view: View) -> GBuffer {
        GBuffer::from_receivers(view, &receivers(scene, view))
    }

    /// The guides of `view` from the surface each of its camera rays met (row-major, none where
    /// a ray met nothing), as [`receivers`] casts them.
    pub fn from_receivers(view: View, receivers: &[Option<Receiver>]) -> GBuffer {
        let (w, h) = (view.width, view.height);
        let texels: Vec<(f32, [f32; 3], f32, DVec3)> = receivers
            .par_iter()
            .enumerate()
            .map(|(i, hit)| {
                let i = i as u32;
                let (x, y) = (i % w, i / w);
                let ray = view.camera.ray(x, y, w, h);
                let Some(hit) = hit else {
                    return (f32::INFINITY, [0.0; 3], 0.0, DVec3::NAN);
                };
                // Where the next pixel's ray meets the tangent plane: the footprint's side.
                let (nx, ny) = (
                    if x + 1 < w { x + 1 } else { x - 1 },
                    if y + 1 < h { y + 1 } else { y - 1 },
                );
                let side = |px: u32, py: u32| {
                    let r = view.camera.ray(px, py, w, h);
                    let t = hit.n.dot(hit.p - r.origin) / hit.n.dot(r.direction);
                    (r.origin + r.direction * t - hit.p).length()
                };
                let footprint = (side(nx, y) * side(x, ny)).sqrt();
                (
                    (hit.p - ray.origin).length() as f32,
                    hit.n.as_vec3().to_array(),
                    if footprint.is_finite() { footprint as f32 } else { 0.0 },
                    hit.p,
                )
            })
            .collect();
        GBuffer {
            depth: texels.iter().map(|t| t.0).collect(),
            normal: texels.iter().map(|t| t.1).collect(),
            footprint: texels.iter().map(|t| t.2).collect(),
            point: texels.iter().map(|t| t.3).collect(),
        }
    }

    /// A flat view of a plane facing the camera: one depth, one normal, one footprint; for tests
    /// and for filters judged without geometry.
    pub fn flat(pixels: usize, depth: f32, footprint: f32) -> GBuffer {
        GBuffer {
            depth: vec![depth; pixels],
            normal: vec![[0.0, 0.0, 1.0]; pixels],
            footprint: vec![footprint; pixels],
            point: vec![DVec3::ZERO; pixels],
        }
    }
}

/// The surface each camera ray of `view` meets in `scene`, row-major (none where it meets
/// nothing): what the guides are made from and the shadow rays leave from.
pub fn receivers(scene: &Scene, view: View) -> Vec<Option<Receiver>> {
    (0..view.pixels() as u32)
        .into_par_iter()
        .map(|i| {
            let ray = view.camera.ray(i % view.width, i / view.width, view.width, view.height);
            closest_hit(scene, ray.origin, ray.direction)
        })
        .collect()
}
