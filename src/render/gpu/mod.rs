//! The wgpu compute backend: headless, on any adapter wgpu supports (Mesa's lavapipe in CI).
//!
//! Setup (adapter, device with the adapter's real limits, pipelines) happens once in
//! [`GpuBackend::new`]; each frame uploads the packed scene, runs the plan's passes (primary,
//! then one shadow pass per light, split into dispatches of at most
//! `layout::samples_per_dispatch` samples) with a timestamp pair around each pass when the
//! adapter supports timestamp queries, and reads the outputs back.

mod layout;

use super::plan::{RenderPlan, MAX_LIGHTS};
use super::{AdapterInfo, Backend, Clock, Frame, RayCounts, Sampling, Timing, View};
use crate::sampling::DiskScheme;
use anyhow::{anyhow, bail, Context};
use bytemuck::{Pod, Zeroable};
use layout::{pack, GpuLight, Packed, PassInfo, HIT_BYTES};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use wgpu::util::DeviceExt;

/// How long one frame may run before it is reported as a GPU timeout.
pub const FRAME_TIMEOUT: Duration = Duration::from_secs(300);

const SHADER: &str = concat!(
    include_str!("shaders/sampling.wgsl"),
    include_str!("shaders/geometry.wgsl"),
    include_str!("shaders/bvh.wgsl"),
    include_str!("shaders/render.wgsl"),
);

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
    layout0: wgpu::BindGroupLayout,
    layout1: wgpu::BindGroupLayout,
    /// The plan's passes, compiled with (`[1]`) and without (`[0]`) mesh traversal: a scene
    /// without meshes runs shaders in which the BVH walks are constant-folded away.
    primary: [wgpu::ComputePipeline; 2],
    shadow: [wgpu::ComputePipeline; 2],
    dump: wgpu::ComputePipeline,
    probe: wgpu::ComputePipeline,
}

/// Per-frame GPU resources.
struct FrameResources {
    bind0: wgpu::BindGroup,
    /// Per light, one bind group per dispatch of its samples.
    passes: Vec<Vec<wgpu::BindGroup>>,
    hits: wgpu::Buffer,
    visibility: wgpu::Buffer,
    radiance: wgpu::Buffer,
    counters: wgpu::Buffer,
    queries: Option<(wgpu::QuerySet, wgpu::Buffer)>,
    /// Whether the scene has meshes (selects the pipeline variant).
    meshes: bool,
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
        device.on_uncaptured_error(Arc::new(|e: wgpu::Error| {
            eprintln!("penumbra: uncaptured GPU error: {e}")
        }));
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("render.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let storage = |binding: u32, read_only: bool| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let uniform = |binding: u32| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let mut entries = vec![uniform(0)];
        entries.extend((1..=4).map(|b| storage(b, true)));
        entries.extend((5..=8).map(|b| storage(b, false)));
        entries.extend((9..=11).map(|b| storage(b, true)));
        let layout0 = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame"),
            entries: &entries,
        });
        let layout1 = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pass"),
            entries: &[uniform(0)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("render"),
            bind_group_layouts: &[Some(&layout0), Some(&layout1)],
            immediate_size: 0,
        });
        let variant = |entry: &str, meshes: bool| {
            let constants = [("MESHES", if meshes { 1.0 } else { 0.0 })];
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    ..Default::default()
                },
                cache: None,
            })
        };
        let pipeline = |entry: &str| variant(entry, true);
        let (primary, shadow, dump, probe) = (
            [variant("primary", false), variant("primary", true)],
            [variant("shadow", false), variant("shadow", true)],
            pipeline("dump_samples"),
            pipeline("trace_probes"),
        );
        let info = AdapterInfo {
            backend: "gpu".into(),
            name: ai.name.clone(),
            driver: format!("{} {}", ai.driver, ai.driver_info).trim().to_string(),
            api: format!("{:?}", ai.backend),
        };
        Ok(GpuBackend {
            device,
            queue,
            info,
            timestamps,
            lost,
            layout0,
            layout1,
            primary,
            shadow,
            dump,
            probe,
        })
    }

    fn storage<T: Pod>(&self, label: &str, data: &[T], zeroed: T) -> wgpu::Buffer {
        // WGSL runtime-sized arrays need a non-empty binding.
        let one = [zeroed];
        let data: &[T] = if data.is_empty() { &one } else { data };
        self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytemuck::cast_slice(data),
            usage: wgpu::BufferUsages::STORAGE,
        })
    }

    fn output(&self, label: &str, size: u64) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(16),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    fn check_limits(&self, scene: &crate::scene::Scene, view: View) -> anyhow::Result<()> {
        let lights = scene.lights.len();
        if let Some(b) = scene.bvh.as_ref().filter(|b| b.depth > 2 * 31) {
            bail!(
                "the BVH is {} levels deep; the GPU traversal stack holds 64 entries (depth 62 at most)",
                b.depth
            );
        }
        let limits = self.device.limits();
        let max = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        let (nodes, triangles) = scene
            .bvh
            .as_ref()
            .map_or((0, 0), |b| (b.node_count(), b.tree.primitive_indices.len()));
        for (what, bytes) in [
            ("hit buffer", view.pixels() as u64 * HIT_BYTES),
            ("visibility buffer", (view.pixels() * lights.max(1)) as u64 * 4),
            (
                "BVH node buffer",
                (nodes * std::mem::size_of::<layout::GpuNode>()) as u64,
            ),
            (
                "triangle buffer",
                (triangles * std::mem::size_of::<layout::GpuTri>()) as u64,
            ),
        ] {
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

    fn resources(&self, packed: &Packed, view: View, probes: &[[f32; 4]]) -> FrameResources {
        let params = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("params"),
            contents: bytemuck::bytes_of(&packed.params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let spheres = self.storage("spheres", &packed.spheres, bytemuck::Zeroable::zeroed());
        let planes = self.storage("planes", &packed.planes, bytemuck::Zeroable::zeroed());
        let lights = self.storage("lights", &packed.lights, bytemuck::Zeroable::zeroed());
        let shared = self.storage("shared points", &packed.shared, [0f32; 2]);
        let pixels = view.pixels() as u64;
        let hits = self.output("hits", pixels * HIT_BYTES);
        let visibility = self.output(
            "visibility",
            (pixels * packed.lights.len().max(1) as u64).max(3 * (probes.len() / 2) as u64) * 4,
        );
        let nodes = self.storage("bvh nodes", &packed.nodes, bytemuck::Zeroable::zeroed());
        let triangles = self.storage("triangles", &packed.triangles, bytemuck::Zeroable::zeroed());
        let probe_rays = self.storage("probe rays", probes, [0f32; 4]);
        let radiance = self.output("radiance", pixels * 4);
        let counters = self.output("ray counters", (MAX_LIGHTS * 2 * 4) as u64);
        let buffers = [
            &params,
            &spheres,
            &planes,
            &lights,
            &shared,
            &hits,
            &visibility,
            &radiance,
            &counters,
            &nodes,
            &triangles,
            &probe_rays,
        ];
        let entries: Vec<_> = buffers
            .iter()
            .enumerate()
            .map(|(i, b)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: b.as_entire_binding(),
            })
            .collect();
        let bind0 = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("frame"),
            layout: &self.layout0,
            entries: &entries,
        });
        let chunk = layout::samples_per_dispatch(packed);
        let one = [GpuLight::zeroed()];
        let lights = if packed.lights.is_empty() {
            &one[..]
        } else {
            &packed.lights[..]
        };
        let passes = lights
            .iter()
            .enumerate()
            .map(|(light, l)| {
                (0..l.samples.max(1).div_ceil(chunk))
                    .map(|c| {
                        let info = PassInfo {
                            light: light as u32,
                            first_sample: c * chunk,
                            sample_count: chunk,
                            _pad: 0,
                        };
                        let buffer = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                            label: Some("pass info"),
                            contents: bytemuck::bytes_of(&info),
                            usage: wgpu::BufferUsages::UNIFORM,
                        });
                        self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                            label: Some("pass"),
                            layout: &self.layout1,
                            entries: &[wgpu::BindGroupEntry {
                                binding: 0,
                                resource: buffer.as_entire_binding(),
                            }],
                        })
                    })
                    .collect()
            })
            .collect();
        let queries = self.timestamps.then(|| {
            let count = 2 * (packed.lights.len() as u32 + 1);
            let set = self.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count,
            });
            let resolve = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size: count as u64 * 8,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            (set, resolve)
        });
        FrameResources {
            bind0,
            passes,
            hits,
            visibility,
            radiance,
            counters,
            queries,
            meshes: !packed.nodes.is_empty(),
        }
    }

    /// Records the plan's passes into `encoder`: primary, then one shadow pass per light.
    fn encode(&self, encoder: &mut wgpu::CommandEncoder, r: &FrameResources, view: View, lights: usize) {
        encoder.clear_buffer(&r.counters, 0, None);
        encoder.clear_buffer(&r.visibility, 0, None);
        let groups = (view.width.div_ceil(8), view.height.div_ceil(8));
        for pass in 0..=lights {
            let timestamp_writes = r.queries.as_ref().map(|(set, _)| wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(2 * pass as u32),
                end_of_pass_write_index: Some(2 * pass as u32 + 1),
            });
            let mut cp = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: None,
                timestamp_writes,
            });
            let pipelines = if pass == 0 { &self.primary } else { &self.shadow };
            cp.set_pipeline(&pipelines[r.meshes as usize]);
            cp.set_bind_group(0, &r.bind0, &[]);
            // The primary pass ignores group 1; a shadow pass runs one dispatch per sample chunk.
            let chunks = if pass == 0 {
                &r.passes[0][..1]
            } else {
                &r.passes[pass - 1][..]
            };
            for chunk in chunks {
                cp.set_bind_group(1, chunk, &[]);
                cp.dispatch_workgroups(groups.0, groups.1, 1);
            }
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

    /// (whole frame, primary pass) seconds from the timestamps around each pass.
    fn frame_seconds(&self, r: &FrameResources) -> anyhow::Result<Option<(f64, f64)>> {
        let Some((set, resolve)) = &r.queries else {
            return Ok(None);
        };
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.resolve_query_set(set, 0..set_count(resolve), resolve, 0);
        self.submit(encoder, self.device.push_error_scope(wgpu::ErrorFilter::Validation))?;
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&self.read(resolve, resolve.size())?);
        let (first, last) = (ticks[0], ticks[ticks.len() - 1]);
        let period = self.queue.get_timestamp_period() as f64;
        let seconds = |a: u64, b: u64| b.saturating_sub(a) as f64 * period * 1e-9;
        Ok(Some((seconds(first, last), seconds(ticks[0], ticks[1]))))
    }

    /// Runs a one-dimensional test-hook kernel over `groups` workgroups.
    fn run_hook(&self, pipeline: &wgpu::ComputePipeline, r: &FrameResources, groups: u32) -> anyhow::Result<()> {
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
            cp.dispatch_workgroups(groups, 1, 1);
        }
        self.submit(encoder, scope)
    }

    /// Unit-disk points of `scheme` for pixel `pixel` with `seed`, computed by the WGSL sampler:
    /// lets tests compare it with the Rust one ([`DiskScheme::point`]).
    pub fn disk_points(&mut self, scheme: DiskScheme, n: u32, seed: u32, pixel: u32) -> anyhow::Result<Vec<[f32; 2]>> {
        let scene = crate::scene::Scene::analytic(vec![], vec![], vec![]);
        let cam = dummy_camera();
        let view = View {
            camera: &cam,
            width: n,
            height: 1,
        };
        let mut packed = pack(
            &scene,
            view,
            Sampling {
                scheme,
                pattern: crate::sampling::Pattern::PerPixel,
                seed,
            },
        );
        packed.params.height = pixel;
        let r = self.resources(
            &packed,
            View {
                camera: &cam,
                width: n,
                height: 2,
            },
            &[],
        );
        self.run_hook(&self.dump, &r, n.div_ceil(64))?;
        let raw: Vec<f32> = bytemuck::pod_collect_to_vec(&self.read(&r.visibility, n as u64 * 8)?);
        Ok(raw.chunks(2).map(|c| [c[0], c[1]]).collect())
    }
}

/// Timestamps a resolve buffer holds.
fn set_count(resolve: &wgpu::Buffer) -> u32 {
    (resolve.size() / 8) as u32
}

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
    /// Traces `rays` against the scene's mesh BVH with the WGSL closest-hit and any-hit
    /// traversals, in the same local frame as a render: lets tests compare the GPU's traversal
    /// with obvhs' and with brute force.
    pub fn probe(&mut self, scene: &crate::scene::Scene, rays: &[ProbeRay]) -> anyhow::Result<Vec<ProbeHit>> {
        let cam = scene.cameras.values().next().cloned().unwrap_or_else(dummy_camera);
        let view = View {
            camera: &cam,
            width: rays.len() as u32,
            height: 1,
        };
        let mut packed = pack(
            scene,
            view,
            Sampling {
                scheme: DiskScheme::Uniform,
                pattern: crate::sampling::Pattern::PerPixel,
                seed: 0,
            },
        );
        packed.params.width = rays.len() as u32;
        let (origin, scale) = layout::local_frame(scene, view);
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
        let r = self.resources(&packed, view, &probes);
        self.run_hook(&self.probe, &r, (rays.len() as u32).div_ceil(64))?;
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

impl Backend for GpuBackend {
    fn adapter(&self) -> &AdapterInfo {
        &self.info
    }

    fn render(&mut self, scene: &crate::scene::Scene, view: View, sampling: Sampling) -> anyhow::Result<Frame> {
        RenderPlan::new(scene, view)?;
        self.check_limits(scene, view)?;
        let packed = pack(scene, view, sampling);
        let lights = scene.lights.len();
        let r = self.resources(&packed, view, &[]);
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.encode(&mut encoder, &r, view, lights);
        self.submit(encoder, scope)?;
        let pixels = view.pixels();
        let hits: Vec<u32> = bytemuck::pod_collect_to_vec(&self.read(&r.hits, pixels as u64 * HIT_BYTES)?);
        let vis: Vec<f32> = if lights > 0 {
            bytemuck::pod_collect_to_vec(&self.read(&r.visibility, (pixels * lights) as u64 * 4)?)
        } else {
            vec![]
        };
        let radiance: Vec<f32> = bytemuck::pod_collect_to_vec(&self.read(&r.radiance, pixels as u64 * 4)?);
        let counters: Vec<u32> = bytemuck::pod_collect_to_vec(&self.read(&r.counters, (MAX_LIGHTS * 8) as u64)?);
        let mut rays = RayCounts {
            primary: pixels as u64,
            shadow: [0; MAX_LIGHTS],
        };
        for (i, s) in rays.shadow.iter_mut().enumerate() {
            *s = counters[2 * i] as u64 | ((counters[2 * i + 1] as u64) << 32);
        }
        Ok(Frame {
            width: view.width,
            height: view.height,
            radiance,
            visibility: vis.chunks(pixels.max(1)).map(<[f32]>::to_vec).collect(),
            hit: hits.chunks((HIT_BYTES / 4) as usize).map(|h| h[3]).collect(),
            rays,
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
        RenderPlan::new(scene, view)?;
        self.check_limits(scene, view)?;
        let packed = pack(scene, view, sampling);
        let lights = scene.lights.len();
        let r = self.resources(&packed, view, &[]);
        let (mut seconds, mut primary_seconds) = (Vec::new(), Vec::new());
        for i in 0..warmup + repeats {
            let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
            let mut encoder = self.device.create_command_encoder(&Default::default());
            self.encode(&mut encoder, &r, view, lights);
            let start = Instant::now();
            self.submit(encoder, scope)?;
            let wall = start.elapsed().as_secs_f64();
            let passes = self.frame_seconds(&r)?;
            if i >= warmup {
                seconds.push(passes.map_or(wall, |p| p.0));
                primary_seconds.extend(passes.map(|p| p.1));
            }
        }
        Ok(Timing {
            seconds,
            primary_seconds,
            clock: if self.timestamps {
                Clock::GpuTimestamp
            } else {
                Clock::WallClock
            },
        })
    }
}
