//! The visibility-field paper's scaling scenes (Fig. 5): "uniformly distributed random
//! triangles". The paper states no size distribution; here each triangle's centre is uniform in
//! the cube [-1, 1]^3 and its corners lie at distance `a` from the centre along three
//! independent uniform directions, with a = 0.05 m at 9K triangles scaled by count^(-1/2): the
//! total area, and so the number of triangles a ray crossing the cube meets on average, stays
//! the same at every count, and frame times compare structures rather than occlusion.

use super::{Generated, Part};
use crate::sampling::rng::{pcg, to_unit};
use crate::scene::camera::{Camera, Projection};
use crate::scene::Light;
use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// The size distribution in a sentence, for reports.
pub const DISTRIBUTION: &str = "each triangle's centre is uniform in the cube [-1, 1]^3 and its three corners lie at distance a = 0.05 m x (9000 / N)^(1/2) from it along independent uniform directions, so the total area (and the triangles a ray crossing the cube meets, about 2 on average) stays the same at every count N";

/// Corner distance from the centre at `count` triangles.
pub fn corner_distance(count: usize) -> f64 {
    0.05 * (9000.0 / count.max(1) as f64).sqrt()
}

/// `count` random triangles from `seed` (same count and seed, same triangles), lit by one
/// point light above a corner of the cube.
pub fn random_triangles(count: usize, seed: u32) -> Generated {
    let mut index = 0u32;
    let base = pcg(seed ^ 0x7261_6e64);
    let mut next = || {
        index += 1;
        to_unit(pcg(base ^ pcg(index)))
    };
    let a = corner_distance(count);
    let mut part = Part::new("triangles", 0.7);
    for _ in 0..count {
        let c = DVec3::new(2.0 * next() - 1.0, 2.0 * next() - 1.0, 2.0 * next() - 1.0);
        let mut corner = || {
            let z = 2.0 * next() - 1.0;
            let phi = TAU * next();
            let s = (1.0 - z * z).sqrt();
            c + a * DVec3::new(s * phi.cos(), s * phi.sin(), z)
        };
        part.triangles.push([corner(), corner(), corner()]);
    }
    Generated {
        description: format!("{count} random triangles, seed {seed}"),
        parts: vec![part],
        lights: vec![Light::Point {
            position: DVec3::new(3.0, -2.0, 4.0),
            power: 4.0 * PI * 30.0,
        }],
    }
}

/// The two viewpoints' short camera paths, `frames` frames each: `outside`, orbiting the cube
/// at 3.2 m by 1 degree a frame, and `inside`, walking from one corner region towards the
/// centre by 2 cm a frame, among the triangles.
pub fn camera_path(viewpoint: &str, frame: u32) -> Option<Camera> {
    let f = frame as f64;
    let (position, look_at) = match viewpoint {
        "outside" => {
            let az = (-60.0 + f).to_radians();
            let el = 25f64.to_radians();
            (
                3.2 * DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin()),
                DVec3::ZERO,
            )
        }
        "inside" => {
            let dir = DVec3::new(1.0, 1.0, 0.25).normalize();
            let p = DVec3::new(-0.9, -0.9, -0.2) + dir * 0.02 * f;
            (p, p + dir)
        }
        _ => return None,
    };
    Some(looking(position, look_at))
}

/// Camera `frame` of `viewpoint` drawn at random, independently of every other frame, from the
/// seeded stream `seed`: `outside`, at 3.2 m from the centre at an azimuth uniform in [0, 360)
/// degrees and an elevation uniform in [10, 40] degrees, looking at the centre; `inside`,
/// anywhere in [-0.8, 0.8]^3 looking at a point uniform in the core [-0.3, 0.3]^3 at least
/// 0.3 m away and not within 25 degrees of vertical (drawn again until it is), so that every
/// inside view looks through the triangles rather than out of the cube past its edge. Frames
/// drawn so are independent samples of the viewpoint's cameras, so a median over them has an
/// exact order-statistic interval (a path's consecutive frames are correlated and do not).
pub fn random_camera(viewpoint: &str, seed: u32, frame: u32) -> Option<Camera> {
    let stream = crate::sampling::Stream::new(seed, 0, Some(frame));
    let u = |i: u32| stream.unit(i);
    let angle = |i: u32, lo: f64, hi: f64| (lo + (hi - lo) * u(i)).to_radians();
    let along = |az: f64, el: f64| DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
    let point = |i: u32, half: f64| (DVec3::new(u(i), u(i + 1), u(i + 2)) * 2.0 - DVec3::ONE) * half;
    let (position, look_at) = match viewpoint {
        "outside" => (3.2 * along(angle(0, 0.0, 360.0), angle(1, 10.0, 40.0)), DVec3::ZERO),
        "inside" => (0..)
            .map(|k| (point(6 * k, 0.8), point(6 * k + 3, 0.3)))
            .find(|&(p, t)| {
                let d = t - p;
                d.length() >= 0.3 && d.normalize().z.abs() <= 25f64.to_radians().cos()
            })
            .expect("a draw succeeds with probability above one half"),
        _ => return None,
    };
    Some(looking(position, look_at))
}

/// The viewpoints' camera at `position` looking at `look_at`, z up, 60 degrees vertical field.
fn looking(position: DVec3, look_at: DVec3) -> Camera {
    Camera {
        position,
        look_at,
        up: DVec3::Z,
        projection: Projection::Perspective { fov_y_deg: 60.0 },
    }
}

/// The viewpoints [`camera_path`] and [`random_camera`] know.
pub const VIEWPOINTS: [&str; 2] = ["outside", "inside"];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangles_are_seeded_inside_the_padded_cube_and_sized_as_stated() {
        let g = random_triangles(2000, 3);
        assert_eq!(g.triangles().positions, random_triangles(2000, 3).triangles().positions);
        assert_ne!(g.triangles().positions, random_triangles(2000, 4).triangles().positions);
        let a = corner_distance(2000);
        let mut centre_mean = DVec3::ZERO;
        for t in &g.parts[0].triangles {
            let c = (t[0] + t[1] + t[2]) / 3.0;
            assert!(c.abs().max_element() <= 1.0 + a);
            centre_mean += c / 2000.0;
        }
        assert!(
            centre_mean.length() < 0.06,
            "uniform centres average near 0: {centre_mean}"
        );
        assert!((corner_distance(36_000) - 0.025).abs() < 1e-15);
    }
}
