//! The f64 CPU backend: the fallback when no GPU adapter exists and the cross-check of the GPU
//! in tests. Same plan, same sample streams, double precision, rayon over rows.

use super::shading::{shade_light, Targets};
use super::{AdapterInfo, Backend, Clock, Frame, RayCounts, Sampling, Timing, View, NO_HIT, NO_RECEIVER};
use crate::geometry::{plane_t, reproject_plane, reproject_sphere, sphere_roots};
use crate::render::plan::{RenderPlan, MAX_LIGHTS};
use crate::sampling::{shared_points, Pattern, Stream};
use crate::scene::Scene;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::FRAC_1_PI;
use std::time::Instant;

/// The CPU reference renderer.
pub struct CpuBackend {
    info: AdapterInfo,
}

impl Default for CpuBackend {
    fn default() -> Self {
        CpuBackend {
            info: AdapterInfo {
                backend: "cpu".into(),
                name: "penumbra f64 reference".into(),
                driver: format!("rayon, {} threads", rayon::current_num_threads()),
                api: "cpu".into(),
            },
        }
    }
}

/// The closest surface a ray meets: point (re-projected onto the surface), normal facing the
/// ray, albedo and object id.
pub fn closest_hit(scene: &Scene, origin: DVec3, dir: DVec3) -> Option<(DVec3, DVec3, f64, u32)> {
    let mut best: Option<(f64, u32)> = None;
    let mut consider = |t: f64, id: u32| {
        if t > 0.0 && best.is_none_or(|(bt, _)| t < bt) {
            best = Some((t, id));
        }
    };
    for (i, s) in scene.spheres.iter().enumerate() {
        if let Some((t0, t1)) = sphere_roots(origin, dir, s) {
            consider(if t0 > 0.0 { t0 } else { t1 }, i as u32);
        }
    }
    for (i, p) in scene.planes.iter().enumerate() {
        if let Some(t) = plane_t(origin, dir, p) {
            consider(t, scene.plane_id(i));
        }
    }
    let (t, id) = best?;
    let raw = origin + dir * t;
    let (p, n, albedo) = match scene.spheres.get(id as usize) {
        Some(s) => {
            let p = reproject_sphere(raw, s);
            (p, (p - s.center) / s.radius, s.albedo)
        }
        None => {
            let pl = &scene.planes[id as usize - scene.spheres.len()];
            (reproject_plane(raw, pl), pl.normal, pl.albedo)
        }
    };
    let n = if n.dot(dir) > 0.0 { -n } else { n };
    Some((p, n, albedo, id))
}

impl Backend for CpuBackend {
    fn adapter(&self) -> &AdapterInfo {
        &self.info
    }

    fn render(&mut self, scene: &Scene, view: View, sampling: Sampling) -> anyhow::Result<Frame> {
        RenderPlan::new(scene, view)?;
        let shared: Vec<Option<Vec<_>>> = scene
            .lights
            .iter()
            .enumerate()
            .map(|(i, l)| {
                (sampling.pattern == Pattern::Shared)
                    .then(|| shared_points(sampling.scheme, l.samples(), sampling.seed, i as u32))
            })
            .collect();
        let w = view.width as usize;
        let lights = scene.lights.len();
        let rows: Vec<_> = (0..view.height)
            .into_par_iter()
            .map(|y| {
                let mut radiance = vec![0f32; w];
                let mut vis = vec![NO_RECEIVER; w * lights];
                let mut hit = vec![NO_HIT; w];
                let mut rays = [0u64; MAX_LIGHTS];
                for x in 0..view.width {
                    let ray = view.camera.ray(x, y, view.width, view.height);
                    let Some((p, n, albedo, id)) = closest_hit(scene, ray.origin, ray.direction) else {
                        continue;
                    };
                    let pixel = y * view.width + x;
                    hit[x as usize] = id;
                    let mut irradiance = 0.0;
                    for (li, light) in scene.lights.iter().enumerate() {
                        let targets = match &shared[li] {
                            Some(points) => Targets::Shared(points),
                            None => {
                                Targets::PerPixel(sampling.scheme, Stream::new(sampling.seed, li as u32, Some(pixel)))
                            }
                        };
                        let s = shade_light(scene, p, n, id, light, targets);
                        vis[li * w + x as usize] = s.visibility as f32;
                        irradiance += s.irradiance;
                        rays[li] += s.rays;
                    }
                    radiance[x as usize] = (albedo * FRAC_1_PI * irradiance) as f32;
                }
                (radiance, vis, hit, rays)
            })
            .collect();
        let mut frame = Frame {
            width: view.width,
            height: view.height,
            radiance: Vec::with_capacity(view.pixels()),
            visibility: vec![Vec::with_capacity(view.pixels()); lights],
            hit: Vec::with_capacity(view.pixels()),
            rays: RayCounts {
                primary: view.pixels() as u64,
                shadow: [0; MAX_LIGHTS],
            },
        };
        for (radiance, vis, hit, rays) in rows {
            frame.radiance.extend(radiance);
            frame.hit.extend(hit);
            for (li, v) in frame.visibility.iter_mut().enumerate() {
                v.extend_from_slice(&vis[li * w..(li + 1) * w]);
            }
            for (total, r) in frame.rays.shadow.iter_mut().zip(rays) {
                *total += r;
            }
        }
        Ok(frame)
    }

    fn time(
        &mut self,
        scene: &Scene,
        view: View,
        sampling: Sampling,
        warmup: u32,
        repeats: u32,
    ) -> anyhow::Result<Timing> {
        let mut seconds = Vec::new();
        for i in 0..warmup + repeats {
            let t = Instant::now();
            self.render(scene, view, sampling)?;
            if i >= warmup {
                seconds.push(t.elapsed().as_secs_f64());
            }
        }
        Ok(Timing {
            seconds,
            clock: Clock::WallClock,
        })
    }
}
