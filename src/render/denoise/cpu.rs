//! The filters in f64: the reference the WGSL kernels (`gpu/shaders/denoise.wgsl`) follow line
//! for line in f32; change both together.

use super::{gaussian_radius, Filter, Input, Output, B3, DIRECTIONLESS, DIRECTION_SIGMA, LUMINANCE_EPSILON, MIN_SIGMA};
use rayon::prelude::*;

/// Runs `filter` on `input`.
pub fn apply(filter: Filter, input: &Input) -> Output {
    let image = match filter {
        Filter::None => input.image.to_vec(),
        Filter::Gaussian => {
            let sigma = input.settings.gaussian_sigma;
            per_pixel(input, |x, y| gaussian_at(input, x, y, sigma, false))
        }
        Filter::Penumbra => per_pixel(input, |x, y| {
            let along = input.sigma[index(input, x, y)] as f64;
            if along < MIN_SIGMA {
                input.image[index(input, x, y)] as f64
            } else {
                oriented_at(input, x, y, along)
            }
        }),
        Filter::Atrous => atrous(input),
    };
    Output {
        image,
        taps: input.taps(filter),
    }
}

fn index(input: &Input, x: i32, y: i32) -> usize {
    (y as u32 * input.width + x as u32) as usize
}

/// `value(x, y)` at every receiver pixel, [`crate::render::NO_RECEIVER`] elsewhere.
fn per_pixel(input: &Input, value: impl Fn(i32, i32) -> f64 + Sync) -> Vec<f32> {
    (0..input.pixels())
        .into_par_iter()
        .map(|i| {
            if !input.receives(i) {
                return crate::render::NO_RECEIVER;
            }
            let w = input.width as usize;
            value((i % w) as i32, (i / w) as i32) as f32
        })
        .collect()
}

/// Whether (x, y) is inside the image and has a receiver.
fn usable(input: &Input, x: i32, y: i32) -> bool {
    x >= 0 && y >= 0 && x < input.width as i32 && y < input.height as i32 && input.receives(index(input, x, y))
}

/// A normalised Gaussian of `sigma` pixels over the receiver pixels of its window, weighted by
/// the geometry where `guided`.
fn gaussian_at(input: &Input, x: i32, y: i32, sigma: f64, guided: bool) -> f64 {
    let r = gaussian_radius(sigma);
    let (mut sum, mut weight) = (0.0, 0.0);
    let slope = depth_slope(input, x, y);
    for dy in -r..=r {
        for dx in -r..=r {
            let (qx, qy) = (x + dx, y + dy);
            if !usable(input, qx, qy) {
                continue;
            }
            let d2 = (dx * dx + dy * dy) as f64;
            let s = sigma as f32 as f64;
            let mut w = (-d2 / (2.0 * s * s)).exp();
            if guided {
                w *= geometry_weight(input, x, y, qx, qy, slope, d2.sqrt());
            }
            sum += w * input.image[index(input, qx, qy)] as f64;
            weight += w;
        }
    }
    sum / weight
}

/// The penumbra filter at (x, y): a 1-D Gaussian of `along` pixels along the shadow's edge,
/// weighted by the geometry, and nothing across it, so that it does not widen the penumbra. Its
/// taps lie on the edge's line through the pixel, one per pixel of the line's major axis, each
/// read by Catmull-Rom interpolation across the four pixels around the line, so the weights move
/// continuously as the direction turns. The edge's normal is the gradient of the weighted
/// least-squares plane through the values under an isotropic Gaussian of [`DIRECTION_SIGMA`];
/// where there is none (a flat or symmetric neighbourhood) the pixel is left as it is.
fn oriented_at(input: &Input, x: i32, y: i32, along: f64) -> f64 {
    let slope = depth_slope(input, x, y);
    let guided = |qx: i32, qy: i32| {
        let (fx, fy) = ((qx - x) as f64, (qy - y) as f64);
        geometry_weight(input, x, y, qx, qy, slope, (fx * fx + fy * fy).sqrt())
    };
    let value = |qx: i32, qy: i32| input.image[index(input, qx, qy)] as f64;
    let sd = DIRECTION_SIGMA as f32 as f64;
    let rd = gaussian_radius(sd);
    // One pass of weighted sums (q and I relative to p's): the least-squares plane's gradient
    // is C^-1 b with b = sum w (I - mean) (q - centroid) and C the window's covariance, which a
    // window cut by the image's border or by the geometry makes anisotropic. Values relative to
    // I_p keep b's cancellation small in f32 on a nearly flat fringe.
    let centre = value(x, y);
    let (mut w0, mut wv, mut wx, mut wy, mut wvx, mut wvy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut wxx, mut wxy, mut wyy) = (0.0, 0.0, 0.0);
    for dy in -rd..=rd {
        for dx in -rd..=rd {
            let (qx, qy) = (x + dx, y + dy);
            if !usable(input, qx, qy) {
                continue;
            }
            let (fx, fy) = (dx as f64, dy as f64);
            let w = guided(qx, qy) * (-(fx * fx + fy * fy) / (2.0 * sd * sd)).exp();
            let v = value(qx, qy) - centre;
            (w0, wv, wx, wy) = (w0 + w, wv + w * v, wx + w * fx, wy + w * fy);
            (wvx, wvy) = (wvx + w * v * fx, wvy + w * v * fy);
            (wxx, wxy, wyy) = (wxx + w * fx * fx, wxy + w * fx * fy, wyy + w * fy * fy);
        }
    }
    let (bx, by) = (wvx - wv * wx / w0, wvy - wv * wy / w0);
    if (bx * bx + by * by).sqrt() <= DIRECTIONLESS * w0 {
        return centre;
    }
    let (cxx, cxy, cyy) = (wxx - wx * wx / w0, wxy - wx * wy / w0, wyy - wy * wy / w0);
    // C^-1 b up to its determinant, positive unless every usable pixel of the window lies on
    // one line: then there is no plane to fit, and no direction.
    let (nx, ny) = (cyy * bx - cxy * by, cxx * by - cxy * bx);
    let norm = (nx * nx + ny * ny).sqrt();
    if norm.is_nan() || norm <= 0.0 {
        return centre;
    }
    // The edge's tangent, walked along its major axis.
    let (tx, ty) = (-ny / norm, nx / norm);
    let x_major = tx.abs() >= ty.abs();
    let minor_per_step = if x_major { ty / tx } else { tx / ty };
    let distance_per_step = (1.0 + minor_per_step * minor_per_step).sqrt();
    let sa = along as f32 as f64;
    let r = gaussian_radius(along);
    let (mut sum, mut weight, mut lo, mut hi) = (0.0, 0.0, f64::INFINITY, f64::NEG_INFINITY);
    for k in -r..=r {
        let t = k as f64 * distance_per_step;
        let g = (-t * t / (2.0 * sa * sa)).exp();
        let offset = k as f64 * minor_per_step;
        let below = offset.floor();
        let f = offset - below;
        let pixel = |j: i32| {
            let m = below as i32 + j - 1;
            if x_major {
                (x + k, y + m)
            } else {
                (x + m, y + k)
            }
        };
        // Where a hole cuts the four, the step falls back to the two around the line, linearly:
        // the negative lobes must not outweigh what is left.
        let whole = (0..4).all(|j| {
            let (qx, qy) = pixel(j);
            usable(input, qx, qy)
        });
        let shares = if whole { catmull_rom(f) } else { [0.0, 1.0 - f, f, 0.0] };
        for (j, share) in shares.into_iter().enumerate() {
            let (qx, qy) = pixel(j as i32);
            if !usable(input, qx, qy) {
                continue;
            }
            let (w, v) = (g * share * guided(qx, qy), value(qx, qy));
            (sum, weight) = (sum + w * v, weight + w);
            (lo, hi) = (lo.min(v), hi.max(v));
        }
    }
    // The centre's tap alone weighs 1; under half that, the lobes of taps whose neighbours the
    // geometry cut away dominate and the sum means nothing.
    if weight < 0.5 {
        return centre;
    }
    // Catmull-Rom's negative lobes can ring past the values read.
    (sum / weight).clamp(lo, hi)
}

/// Catmull-Rom weights of the four pixels at -1, 0, 1, 2 around a point `f` in [0, 1) past
/// pixel 0: exact on quadratics, so that reading a penumbra's profile between pixels hardly
/// blurs it (linear interpolation would, by up to 0.5 px).
fn catmull_rom(f: f64) -> [f64; 4] {
    let (f2, f3) = (f * f, f * f * f);
    [
        (-f + 2.0 * f2 - f3) / 2.0,
        (2.0 - 5.0 * f2 + 3.0 * f3) / 2.0,
        (f + 4.0 * f2 - 3.0 * f3) / 2.0,
        (-f2 + f3) / 2.0,
    ]
}

/// The depth change per pixel at (x, y): the larger central (or one-sided, at an edge of the
/// image or of the receivers) difference of the two axes.
fn depth_slope(input: &Input, x: i32, y: i32) -> f64 {
    let z = |x: i32, y: i32| input.gbuffer.depth[index(input, x, y)] as f64;
    let axis = |dx: i32, dy: i32| {
        let (a, b) = ((x - dx, y - dy), (x + dx, y + dy));
        match (usable(input, a.0, a.1), usable(input, b.0, b.1)) {
            (true, true) => (z(b.0, b.1) - z(a.0, a.1)).abs() / 2.0,
            (true, false) => (z(x, y) - z(a.0, a.1)).abs(),
            (false, true) => (z(b.0, b.1) - z(x, y)).abs(),
            (false, false) => 0.0,
        }
    };
    axis(1, 0).max(axis(0, 1))
}

/// SVGF's edge-stopping by geometry (eqs. 3, 4): depth differences against the local slope
/// times the distance, and the normals' cosine to the power sigma_n.
fn geometry_weight(input: &Input, x: i32, y: i32, qx: i32, qy: i32, slope: f64, distance: f64) -> f64 {
    let s = &input.settings;
    let (p, q) = (index(input, x, y), index(input, qx, qy));
    let (zp, zq) = (input.gbuffer.depth[p] as f64, input.gbuffer.depth[q] as f64);
    let scale = (s.atrous_sigma_depth * slope * distance).max(1e-3 * zp);
    let wz = (-(zp - zq).abs() / scale).exp();
    let (np, nq) = (input.gbuffer.normal[p], input.gbuffer.normal[q]);
    let cos = np[0] as f64 * nq[0] as f64 + np[1] as f64 * nq[1] as f64 + np[2] as f64 * nq[2] as f64;
    wz * cos.max(0.0).powf(s.atrous_sigma_normal)
}

/// SVGF's a-trous iterations (eqs. 1, 2, 5): each a 5 x 5 B3-spline kernel at step 2^k, weighted
/// by geometry and by value differences against the 3 x 3-blurred standard deviation, which
/// each iteration filters with the squared weights.
fn atrous(input: &Input) -> Vec<f32> {
    let mut image: Vec<f64> = input.image.iter().map(|&v| v as f64).collect();
    let mut variance: Vec<f64> = input.variance.iter().map(|&v| v as f64).collect();
    for k in 0..input.settings.atrous_iterations {
        let step = 1i32 << k;
        let next: Vec<(f64, f64)> = (0..input.pixels())
            .into_par_iter()
            .map(|i| {
                if !input.receives(i) {
                    return (crate::render::NO_RECEIVER as f64, 0.0);
                }
                let w = input.width as usize;
                atrous_at(input, &image, &variance, (i % w) as i32, (i / w) as i32, step)
            })
            .collect();
        image = next.iter().map(|v| v.0).collect();
        variance = next.iter().map(|v| v.1).collect();
    }
    image.iter().map(|&v| v as f32).collect()
}

/// One a-trous tap set at (x, y): the filtered value and variance.
fn atrous_at(input: &Input, image: &[f64], variance: &[f64], x: i32, y: i32, step: i32) -> (f64, f64) {
    let s = &input.settings;
    let p = index(input, x, y);
    let sd = blurred_variance(input, variance, x, y).sqrt();
    let denom = s.atrous_sigma_luminance * sd + LUMINANCE_EPSILON;
    let slope = depth_slope(input, x, y);
    let (mut sum, mut weight, mut var) = (0.0, 0.0, 0.0);
    for j in -2..=2i32 {
        for i in -2..=2i32 {
            let (qx, qy) = (x + step * i, y + step * j);
            if !usable(input, qx, qy) {
                continue;
            }
            let q = index(input, qx, qy);
            let distance = (step as f64) * ((i * i + j * j) as f64).sqrt();
            let h = B3[(i + 2) as usize] * B3[(j + 2) as usize];
            let w = h
                * geometry_weight(input, x, y, qx, qy, slope, distance)
                * (-(image[p] - image[q]).abs() / denom).exp();
            sum += w * image[q];
            weight += w;
            var += w * w * variance[q];
        }
    }
    (sum / weight, var / (weight * weight))
}

/// The variance at (x, y) under a 3 x 3 binomial blur over receiver pixels (SVGF's prefilter of
/// the luminance weight's variance).
fn blurred_variance(input: &Input, variance: &[f64], x: i32, y: i32) -> f64 {
    const K: [f64; 3] = [0.25, 0.5, 0.25];
    let (mut sum, mut weight) = (0.0, 0.0);
    for j in -1..=1i32 {
        for i in -1..=1i32 {
            if usable(input, x + i, y + j) {
                let w = K[(i + 1) as usize] * K[(j + 1) as usize];
                sum += w * variance[index(input, x + i, y + j)];
                weight += w;
            }
        }
    }
    sum / weight
}
