//! Seeded ray generators shared by the visibility-field tests: every kind of ray the renderer
//! and the AO experiments cast, over any `Triangles` (a soup, the body, the OFF meshes).

use glam::DVec3;
use penumbra::accel::vlf::directions::Directions;
use penumbra::mesh::Triangles;

/// The seeded generator the benches draw with too.
pub use penumbra::sampling::rng::Seeded as Rng;

/// A query: origin, unit direction, tmax, skip.
pub type Ray = (DVec3, DVec3, f64, u32);

pub fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

pub fn tris(positions: Vec<[DVec3; 3]>) -> Triangles {
    let n = positions.len();
    Triangles {
        positions,
        object_of: (0..n as u32).map(|i| i % 4).collect(),
    }
}

pub fn bounds(t: &Triangles) -> (DVec3, DVec3) {
    t.positions.iter().flatten().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}

pub fn point_on(t: &[DVec3; 3], r: &mut Rng) -> DVec3 {
    r.point_on(t)
}

pub fn normal(t: &[DVec3; 3]) -> DVec3 {
    (t[1] - t[0]).cross(t[2] - t[0]).normalize_or(DVec3::Z)
}

/// Random segments between points of the (20 % enlarged) bounding box.
pub fn random_segments(t: &Triangles, n: usize, r: &mut Rng) -> Vec<Ray> {
    let (lo, hi) = bounds(t);
    let (c, h) = (0.5 * (lo + hi), 0.6 * (hi - lo) + DVec3::splat(1e-3));
    (0..n)
        .map(|_| {
            let p = |r: &mut Rng| c + h * v(r.range(-1., 1.), r.range(-1., 1.), r.range(-1., 1.));
            let (a, b) = (p(r), p(r));
            let d = (b - a).normalize_or(DVec3::X);
            (a, d, (b - a).length(), u32::MAX)
        })
        .collect()
}

/// AO rays from points on triangles along stored directions (both orientations, the one into
/// the triangle's front and its opposite), length 4 ball radii, skipping the start triangle.
pub fn ao_grid(t: &Triangles, dirs: &Directions, n: usize, r: &mut Rng) -> Vec<Ray> {
    let (lo, hi) = bounds(t);
    let len = 2.0 * (hi - lo).length();
    (0..n)
        .map(|k| {
            let i = r.index(t.positions.len());
            let w = dirs.direction(r.index(dirs.len()) as u32);
            let d = if (k % 2 == 0) == (w.dot(normal(&t.positions[i])) >= 0.0) {
                w
            } else {
                -w
            };
            (point_on(&t.positions[i], r), d, len, i as u32)
        })
        .collect()
}

/// AO rays in uniformly random directions of each point's normal hemisphere.
pub fn ao_random(t: &Triangles, n: usize, r: &mut Rng) -> Vec<Ray> {
    let (lo, hi) = bounds(t);
    let len = 2.0 * (hi - lo).length();
    (0..n)
        .map(|_| {
            let i = r.index(t.positions.len());
            let d = r.unit();
            let d = if d.dot(normal(&t.positions[i])) < 0.0 { -d } else { d };
            (point_on(&t.positions[i], r), d, len, i as u32)
        })
        .collect()
}

/// Shadow rays from points on triangles to a 4 cm disk light above the scene (tmax: the light).
pub fn shadow_rays(t: &Triangles, n: usize, r: &mut Rng) -> Vec<Ray> {
    let (lo, hi) = bounds(t);
    let centre = v(
        0.5 * (lo.x + hi.x) + 0.3 * (hi.x - lo.x),
        0.5 * (lo.y + hi.y),
        hi.z + 0.5 * (hi - lo).length(),
    );
    (0..n)
        .map(|_| {
            let i = r.index(t.positions.len());
            let p = point_on(&t.positions[i], r);
            let (rad, ang) = (0.02 * r.f().sqrt(), r.range(0., std::f64::consts::TAU));
            let q = centre + v(rad * ang.cos(), rad * ang.sin(), 0.0);
            ((p), (q - p).normalize(), (q - p).length(), i as u32)
        })
        .collect()
}

/// Camera rays from a point outside the scene through random points of its box (tmax infinite).
pub fn camera_rays(t: &Triangles, n: usize, r: &mut Rng) -> Vec<Ray> {
    let (lo, hi) = bounds(t);
    let eye = 0.5 * (lo + hi) + v(0.3, -2.0, 0.8) * (hi - lo).length();
    (0..n)
        .map(|_| {
            let target = lo + (hi - lo) * v(r.f(), r.f(), r.f());
            (eye, (target - eye).normalize(), f64::INFINITY, u32::MAX)
        })
        .collect()
}

/// Rays aimed at vertices and edge midpoints from outside, and rays starting or ending exactly
/// on a triangle (no skip), and grazing rays nearly in a triangle's plane.
pub fn touching_rays(t: &Triangles, n: usize, r: &mut Rng) -> Vec<Ray> {
    let (lo, hi) = bounds(t);
    let size = (hi - lo).length().max(1e-9);
    let mut out = Vec::new();
    for k in 0..n {
        let i = r.index(t.positions.len());
        let tri = &t.positions[i];
        let p = match k % 3 {
            0 => tri[k % 3],
            1 => 0.5 * (tri[0] + tri[1]),
            _ => point_on(tri, r),
        };
        let d = r.unit();
        out.push((p - d * size * r.range(0.1, 2.0), d, f64::INFINITY, u32::MAX));
        out.push((p, d, f64::INFINITY, u32::MAX));
        out.push((p - d * size * 0.5, d, size * 0.5, u32::MAX));
        let nrm = normal(tri);
        let inplane = (tri[1] - tri[0]).normalize_or(DVec3::X);
        let g = (inplane + nrm * 10f64.powf(r.range(-9., -2.))).normalize();
        out.push((p - g * size * 0.3, g, f64::INFINITY, u32::MAX));
    }
    out
}

/// Every kind of ray, `n` of each.
pub fn all_rays(t: &Triangles, dirs: &Directions, n: usize, seed: u32) -> Vec<(&'static str, Vec<Ray>)> {
    let mut r = Rng(seed);
    vec![
        ("segments", random_segments(t, n, &mut r)),
        ("ao-grid", ao_grid(t, dirs, n, &mut r)),
        ("ao-random", ao_random(t, n, &mut r)),
        ("shadow", shadow_rays(t, n, &mut r)),
        ("camera", camera_rays(t, n, &mut r)),
        ("touching", touching_rays(t, n / 4, &mut r)),
    ]
}

/// Random triangles of mixed sizes (large, tile-sized, far smaller than a tile, slivers,
/// degenerate) in a box off the origin.
pub fn soup(n: usize, seed: u32) -> Triangles {
    let mut r = Rng(seed);
    let offset = v(3.0, -2.0, 1.5);
    let mut out = Vec::new();
    for k in 0..n {
        let c = offset + v(r.range(-1., 1.), r.range(-1., 1.), r.range(-0.5, 0.5));
        let s = [0.5, 0.05, 0.01, 1e-5][k % 4];
        let (a, b) = (r.unit() * s, r.unit() * s);
        out.push(match k % 23 {
            7 => [c, c + a, c + 2.0 * a],       // collinear
            11 => [c, c, c],                    // a point
            13 => [c, c + a, c + a + b * 1e-9], // sliver
            _ => [c, c + a, c + b],
        });
    }
    tris(out)
}
