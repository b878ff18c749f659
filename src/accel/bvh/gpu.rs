//! The BVH's GPU form: obvhs' nodes and the triangles in leaf order, in the frame's local
//! coordinates, `#[repr(C)]` and Pod with sizes pinned to the WGSL structs in `traverse.wgsl`.

use super::Bvh;
use crate::accel::{GpuStructure, GpuTri};
use crate::geometry::LocalFrame;
use bytemuck::{Pod, Zeroable};

/// Entries of the traversal stack in `traverse.wgsl`.
const STACK_SIZE: usize = 64;

/// Loop iterations budgeted for one any-hit walk (node pops plus leaf triangles). obvhs's SAH
/// trees over the shipped meshes stay in the low hundreds; grazing rays pay more.
const WALK_ITERATIONS: u32 = 1536;

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

const _: () = assert!(std::mem::size_of::<GpuNode>() == 32);

/// Why a tree `depth` levels deep has no GPU form: its walk would overflow the traversal stack.
pub(super) fn too_deep(depth: usize) -> Option<String> {
    let most = 2 * (STACK_SIZE / 2 - 1);
    (depth > most).then(|| {
        format!(
            "the BVH is {depth} levels deep; the GPU traversal stack holds {STACK_SIZE} entries (depth {most} at most)"
        )
    })
}

/// Node bounds converted through f64 and widened by a few f32 ulps so that no triangle pokes out
/// of its node after rounding; triangles laid out in leaf order (obvhs' `primitive_indices`), so
/// leaves index them directly. Fails where the tree is deeper than the traversal stack.
pub(super) fn structure(bvh: &Bvh, frame: &LocalFrame) -> anyhow::Result<GpuStructure> {
    if let Some(refusal) = too_deep(bvh.depth) {
        anyhow::bail!("{refusal}");
    }
    let to_local = |p: glam::Vec3A| frame.point_f64(glam::Vec3::from(p).as_dvec3() + bvh.centre);
    let nodes: Vec<GpuNode> = bvh
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
    let triangles: Vec<GpuTri> = bvh
        .tree
        .primitive_indices
        .iter()
        .map(|&i| GpuTri::new(&bvh.world[i as usize], i, frame))
        .collect();
    Ok(GpuStructure {
        buffers: vec![
            ("BVH node buffer", bytemuck::cast_slice(&nodes).to_vec()),
            ("BVH triangle buffer", bytemuck::cast_slice(&triangles).to_vec()),
        ],
        walk_iterations: WALK_ITERATIONS,
    })
}
