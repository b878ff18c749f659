//! The penumbra's width in any scene, not only on-axis ones: the profile of an image across the
//! reference's half-shadow contour.
//!
//! - Contour: where the reference crosses 1/2 between 4-neighbour receiver pixels, joined cell
//!   by cell into segments (marching squares).
//! - Signed distance: each receiver pixel's distance (pixels) to the nearest contour segment,
//!   positive on the lit side (reference >= 1/2). The nearest contour point read long between
//!   points, up to 0.3 px near a slanted edge. Pixels whose nearest point is past an open end of
//!   the contour (an image border, a receiver's edge) are left out: no distance across it exists.
//! - Profile: the mean of the image over pixels in bins of [`BIN`] pixels of signed distance, at
//!   their mean distance (on an axis-aligned or diagonal edge they sit at one distance, up to a
//!   quarter bin from the bin's centre).
//! - 10-90 % width: d(V = 0.9) - d(V = 0.1), each the first crossing going outwards from the
//!   contour. Averaging along the contour is what lets a one-ray image have a width at all. On
//!   an on-axis scene it reads what the radial profile reads ([`super::RadialProfile`]).
//!
//! Between samples (contour points between pixels, crossings between bins) the profile is taken
//! to be a disk light's penumbra behind a straight edge, V = [`disk_edge`](alpha + beta d): the
//! reference's own shape. Linear in V, which bends to 0 and 1 within a pixel or two of the 10
//! and 90 % levels, read 2-8 px penumbrae up to 26 % wide (module tests). On any other profile
//! it is still a monotone curve through the bins.

use crate::render::NO_RECEIVER;
use std::f64::consts::PI;
use std::ops::Range;

/// Bin width of the profile, pixels.
pub const BIN: f64 = 0.5;

/// The lit share of a disk light of radius 1 whose centre is `u` radii on the lit side of a
/// straight occluding edge: the circular segment's area (acos(-u) + u sqrt(1 - u^2)) / pi.
/// It runs from 0 at u = -1 to 1 at u = 1, and 1 - V(u) = V(-u).
pub fn disk_edge(u: f64) -> f64 {
    let u = u.clamp(-1.0, 1.0);
    0.5 + (u.asin() + u * (1.0 - u * u).sqrt()) / PI
}

/// The inverse of [`disk_edge`] on [0, 1] (by bisection, to f64 precision); -1 and 1 outside.
pub fn disk_edge_inverse(v: f64) -> f64 {
    if v.is_nan() {
        return f64::NAN;
    }
    let (mut lo, mut hi) = (-1.0f64, 1.0f64);
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if disk_edge(mid) < v {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The exact 10-90 % width of the straight-edge penumbra of a disk light whose penumbra is
/// `full` wide (0 to 1, the light's image through the edge): full * u(0.9), as u(0.1) = -u(0.9).
pub fn disk_edge_width_10_90(full: f64) -> f64 {
    full * disk_edge_inverse(0.9)
}

/// The reference's contour and every receiver pixel's signed distance to it.
#[derive(Clone, Debug)]
pub struct EdgeProfile {
    /// (pixel index, signed distance in pixels) of receiver pixels within `reach` of the contour,
    /// ascending by distance.
    pub pixels: Vec<(usize, f64)>,
    /// Contour points found.
    pub contour: usize,
    /// The non-empty bins of the profile, ascending: their ranges in `pixels`.
    bins: Vec<Range<usize>>,
}

impl EdgeProfile {
    /// The contour of `reference` (a `width` x `height` image, [`NO_RECEIVER`] where none) and
    /// the signed distances of receiver pixels up to `reach` pixels from it.
    pub fn new(reference: &[f32], width: u32, height: u32, reach: f64) -> EdgeProfile {
        let w = width as usize;
        let contour = Contour::new(reference, w, height as usize);
        let mut pixels = Vec::new();
        for (i, &v) in reference.iter().enumerate().take(w * height as usize) {
            if v == NO_RECEIVER {
                continue;
            }
            match contour.distance((i % w) as f64, (i / w) as f64) {
                Some(d) if d <= reach => pixels.push((i, if v >= 0.5 { d } else { -d })),
                _ => {}
            }
        }
        pixels.sort_by(|a, b| a.1.total_cmp(&b.1));
        let bin = |d: f64| ((d + reach) / BIN).floor() as i64;
        let mut bins: Vec<Range<usize>> = Vec::new();
        for k in 0..pixels.len() {
            match bins.last_mut() {
                Some(last) if bin(pixels[last.start].1) == bin(pixels[k].1) => last.end = k + 1,
                _ => bins.push(k..k + 1),
            }
        }
        EdgeProfile {
            pixels,
            contour: contour.crossings,
            bins,
        }
    }

    /// The profile of `image`: (mean signed distance of the bin's pixels, mean of `image` over
    /// them) for every non-empty bin, ascending.
    pub fn profile(&self, image: &[f32]) -> Vec<(f64, f64)> {
        self.bins
            .iter()
            .map(|r| {
                let n = r.len() as f64;
                let px = &self.pixels[r.clone()];
                (
                    px.iter().map(|p| p.1).sum::<f64>() / n,
                    px.iter().map(|p| image[p.0] as f64).sum::<f64>() / n,
                )
            })
            .collect()
    }

    /// The 10-90 % width of `image` across the contour, pixels; NaN where the profile does not
    /// reach 0.1 on the dark side or 0.9 on the lit side within the reach.
    pub fn width_10_90(&self, image: &[f32]) -> f64 {
        let p = self.profile(image);
        let Some(zero) = p.iter().position(|&(d, _)| d >= 0.0) else {
            return f64::NAN;
        };
        self.crossing(&p, zero as isize, 0.9, 1) - self.crossing(&p, zero as isize - 1, 0.1, -1)
    }

    /// Where profile `p` first reaches `level` going from bin `start` outwards (`dir` 1: the lit
    /// side, up to `level`; -1: the dark side, below it): on the disk-edge curve whose means over
    /// the pixels of the bins either side of it are those bins' means ([`fit`]). A lit (or dark)
    /// bin, within [`SATURATED`] of 1 (or 0), only bounds where the penumbra ends, so past one
    /// the curve is fitted to the two bins short of it. The crossing is kept within the bins
    /// either side.
    fn crossing(&self, p: &[(f64, f64)], start: isize, level: f64, dir: isize) -> f64 {
        let at = |i: isize| usize::try_from(i).ok().filter(|&i| i < p.len());
        let reached = |v: f64| if dir > 0 { v >= level } else { v < level };
        let inside = |v: f64| v > SATURATED && v < 1.0 - SATURATED;
        let distances = |b: usize| {
            self.pixels[self.bins[b].clone()]
                .iter()
                .map(|p| p.1)
                .collect::<Vec<f64>>()
        };
        let mut i = start;
        while let Some(b) = at(i) {
            if !reached(p[b].1) {
                i += dir;
                continue;
            }
            // The bin before it, across the contour where it is the first.
            let Some(a) = at(i - dir).filter(|&a| !reached(p[a].1)) else {
                return p[b].0;
            };
            let (near, far) = (self.bins[a.min(b)].start, self.bins[a.max(b)].end - 1);
            let within = |d: f64| d.clamp(self.pixels[near].1, self.pixels[far].1);
            // The two bins the curve goes through.
            let pair = if inside(p[b].1) {
                Some((a, b))
            } else {
                at(i - 2 * dir).map(|c| (c, a))
            };
            if let Some((c, a)) = pair.filter(|&(c, a)| inside(p[c].1) && inside(p[a].1)) {
                if let Some((alpha, beta)) = fit(&distances(c), p[c].1, &distances(a), p[a].1) {
                    return within((disk_edge_inverse(level) - alpha) / beta);
                }
            }
            let (ua, ub) = (disk_edge_inverse(p[a].1), disk_edge_inverse(p[b].1));
            return if ua == ub {
                p[b].0
            } else {
                within(p[a].0 + (disk_edge_inverse(level) - ua) * (p[b].0 - p[a].0) / (ub - ua))
            };
        }
        f64::NAN
    }
}

/// How close to 0 or 1 a bin's mean may come and still place the disk-edge curve: a bin whose
/// pixels lie mostly past the penumbra's end says only that it ends, and fitting the curve to
/// its mean would make the width jump with a change of 1e-9 in it.
pub const SATURATED: f64 = 0.01;

/// The reference's half-shadow contour: points where it crosses 1/2 and the segments that join
/// them.
struct Contour {
    points: Vec<(f64, f64)>,
    segments: Vec<[usize; 2]>,
    /// Segments meeting at each point: under 2 at an open end.
    degree: Vec<u32>,
    /// Points on no segment.
    lone: Vec<usize>,
    /// 4-neighbour pairs the contour crosses.
    crossings: usize,
}

impl Contour {
    fn new(reference: &[f32], w: usize, h: usize) -> Contour {
        let value = |x: usize, y: usize| reference[y * w + x];
        let mut points = Vec::new();
        // The point between (x, y) and its right (k = 0) or lower (k = 1) neighbour, at
        // 2 (y w + x) + k; one on a pixel's centre (a value of exactly 1/2) is one point for all
        // its pairs.
        let mut on_pair: Vec<Option<usize>> = vec![None; 2 * w * h];
        let mut on_pixel: Vec<Option<usize>> = vec![None; w * h];
        let mut crossings = 0;
        for y in 0..h {
            for x in 0..w {
                let a = value(x, y);
                if a == NO_RECEIVER {
                    continue;
                }
                for (k, (nx, ny)) in [(x + 1, y), (x, y + 1)].into_iter().enumerate() {
                    if nx >= w || ny >= h {
                        continue;
                    }
                    let b = value(nx, ny);
                    if b == NO_RECEIVER || (a >= 0.5) == (b >= 0.5) {
                        continue;
                    }
                    crossings += 1;
                    let (ua, ub) = (disk_edge_inverse(a as f64), disk_edge_inverse(b as f64));
                    let t = if a == 0.5 {
                        0.0
                    } else if b == 0.5 {
                        1.0
                    } else if ua == ub {
                        0.5
                    } else {
                        (ua / (ua - ub)).clamp(0.0, 1.0)
                    };
                    let id = if t == 0.0 || t == 1.0 {
                        let (px, py) = if t == 0.0 { (x, y) } else { (nx, ny) };
                        *on_pixel[py * w + px].get_or_insert_with(|| {
                            points.push((px as f64, py as f64));
                            points.len() - 1
                        })
                    } else {
                        points.push((x as f64 + t * (nx - x) as f64, y as f64 + t * (ny - y) as f64));
                        points.len() - 1
                    };
                    on_pair[2 * (y * w + x) + k] = Some(id);
                }
            }
        }
        // Each 2 x 2 cell joins its points; a saddle (four) is split the way the cell's mean lies.
        let mut segments: Vec<[usize; 2]> = Vec::new();
        for y in 0..h.saturating_sub(1) {
            for x in 0..w.saturating_sub(1) {
                // Top, right, bottom, left sides, clockwise.
                let sides = [
                    2 * (y * w + x),
                    2 * (y * w + x + 1) + 1,
                    2 * ((y + 1) * w + x),
                    2 * (y * w + x) + 1,
                ];
                let crossed: Vec<usize> = sides.into_iter().filter_map(|s| on_pair[s]).collect();
                match crossed[..] {
                    [a, b] => segments.push([a, b]),
                    [top, right, bottom, left] => {
                        let corners = [value(x, y), value(x + 1, y), value(x + 1, y + 1), value(x, y + 1)];
                        let mean = corners.iter().map(|&v| v as f64).sum::<f64>() / 4.0;
                        if (corners[0] >= 0.5) == (mean >= 0.5) {
                            // Top-left and bottom-right join through the middle.
                            segments.extend([[top, right], [bottom, left]]);
                        } else {
                            segments.extend([[left, top], [right, bottom]]);
                        }
                    }
                    // None, or one beside a missing receiver.
                    _ => {}
                }
            }
        }
        segments.retain(|s| s[0] != s[1]);
        let mut degree = vec![0; points.len()];
        for &i in segments.iter().flatten() {
            degree[i] += 1;
        }
        Contour {
            lone: (0..points.len()).filter(|&i| degree[i] == 0).collect(),
            points,
            segments,
            degree,
            crossings,
        }
    }

    /// The distance from (x, y) to the nearest point of the contour; None where that point is
    /// past an open end (or there is none).
    fn distance(&self, x: f64, y: f64) -> Option<f64> {
        // (squared distance, whether past an open end).
        let mut best = (f64::INFINITY, true);
        let mut offer = |d2: f64, past: bool| {
            if d2 < best.0 || (d2 == best.0 && !past) {
                best = (d2, past);
            }
        };
        for &[i, j] in &self.segments {
            let ((ax, ay), (bx, by)) = (self.points[i], self.points[j]);
            let (ex, ey) = (bx - ax, by - ay);
            let t = ((x - ax) * ex + (y - ay) * ey) / (ex * ex + ey * ey);
            let past = (t < 0.0 && self.degree[i] < 2) || (t > 1.0 && self.degree[j] < 2);
            let t = t.clamp(0.0, 1.0);
            offer((x - ax - t * ex).powi(2) + (y - ay - t * ey).powi(2), past);
        }
        for &i in &self.lone {
            let (px, py) = self.points[i];
            offer((x - px).powi(2) + (y - py).powi(2), true);
        }
        (!best.1).then(|| best.0.sqrt())
    }
}

/// (alpha, beta), beta > 0, such that disk_edge(alpha + beta d) averages `va` over distances
/// `a` and `vb` over `b` (both strictly between 0 and 1): Newton's method from the line through
/// the bins' mean distances, None where it does not converge.
fn fit(a: &[f64], va: f64, b: &[f64], vb: f64) -> Option<(f64, f64)> {
    let mean = |d: &[f64]| d.iter().sum::<f64>() / d.len() as f64;
    let (ua, ub, da, db) = (disk_edge_inverse(va), disk_edge_inverse(vb), mean(a), mean(b));
    let beta = (ub - ua) / (db - da);
    let mut x = (ua - beta * da, beta);
    // Residuals and their Jacobian, d/d(alpha, beta) of each bin's mean.
    let eval = |(alpha, beta): (f64, f64)| {
        let one = |d: &[f64], v: f64| {
            let (mut f, mut ja, mut jb) = (0.0, 0.0, 0.0);
            for &d in d {
                let u = alpha + beta * d;
                let slope = 2.0 * (1.0 - u * u).max(0.0).sqrt() / PI;
                f += disk_edge(u);
                ja += slope;
                jb += slope * d;
            }
            let n = d.len() as f64;
            (f / n - v, ja / n, jb / n)
        };
        (one(a, va), one(b, vb))
    };
    let norm = |r: ((f64, f64, f64), (f64, f64, f64))| r.0 .0.abs().max(r.1 .0.abs());
    let mut r = eval(x);
    for _ in 0..100 {
        if norm(r) < 1e-13 {
            break;
        }
        let ((fa, aa, ab), (fb, ba, bb)) = r;
        let det = aa * bb - ab * ba;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let step = ((fa * bb - fb * ab) / det, (aa * fb - ba * fa) / det);
        let mut scale = 1.0;
        loop {
            let next = (x.0 - scale * step.0, x.1 - scale * step.1);
            let rn = eval(next);
            if norm(rn) < norm(r) {
                (x, r) = (next, rn);
                break;
            }
            scale *= 0.5;
            if scale < 1e-9 {
                return None;
            }
        }
    }
    (norm(r) < 1e-9 && x.1 > 0.0).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vertical straight edge: V(x) a linear ramp over `ramp` pixels centred at `centre`.
    fn ramp_image(w: u32, h: u32, centre: f64, ramp: f64) -> Vec<f32> {
        (0..w * h)
            .map(|i| (((i % w) as f64 - centre) / ramp + 0.5).clamp(0.0, 1.0) as f32)
            .collect()
    }

    #[test]
    fn a_linear_ramp_is_four_fifths_of_its_length_wide() {
        for (centre, ramp) in [(40.3, 10.0), (40.0, 24.0), (33.7, 6.5)] {
            let image = ramp_image(96, 16, centre, ramp);
            let edge = EdgeProfile::new(&image, 96, 16, 30.0);
            let width = edge.width_10_90(&image);
            // Bins of half a pixel sample the ramp; the disk-edge curve between two of them
            // bends little over half a pixel.
            assert!((width - 0.8 * ramp).abs() < 0.6, "ramp {ramp}: width {width}");
        }
    }

    #[test]
    fn a_step_has_no_width_and_no_receivers_no_contour() {
        let step = ramp_image(64, 8, 32.5, 1e-6);
        let edge = EdgeProfile::new(&step, 64, 8, 10.0);
        assert!(edge.width_10_90(&step) <= 1.0);
        let none = vec![NO_RECEIVER; 64];
        let e = EdgeProfile::new(&none, 8, 8, 10.0);
        assert_eq!(e.contour, 0);
        assert!(e.width_10_90(&none).is_nan());
    }

    /// Sub-pixel offsets, seeded (splitmix64).
    fn offsets(seed: u64, n: usize) -> Vec<(f64, f64)> {
        let mut state = seed;
        let mut next = || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        };
        std::iter::once((0.0, 0.0))
            .chain((1..n).map(|_| (next(), next())))
            .collect()
    }

    /// A `size`-pixel square point-sampled at pixel centres: V = disk_edge(s / (full / 2)),
    /// `s` the signed distance of (x, y) from the edge, for a 10-90 % width of `width`.
    fn disk_image(size: usize, width: f64, s: impl Fn(f64, f64) -> f64) -> Vec<f32> {
        let half = 0.5 * width / disk_edge_inverse(0.9);
        (0..size * size)
            .map(|i| disk_edge(s((i % size) as f64, (i / size) as f64) / half) as f32)
            .collect()
    }

    /// A straight edge through (c + dx, c + dy), its lit side towards `degrees`.
    fn straight(size: usize, degrees: f64, (dx, dy): (f64, f64)) -> impl Fn(f64, f64) -> f64 {
        let (sin, cos) = degrees.to_radians().sin_cos();
        let c = size as f64 / 2.0;
        move |x, y| (x - c - dx) * cos + (y - c - dy) * sin
    }

    #[test]
    fn the_exact_width_matches_the_segment_area_integrated_numerically() {
        // The lit share behind an edge s radii off the disk's centre, integrated over the chords
        // (x = sin phi): (2 / pi) * integral of cos^2 phi from -pi/2 to asin(s), Simpson's rule;
        // the 90 % point by the secant method, the 10 % point on its own.
        let share = |s: f64| {
            let (a, b, n) = (-PI / 2.0, s.asin(), 4000);
            let h = (b - a) / n as f64;
            let f = |k: usize| (a + k as f64 * h).cos().powi(2);
            let inner: f64 = (1..n).map(|k| if k % 2 == 1 { 4.0 } else { 2.0 } * f(k)).sum();
            2.0 / PI * h / 3.0 * (f(0) + inner + f(n))
        };
        let solve = |level: f64| {
            let (mut s0, mut s1) = (-0.5, 0.5);
            for _ in 0..60 {
                let (f0, f1) = (share(s0) - level, share(s1) - level);
                if f1 == f0 {
                    break;
                }
                (s0, s1) = (s1, s1 - f1 * (s1 - s0) / (f1 - f0));
            }
            s1
        };
        let (s10, s90) = (solve(0.1), solve(0.9));
        for full in [1.0, 2.9, 5.53, 11.64] {
            let numeric = 0.5 * full * (s90 - s10);
            let exact = disk_edge_width_10_90(full);
            assert!((exact - numeric).abs() < 1e-12 * full, "{full}: {exact} vs {numeric}");
        }
        for s in [-0.9, -0.3, 0.0, 0.42, 0.99] {
            assert!((disk_edge(s) - share(s)).abs() < 1e-13, "{s}");
            assert!((disk_edge_inverse(disk_edge(s)) - s).abs() < 1e-12, "{s}");
        }
    }

    #[test]
    fn straight_disk_edges_2_to_8_pixels_wide_read_within_1_percent_at_any_angle_and_offset() {
        let size = 64;
        for width in [2.0, 3.0, 3.8, 5.0, 8.0] {
            for degrees in [0.0, 10.0, 30.0, 45.0] {
                for offset in offsets(7, 4) {
                    let s = straight(size, degrees, offset);
                    let image = disk_image(size, width, &s);
                    let edge = EdgeProfile::new(&image, size as u32, size as u32, 12.0);
                    let read = edge.width_10_90(&image);
                    assert!(
                        (read / width - 1.0).abs() < 0.01,
                        "{width} px at {degrees} deg, offset {offset:?}: read {read}"
                    );
                }
            }
        }
    }

    #[test]
    fn distances_are_to_the_contour_line_and_none_past_its_ends() {
        // Contour points of a disk edge 2+ px wide lie on the line, so every distance kept is
        // the pixel's own; one to the nearest contour point is up to 0.3 px long here.
        let size = 48;
        for degrees in [10.0, 30.0, 45.0] {
            let s = straight(size, degrees, (0.31, 0.77));
            let image = disk_image(size, 3.8, &s);
            let edge = EdgeProfile::new(&image, size as u32, size as u32, 8.0);
            assert!(edge.pixels.len() > 8 * size);
            for &(i, d) in &edge.pixels {
                let exact = s((i % size) as f64, (i / size) as f64);
                assert!((d - exact).abs() < 1e-4, "{degrees} deg, pixel {i}: {d} vs {exact}");
            }
        }
    }

    #[test]
    fn a_width_does_not_jump_when_saturated_bins_move_by_a_rounding_error() {
        let image = disk_image(64, 4.0, straight(64, 0.0, (0.3, 0.0)));
        let edge = EdgeProfile::new(&image, 64, 64, 16.0);
        let nudged: Vec<f32> = image.iter().map(|&v| (v + 4e-10).min(1.0)).collect();
        let (a, b) = (edge.width_10_90(&image), edge.width_10_90(&nudged));
        assert!((a / b - 1.0).abs() < 1e-6, "{a} vs {b}");
    }

    #[test]
    fn a_circular_edge_reads_its_width_along_the_normal_within_1_percent() {
        let size = 72;
        for width in [2.0, 3.8, 8.0] {
            for radius in [20.0, 24.0, 28.0] {
                let (cx, cy) = (36.3, 35.6);
                let image = disk_image(size, width, |x, y| {
                    ((x - cx).powi(2) + (y - cy).powi(2)).sqrt() - radius
                });
                let edge = EdgeProfile::new(&image, size as u32, size as u32, 12.0);
                let read = edge.width_10_90(&image);
                assert!(
                    (read / width - 1.0).abs() < 0.01,
                    "{width} px, radius {radius}: read {read}"
                );
            }
        }
    }
}
