//! The f64 CPU backend: the fallback when no GPU adapter exists and the cross-check of the GPU
//! in tests. It runs the plan's passes in order, each a parallel loop over pixels (rayon), with
//! the GPU's sample streams, in double precision.

use super::ambient::{occlusion, occlusion_bundled, AMBIENT_STREAM};
use super::mirror::{mirror_chain, Chain};
use super::shading::{shade_light, LightSample, Receiver, Targets};
use super::{AdapterInfo, Backend, Clock, Frame, RayCounts, Sampling, Timing, View, NO_HIT, NO_RECEIVER};
use crate::accel::work::{self, Work};
use crate::accel::Issue;
use crate::render::plan::{Pass, RenderPlan};
use crate::sampling::{shared_points, Pattern, Site};
use crate::scene::ambient::{AmbientOcclusion, AoDirections};
use crate::scene::Scene;
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use std::f64::consts::FRAC_1_PI;
use std::time::Instant;

/// The CPU reference renderer.
pub struct CpuBackend {
    info: AdapterInfo,
    /// Passes run so far, all frames: one parallel loop per pass of the plan.
    dispatches: u64,
}

impl Default for CpuBackend {
    fn default() -> Self {
        CpuBackend {
            info: AdapterInfo {
                backend: "cpu".into(),
                name: "penumbra f64 reference".into(),
                driver: "rayon".into(),
                api: "cpu".into(),
                loop_cap: None,
                threads: Some(rayon::current_num_threads()),
            },
            dispatches: 0,
        }
    }
}

/// The closest surface a ray meets, as a receiver of shadow rays: point re-projected onto
/// analytic surfaces, geometric normal facing the ray. Analytic shapes are tested in id order
/// (the first of equal distances wins), then the accelerator within the distance found.
pub fn closest_hit(scene: &Scene, origin: DVec3, dir: DVec3) -> Option<Receiver> {
    closest_hit_skipping(scene, origin, dir, NO_HIT)
}

/// [`closest_hit`] ignoring triangle `skip` (a secondary ray's own triangle).
pub fn closest_hit_skipping(scene: &Scene, origin: DVec3, dir: DVec3, skip: u32) -> Option<Receiver> {
    work::query();
    work::add(0, scene.analytic_shapes() as u64);
    let mut best: Option<(f64, usize)> = None;
    for (id, shape) in scene.shapes.iter().enumerate() {
        if let Some(t) = shape.first_t(origin, dir) {
            if best.is_none_or(|(bt, _)| t < bt) {
                best = Some((t, id));
            }
        }
    }
    let tmax = best.map_or(f64::INFINITY, |b| b.0);
    let mesh_hit = scene.accel.as_ref().and_then(|a| a.closest(origin, dir, tmax, skip));
    let (p, n, object, triangle) = match mesh_hit {
        Some(h) if h.t > 0.0 => {
            let tri = &scene.triangles.positions[h.triangle as usize];
            let object = scene.triangles.object_of[h.triangle as usize];
            let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize();
            (origin + dir * h.t, n, object as usize, h.triangle)
        }
        _ => {
            let (t, id) = best?;
            let surface = scene.shapes[id].surface(origin + dir * t)?;
            (surface.point, surface.normal, id, NO_HIT)
        }
    };
    let n = if n.dot(dir) > 0.0 { -n } else { n };
    Some(Receiver {
        p,
        n,
        albedo: scene.shapes[object].albedo(),
        object: object as u32,
        triangle,
    })
}

/// Where each light's shadow rays land for one frame: the shared set, drawn once, or each
/// pixel's own stream.
struct LightTargets {
    shared: Vec<Option<Vec<DVec2>>>,
    sampling: Sampling,
    width: u32,
}

/// Pixel `pixel`'s sampling site for stream `light` (a light's index, or the ambient pass's).
fn site(sampling: Sampling, light: u32, pixel: usize, width: u32) -> Site {
    let p = pixel as u32;
    Site::pixel(sampling.seed, light, [p % width, p / width], p, sampling.frame)
}

impl LightTargets {
    fn new(scene: &Scene, sampling: Sampling, width: u32) -> LightTargets {
        let shared = scene
            .lights
            .iter()
            .enumerate()
            .map(|(i, l)| {
                (sampling.pattern == Pattern::Shared)
                    .then(|| shared_points(sampling.scheme, l.samples(), sampling.seed, i as u32, sampling.frame))
            })
            .collect();
        LightTargets {
            shared,
            sampling,
            width,
        }
    }

    fn of(&self, light: usize, pixel: usize) -> Targets<'_> {
        match &self.shared[light] {
            Some(points) => Targets::Shared(points),
            None => Targets::PerPixel(
                self.sampling.scheme,
                site(self.sampling, light as u32, pixel, self.width),
            ),
        }
    }
}

/// One light over every receiver (its shadow rays, or unoccluded where the scene has no
/// shadows): visibility into `frame`, irradiance added to `irradiance`; returns the rays traced.
fn light_pass(
    scene: &Scene,
    receivers: &[Option<Receiver>],
    light: usize,
    targets: &LightTargets,
    frame: &mut Frame,
    irradiance: &mut [f64],
) -> u64 {
    let l = &scene.lights[light];
    let samples: Vec<(Option<LightSample>, Work)> = receivers
        .par_iter()
        .enumerate()
        .map(|(pixel, r)| work::counted(|| r.as_ref().map(|r| shade_light(scene, r, l, targets.of(light, pixel)))))
        .collect();
    let (samples, work) = split_work(samples);
    frame.work += work;
    let mut rays = 0;
    for (pixel, s) in samples.iter().enumerate() {
        if let Some(s) = s {
            frame.visibility[light][pixel] = s.visibility as f32;
            irradiance[pixel] += s.irradiance;
            rays += s.rays;
        }
    }
    rays
}

/// A pixel's ambient occlusion and rays, where it has a receiver.
type Pixel = Option<(f64, u64)>;

/// Receivers per bundle when the ambient pass issues rays direction-major: 16 rows of a 256-wide
/// image, so a frame still splits into enough bundles to keep every core busy.
const BUNDLE: usize = 4096;

/// The ambient-occlusion pass over every receiver: the image and the rays traced.
fn ambient_image(
    scene: &Scene,
    ao: &AmbientOcclusion,
    receivers: &[Option<Receiver>],
    sampling: Sampling,
    width: u32,
) -> (Vec<f32>, u64, Work) {
    let shared = match (&ao.directions, sampling.pattern) {
        (AoDirections::Disk(scheme), Pattern::Shared) => Some(shared_points(
            *scheme,
            ao.rays,
            sampling.seed,
            AMBIENT_STREAM,
            sampling.frame,
        )),
        _ => None,
    };
    let at = |pixel: usize| site(sampling, AMBIENT_STREAM, pixel, width);
    let (values, work) = match ao.issue {
        Issue::Single => split_work(
            receivers
                .par_iter()
                .enumerate()
                .map(|(pixel, r)| {
                    work::counted(|| {
                        r.as_ref()
                            .map(|r| occlusion(scene, r, ao, shared.as_deref(), at(pixel)))
                    })
                })
                .collect(),
        ),
        Issue::Bundled => {
            let chunks: Vec<(Vec<Pixel>, Work)> = receivers
                .par_chunks(BUNDLE)
                .enumerate()
                .map(|(c, chunk)| {
                    let live: Vec<(&Receiver, Site)> = chunk
                        .iter()
                        .enumerate()
                        .filter_map(|(i, r)| r.as_ref().map(|r| (r, at(c * BUNDLE + i))))
                        .collect();
                    let (mut values, work) = work::counted(|| occlusion_bundled(scene, &live, ao, shared.as_deref()));
                    values.reverse();
                    (
                        chunk.iter().map(|r| r.as_ref().and_then(|_| values.pop())).collect(),
                        work,
                    )
                })
                .collect();
            let work = chunks.iter().map(|c| c.1).sum();
            (chunks.into_iter().flat_map(|c| c.0).collect(), work)
        }
    };
    let rays = values.iter().flatten().map(|v| v.1).sum();
    let image = values.iter().map(|v| v.map_or(NO_RECEIVER, |v| v.0 as f32)).collect();
    (image, rays, work)
}

/// Per-pixel values and the sum of their work.
fn split_work<T>(pixels: Vec<(T, Work)>) -> (Vec<T>, Work) {
    let work = pixels.iter().map(|p| p.1).sum();
    (pixels.into_iter().map(|p| p.0).collect(), work)
}

impl Backend for CpuBackend {
    fn adapter(&self) -> &AdapterInfo {
        &self.info
    }

    fn dispatches(&self) -> u64 {
        self.dispatches
    }

    fn render(&mut self, scene: &Scene, view: View, sampling: Sampling) -> anyhow::Result<Frame> {
        let plan = RenderPlan::new(scene, view)?;
        let pixels = view.pixels();
        let mut frame = Frame {
            width: view.width,
            height: view.height,
            radiance: vec![0.0; pixels],
            visibility: vec![vec![NO_RECEIVER; pixels]; scene.lights.len()],
            hit: vec![NO_HIT; pixels],
            ambient: None,
            rays: RayCounts::default(),
            work: Work::ZERO,
            counted: true,
            mirror_bounces: 0,
        };
        let mut receivers: Vec<Option<Receiver>> = vec![];
        let mut irradiance = vec![0f64; pixels];
        let mut reflected = vec![0f64; pixels];
        let targets = LightTargets::new(scene, sampling, view.width);
        for pass in &plan.passes {
            self.dispatches += 1;
            match *pass {
                Pass::Primary { rays, .. } => {
                    let hits: Vec<(Option<Receiver>, Work)> = (0..pixels)
                        .into_par_iter()
                        .map(|i| {
                            let (x, y) = (i as u32 % view.width, i as u32 / view.width);
                            let ray = view.camera.ray(x, y, view.width, view.height);
                            work::counted(|| closest_hit(scene, ray.origin, ray.direction))
                        })
                        .collect();
                    let work;
                    (receivers, work) = split_work(hits);
                    frame.work += work;
                    for (h, r) in frame.hit.iter_mut().zip(&receivers) {
                        *h = r.map_or(NO_HIT, |r| r.object);
                    }
                    frame.rays.primary = rays;
                }
                Pass::Shadow { light, .. } => {
                    frame.rays.shadow[light] +=
                        light_pass(scene, &receivers, light, &targets, &mut frame, &mut irradiance);
                }
                Pass::Direct { .. } => {
                    for light in 0..scene.lights.len() {
                        light_pass(scene, &receivers, light, &targets, &mut frame, &mut irradiance);
                    }
                }
                Pass::Mirror { .. } => {
                    let chains: Vec<(Option<Chain>, Work)> = receivers
                        .par_iter()
                        .enumerate()
                        .map(|(pixel, r)| {
                            work::counted(|| {
                                let r = r.as_ref()?;
                                let (x, y) = (pixel as u32 % view.width, pixel as u32 / view.width);
                                let ray = view.camera.ray(x, y, view.width, view.height);
                                Some(mirror_chain(scene, r, ray.direction, &|l| targets.of(l, pixel)))
                            })
                        })
                        .collect();
                    let (chains, work) = split_work(chains);
                    frame.work += work;
                    frame.mirror_bounces = chains
                        .iter()
                        .flatten()
                        .map(|c| c.reflection_rays as u32)
                        .fold(1, u32::max);
                    for (pixel, c) in chains.iter().enumerate() {
                        if let Some(c) = c {
                            reflected[pixel] = c.radiance;
                            frame.rays.reflection += c.reflection_rays;
                            for (total, n) in frame.rays.shadow.iter_mut().zip(c.shadow_rays) {
                                *total += n;
                            }
                        }
                    }
                }
                Pass::Ambient { .. } => {
                    let ao = scene.ambient.as_ref().expect("the plan has the pass only then");
                    let (image, rays, work) = ambient_image(scene, ao, &receivers, sampling, view.width);
                    frame.work += work;
                    frame.ambient = Some(image);
                    frame.rays.ambient = rays;
                }
            }
        }
        frame
            .radiance
            .par_iter_mut()
            .zip(receivers.par_iter().zip(irradiance.par_iter().zip(&reflected)))
            .for_each(|(out, (r, (e, reflected)))| {
                if let Some(r) = r {
                    let m = scene.shapes[r.object as usize].mirror();
                    *out = ((1.0 - m) * r.albedo * FRAC_1_PI * e + reflected) as f32;
                }
            });
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
