//! Radial profiles of a visibility image about the shadow's centre, and the penumbra extent and
//! 10-90 % width read from them (on-axis scenes, where the exact shadow is rotationally symmetric).
//!
//! - Profile: V(r_b) = mean of the visibility of receiver pixels whose distance from the shadow's
//!   centre falls in bin b (bins one pixel wide).
//! - Extent: see [`super::extent`] (a sliding one-pixel annulus).
//! - Profile bias: mean of (profile - exact profile) over the bins inside the exact extent, signed
//!   and absolute.
//! - 10-90 % width: r(V = 0.9) - r(V = 0.1), each the first crossing going outwards, linearly
//!   interpolated between bin centres.

use crate::render::View;
use crate::scene::Scene;
use glam::DVec3;

use super::extent::Annuli;

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
        let (id, pl) = scene.plane(plane).expect("the measured plane was validated");
        let (mut pixels, mut points) = (Vec::new(), Vec::new());
        for y in 0..view.height {
            for x in 0..view.width {
                let i = (y * view.width + x) as usize;
                if hit[i] != id {
                    continue;
                }
                let ray = view.camera.ray(x, y, view.width, view.height);
                if let Some(t) = pl.t(ray.origin, ray.direction) {
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

/// A radial profile (per-bin means) and the pixels the extent is read from.
#[derive(Clone, Debug)]
pub struct RadialProfile {
    /// Bin centres (m).
    pub radius: Vec<f64>,
    /// Mean visibility per bin (NaN for empty bins).
    pub mean: Vec<f64>,
    /// Pixels per bin.
    pub count: Vec<usize>,
    /// The pixels themselves, for the extent.
    pub annuli: Annuli,
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
            annuli: Annuli::new(
                receivers
                    .pixels
                    .iter()
                    .map(|&(i, r)| (r, visibility[i] as f64))
                    .collect(),
                receivers.bin_width,
            ),
        };
        for &(i, r) in &receivers.pixels {
            let b = receivers.bin(r) - bins.start;
            p.mean[b] += visibility[i] as f64;
            p.count[b] += 1;
        }
        for (m, &c) in p.mean.iter_mut().zip(&p.count) {
            *m = if c > 0 { *m / c as f64 } else { f64::NAN };
        }
        p
    }

    /// The profile of several images of one configuration (its seeds): per bin, the mean of
    /// their bin means. Its extent pixels are the first image's.
    pub fn mean_over(receivers: &Receivers, images: &[Vec<f32>]) -> Self {
        let mut avg = RadialProfile::new(receivers, &images[0]);
        let profiles: Vec<_> = images.iter().map(|im| RadialProfile::new(receivers, im)).collect();
        for (b, m) in avg.mean.iter_mut().enumerate() {
            *m = profiles.iter().map(|p| p.mean[b]).sum::<f64>() / profiles.len() as f64;
        }
        avg
    }

    /// Inner and outer extent of partial shadow (m), see [`super::extent`].
    pub fn extent(&self) -> (f64, f64) {
        self.annuli.extent()
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

    /// Signed and absolute mean of (self - exact) over the bins inside the exact profile's extent;
    /// NaN when no bin is.
    pub fn bias_against(&self, exact: &RadialProfile) -> (f64, f64) {
        let (lo, hi) = exact.extent();
        let diffs: Vec<f64> = (0..self.radius.len().min(exact.radius.len()))
            .filter(|&b| self.radius[b] >= lo && self.radius[b] <= hi)
            .map(|b| self.mean[b] - exact.mean[b])
            .filter(|d| !d.is_nan())
            .collect();
        if diffs.is_empty() {
            return (f64::NAN, f64::NAN);
        }
        let n = diffs.len() as f64;
        (
            diffs.iter().sum::<f64>() / n,
            diffs.iter().map(|d| d.abs()).sum::<f64>() / n,
        )
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
        // Every pixel of a bin sits at its centre, so an annulus's share jumps from 0 to 1 when it
        // reaches the first lit (r = 2.5) or last shadowed (r = 11.5) pixels: at 2.0 and 12.0.
        let (inner, outer) = p.extent();
        assert!(
            (inner - 2.0).abs() < 1.0 / 32.0 && (outer - 12.0).abs() < 1.0 / 32.0,
            "{inner} {outer}"
        );
    }

    /// 100 pixels spread evenly inside each of 10 bins, with visibility `v(r)`.
    fn radial(v: impl Fn(f64) -> f64) -> (Receivers, Vec<f32>) {
        let values: Vec<(f64, f32)> = (0..10 * 100)
            .map(|k| {
                let r = (k as f64 + 0.5) / 100.0;
                (r, v(r) as f32)
            })
            .collect();
        synthetic(&values)
    }

    #[test]
    fn bias_against_the_exact_profile_covers_its_extent_only() {
        // Exact penumbra from r = 3 to 7: extent [2.55, 7.45], bins 3 to 6 inside.
        let (rec, exact) = radial(|r| ((r - 3.0) / 4.0).clamp(0.0, 1.0));
        let exact_profile = RadialProfile::new(&rec, &exact);
        // Add 0.1 to every pixel of bin 4 and subtract 0.3 in bin 8, outside the exact extent.
        let mut image = exact.clone();
        for &(i, r) in &rec.pixels {
            if (4.0..5.0).contains(&r) {
                image[i] += 0.1;
            }
            if (8.0..9.0).contains(&r) {
                image[i] -= 0.3;
            }
        }
        let (lo, hi) = exact_profile.extent();
        let inside: Vec<usize> = (0..exact_profile.radius.len())
            .filter(|&b| exact_profile.radius[b] >= lo && exact_profile.radius[b] <= hi)
            .collect();
        assert_eq!(inside, vec![3, 4, 5, 6], "extent [{lo}, {hi}]");
        let (signed, abs) = RadialProfile::new(&rec, &image).bias_against(&exact_profile);
        assert!(
            (signed - 0.025).abs() < 1e-6 && (abs - 0.025).abs() < 1e-6,
            "{signed} {abs}"
        );
        let (signed, _) = RadialProfile::new(&rec, &exact).bias_against(&exact_profile);
        assert_eq!(signed, 0.0);
    }
}
