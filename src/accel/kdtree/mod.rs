//! A kd-tree as the visibility-field paper's baseline built it: single-ray Coherent Ray Tracing
//! (Wald, Slusallek, Benthin, Wagner 2001), a BSP over axis-aligned planes with spatial-median
//! splits (no SAH), 8-byte nodes, and an explicit-stack front-to-back traversal. Tuned, as the
//! paper tuned it, on maximum depth and leaf size ([`KdSettings`]).
//!
//! # Nodes
//! Two u32 words ([`KdNode`]). Inner: the split plane's coordinate, measured from the root box's
//! low corner, as f32 bits (relative to the scene's extent, not its distance from the origin, so a
//! scene placed far away keeps its splits), then `left << 2 | axis` (the right child is
//! `left + 1`). Leaf: the first entry of its triangle list in `items`, then `count << 2 | 3`.
//!
//! # Exactness
//! A node's triangles are those whose bounding box meets its closed half-space, so a triangle
//! touching a plane sits on both sides. The walk treats each plane as a slab `delta` thick
//! ([`walk`]), visiting both children wherever rounding could decide the side, and leaves test
//! triangles with [`crate::accel::intersect`] over the whole segment: answers equal brute
//! force's bit for bit, ties going to the lower index. A popped subtree is skipped only when its
//! entry distance lies beyond the best hit, and entry distances are lower bounds.

mod gpu;
pub mod walk;

use super::{Accelerator, BuildStats, GpuStructure, TriHit};
use crate::geometry::LocalFrame;
use crate::mesh::Triangles;
use bytemuck::{Pod, Zeroable};
use glam::DVec3;
use std::time::{Duration, Instant};

/// Its WGSL: `accel_closest` and `accel_any` as one stack walk ([`gpu`] lays out the buffers).
pub const WGSL: &str = include_str!("kdtree.wgsl");

/// Storage buffers `kdtree.wgsl` declares: header, nodes, items, triangles.
pub const GPU_BUFFERS: u32 = 4;

/// Deepest tree the walk's stack (64 entries on the CPU and the GPU) allows.
pub const MAX_DEPTH: u32 = 60;

/// The paper's tuning knobs for its CRT baseline (`[accel.kdtree]`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct KdSettings {
    /// Deepest split level (the paper's best: 16-23 for AO, 23 for the walkthrough).
    pub max_depth: u32,
    /// Nodes with at most this many triangles become leaves.
    pub leaf_size: u32,
}

impl Default for KdSettings {
    /// The best of `cargo bench --bench vlf_compare -- --tune-kdtree` (depths 16-30, leaves
    /// 2-32, AO rays along the 513 grid directions, one thread): depth 22 and leaf 8 on the cow
    /// (1.56 Mrays/s) and bull (1.25); the man and the body peak deeper (26-28) within 10 %.
    fn default() -> Self {
        KdSettings {
            max_depth: 22,
            leaf_size: 8,
        }
    }
}

impl crate::accel::settings::Params for KdSettings {
    fn check(&self) -> Result<(), (&'static str, String)> {
        if self.max_depth > MAX_DEPTH {
            return Err((
                "max_depth",
                format!("must lie in 0..={MAX_DEPTH} (the walk's stack), got {}", self.max_depth),
            ));
        }
        if self.leaf_size > 1 << 16 {
            return Err((
                "leaf_size",
                format!("must lie in 0..={}, got {}", 1 << 16, self.leaf_size),
            ));
        }
        Ok(())
    }

    /// The paper's CRT depths (16-23) and deeper, at three leaf sizes.
    fn tuning() -> toml::Table {
        toml::toml! {
            max_depth = [16, 18, 22, 26, 30]
            leaf_size = [4, 8, 16]
        }
    }
}

impl KdSettings {
    /// The parameters in a few words.
    pub fn describe(&self) -> String {
        format!("depth {} leaf {}", self.max_depth, self.leaf_size)
    }
}

/// One node, 8 bytes (see the module doc).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct KdNode {
    /// Inner: split coordinate from the root box's low corner (f32 bits); leaf: first entry in
    /// `items`.
    pub word: u32,
    /// Inner: `left << 2 | axis`; leaf: `count << 2 | 3`.
    pub data: u32,
}

const LEAF: u32 = 3;

impl KdNode {
    fn leaf(first: usize, count: usize) -> KdNode {
        KdNode {
            word: first as u32,
            data: (count as u32) << 2 | LEAF,
        }
    }

    /// `Some((axis, split from the root box's low corner, left child))` for an inner node.
    pub fn inner(&self) -> Option<(usize, f64, usize)> {
        let axis = self.data & 3;
        (axis != LEAF).then(|| {
            (
                axis as usize,
                f32::from_bits(self.word) as f64,
                (self.data >> 2) as usize,
            )
        })
    }

    /// `(first, count)` of a leaf's entries in `items`.
    pub fn items(&self) -> (usize, usize) {
        (self.word as usize, (self.data >> 2) as usize)
    }
}

/// The tree over a scene's triangles.
#[derive(Debug)]
pub struct KdTree {
    /// Nodes, root first; children of an inner node adjacent.
    pub nodes: Vec<KdNode>,
    /// Leaves' triangle lists (input indices).
    pub items: Vec<u32>,
    /// Bounds of every triangle: the root's box.
    pub bounds: (DVec3, DVec3),
    /// Deepest leaf.
    pub depth: u32,
    triangles: Triangles,
    settings: KdSettings,
    build_time: Duration,
}

/// Axis-aligned bounds of a triangle.
fn bounds_of(t: &[DVec3; 3]) -> (DVec3, DVec3) {
    (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]))
}

struct Builder<'a> {
    boxes: &'a [(DVec3, DVec3)],
    /// The root box's low corner, from which splits are stored.
    origin: DVec3,
    settings: KdSettings,
    nodes: Vec<KdNode>,
    items: Vec<u32>,
    depth: u32,
}

impl Builder<'_> {
    /// Fills node `at` (already allocated) for `tris` inside `bounds` at `depth`.
    fn node(&mut self, at: usize, tris: Vec<u32>, bounds: (DVec3, DVec3), depth: u32) {
        self.depth = self.depth.max(depth);
        let split = (tris.len() > self.settings.leaf_size as usize && depth < self.settings.max_depth)
            .then(|| self.split(&tris, bounds))
            .flatten();
        let Some((axis, s, left, right)) = split else {
            self.nodes[at] = KdNode::leaf(self.items.len(), tris.len());
            self.items.extend(tris);
            return;
        };
        let first = self.nodes.len();
        self.nodes.push(KdNode::zeroed());
        self.nodes.push(KdNode::zeroed());
        self.nodes[at] = KdNode {
            word: ((s - self.origin[axis]) as f32).to_bits(),
            data: (first as u32) << 2 | axis as u32,
        };
        let (mut lo_box, mut hi_box) = (bounds, bounds);
        lo_box.1[axis] = s;
        hi_box.0[axis] = s;
        self.node(first, left, lo_box, depth + 1);
        self.node(first + 1, right, hi_box, depth + 1);
    }

    /// The spatial median of the longest side (rounded to the f32 the node stores, from the root
    /// box's low corner) and each side's triangles; `None` where the plane would not divide
    /// anything.
    #[allow(clippy::type_complexity)]
    fn split(&self, tris: &[u32], (lo, hi): (DVec3, DVec3)) -> Option<(usize, f64, Vec<u32>, Vec<u32>)> {
        let axis = (hi - lo).max_position();
        let o = self.origin[axis];
        let s = o + ((lo[axis] + hi[axis]) * 0.5 - o) as f32 as f64;
        if !(s > lo[axis] && s < hi[axis]) {
            return None;
        }
        let (mut left, mut right) = (Vec::new(), Vec::new());
        for &t in tris {
            let (a, b) = self.boxes[t as usize];
            if a[axis] <= s {
                left.push(t);
            }
            if b[axis] >= s {
                right.push(t);
            }
        }
        (left.len() < tris.len() || right.len() < tris.len()).then_some((axis, s, left, right))
    }
}

impl KdTree {
    /// Builds the tree over `triangles` (all of them: degenerate ones are simply never hit), no
    /// deeper than [`MAX_DEPTH`] whatever `settings` ask (the walks' stacks hold that much).
    pub fn build(triangles: &Triangles, settings: KdSettings) -> KdTree {
        let started = Instant::now();
        let settings = KdSettings {
            max_depth: settings.max_depth.min(MAX_DEPTH),
            ..settings
        };
        let boxes: Vec<(DVec3, DVec3)> = triangles.positions.iter().map(bounds_of).collect();
        let bounds = boxes
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), (a, b)| {
                (lo.min(*a), hi.max(*b))
            });
        let mut b = Builder {
            boxes: &boxes,
            origin: bounds.0,
            settings,
            nodes: vec![KdNode::zeroed()],
            items: Vec::new(),
            depth: 0,
        };
        b.node(0, (0..boxes.len() as u32).collect(), bounds, 0);
        KdTree {
            nodes: b.nodes,
            items: b.items,
            bounds,
            depth: b.depth,
            triangles: triangles.clone(),
            settings,
            build_time: started.elapsed(),
        }
    }

    /// Bytes of nodes and triangle lists (the structure's own memory, triangles aside).
    pub fn bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<KdNode>() + self.items.len() * 4
    }

    /// `Some((axis, split coordinate, left child))` of inner node `node`, the split in world
    /// coordinates.
    pub fn split(&self, node: usize) -> Option<(usize, f64, usize)> {
        let (axis, s, left) = self.nodes[node].inner()?;
        Some((axis, self.bounds.0[axis] + s, left))
    }

    /// The build parameters.
    pub fn settings(&self) -> KdSettings {
        self.settings
    }
}

impl Accelerator for KdTree {
    fn name(&self) -> &'static str {
        "kdtree"
    }

    fn closest(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> Option<TriHit> {
        walk::walk(self, &self.triangles, origin, dir, tmax, skip, false)
    }

    fn any_hit(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> bool {
        walk::walk(self, &self.triangles, origin, dir, tmax, skip, true).is_some()
    }

    fn stats(&self) -> BuildStats {
        let leaves = self.nodes.iter().filter(|n| n.inner().is_none()).count();
        let n = self.triangles.positions.len();
        BuildStats {
            parameters: self.settings.describe(),
            build_time: self.build_time,
            gpu_bytes: (self.bytes() + n * std::mem::size_of::<super::GpuTri>()) as u64,
            memory_bytes: self.bytes() as u64,
            triangles: n,
            description: format!(
                "kd-tree (spatial median, {}): {} nodes, {leaves} leaves, depth {}, {:.2} triangle \
                 references per triangle, {:.1} MB, built in {:.0} ms",
                self.settings.describe(),
                self.nodes.len(),
                self.depth,
                self.items.len() as f64 / n.max(1) as f64,
                self.bytes() as f64 / 1e6,
                self.build_time.as_secs_f64() * 1e3
            ),
        }
    }

    fn gpu(&self, frame: &LocalFrame) -> anyhow::Result<GpuStructure> {
        gpu::structure(self, &self.triangles, frame)
    }

    fn update(
        &mut self,
        method: &str,
        moved: &Triangles,
        _object: u32,
        _step: DVec3,
    ) -> anyhow::Result<crate::accel::Updated> {
        match method {
            "rebuild" => *self = KdTree::build(moved, self.settings),
            m => return Err(crate::accel::unknown_update(self, m)),
        }
        Ok(crate::accel::Updated::Rebuilt)
    }
}
