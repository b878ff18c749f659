//! Whitted's mirror chains on the CPU backend (Whitted 1980; the visibility-field paper's
//! walkthrough shading, Section 6). From a receiver with mirror weight m the reflected ray's
//! closest hit is shaded from every light (with shadow rays where the scene has shadows) and,
//! where it reflects too, followed again, up to the scene's mirror depth. Radiance leaving a
//! vertex is (1 - m) x diffuse + m x reflected; a chain cut at the depth limit, or leaving the
//! scene, brings back nothing (there is no environment light).

use super::cpu::closest_hit_skipping;
use super::plan::MAX_LIGHTS;
use super::shading::{shade_light, Receiver, Targets};
use crate::scene::Scene;
use glam::DVec3;
use std::f64::consts::FRAC_1_PI;

/// What one mirror chain brought back.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Chain {
    /// Radiance reflected towards the chain's first receiver, already weighted by its mirror
    /// weight (W m^-2 sr^-1).
    pub radiance: f64,
    /// Reflected rays traced.
    pub reflection_rays: u64,
    /// Shadow rays traced at the chain's vertices, per light.
    pub shadow_rays: [u64; MAX_LIGHTS],
}

/// The mirror direction of `d` about unit normal `n`.
pub fn reflect(d: DVec3, n: DVec3) -> DVec3 {
    d - 2.0 * d.dot(n) * n
}

/// Diffuse radiance leaving `r` under every light (albedo / pi x irradiance), adding each
/// light's shadow rays to `rays`; `targets(light)` says where that light's rays land.
pub fn diffuse<'a>(
    scene: &Scene,
    r: &Receiver,
    targets: &dyn Fn(usize) -> Targets<'a>,
    rays: &mut [u64; MAX_LIGHTS],
) -> f64 {
    let mut irradiance = 0.0;
    for (i, light) in scene.lights.iter().enumerate() {
        let s = shade_light(scene, r, light, targets(i));
        irradiance += s.irradiance;
        rays[i] += s.rays;
    }
    r.albedo * FRAC_1_PI * irradiance
}

/// The chain leaving receiver `r`, seen along `incoming` (unit, towards `r`). A vertex that is
/// a perfect mirror (m = 1) has no diffuse part and traces no shadow rays.
pub fn mirror_chain<'a>(scene: &Scene, r: &Receiver, incoming: DVec3, targets: &dyn Fn(usize) -> Targets<'a>) -> Chain {
    let mut chain = Chain::default();
    let mut weight = scene.shapes[r.object as usize].mirror();
    let (mut at, mut dir) = (*r, reflect(incoming, r.n).normalize());
    for _ in 0..scene.shading.mirror_depth {
        if weight == 0.0 {
            break;
        }
        chain.reflection_rays += 1;
        let Some(next) = closest_hit_skipping(scene, at.origin(), dir, at.triangle) else {
            break;
        };
        let m = scene.shapes[next.object as usize].mirror();
        if m < 1.0 {
            let local = diffuse(scene, &next, targets, &mut chain.shadow_rays);
            chain.radiance += weight * (1.0 - m) * local;
        }
        weight *= m;
        dir = reflect(dir, next.n).normalize();
        at = next;
    }
    chain
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflection_keeps_length_and_flips_the_normal_component() {
        let n = DVec3::new(0.0, 0.6, 0.8);
        let d = DVec3::new(0.3, -0.5, -0.7).normalize();
        let r = reflect(d, n);
        assert!((r.length() - 1.0).abs() < 1e-15);
        assert!((r.dot(n) + d.dot(n)).abs() < 1e-15);
        assert!((r - r.dot(n) * n - (d - d.dot(n) * n)).length() < 1e-15);
    }
}
