//! The CWBVH's GPU form: obvhs' 80-byte compressed wide nodes, each re-based from the tree's
//! coordinates (relative to the mesh's centre) into the frame's local ones, and the triangles in
//! primitive-slot order, `#[repr(C)]` and Pod with sizes pinned to the WGSL structs in
//! `cwbvh.wgsl`. Re-basing moves the node's corner `p` (rounded once more to f32) and shifts its
//! three exponents by the frame's power-of-two scale, so the 8-bit child planes stay as obvhs
//! quantised them.

use super::Cwbvh;
use crate::accel::{GpuStructure, GpuTri};
use crate::geometry::LocalFrame;
use bytemuck::{Pod, Zeroable};

/// Entries of the traversal stack in `cwbvh.wgsl`.
const STACK_SIZE: usize = 128;

/// Loop iterations budgeted for one any-hit walk: node pops, eight child tests each, and leaf
/// triangles.
const WALK_ITERATIONS: u32 = 4096;

/// A CWBVH8 node as `cwbvh.wgsl` reads it: obvhs' `CwBvhNode` field for field.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
pub struct GpuCwNode {
    pub p: [f32; 3],
    /// Exponent bytes (x, y, z), then the mask of inner children.
    pub e_imask: [u8; 4],
    pub child_base: u32,
    pub prim_base: u32,
    pub child_meta: [u8; 8],
    /// Child planes: x min, x max, y min, y max, z min, z max.
    pub q: [[u8; 8]; 6],
}

const _: () = assert!(std::mem::size_of::<GpuCwNode>() == 80);

/// Levels of inner nodes below the root, deepest path.
pub(super) fn depth(tree: &obvhs::cwbvh::CwBvh) -> usize {
    let mut deepest = 0;
    let mut todo = vec![(0usize, 1usize)];
    while let Some((i, d)) = todo.pop() {
        deepest = deepest.max(d);
        let n = &tree.nodes[i];
        let inner = n.imask.count_ones() as usize;
        todo.extend((0..inner).map(|k| (n.child_base_idx as usize + k, d + 1)));
    }
    deepest
}

/// Why a tree `levels` deep has no GPU form: a walk may hold seven siblings per level on the
/// stack besides the node it is in.
pub(super) fn too_deep(levels: usize) -> Option<String> {
    let most = (STACK_SIZE - 1) / 7;
    (levels > most).then(|| {
        format!(
            "the CWBVH is {levels} levels deep; the GPU traversal stack holds {STACK_SIZE} entries (depth {most} at most)"
        )
    })
}

/// The exponent byte of `2^(e - 127) / scale` for a power-of-two `scale`, or an error naming the
/// node where it leaves f32's normal range.
fn rebased_exponent(e: u8, shift: i32, node: usize) -> anyhow::Result<u8> {
    if e == 0 {
        return Ok(0);
    }
    let moved = e as i32 - shift;
    anyhow::ensure!(
        (1..=254).contains(&moved),
        "CWBVH node {node}: its child grid step 2^{} is not a normal f32 in the frame's units (scale 2^{shift})",
        e as i32 - 127
    );
    Ok(moved as u8)
}

pub(super) fn structure(cw: &Cwbvh, frame: &LocalFrame) -> anyhow::Result<GpuStructure> {
    let shift = frame.scale.log2();
    anyhow::ensure!(
        shift.fract() == 0.0,
        "the GPU frame's scale {} is not a power of two, which the CWBVH's re-based exponents need",
        frame.scale
    );
    let shift = shift as i32;
    if cw.tree.nodes.is_empty() {
        return Ok(GpuStructure {
            buffers: vec![("CWBVH node buffer", vec![]), ("CWBVH triangle buffer", vec![])],
            walk_iterations: WALK_ITERATIONS,
        });
    }
    if let Some(refusal) = too_deep(depth(&cw.tree)) {
        anyhow::bail!("{refusal}");
    }
    let mut nodes = Vec::with_capacity(cw.tree.nodes.len());
    for (i, n) in cw.tree.nodes.iter().enumerate() {
        let p = frame.point_f64(n.p.as_dvec3() + cw.centre);
        nodes.push(GpuCwNode {
            p: p.as_vec3().to_array(),
            e_imask: [
                rebased_exponent(n.e[0], shift, i)?,
                rebased_exponent(n.e[1], shift, i)?,
                rebased_exponent(n.e[2], shift, i)?,
                n.imask,
            ],
            child_base: n.child_base_idx,
            prim_base: n.primitive_base_idx,
            child_meta: n.child_meta,
            q: [
                n.child_min_x,
                n.child_max_x,
                n.child_min_y,
                n.child_max_y,
                n.child_min_z,
                n.child_max_z,
            ],
        });
    }
    let triangles: Vec<GpuTri> = cw
        .tree
        .primitive_indices
        .iter()
        .map(|&i| GpuTri::new(&cw.world[i as usize], i, frame))
        .collect();
    Ok(GpuStructure {
        buffers: vec![
            ("CWBVH node buffer", bytemuck::cast_slice(&nodes).to_vec()),
            ("CWBVH triangle buffer", bytemuck::cast_slice(&triangles).to_vec()),
        ],
        walk_iterations: WALK_ITERATIONS,
    })
}

/// Bytes of the GPU form: 80 per node, a 48-byte triangle per primitive slot.
pub(super) fn bytes(cw: &Cwbvh) -> u64 {
    80 * cw.tree.nodes.len() as u64 + 48 * cw.tree.primitive_indices.len() as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponents_move_by_the_frame_scale_and_refuse_leaving_the_normal_range() {
        assert_eq!(rebased_exponent(127, 3, 0).unwrap(), 124);
        assert_eq!(rebased_exponent(127, -3, 0).unwrap(), 130);
        assert_eq!(rebased_exponent(0, 5, 0).unwrap(), 0);
        let e = rebased_exponent(2, 4, 17).unwrap_err().to_string();
        assert!(e.contains("node 17"), "{e}");
        assert!(rebased_exponent(250, -10, 0).is_err());
    }

    #[test]
    fn the_stack_bound_is_seven_siblings_per_level() {
        assert!(too_deep(18).is_none());
        let e = too_deep(19).unwrap();
        assert!(e.contains("19 levels") && e.contains("128 entries"), "{e}");
    }
}
