//! The penumbra's visible extent ("how far partial shadow reaches", as an eye reads an image),
//! measured with a sliding annulus one bin (one pixel) wide:
//!
//! - inner = the centre radius, going outwards, at which at least [`SHARE`] of the annulus's
//!   receiver pixels first see some light (V > 0);
//! - outer = the centre radius, going inwards, at which at least [`SHARE`] of them are first
//!   shadowed (V < 1).
//!
//! The annulus slides in steps of 1/[`STEPS`] of its width and the crossing is interpolated
//! between steps, so the extent is not quantised to pixels. For a sharp edge at r0 the share
//! rises linearly from 0 to 1 as the annulus passes over it, so inner = r0 - (1/2 - SHARE) w and
//! outer = r0 + (1/2 - SHARE) w for annulus width w, wherever r0 falls relative to the pixels: the
//! exact image's extent is r_p - r_u + 0.9 w. Annuli with fewer than [`MIN_PIXELS`] pixels (the
//! corners of the patch) are skipped. A crossing that the patch clips (the outermost annulus
//! still shadowed, or the innermost lit where the patch does not reach the axis) is not a
//! measurement: the extent is NaN there, "beyond the patch", never the patch's edge.

/// Share of an annulus's pixels that must show (partial) shadow or light.
pub const SHARE: f64 = 0.05;
/// Annuli with fewer pixels are left out.
pub const MIN_PIXELS: usize = 8;
/// Positions of the sliding annulus per width.
pub const STEPS: u32 = 32;

/// Receiver pixels sorted by radius, with running counts of lit and shadowed pixels.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Annuli {
    radius: Vec<f64>,
    /// lit[k]: pixels with V > 0 among the first k.
    lit: Vec<usize>,
    /// shadowed[k]: pixels with V < 1 among the first k.
    shadowed: Vec<usize>,
    width: f64,
}

impl Annuli {
    /// From (radius, visibility) pairs and the annulus width.
    pub fn new(mut pixels: Vec<(f64, f64)>, width: f64) -> Self {
        pixels.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (mut lit, mut shadowed) = (vec![0], vec![0]);
        for &(_, v) in &pixels {
            lit.push(lit.last().unwrap_or(&0) + (v > 0.0) as usize);
            shadowed.push(shadowed.last().unwrap_or(&0) + (v < 1.0) as usize);
        }
        Annuli {
            radius: pixels.iter().map(|p| p.0).collect(),
            lit,
            shadowed,
            width,
        }
    }

    /// (pixels, share with the property) of the annulus centred at `c`.
    fn share(&self, c: f64, counts: &[usize]) -> (usize, f64) {
        let lo = self.radius.partition_point(|&r| r < c - 0.5 * self.width);
        let hi = self.radius.partition_point(|&r| r < c + 0.5 * self.width);
        let n = hi - lo;
        (n, (counts[hi] - counts[lo]) as f64 / n.max(1) as f64)
    }

    /// Inner and outer extent (m); NaN where no annulus qualifies or the patch clips the crossing.
    pub fn extent(&self) -> (f64, f64) {
        let (Some(&first), Some(&last)) = (self.radius.first(), self.radius.last()) else {
            return (f64::NAN, f64::NAN);
        };
        let step = self.width / STEPS as f64;
        let count = ((last - first) / step).ceil() as usize + 1;
        let centres = (0..count).map(|k| first + k as f64 * step);
        // An innermost annulus that covers the axis may already be lit: there is no umbra.
        let from_axis = first <= 0.5 * self.width;
        let inner = self.crossing(centres.clone(), &self.lit, from_axis);
        let outer = self.crossing(centres.rev(), &self.shadowed, false);
        (inner, outer)
    }

    /// The first centre in `centres` whose share reaches [`SHARE`], interpolated from the
    /// previous qualifying-size annulus. Reached at the first annulus, the crossing lies at or
    /// before the patch's edge: NaN unless `open_start` says nothing lies before it.
    fn crossing(&self, centres: impl Iterator<Item = f64>, counts: &[usize], open_start: bool) -> f64 {
        let mut previous: Option<(f64, f64)> = None;
        for c in centres {
            let (n, s) = self.share(c, counts);
            if n < MIN_PIXELS {
                continue;
            }
            if s >= SHARE {
                return match previous {
                    Some((c0, s0)) => c0 + (c - c0) * (SHARE - s0) / (s - s0),
                    None if open_start => c,
                    None => f64::NAN,
                };
            }
            previous = Some((c, s));
        }
        f64::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 100 pixels per unit of radius, evenly spread over [0, 10), visibility `v(r)`.
    fn annuli(v: impl Fn(f64) -> f64) -> Annuli {
        let pixels = (0..1000)
            .map(|k| {
                let r = (k as f64 + 0.5) / 100.0;
                (r, v(r))
            })
            .collect();
        Annuli::new(pixels, 1.0)
    }

    #[test]
    fn a_sharp_edge_is_found_at_a_constant_offset_wherever_it_falls() {
        for k in 0..20 {
            let r0 = 5.0 + 0.05 * k as f64 + 0.003;
            let (inner, outer) = annuli(|r| (r > r0) as u8 as f64).extent();
            let (want_in, want_out) = (r0 - (0.5 - SHARE), r0 + (0.5 - SHARE));
            // Pixels are 0.01 apart: the share moves in steps of 0.01, so r in steps of 0.01.
            assert!(
                (inner - want_in).abs() < 0.011,
                "r0 {r0}: inner {inner}, want {want_in}"
            );
            assert!(
                (outer - want_out).abs() < 0.011,
                "r0 {r0}: outer {outer}, want {want_out}"
            );
        }
    }

    #[test]
    fn a_linear_ramp_has_its_known_extent() {
        // Partial shadow from r = 2 to r = 8.
        let (inner, outer) = annuli(|r| ((r - 2.0) / 6.0).clamp(0.0, 1.0)).extent();
        assert!(
            (inner - 1.55).abs() < 0.011 && (outer - 8.45).abs() < 0.011,
            "{inner} {outer}"
        );
    }

    #[test]
    fn crossings_the_patch_clips_are_not_measured() {
        // Partial shadow from r = 2 to past the patch's edge at r = 10.
        let (inner, outer) = annuli(|r| ((r - 2.0) / 12.0).clamp(0.0, 1.0)).extent();
        assert!((inner - 1.55).abs() < 0.011, "{inner}");
        assert!(outer.is_nan(), "the penumbra runs past the patch, yet outer = {outer}");
        // A ring patch (r in [3, 10)) lit throughout: the umbra, if any, lies inside r = 3.
        let ring: Vec<(f64, f64)> = (300..1000).map(|k| ((k as f64 + 0.5) / 100.0, 1.0)).collect();
        let (inner, _) = Annuli::new(ring, 1.0).extent();
        assert!(inner.is_nan(), "the ring's inner edge read as an extent: {inner}");
    }

    #[test]
    fn all_lit_images_have_light_from_the_axis_and_no_outer_extent() {
        // Light reaches the axis (inner = the first annulus's centre); nothing is shadowed.
        let (inner, outer) = annuli(|_| 1.0).extent();
        assert_eq!(inner, 0.005, "the first annulus already qualifies: {inner}");
        assert!(outer.is_nan());
        let (a, b) = Annuli::new(vec![], 1.0).extent();
        assert!(a.is_nan() && b.is_nan());
    }
}
