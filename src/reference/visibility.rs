//! The exact visible fraction of a disk light from a receiver point.
//!
//! V(P) = (1 / (pi a^2)) * integral over the disk of [Q visible from P] dA(Q). In polar
//! coordinates about the light's centre, for each angle theta the set of visible radii rho is a
//! union of intervals whose ends are roots of linear or quadratic polynomials in rho (receiver
//! horizon, planes, and for each sphere: "Q inside the ball" and "closest point of segment PQ to
//! the centre lies on the segment and within R"). Between consecutive roots the predicate is
//! constant, so the inner integral of rho d rho is exact; the outer integral over theta is
//! adaptive Gauss-Kronrod. This is the "adaptive 1-D quadrature of the chord overlap" of
//! FACTS.md, generalised to any number of spheres and planes and to lights that touch or
//! enter an occluder.

use super::quadrature::{integrate_panels, Integral};
use crate::scene::{DiskLight, Plane, Scene, Shape, Sphere};
use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// Absolute tolerance on V requested from the quadrature.
pub const TOLERANCE: f64 = 1e-10;

/// Initial angular panels: a visible or occluded sliver narrower than 2 pi / (128 x 15) in angle
/// could be missed; near a tangency its area scales as the cube of that width, ~4e-9 of the disk.
const PANELS: u32 = 128;

/// The occluders of a scene as the exact answer takes them: its spheres and planes, or None
/// where it holds any triangle (no closed form covers triangles; such scenes are judged against
/// the ground truth alone). A mesh whose triangles were all dropped occludes nothing.
pub fn occluders(scene: &Scene) -> Option<(Vec<Sphere>, Vec<Plane>)> {
    if !scene.triangles.positions.is_empty() {
        return None;
    }
    let (mut spheres, mut planes) = (vec![], vec![]);
    for s in &scene.shapes {
        match s {
            Shape::Sphere(s) => spheres.push(*s),
            Shape::Plane(p) => planes.push(*p),
            Shape::Mesh(_) => {}
        }
    }
    Some((spheres, planes))
}

/// Exact fraction of `light` visible from point `p` with surface normal `n` (the receiver's own
/// horizon counts as an occluder), with `spheres` and `planes` as occluders. Planes through `p`
/// are the receiver itself and are skipped.
pub fn visible_fraction(p: DVec3, n: DVec3, light: &DiskLight, spheres: &[Sphere], planes: &[Plane]) -> f64 {
    visible_fraction_estimate(p, n, light, spheres, planes).value
}

/// [`visible_fraction`] with the quadrature's error bound and depth-limited panels (in units of
/// V: the integral's divided by the disk's area).
pub fn visible_fraction_estimate(
    p: DVec3,
    n: DVec3,
    light: &DiskLight,
    spheres: &[Sphere],
    planes: &[Plane],
) -> Integral {
    fraction(p, n, light, spheres, planes, Weight::Area).0
}

/// The exact irradiance a disk light gives a receiver point, as the fraction of its unoccluded
/// irradiance that arrives and that unoccluded part: E = L_e (fraction x free), with
/// free = integral over the disk (above the receiver's horizon) of cos_r cos_l / d^2 dA (m^0:
/// a solid-angle-like geometry term) and L_e = power / (pi^2 a^2) for the one-sided
/// Lambertian disk. This is what a renderer's radiance estimates converge to (penumbra's
/// irradiance estimate, [`crate::render::shading`], and any path tracer's); [`visible_fraction`]
/// weighs the disk by area instead, and the two differ by the weight's variation over the
/// disk (about 4 r a / d^2, under 1 % for the shipped scene) inside the penumbra.
pub fn irradiance_fraction_estimate(
    p: DVec3,
    n: DVec3,
    light: &DiskLight,
    spheres: &[Sphere],
    planes: &[Plane],
) -> (Integral, f64) {
    fraction(p, n, light, spheres, planes, Weight::Irradiance)
}

/// How the points of the disk count in an integral over its visible part.
#[derive(Clone, Copy, PartialEq)]
enum Weight {
    /// By area: the visible fraction V.
    Area,
    /// By cos_r cos_l / d^2: the irradiance.
    Irradiance,
}

/// The visible part of the disk as a fraction of the whole (as `weight` counts it), with the
/// whole's integral (pi a^2 for [`Weight::Area`]; above the receiver's horizon for
/// [`Weight::Irradiance`]).
fn fraction(
    p: DVec3,
    n: DVec3,
    light: &DiskLight,
    spheres: &[Sphere],
    planes: &[Plane],
    weight: Weight,
) -> (Integral, f64) {
    let a = light.radius;
    let (u, v) = light.basis();
    let chord = |theta: f64, spheres: &[Sphere], planes: &[&Plane]| {
        visible_rho_integral(p, n, light, u * theta.cos() + v * theta.sin(), spheres, planes, weight)
    };
    let whole = match weight {
        Weight::Area => PI * a * a,
        Weight::Irradiance if light.normal.dot(p - light.center) <= 0.0 => 0.0,
        Weight::Irradiance => {
            // Only the horizon cuts the unoccluded disk: a smooth integrand but for the
            // horizon's chord, resolved to the same relative tolerance as the visible part.
            let d = (light.center - p).length();
            let scale = PI * a * a / (d * d);
            integrate_panels(|t| chord(t, &[], &[]), 0.0, TAU, TOLERANCE * scale, PANELS).value
        }
    };
    let exactly = |value: f64| {
        let integral = Integral {
            value,
            ..Default::default()
        };
        (integral, whole)
    };
    if light.normal.dot(p - light.center) <= 0.0 || whole <= 0.0 {
        return exactly(0.0); // behind the one-sided emitter, or below the horizon
    }
    if spheres
        .iter()
        .any(|s| (p - s.center).length_squared() < s.radius * s.radius)
    {
        return exactly(0.0);
    }
    let scale = (p - light.center).length().max(light.radius);
    let occluding_planes: Vec<&Plane> = planes
        .iter()
        .filter(|pl| (p - pl.point).dot(pl.normal).abs() > 1e-12 * scale.max(pl.point.length()))
        .collect();
    if occluding_planes.is_empty() && unoccluded_and_above_horizon(p, n, light, spheres) {
        return exactly(1.0);
    }
    let total = integrate_panels(
        |t| chord(t, spheres, &occluding_planes),
        0.0,
        TAU,
        TOLERANCE * whole,
        PANELS,
    );
    let integral = Integral {
        value: (total.value / whole).clamp(0.0, 1.0),
        error: total.error / whole,
        depth_limited: total.depth_limited,
    };
    (integral, whole)
}

/// Conservative test that nothing can hide any part of the light: the whole disk is above the
/// receiver's horizon and every sphere's cone from `p` misses the light's bounding cone.
fn unoccluded_and_above_horizon(p: DVec3, n: DVec3, light: &DiskLight, spheres: &[Sphere]) -> bool {
    let to_light = light.center - p;
    let dist = to_light.length();
    let tilt = (1.0 - n.dot(light.normal).powi(2)).max(0.0).sqrt();
    if n.dot(to_light) - light.radius * tilt <= 0.0 || dist <= light.radius {
        return false;
    }
    let light_half_angle = (light.radius / dist).asin();
    spheres.iter().all(|s| {
        let f = s.center - p;
        let sphere_half_angle = (s.radius / f.length()).min(1.0).asin();
        f.angle_between(to_light) > sphere_half_angle + light_half_angle + 1e-9
    })
}

/// Integral of w rho d rho over the visible part of the ray {C + rho e : 0 <= rho <= a}, with
/// w = 1 ([`Weight::Area`]: exact) or cos_r cos_l / d^2 ([`Weight::Irradiance`]: 8-point
/// Gauss-Legendre on pieces of each visible interval no longer than half the receiver's
/// distance to the light's plane, where w is smooth).
fn visible_rho_integral(
    p: DVec3,
    n: DVec3,
    light: &DiskLight,
    e: DVec3,
    spheres: &[Sphere],
    planes: &[&Plane],
    weight: Weight,
) -> f64 {
    let (c, a) = (light.center, light.radius);
    let w0 = c - p;
    let mut cuts = vec![0.0, a];
    let mut add = |c2: f64, c1: f64, c0: f64| {
        for r in quadratic_roots(c2, c1, c0) {
            if r > 0.0 && r < a {
                cuts.push(r);
            }
        }
    };
    add(0.0, n.dot(e), n.dot(w0));
    for s in spheres {
        let f = s.center - p;
        let k = f.length_squared() - s.radius * s.radius;
        let (fe, fw0, we, ww0) = (f.dot(e), f.dot(w0), w0.dot(e), w0.length_squared());
        let g = w0 - f;
        add(1.0, 2.0 * e.dot(g), g.length_squared() - s.radius * s.radius);
        add(0.0, fe, fw0);
        add(1.0, 2.0 * we - fe, ww0 - fw0);
        add(fe * fe - k, 2.0 * (fw0 * fe - k * we), fw0 * fw0 - k * ww0);
    }
    for pl in planes {
        add(0.0, pl.normal.dot(e), pl.normal.dot(c - pl.point));
    }
    cuts.sort_by(f64::total_cmp);
    let geometry = |rho: f64| {
        let d = w0 + e * rho;
        let d2 = d.length_squared();
        n.dot(d).max(0.0) * (-light.normal.dot(d)).max(0.0) / (d2 * d2)
    };
    let mut sum = 0.0;
    for w in cuts.windows(2) {
        let (r0, r1) = (w[0], w[1]);
        if r1 > r0 && is_visible(p, n, c + e * (0.5 * (r0 + r1)), spheres, planes) {
            sum += match weight {
                Weight::Area => 0.5 * (r1 * r1 - r0 * r0),
                Weight::Irradiance => {
                    // The weight varies on the scale of the receiver's distance to the light's
                    // plane: pieces no longer than half of it keep the rule exact to rounding
                    // for receivers close to the light too.
                    let scale = 0.5 * light.normal.dot(p - c).abs();
                    let pieces = ((r1 - r0) / scale).ceil().clamp(1.0, 256.0) as usize;
                    let h = (r1 - r0) / pieces as f64;
                    (0..pieces)
                        .map(|k| {
                            gauss_legendre_8(|rho| geometry(rho) * rho, r0 + h * k as f64, r0 + h * (k + 1) as f64)
                        })
                        .sum()
                }
            };
        }
    }
    sum
}

/// 8-point Gauss-Legendre rule on [a, b]: exact for polynomials of degree 15.
fn gauss_legendre_8(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    const X: [f64; 4] = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    const W: [f64; 4] = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    h * X
        .iter()
        .zip(W)
        .map(|(&x, w)| w * (f(c - h * x) + f(c + h * x)))
        .sum::<f64>()
}

/// Whether light point `q` is visible from receiver `p` (normal `n`): above the horizon, and the
/// closed segment pq misses every sphere and crosses no plane.
pub fn is_visible(p: DVec3, n: DVec3, q: DVec3, spheres: &[Sphere], planes: &[&Plane]) -> bool {
    let w = q - p;
    if n.dot(w) <= 0.0 {
        return false;
    }
    let ww = w.length_squared();
    let blocked_by_sphere = spheres.iter().any(|sph| {
        let f = sph.center - p;
        let s = (f.dot(w) / ww).clamp(0.0, 1.0);
        (f - w * s).length_squared() <= sph.radius * sph.radius
    });
    let blocked_by_plane = planes
        .iter()
        .any(|pl| (p - pl.point).dot(pl.normal) * (q - pl.point).dot(pl.normal) < 0.0);
    !blocked_by_sphere && !blocked_by_plane
}

/// Real roots of c2 x^2 + c1 x + c0 (a linear equation when c2 == 0), without cancellation.
pub fn quadratic_roots(c2: f64, c1: f64, c0: f64) -> Vec<f64> {
    if c2 == 0.0 {
        return if c1 != 0.0 { vec![-c0 / c1] } else { vec![] };
    }
    let disc = c1 * c1 - 4.0 * c2 * c0;
    if disc < 0.0 {
        return vec![];
    }
    let q = -0.5 * (c1 + disc.sqrt().copysign(c1));
    if q == 0.0 {
        return vec![0.0];
    }
    vec![q / c2, c0 / q]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn down_light(center: DVec3, radius: f64) -> DiskLight {
        DiskLight {
            center,
            normal: DVec3::NEG_Z,
            radius,
            power: 1.0,
            samples: 1,
        }
    }

    /// Area of the intersection of two disks (radii r1, r2, centres d apart): the lens formula.
    fn lens(r1: f64, r2: f64, d: f64) -> f64 {
        if d >= r1 + r2 {
            return 0.0;
        }
        if d <= (r1 - r2).abs() {
            return PI * r1.min(r2).powi(2);
        }
        let a1 = r1 * r1 * ((d * d + r1 * r1 - r2 * r2) / (2.0 * d * r1)).acos();
        let a2 = r2 * r2 * ((d * d + r2 * r2 - r1 * r1) / (2.0 * d * r2)).acos();
        let k = 0.5 * ((-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2)).sqrt();
        a1 + a2 - k
    }

    /// Across the shipped sphere scene's penumbra (r_u = 0.3306 m to r_p = 0.3455 m and a little
    /// beyond), the quadrature's own error bound meets the tolerance asked for. Panels next to a
    /// tangency of the sphere's silhouette with the disk's rim (a square-root endpoint) reach the
    /// depth limit with errors far below the tolerance; they are counted, not hidden.
    #[test]
    fn error_bounds_of_the_shipped_scene_meet_the_tolerance() {
        let l = down_light(DVec3::new(0.0, 0.0, 2.0), 0.02);
        let s = [Sphere {
            center: DVec3::new(0.0, 0.0, 0.5),
            radius: 0.25,
            albedo: 0.8,
        }];
        let (mut partial, mut limited) = (0, 0);
        for k in 0..300 {
            let (r, phi) = (0.328 + 0.02 * k as f64 / 300.0, 2.399_963 * k as f64);
            let p = DVec3::new(r * phi.cos(), r * phi.sin(), 0.0);
            let e = visible_fraction_estimate(p, DVec3::Z, &l, &s, &[]);
            assert!(e.error <= TOLERANCE, "r = {r}: {e:?}");
            assert_eq!(e.value, visible_fraction(p, DVec3::Z, &l, &s, &[]));
            partial += (e.value > 0.0 && e.value < 1.0) as u32;
            limited += (e.depth_limited > 0) as u32;
        }
        assert!(partial > 200, "{partial} of 300 points in the penumbra");
        eprintln!("{limited} of 300 points reached the depth limit somewhere");
    }

    #[test]
    fn unoccluded_light_is_fully_visible() {
        let l = down_light(DVec3::new(0.3, 0.1, 2.0), 0.5);
        assert_eq!(visible_fraction(DVec3::ZERO, DVec3::Z, &l, &[], &[]), 1.0);
    }

    /// With the receiver directly below the sphere's centre, the occluder's cone meets the light
    /// plane in a circle, so the occluded area is a circle-circle lens: a closed form, here with
    /// the light off-centre so the overlap is partial.
    #[test]
    fn matches_lens_closed_form_below_the_sphere() {
        let (h_light, h_sphere, r_sphere) = (4.0, 1.5, 0.5);
        let sphere = Sphere {
            center: DVec3::new(0.0, 0.0, h_sphere),
            radius: r_sphere,
            albedo: 1.0,
        };
        // Tangent cone from the origin: half angle asin(R / h); cut at z = H: radius H tan(.)
        let beta = (r_sphere / h_sphere).asin();
        let rb = h_light * beta.tan();
        for (offset, radius) in [(0.9, 0.6), (1.3, 0.6), (0.2, 1.5), (2.0, 0.3), (0.0, 0.5)] {
            let light = down_light(DVec3::new(offset, 0.0, h_light), radius);
            let v = visible_fraction(DVec3::ZERO, DVec3::Z, &light, std::slice::from_ref(&sphere), &[]);
            let expected = 1.0 - lens(radius, rb, offset) / (PI * radius * radius);
            assert!(
                (v - expected).abs() < 1e-9,
                "offset {offset} radius {radius}: {v} vs {expected}"
            );
        }
    }

    #[test]
    fn light_inside_or_touching_an_occluder() {
        let sphere = Sphere {
            center: DVec3::new(0.0, 0.0, 2.0),
            radius: 1.0,
            albedo: 1.0,
        };
        let inside = down_light(DVec3::new(0.0, 0.0, 2.2), 0.3);
        let p = DVec3::new(3.0, 0.0, 0.0);
        assert_eq!(
            visible_fraction(p, DVec3::Z, &inside, std::slice::from_ref(&sphere), &[]),
            0.0
        );
        // A light whose plane cuts the sphere's top: the receiver far to the side still sees it
        // partly, and the answer is continuous as the light slides into the sphere.
        let mut prev = None;
        for dz in [0.05, 0.0, -0.05] {
            let l = down_light(DVec3::new(0.0, 0.0, 3.0 + dz), 0.4);
            let v = visible_fraction(
                DVec3::new(1.5, 0.0, 0.0),
                DVec3::Z,
                &l,
                std::slice::from_ref(&sphere),
                &[],
            );
            assert!((0.0..=1.0).contains(&v));
            if let Some(p) = prev {
                assert!(v <= p + 1e-12, "sinking the light into the sphere can only hide more");
            }
            prev = Some(v);
        }
    }

    #[test]
    fn horizon_cuts_a_light_standing_on_the_receiver_plane() {
        // A vertical light centred on the receiver's plane: exactly half is below the horizon.
        let l = DiskLight {
            center: DVec3::new(0.0, 5.0, 0.0),
            normal: DVec3::NEG_Y,
            radius: 0.5,
            power: 1.0,
            samples: 1,
        };
        let v = visible_fraction(DVec3::ZERO, DVec3::Z, &l, &[], &[]);
        assert!((v - 0.5).abs() < 1e-10, "{v}");
    }

    #[test]
    fn light_facing_away_is_invisible() {
        let l = DiskLight {
            center: DVec3::new(0.0, 0.0, 2.0),
            normal: DVec3::Z,
            radius: 0.5,
            power: 1.0,
            samples: 1,
        };
        assert_eq!(visible_fraction(DVec3::ZERO, DVec3::Z, &l, &[], &[]), 0.0);
    }

    #[test]
    fn roots_without_cancellation() {
        let r = quadratic_roots(1.0, -1e8, 1.0);
        assert!(r.iter().any(|&x| (x - 1e-8).abs() < 1e-22));
        assert!(quadratic_roots(1.0, 0.0, 1.0).is_empty());
        assert_eq!(quadratic_roots(0.0, 2.0, -1.0), vec![0.5]);
    }

    /// Configuration factor of a differential area facing a parallel coaxial-plane disk of
    /// radius a at height h, offset r from its axis: F = (1 - (h^2 + r^2 - a^2) /
    /// sqrt((h^2 + r^2 + a^2)^2 - 4 r^2 a^2)) / 2; the integral of cos cos / d^2 is pi F.
    fn parallel_disk_factor(h: f64, r: f64, a: f64) -> f64 {
        let (h2, r2, a2) = (h * h, r * r, a * a);
        0.5 * (1.0 - (h2 + r2 - a2) / ((h2 + r2 + a2).powi(2) - 4.0 * r2 * a2).sqrt())
    }

    #[test]
    fn unoccluded_irradiance_is_the_parallel_disk_configuration_factor() {
        for (h, a) in [(2.0, 0.02), (1.0, 0.5), (0.1, 0.05), (0.01, 0.1), (0.002, 0.02)] {
            let l = down_light(DVec3::new(0.0, 0.0, h), a);
            for r in [0.0, 0.3 * a, a, 3.0 * a, 40.0 * a] {
                let (f, whole) = irradiance_fraction_estimate(DVec3::new(r, 0.0, 0.0), DVec3::Z, &l, &[], &[]);
                let exact = PI * parallel_disk_factor(h, r, a);
                // Within 1e-9 relative, or the quadrature's absolute tolerance (TOLERANCE of
                // pi a^2 / d^2) where the disk is seen at grazing angles and the value is tiny.
                let tol = (1e-9 * exact).max(TOLERANCE * PI * a * a / (h * h + r * r));
                assert!((whole - exact).abs() < tol, "h {h} a {a} r {r}: {whole} vs {exact}");
                assert_eq!(f.value, 1.0);
            }
        }
    }

    /// A tilted receiver sees part of the disk below its horizon: the unoccluded integral is
    /// the area's weighted integral above the horizon only, checked here against a fine
    /// midpoint sum over the disk (an independent path).
    #[test]
    fn a_horizon_cuts_the_unoccluded_irradiance() {
        let l = down_light(DVec3::new(0.0, 0.0, 0.3), 0.2);
        let n = DVec3::new(1.0, 0.0, 0.2).normalize();
        let p = DVec3::new(0.05, 0.0, 0.0);
        let (f, whole) = irradiance_fraction_estimate(p, n, &l, &[], &[]);
        let steps = 2000;
        let h = 2.0 * l.radius / steps as f64;
        let mut sum = 0.0;
        for i in 0..steps {
            for j in 0..steps {
                let (x, y) = (-l.radius + (i as f64 + 0.5) * h, -l.radius + (j as f64 + 0.5) * h);
                if x * x + y * y < l.radius * l.radius {
                    let d = l.center + DVec3::new(x, y, 0.0) - p;
                    let d2 = d.length_squared();
                    sum += n.dot(d).max(0.0) * (-l.normal.dot(d)).max(0.0) / (d2 * d2) * h * h;
                }
            }
        }
        assert!((whole / sum - 1.0).abs() < 2e-4, "{whole} vs midpoint {sum}");
        assert_eq!(f.value, 1.0, "the horizon is in the whole, not an occluder of it");
    }

    /// In the shipped scene's penumbra the irradiance-weighted fraction agrees with a
    /// stratified estimate over the disk (an independent path: point tests, no roots) within
    /// its sampling error, and differs from the area fraction V by more than that error: the
    /// two conventions are distinguishable, which is why the judge uses this one.
    #[test]
    fn the_irradiance_fraction_matches_a_stratified_estimate_and_differs_from_v() {
        let l = down_light(DVec3::new(0.0, 0.0, 2.0), 0.02);
        let s = [Sphere {
            center: DVec3::new(0.0, 0.0, 0.5),
            radius: 0.25,
            albedo: 0.8,
        }];
        let (u, v) = l.basis();
        let mut separated = 0;
        for r in [0.333, 0.336, 0.339, 0.342] {
            let p = DVec3::new(r, 0.0, 0.0);
            let (f, whole) = irradiance_fraction_estimate(p, DVec3::Z, &l, &s, &[]);
            let m = 1200;
            let (mut vis, mut all) = (0.0, 0.0);
            for i in 0..m {
                for j in 0..m {
                    // Stratified in (rho^2, theta) with a fixed interior offset: uniform by area.
                    let (a, b) = ((i as f64 + 0.37) / m as f64, (j as f64 + 0.61) / m as f64);
                    let (rho, th) = (l.radius * a.sqrt(), TAU * b);
                    let q = l.center + rho * (th.cos() * u + th.sin() * v);
                    let d = q - p;
                    let d2 = d.length_squared();
                    let w = DVec3::Z.dot(d) * (-l.normal.dot(d)) / (d2 * d2);
                    all += w;
                    if is_visible(p, DVec3::Z, q, &s, &[]) {
                        vis += w;
                    }
                }
            }
            let stratified = vis / all;
            // A stratified estimate errs only in the ~m cells the silhouette crosses (1/m^2
            // each, signs mixed): about m^-1.5 = 2.4e-5 here; measured 4e-6 to 4.2e-5.
            let tol = 1.5e-4;
            assert!((f.value - stratified).abs() < tol, "r {r}: {} vs {stratified}", f.value);
            assert!((whole / (PI * parallel_disk_factor(2.0, r, 0.02)) - 1.0).abs() < 1e-9);
            let area = visible_fraction(p, DVec3::Z, &l, &s, &[]);
            separated += ((f.value - area).abs() > tol) as u32;
        }
        // Measured: the weighted fraction exceeds V by 5e-4 to 1.4e-3 at these four points.
        assert_eq!(separated, 4, "the weighting moved a point by less than the error");
    }
}
