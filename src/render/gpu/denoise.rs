//! The reconstruction filters on the GPU (`shaders/denoise.wgsl`): one pipeline per filter,
//! compiled on first use; a filter's inputs are uploaded, its pass timed by timestamp queries
//! where the adapter has them (as frames are), else on the wall clock around submit and wait
//! (uploads and the read-back outside the time either way), its image read back.

use super::GpuBackend;
use crate::render::denoise::{Filter, Input, Output, DIRECTIONLESS, DIRECTION_SIGMA, LUMINANCE_EPSILON, MIN_SIGMA};
use bytemuck::{Pod, Zeroable};
use std::time::Instant;
use wgpu::util::DeviceExt;

/// The kernels' uniform block (`Params` in denoise.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
struct Params {
    width: u32,
    height: u32,
    step: u32,
    _pad: u32,
    gaussian_sigma: f32,
    sigma_luminance: f32,
    sigma_depth: f32,
    sigma_normal: f32,
    min_sigma: f32,
    luminance_epsilon: f32,
    directionless: f32,
    direction_sigma: f32,
}
const _: () = assert!(std::mem::size_of::<Params>() == 48);

/// The filters' layout and pipelines.
pub(super) struct Pipelines {
    layout: wgpu::BindGroupLayout,
    gaussian: wgpu::ComputePipeline,
    penumbra: wgpu::ComputePipeline,
    atrous: wgpu::ComputePipeline,
}

impl Pipelines {
    pub(super) fn new(device: &wgpu::Device) -> Pipelines {
        let entry = |binding: u32, ty: wgpu::BufferBindingType| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let read = wgpu::BufferBindingType::Storage { read_only: true };
        let write = wgpu::BufferBindingType::Storage { read_only: false };
        let mut entries = vec![entry(0, wgpu::BufferBindingType::Uniform)];
        entries.extend((1..=5).map(|b| entry(b, read)));
        entries.extend((6..=7).map(|b| entry(b, write)));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("denoise"),
            entries: &entries,
        });
        let module = device.create_shader_module(wgpu::include_wgsl!("shaders/denoise.wgsl"));
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("denoise"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        Pipelines {
            gaussian: pipeline("gaussian"),
            penumbra: pipeline("penumbra"),
            atrous: pipeline("atrous"),
            layout,
        }
    }
}

impl GpuBackend {
    /// Runs `filter` on `input` in WGSL: the image and the seconds its dispatches took.
    pub(super) fn filter(&mut self, filter: Filter, input: &Input) -> anyhow::Result<(Output, f64)> {
        if filter == Filter::None {
            return Ok((
                Output {
                    image: input.image.to_vec(),
                    taps: 0,
                },
                0.0,
            ));
        }
        if self.denoise.is_none() {
            self.denoise = Some(Pipelines::new(&self.device));
        }
        let pixels = input.pixels() as u64;
        let s = input.settings;
        let params = |step: u32| Params {
            width: input.width,
            height: input.height,
            step,
            _pad: 0,
            gaussian_sigma: s.gaussian_sigma as f32,
            sigma_luminance: s.atrous_sigma_luminance as f32,
            sigma_depth: s.atrous_sigma_depth as f32,
            sigma_normal: s.atrous_sigma_normal as f32,
            min_sigma: MIN_SIGMA as f32,
            luminance_epsilon: LUMINANCE_EPSILON as f32,
            directionless: DIRECTIONLESS as f32,
            direction_sigma: DIRECTION_SIGMA as f32,
        };
        let normals: Vec<[f32; 4]> = input.gbuffer.normal.iter().map(|n| [n[0], n[1], n[2], 0.0]).collect();
        let depth = self.storage("depth", &input.gbuffer.depth, 0.0);
        let normal = self.storage("normal", &normals, [0.0; 4]);
        let sigma = self.storage("sigma", input.sigma, 0.0);
        // Ping-pong pairs (image, variance): the input, then two outputs the iterations swap.
        let image_in = self.storage("image", input.image, 0.0);
        let variance_in = self.storage("variance", input.variance, 0.0);
        let outputs = [
            (
                self.output("image a", pixels * 4),
                self.output("variance a", pixels * 4),
            ),
            (
                self.output("image b", pixels * 4),
                self.output("variance b", pixels * 4),
            ),
        ];
        let (pipeline, steps): (&wgpu::ComputePipeline, Vec<u32>) = {
            let p = self.denoise.as_ref().expect("compiled above");
            match filter {
                Filter::Gaussian => (&p.gaussian, vec![1]),
                Filter::Penumbra => (&p.penumbra, vec![1]),
                Filter::Atrous => (&p.atrous, (0..s.atrous_iterations).map(|k| 1 << k).collect()),
                Filter::None => unreachable!("returned above"),
            }
        };
        let layout = &self.denoise.as_ref().expect("compiled above").layout;
        let groups: Vec<wgpu::BindGroup> = steps
            .iter()
            .enumerate()
            .map(|(k, &step)| {
                let uniform = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("denoise params"),
                    contents: bytemuck::bytes_of(&params(step)),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
                let (src_image, src_variance) = match k {
                    0 => (&image_in, &variance_in),
                    _ => (&outputs[(k - 1) % 2].0, &outputs[(k - 1) % 2].1),
                };
                let dst = &outputs[k % 2];
                let buffers = [
                    &uniform,
                    src_image,
                    src_variance,
                    &depth,
                    &normal,
                    &sigma,
                    &dst.0,
                    &dst.1,
                ];
                let entries: Vec<wgpu::BindGroupEntry> = buffers
                    .iter()
                    .enumerate()
                    .map(|(b, buf)| wgpu::BindGroupEntry {
                        binding: b as u32,
                        resource: buf.as_entire_binding(),
                    })
                    .collect();
                self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("denoise"),
                    layout,
                    entries: &entries,
                })
            })
            .collect();
        // Timestamps around the filter's pass where the adapter has them: the clock its renders
        // are timed by, so a pipeline's render and filter add up.
        let queries = self.timestamps.then(|| {
            let set = self.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("denoise timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            });
            let resolve = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("denoise timestamp resolve"),
                size: 16,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            (set, resolve)
        });
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        {
            let timestamp_writes = queries.as_ref().map(|(set, _)| wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(0),
                end_of_pass_write_index: Some(1),
            });
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("denoise"),
                timestamp_writes,
            });
            pass.set_pipeline(pipeline);
            for g in &groups {
                pass.set_bind_group(0, g, &[]);
                pass.dispatch_workgroups(input.width.div_ceil(8), input.height.div_ceil(8), 1);
            }
        }
        self.dispatches.set(self.dispatches.get() + groups.len() as u64);
        if let Some((set, resolve)) = &queries {
            encoder.resolve_query_set(set, 0..2, resolve, 0);
        }
        let start = Instant::now();
        self.submit(encoder, scope)?;
        let mut seconds = start.elapsed().as_secs_f64();
        if let Some((_, resolve)) = &queries {
            let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&self.read(resolve, 16)?);
            let period = self.queue.get_timestamp_period() as f64;
            seconds = ticks[1].saturating_sub(ticks[0]) as f64 * period * 1e-9;
        }
        let last = &outputs[(groups.len() - 1) % 2].0;
        let image: Vec<f32> = bytemuck::pod_collect_to_vec(&self.read(last, pixels * 4)?);
        Ok((
            Output {
                image,
                taps: input.taps(filter),
            },
            seconds,
        ))
    }
}
