//! GPU resources split as wgpu's examples split them: the scene's static data (spheres, planes,
//! mesh triangles, the acceleration structure's buffers) is uploaded once and stays resident while its packed content is
//! unchanged; per-frame data (parameters, lights, shared sample points, pass infos, outputs,
//! timestamp queries) is made for each call. Timed repeats and warm-up frames of one call run
//! over the same resources, and successive calls on one scene upload no geometry.

use super::layout::{GpuLight, Packed, PassInfo, CHAIN_BYTES, HIT_BYTES};
use super::pipelines::NO_ACCEL;
use super::GpuBackend;
use super::{COUNTER_WORDS, CUT_SHORT_SLOT};
use crate::fingerprint::fnv1a;
use crate::render::plan::{Pass, RenderPlan};
use crate::render::View;
use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

/// `PassInfo.light` of the AO pass's dispatches (no light has this index).
const AMBIENT_PASS: u32 = u32::MAX;
/// `PassInfo.light` of the mirror pass's trace and step dispatches (`first_sample`: the bounce).
const MIRROR_PASS: u32 = u32::MAX - 1;

/// The scene's static buffers and the hash of the packed content they hold.
pub(super) struct SceneBuffers {
    key: u64,
    /// The capped chunk is divided by this: doubled each time a frame over this scene reports
    /// loops cut short (a BVH walk longer than its budget), so the split adapts per scene.
    pub chunk_divisor: u32,
    spheres: wgpu::Buffer,
    planes: wgpu::Buffer,
    mesh_tris: wgpu::Buffer,
    /// Per object id, its mirror weight.
    mirrors: wgpu::Buffer,
    /// The acceleration structure's name and its buffers' bind group (group 2).
    accel: &'static str,
    accel_group: wgpu::BindGroup,
}

/// Per-frame GPU resources.
pub(super) struct FrameResources {
    pub bind0: wgpu::BindGroup,
    /// Per light, one bind group per dispatch of its samples.
    pub passes: Vec<Vec<wgpu::BindGroup>>,
    pub hits: wgpu::Buffer,
    pub visibility: wgpu::Buffer,
    pub radiance: wgpu::Buffer,
    /// Per light and pixel, the running sum of its sample terms between chunks.
    pub light_sums: wgpu::Buffer,
    /// One bind group per bounce of the mirror pass (none without the pass).
    pub mirror_passes: Vec<wgpu::BindGroup>,
    /// The mirror gate's group and the indirect arguments it writes (with the pass only).
    pub mirror_gate: Option<(wgpu::BindGroup, wgpu::Buffer)>,
    /// Per pixel, the AO pass's (unoccluded, total) weights.
    pub ambient: wgpu::Buffer,
    /// One bind group per dispatch of the AO pass's rays (none without the pass).
    pub ambient_passes: Vec<wgpu::BindGroup>,
    pub counters: wgpu::Buffer,
    pub queries: Option<(wgpu::QuerySet, wgpu::Buffer)>,
    /// The acceleration structure (selects the pipelines) and its bind group.
    pub accel: &'static str,
    pub accel_group: wgpu::BindGroup,
}

/// Hash of the packed static data: equal hashes mean the resident buffers can be reused.
fn static_key(p: &Packed) -> u64 {
    let mut bytes: Vec<u8> = Vec::new();
    let mut parts = vec![
        (p.spheres.len(), bytemuck::cast_slice::<_, u8>(&p.spheres)),
        (p.planes.len(), bytemuck::cast_slice(&p.planes)),
        (p.mesh_tris.len(), bytemuck::cast_slice(&p.mesh_tris)),
        (p.mirrors.len(), bytemuck::cast_slice(&p.mirrors)),
    ];
    if let Some((name, s)) = &p.accel {
        parts.push((0, name.as_bytes()));
        parts.extend(s.buffers.iter().map(|(_, b)| (b.len(), b.as_slice())));
    }
    for (len, data) in parts {
        bytes.extend_from_slice(&(len as u64).to_le_bytes());
        bytes.extend_from_slice(&fnv1a(data).to_le_bytes());
    }
    fnv1a(&bytes)
}

impl GpuBackend {
    pub(super) fn storage<T: Pod>(&self, label: &str, data: &[T], zeroed: T) -> wgpu::Buffer {
        // WGSL runtime-sized arrays need a non-empty binding.
        let one = [zeroed];
        let data: &[T] = if data.is_empty() { &one } else { data };
        self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytemuck::cast_slice(data),
            usage: wgpu::BufferUsages::STORAGE,
        })
    }

    pub(super) fn output(&self, label: &str, size: u64) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(16),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    /// The resident static buffers for `packed`, uploading them only when its content changed.
    fn scene_buffers(&mut self, packed: &Packed) -> anyhow::Result<&SceneBuffers> {
        let key = static_key(packed);
        if self.scene.as_ref().is_none_or(|s| s.key != key) {
            self.static_uploads += 1;
            let accel = packed.accel.as_ref().map_or(NO_ACCEL, |(name, _)| *name);
            if let Some((name, s)) = &packed.accel {
                let r = crate::accel::registered(name).ok_or_else(|| {
                    anyhow::anyhow!("acceleration structure `{name}` is not registered in accel::REGISTRY")
                })?;
                anyhow::ensure!(
                    s.buffers.len() == r.gpu_buffers as usize,
                    "acceleration structure `{name}` packs {} buffers; its registry entry declares {}",
                    s.buffers.len(),
                    r.gpu_buffers
                );
            }
            let buffers: Vec<wgpu::Buffer> = packed
                .accel
                .iter()
                .flat_map(|(_, s)| &s.buffers)
                .map(|(label, bytes)| self.storage(label, bytes, 0u8))
                .collect();
            let layout = &self
                .pipelines
                .get(&self.device, &self.layouts, accel, CUT_SHORT_SLOT)
                .accel;
            let entries: Vec<_> = buffers
                .iter()
                .enumerate()
                .map(|(i, b)| wgpu::BindGroupEntry {
                    binding: i as u32,
                    resource: b.as_entire_binding(),
                })
                .collect();
            let accel_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(accel),
                layout,
                entries: &entries,
            });
            self.scene = Some(SceneBuffers {
                key,
                chunk_divisor: 1,
                spheres: self.storage("spheres", &packed.spheres, Zeroable::zeroed()),
                planes: self.storage("planes", &packed.planes, Zeroable::zeroed()),
                mesh_tris: self.storage("mesh triangles", &packed.mesh_tris, Zeroable::zeroed()),
                mirrors: self.storage("mirror weights", &packed.mirrors, 0f32),
                accel,
                accel_group,
            });
        }
        Ok(self.scene.as_ref().expect("just set"))
    }

    /// Per-frame resources over the resident static buffers. `extra_floats` widens the visibility
    /// buffer for the test hooks that write into it.
    pub(super) fn resources(
        &mut self,
        packed: &Packed,
        view: View,
        plan: &RenderPlan,
        extra_floats: u64,
    ) -> anyhow::Result<FrameResources> {
        self.scene_buffers(packed)?;
        let s = self.scene.as_ref().expect("resident");
        let params = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("params"),
            contents: bytemuck::bytes_of(&packed.params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let lights = self.storage("lights", &packed.lights, Zeroable::zeroed());
        let shared = self.storage("shared points", &packed.shared, [0f32; 2]);
        let pixels = view.pixels() as u64;
        let hits = self.output("hits", pixels * HIT_BYTES);
        let visibility = self.output(
            "visibility",
            (pixels * packed.lights.len().max(1) as u64).max(extra_floats) * 4,
        );
        let radiance = self.output("radiance", pixels * 4);
        let light_sums = self.output("light sums", pixels * packed.lights.len().max(1) as u64 * 4);
        let depth = plan.passes.iter().find_map(|p| match p {
            Pass::Mirror { max_depth, .. } => Some(*max_depth),
            _ => None,
        });
        let chains = self.output("mirror chains", if depth.is_some() { pixels * CHAIN_BYTES } else { 16 });
        let counters = self.output("ray counters", COUNTER_WORDS as u64 * 4);
        let ao_dirs = self.storage("ambient-occlusion directions", &packed.ao_dirs, [0f32; 4]);
        let ao_on = packed.params.ao_rays > 0;
        let ambient = self.output("ambient occlusion", if ao_on { pixels * 8 } else { 16 });
        let tables = self.storage("sampling tables", &packed.tables, 0u32);
        let buffers = [
            &params,
            &s.spheres,
            &s.planes,
            &lights,
            &shared,
            &hits,
            &visibility,
            &radiance,
            &counters,
            &s.mesh_tris,
            &ao_dirs,
            &ambient,
            &tables,
            &s.mirrors,
            &light_sums,
            &chains,
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
            layout: &self.layouts.frame,
            entries: &entries,
        });
        let chunk = self.samples_per_dispatch(packed);
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
                    .map(|c| self.pass_info(light as u32, c * chunk, chunk))
                    .collect()
            })
            .collect();
        // AO rays take the shadow samples' chunk (each costs one point and one occlusion query),
        // or one ray per dispatch where they are issued direction-major.
        let ao_chunk = if packed.ao_direction_major { 1 } else { chunk };
        let ambient_passes = (0..if ao_on {
            packed.params.ao_rays.div_ceil(ao_chunk)
        } else {
            0
        })
            .map(|c| self.pass_info(AMBIENT_PASS, c * ao_chunk, ao_chunk))
            .collect();
        let mirror_passes = (0..depth.unwrap_or(0))
            .map(|bounce| self.pass_info(MIRROR_PASS, bounce, 0))
            .collect();
        let mirror_gate = depth.map(|_| {
            let groups = (view.width.div_ceil(8), view.height.div_ceil(8));
            let args = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("mirror bounce dispatch"),
                contents: bytemuck::cast_slice(&[groups.0, groups.1, 1, groups.0, groups.1]),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
            });
            let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("mirror gate"),
                layout: &self.layouts.gate,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: counters.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: args.as_entire_binding(),
                    },
                ],
            });
            (group, args)
        });
        let queries = self.timestamps.then(|| {
            let count = 2 * plan.passes.len().max(1) as u32;
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
        Ok(FrameResources {
            bind0,
            passes,
            hits,
            visibility,
            radiance,
            light_sums,
            mirror_passes,
            mirror_gate,
            ambient,
            ambient_passes,
            counters,
            queries,
            accel: s.accel,
            accel_group: s.accel_group.clone(),
        })
    }

    fn pass_info(&self, light: u32, first_sample: u32, sample_count: u32) -> wgpu::BindGroup {
        let info = PassInfo {
            light,
            first_sample,
            sample_count,
            _pad: 0,
        };
        let buffer = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("pass info"),
            contents: bytemuck::bytes_of(&info),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pass"),
            layout: &self.layouts.pass,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: buffer.as_entire_binding(),
            }],
        })
    }

    /// Shadow samples per dispatch: all of a light's samples in one, unless the adapter caps loop
    /// iterations (see [`super::loop_cap`]), where a chunk keeps one invocation's loop iterations
    /// under the cap: [`shadow_sample_iterations`] per sample, and the primary ray's loop,
    /// divided further where frames over this scene were cut short.
    pub(super) fn samples_per_dispatch(&self, packed: &Packed) -> u32 {
        let divisor = self.scene.as_ref().map_or(1, |s| s.chunk_divisor);
        match self.loop_cap {
            None => u32::MAX,
            Some(cap) => (chunk_under_cap(cap, packed) / divisor).max(1),
        }
    }
}

/// Loop iterations one shadow sample may run besides its occluder loops: the disk-point
/// generators in sampling.wgsl (isqrt's two digit loops, at most 16 each; the strata search,
/// at most sqrt(n) ≤ 64 for n ≤ 4096; Sobol's bit loop, at most 32), with room to spare.
const SAMPLE_POINT_ITERATIONS: u32 = 192;
/// Upper bound on the loop iterations of one shadow sample in render.wgsl: the sample loop's own
/// step, the point generator, one test per sphere and per plane, and the acceleration
/// structure's own budget for one any-hit query when the scene has triangles.
pub(super) fn shadow_sample_iterations(packed: &Packed) -> u32 {
    let walk = packed.accel.as_ref().map_or(0, |(_, s)| s.walk_iterations);
    1 + SAMPLE_POINT_ITERATIONS + packed.spheres.len() as u32 + packed.planes.len() as u32 + walk
}

/// Samples per dispatch on an adapter that stops loops after `cap` iterations: the largest count
/// whose loops, with the primary ray's (one per sphere and plane), fit under the cap. Never zero:
/// a scene too large even for one sample per dispatch is caught when its frames come back cut
/// short.
pub(super) fn chunk_under_cap(cap: u32, packed: &Packed) -> u32 {
    let primary = (packed.spheres.len() + packed.planes.len()) as u32;
    (cap.saturating_sub(primary) / shadow_sample_iterations(packed)).max(1)
}
