//! An infinite plane; `plane.wgsl` is its f32 twin.

use glam::DVec3;

/// An infinite plane {x : normal . (x - point) = 0}.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// A point on the plane.
    pub point: DVec3,
    /// Unit normal.
    pub normal: DVec3,
    /// Lambertian albedo.
    pub albedo: f64,
}

impl Plane {
    /// Distance along a unit `dir` to the plane, if the ray is not parallel to it.
    pub fn t(&self, origin: DVec3, dir: DVec3) -> Option<f64> {
        let denom = dir.dot(self.normal);
        (denom != 0.0).then(|| (self.point - origin).dot(self.normal) / denom)
    }

    /// Snaps a computed hit point back onto the plane.
    pub fn reproject(&self, p: DVec3) -> DVec3 {
        p - self.normal * (p - self.point).dot(self.normal)
    }
}
