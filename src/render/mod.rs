//! Rendering: one [`Backend`] trait, a wgpu compute implementation ([`gpu`]) and an f64 CPU
//! reference ([`cpu`]) that follow the same [`plan::RenderPlan`] and the same sample streams.
//!
//! A frame holds, per pixel, the radiance of the first surface seen and, per light, its
//! visibility: the fraction of that light's shadow-ray targets that are above the receiver's
//! horizon, in front of the one-sided emitter, and unoccluded.

pub mod ambient;
pub mod cpu;
pub mod denoise;
pub mod gpu;
pub mod limit;
pub mod mirror;
pub mod plan;
pub mod shading;

use crate::sampling::{DiskScheme, Pattern};
use crate::scene::{camera::Camera, Scene};
use serde::Serialize;

pub use plan::RenderPlan;

/// Visibility value written where the camera ray hits nothing (no receiver to shade).
pub const NO_RECEIVER: f32 = -1.0;
/// Object id written where the camera ray hits nothing.
pub const NO_HIT: u32 = u32::MAX;

/// How shadow-ray targets are chosen for one render.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sampling {
    /// Disk sampling scheme.
    pub scheme: DiskScheme,
    /// Per-pixel or shared random numbers.
    pub pattern: Pattern,
    /// Seed of every random number in the frame.
    pub seed: u32,
    /// Index of this frame in a temporal sequence, 0 for a single frame: what each scheme does
    /// with it is [`DiskScheme::point`]'s business.
    pub frame: u32,
}

/// What to render: a camera and an image size.
#[derive(Clone, Copy, Debug)]
pub struct View<'a> {
    /// The camera.
    pub camera: &'a Camera,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl View<'_> {
    /// Pixel count.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }
}

/// Rays a frame actually traced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct RayCounts {
    /// Camera rays (one per pixel).
    pub primary: u64,
    /// Shadow rays per light, in scene order.
    pub shadow: [u64; plan::MAX_LIGHTS],
    /// Ambient-occlusion rays.
    pub ambient: u64,
    /// Mirror-reflection rays (their vertices' shadow rays count in `shadow`).
    pub reflection: u64,
}

impl RayCounts {
    /// All shadow rays.
    pub fn shadow_total(&self) -> u64 {
        self.shadow.iter().sum()
    }

    /// Every ray of the frame.
    pub fn total(&self) -> u64 {
        self.primary + self.shadow_total() + self.ambient + self.reflection
    }
}

/// A rendered frame.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Outgoing radiance (W m^-2 sr^-1) of the surface seen, row-major, top row first.
    pub radiance: Vec<f32>,
    /// Per light, per pixel visibility in [0, 1], or [`NO_RECEIVER`].
    pub visibility: Vec<Vec<f32>>,
    /// Per pixel, the object id hit by the camera ray, or [`NO_HIT`].
    pub hit: Vec<u32>,
    /// Per pixel, the ambient-occlusion value in [0, 1] (the scene's weighting) or
    /// [`NO_RECEIVER`]; `None` where the scene asks for no ambient occlusion.
    pub ambient: Option<Vec<f32>>,
    /// Rays traced.
    pub rays: RayCounts,
    /// What the queries cost (nodes visited, primitives tested), where the backend counts it:
    /// the CPU always, the GPU where switched on ([`Backend::count_work`]; never in timed
    /// frames).
    pub work: crate::accel::work::Work,
    /// Whether `work` was counted.
    pub counted: bool,
    /// Bounces the mirror pass ran (0 without the pass): the longest chain's reflected rays,
    /// at least one. The GPU dispatches no bounce past it, whatever the depth limit.
    pub mirror_bounces: u32,
}

impl Frame {
    /// The work counters, where counted.
    pub fn work(&self) -> Option<crate::accel::work::Work> {
        self.counted.then_some(self.work)
    }
}

/// How a frame time was measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Clock {
    /// GPU timestamp queries around the passes.
    GpuTimestamp,
    /// Host wall clock around submit and wait (includes driver overhead).
    WallClock,
}

impl Clock {
    /// The label written into results.
    pub fn name(self) -> &'static str {
        match self {
            Clock::GpuTimestamp => "gpu-timestamp",
            Clock::WallClock => "wall-clock",
        }
    }
}

/// Repeated frame times after warm-up.
#[derive(Clone, Debug)]
pub struct Timing {
    /// Seconds per frame, one per timed repeat.
    pub seconds: Vec<f64>,
    /// Seconds of the primary (camera-ray) pass per frame, where the clock can split passes.
    pub primary_seconds: Vec<f64>,
    /// Where the times came from.
    pub clock: Clock,
}

/// Identity of the device that produced a result, written into every record.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct AdapterInfo {
    /// `gpu` or `cpu`.
    pub backend: String,
    /// Adapter name, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
    pub name: String,
    /// Driver name and version.
    pub driver: String,
    /// Graphics API under wgpu (Vulkan, Metal, ...), or `cpu`.
    pub api: String,
    /// Iterations after which the adapter leaves a loop, where it caps them (Mesa's llvmpipe).
    pub loop_cap: Option<u32>,
    /// Worker threads of the CPU backend: they change its times, never its values, so they are
    /// recorded but kept out of the keys that say which device made a result.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threads: Option<usize>,
}

impl AdapterInfo {
    /// Whether this is the GPU backend (its bundles, counts and rounding are not the CPU's).
    pub fn is_gpu(&self) -> bool {
        self.backend == "gpu"
    }

    /// The device in a plot title's few words: `GPU <adapter>` or `CPU f64`.
    pub fn short(&self) -> String {
        if self.is_gpu() {
            format!("GPU {}", self.name)
        } else {
            "CPU f64".into()
        }
    }

    /// The device in the words a report opens with: the CPU backend and its threads, or the GPU
    /// adapter, saying so where the adapter is Mesa's software rasteriser (its GPU times are a
    /// CPU's).
    pub fn describe(&self) -> String {
        if self.backend == "cpu" {
            return format!("the f64 CPU backend ({} threads)", self.threads.unwrap_or(1));
        }
        let software = if self.name.contains("llvmpipe") {
            ": Mesa's software Vulkan driver, so its GPU times are this machine's CPU's"
        } else {
            ""
        };
        format!("the GPU backend on {} ({}){software}", self.name, self.api)
    }
}

/// A renderer of scenes into frames.
pub trait Backend {
    /// Which device this is.
    fn adapter(&self) -> &AdapterInfo;

    /// Work units issued so far over all frames (GPU: compute dispatches, CPU: pass loops): what
    /// tests count against the plan, since a pass not in the plan must never run.
    fn dispatches(&self) -> u64;

    /// Switches the counting of work (queries, nodes, primitive tests) in the frames read back:
    /// the CPU always counts; the GPU only when switched on (its atomics), which the ao and
    /// frames kinds do and the sweep, fps and realtime kinds do not (their GPU rows read n/a).
    fn count_work(&mut self, _on: bool) {}

    /// Renders one frame and reads it back.
    fn render(&mut self, scene: &Scene, view: View, sampling: Sampling) -> anyhow::Result<Frame>;

    /// Renders `warmup + repeats` frames without reading them back and times the last `repeats`.
    fn time(
        &mut self,
        scene: &Scene,
        view: View,
        sampling: Sampling,
        warmup: u32,
        repeats: u32,
    ) -> anyhow::Result<Timing>;

    /// Reconstructs an accumulated shadow image with `filter` ([`denoise`]): the image, its taps
    /// and the seconds the filter took. The CPU runs the f64 reference; the GPU its WGSL twin.
    fn reconstruct(
        &mut self,
        filter: denoise::Filter,
        input: &denoise::Input,
    ) -> anyhow::Result<(denoise::Output, f64)> {
        let start = std::time::Instant::now();
        let out = denoise::cpu::apply(filter, input);
        Ok((out, start.elapsed().as_secs_f64()))
    }
}

/// Which renderer runs an experiment: the experiment file's `backend` key, or `--backend`.
#[derive(Clone, Copy, Debug, Default, serde::Deserialize, PartialEq, Eq, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum BackendChoice {
    /// The GPU when an adapter exists, else the CPU with a warning.
    #[default]
    Auto,
    /// The GPU or an error.
    Gpu,
    /// The f64 CPU reference.
    Cpu,
}

/// Opens the backend an experiment asks for; `Auto` falls back to the CPU with a warning that
/// names what to install.
pub fn open_backend(choice: BackendChoice) -> anyhow::Result<Box<dyn Backend>> {
    match choice {
        BackendChoice::Cpu => Ok(Box::new(cpu::CpuBackend::default())),
        BackendChoice::Gpu => Ok(Box::new(gpu::GpuBackend::new()?)),
        BackendChoice::Auto => match gpu::GpuBackend::new() {
            Ok(g) => Ok(Box::new(g)),
            Err(e) => {
                tracing::warn!("{e:#}");
                tracing::warn!("falling back to the f64 CPU backend (slow; results record it)");
                Ok(Box::new(cpu::CpuBackend::default()))
            }
        },
    }
}
