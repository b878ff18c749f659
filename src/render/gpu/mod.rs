//! The wgpu compute backend: headless, on any adapter wgpu supports (Mesa's lavapipe in CI).
//!
//! Setup (adapter, device with the adapter's real limits, pipelines, the loop-cap probe) happens
//! once in [`GpuBackend::new`]; the scene's geometry is uploaded once and stays resident
//! ([`resources`]); each frame runs the plan's passes (primary, then one shadow pass per light
//! and the ambient-occlusion pass where the scene asks, each in one dispatch or, on adapters
//! that cap loop iterations, several) with a timestamp pair
//! around each pass when the adapter supports timestamp queries, and reads the outputs back.

mod denoise;
#[cfg(feature = "test-hooks")]
mod hooks;
mod layout;
pub mod loop_cap;
mod pipelines;
mod resources;
mod timing;

use super::plan::{Pass, RenderPlan, MAX_LIGHTS};
use super::{AdapterInfo, Backend, Frame, RayCounts, Sampling, Timing, View, NO_HIT};
use anyhow::{anyhow, bail, Context};
use layout::{pack, HIT_BYTES};
use pipelines::{Layouts, PipelineCache, NO_ACCEL};
use resources::{FrameResources, SceneBuffers};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

#[cfg(feature = "test-hooks")]
pub use hooks::{ProbeHit, ProbeRay};
pub use pipelines::scheme_prelude;

/// How long one frame may run before it is reported as a GPU timeout.
pub const FRAME_TIMEOUT: Duration = Duration::from_secs(300);

/// u32 words of the counters buffer: per light, shadow rays as (low, high) words; the count of
/// invocations whose loops were cut short; ambient-occlusion rays as (low, high) words.
pub(crate) const COUNTER_WORDS: usize = 2 * MAX_LIGHTS + 3;
/// Word of the counters buffer that counts invocations cut short (`cut_short` in render.wgsl).
const CUT_SHORT_SLOT: usize = 2 * MAX_LIGHTS;

/// What to install when no adapter is found, for the error message.
pub const NO_ADAPTER_HELP: &str = "no GPU adapter found; on Debian install the software Vulkan driver with \
     `apt-get install mesa-vulkan-drivers`, or run with the CPU backend (`--backend cpu`)";

/// The wgpu renderer.
pub struct GpuBackend {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: AdapterInfo,
    timestamps: bool,
    lost: Arc<AtomicBool>,
    layouts: Layouts,
    /// The plan's passes compiled per acceleration structure, on first use.
    pipelines: PipelineCache,
    /// Iterations after which the adapter leaves a loop, if it caps them ([`loop_cap`]).
    loop_cap: Option<u32>,
    /// The resident static scene data.
    scene: Option<SceneBuffers>,
    /// Times static scene data was uploaded.
    static_uploads: u64,
    /// Compute dispatches recorded so far (all passes, all frames).
    dispatches: std::cell::Cell<u64>,
    /// The reconstruction filters' pipelines, compiled on first use.
    denoise: Option<denoise::Pipelines>,
}

impl GpuBackend {
    /// Opens the first adapter wgpu finds (high-performance preferred, software allowed;
    /// `WGPU_BACKEND` narrows the graphics APIs tried).
    pub fn new() -> anyhow::Result<GpuBackend> {
        pollster::block_on(Self::open())
    }

    async fn open() -> anyhow::Result<GpuBackend> {
        // WGPU_BACKEND (e.g. `vulkan`, `gl`) restricts the APIs tried.
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle().with_env());
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                ..Default::default()
            })
            .await
            .map_err(|e| anyhow!("{NO_ADAPTER_HELP} ({e})"))?;
        let ai = adapter.get_info();
        let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let features = if timestamps {
            wgpu::Features::TIMESTAMP_QUERY
        } else {
            wgpu::Features::empty()
        };
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("penumbra"),
                required_features: features,
                required_limits: adapter.limits(),
                ..Default::default()
            })
            .await
            .context("requesting a device from the GPU adapter")?;
        let lost = Arc::new(AtomicBool::new(false));
        let flag = lost.clone();
        device.set_device_lost_callback(move |_, _| flag.store(true, Ordering::SeqCst));
        device.on_uncaptured_error(Arc::new(|e: wgpu::Error| tracing::error!("uncaptured GPU error: {e}")));
        let loop_cap = loop_cap::detect(&device, &queue).context("probing the adapter's loop limits")?;
        let layouts = Layouts::new(&device);
        let info = AdapterInfo {
            backend: "gpu".into(),
            name: ai.name.clone(),
            driver: format!("{} {}", ai.driver, ai.driver_info).trim().to_string(),
            api: format!("{:?}", ai.backend),
            loop_cap,
            threads: None,
        };
        Ok(GpuBackend {
            device,
            queue,
            info,
            timestamps,
            lost,
            layouts,
            pipelines: PipelineCache::default(),
            loop_cap,
            scene: None,
            static_uploads: 0,
            dispatches: Default::default(),
            denoise: None,
        })
    }

    /// Iterations after which this adapter leaves a loop, if the probe found a cap.
    pub fn loop_cap(&self) -> Option<u32> {
        self.loop_cap
    }

    /// Overrides the probe's finding (`None`: one dispatch per light whatever the adapter does).
    /// For experiments on the workaround itself: on a capped adapter it loses rays.
    pub fn set_loop_cap(&mut self, cap: Option<u32>) {
        self.loop_cap = cap;
    }

    /// How many times static scene data (geometry, BVH) has been uploaded.
    pub fn static_uploads(&self) -> u64 {
        self.static_uploads
    }

    /// What the capped chunk over the resident scene is divided by: doubled each time a frame
    /// came back cut short (1: never).
    pub fn chunk_divisor(&self) -> u32 {
        self.scene.as_ref().map_or(1, |s| s.chunk_divisor)
    }

    /// Checks every buffer a frame needs against the adapter's binding and buffer limits, naming
    /// the buffer and the excess.
    fn check_limits(&self, packed: &layout::Packed, view: View) -> anyhow::Result<()> {
        let limits = self.device.limits();
        let max = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        let mut buffers = vec![
            ("hit buffer", view.pixels() as u64 * HIT_BYTES),
            (
                "visibility buffer",
                (view.pixels() * packed.lights.len().max(1)) as u64 * 4,
            ),
            (
                "mesh triangle buffer",
                std::mem::size_of_val(packed.mesh_tris.as_slice()) as u64,
            ),
            ("ambient-occlusion buffer", view.pixels() as u64 * 8),
        ];
        if let Some((_, s)) = &packed.accel {
            buffers.extend(s.buffers.iter().map(|(label, b)| (*label, b.len() as u64)));
        }
        for (what, bytes) in buffers {
            if bytes > max {
                bail!(
                    "a {}x{} frame of this scene needs a {what} of {bytes} bytes, over this adapter's max_storage_buffer_binding_size / max_buffer_size of {max} bytes by {} bytes",
                    view.width,
                    view.height,
                    bytes - max
                );
            }
        }
        Ok(())
    }

    /// Records the plan's passes into `encoder`, in the plan's order: the primary pass, and for
    /// each shadow pass one dispatch per sample chunk of its light. Nothing outside the plan is
    /// dispatched.
    fn encode(&mut self, encoder: &mut wgpu::CommandEncoder, r: &FrameResources, view: View, plan: &RenderPlan) {
        let p = self.pipelines.get(&self.device, &self.layouts, r.accel, CUT_SHORT_SLOT);
        encoder.clear_buffer(&r.counters, 0, None);
        encoder.clear_buffer(&r.visibility, 0, None);
        encoder.clear_buffer(&r.ambient, 0, None);
        let groups = (view.width.div_ceil(8), view.height.div_ceil(8));
        for (index, pass) in plan.passes.iter().enumerate() {
            let timestamp_writes = r.queries.as_ref().map(|(set, _)| wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(2 * index as u32),
                end_of_pass_write_index: Some(2 * index as u32 + 1),
            });
            let mut cp = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: None,
                timestamp_writes,
            });
            // The primary pass ignores group 1; a shadow pass runs one dispatch per sample chunk.
            let (pipeline, chunks) = match pass {
                Pass::Primary { .. } => (&p.primary, &r.passes[0][..1]),
                Pass::Shadow { light, .. } => (&p.shadow, &r.passes[*light][..]),
                Pass::Ambient { .. } => (&p.ambient, &r.ambient_passes[..]),
                Pass::Direct { .. } | Pass::Mirror { .. } => unreachable!("refused before encoding"),
            };
            cp.set_pipeline(pipeline);
            cp.set_bind_group(0, &r.bind0, &[]);
            if r.accel != NO_ACCEL {
                cp.set_bind_group(2, &r.accel_group, &[]);
            }
            for chunk in chunks {
                cp.set_bind_group(1, chunk, &[]);
                cp.dispatch_workgroups(groups.0, groups.1, 1);
            }
            self.dispatches.set(self.dispatches.get() + chunks.len() as u64);
        }
    }

    /// Submits, waits with [`FRAME_TIMEOUT`], and turns validation errors, a lost device or a
    /// timeout into errors.
    fn submit(&self, encoder: wgpu::CommandEncoder, scope: wgpu::ErrorScopeGuard) -> anyhow::Result<()> {
        let index = self.queue.submit([encoder.finish()]);
        let polled = self.device.poll(wgpu::PollType::Wait {
            submission_index: Some(index),
            timeout: Some(FRAME_TIMEOUT),
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            bail!("GPU validation error: {e}");
        }
        if self.lost.load(Ordering::SeqCst) {
            bail!("the GPU device was lost during the frame");
        }
        polled.map_err(|e| anyhow!("GPU frame did not finish within {FRAME_TIMEOUT:?}: {e}"))?;
        Ok(())
    }

    fn read(&self, src: &wgpu::Buffer, size: u64) -> anyhow::Result<Vec<u8>> {
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(src, 0, &staging, 0, size);
        self.submit(encoder, self.device.push_error_scope(wgpu::ErrorFilter::Validation))?;
        let (tx, rx) = std::sync::mpsc::channel();
        staging.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: None,
                timeout: Some(FRAME_TIMEOUT),
            })
            .map_err(|e| anyhow!("mapping a GPU buffer: {e}"))?;
        rx.recv()?.map_err(|e| anyhow!("mapping a GPU buffer: {e}"))?;
        let bytes = staging
            .get_mapped_range(..)
            .map_err(|e| anyhow!("reading a GPU buffer: {e:?}"))?
            .to_vec();
        staging.unmap();
        Ok(bytes)
    }

    /// The counters buffer of the frame just rendered over `r` ([`COUNTER_WORDS`] words).
    fn counters(&self, r: &FrameResources) -> anyhow::Result<Vec<u32>> {
        Ok(bytemuck::pod_collect_to_vec(
            &self.read(&r.counters, COUNTER_WORDS as u64 * 4)?,
        ))
    }

    /// Whether a frame whose counters are `counters` is whole: no invocation reported a loop cut
    /// short. If some did, the capped chunk over this scene is halved for the next attempt
    /// (`Ok(false)`); where it is one sample already, or the adapter has no cap, no smaller split
    /// can help (a BVH deeper than the traversal stack) and the frame is an error, never a silent
    /// answer.
    fn whole(&mut self, counters: &[u32], packed: &layout::Packed) -> anyhow::Result<bool> {
        let cut = counters[CUT_SHORT_SLOT];
        if cut == 0 {
            return Ok(true);
        }
        let chunk = self.samples_per_dispatch(packed);
        match (&mut self.scene, self.loop_cap) {
            (Some(scene), Some(_)) if chunk > 1 => {
                scene.chunk_divisor *= 2;
                Ok(false)
            }
            _ => bail!(
                "{cut} GPU invocations ended a loop early (at {chunk} shadow sample(s) per dispatch, loop cap {:?}): a mesh walk longer than the adapter allows or a BVH deeper than the traversal stack; use the CPU backend for this scene",
                self.loop_cap
            ),
        }
    }
}

/// A part of a scene the GPU kernels cannot render: the pass (or material) and the scene-file
/// key that asks for it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GpuGap {
    /// The pass or material, in the words of the render plan.
    pub what: &'static str,
    /// The scene-file key that asks for it.
    pub key: String,
}

impl std::fmt::Display for GpuGap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "key `{}` asks for {}, which the GPU backend has no kernel for",
            self.key, self.what
        )
    }
}

/// What of `scene` the GPU has no kernel for, if anything. The GPU kernels cover the primary,
/// shadow and ambient passes over diffuse materials; OpenGL-like direct light (the `direct`
/// pass, where `[shading] shadows = false`), Whitted's mirror chains (the `mirror` pass) and
/// mirror materials (whose diffuse part is scaled by 1 - mirror) are the CPU backend's only. The
/// conditions are [`RenderPlan::new`]'s, read from the scene alone, so a run can choose its
/// backend before any frame.
pub fn gpu_gap(scene: &crate::scene::Scene) -> Option<GpuGap> {
    if !scene.shading.shadows && !scene.lights.is_empty() {
        return Some(GpuGap {
            what: "the direct pass (OpenGL-like shading without shadow rays)",
            key: "shading.shadows".into(),
        });
    }
    let mirror = scene.meshes().position(|m| m.mirror > 0.0)?;
    Some(if scene.shading.mirror_depth > 0 {
        GpuGap {
            what: "the mirror pass (Whitted's mirror chains)",
            key: "shading.mirror_depth".into(),
        }
    } else {
        GpuGap {
            what: "mirror materials",
            key: format!("meshes[{mirror}].mirror"),
        }
    })
}

/// Refuses a scene the GPU kernels cannot render ([`gpu_gap`]), never skipping what it asks for.
fn refuse_unsupported(scene: &crate::scene::Scene) -> anyhow::Result<()> {
    match gpu_gap(scene) {
        Some(gap) => bail!("{gap}; render this scene with backend = \"cpu\""),
        None => Ok(()),
    }
}

impl Backend for GpuBackend {
    fn adapter(&self) -> &AdapterInfo {
        &self.info
    }

    fn reconstruct(
        &mut self,
        filter: super::denoise::Filter,
        input: &super::denoise::Input,
    ) -> anyhow::Result<(super::denoise::Output, f64)> {
        self.filter(filter, input)
    }

    fn dispatches(&self) -> u64 {
        self.dispatches.get()
    }

    fn render(&mut self, scene: &crate::scene::Scene, view: View, sampling: Sampling) -> anyhow::Result<Frame> {
        let plan = RenderPlan::new(scene, view)?;
        refuse_unsupported(scene)?;
        let packed = pack(scene, view, sampling)?;
        self.check_limits(&packed, view)?;
        let lights = scene.lights.len();
        let (r, counters) = loop {
            let r = self.resources(&packed, view, 0)?;
            let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
            let mut encoder = self.device.create_command_encoder(&Default::default());
            self.encode(&mut encoder, &r, view, &plan);
            self.submit(encoder, scope)?;
            let counters = self.counters(&r)?;
            if self.whole(&counters, &packed)? {
                break (r, counters);
            }
        };
        let pixels = view.pixels();
        let hits: Vec<u32> = bytemuck::pod_collect_to_vec(&self.read(&r.hits, pixels as u64 * HIT_BYTES)?);
        let vis: Vec<f32> = if lights > 0 {
            bytemuck::pod_collect_to_vec(&self.read(&r.visibility, (pixels * lights) as u64 * 4)?)
        } else {
            vec![]
        };
        let radiance: Vec<f32> = bytemuck::pod_collect_to_vec(&self.read(&r.radiance, pixels as u64 * 4)?);
        let mut rays = RayCounts {
            primary: pixels as u64,
            shadow: [0; MAX_LIGHTS],
            ambient: 0,
            reflection: 0,
        };
        for (i, s) in rays.shadow.iter_mut().enumerate() {
            *s = counters[2 * i] as u64 | ((counters[2 * i + 1] as u64) << 32);
        }
        let hit: Vec<u32> = hits.chunks((HIT_BYTES / 4) as usize).map(|h| h[3]).collect();
        let ambient = match scene.ambient {
            Some(_) => {
                rays.ambient = counters[CUT_SHORT_SLOT + 1] as u64 | ((counters[CUT_SHORT_SLOT + 2] as u64) << 32);
                let sums: Vec<f32> = bytemuck::pod_collect_to_vec(&self.read(&r.ambient, pixels as u64 * 8)?);
                Some(
                    sums.chunks(2)
                        .zip(&hit)
                        .map(|(s, &h)| match h {
                            NO_HIT => super::NO_RECEIVER,
                            _ if s[1] > 0.0 => s[0] / s[1],
                            _ => 1.0,
                        })
                        .collect(),
                )
            }
            None => None,
        };
        Ok(Frame {
            width: view.width,
            height: view.height,
            radiance,
            visibility: vis.chunks(pixels.max(1)).map(<[f32]>::to_vec).collect(),
            hit,
            ambient,
            rays,
            work: crate::accel::work::Work::ZERO,
            counted: false,
        })
    }

    fn time(
        &mut self,
        scene: &crate::scene::Scene,
        view: View,
        sampling: Sampling,
        warmup: u32,
        repeats: u32,
    ) -> anyhow::Result<Timing> {
        let plan = RenderPlan::new(scene, view)?;
        refuse_unsupported(scene)?;
        let packed = pack(scene, view, sampling)?;
        self.check_limits(&packed, view)?;
        loop {
            let r = self.resources(&packed, view, 0)?;
            let timing = self.time_frames(&r, view, &plan, warmup, repeats)?;
            if self.whole(&self.counters(&r)?, &packed)? {
                return Ok(timing);
            }
        }
    }
}
