//! The f64 CPU backend: the fallback when no GPU adapter exists and the cross-check of the GPU
//! in tests. Same plan, same sample streams, double precision, rayon over rows.

use super::shading::{shade_light, Receiver, Targets};
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
                loop_cap: None,
            },
        }
    }
}

/// The closest surface a ray meets, as a receiver of shadow rays: point re-projected onto
/// analytic surfaces, geometric normal facing the ray.
pub fn closest_hit(scene: &Scene, origin: DVec3, dir: DVec3) -> Option<Receiver> {
    let mut best: Option<(f64, u32, u32)> = None;
    let consider = |best: &mut Option<(f64, u32, u32)>, t: f64, id: u32, tri: u32| {
        if t > 0.0 && best.is_none_or(|(bt, _, _)| t < bt) {
            *best = Some((t, id, tri));
        }
    };
    for (i, s) in scene.spheres.iter().enumerate() {
        if let Some((t0, t1)) = sphere_roots(origin, dir, s) {
            consider(&mut best, if t0 > 0.0 { t0 } else { t1 }, i as u32, NO_HIT);
        }
    }
    for (i, p) in scene.planes.iter().enumerate() {
        if let Some(t) = plane_t(origin, dir, p) {
            consider(&mut best, t, scene.plane_id(i), NO_HIT);
        }
    }
    if let Some(bvh) = &scene.bvh {
        let tmax = best.map_or(f64::INFINITY, |b| b.0);
        if let Some(h) = bvh.closest(origin, dir, tmax, NO_HIT) {
            consider(
                &mut best,
                h.t,
                scene.mesh_id(bvh.mesh_of[h.triangle as usize] as usize),
                h.triangle,
            );
        }
    }
    let (t, object, triangle) = best?;
    let raw = origin + dir * t;
    let (p, n, albedo) = if let Some(s) = scene.spheres.get(object as usize) {
        let p = reproject_sphere(raw, s);
        (p, (p - s.center) / s.radius, s.albedo)
    } else if let Some(pl) = scene.planes.get(object as usize - scene.spheres.len()) {
        (reproject_plane(raw, pl), pl.normal, pl.albedo)
    } else {
        let bvh = scene.bvh.as_ref().expect("a mesh hit has a BVH");
        let tri = &bvh.world[triangle as usize];
        let mesh = bvh.mesh_of[triangle as usize] as usize;
        (
            raw,
            (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize(),
            scene.meshes[mesh].albedo,
        )
    };
    let n = if n.dot(dir) > 0.0 { -n } else { n };
    Some(Receiver {
        p,
        n,
        albedo,
        object,
        triangle,
    })
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
                    let Some(receiver) = closest_hit(scene, ray.origin, ray.direction) else {
                        continue;
                    };
                    let pixel = y * view.width + x;
                    hit[x as usize] = receiver.object;
                    let mut irradiance = 0.0;
                    for (li, light) in scene.lights.iter().enumerate() {
                        let targets = match &shared[li] {
                            Some(points) => Targets::Shared(points),
                            None => {
                                Targets::PerPixel(sampling.scheme, Stream::new(sampling.seed, li as u32, Some(pixel)))
                            }
                        };
                        let s = shade_light(scene, &receiver, light, targets);
                        vis[li * w + x as usize] = s.visibility as f32;
                        irradiance += s.irradiance;
                        rays[li] += s.rays;
                    }
                    radiance[x as usize] = (receiver.albedo * FRAC_1_PI * irradiance) as f32;
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
            primary_seconds: vec![],
            clock: Clock::WallClock,
        })
    }
}
