//! Test hooks: kernels (`shaders/hooks.wgsl`) that expose the WGSL sampler and the acceleration
//! structure's queries to tests. They are compiled only when called and bound through their own
//! group (probe rays), so nothing of theirs sits in the render pipelines or their layout.

use super::layout::{self, pack};
use super::GpuBackend;
use crate::render::{Sampling, View};
use crate::sampling::DiskScheme;
use wgpu::util::DeviceExt;

/// A probe ray for [`GpuBackend::probe`]: origin, unit direction, farthest distance.
pub type ProbeRay = (glam::DVec3, glam::DVec3, f64);

/// What the GPU found along a probe ray: closest distance and triangle (if any), and whether the
/// any-hit query reported a hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeHit {
    /// Closest hit (distance, triangle index).
    pub closest: Option<(f64, u32)>,
    /// Any-hit result.
    pub any: bool,
}

/// The hooks run outside any render plan.
fn no_passes() -> crate::render::RenderPlan {
    crate::render::RenderPlan { passes: vec![] }
}

fn dummy_camera() -> crate::scene::camera::Camera {
    use glam::DVec3;
    crate::scene::camera::Camera {
        position: DVec3::Z,
        look_at: DVec3::ZERO,
        up: DVec3::Y,
        projection: crate::scene::camera::Projection::Orthographic { width: 1.0 },
    }
}

impl GpuBackend {
    /// Runs a one-dimensional test-hook kernel over `groups` workgroups with `rays` bound as the
    /// hooks' probe rays.
    fn run_hook(
        &mut self,
        probe: bool,
        r: &super::FrameResources,
        rays: &[[f32; 4]],
        groups: u32,
    ) -> anyhow::Result<()> {
        let one = [[0f32; 4]];
        let buffer = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("probe rays"),
            contents: bytemuck::cast_slice(if rays.is_empty() { &one[..] } else { rays }),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let hook = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("test hooks"),
            layout: &self.layouts.hooks,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: buffer.as_entire_binding(),
            }],
        });
        let (dump, trace) = self
            .pipelines
            .hooks(&self.device, &self.layouts, r.accel, super::CUT_SHORT_SLOT);
        let pipeline = if probe { trace } else { dump };
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        {
            let mut cp = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: None,
                timestamp_writes: None,
            });
            cp.set_pipeline(pipeline);
            cp.set_bind_group(0, &r.bind0, &[]);
            cp.set_bind_group(1, &r.passes[0][0], &[]);
            cp.set_bind_group(2, &r.accel_group, &[]);
            cp.set_bind_group(3, &hook, &[]);
            cp.dispatch_workgroups(groups, 1, 1);
        }
        self.submit(encoder, scope)
    }

    /// Unit-disk points of `scheme` for pixel `pixel` (index of a notional image 64 wide, light
    /// 0) with `seed`, computed by the WGSL sampler: lets tests compare it with the Rust one
    /// ([`DiskScheme::point`] at [`crate::sampling::Site::pixel`]).
    pub fn disk_points(&mut self, scheme: DiskScheme, n: u32, seed: u32, pixel: u32) -> anyhow::Result<Vec<[f32; 2]>> {
        self.disk_points_at(scheme, n, seed, pixel, 0)
    }

    /// [`GpuBackend::disk_points`] in frame `frame` of a temporal sequence ([`Sampling::frame`]).
    pub fn disk_points_at(
        &mut self,
        scheme: DiskScheme,
        n: u32,
        seed: u32,
        pixel: u32,
        frame: u32,
    ) -> anyhow::Result<Vec<[f32; 2]>> {
        self.sample_disk(scheme.gpu_id(), Some(scheme), n, seed, pixel, frame)
    }

    /// [`GpuBackend::disk_points`] for a raw scheme id, known or not (an unknown id must give
    /// NaN points, never another scheme's).
    pub fn disk_points_of_id(&mut self, id: u32, n: u32, seed: u32, pixel: u32) -> anyhow::Result<Vec<[f32; 2]>> {
        self.sample_disk(id, DiskScheme::ALL.get(id as usize).copied(), n, seed, pixel, 0)
    }

    /// Runs the sampler hook for scheme id `id` in frame `frame`, with the tables of `scheme`
    /// where known.
    fn sample_disk(
        &mut self,
        id: u32,
        scheme: Option<DiskScheme>,
        n: u32,
        seed: u32,
        pixel: u32,
        frame: u32,
    ) -> anyhow::Result<Vec<[f32; 2]>> {
        let scene = crate::scene::Scene::analytic(vec![], vec![], vec![]);
        let cam = dummy_camera();
        let view = View {
            camera: &cam,
            width: n,
            height: 1,
        };
        let sampling = Sampling {
            scheme: DiskScheme::Uniform,
            pattern: crate::sampling::Pattern::PerPixel,
            seed,
            frame,
        };
        let mut packed = pack(&scene, view, sampling)?;
        packed.params.scheme = id;
        packed.params.height = pixel;
        if let Some(scheme) = scheme {
            packed.tables = crate::sampling::tables::pack(&[(scheme, n)]);
        }
        let r = self.resources(&packed, View { height: 2, ..view }, &no_passes(), 0)?;
        self.run_hook(false, &r, &[], n.div_ceil(64))?;
        let raw: Vec<f32> = bytemuck::pod_collect_to_vec(&self.read(&r.visibility, n as u64 * 8)?);
        Ok(raw.chunks(2).map(|c| [c[0], c[1]]).collect())
    }

    /// Traces `rays` against the scene's acceleration structure with its WGSL closest-hit and
    /// any-hit queries, in the same local frame as a render: lets tests compare the GPU's
    /// traversal with the CPU's and with brute force.
    pub fn probe(&mut self, scene: &crate::scene::Scene, rays: &[ProbeRay]) -> anyhow::Result<Vec<ProbeHit>> {
        let cam = scene.cameras.values().next().cloned().unwrap_or_else(dummy_camera);
        let view = View {
            camera: &cam,
            width: rays.len() as u32,
            height: 1,
        };
        let sampling = Sampling {
            scheme: DiskScheme::Uniform,
            pattern: crate::sampling::Pattern::PerPixel,
            seed: 0,
            frame: 0,
        };
        let mut packed = pack(scene, view, sampling)?;
        packed.params.width = rays.len() as u32;
        let frame = layout::local_frame(scene, view);
        let (origin, scale) = (frame.origin, frame.scale);
        let probes: Vec<[f32; 4]> = rays
            .iter()
            .flat_map(|(o, d, tmax)| {
                let lo = ((*o - origin) / scale).as_vec3();
                [
                    [lo.x, lo.y, lo.z, (tmax / scale).min(f32::MAX as f64) as f32],
                    [d.x as f32, d.y as f32, d.z as f32, 0.0],
                ]
            })
            .collect();
        let r = self.resources(&packed, view, &no_passes(), 3 * rays.len() as u64)?;
        self.run_hook(true, &r, &probes, (rays.len() as u32).div_ceil(64))?;
        let raw: Vec<f32> = bytemuck::pod_collect_to_vec(&self.read(&r.visibility, rays.len() as u64 * 12)?);
        Ok(raw
            .chunks(3)
            .map(|c| ProbeHit {
                closest: (c[0] >= 0.0).then(|| (c[0] as f64 * scale, c[1].to_bits())),
                any: c[2] > 0.0,
            })
            .collect())
    }
}
