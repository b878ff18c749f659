//! Closed-form umbra and penumbra radii for a sphere above a plane under a coaxial disk light
//! (FACTS.md): with phi = atan(a / (H - h)) and beta = asin(R / sqrt(a^2 + (H - h)^2)),
//! r_u = a + H tan(beta - phi) and r_p = -a + H tan(beta + phi).

use crate::scene::{DiskLight, Light, Plane, Scene, Sphere};
use glam::DVec3;

/// The on-axis configuration of the paper's Fig. 2: light, sphere centre and shadow centre on one
/// line perpendicular to the receiver plane. Radial profiles are measured about `foot`.
#[derive(Clone, Debug, PartialEq)]
pub struct OnAxis {
    /// Light radius a.
    pub light_radius: f64,
    /// Light height H above the plane.
    pub light_height: f64,
    /// Sphere centre height h above the plane.
    pub sphere_height: f64,
    /// Sphere radius R.
    pub sphere_radius: f64,
    /// Where the axis meets the receiver plane: the shadow's centre.
    pub foot: DVec3,
    /// A unit direction in the plane, to walk out along a radius.
    pub radial: DVec3,
}

impl OnAxis {
    /// Recognises the on-axis case: one sphere, the light's axis through its centre and
    /// perpendicular to plane `plane`, the light facing the plane. `None` otherwise.
    pub fn detect(scene: &Scene, light: usize, plane: usize) -> Option<OnAxis> {
        let Some(Light::Disk(l)) = scene.lights.get(light) else {
            return None;
        };
        // A mesh would cast a shadow the closed form does not know.
        let (spheres, _) = super::occluders(scene)?;
        let [s] = spheres.as_slice() else {
            return None;
        };
        let (_, pl) = scene.plane(plane)?;
        Self::from_parts(l, s, pl)
    }

    fn from_parts(l: &DiskLight, s: &Sphere, pl: &Plane) -> Option<OnAxis> {
        let tol = 1e-9;
        let light_height = (l.center - pl.point).dot(pl.normal);
        let sphere_height = (s.center - pl.point).dot(pl.normal);
        let aligned = l.normal.dot(pl.normal) < -1.0 + tol;
        let axis_offset = (s.center - l.center).reject_from_normalized(pl.normal).length();
        let above = light_height > sphere_height + s.radius && sphere_height > s.radius;
        if !(aligned && axis_offset <= tol * light_height && above) {
            return None;
        }
        let foot = l.center - pl.normal * light_height;
        Some(OnAxis {
            light_radius: l.radius,
            light_height,
            sphere_height,
            sphere_radius: s.radius,
            foot,
            radial: pl.normal.any_orthonormal_vector(),
        })
    }

    fn angles(&self) -> (f64, f64) {
        let (a, dh) = (self.light_radius, self.light_height - self.sphere_height);
        ((a / dh).atan(), (self.sphere_radius / (a * a + dh * dh).sqrt()).asin())
    }

    /// Umbra radius r_u; negative when there is no umbra.
    pub fn umbra_radius(&self) -> f64 {
        let (phi, beta) = self.angles();
        self.light_radius + self.light_height * (beta - phi).tan()
    }

    /// Where partial shadow begins: r_u, or the axis when there is no umbra (r_u < 0 means the
    /// whole light is seen past the sphere's silhouette from every receiver point).
    pub fn inner_radius(&self) -> f64 {
        self.umbra_radius().max(0.0)
    }

    /// Penumbra (outer) radius r_p.
    pub fn penumbra_radius(&self) -> f64 {
        let (phi, beta) = self.angles();
        -self.light_radius + self.light_height * (beta + phi).tan()
    }

    /// The receiver point at distance `r` from the shadow's centre.
    pub fn point_at(&self, r: f64) -> DVec3 {
        self.foot + self.radial * r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::visible_fraction;

    fn example() -> (DiskLight, Sphere, Plane) {
        (
            DiskLight {
                center: DVec3::new(0.0, 0.0, 10.0),
                normal: DVec3::NEG_Z,
                radius: 1.0,
                power: 1.0,
                samples: 1,
            },
            Sphere {
                center: DVec3::new(0.0, 0.0, 3.0),
                radius: 1.0,
                albedo: 1.0,
            },
            Plane {
                point: DVec3::ZERO,
                normal: DVec3::Z,
                albedo: 1.0,
            },
        )
    }

    #[test]
    fn known_facts_example() {
        let (l, s, p) = example();
        let o = OnAxis::from_parts(&l, &s, &p).unwrap();
        assert!((o.umbra_radius() - 1.000).abs() < 5e-4, "{}", o.umbra_radius());
        assert!((o.penumbra_radius() - 1.917).abs() < 5e-4, "{}", o.penumbra_radius());
    }

    /// The closed-form radii and the quadrature agree: V is 0 just inside r_u, 1 just outside
    /// r_p, and strictly between inside the penumbra. Two independent derivations.
    #[test]
    fn radii_bound_the_exact_transition() {
        for (a, h, r) in [(1.0, 3.0, 1.0), (0.02, 0.5, 0.25), (0.3, 1.0, 0.2)] {
            let (mut l, mut s, p) = example();
            l.radius = a;
            l.center.z = 2.0 * h + 1.0;
            s.center.z = h;
            s.radius = r;
            let o = OnAxis::from_parts(&l, &s, &p).unwrap();
            let v = |x: f64| visible_fraction(o.point_at(x), DVec3::Z, &l, std::slice::from_ref(&s), &[]);
            let (ru, rp) = (o.umbra_radius(), o.penumbra_radius());
            let d = 1e-6 * rp;
            if ru > d {
                assert!(v(ru - d) < 1e-6, "a={a}: V(r_u-) = {}", v(ru - d));
                assert!(v(ru + 1e-3 * (rp - ru)) > 0.0);
            }
            assert!((v(rp + d) - 1.0).abs() < 1e-9, "a={a}: V(r_p+) = {}", v(rp + d));
            assert!(v(rp - 1e-3 * (rp - ru.max(0.0))) < 1.0);
            let mid = v(0.5 * (ru.max(0.0) + rp));
            assert!(mid > 0.0 && mid < 1.0);
        }
    }

    #[test]
    fn off_axis_is_not_detected() {
        let (l, mut s, p) = example();
        s.center.x = 0.1;
        assert!(OnAxis::from_parts(&l, &s, &p).is_none());
    }
}
