//! The penumbra's size from the blockers the shadow rays meet, as percentage-closer soft
//! shadows estimate it (Fernando 2005) and Boksansky et al. 2019 use it to size their filter:
//! a disk of radius a at distance D from the receiver, behind a blocker at distance d from the
//! receiver, casts a penumbra 2 a d / (D - d) wide (similar triangles through the blocker's
//! edge). In pixels, over the receiver's footprint, it sets the filter's standard deviation.

use super::{FilterSettings, GBuffer};
use crate::render::shading::Receiver;
use crate::render::NO_HIT;
use crate::scene::{DiskLight, Scene};
use glam::DVec3;

/// Width (m) of the penumbra a disk of radius `radius` at distance `light` casts behind a
/// blocker at distance `blocker`, both from the receiver.
pub fn penumbra_width(radius: f64, light: f64, blocker: f64) -> f64 {
    if !(blocker > 0.0 && blocker < light) {
        return 0.0;
    }
    2.0 * radius * blocker / (light - blocker)
}

/// Distance from `r` to the first blocker on the shadow ray to `target`, if one lies before it.
pub fn blocker_distance(scene: &Scene, r: &Receiver, target: DVec3) -> Option<f64> {
    let origin = r.origin();
    let d = target - origin;
    let len = d.length();
    let dir = d / len;
    // The receiver's own sphere or plane is convex and faces away: skipped, as the shadow rays
    // skip it; a mesh receiver skips its own triangle.
    let own = (r.triangle == NO_HIT).then_some(r.object as usize);
    let analytic = (scene.shapes.iter().enumerate())
        .filter(|&(id, _)| Some(id) != own)
        .filter_map(|(_, s)| s.first_t(origin, dir))
        .fold(f64::INFINITY, f64::min);
    let mesh = (scene.accel.as_ref())
        .and_then(|a| a.closest(origin, dir, analytic.min(len), r.triangle))
        .map_or(f64::INFINITY, |h| h.t);
    Some(analytic.min(mesh)).filter(|&t| t > 0.0 && t < len)
}

/// Per pixel, the penumbra filter's standard deviation (pixels) along the edge
/// ([`FilterSettings::penumbra_scale`] times the width, capped at `penumbra_max_sigma`), from
/// the penumbra width W (pixels, over the pixel's footprint) its blocker estimate gives; 0 where
/// no blocker was seen nearby. Pixels on a penumbra's lit side see no blocker themselves: each
/// blocked pixel lends its W (at most the width whose sigma reaches the cap) to the pixels
/// around it, falling linearly to 0 at W + 1 pixels away, and a pixel takes the largest it is
/// lent. The tent is continuous, so the kernel shrinks to nothing instead of stopping at a seam.
pub fn kernel_sigma(
    blocker: &[f64],
    gbuffer: &GBuffer,
    light: &DiskLight,
    width: u32,
    height: u32,
    settings: &FilterSettings,
) -> Vec<f32> {
    let (w, h) = (width as i64, height as i64);
    // Past the width whose sigma is capped a wider estimate changes nothing: lending it no
    // further keeps the tents' reach (and the work, each tent's area) bounded.
    let widest = settings.penumbra_max_sigma / settings.penumbra_scale;
    let mut lent = vec![0f64; blocker.len()];
    for (i, &b) in blocker.iter().enumerate() {
        if gbuffer.footprint[i] <= 0.0 || !b.is_finite() {
            continue;
        }
        let d_light = (light.center - gbuffer.point[i]).length();
        let own = penumbra_width(light.radius, d_light, b) / gbuffer.footprint[i] as f64;
        let own = own.min(widest);
        let reach = own + 1.0;
        let r = reach.floor() as i64;
        let (x, y) = (i as i64 % w, i as i64 / w);
        for qy in (y - r).max(0)..=(y + r).min(h - 1) {
            for qx in (x - r).max(0)..=(x + r).min(w - 1) {
                let d = (((qx - x).pow(2) + (qy - y).pow(2)) as f64).sqrt();
                let q = (qy * w + qx) as usize;
                if d < reach && gbuffer.footprint[q] > 0.0 {
                    lent[q] = lent[q].max(own * (1.0 - d / reach));
                }
            }
        }
    }
    lent.iter()
        .map(|&width| (settings.penumbra_scale * width).min(settings.penumbra_max_sigma) as f32)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kernel_follows_the_penumbra_and_fades_to_lit_neighbours_without_a_seam() {
        // A 41 x 1 floor row under a light 2 m up, 1 mm pixels; a blocker 0.5 m up is seen by
        // pixel 20 only.
        let n = 41;
        let mut g = GBuffer::flat(n, 2.0, 0.001);
        g.point = (0..n).map(|i| DVec3::new(i as f64 * 0.001, 0.0, 0.0)).collect();
        let light = DiskLight {
            center: DVec3::new(0.020, 0.0, 2.0),
            normal: DVec3::NEG_Z,
            radius: 0.02,
            power: 1.0,
            samples: 1,
        };
        let mut blocker = vec![f64::NAN; n];
        blocker[20] = 0.5;
        let settings = FilterSettings::default();
        let sigma = kernel_sigma(&blocker, &g, &light, n as u32, 1, &settings);
        // 2 a b / (D - b) = 0.04 * 0.5 / 1.5 m = 13.3 px.
        let width = 0.04 * 0.5 / 1.5 / 0.001;
        let expect = |d: f64| width * (1.0 - d / (width + 1.0));
        for (i, s) in sigma.iter().enumerate() {
            let d = (i as f64 - 20.0).abs();
            let along = (settings.penumbra_scale * expect(d)).min(settings.penumbra_max_sigma);
            if d < width + 1.0 {
                assert!((*s as f64 - along).abs() < 1e-4, "pixel {i}: {s}, expected {along}");
            } else {
                assert_eq!(*s, 0.0, "pixel {i}");
            }
        }
        // No seam: neighbours differ by at most the tent's slope.
        let slope = settings.penumbra_scale * width / (width + 1.0);
        for pair in sigma.windows(2) {
            assert!((pair[0] - pair[1]).abs() as f64 <= slope + 1e-4, "{pair:?}");
        }
        // Capped: at its cap, the width lent at the one whose sigma reaches it.
        let wide = FilterSettings {
            penumbra_scale: 10.0,
            ..settings
        };
        let capped = kernel_sigma(&blocker, &g, &light, n as u32, 1, &wide);
        assert_eq!(capped[20], 8.0);
        assert!(capped[21] > 0.0 && capped[21] < 8.0);
        assert_eq!(capped[22], 0.0, "the tent reaches only the capped width (0.8 px) + 1");
    }

    #[test]
    fn similar_triangles_give_the_closed_form() {
        // A blocker half way: the penumbra is the light's diameter.
        assert!((penumbra_width(0.02, 2.0, 1.0) - 0.04).abs() < 1e-15);
        // Touching the receiver: no penumbra; at or past the light: none either.
        assert_eq!(penumbra_width(0.02, 2.0, 0.0), 0.0);
        assert_eq!(penumbra_width(0.02, 2.0, 2.0), 0.0);
        // The sphere scene: blocker at 0.25..0.75 m under a light 2 m up, 2 cm radius.
        assert!((penumbra_width(0.02, 2.0, 0.5) - 0.04 * 0.5 / 1.5).abs() < 1e-15);
    }
}
