//! The wgpu compute backend: headless, on any adapter wgpu supports (Mesa's lavapipe in CI).
//!
//! Setup (adapter, device with the adapter's real limits, pipelines, the loop-cap probe) happens
//! once in [`GpuBackend::new`]; the scene's geometry is uploaded once and stays resident
//! ([`resources`]); each frame runs the plan's passes (primary; one shadow pass per light, or
//! the direct pass over every light where the scene has no shadows; Whitted's mirror chains, per
//! bounce a trace, the lights' chunks and a step; the ambient-occlusion pass where the scene
//! asks; each in one dispatch per step or, on adapters that cap loop iterations, per chunk) with
//! a timestamp pair around each pass when the adapter supports timestamp queries, and reads the
//! outputs back. Where switched on
//! ([`Backend::count_work`]), frames read back count their work (queries, nodes, primitive tests)
//! in atomics the kernels add to once per invocation; timed frames never count.

mod denoise;
#[cfg(feature = "test-hooks")]
mod hooks;
mod layout;
pub mod loop_cap;
mod pipelines;
mod resources;
mod timing;

use super::limit::{DeviceLimit, Part};
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
/// invocations whose loops were cut short; then as (low, high) words ambient-occlusion rays,
/// reflection rays, and the work of frames that count it (queries, nodes, primitive tests); the
/// count of reflected rays whose closest-hit walk was cut short (no smaller chunk helps those);
/// the mirror chains still live after a bounce (the gate's, reset as it reads them) and the
/// bounces after the first that the gate let run.
pub(crate) const COUNTER_WORDS: usize = 2 * MAX_LIGHTS + 14;
/// Word of the counters buffer that counts invocations cut short (`cut_short` in render.wgsl).
const CUT_SHORT_SLOT: usize = 2 * MAX_LIGHTS;
/// Word of the counters buffer that counts the mirror bounces after the first that ran.
const MIRROR_BOUNCES_SLOT: usize = CUT_SHORT_SLOT + 13;

/// The 64-bit counter at words (`slot`, `slot + 1`) of a counters read-back.
fn wide(counters: &[u32], slot: usize) -> u64 {
    counters[slot] as u64 | ((counters[slot + 1] as u64) << 32)
}

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
    /// Whether frames read back count their work ([`Backend::count_work`]).
    count_work: bool,
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
            count_work: false,
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

    /// Checks every buffer a frame of `scene` needs against the adapter's binding and buffer
    /// limits, naming the buffer and the excess (and for the meshes' buffer, the meshes: no kind
    /// has one key for them to be located at).
    fn check_limits(
        &self,
        scene: &crate::scene::Scene,
        packed: &layout::Packed,
        view: View,
        plan: &RenderPlan,
    ) -> anyhow::Result<()> {
        let limits = self.device.limits();
        let structure = packed.accel.as_ref().map(|(name, s)| (*name, s.buffers.len() as u32));
        storage_buffers_fit(
            self.layouts.frame_storage,
            structure,
            limits.max_storage_buffers_per_shader_stage,
        )?;
        let max =
            crate::render::limit::binding_bytes(limits.max_storage_buffer_binding_size.min(limits.max_buffer_size));
        let lights = packed.lights.len().max(1) as u64;
        let pixels = view.pixels() as u64;
        let frame = Part::Frame {
            width: view.width,
            height: view.height,
        };
        let mut buffers = vec![
            (frame, "hit buffer", pixels * HIT_BYTES),
            (frame, "visibility buffer", pixels * lights * 4),
            (frame, "light sums buffer", pixels * lights * 4),
            (
                Part::Scene,
                "mesh triangle buffer",
                std::mem::size_of_val(packed.mesh_tris.as_slice()) as u64,
            ),
            (frame, "ambient-occlusion buffer", pixels * 8),
        ];
        if plan.passes.iter().any(|p| matches!(p, Pass::Mirror { .. })) {
            buffers.push((frame, "mirror chain buffer", pixels * layout::CHAIN_BYTES));
        }
        if let Some((name, s)) = &packed.accel {
            buffers.extend(
                s.buffers
                    .iter()
                    .map(|(label, b)| (Part::Structure(name), *label, b.len() as u64)),
            );
        }
        for (part, what, bytes) in buffers {
            if bytes > max {
                let by = bytes - max;
                let message = match part {
                    Part::Frame { .. } => format!(
                        "a {}x{} frame of this scene needs a {what} of {bytes} bytes, over this adapter's binding limit (max_storage_buffer_binding_size / max_buffer_size) of {max} bytes by {by} bytes; render a smaller frame",
                        view.width, view.height
                    ),
                    Part::Scene => {
                        let mut meshes: Vec<&str> = scene.meshes().map(|m| m.source.as_str()).collect();
                        meshes.dedup();
                        format!(
                            "this scene's meshes ({}) need a {what} of {bytes} bytes on the GPU, over this adapter's binding limit (max_storage_buffer_binding_size / max_buffer_size) of {max} bytes by {by} bytes; use fewer triangles",
                            meshes.join(", ")
                        )
                    }
                    Part::Structure(name) => format!(
                        "`{name}` needs a {what} of {bytes} bytes, over this adapter's binding limit (max_storage_buffer_binding_size / max_buffer_size) of {max} bytes by {by} bytes"
                    ),
                };
                return Err(DeviceLimit::new(part, message).into());
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
        encoder.clear_buffer(&r.light_sums, 0, None);
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
            // The primary pass ignores group 1; a shadow pass runs one dispatch per sample chunk;
            // the direct pass runs the shadow kernel (without occlusion tests) over every light's
            // chunks; the mirror pass, per bounce, a trace, every light's chunks and a step, then
            // its finish (each dispatch sees the previous one's writes). Bounces after the first
            // take their workgroups from the gate run after the bounce before: none once every
            // chain has ended.
            let every_light = || r.passes.iter().flatten();
            let frame = |pipeline, info| Dispatch::Frame(pipeline, info);
            let steps: Vec<Dispatch> = match pass {
                Pass::Primary { .. } => vec![frame(&p.primary, &r.passes[0][0])],
                Pass::Shadow { light, .. } => r.passes[*light].iter().map(|c| frame(&p.shadow, c)).collect(),
                Pass::Direct { .. } => every_light().map(|c| frame(&p.shadow, c)).collect(),
                Pass::Mirror { .. } => {
                    let m = &p.mirror;
                    let (gate, args) = r.mirror_gate.as_ref().expect("made with the mirror pass");
                    let mut steps = Vec::new();
                    for (bounce, info) in r.mirror_passes.iter().enumerate() {
                        let run = |pipeline, group| match bounce {
                            0 => Dispatch::Frame(pipeline, group),
                            _ => Dispatch::Indirect(pipeline, group, args),
                        };
                        if bounce > 0 {
                            steps.push(Dispatch::Gate(&m.gate, gate));
                        }
                        steps.push(run(&m.trace, info));
                        steps.extend(every_light().map(|c| run(&m.shade, c)));
                        steps.push(run(&m.step, info));
                    }
                    steps.push(frame(&m.finish, &r.passes[0][0]));
                    steps
                }
                Pass::Ambient { .. } => r.ambient_passes.iter().map(|c| frame(&p.ambient, c)).collect(),
            };
            let bind_frame = |cp: &mut wgpu::ComputePass| {
                cp.set_bind_group(0, &r.bind0, &[]);
                if r.accel != NO_ACCEL {
                    cp.set_bind_group(2, &r.accel_group, &[]);
                }
            };
            bind_frame(&mut cp);
            for (i, step) in steps.iter().enumerate() {
                match *step {
                    Dispatch::Frame(pipeline, info) => {
                        cp.set_pipeline(pipeline);
                        cp.set_bind_group(1, info, &[]);
                        cp.dispatch_workgroups(groups.0, groups.1, 1);
                    }
                    Dispatch::Indirect(pipeline, info, args) => {
                        cp.set_pipeline(pipeline);
                        cp.set_bind_group(1, info, &[]);
                        cp.dispatch_workgroups_indirect(args, 0);
                    }
                    Dispatch::Gate(pipeline, group) => {
                        cp.set_pipeline(pipeline);
                        cp.set_bind_group(0, group, &[]);
                        cp.dispatch_workgroups(1, 1, 1);
                        if i + 1 < steps.len() {
                            bind_frame(&mut cp);
                        }
                    }
                }
            }
            self.dispatches.set(self.dispatches.get() + steps.len() as u64);
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
        let walks = counters[CUT_SHORT_SLOT + 11];
        if walks > 0 {
            bail!(
                "{walks} GPU invocations of the mirror pass ended a reflected ray's closest-hit walk early: one query runs past this adapter's loop cap {:?} (or a BVH is deeper than the traversal stack), which no split of the pass can help; use the CPU backend for this scene",
                self.loop_cap
            );
        }
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

/// One dispatch of a pass: a render kernel over the whole frame, a render kernel over the
/// workgroups the mirror gate wrote, or the mirror gate itself (its own group 0).
enum Dispatch<'a> {
    Frame(&'a wgpu::ComputePipeline, &'a wgpu::BindGroup),
    Indirect(&'a wgpu::ComputePipeline, &'a wgpu::BindGroup, &'a wgpu::Buffer),
    Gate(&'a wgpu::ComputePipeline, &'a wgpu::BindGroup),
}

/// Whether the kernels' storage buffers (the frame layout's `frame` and structure `(name,
/// buffers)`'s) fit the adapter's per-stage limit, else an error naming both counts: a
/// compute-only fallback (wgpu's GL backend offers 8-16) cannot bind the visibility field's nine.
fn storage_buffers_fit(frame: u32, structure: Option<(&str, u32)>, limit: u32) -> anyhow::Result<()> {
    let (name, own) = structure.unwrap_or(("no structure", 0));
    let needed = frame + own;
    anyhow::ensure!(
        needed <= limit,
        "the render kernels bind {needed} storage buffers ({frame} per frame, {own} of `{name}`); this adapter allows {limit} per shader stage"
    );
    Ok(())
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

    fn count_work(&mut self, on: bool) {
        self.count_work = on;
    }

    fn render(&mut self, scene: &crate::scene::Scene, view: View, sampling: Sampling) -> anyhow::Result<Frame> {
        let plan = RenderPlan::new(scene, view)?;
        let mut packed = pack(scene, view, sampling)?;
        packed.params.stats = self.count_work as u32;
        self.check_limits(scene, &packed, view, &plan)?;
        let lights = scene.lights.len();
        let (r, counters) = loop {
            let r = self.resources(&packed, view, &plan, 0)?;
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
            reflection: wide(&counters, CUT_SHORT_SLOT + 3),
        };
        for (i, s) in rays.shadow.iter_mut().enumerate() {
            *s = wide(&counters, 2 * i);
        }
        let hit: Vec<u32> = hits.chunks((HIT_BYTES / 4) as usize).map(|h| h[3]).collect();
        let ambient = match scene.ambient {
            Some(_) => {
                rays.ambient = wide(&counters, CUT_SHORT_SLOT + 1);
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
            work: crate::accel::work::Work {
                queries: wide(&counters, CUT_SHORT_SLOT + 5),
                nodes: wide(&counters, CUT_SHORT_SLOT + 7),
                primitives: wide(&counters, CUT_SHORT_SLOT + 9),
            },
            counted: self.count_work,
            mirror_bounces: match plan.passes.iter().any(|p| matches!(p, Pass::Mirror { .. })) {
                true => 1 + counters[MIRROR_BOUNCES_SLOT],
                false => 0,
            },
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
        let packed = pack(scene, view, sampling)?;
        self.check_limits(scene, &packed, view, &plan)?;
        loop {
            let r = self.resources(&packed, view, &plan, 0)?;
            let timing = self.time_frames(&r, view, &plan, warmup, repeats)?;
            if self.whole(&self.counters(&r)?, &packed)? {
                return Ok(timing);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn storage_buffers_beyond_the_adapters_limit_are_refused_with_both_counts() {
        assert!(storage_buffers_fit(14, Some(("vlf", 9)), 23).is_ok());
        let e = storage_buffers_fit(14, Some(("vlf", 9)), 16).unwrap_err().to_string();
        assert!(
            e.contains("23 storage buffers") && e.contains("9 of `vlf`") && e.contains("allows 16"),
            "{e}"
        );
        assert!(storage_buffers_fit(14, None, 14).is_ok());
        assert!(storage_buffers_fit(14, None, 13).is_err());
    }
}
