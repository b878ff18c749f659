//! GPU-side struct layouts, `#[repr(C)]` and Pod, their sizes pinned at compile time to match
//! the WGSL structs in `shaders/render.wgsl` (vec3<f32> has 16-byte alignment there).

use crate::render::{Sampling, View};
use crate::sampling::{shared_points, Pattern};
use crate::scene::{Light, Scene};
use bytemuck::{Pod, Zeroable};
use glam::DVec3;

/// Uniform block of one frame.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
pub struct Params {
    pub width: u32,
    pub height: u32,
    pub sphere_count: u32,
    pub plane_count: u32,
    pub light_count: u32,
    pub scheme: u32,
    pub shared_pattern: u32,
    pub seed: u32,
    pub cam_origin: [f32; 3],
    pub ortho: u32,
    pub cam_right: [f32; 3],
    pub half_x: f32,
    pub cam_up: [f32; 3],
    pub half_y: f32,
    pub cam_forward: [f32; 3],
    pub node_count: u32,
    pub object_base: u32,
    pub _pad: [u32; 3],
}

/// A BVH2 node: bounds, then the leaf's triangle count (0 for inner nodes) and the first child
/// (inner) or first triangle (leaf). Children of an inner node are adjacent.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
pub struct GpuNode {
    pub min: [f32; 3],
    pub prim_count: u32,
    pub max: [f32; 3],
    pub first_index: u32,
}

/// A triangle as vertex + two edges in full f32, with its mesh, index and albedo.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
pub struct GpuTri {
    pub v0: [f32; 3],
    pub mesh: u32,
    pub e1: [f32; 3],
    pub index: u32,
    pub e2: [f32; 3],
    pub albedo: f32,
}

/// A sphere.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
pub struct GpuSphere {
    pub center: [f32; 3],
    pub radius: f32,
    pub albedo: f32,
    pub _pad: [f32; 3],
}

/// A plane.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
pub struct GpuPlane {
    pub point: [f32; 3],
    pub albedo: f32,
    pub normal: [f32; 3],
    pub _pad: f32,
}

/// A light; `kind` 0 = point, 1 = disk; (u, v) span the disk's plane.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
pub struct GpuLight {
    pub center: [f32; 3],
    pub radius: f32,
    pub normal: [f32; 3],
    pub power: f32,
    pub u: [f32; 3],
    pub kind: u32,
    pub v: [f32; 3],
    pub samples: u32,
    pub shared_offset: u32,
    pub _pad: [u32; 3],
}

/// Per-dispatch uniform: which light a shadow dispatch serves and which of its samples.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
pub struct PassInfo {
    pub light: u32,
    pub first_sample: u32,
    pub sample_count: u32,
    pub _pad: u32,
}

/// Bytes per pixel of the hit buffer (WGSL `Hit`).
pub const HIT_BYTES: u64 = 48;

const _: () = assert!(std::mem::size_of::<Params>() == 112);
const _: () = assert!(std::mem::size_of::<GpuNode>() == 32);
const _: () = assert!(std::mem::size_of::<GpuTri>() == 48);
const _: () = assert!(std::mem::size_of::<GpuSphere>() == 32);
const _: () = assert!(std::mem::size_of::<GpuPlane>() == 32);
const _: () = assert!(std::mem::size_of::<GpuLight>() == 80);
const _: () = assert!(std::mem::size_of::<PassInfo>() == 16);

/// The frame of GPU coordinates: world = origin + scale * local. `scale` is a power of two, so
/// dividing by it is exact.
struct Local {
    origin: DVec3,
    scale: f64,
}

impl Local {
    /// Re-bases on the camera's look-at point and rescales to the scene's extent, so that f32
    /// keeps its relative precision wherever the scene is placed and whatever its size, and the
    /// self-intersection offsets (tuned for unit-sized scenes) stay proportionate.
    fn new(scene: &Scene, view: View) -> Local {
        let origin = view.camera.look_at;
        let mut extent = (view.camera.position - origin).length();
        for s in &scene.spheres {
            extent = extent.max((s.center - origin).length() + s.radius);
        }
        for l in &scene.lights {
            extent = extent.max(match l {
                Light::Point { position, .. } => (*position - origin).length(),
                Light::Disk(d) => (d.center - origin).length() + d.radius,
            });
        }
        let scale = if extent > 0.0 && extent.is_finite() {
            2f64.powi(extent.log2().round() as i32)
        } else {
            1.0
        };
        Local { origin, scale }
    }

    fn point(&self, p: DVec3) -> [f32; 3] {
        ((p - self.origin) / self.scale).as_vec3().to_array()
    }

    fn length(&self, x: f64) -> f32 {
        (x / self.scale) as f32
    }

    /// Power rescaled so that irradiance, Phi / d^2, comes out in world units.
    fn power(&self, x: f64) -> f32 {
        (x / (self.scale * self.scale)) as f32
    }
}

fn dir(p: DVec3) -> [f32; 3] {
    p.as_vec3().to_array()
}

/// Everything uploaded for one frame, in the local frame of [`Local`].
pub struct Packed {
    pub params: Params,
    pub spheres: Vec<GpuSphere>,
    pub planes: Vec<GpuPlane>,
    pub lights: Vec<GpuLight>,
    pub shared: Vec<[f32; 2]>,
    pub nodes: Vec<GpuNode>,
    pub triangles: Vec<GpuTri>,
}

/// The local frame of a render: (origin, scale) with world = origin + scale * local.
pub fn local_frame(scene: &Scene, view: View) -> (DVec3, f64) {
    let l = Local::new(scene, view);
    (l.origin, l.scale)
}

/// Packs a scene, view and sampling choice into GPU structs.
pub fn pack(scene: &Scene, view: View, sampling: Sampling) -> Packed {
    let local = Local::new(scene, view);
    let (frame, (hx, hy), ortho) = view.camera.gpu_terms(view.width, view.height);
    // Perspective half extents are tangents (unitless); orthographic ones are lengths.
    let (hx, hy) = if ortho {
        (hx / local.scale, hy / local.scale)
    } else {
        (hx, hy)
    };
    let params = Params {
        width: view.width,
        height: view.height,
        sphere_count: scene.spheres.len() as u32,
        plane_count: scene.planes.len() as u32,
        light_count: scene.lights.len() as u32,
        scheme: sampling.scheme.gpu_id(),
        shared_pattern: (sampling.pattern == Pattern::Shared) as u32,
        seed: sampling.seed,
        cam_origin: local.point(view.camera.position),
        ortho: ortho as u32,
        cam_right: dir(frame.right),
        half_x: hx as f32,
        cam_up: dir(frame.up),
        half_y: hy as f32,
        cam_forward: dir(frame.forward),
        node_count: scene.bvh.as_ref().map_or(0, |b| b.node_count() as u32),
        object_base: (scene.spheres.len() + scene.planes.len()) as u32,
        _pad: [0; 3],
    };
    let spheres = scene
        .spheres
        .iter()
        .map(|s| GpuSphere {
            center: local.point(s.center),
            radius: local.length(s.radius),
            albedo: s.albedo as f32,
            _pad: [0.0; 3],
        })
        .collect();
    let planes = scene
        .planes
        .iter()
        .map(|p| GpuPlane {
            // The point of the plane nearest the new origin: small coordinates, same plane.
            point: local.point(local.origin - p.normal * (local.origin - p.point).dot(p.normal)),
            albedo: p.albedo as f32,
            normal: dir(p.normal),
            _pad: 0.0,
        })
        .collect();
    let mut shared = Vec::new();
    let mut lights = Vec::new();
    for (i, l) in scene.lights.iter().enumerate() {
        let offset = shared.len() as u32;
        lights.push(match l {
            Light::Point { position, power } => GpuLight {
                center: local.point(*position),
                radius: 0.0,
                normal: [0.0; 3],
                power: local.power(*power),
                u: [0.0; 3],
                kind: 0,
                v: [0.0; 3],
                samples: 1,
                shared_offset: offset,
                _pad: [0; 3],
            },
            Light::Disk(d) => {
                let (u, v) = d.basis();
                if sampling.pattern == Pattern::Shared {
                    shared.extend(
                        shared_points(sampling.scheme, d.samples, sampling.seed, i as u32)
                            .iter()
                            .map(|p| p.as_vec2().to_array()),
                    );
                }
                GpuLight {
                    center: local.point(d.center),
                    radius: local.length(d.radius),
                    normal: dir(d.normal),
                    power: local.power(d.power),
                    u: dir(u),
                    kind: 1,
                    v: dir(v),
                    samples: d.samples,
                    shared_offset: offset,
                    _pad: [0; 3],
                }
            }
        });
    }
    let (nodes, triangles) = scene
        .bvh
        .as_ref()
        .map_or((vec![], vec![]), |b| pack_bvh(scene, b, &local));
    Packed {
        params,
        spheres,
        planes,
        lights,
        shared,
        nodes,
        triangles,
    }
}

/// The BVH in the frame's local coordinates: node bounds converted through f64 and widened by
/// a few f32 ulps so that no triangle pokes out of its node after rounding; triangles laid out
/// in leaf order (obvhs' `primitive_indices`), so leaves index them directly.
fn pack_bvh(scene: &Scene, bvh: &crate::accel::Bvh, local: &Local) -> (Vec<GpuNode>, Vec<GpuTri>) {
    let to_local = |p: glam::Vec3A| (glam::Vec3::from(p).as_dvec3() + bvh.centre - local.origin) / local.scale;
    let nodes = bvh
        .tree
        .nodes
        .iter()
        .map(|n| {
            let (lo, hi) = (to_local(n.aabb.min), to_local(n.aabb.max));
            let size = (hi - lo)
                .max_element()
                .max(lo.abs().max_element())
                .max(hi.abs().max_element());
            let pad = size * 4.0 * f32::EPSILON as f64;
            GpuNode {
                min: (lo - pad).as_vec3().to_array(),
                prim_count: n.prim_count,
                max: (hi + pad).as_vec3().to_array(),
                first_index: n.first_index,
            }
        })
        .collect();
    let triangles = bvh
        .tree
        .primitive_indices
        .iter()
        .map(|&i| {
            let t = &bvh.world[i as usize];
            let mesh = bvh.mesh_of[i as usize];
            let p = t.map(|c| (c - local.origin) / local.scale);
            GpuTri {
                v0: p[0].as_vec3().to_array(),
                mesh,
                e1: (p[1] - p[0]).as_vec3().to_array(),
                index: i,
                e2: (p[2] - p[0]).as_vec3().to_array(),
                albedo: scene.meshes[mesh as usize].albedo as f32,
            }
        })
        .collect();
    (nodes, triangles)
}
