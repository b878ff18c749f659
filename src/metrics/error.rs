//! Pixel errors against a reference image over the penumbra.
//!
//! - RMSE = sqrt(mean_p (x_p - ref_p)^2)
//! - relMSE = mean_p (x_p - ref_p)^2 / (ref_p^2 + 0.01)   (known-facts.md, "Error metrics in use")
//! - bias = mean_p (x_p - ref_p), signed
//!
//! where p runs over the penumbra mask: pixels whose reference visibility is strictly between
//! `EPS` and 1 - `EPS`. The mask comes from the ground truth, so it exists for any scene.

/// Visibility margin of the penumbra mask.
pub const EPS: f64 = 1e-3;

/// Pixels that are in the penumbra of the reference.
#[derive(Clone, Debug)]
pub struct PenumbraMask {
    /// Indices of penumbra pixels.
    pub pixels: Vec<usize>,
}

impl PenumbraMask {
    /// Pixels with `EPS < reference < 1 - EPS` (receiver pixels only: [`crate::render::NO_RECEIVER`] is negative).
    pub fn from_reference(reference: &[f32]) -> Self {
        let pixels = (0..reference.len())
            .filter(|&i| {
                let v = reference[i] as f64;
                v > EPS && v < 1.0 - EPS
            })
            .collect();
        PenumbraMask { pixels }
    }
}

/// Errors of one image over a mask.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorMetrics {
    /// Root mean squared error.
    pub rmse: f64,
    /// Relative MSE with the 0.01 regulariser.
    pub relmse: f64,
    /// Mean signed error.
    pub bias: f64,
    /// Largest absolute error.
    pub max_abs: f64,
}

impl ErrorMetrics {
    /// Errors of `image` against `reference` over `mask`; NaN when the mask is empty.
    pub fn measure(image: &[f32], reference: &[f32], mask: &PenumbraMask) -> Self {
        let n = mask.pixels.len() as f64;
        let (mut se, mut rel, mut sum, mut max_abs) = (0.0, 0.0, 0.0, 0.0f64);
        for &i in &mask.pixels {
            let (x, r) = (image[i] as f64, reference[i] as f64);
            let d = x - r;
            se += d * d;
            rel += d * d / (r * r + 0.01);
            sum += d;
            max_abs = max_abs.max(d.abs());
        }
        if mask.pixels.is_empty() {
            return ErrorMetrics {
                rmse: f64::NAN,
                relmse: f64::NAN,
                bias: f64::NAN,
                max_abs: f64::NAN,
            };
        }
        ErrorMetrics {
            rmse: (se / n).sqrt(),
            relmse: rel / n,
            bias: sum / n,
            max_abs,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_of_a_known_offset() {
        let reference = [0.0, 0.5, 0.5, 1.0, -1.0];
        let image = [0.3, 0.6, 0.4, 1.0, -1.0];
        let mask = PenumbraMask::from_reference(&reference);
        assert_eq!(mask.pixels, vec![1, 2]);
        let e = ErrorMetrics::measure(&image, &reference, &mask);
        assert!((e.rmse - 0.1).abs() < 1e-7);
        assert!(e.bias.abs() < 1e-7);
        assert!((e.relmse - 0.01 / 0.26).abs() < 1e-6);
        assert!((e.max_abs - 0.1).abs() < 1e-7);
    }
}
