//! The penumbra's width in any scene, not only on-axis ones: the profile of an image across the
//! reference's half-shadow contour.
//!
//! - Contour: where the reference crosses 1/2 between 4-neighbour receiver pixels, placed by
//!   linear interpolation (sub-pixel).
//! - Signed distance: each receiver pixel's distance (pixels) to the nearest contour point,
//!   positive on the lit side (reference >= 1/2).
//! - Profile: the mean of the image over pixels in bins of [`BIN`] pixels of signed distance.
//! - 10-90 % width: d(V = 0.9) - d(V = 0.1), each the first crossing going outwards from the
//!   contour, linearly interpolated between bin centres. Averaging along the contour is what
//!   lets a one-ray image have a width at all. On an on-axis scene it reads what the radial
//!   profile reads ([`super::RadialProfile`]).

use crate::render::NO_RECEIVER;

/// Bin width of the profile, pixels.
pub const BIN: f64 = 0.5;

/// The reference's contour and every receiver pixel's signed distance to it.
#[derive(Clone, Debug)]
pub struct EdgeProfile {
    /// (pixel index, signed distance in pixels) of receiver pixels within `reach` of the contour.
    pub pixels: Vec<(usize, f64)>,
    /// Contour points found.
    pub contour: usize,
    reach: f64,
}

impl EdgeProfile {
    /// The contour of `reference` (a `width` x `height` image, [`NO_RECEIVER`] where none) and
    /// the signed distances of receiver pixels up to `reach` pixels from it.
    pub fn new(reference: &[f32], width: u32, height: u32, reach: f64) -> EdgeProfile {
        let (w, h) = (width as usize, height as usize);
        let mut points = Vec::new();
        let value = |x: usize, y: usize| reference[y * w + x];
        for y in 0..h {
            for x in 0..w {
                let a = value(x, y);
                if a == NO_RECEIVER {
                    continue;
                }
                for (nx, ny) in [(x + 1, y), (x, y + 1)] {
                    if nx >= w || ny >= h {
                        continue;
                    }
                    let b = value(nx, ny);
                    if b == NO_RECEIVER || (a >= 0.5) == (b >= 0.5) {
                        continue;
                    }
                    let t = (0.5 - a as f64) / (b as f64 - a as f64);
                    points.push((x as f64 + t * (nx - x) as f64, y as f64 + t * (ny - y) as f64));
                }
            }
        }
        let mut pixels = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let v = value(x, y);
                if v == NO_RECEIVER || points.is_empty() {
                    continue;
                }
                let d2 = points
                    .iter()
                    .map(|&(px, py)| (px - x as f64).powi(2) + (py - y as f64).powi(2))
                    .fold(f64::INFINITY, f64::min);
                let d = d2.sqrt();
                if d <= reach {
                    pixels.push((y * w + x, if v >= 0.5 { d } else { -d }));
                }
            }
        }
        EdgeProfile {
            pixels,
            contour: points.len(),
            reach,
        }
    }

    /// The profile of `image`: (bin centre in pixels, mean) for every non-empty bin, ascending.
    pub fn profile(&self, image: &[f32]) -> Vec<(f64, f64)> {
        let bins = (2.0 * self.reach / BIN).ceil() as usize + 2;
        let (mut sum, mut count) = (vec![0.0; bins], vec![0usize; bins]);
        for &(i, d) in &self.pixels {
            let b = ((d + self.reach) / BIN).floor() as usize;
            sum[b] += image[i] as f64;
            count[b] += 1;
        }
        (0..bins)
            .filter(|&b| count[b] > 0)
            .map(|b| ((b as f64 + 0.5) * BIN - self.reach, sum[b] / count[b] as f64))
            .collect()
    }

    /// The 10-90 % width of `image` across the contour, pixels; NaN where the profile does not
    /// reach 0.1 on the dark side or 0.9 on the lit side within the reach.
    pub fn width_10_90(&self, image: &[f32]) -> f64 {
        let p = self.profile(image);
        let Some(zero) = p.iter().position(|&(d, _)| d >= 0.0) else {
            return f64::NAN;
        };
        let crossing = |level: f64, outwards: &mut dyn Iterator<Item = usize>, above: bool| -> f64 {
            let mut prev: Option<(f64, f64)> = None;
            for b in outwards {
                let (d, v) = p[b];
                if (v >= level) == above {
                    return match prev {
                        Some((pd, pv)) if pv != v => pd + (level - pv) * (d - pd) / (v - pv),
                        _ => d,
                    };
                }
                prev = Some((d, v));
            }
            f64::NAN
        };
        let d90 = crossing(0.9, &mut (zero..p.len()), true);
        let d10 = crossing(0.1, &mut (0..zero).rev(), false);
        d90 - d10
    }
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
            // Bins of half a pixel sample the ramp; interpolation is exact on a line.
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
}
