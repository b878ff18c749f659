//! Whether the adapter caps the iterations a loop may run per invocation. Mesa 22.3's llvmpipe
//! (lavapipe) stops a loop after 65535 iterations, counting an inner loop's iterations across
//! every pass of the loop around it, and then quietly leaves the loop for the whole SIMD row: a
//! 1024-ray shadow loop over a BVH lost about half its rays. Where the probe finds such a cap the
//! renderer splits each shadow pass into dispatches of few samples; elsewhere one dispatch runs
//! a light's samples.

use anyhow::{anyhow, Context};
use wgpu::util::DeviceExt;

/// Iterations the probe asks for: far above any cap seen, small enough to take microseconds.
pub const PROBE_ITERATIONS: (u32, u32) = (500, 400);

/// Runs the probe kernel; `Some(iterations reached)` when the adapter stopped short.
pub fn detect(device: &wgpu::Device, queue: &wgpu::Queue) -> anyhow::Result<Option<u32>> {
    let module = device.create_shader_module(wgpu::include_wgsl!("shaders/loop_probe.wgsl"));
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("loop probe"),
        layout: None,
        module: &module,
        entry_point: Some("count_iterations"),
        compilation_options: Default::default(),
        cache: None,
    });
    let (outer, inner) = PROBE_ITERATIONS;
    let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("loop probe"),
        contents: bytemuck::cast_slice(&[outer, inner, 0u32, 0u32]),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    });
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("loop probe readback"),
        size: 16,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("loop probe"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: buffer.as_entire_binding(),
        }],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(1, 1, 1);
    }
    encoder.copy_buffer_to_buffer(&buffer, 0, &staging, 0, 16);
    queue.submit([encoder.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    staging.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::Wait {
            submission_index: None,
            timeout: Some(super::FRAME_TIMEOUT),
        })
        .map_err(|e| anyhow!("the loop probe did not finish: {e}"))?;
    rx.recv()?.map_err(|e| anyhow!("reading the loop probe: {e}"))?;
    let words: Vec<u32> = bytemuck::pod_collect_to_vec(
        &staging
            .get_mapped_range(..)
            .map_err(|e| anyhow!("reading the loop probe: {e:?}"))
            .context("loop probe")?,
    );
    let reached = words[2];
    Ok((reached < outer * inner).then_some(reached))
}
