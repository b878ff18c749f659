//! Per-receiver shadow-ray logic of the CPU backend, in f64. `shaders/render.wgsl` follows it
//! line for line in f32; change both together.

use crate::accel::work;
use crate::geometry::offset_origin;
use crate::sampling::{DiskScheme, Site};
use crate::scene::{DiskLight, Light, Scene, Shape};
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// What one receiver point gets from one light.
pub struct LightSample {
    /// Fraction of shadow-ray targets visible.
    pub visibility: f64,
    /// Irradiance estimate, W m^-2.
    pub irradiance: f64,
    /// Shadow rays traced.
    pub rays: u64,
}

/// A surface point that receives shadow rays.
#[derive(Clone, Copy, Debug)]
pub struct Receiver {
    /// Position.
    pub p: DVec3,
    /// Unit geometric normal, on the side the camera sees.
    pub n: DVec3,
    /// Lambertian albedo.
    pub albedo: f64,
    /// Object id.
    pub object: u32,
    /// Triangle index for mesh receivers, else [`super::NO_HIT`].
    pub triangle: u32,
}

impl Receiver {
    /// Where its shadow rays start. Spheres and planes are convex: a ray leaving one towards its
    /// outside cannot meet it again, so skipping the receiver's own object removes
    /// self-intersection exactly and the ray starts on the surface (an offset along the normal
    /// would move the shadow edge and bias visibility in proportion to offset / penumbra width).
    /// A mesh is not convex: its own triangle is skipped and the origin is lifted by Waechter &
    /// Binder's scale-relative offset so neighbouring triangles sharing an edge are not hit.
    pub fn origin(&self) -> DVec3 {
        if self.triangle == super::NO_HIT {
            self.p
        } else {
            offset_origin(self.p, self.n)
        }
    }
}

/// Any-hit test of the segment origin -> origin + d (exclusive of both ends) against the scene,
/// skipping the receiver's own sphere or plane (`object`) or triangle.
pub fn occluded(scene: &Scene, origin: DVec3, d: DVec3, r: &Receiver) -> bool {
    let len = d.length();
    blocked(scene, origin, d / len, len, r)
}

/// Any-hit test of `origin + t dir`, `0 < t < len` (`len` may be infinite), skipping the
/// receiver's own sphere or plane or triangle.
pub fn blocked(scene: &Scene, origin: DVec3, dir: DVec3, len: f64, r: &Receiver) -> bool {
    blocked_by_shapes(scene, origin, dir, len, r)
        || scene
            .accel
            .as_ref()
            .is_some_and(|a| a.any_hit(origin, dir, len, r.triangle))
}

/// The query of [`blocked`] counted, and its analytic shapes (not the receiver's own) tested:
/// whether one of them blocks. The triangles are the structure's to answer.
pub fn blocked_by_shapes(scene: &Scene, origin: DVec3, dir: DVec3, len: f64, r: &Receiver) -> bool {
    work::query();
    let mut tests = 0;
    let analytic = scene.shapes.iter().enumerate().any(|(id, s)| {
        let tested = id as u32 != r.object && !matches!(s, Shape::Mesh(_));
        tests += tested as u64;
        tested && s.blocks(origin, dir, len)
    });
    work::add(0, tests);
    analytic
}

/// Whether no part of the disk can be above the horizon of (p, n), or p is behind the emitter:
/// then the receiver issues no shadow rays to it.
pub fn disk_unreachable(p: DVec3, n: DVec3, l: &DiskLight) -> bool {
    let tilt = (1.0 - n.dot(l.normal).powi(2)).max(0.0).sqrt();
    l.normal.dot(p - l.center) <= 0.0 || n.dot(l.center - p) + l.radius * tilt <= 0.0
}

/// Where a receiver's shadow rays land on the unit disk.
pub enum Targets<'a> {
    /// Drawn by `scheme` at this receiver's pixel.
    PerPixel(DiskScheme, Site),
    /// The precomputed set every receiver shares.
    Shared(&'a [DVec2]),
}

/// Shadow rays from a receiver to `light`; where the scene's shading has no shadows (OpenGL-like),
/// the same estimate with every target taken as visible and no rays traced.
pub fn shade_light(scene: &Scene, r: &Receiver, light: &Light, targets: Targets) -> LightSample {
    let (p, n, origin) = (r.p, r.n, r.origin());
    match light {
        Light::Point { position, power } => {
            let d = *position - p;
            if n.dot(d) <= 0.0 {
                return LightSample {
                    visibility: 0.0,
                    irradiance: 0.0,
                    rays: 0,
                };
            }
            let shadows = scene.shading.shadows;
            let visible = !shadows || !occluded(scene, origin, *position - origin, r);
            let irradiance = if visible {
                power / (4.0 * PI) * n.dot(d.normalize()) / d.length_squared()
            } else {
                0.0
            };
            LightSample {
                visibility: visible as u8 as f64,
                irradiance,
                rays: shadows as u64,
            }
        }
        Light::Disk(l) => {
            if disk_unreachable(p, n, l) {
                return LightSample {
                    visibility: 0.0,
                    irradiance: 0.0,
                    rays: 0,
                };
            }
            let (u, v) = l.basis();
            let (mut visible, mut rays, mut sum) = (0u32, 0u64, 0.0);
            for k in 0..l.samples {
                let s = match targets {
                    Targets::Shared(points) => points[k as usize],
                    Targets::PerPixel(scheme, site) => scheme.point(l.samples, k, site),
                };
                let q = l.center + l.radius * (s.x * u + s.y * v);
                let d = q - p;
                if n.dot(d) <= 0.0 || l.normal.dot(d) >= 0.0 {
                    continue;
                }
                rays += scene.shading.shadows as u64;
                if !scene.shading.shadows || !occluded(scene, origin, q - origin, r) {
                    visible += 1;
                    let d2 = d.length_squared();
                    sum += n.dot(d) * -l.normal.dot(d) / (d2 * d2);
                }
            }
            let n_f = l.samples as f64;
            LightSample {
                visibility: visible as f64 / n_f,
                irradiance: l.power / (PI * n_f) * sum,
                rays,
            }
        }
    }
}
