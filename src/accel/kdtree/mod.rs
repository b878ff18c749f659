//! A kd-tree as the visibility-field paper's baseline built it: single-ray Coherent Ray Tracing
//! (Wald, Slusallek, Benthin, Wagner 2001), a BSP over axis-aligned planes with spatial-median
//! splits ([`median`]), 8-byte nodes, and an explicit-stack front-to-back traversal. Tuned, as the
//! paper tuned it, on maximum depth and leaf size ([`KdSettings`]). Beside it, the split the
//! paper's authors name as the missing improvement: planes chosen by the surface area heuristic
//! (Wald & Havran 2006, [`sah`]), over the same nodes and the same walk.
//!
//! # Nodes
//! Two u32 words ([`KdNode`]). Inner: the split plane's coordinate, measured from the root box's
//! low corner, as f32 bits (relative to the scene's extent, not its distance from the origin, so a
//! scene placed far away keeps its splits), then `left << 2 | axis` (the right child is
//! `left + 1`). Leaf: the first entry of its triangle list in `items`, then `count << 2 | 3`.
//!
//! # Exactness
//! Every triangle meeting a node's closed box is in one of its children at least: the median
//! puts a triangle whose bounding box meets a closed half-space on that side (touching a plane: on
//! both sides); the SAH clips triangles to the node (conservatively) and may put one that only
//! touches the plane, or lies in it, on one side. The walk treats each plane as a slab `delta`
//! thick ([`walk`]), visiting both children wherever rounding could decide the side, and leaves
//! test triangles with [`crate::accel::intersect`] over the whole segment: answers equal brute
//! force's bit for bit, ties going to the lower index. A popped subtree is skipped only when its
//! entry distance lies beyond the best hit, and entry distances are lower bounds.

mod clip;
mod gpu;
pub mod median;
pub mod packet;
pub mod sah;
mod settings;
pub mod walk;

pub use settings::{sah_params, sah_tuning, KdSettings, SahCosts, Split, PAPER_COSTS};

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

/// Most leaf entries a tree may hold: a leaf starts at a u32 index into them.
pub const MAX_ENTRIES: usize = u32::MAX as usize;

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
    name: &'static str,
}

/// Axis-aligned bounds of a triangle.
fn bounds_of(t: &[DVec3; 3]) -> (DVec3, DVec3) {
    (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]))
}

/// The node array as a build fills it: each builder allocates children in pairs and stores planes
/// from the root box's low corner, rounded to the f32 the node holds.
struct Layout {
    /// The root box's low corner, from which splits are stored.
    origin: DVec3,
    nodes: Vec<KdNode>,
    items: Vec<u32>,
    depth: u32,
    /// Most leaf entries the tree may hold; past it the build stops ([`Layout::overflowed`]).
    budget: usize,
    /// Whether a leaf would have taken the entries past `budget`: triangles that straddle every
    /// plane (slivers crossing one another) are copied into every leaf, and a deep tree over
    /// them would hold 2^depth copies.
    overflowed: bool,
}

/// The f32 next to finite `x`, above it (`up`) or below.
fn adjacent(x: f32, up: bool) -> f32 {
    if x == 0.0 {
        let least = f32::from_bits(1);
        return if up { least } else { -least };
    }
    let bits = x.to_bits();
    f32::from_bits(if (x > 0.0) == up { bits + 1 } else { bits - 1 })
}

impl Layout {
    fn new(origin: DVec3, budget: usize) -> Layout {
        Layout {
            origin,
            nodes: vec![KdNode::zeroed()],
            items: Vec::new(),
            depth: 0,
            budget,
            overflowed: false,
        }
    }

    /// The plane `s` on `axis` as the node will store it (f32 from the root box's corner), in
    /// world coordinates.
    fn stored(&self, axis: usize, s: f64) -> f64 {
        let o = self.origin[axis];
        o + (s - o) as f32 as f64
    }

    /// The greatest plane a node can store at or below `v` on `axis` (`up`: the least at or
    /// above): a coordinate rounded outward onto the planes a split can take.
    fn stored_toward(&self, axis: usize, v: f64, up: bool) -> f64 {
        let o = self.origin[axis];
        let mut x = (v - o) as f32;
        while up && o + (x as f64) < v {
            x = adjacent(x, true);
        }
        while !up && o + (x as f64) > v {
            x = adjacent(x, false);
        }
        o + x as f64
    }

    /// Makes node `at` a leaf holding `tris`.
    fn leaf(&mut self, at: usize, tris: &[u32], depth: u32) {
        self.depth = self.depth.max(depth);
        if self.overflowed || self.items.len() + tris.len() > self.budget {
            self.overflowed = true;
            self.nodes[at] = KdNode::leaf(self.items.len(), 0);
            return;
        }
        self.nodes[at] = KdNode::leaf(self.items.len(), tris.len());
        self.items.extend_from_slice(tris);
    }

    /// Makes node `at` an inner node splitting `axis` at `s` (a value [`Layout::stored`]
    /// returned); returns its left child (the right one follows it).
    fn inner(&mut self, at: usize, axis: usize, s: f64) -> usize {
        let first = self.nodes.len();
        self.nodes.push(KdNode::zeroed());
        self.nodes.push(KdNode::zeroed());
        self.nodes[at] = KdNode {
            word: ((s - self.origin[axis]) as f32).to_bits(),
            data: (first as u32) << 2 | axis as u32,
        };
        first
    }
}

/// `bounds` cut at `s` on `axis`: the low and high halves.
fn halves(bounds: (DVec3, DVec3), axis: usize, s: f64) -> ((DVec3, DVec3), (DVec3, DVec3)) {
    let (mut lo, mut hi) = (bounds, bounds);
    lo.1[axis] = s;
    hi.0[axis] = s;
    (lo, hi)
}

impl KdTree {
    /// Builds the tree over `triangles` (all of them: degenerate ones are simply never hit) with
    /// the planes `settings.split` chooses, no deeper than [`MAX_DEPTH`] whatever `settings` ask
    /// (the walks' stacks hold that much).
    pub fn build(triangles: &Triangles, settings: KdSettings) -> KdTree {
        Self::within(triangles, settings, MAX_ENTRIES).expect("a tree within the entries a leaf can index")
    }

    /// [`KdTree::build`], refused once its leaves would hold more than `budget` entries (4 bytes
    /// each), as triangles straddling every plane make them: the build stops there and says so.
    pub fn within(triangles: &Triangles, settings: KdSettings, budget: usize) -> Result<KdTree, String> {
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
        let budget = budget.min(MAX_ENTRIES);
        let mut layout = Layout::new(bounds.0, budget);
        match settings.split {
            Split::Median => median::build(&mut layout, &boxes, bounds, &settings),
            Split::Sah => sah::build(&mut layout, &triangles.positions, &boxes, bounds, &settings),
        }
        if layout.overflowed {
            return Err(format!(
                "the kd-tree ({}) over {} triangles would hold more than {budget} triangle entries ({:.1} MB) in its leaves: \
                 its triangles straddle the planes at every depth (slivers crossing one another); lower `max_depth`",
                settings.describe(),
                triangles.positions.len(),
                budget as f64 * 4.0 / 1e6
            ));
        }
        Ok(KdTree {
            nodes: layout.nodes,
            items: layout.items,
            bounds,
            depth: layout.depth,
            triangles: triangles.clone(),
            settings,
            build_time: started.elapsed(),
            name: "kdtree",
        })
    }

    /// The same tree under another registry name (`kdtree-sah`, the SAH tree registered beside
    /// the median one).
    pub fn named(self, name: &'static str) -> KdTree {
        KdTree { name, ..self }
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
        self.name
    }

    fn closest(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> Option<TriHit> {
        walk::walk(self, &self.triangles, origin, dir, tmax, skip, false)
    }

    fn any_hit(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> bool {
        walk::walk(self, &self.triangles, origin, dir, tmax, skip, true).is_some()
    }

    fn any_hits(&self, queries: &[crate::accel::Query], hits: &mut [bool]) {
        packet::any_hits(self, queries, hits)
    }

    fn bundles(&self) -> bool {
        true
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
                "kd-tree ({}): {} nodes, {leaves} leaves, depth {}, {:.2} triangle \
                 references per triangle, {:.1} MB, built in {:.0} ms",
                match self.settings.split {
                    Split::Median => format!("spatial median, {}", self.settings.describe()),
                    Split::Sah => format!("SAH planes, {}", self.settings.describe()),
                },
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
        method: crate::accel::UpdateMethod,
        moved: &Triangles,
        _object: u32,
        _step: DVec3,
    ) -> anyhow::Result<crate::accel::Updated> {
        match method {
            // The same budget as the first build: a moved part whose triangles now straddle
            // every plane is refused, not built past the memory there is.
            crate::accel::UpdateMethod::Rebuild => {
                *self = KdTree::within(moved, self.settings, super::kdtree_entries())
                    .map_err(anyhow::Error::msg)?
                    .named(self.name)
            }
            m => return Err(crate::accel::unknown_update(self, m)),
        }
        Ok(crate::accel::Updated::Rebuilt)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A coordinate rounded outward lands on storable planes on either side of it, adjacent
    /// ones (no storable plane strictly between), and a storable coordinate stays put.
    #[test]
    fn adjacent_floats_step_by_one_unit_in_the_last_place() {
        for x in [1.0f32, -1.0, 0.1, -3.5e-20, 1e30, f32::from_bits(1)] {
            let (up, down) = (adjacent(x, true), adjacent(x, false));
            assert!(down < x && x < up, "{x}");
            assert_eq!(adjacent(up, false), x);
            assert_eq!(adjacent(down, true), x);
        }
        assert_eq!(adjacent(0.0, true), f32::from_bits(1));
        assert_eq!(adjacent(-0.0, false), -f32::from_bits(1));
    }

    #[test]
    fn coordinates_round_outward_onto_adjacent_storable_planes() {
        let layout = Layout::new(DVec3::new(-5.0, 0.1, 1e6), 1);
        let mut v = 0.123_456_789_f64;
        for axis in 0..3 {
            for k in 0..2000 {
                v = (v * 7.77 + k as f64 * 0.0131).rem_euclid(10.0) - 5.0;
                let (down, up) = (
                    layout.stored_toward(axis, v, false),
                    layout.stored_toward(axis, v, true),
                );
                assert!(down <= v && v <= up, "{down} {v} {up}");
                assert_eq!(layout.stored(axis, down), down);
                assert_eq!(layout.stored(axis, up), up);
                let o = layout.origin[axis];
                let (xd, xu) = ((down - o) as f32, (up - o) as f32);
                assert!(xd == xu || adjacent(xd, true) == xu, "{axis}: {xd} {xu} not adjacent");
                assert_eq!(xd == xu, layout.stored(axis, v) == v);
            }
        }
    }
}
