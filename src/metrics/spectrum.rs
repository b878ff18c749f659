//! Where the error goes, which RMSE and mean FLIP do not see: the radially averaged power
//! spectrum of a run's signed error image, its low-frequency share, and the error a simple
//! denoiser (a small Gaussian blur) leaves.
//!
//! - Spectrum: the signed error `run - ground truth` on receiver pixels (0 elsewhere), its mean
//!   over the receivers removed (the bias is reported apart), times a 2-D Hann window, zero-padded
//!   to powers of two and transformed; `|F|^2` averaged over rings of [`BIN`] cycles per pixel
//!   out to the Nyquist frequency 0.5.
//! - Low-frequency share: the power below [`LOW_CUTOFF`] cycles per pixel over all the power out
//!   to 0.5 (the zero frequency left out). White noise puts the area's share there,
//!   (0.125 / 0.5)^2 = 1/16; blue noise far less; banding (a pattern shared by every pixel) more.
//! - Blurred error: the RMSE over the penumbra mask of the error blurred by a Gaussian of
//!   [`BLUR_SIGMA`] pixels, normalised over receiver pixels (what is left after a denoiser that
//!   averages neighbours: low-frequency error survives it, high-frequency error does not).

use std::f64::consts::PI;

/// Width of a ring of the radial spectrum, cycles per pixel.
pub const BIN: f64 = 1.0 / 32.0;
/// Frequencies below this (cycles per pixel) are "low".
pub const LOW_CUTOFF: f64 = 0.125;
/// Standard deviation of the denoising blur, pixels.
pub const BLUR_SIGMA: f64 = 1.0;

/// The radial spectrum of an error image and what is read from it.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorSpectrum {
    /// Mean power per ring, rings of [`BIN`] from 0 to 0.5 cycles per pixel.
    pub radial: Vec<f64>,
    /// Share of the power below [`LOW_CUTOFF`].
    pub low_share: f64,
}

/// In-place radix-2 FFT of `re`, `im` (length a power of two).
fn fft(re: &mut [f64], im: &mut [f64]) {
    let n = re.len();
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            re.swap(i, j);
            im.swap(i, j);
        }
    }
    let mut len = 2;
    while len <= n {
        let angle = -2.0 * PI / len as f64;
        for start in (0..n).step_by(len) {
            for k in 0..len / 2 {
                let (c, s) = ((angle * k as f64).cos(), (angle * k as f64).sin());
                let (a, b) = (start + k, start + k + len / 2);
                let (tr, ti) = (re[b] * c - im[b] * s, re[b] * s + im[b] * c);
                re[b] = re[a] - tr;
                im[b] = im[a] - ti;
                re[a] += tr;
                im[a] += ti;
            }
        }
        len <<= 1;
    }
}

/// `|F|^2` of a `w` x `h` image zero-padded to powers of two, with the padded size.
fn power(image: &[f64], w: usize, h: usize) -> (Vec<f64>, usize, usize) {
    let (pw, ph) = (w.next_power_of_two(), h.next_power_of_two());
    let (mut re, mut im) = (vec![0.0; pw * ph], vec![0.0; pw * ph]);
    for y in 0..h {
        re[y * pw..y * pw + w].copy_from_slice(&image[y * w..y * w + w]);
    }
    for y in 0..ph {
        fft(&mut re[y * pw..(y + 1) * pw], &mut im[y * pw..(y + 1) * pw]);
    }
    let (mut cr, mut ci) = (vec![0.0; ph], vec![0.0; ph]);
    for x in 0..pw {
        for y in 0..ph {
            (cr[y], ci[y]) = (re[y * pw + x], im[y * pw + x]);
        }
        fft(&mut cr, &mut ci);
        for y in 0..ph {
            (re[y * pw + x], im[y * pw + x]) = (cr[y], ci[y]);
        }
    }
    (re.iter().zip(&im).map(|(r, i)| r * r + i * i).collect(), pw, ph)
}

/// The spectrum of `error` (`w` x `h`, row-major) over the pixels `receiver` marks.
pub fn error_spectrum(error: &[f64], receiver: &[bool], w: usize, h: usize) -> ErrorSpectrum {
    let n = receiver.iter().filter(|&&r| r).count().max(1);
    let mean = error
        .iter()
        .zip(receiver)
        .filter(|(_, &r)| r)
        .map(|(e, _)| e)
        .sum::<f64>()
        / n as f64;
    let hann = |i: usize, len: usize| 0.5 - 0.5 * (2.0 * PI * (i as f64 + 0.5) / len as f64).cos();
    let windowed: Vec<f64> = (0..w * h)
        .map(|i| {
            if receiver[i] {
                (error[i] - mean) * hann(i % w, w) * hann(i / w, h)
            } else {
                0.0
            }
        })
        .collect();
    let (p, pw, ph) = power(&windowed, w, h);
    let rings = (0.5 / BIN).round() as usize;
    let (mut sum, mut count) = (vec![0.0; rings], vec![0usize; rings]);
    let (mut low, mut all) = (0.0, 0.0);
    for v in 0..ph {
        for u in 0..pw {
            let fu = (if u < pw / 2 { u as f64 } else { u as f64 - pw as f64 }) / pw as f64;
            let fv = (if v < ph / 2 { v as f64 } else { v as f64 - ph as f64 }) / ph as f64;
            let f = (fu * fu + fv * fv).sqrt();
            if f == 0.0 || f > 0.5 {
                continue;
            }
            let power = p[v * pw + u];
            let ring = ((f / BIN) as usize).min(rings - 1);
            sum[ring] += power;
            count[ring] += 1;
            all += power;
            if f < LOW_CUTOFF {
                low += power;
            }
        }
    }
    ErrorSpectrum {
        radial: sum.iter().zip(&count).map(|(s, &c)| s / c.max(1) as f64).collect(),
        low_share: if all > 0.0 { low / all } else { f64::NAN },
    }
}

/// RMSE over `mask` pixels of `error` blurred by a Gaussian of [`BLUR_SIGMA`] pixels, each
/// pixel's blur normalised over the receiver pixels around it.
pub fn blurred_rmse(error: &[f64], receiver: &[bool], mask: &[usize], w: usize, h: usize) -> f64 {
    if mask.is_empty() {
        return f64::NAN;
    }
    let reach = (3.0 * BLUR_SIGMA).ceil() as i64;
    let weight: Vec<f64> = (-reach..=reach)
        .map(|d| (-((d * d) as f64) / (2.0 * BLUR_SIGMA * BLUR_SIGMA)).exp())
        .collect();
    let sq: f64 = mask
        .iter()
        .map(|&i| {
            let (px, py) = ((i % w) as i64, (i / w) as i64);
            let (mut num, mut den) = (0.0, 0.0);
            for dy in -reach..=reach {
                for dx in -reach..=reach {
                    let (x, y) = (px + dx, py + dy);
                    if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
                        continue;
                    }
                    let q = y as usize * w + x as usize;
                    if receiver[q] {
                        let k = weight[(dx + reach) as usize] * weight[(dy + reach) as usize];
                        num += k * error[q];
                        den += k;
                    }
                }
            }
            let b = if den > 0.0 { num / den } else { 0.0 };
            b * b
        })
        .sum();
    (sq / mask.len() as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Stream;

    fn noise(w: usize, h: usize, seed: u32) -> Vec<f64> {
        let s = Stream::new(seed, 0, None);
        (0..(w * h) as u32).map(|i| s.unit(i) - 0.5).collect()
    }

    #[test]
    fn the_fft_matches_a_direct_transform() {
        let x = noise(8, 1, 3);
        let (mut re, mut im) = (x.clone(), vec![0.0; 8]);
        fft(&mut re, &mut im);
        for k in 0..8 {
            let (mut r, mut i) = (0.0, 0.0);
            for (n, v) in x.iter().enumerate() {
                let a = -2.0 * PI * (k * n) as f64 / 8.0;
                r += v * a.cos();
                i += v * a.sin();
            }
            assert!((re[k] - r).abs() < 1e-12 && (im[k] - i).abs() < 1e-12, "{k}");
        }
    }

    /// White noise puts 1/16 of its power below 0.125 cycles per pixel and has a flat spectrum;
    /// a smooth field (the same error shared by neighbours) puts almost all of it there.
    #[test]
    fn white_noise_is_flat_and_smooth_error_is_low() {
        let (w, h) = (128, 128);
        let all = vec![true; w * h];
        let white = error_spectrum(&noise(w, h, 1), &all, w, h);
        assert!((white.low_share - 1.0 / 16.0).abs() < 0.02, "{}", white.low_share);
        let mean = white.radial[1..].iter().sum::<f64>() / (white.radial.len() - 1) as f64;
        for (k, p) in white.radial.iter().enumerate().skip(1) {
            assert!((p / mean - 1.0).abs() < 0.3, "ring {k}: {p} vs {mean}");
        }
        let smooth: Vec<f64> = (0..w * h)
            .map(|i| ((i % w) as f64 / 20.0).sin() + ((i / w) as f64 / 15.0).cos())
            .collect();
        assert!(error_spectrum(&smooth, &all, w, h).low_share > 0.9);
    }

    /// A blur removes most of white noise's error and little of a smooth field's.
    #[test]
    fn blurring_keeps_low_frequency_error() {
        let (w, h) = (64, 64);
        let all = vec![true; w * h];
        let mask: Vec<usize> = (0..w * h).collect();
        let rms = |e: &[f64]| (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt();
        let white = noise(w, h, 2);
        assert!(blurred_rmse(&white, &all, &mask, w, h) < 0.4 * rms(&white));
        let smooth: Vec<f64> = (0..w * h).map(|i| ((i % w) as f64 / 10.0).sin()).collect();
        assert!(blurred_rmse(&smooth, &all, &mask, w, h) > 0.9 * rms(&smooth));
        assert!(blurred_rmse(&white, &all, &[], w, h).is_nan());
    }
}
