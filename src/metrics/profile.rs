//! Radial profiles of a visibility image about the shadow's centre, and the penumbra extent and
//! 10-90 % width read from them (on-axis scenes, where the exact shadow is rotationally symmetric).
//!
//! - Profile: V(r_b) = mean of the visibility of receiver pixels whose distance from the shadow's
//!   centre falls in bin b (bins one pixel wide).
//! - Extent ("how far partial shadow reaches", as an eye reads an image): inner = the first bin,
//!   going outwards, in which at least [`SHARE`] of the pixels see some light (V > 0); outer =
//!   the last bin in which at least [`SHARE`] of the pixels are shadowed (V < 1). For the exact
//!   image these are the umbra and penumbra radii r_u and r_p.
//! - 10-90 % width: r(V = 0.9) - r(V = 0.1), each the first crossing going outwards, linearly
//!   interpolated between bin centres.

use crate::render::View;
use crate::scene::Scene;
use glam::DVec3;

/// Share of a bin's pixels that must show (partial) shadow or light to count towards the extent.
pub const SHARE: f64 = 0.05;
/// Bins with fewer pixels are left out of the extent (patch corners).
pub const MIN_BIN_PIXELS: usize = 8;

/// The receiver-plane pixels of a view: their ground points and distances from the shadow centre.
#[derive(Clone, Debug)]
pub struct Receivers {
    /// (pixel index, distance from the centre) for every pixel whose camera ray hits the plane.
    pub pixels: Vec<(usize, f64)>,
    /// The ground point of each entry of `pixels`, where its camera ray meets the plane.
    pub points: Vec<DVec3>,
    /// Bin width (m): one pixel of an orthographic view.
    pub bin_width: f64,
}

impl Receivers {
    /// Receiver pixels of `view`: those whose object id in `hit` is plane `plane`, located by
    /// intersecting their camera rays with that plane in f64.
    pub fn new(scene: &Scene, view: View, plane: usize, hit: &[u32], centre: DVec3, bin_width: f64) -> Self {
        let pl = &scene.planes[plane];
        let id = scene.plane_id(plane);
        let (mut pixels, mut points) = (Vec::new(), Vec::new());
        for y in 0..view.height {
            for x in 0..view.width {
                let i = (y * view.width + x) as usize;
                if hit[i] != id {
                    continue;
                }
                let ray = view.camera.ray(x, y, view.width, view.height);
                if let Some(t) = crate::geometry::plane_t(ray.origin, ray.direction, pl) {
                    let p = ray.origin + ray.direction * t;
                    pixels.push((i, (p - centre).length()));
                    points.push(p);
                }
            }
        }
        Receivers {
            pixels,
            points,
            bin_width,
        }
    }

    /// Bin index of a radius.
    pub fn bin(&self, r: f64) -> usize {
        (r / self.bin_width).floor() as usize
    }

    /// Centre radius of bin `b`.
    pub fn bin_centre(&self, b: usize) -> f64 {
        (b as f64 + 0.5) * self.bin_width
    }

    /// The range of bins that hold receiver pixels.
    pub fn bins(&self) -> std::ops::Range<usize> {
        let lo = self.pixels.iter().map(|p| self.bin(p.1)).min().unwrap_or(0);
        let hi = self.pixels.iter().map(|p| self.bin(p.1) + 1).max().unwrap_or(0);
        lo..hi
    }
}

/// A radial profile with the per-bin counts the extent needs.
#[derive(Clone, Debug)]
pub struct RadialProfile {
    /// Bin centres (m).
    pub radius: Vec<f64>,
    /// Mean visibility per bin (NaN for empty bins).
    pub mean: Vec<f64>,
    /// Pixels per bin.
    pub count: Vec<usize>,
    /// Pixels with V < 1 per bin.
    pub shadowed: Vec<usize>,
    /// Pixels with V > 0 per bin.
    pub lit: Vec<usize>,
}

impl RadialProfile {
    /// Profile of `visibility` over the receivers.
    pub fn new(receivers: &Receivers, visibility: &[f32]) -> Self {
        let bins = receivers.bins();
        let n = bins.len();
        let mut p = RadialProfile {
            radius: bins.clone().map(|b| receivers.bin_centre(b)).collect(),
            mean: vec![0.0; n],
            count: vec![0; n],
            shadowed: vec![0; n],
            lit: vec![0; n],
        };
        for &(i, r) in &receivers.pixels {
            let b = receivers.bin(r) - bins.start;
            let v = visibility[i] as f64;
            p.mean[b] += v;
            p.count[b] += 1;
            p.shadowed[b] += (v < 1.0) as usize;
            p.lit[b] += (v > 0.0) as usize;
        }
        for (m, &c) in p.mean.iter_mut().zip(&p.count) {
            *m = if c > 0 { *m / c as f64 } else { f64::NAN };
        }
        p
    }

    /// Inner and outer extent of partial shadow (m); NaN when no bin qualifies.
    pub fn extent(&self) -> (f64, f64) {
        let ok = |b: usize| self.count[b] >= MIN_BIN_PIXELS;
        let share = |k: usize, b: usize| k as f64 / self.count[b] as f64;
        let inner = (0..self.radius.len()).find(|&b| ok(b) && share(self.lit[b], b) >= SHARE);
        let outer = (0..self.radius.len())
            .rev()
            .find(|&b| ok(b) && share(self.shadowed[b], b) >= SHARE);
        (
            inner.map_or(f64::NAN, |b| self.radius[b]),
            outer.map_or(f64::NAN, |b| self.radius[b]),
        )
    }

    /// First radius, going outwards, where the mean profile reaches `level` (interpolated).
    pub fn crossing(&self, level: f64) -> f64 {
        let pts: Vec<(f64, f64)> = self
            .radius
            .iter()
            .copied()
            .zip(self.mean.iter().copied())
            .filter(|p| !p.1.is_nan())
            .collect();
        for w in pts.windows(2) {
            let ((r0, v0), (r1, v1)) = (w[0], w[1]);
            if v0 < level && v1 >= level {
                return r0 + (r1 - r0) * (level - v0) / (v1 - v0);
            }
        }
        f64::NAN
    }

    /// 10-90 % width (m).
    pub fn width_10_90(&self) -> f64 {
        self.crossing(0.9) - self.crossing(0.1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn synthetic(values: &[(f64, f32)]) -> (Receivers, Vec<f32>) {
        let pixels = values.iter().enumerate().map(|(i, (r, _))| (i, *r)).collect();
        (
            Receivers {
                pixels,
                points: vec![],
                bin_width: 1.0,
            },
            values.iter().map(|v| v.1).collect(),
        )
    }

    #[test]
    fn linear_ramp_has_known_width_and_extent() {
        // V rises linearly from 0 at r = 2 to 1 at r = 12, ten pixels per bin.
        let mut values = Vec::new();
        for b in 0..16 {
            let r = b as f64 + 0.5;
            let v = ((r - 2.0) / 10.0).clamp(0.0, 1.0) as f32;
            values.extend(std::iter::repeat_n((r, v), 10));
        }
        let (rec, vis) = synthetic(&values);
        let p = RadialProfile::new(&rec, &vis);
        assert!((p.width_10_90() - 8.0).abs() < 1e-6, "{}", p.width_10_90());
        let (inner, outer) = p.extent();
        assert_eq!((inner, outer), (2.5, 11.5));
    }
}
