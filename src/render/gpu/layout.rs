//! GPU-side struct layouts, `#[repr(C)]` and Pod, their sizes pinned at compile time to match
//! the WGSL structs in `shaders/render.wgsl` and the shapes' WGSL (vec3<f32> has 16-byte
//! alignment there). The acceleration structure packs its own buffers ([`crate::accel`]).

use crate::accel::GpuStructure;
use crate::geometry::LocalFrame;
use crate::render::ambient::AMBIENT_STREAM;
use crate::render::{Sampling, View};
use crate::sampling::{shared_points, Pattern};
use crate::scene::ambient::{AmbientOcclusion, AoDirections, Weighting};
use crate::scene::{Light, Scene, Shape};
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
    pub triangle_count: u32,
    /// Ambient-occlusion rays per receiver (0: no AO pass).
    pub ao_rays: u32,
    /// [`AoMode`] as its number.
    pub ao_mode: u32,
    /// The AO disk scheme's id (disk modes).
    pub ao_scheme: u32,
    /// Farthest AO occluder, local units (infinite: none).
    pub ao_max_distance: f32,
    /// Index of the frame in a temporal sequence ([`Sampling::frame`]).
    pub frame: u32,
    /// 1 where lights are tested for occlusion; 0 for OpenGL-like shading (the plan's `direct`
    /// pass runs the shadow kernel with every target visible).
    pub shadows: u32,
    /// Most mirror bounces after the camera ray ([`crate::scene::Shading::mirror_depth`]).
    pub mirror_depth: u32,
    /// 1 where the kernels add their work to the counters (untimed frames only).
    pub stats: u32,
}

/// How the AO kernel makes and weights its directions (`AO_*` in render.wgsl).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AoMode {
    /// No AO pass.
    None = 0,
    /// Grid lines from `ao_dirs`, oriented into the hemisphere, counted.
    GridPlain = 1,
    /// Grid lines, cosine-weighted.
    GridCosine = 2,
    /// Disk points lifted by the equal-area map, counted.
    DiskPlain = 3,
    /// Disk points lifted by Malley's projection, counted.
    DiskCosine = 4,
}

/// A mesh triangle's shading data, in input order: the edges give the geometric normal exactly
/// as the traversal's triangles do, so normals match whichever structure found the hit.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
pub struct GpuMeshTri {
    pub e1: [f32; 3],
    pub object: u32,
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
    pub object: u32,
    pub _pad: [u32; 2],
}

/// A plane.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
pub struct GpuPlane {
    pub point: [f32; 3],
    pub albedo: f32,
    pub normal: [f32; 3],
    pub object: u32,
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
/// Bytes per pixel of the mirror pass's chain buffer (WGSL `Chain`: its last vertex, the ray's
/// direction and weight, and its running sums).
pub const CHAIN_BYTES: u64 = HIT_BYTES + 48;

const _: () = assert!(std::mem::size_of::<Params>() == 128);
const _: () = assert!(std::mem::size_of::<GpuMeshTri>() == 32);
const _: () = assert!(std::mem::size_of::<GpuSphere>() == 32);
const _: () = assert!(std::mem::size_of::<GpuPlane>() == 32);
const _: () = assert!(std::mem::size_of::<GpuLight>() == 80);
const _: () = assert!(std::mem::size_of::<PassInfo>() == 16);

/// The local frame of a render: re-based on the camera's look-at point and rescaled to the
/// scene's extent, so that f32 keeps its relative precision wherever the scene is placed and
/// whatever its size, and the self-intersection offsets (tuned for unit-sized scenes) stay
/// proportionate.
pub fn local_frame(scene: &Scene, view: View) -> LocalFrame {
    let origin = view.camera.look_at;
    let mut extent = (view.camera.position - origin).length();
    for s in scene.spheres() {
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
    LocalFrame { origin, scale }
}

/// Power rescaled so that irradiance, Phi / d^2, comes out in world units.
fn scaled_power(local: &LocalFrame, x: f64) -> f32 {
    (x / (local.scale * local.scale)) as f32
}

fn dir(p: DVec3) -> [f32; 3] {
    p.as_vec3().to_array()
}

/// Everything uploaded for one frame, in the local frame of [`local_frame`].
pub struct Packed {
    pub params: Params,
    pub spheres: Vec<GpuSphere>,
    pub planes: Vec<GpuPlane>,
    pub lights: Vec<GpuLight>,
    pub shared: Vec<[f32; 2]>,
    pub mesh_tris: Vec<GpuMeshTri>,
    /// AO directions: the grid's lines (xyz) or the shared disk points (xy); empty otherwise.
    pub ao_dirs: Vec<[f32; 4]>,
    /// The acceleration structure's name and buffers; None without triangles.
    pub accel: Option<(&'static str, GpuStructure)>,
    /// The tables the per-pixel schemes read ([`crate::sampling::tables::pack`]).
    pub tables: Vec<u32>,
    /// Per object id, its mirror weight (0 for analytic shapes).
    pub mirrors: Vec<f32>,
    /// Whether the AO rays are issued direction-major ([`crate::accel::Issue::Bundled`]): one
    /// dispatch per direction, every receiver's ray along it, so a dispatch walks one
    /// direction's part of a structure.
    pub ao_direction_major: bool,
}

/// A mirror weight in f32 on the same side of 0 and of 1 as in f64: the kernels decide "no
/// mirror" (m = 0) and "no diffuse part" (m = 1) by comparison, as the CPU does, so a weight
/// f32 would round onto either end keeps the nearest value inside (a chain's contribution at
/// such weights is below f32's resolution anyway).
fn mirror_weight(m: f64) -> f32 {
    let w = m as f32;
    if w == 0.0 && m > 0.0 {
        f32::MIN_POSITIVE
    } else if w == 1.0 && m < 1.0 {
        1.0 - f32::EPSILON / 2.0
    } else {
        w
    }
}

/// Packs a scene, view and sampling choice into GPU structs; fails where the scene's
/// acceleration structure exceeds a limit of its GPU form.
pub fn pack(scene: &Scene, view: View, sampling: Sampling) -> anyhow::Result<Packed> {
    let local = local_frame(scene, view);
    let (frame, (hx, hy), ortho) = view.camera.gpu_terms(view.width, view.height);
    // Perspective half extents are tangents (unitless); orthographic ones are lengths.
    let (hx, hy) = if ortho {
        (hx / local.scale, hy / local.scale)
    } else {
        (hx, hy)
    };
    let mut params = Params {
        width: view.width,
        height: view.height,
        sphere_count: scene.spheres().count() as u32,
        plane_count: scene.planes().count() as u32,
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
        triangle_count: scene.triangles.positions.len() as u32,
        ao_rays: 0,
        ao_mode: AoMode::None as u32,
        ao_scheme: 0,
        ao_max_distance: f32::INFINITY,
        frame: sampling.frame,
        shadows: scene.shading.shadows as u32,
        mirror_depth: scene.shading.mirror_depth,
        stats: 0,
    };
    let mut ao_dirs = Vec::new();
    if let Some(ao) = &scene.ambient {
        params.ao_rays = ao.rays;
        params.ao_max_distance = local.length(ao.max_distance);
        params.ao_mode = match (&ao.directions, ao.weighting) {
            (AoDirections::Grid { lines, .. }, w) => {
                ao_dirs = lines
                    .iter()
                    .map(|l| [l.x as f32, l.y as f32, l.z as f32, 0.0])
                    .collect();
                match w {
                    Weighting::Plain => AoMode::GridPlain,
                    Weighting::Cosine => AoMode::GridCosine,
                }
            }
            (AoDirections::Disk(scheme), w) => {
                params.ao_scheme = scheme.gpu_id();
                if sampling.pattern == Pattern::Shared {
                    ao_dirs = shared_points(*scheme, ao.rays, sampling.seed, AMBIENT_STREAM, sampling.frame)
                        .iter()
                        .map(|p| [p.x as f32, p.y as f32, 0.0, 0.0])
                        .collect();
                }
                match w {
                    Weighting::Plain => AoMode::DiskPlain,
                    Weighting::Cosine => AoMode::DiskCosine,
                }
            }
        } as u32;
    }
    let (mut spheres, mut planes) = (vec![], vec![]);
    for (id, shape) in scene.shapes.iter().enumerate() {
        let object = id as u32;
        match shape {
            Shape::Sphere(s) => spheres.push(GpuSphere {
                center: local.point(s.center),
                radius: local.length(s.radius),
                albedo: s.albedo as f32,
                object,
                _pad: [0; 2],
            }),
            Shape::Plane(p) => planes.push(GpuPlane {
                // The point of the plane nearest the new origin: small coordinates, same plane.
                point: local.point(local.origin - p.normal * (local.origin - p.point).dot(p.normal)),
                albedo: p.albedo as f32,
                normal: dir(p.normal),
                object,
            }),
            Shape::Mesh(_) => {}
        }
    }
    let mut shared = Vec::new();
    let mut lights = Vec::new();
    for (i, l) in scene.lights.iter().enumerate() {
        let offset = shared.len() as u32;
        lights.push(match l {
            Light::Point { position, power } => GpuLight {
                center: local.point(*position),
                radius: 0.0,
                normal: [0.0; 3],
                power: scaled_power(&local, *power),
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
                        shared_points(sampling.scheme, d.samples, sampling.seed, i as u32, sampling.frame)
                            .iter()
                            .map(|p| p.as_vec2().to_array()),
                    );
                }
                GpuLight {
                    center: local.point(d.center),
                    radius: local.length(d.radius),
                    normal: dir(d.normal),
                    power: scaled_power(&local, d.power),
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
    let mesh_tris = scene
        .triangles
        .positions
        .iter()
        .zip(&scene.triangles.object_of)
        .map(|(t, &object)| {
            let p = t.map(|c| local.point_f64(c));
            GpuMeshTri {
                e1: (p[1] - p[0]).as_vec3().to_array(),
                object,
                e2: (p[2] - p[0]).as_vec3().to_array(),
                albedo: scene.shapes[object as usize].albedo() as f32,
            }
        })
        .collect();
    let accel = match &scene.accel {
        Some(a) => Some((a.name(), a.gpu(&local)?)),
        None => None,
    };
    // Per-pixel patterns read the tables on the GPU; shared ones were drawn above.
    let mut uses: Vec<(crate::sampling::DiskScheme, u32)> = Vec::new();
    if sampling.pattern == Pattern::PerPixel {
        uses.extend(scene.lights.iter().map(|l| (sampling.scheme, l.samples())));
        if let Some(AmbientOcclusion {
            directions: AoDirections::Disk(s),
            rays,
            ..
        }) = &scene.ambient
        {
            uses.push((*s, *rays));
        }
    }
    Ok(Packed {
        params,
        spheres,
        planes,
        lights,
        shared,
        mesh_tris,
        ao_dirs,
        accel,
        tables: crate::sampling::tables::pack(&uses),
        mirrors: scene.shapes.iter().map(|s| mirror_weight(s.mirror())).collect(),
        ao_direction_major: scene
            .ambient
            .as_ref()
            .is_some_and(|a| a.issue == crate::accel::Issue::Bundled),
    })
}

#[cfg(test)]
mod tests {
    use super::mirror_weight;

    #[test]
    fn mirror_weights_keep_their_side_of_0_and_1_in_f32() {
        assert_eq!(mirror_weight(0.0), 0.0);
        assert_eq!(mirror_weight(1.0), 1.0);
        assert_eq!(mirror_weight(0.5), 0.5);
        assert!(mirror_weight(1e-30) > 0.0 && mirror_weight(1e-300) > 0.0);
        assert!(mirror_weight(0.99999999) < 1.0);
        assert_eq!(mirror_weight(0.99999999), 1.0 - f32::EPSILON / 2.0);
    }
}
