//! Ray-shape intersection and self-intersection-safe ray origins, in f64 for the CPU backend.
//! The WGSL copies in `render/gpu/shaders/geometry.wgsl` follow the same formulas in f32.

use crate::scene::{Plane, Sphere};
use glam::DVec3;

/// Both roots of a ray-sphere intersection for a unit `dir`, or `None` on a miss.
///
/// Uses the formulation of Haines et al., "Precision Improvements for Ray/Sphere Intersection"
/// (Ray Tracing Gems, ch. 7): the discriminant is computed from the closest-approach vector
/// rather than b^2 - c, which loses every digit for small spheres far from the ray origin.
pub fn sphere_roots(origin: DVec3, dir: DVec3, s: &Sphere) -> Option<(f64, f64)> {
    let f = origin - s.center;
    let b = -f.dot(dir);
    let l = f + b * dir;
    let disc = s.radius * s.radius - l.length_squared();
    if disc < 0.0 {
        return None;
    }
    let c = f.length_squared() - s.radius * s.radius;
    let q = b + disc.sqrt().copysign(b);
    let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (c / q, q) };
    Some((t0.min(t1), t0.max(t1)))
}

/// Distance along a unit `dir` to a plane, if the ray is not parallel to it.
pub fn plane_t(origin: DVec3, dir: DVec3, p: &Plane) -> Option<f64> {
    let denom = dir.dot(p.normal);
    (denom != 0.0).then(|| (p.point - origin).dot(p.normal) / denom)
}

/// Moves a surface point off the surface along its geometric normal by an amount that scales
/// with the point's magnitude, after Waechter & Binder, "A Fast and Robust Method for Avoiding
/// Self-Intersection" (Ray Tracing Gems, ch. 6): a fixed number of ULPs of each coordinate far
/// from the origin, a tiny absolute offset near it. No scene-dependent epsilon.
pub fn offset_origin(p: DVec3, n: DVec3) -> DVec3 {
    // Constants scaled from the paper's f32 values (1/32, 2^-16, 256) to f64's 52-bit mantissa.
    const ORIGIN: f64 = 1.0 / 32.0;
    const FLOAT_SCALE: f64 = 1.0 / (1u64 << 45) as f64;
    const INT_SCALE: f64 = 256.0;
    let nudge = |p: f64, n: f64| -> f64 {
        if p.abs() < ORIGIN {
            return p + FLOAT_SCALE * n;
        }
        let of = (INT_SCALE * n) as i64;
        let bits = p.to_bits() as i64;
        f64::from_bits((bits + if p < 0.0 { -of } else { of }) as u64)
    };
    DVec3::new(nudge(p.x, n.x), nudge(p.y, n.y), nudge(p.z, n.z))
}

/// Snaps a computed hit point back onto the sphere, removing the error of `origin + t dir`
/// that grows with the ray's length (pbrt-v4 re-projects the same way).
pub fn reproject_sphere(p: DVec3, s: &Sphere) -> DVec3 {
    s.center + (p - s.center).normalize() * s.radius
}

/// Snaps a computed hit point back onto the plane.
pub fn reproject_plane(p: DVec3, pl: &Plane) -> DVec3 {
    p - pl.normal * (p - pl.point).dot(pl.normal)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_roots_survive_tiny_spheres_far_away() {
        let s = Sphere {
            center: DVec3::new(0.0, 0.0, 1e6),
            radius: 1e-3,
            albedo: 1.0,
        };
        let (t0, t1) = sphere_roots(DVec3::ZERO, DVec3::Z, &s).unwrap();
        assert!((t0 - (1e6 - 1e-3)).abs() < 1e-9 && (t1 - (1e6 + 1e-3)).abs() < 1e-9);
        assert!(sphere_roots(DVec3::new(2e-3, 0.0, 0.0), DVec3::Z, &s).is_none());
    }

    #[test]
    fn offset_leaves_the_surface_on_the_normal_side_at_any_scale() {
        for scale in [1e-6, 1e-3, 1.0, 1e3, 1e5, 1e8] {
            let pl = Plane {
                point: DVec3::new(scale, -scale, scale),
                normal: DVec3::Z,
                albedo: 1.0,
            };
            let p = offset_origin(pl.point, pl.normal);
            assert!((p - pl.point).dot(pl.normal) > 0.0, "scale {scale}");
            assert!((p - pl.point).length() < 1e-9 * scale.max(1.0), "scale {scale}");
        }
    }
}
