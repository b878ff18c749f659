//! Pixel errors against a reference image over the penumbra, and how much of the penumbra an
//! image keeps.
//!
//! - RMSE = sqrt(mean_p (x_p - ref_p)^2)
//! - relMSE = mean_p (x_p - ref_p)^2 / (ref_p^2 + 0.01)   (FACTS.md, "Error metrics in use")
//! - bias = mean_p (x_p - ref_p), signed
//!
//! where p runs over a [`PenumbraMask`]: the measured receiver's pixels whose reference visibility
//! is strictly between [`EPS`] and 1 - [`EPS`] (with several lights, that of any one light). Pixels that see another surface (the occluder
//! itself, a mesh, the sky) are never in it: the exact answer does not exist there, and the shadow
//! being judged is the one cast on the receiver.

use super::profile::Receivers;

/// Visibility margin of the penumbra mask.
pub const EPS: f64 = 1e-3;

/// Whether a visibility value is strictly inside the penumbra.
fn in_penumbra(v: f32) -> bool {
    let v = v as f64;
    v > EPS && v < 1.0 - EPS
}

/// The receiver pixels that are in the penumbra of a reference image: the one mask every error
/// metric of a run is taken over.
#[derive(Clone, Debug, PartialEq)]
pub struct PenumbraMask {
    /// Indices of penumbra pixels, ascending.
    pub pixels: Vec<usize>,
}

impl PenumbraMask {
    /// Receiver pixels with `EPS < reference < 1 - EPS`. Runs are judged over the ground truth's
    /// mask (it exists for any scene); the ground truth itself over the exact image's.
    pub fn new(reference: &[f32], receivers: &Receivers) -> Self {
        let mut pixels: Vec<usize> = receivers
            .pixels
            .iter()
            .map(|&(i, _)| i)
            .filter(|&i| in_penumbra(reference[i]))
            .collect();
        pixels.sort_unstable();
        PenumbraMask { pixels }
    }
}

impl PenumbraMask {
    /// Receiver pixels in the penumbra of any of `lights` (per-light reference visibilities):
    /// with several lights, a pixel one light wholly lights and another wholly misses has a
    /// partial mean but no penumbra, and no sampling error to judge.
    pub fn union(lights: &[Vec<f32>], receivers: &Receivers) -> Self {
        let mut pixels: Vec<usize> = receivers
            .pixels
            .iter()
            .map(|&(i, _)| i)
            .filter(|&i| lights.iter().any(|l| in_penumbra(l[i])))
            .collect();
        pixels.sort_unstable();
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
        if mask.pixels.is_empty() {
            return ErrorMetrics {
                rmse: f64::NAN,
                relmse: f64::NAN,
                bias: f64::NAN,
                max_abs: f64::NAN,
            };
        }
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
        ErrorMetrics {
            rmse: (se / n).sqrt(),
            relmse: rel / n,
            bias: sum / n,
            max_abs,
        }
    }
}

/// How an image renders the reference's penumbra, on the receiver: its own penumbra area (receiver
/// pixels with EPS < V < 1 - EPS) relative to the mask's, and the share of the mask it shows as
/// fully lit or fully dark (penumbra it loses). NaN for an empty mask.
pub fn penumbra_coverage(image: &[f32], mask: &PenumbraMask, receivers: &Receivers) -> (f64, f64) {
    let n = mask.pixels.len() as f64;
    if mask.pixels.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let area = receivers.pixels.iter().filter(|&&(i, _)| in_penumbra(image[i])).count() as f64;
    let lost = mask.pixels.iter().filter(|&&i| !in_penumbra(image[i])).count() as f64;
    (area / n, lost / n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn receivers(pixels: &[usize]) -> Receivers {
        Receivers {
            pixels: pixels.iter().map(|&i| (i, i as f64)).collect(),
            points: vec![],
            bin_width: 1.0,
        }
    }

    #[test]
    fn errors_of_a_known_offset() {
        let reference = [0.0, 0.5, 0.5, 1.0, -1.0];
        let image = [0.3, 0.6, 0.4, 1.0, -1.0];
        let mask = PenumbraMask::new(&reference, &receivers(&[0, 1, 2, 3]));
        assert_eq!(mask.pixels, vec![1, 2]);
        let e = ErrorMetrics::measure(&image, &reference, &mask);
        assert!((e.rmse - 0.1).abs() < 1e-7);
        assert!(e.bias.abs() < 1e-7);
        assert!((e.relmse - 0.01 / 0.26).abs() < 1e-6);
        assert!((e.max_abs - 0.1).abs() < 1e-7);
    }

    /// With two lights, the penumbra is either light's: a pixel one light wholly lights and the
    /// other wholly misses (mean 0.5) is not in it; a pixel in one light's penumbra is, whatever
    /// the other does.
    #[test]
    fn the_mask_of_several_lights_is_their_penumbrae() {
        let l0 = vec![0.0, 0.0, 0.5, 1.0, 1.0];
        let l1 = vec![1.0, 0.3, 1.0, 1.0, 0.0];
        let mask = PenumbraMask::union(&[l0.clone(), l1.clone()], &receivers(&[0, 1, 2, 3, 4]));
        assert_eq!(mask.pixels, vec![1, 2]);
        let mean: Vec<f32> = l0.iter().zip(&l1).map(|(a, b)| (a + b) / 2.0).collect();
        let of_mean = PenumbraMask::new(&mean, &receivers(&[0, 1, 2, 3, 4]));
        assert_eq!(of_mean.pixels, vec![0, 1, 2, 4], "the mean alone would take in 0 and 4");
        assert_eq!(PenumbraMask::union(&[l0], &receivers(&[0, 1, 2, 3, 4])).pixels, vec![2]);
    }

    #[test]
    fn the_mask_holds_receiver_pixels_only() {
        // Pixel 1 sees the occluder (partly lit, as the sphere's own terminator is), pixel 4 the
        // sky: neither is judged, whatever their values.
        let reference = [0.2, 0.4, 0.6, 0.0005, -1.0, 0.9995, 0.8];
        let mask = PenumbraMask::new(&reference, &receivers(&[6, 0, 2, 3, 5]));
        assert_eq!(mask.pixels, vec![0, 2, 6]);
        let empty = PenumbraMask::new(&reference, &receivers(&[]));
        assert!(ErrorMetrics::measure(&reference, &reference, &empty).rmse.is_nan());
    }

    #[test]
    fn coverage_counts_area_and_lost_penumbra_on_the_receiver() {
        // Ground-truth penumbra: receiver pixels 0, 1, 2, 3. The image keeps 0 and 2, shows 1 as
        // fully lit and 3 as fully dark, and puts penumbra at receiver pixel 4 and at pixel 5,
        // which is not on the receiver and must not count.
        let gt = [0.3, 0.5, 0.7, 0.9, 1.0, 0.5];
        let image = [0.2, 1.0, 0.6, 0.0, 0.5, 0.5];
        let rec = receivers(&[0, 1, 2, 3, 4]);
        let mask = PenumbraMask::new(&gt, &rec);
        let (area, lost) = penumbra_coverage(&image, &mask, &rec);
        assert_eq!(area, 3.0 / 4.0);
        assert_eq!(lost, 2.0 / 4.0);
        let nothing = PenumbraMask { pixels: vec![] };
        assert!(penumbra_coverage(&image, &nothing, &rec).0.is_nan());
    }
}
