//! Self-intersection-safe ray origins and the GPU's local coordinate frame. The WGSL copy in
//! `render/gpu/shaders/geometry.wgsl` follows the same formula in f32.

use glam::DVec3;

/// A frame of f32 coordinates for the GPU: world = origin + scale * local. `scale` is a power of
/// two, so dividing by it is exact; the render re-bases on the camera's look-at point so f32
/// keeps its relative precision wherever the scene is placed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalFrame {
    /// World position of the local origin.
    pub origin: DVec3,
    /// World length of one local unit.
    pub scale: f64,
}

impl LocalFrame {
    /// A world point in local coordinates, still in f64.
    pub fn point_f64(&self, p: DVec3) -> DVec3 {
        (p - self.origin) / self.scale
    }

    /// A world point in local f32 coordinates.
    pub fn point(&self, p: DVec3) -> [f32; 3] {
        self.point_f64(p).as_vec3().to_array()
    }

    /// A world length in local units.
    pub fn length(&self, x: f64) -> f32 {
        (x / self.scale) as f32
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_leaves_the_surface_on_the_normal_side_at_any_scale() {
        for scale in [1e-6, 1e-3, 1.0, 1e3, 1e5, 1e8] {
            let (point, normal) = (DVec3::new(scale, -scale, scale), DVec3::Z);
            let p = offset_origin(point, normal);
            assert!((p - point).dot(normal) > 0.0, "scale {scale}");
            assert!((p - point).length() < 1e-9 * scale.max(1.0), "scale {scale}");
        }
    }
}
