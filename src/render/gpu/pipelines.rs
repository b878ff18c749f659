//! The render layout and the pipelines compiled per acceleration structure: the shapes' and the
//! renderer's WGSL with one structure's module appended, whose buffers bind at group 2. A scene
//! without triangles gets `shaders/no_accel.wgsl`, so its kernels hold no mesh traversal.

use crate::accel;
use crate::sampling::DiskScheme;
use std::collections::HashMap;

/// The renderer's WGSL without an acceleration structure.
const RENDER: &str = concat!(
    include_str!("shaders/sampling.wgsl"),
    include_str!("shaders/geometry.wgsl"),
    include_str!("../../scene/shape/sphere.wgsl"),
    include_str!("../../scene/shape/plane.wgsl"),
    include_str!("../../scene/shape/mesh.wgsl"),
    include_str!("shaders/render.wgsl"),
);

/// Name of the structure-less module (no triangles in the scene).
pub const NO_ACCEL: &str = "none";

/// WGSL constants naming each disk scheme's id, generated from [`DiskScheme::ALL`], and the
/// layout of the schemes' tables ([`crate::sampling::tables`]), prepended to the shaders, so
/// Rust and WGSL share one list.
pub fn scheme_prelude() -> String {
    let ids: String = DiskScheme::ALL
        .iter()
        .map(|s| {
            let name = s.name().to_uppercase().replace('-', "_");
            format!("const SCHEME_{name}: u32 = {}u;\n", s.gpu_id())
        })
        .collect();
    let points = format!("const SCHEME_POINTS: u32 = {}u;\n", crate::sampling::POINTS_GPU_ID);
    ids + &points + &crate::sampling::tables::wgsl_prelude()
}

/// The bind group layouts every pipeline shares: per frame (group 0), per dispatch (group 1),
/// and, with the `test-hooks` feature, the hooks' own (group 3), which no render pipeline
/// includes.
pub(super) struct Layouts {
    pub frame: wgpu::BindGroupLayout,
    /// Storage buffers in the frame's layout (every binding but the parameters' uniform).
    pub frame_storage: u32,
    pub pass: wgpu::BindGroupLayout,
    /// The mirror gate's own group: the counters and the next bounce's dispatch arguments,
    /// which no render kernel binds (they are read as indirect arguments).
    pub gate: wgpu::BindGroupLayout,
    #[cfg(feature = "test-hooks")]
    pub hooks: wgpu::BindGroupLayout,
}

/// The mirror pass's kernels (render.wgsl's `mirror_*`).
pub(super) struct MirrorPipelines {
    pub trace: wgpu::ComputePipeline,
    pub shade: wgpu::ComputePipeline,
    pub step: wgpu::ComputePipeline,
    /// Between bounces: the next bounce's workgroups, none once every chain has ended
    /// (mirror_gate.wgsl).
    pub gate: wgpu::ComputePipeline,
    pub finish: wgpu::ComputePipeline,
}

/// One structure's pipelines.
pub(super) struct Pipelines {
    /// Its buffers' layout (group 2).
    pub accel: wgpu::BindGroupLayout,
    pub primary: wgpu::ComputePipeline,
    /// Also the plan's `direct` pass (`Params::shadows` off).
    pub shadow: wgpu::ComputePipeline,
    /// The split mirror pass: per bounce a trace, shading chunks and a step; then a finish.
    pub mirror: MirrorPipelines,
    pub ambient: wgpu::ComputePipeline,
    #[cfg(feature = "test-hooks")]
    hooks: Option<(wgpu::ComputePipeline, wgpu::ComputePipeline)>,
}

fn storage(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn uniform(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl Layouts {
    pub fn new(device: &wgpu::Device) -> Layouts {
        // params; spheres, planes, lights, shared points; hits, visibility, radiance, counters;
        // mesh triangles; AO directions and output; the sampling schemes' tables; mirror weights;
        // the lights' running sums between sample chunks; the mirror chains between bounces.
        let mut entries = vec![uniform(0)];
        entries.extend((1..=4).map(|b| storage(b, true)));
        entries.extend((5..=8).map(|b| storage(b, false)));
        entries.push(storage(9, true));
        entries.extend([
            storage(10, true),
            storage(11, false),
            storage(12, true),
            storage(13, true),
            storage(14, false),
            storage(15, false),
        ]);
        let layout = |label, entries: &[wgpu::BindGroupLayoutEntry]| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries,
            })
        };
        Layouts {
            frame_storage: entries.len() as u32 - 1,
            frame: layout("frame", &entries),
            pass: layout("pass", &[uniform(0)]),
            gate: layout("mirror gate", &[storage(0, false), storage(1, false)]),
            #[cfg(feature = "test-hooks")]
            hooks: layout("test hooks", &[storage(0, true)]),
        }
    }
}

/// Pipelines by structure name, compiled on first use.
#[derive(Default)]
pub(super) struct PipelineCache {
    by_name: HashMap<&'static str, Pipelines>,
}

impl PipelineCache {
    /// The pipelines of structure `name` ([`NO_ACCEL`] or a registry name).
    pub fn get(
        &mut self,
        device: &wgpu::Device,
        layouts: &Layouts,
        name: &'static str,
        cut_short_slot: usize,
    ) -> &Pipelines {
        self.by_name
            .entry(name)
            .or_insert_with(|| compile(device, layouts, name, cut_short_slot))
    }

    #[cfg(feature = "test-hooks")]
    /// The test-hook kernels (`dump_samples`, `trace_probes`) of structure `name`, compiled on
    /// first use so that rendering never builds them.
    pub fn hooks(
        &mut self,
        device: &wgpu::Device,
        layouts: &Layouts,
        name: &'static str,
        cut_short_slot: usize,
    ) -> &(wgpu::ComputePipeline, wgpu::ComputePipeline) {
        let p = self
            .by_name
            .entry(name)
            .or_insert_with(|| compile(device, layouts, name, cut_short_slot));
        if p.hooks.is_none() {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("test hooks"),
                bind_group_layouts: &[
                    Some(&layouts.frame),
                    Some(&layouts.pass),
                    Some(&p.accel),
                    Some(&layouts.hooks),
                ],
                immediate_size: 0,
            });
            let module = module(device, name, cut_short_slot, include_str!("shaders/hooks.wgsl"));
            let dump = entry(device, &module, "dump_samples", &layout);
            let probe = entry(device, &module, "trace_probes", &layout);
            p.hooks = Some((dump, probe));
        }
        p.hooks.as_ref().expect("just compiled")
    }
}

fn entry(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    name: &str,
    layout: &wgpu::PipelineLayout,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(name),
        layout: Some(layout),
        module,
        entry_point: Some(name),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// The renderer's module with structure `name`'s WGSL, and `extra` (the hooks) appended.
fn module(device: &wgpu::Device, name: &'static str, cut_short_slot: usize, extra: &str) -> wgpu::ShaderModule {
    let wgsl = if name == NO_ACCEL {
        include_str!("shaders/no_accel.wgsl")
    } else {
        let r = accel::registered(name).expect("names are checked against the registry before upload");
        &format!("{}{}", accel::TRIANGLE_WGSL, r.wgsl)
    };
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(name),
        source: wgpu::ShaderSource::Wgsl(
            format!(
                "{}const CUT_SHORT_SLOT: u32 = {cut_short_slot}u;\n{RENDER}{wgsl}{extra}",
                scheme_prelude()
            )
            .into(),
        ),
    })
}

/// The mirror gate's kernel, with the counter slots render.wgsl's mirror pass uses.
fn gate(device: &wgpu::Device, layouts: &Layouts, cut_short_slot: usize) -> wgpu::ComputePipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("mirror gate"),
        source: wgpu::ShaderSource::Wgsl(
            format!(
                "const MIRROR_LIVE_SLOT: u32 = {}u;\nconst MIRROR_BOUNCES_SLOT: u32 = {}u;\n{}",
                cut_short_slot + 12,
                cut_short_slot + 13,
                include_str!("shaders/mirror_gate.wgsl")
            )
            .into(),
        ),
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("mirror gate"),
        bind_group_layouts: &[Some(&layouts.gate)],
        immediate_size: 0,
    });
    entry(device, &module, "mirror_gate", &layout)
}

fn compile(device: &wgpu::Device, layouts: &Layouts, name: &'static str, cut_short_slot: usize) -> Pipelines {
    let buffers = accel::registered(name).map_or(0, |r| r.gpu_buffers);
    let module = module(device, name, cut_short_slot, "");
    let entries: Vec<_> = (0..buffers).map(|b| storage(b, true)).collect();
    let accel = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(name),
        entries: &entries,
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("render"),
        // A structure without buffers leaves group 2 out of the layout altogether.
        bind_group_layouts: &[
            Some(&layouts.frame),
            Some(&layouts.pass),
            (buffers > 0).then_some(&accel),
        ],
        immediate_size: 0,
    });
    Pipelines {
        primary: entry(device, &module, "primary", &layout),
        shadow: entry(device, &module, "shadow", &layout),
        mirror: MirrorPipelines {
            trace: entry(device, &module, "mirror_trace", &layout),
            shade: entry(device, &module, "mirror_shade", &layout),
            step: entry(device, &module, "mirror_step", &layout),
            gate: gate(device, layouts, cut_short_slot),
            finish: entry(device, &module, "mirror_finish", &layout),
        },
        ambient: entry(device, &module, "ambient", &layout),
        accel,
        #[cfg(feature = "test-hooks")]
        hooks: None,
    }
}
