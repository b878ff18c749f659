//! The kd-tree's GPU form, read by `kdtree.wgsl`: a header with the root box, the nodes with
//! their split planes moved into the frame's local coordinates, the leaves' triangle lists, and
//! the triangles in input order.

use super::{KdNode, KdTree};
use crate::accel::{GpuStructure, GpuTri};
use crate::geometry::LocalFrame;
use crate::mesh::Triangles;

/// Largest buffer: wgpu's default (and WebGPU's guaranteed) storage-binding size.
const BINDING_BYTES: usize = 128 << 20;

/// Loop iterations budgeted for one any-hit walk (node steps and leaf triangles): a ray crosses
/// a few dozen leaves of a few triangles each, as many as a BVH walk visits nodes. A walk that
/// runs over is caught as cut short and its frame redone with fewer samples per dispatch.
const WALK_ITERATIONS: u32 = 1536;

/// The buffers of `kdtree.wgsl`, or an error naming the one over the binding limit.
pub(super) fn structure(tree: &KdTree, triangles: &Triangles, frame: &LocalFrame) -> anyhow::Result<GpuStructure> {
    let (lo, hi) = (frame.point(tree.bounds.0), frame.point(tree.bounds.1));
    let header: Vec<u32> = [lo, hi]
        .iter()
        .flat_map(|p| p.iter().map(|c| c.to_bits()).chain([0]))
        .collect();
    let nodes: Vec<KdNode> = tree
        .nodes
        .iter()
        .map(|n| match n.inner() {
            Some((axis, split, _)) => KdNode {
                word: (((tree.bounds.0[axis] + split - frame.origin[axis]) / frame.scale) as f32).to_bits(),
                data: n.data,
            },
            None => *n,
        })
        .collect();
    let tris: Vec<GpuTri> = triangles
        .positions
        .iter()
        .enumerate()
        .map(|(i, t)| GpuTri::new(t, i as u32, frame))
        .collect();
    let buffers = vec![
        ("kd-tree header", bytemuck::cast_slice(&header).to_vec()),
        ("kd-tree nodes", bytemuck::cast_slice(&nodes).to_vec()),
        ("kd-tree triangle lists", bytemuck::cast_slice(&tree.items).to_vec()),
        ("kd-tree triangles", bytemuck::cast_slice(&tris).to_vec()),
    ];
    for (label, bytes) in &buffers {
        anyhow::ensure!(
            bytes.len() <= BINDING_BYTES,
            "the {label} take {} MiB; a storage binding holds {} MiB (lower the kd-tree's max_depth)",
            bytes.len() >> 20,
            BINDING_BYTES >> 20
        );
    }
    Ok(GpuStructure {
        buffers,
        walk_iterations: WALK_ITERATIONS,
    })
}
