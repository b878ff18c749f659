//! The penumbra's size from the blockers the shadow rays meet, as percentage-closer soft
//! shadows estimate it (Fernando 2005) and Boksansky et al. 2019 use it to size their filter:
//! a disk of radius a at distance D from the receiver, behind a blocker at distance d from the
//! receiver, casts a penumbra 2 a d / (D - d) wide (similar triangles through the blocker's
//! edge). In pixels, over the receiver's footprint, it sets the filter's standard deviation.

use super::GBuffer;
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

/// Per-pixel standard deviation (pixels) of the penumbra filter: `scale` times the penumbra's
/// width over the pixel's footprint, from the blocker distance dilated over a 5 x 5 window
/// (pixels of the penumbra's lit side see no blocker themselves), capped at `max_sigma`; 0 where
/// no blocker was seen nearby.
pub fn kernel_sigma(
    blocker: &[f64],
    gbuffer: &GBuffer,
    light: &DiskLight,
    width: u32,
    height: u32,
    scale: f64,
    max_sigma: f64,
) -> Vec<f32> {
    let (w, h) = (width as i64, height as i64);
    let mut sigma = vec![0f32; blocker.len()];
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if gbuffer.footprint[i] <= 0.0 {
                continue;
            }
            let (mut sum, mut n) = (0.0, 0u32);
            for qy in (y - 2).max(0)..=(y + 2).min(h - 1) {
                for qx in (x - 2).max(0)..=(x + 2).min(w - 1) {
                    let b = blocker[(qy * w + qx) as usize];
                    if b.is_finite() {
                        sum += b;
                        n += 1;
                    }
                }
            }
            if n == 0 {
                continue;
            }
            let d_light = (light.center - gbuffer.point[i]).length();
            let width_m = penumbra_width(light.radius, d_light, sum / n as f64);
            let s = scale * width_m / gbuffer.footprint[i] as f64;
            sigma[i] = s.clamp(0.0, max_sigma) as f32;
        }
    }
    sigma
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kernel_follows_the_penumbra_and_reaches_lit_neighbours() {
        // A 9 x 1 floor row under a light 2 m up, 1 mm pixels; a blocker 0.5 m up is seen by
        // pixel 4 only.
        let mut g = GBuffer::flat(9, 2.0, 0.001);
        g.point = (0..9).map(|i| DVec3::new(i as f64 * 0.001, 0.0, 0.0)).collect();
        let light = DiskLight {
            center: DVec3::new(0.004, 0.0, 2.0),
            normal: DVec3::NEG_Z,
            radius: 0.02,
            power: 1.0,
            samples: 1,
        };
        let mut blocker = vec![f64::NAN; 9];
        blocker[4] = 0.5;
        let sigma = kernel_sigma(&blocker, &g, &light, 9, 1, 0.25, 8.0);
        // 2 a b / (D - b) = 0.04 * 0.5 / 1.5 m = 13.3 px; a quarter of it.
        assert!(
            (sigma[4] as f64 - 0.25 * 0.04 * 0.5 / 1.5 / 0.001).abs() < 1e-4,
            "{sigma:?}"
        );
        // The 5 x 5 dilation reaches two pixels each way, with the neighbour's own distance to
        // the light; beyond it nothing.
        assert!(sigma[2] > 3.0 && sigma[6] > 3.0, "{sigma:?}");
        assert_eq!((sigma[1], sigma[7]), (0.0, 0.0));
        // Capped.
        let capped = kernel_sigma(&blocker, &g, &light, 9, 1, 10.0, 8.0);
        assert_eq!(capped[4], 8.0);
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
