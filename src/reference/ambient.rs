//! Exact ambient occlusion next to a sphere (FACTS.md): a receiver on a plane with normal
//! n, a sphere of radius R whose centre lies at distance d and wholly above the receiver's
//! horizon subtends a cone of half-angle alpha = asin(R / d). Its unoccluded fraction is
//! cos(alpha) by solid angle and 1 - (R / d)^2 cos(theta) cosine-weighted, theta the angle
//! between n and the direction to the centre (the view factor of a sphere from a differential
//! area).

use glam::DVec3;

/// Unoccluded fraction of the hemisphere of (p, n), uniform by solid angle, next to the sphere
/// (`centre`, `radius`); `None` unless the sphere lies wholly above the horizon.
pub fn sphere_plain(p: DVec3, n: DVec3, centre: DVec3, radius: f64) -> Option<f64> {
    let (d, _) = geometry(p, n, centre, radius)?;
    Some((1.0 - (radius / d).powi(2)).sqrt())
}

/// Cosine-weighted unoccluded fraction of (p, n) next to the sphere; `None` unless the sphere
/// lies wholly above the horizon.
pub fn sphere_cosine(p: DVec3, n: DVec3, centre: DVec3, radius: f64) -> Option<f64> {
    let (d, cos_theta) = geometry(p, n, centre, radius)?;
    Some(1.0 - (radius / d).powi(2) * cos_theta)
}

/// Distance to the centre and the cosine of its angle from the normal, where the sphere is wholly
/// above the horizon (its centre higher than its radius).
fn geometry(p: DVec3, n: DVec3, centre: DVec3, radius: f64) -> Option<(f64, f64)> {
    let to = centre - p;
    let d = to.length();
    let height = to.dot(n);
    (height > radius).then_some((d, height / d))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directly_below_and_far_away() {
        let (n, c) = (DVec3::Z, DVec3::new(0.0, 0.0, 2.0));
        // Straight below: alpha = asin(1/2) = 30 deg; cos = sqrt(3)/2; cosine-weighted 1 - 1/4.
        assert!((sphere_plain(DVec3::ZERO, n, c, 1.0).unwrap() - 0.75f64.sqrt()).abs() < 1e-15);
        assert!((sphere_cosine(DVec3::ZERO, n, c, 1.0).unwrap() - 0.75).abs() < 1e-15);
        // Far away both tend to 1; a sphere touching the horizon has no answer here.
        assert!(sphere_plain(DVec3::new(1e6, 0.0, 0.0), n, c, 1.0).unwrap() > 1.0 - 1e-12);
        assert!(sphere_plain(DVec3::ZERO, n, DVec3::new(0.0, 0.0, 1.0), 1.0).is_none());
    }
}
