//! Perceptual error of a picture against a reference picture: FLIP (Andersson et al. 2020, "FLIP:
//! A Difference Evaluator for Alternating Images"), through NVIDIA's reference implementation
//! (`nv-flip`). The soft-shadow paper judged "equal quality" by eye; FLIP is the measured stand-in
//! for flipping between two pictures on a monitor. Per pixel it is in [0, 1]: a colour
//! difference (Hunt-adjusted HyAB distance in CIELAB after contrast-sensitivity filtering,
//! compressed and redistributed) raised to the power of one minus a feature (edge and point)
//! difference. Inputs are 8-bit sRGB, as a person would see them.

use anyhow::ensure;

/// Pixels per degree of visual angle for FLIP's default viewing condition: a 0.7 m wide monitor
/// of 3840 pixels seen from 0.7 m, 0.7 * (3840 / 0.7) * pi / 180 = 67.02.
pub const PIXELS_PER_DEGREE: f32 = 0.7 * (3840.0 / 0.7) * (std::f32::consts::PI / 180.0);

/// Per-pixel FLIP error of `test` against `reference`, both `width` x `height` 8-bit sRGB RGB
/// (3 bytes per pixel, row-major from the top left).
pub fn flip_map(reference: &[u8], test: &[u8], width: u32, height: u32, ppd: f32) -> anyhow::Result<Vec<f32>> {
    let n = width as usize * height as usize * 3;
    ensure!(
        width > 0 && height > 0,
        "FLIP needs a non-empty image, got {width}x{height}"
    );
    ensure!(
        reference.len() == n && test.len() == n,
        "FLIP needs two {width}x{height} RGB images ({n} bytes), got {} and {} bytes",
        reference.len(),
        test.len()
    );
    ensure!(
        ppd.is_finite() && ppd > 0.0,
        "pixels per degree must be positive, got {ppd}"
    );
    let r = nv_flip::FlipImageRgb8::with_data(width, height, reference);
    let t = nv_flip::FlipImageRgb8::with_data(width, height, test);
    Ok(nv_flip::flip(r, t, ppd).to_vec())
}

/// Mean FLIP error over the pixels of `test` against `reference` (see [`flip_map`]).
pub fn flip_mean(reference: &[u8], test: &[u8], width: u32, height: u32, ppd: f32) -> anyhow::Result<f64> {
    let map = flip_map(reference, test, width, height, ppd)?;
    Ok(map.iter().map(|&e| e as f64).sum::<f64>() / map.len() as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// FLIP of two uniform images from the paper's formulas, independently of the crate: with no
    /// edges or points the feature difference is 0 and the contrast-sensitivity filters (each
    /// normalised to unit sum) leave a constant image constant, so FLIP is the colour pipeline
    /// alone: sRGB -> linear RGB -> XYZ (D65) -> CIELAB -> Hunt adjustment (a, b scaled by
    /// 0.01 L) -> HyAB distance -> power q_c = 0.7 -> redistribution with p_c = 0.4, p_t = 0.95
    /// against the distance between Hunt-adjusted green and blue.
    fn uniform_flip(a: [u8; 3], b: [u8; 3]) -> f64 {
        fn linear(c: u8) -> f64 {
            let c = c as f64 / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        }
        fn lab_hunt(rgb: [f64; 3]) -> [f64; 3] {
            let m = [
                [0.4124564, 0.3575761, 0.1804375],
                [0.2126729, 0.7151522, 0.0721750],
                [0.0193339, 0.1191920, 0.9503041],
            ];
            let xyz: Vec<f64> = m.iter().map(|row| (0..3).map(|k| row[k] * rgb[k]).sum()).collect();
            let white: Vec<f64> = m.iter().map(|row| row.iter().sum()).collect();
            let f = |t: f64| {
                let d: f64 = 6.0 / 29.0;
                if t > d.powi(3) {
                    t.cbrt()
                } else {
                    t / (3.0 * d * d) + 4.0 / 29.0
                }
            };
            let (fx, fy, fz) = (f(xyz[0] / white[0]), f(xyz[1] / white[1]), f(xyz[2] / white[2]));
            let l = 116.0 * fy - 16.0;
            [l, 0.01 * l * 500.0 * (fx - fy), 0.01 * l * 200.0 * (fy - fz)]
        }
        let hyab =
            |p: [f64; 3], q: [f64; 3]| (p[0] - q[0]).abs() + ((p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
        let (qc, pc, pt) = (0.7, 0.4, 0.95);
        let cmax = hyab(lab_hunt([0.0, 1.0, 0.0]), lab_hunt([0.0, 0.0, 1.0])).powf(qc);
        let e = hyab(lab_hunt(a.map(linear)), lab_hunt(b.map(linear))).powf(qc);
        if e < pc * cmax {
            e * pt / (pc * cmax)
        } else {
            pt + (e - pc * cmax) / (cmax - pc * cmax) * (1.0 - pt)
        }
    }

    fn uniform(c: [u8; 3], w: u32, h: u32) -> Vec<u8> {
        c.iter().copied().cycle().take((w * h * 3) as usize).collect()
    }

    #[test]
    fn the_default_viewing_condition() {
        assert!((PIXELS_PER_DEGREE - 67.02).abs() < 0.01, "{PIXELS_PER_DEGREE}");
        assert!((PIXELS_PER_DEGREE - nv_flip::DEFAULT_PIXELS_PER_DEGREE).abs() < 0.05);
    }

    #[test]
    fn uniform_images_match_the_papers_colour_pipeline() {
        let (w, h) = (24, 16);
        for (a, b) in [
            ([0, 0, 0], [255, 255, 255]),
            ([128, 128, 128], [140, 128, 128]),
            ([60, 60, 60], [66, 66, 66]),
            ([200, 30, 40], [30, 200, 40]),
            ([10, 20, 200], [12, 22, 190]),
        ] {
            let want = uniform_flip(a, b);
            let got = flip_mean(&uniform(a, w, h), &uniform(b, w, h), w, h, PIXELS_PER_DEGREE).unwrap();
            eprintln!("{a:?} vs {b:?}: crate {got:.5}, formulas {want:.5}");
            assert!(
                (got - want).abs() < 1e-4,
                "{a:?} vs {b:?}: crate {got}, formulas {want}"
            );
        }
    }

    #[test]
    fn identical_images_have_no_error_and_sizes_are_checked() {
        let img: Vec<u8> = (0..32 * 32 * 3).map(|i| (i * 37 % 251) as u8).collect();
        assert_eq!(flip_mean(&img, &img, 32, 32, PIXELS_PER_DEGREE).unwrap(), 0.0);
        let e = flip_mean(&img, &img[3..], 32, 32, PIXELS_PER_DEGREE).unwrap_err();
        assert!(e.to_string().contains("32x32"), "{e}");
        assert!(flip_mean(&[], &[], 0, 0, PIXELS_PER_DEGREE).is_err());
    }

    #[test]
    fn one_different_pixel_is_local_and_the_mean_is_the_maps() {
        let (w, h) = (48u32, 48u32);
        let reference = uniform([100, 100, 100], w, h);
        let mut test = reference.clone();
        let centre = ((h / 2) * w + w / 2) as usize * 3;
        test[centre..centre + 3].copy_from_slice(&[250, 250, 250]);
        let map = flip_map(&reference, &test, w, h, PIXELS_PER_DEGREE).unwrap();
        let mean = flip_mean(&reference, &test, w, h, PIXELS_PER_DEGREE).unwrap();
        let sum: f64 = map.iter().map(|&e| e as f64).sum();
        assert!((mean - sum / (w * h) as f64).abs() < 1e-12);
        assert!(map[centre / 3] > 0.2, "{}", map[centre / 3]);
        // The filters reach a few pixels; the far corner sees nothing.
        assert_eq!(map[0], 0.0);
    }

    #[test]
    fn more_noise_gives_more_error() {
        let (w, h) = (64u32, 64u32);
        let reference = uniform([120, 120, 120], w, h);
        let noisy = |amplitude: f64| -> Vec<u8> {
            let s = crate::sampling::Stream::new(5, 0, None);
            (0..w * h)
                .flat_map(|i| {
                    let v = (120.0 + amplitude * (s.unit(i) - 0.5)).round().clamp(0.0, 255.0) as u8;
                    [v; 3]
                })
                .collect()
        };
        let errors: Vec<f64> = [4.0, 16.0, 64.0, 160.0]
            .iter()
            .map(|&a| flip_mean(&reference, &noisy(a), w, h, PIXELS_PER_DEGREE).unwrap())
            .collect();
        assert!(errors.windows(2).all(|p| p[0] < p[1]), "{errors:?}");
    }
}
