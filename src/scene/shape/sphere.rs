//! An analytic sphere; `sphere.wgsl` is its f32 twin.

use glam::DVec3;

/// An analytic sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: DVec3,
    /// Radius (> 0).
    pub radius: f64,
    /// Lambertian albedo.
    pub albedo: f64,
}

impl Sphere {
    /// Both roots of the intersection with a ray along unit `dir`, or `None` on a miss.
    ///
    /// Uses the formulation of Haines et al., "Precision Improvements for Ray/Sphere
    /// Intersection" (Ray Tracing Gems, ch. 7): the discriminant is computed from the
    /// closest-approach vector rather than b^2 - c, which loses every digit for small spheres far
    /// from the ray origin.
    pub fn roots(&self, origin: DVec3, dir: DVec3) -> Option<(f64, f64)> {
        let f = origin - self.center;
        let b = -f.dot(dir);
        let l = f + b * dir;
        let disc = self.radius * self.radius - l.length_squared();
        if disc < 0.0 {
            return None;
        }
        let c = f.length_squared() - self.radius * self.radius;
        let q = b + disc.sqrt().copysign(b);
        let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (c / q, q) };
        Some((t0.min(t1), t0.max(t1)))
    }

    /// The first positive root: the entry point, or the exit point from inside.
    pub fn first_t(&self, origin: DVec3, dir: DVec3) -> Option<f64> {
        let (t0, t1) = self.roots(origin, dir)?;
        let t = if t0 > 0.0 { t0 } else { t1 };
        (t > 0.0).then_some(t)
    }

    /// Snaps a computed hit point back onto the sphere, removing the error of `origin + t dir`
    /// that grows with the ray's length (pbrt-v4 re-projects the same way).
    pub fn reproject(&self, p: DVec3) -> DVec3 {
        self.center + (p - self.center).normalize() * self.radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_survive_tiny_spheres_far_away() {
        let s = Sphere {
            center: DVec3::new(0.0, 0.0, 1e6),
            radius: 1e-3,
            albedo: 1.0,
        };
        let (t0, t1) = s.roots(DVec3::ZERO, DVec3::Z).unwrap();
        assert!((t0 - (1e6 - 1e-3)).abs() < 1e-9 && (t1 - (1e6 + 1e-3)).abs() < 1e-9);
        assert!(s.roots(DVec3::new(2e-3, 0.0, 0.0), DVec3::Z).is_none());
    }

    #[test]
    fn first_root_is_the_exit_from_inside_and_none_behind() {
        let s = Sphere {
            center: DVec3::ZERO,
            radius: 1.0,
            albedo: 1.0,
        };
        assert_eq!(s.first_t(DVec3::new(0.0, 0.0, -3.0), DVec3::Z), Some(2.0));
        assert_eq!(s.first_t(DVec3::ZERO, DVec3::Z), Some(1.0));
        assert_eq!(s.first_t(DVec3::new(0.0, 0.0, 3.0), DVec3::Z), None);
    }
}
