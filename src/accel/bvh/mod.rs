//! A BVH2 over a scene's triangles, built by obvhs (PLOC with parallel reinsertion), traversed
//! by obvhs on the CPU and by `traverse.wgsl` on the GPU from the same node array ([`gpu`]).
//!
//! Triangles keep full f32 positions for the GPU and f64 for the CPU's intersection tests:
//! obvhs' compressed triangle stores edges in f16, which would move shadow boundaries, so it is
//! not used. The tree is built in coordinates relative to the triangles' bounding-box centre so
//! its f32 bounds stay precise wherever the mesh is placed.

mod gpu;

use super::{intersect, work, Accelerator, BuildStats, GpuStructure, TriHit};
use crate::geometry::LocalFrame;
use crate::mesh::Triangles;
use glam::{DVec3, Vec3, Vec3A};
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::bvh2::Bvh2;
use obvhs::ray::Ray;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};

/// obvhs build presets, fastest build to best tree. `medium` is obvhs' recommended default;
/// `slow` and `very-slow` add spatial pre-splits of large triangles (duplicated references).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Preset {
    /// One triangle per leaf, no reinsertion.
    Fastest,
    /// Minimal search, light reinsertion.
    VeryFast,
    /// Low search distance.
    Fast,
    /// Medium search distance and reinsertion (obvhs' default).
    #[default]
    Medium,
    /// High search distance, pre-splits.
    Slow,
    /// Full reinsertion, pre-splits.
    VerySlow,
}

impl Preset {
    /// obvhs' build parameters for this preset.
    pub(crate) fn params(self) -> BvhBuildParams {
        match self {
            Preset::Fastest => BvhBuildParams::fastest_build(),
            Preset::VeryFast => BvhBuildParams::very_fast_build(),
            Preset::Fast => BvhBuildParams::fast_build(),
            Preset::Medium => BvhBuildParams::medium_build(),
            Preset::Slow => BvhBuildParams::slow_build(),
            Preset::VerySlow => BvhBuildParams::very_slow_build(),
        }
    }

    /// Name as written in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Fastest => "fastest",
            Preset::VeryFast => "very-fast",
            Preset::Fast => "fast",
            Preset::Medium => "medium",
            Preset::Slow => "slow",
            Preset::VerySlow => "very-slow",
        }
    }

    /// Every preset.
    pub const ALL: [Preset; 6] = [
        Preset::Fastest,
        Preset::VeryFast,
        Preset::Fast,
        Preset::Medium,
        Preset::Slow,
        Preset::VerySlow,
    ];
}

/// The BVH's parameters (`[accel.bvh]`): obvhs' build preset.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BvhSettings {
    /// Build preset.
    pub preset: Preset,
}

impl super::settings::Params for BvhSettings {
    fn check(&self) -> Result<(), (&'static str, String)> {
        Ok(())
    }
}

/// A built BVH with its triangles.
#[derive(Clone)]
pub struct Bvh {
    /// The obvhs tree (node bounds relative to `centre`), as built: what the GPU form packs.
    pub tree: Bvh2,
    /// The same tree with every box widened by a few f32 ulps of the scene's size, for the CPU
    /// walk: the tree bounds f32-rounded triangles and walks an f32-rounded ray, while hits are
    /// tested in f64, so unwidened boxes drop hits at vertices and edges.
    cpu_tree: Bvh2,
    /// Triangles in f32 relative to `centre`, in input order.
    pub local: Vec<Triangle>,
    /// Triangles in f64 world space, in input order.
    pub world: Vec<[DVec3; 3]>,
    /// Origin of the tree's coordinates.
    pub centre: DVec3,
    /// The preset used.
    pub preset: Preset,
    /// Wall-clock build time (the core PLOC build and reinsertion, as obvhs reports it).
    pub build_time: Duration,
    /// Wall-clock time including conversion and pre-splitting.
    pub total_time: Duration,
    /// Longest root-to-leaf path (the GPU traversal's stack holds 64 entries).
    pub depth: usize,
}

/// The BVH's WGSL: `accel_closest` and `accel_any` over its node and triangle buffers.
pub const WGSL: &str = include_str!("traverse.wgsl");

fn depth(tree: &Bvh2) -> usize {
    let mut deepest = 0;
    let mut stack = vec![(0usize, 1usize)];
    while let Some((i, d)) = stack.pop() {
        let Some(n) = tree.nodes.get(i) else { continue };
        deepest = deepest.max(d);
        if n.prim_count == 0 {
            stack.push((n.first_index as usize, d + 1));
            stack.push((n.first_index as usize + 1, d + 1));
        }
    }
    deepest
}

/// The centre of `positions`' bounding box (the origin of the trees' f32 coordinates), or zero
/// for none.
pub(crate) fn centre(positions: &[[DVec3; 3]]) -> DVec3 {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for t in positions.iter().flatten() {
        lo = lo.min(*t);
        hi = hi.max(*t);
    }
    if lo.is_finite() {
        0.5 * (lo + hi)
    } else {
        DVec3::ZERO
    }
}

/// `positions` in f32 relative to `centre`, as obvhs builds and walks them.
pub(crate) fn relative(positions: &[[DVec3; 3]], centre: DVec3) -> Vec<Triangle> {
    let f = |p: DVec3| Vec3A::from((p - centre).as_vec3());
    positions
        .iter()
        .map(|t| Triangle {
            v0: f(t[0]),
            v1: f(t[1]),
            v2: f(t[2]),
        })
        .collect()
}

/// `tree` with every box widened by a few f32 ulps of its root's size (see `Bvh::cpu_tree`).
pub(crate) fn widened(tree: &Bvh2) -> Bvh2 {
    let mut cpu_tree = tree.clone();
    if let Some(root) = tree.nodes.first() {
        let size = root.aabb.min.abs().max(root.aabb.max.abs()).max_element();
        let pad = Vec3A::splat(size * 8.0 * f32::EPSILON);
        for n in &mut cpu_tree.nodes {
            n.aabb.min -= pad;
            n.aabb.max += pad;
        }
    }
    cpu_tree
}

impl Bvh {
    /// Refits the tree to `triangles`, the same triangles in the same order after some moved
    /// (obvhs' `refit_all`): each leaf's box is recomputed from its whole triangles (a
    /// pre-split leaf's box grows back to its triangle's), then every inner box bottom-up. The
    /// topology is kept, so the tree's quality decays the further things move from where it
    /// was built: the cheap update a dynamic scene weighs against a rebuild. Returns the time.
    pub fn refit(&mut self, triangles: &Triangles) -> Duration {
        assert_eq!(
            triangles.positions.len(),
            self.world.len(),
            "a refit keeps the triangles"
        );
        let start = Instant::now();
        self.local = relative(&triangles.positions, self.centre);
        self.world.clone_from(&triangles.positions);
        let tree = &mut self.tree;
        for i in 0..tree.nodes.len() {
            let n = tree.nodes[i];
            if n.is_leaf() {
                let first = n.first_index as usize;
                let prims = &tree.primitive_indices[first..first + n.prim_count as usize];
                let aabb = prims.iter().fold(obvhs::aabb::Aabb::empty(), |a, &p| {
                    a.union(&self.local[p as usize].aabb())
                });
                tree.nodes[i].set_aabb(aabb);
            }
        }
        tree.refit_all();
        self.cpu_tree = widened(&self.tree);
        start.elapsed()
    }

    /// Builds the tree over `triangles` with `preset`.
    pub fn build(triangles: &Triangles, preset: Preset) -> Bvh {
        let start = Instant::now();
        let centre = centre(&triangles.positions);
        let local = relative(&triangles.positions, centre);
        let mut build_time = Duration::default();
        let tree = build_bvh2_from_tris(&local, preset.params(), &mut build_time);
        let depth = depth(&tree);
        let cpu_tree = widened(&tree);
        Bvh {
            depth,
            tree,
            cpu_tree,
            local,
            world: triangles.positions.clone(),
            centre,
            preset,
            build_time,
            total_time: start.elapsed(),
        }
    }

    /// The f32 ray the CPU walk follows, and its parameter shift `s`, or None when the segment
    /// misses the (widened) root box. A ray from outside the box starts just before it enters,
    /// so that rounding its origin to f32 moves it by ulps of the scene's size rather than of
    /// its distance, which the boxes' widening covers. Its far end is widened too: node culling
    /// must never drop a hit the f64 test would find.
    fn ray(&self, origin: DVec3, dir: DVec3, tmax: f64) -> Option<(Ray, f64)> {
        let root = self.cpu_tree.nodes.first()?;
        let lo = Vec3::from(root.aabb.min).as_dvec3() + self.centre;
        let hi = Vec3::from(root.aabb.max).as_dvec3() + self.centre;
        let (a, b) = ((lo - origin) / dir, (hi - origin) / dir);
        let enter = a.min(b).max_element();
        let exit = a.max(b).min_element();
        let margin = (hi - lo).max_element() * 1e-3;
        // An origin on a slab plane of a ray parallel to it gives NaN: walk such rays unshifted.
        let defined = !(enter.is_nan() || exit.is_nan());
        if defined && (exit < 0.0 || enter > exit + margin || enter > tmax + margin) {
            return None;
        }
        let s = if defined && enter.is_finite() {
            (enter - margin).max(0.0)
        } else {
            0.0
        };
        let ray = Ray::new(
            Vec3A::from((origin + dir * s - self.centre).as_vec3()),
            Vec3A::from(dir.as_vec3()),
            0.0,
            ((tmax - s) * (1.0 + 1e-6) + margin) as f32,
        );
        Some((ray, s))
    }

    /// Walks the CPU tree along `ray`, near child first, calling `test(slot)` for each
    /// primitive slot of every leaf the ray's current segment meets: `Some(t)` shortens the
    /// segment to `t`, `Some(NEG_INFINITY)` ends the walk. Counts the nodes it examines (an
    /// inner node whose children's boxes it tests, a leaf whose triangles it tests; none when
    /// the root's box is missed) and the primitive tests ([`crate::accel::work`]).
    #[inline]
    fn walk(&self, mut ray: Ray, mut test: impl FnMut(usize) -> Option<f32>) {
        let nodes = &self.cpu_tree.nodes;
        let (mut visited, mut prims) = (0u64, 0u64);
        let mut leaf = |node: &obvhs::bvh2::node::Bvh2Node, ray: &mut Ray, prims: &mut u64| -> bool {
            for slot in node.first_index..node.first_index + node.prim_count {
                *prims += 1;
                if let Some(t) = test(slot as usize) {
                    if t == f32::NEG_INFINITY {
                        return false;
                    }
                    ray.tmax = ray.tmax.min(t);
                }
            }
            true
        };
        let root = &nodes[0];
        if root.aabb().intersect_ray(&ray) >= ray.tmax {
            return;
        }
        if root.is_leaf() {
            leaf(root, &mut ray, &mut prims);
            work::add(1, prims);
            return;
        }
        let mut small = [0u32; 128];
        let mut large = Vec::new();
        let stack: &mut [u32] = if self.depth < small.len() {
            &mut small
        } else {
            large.resize(self.depth + 1, 0);
            &mut large
        };
        let mut top = 0;
        let mut current = root.first_index as usize;
        loop {
            let (mut near, mut far) = (&nodes[current], &nodes[current + 1]);
            let (mut tn, mut tf) = (near.aabb().intersect_ray(&ray), far.aabb().intersect_ray(&ray));
            visited += 1;
            if tn > tf {
                std::mem::swap(&mut tn, &mut tf);
                std::mem::swap(&mut near, &mut far);
            }
            let mut next = [None, None];
            for (slot, (node, t)) in [(near, tn), (far, tf)].into_iter().enumerate() {
                if t >= ray.tmax {
                    continue;
                }
                if node.is_leaf() {
                    visited += 1;
                    if !leaf(node, &mut ray, &mut prims) {
                        work::add(visited, prims);
                        return;
                    }
                } else {
                    next[slot] = Some(node.first_index as usize);
                }
            }
            current = match next {
                [Some(a), Some(b)] => {
                    stack[top] = b as u32;
                    top += 1;
                    a
                }
                [Some(a), None] | [None, Some(a)] => a,
                [None, None] => {
                    if top == 0 {
                        work::add(visited, prims);
                        return;
                    }
                    top -= 1;
                    stack[top] as usize
                }
            };
        }
    }

    /// Closest triangle hit with 0 < t < `tmax` along unit `dir`, skipping triangle `skip`.
    pub fn closest(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> Option<TriHit> {
        if self.world.is_empty() {
            return None;
        }
        let mut best: Option<TriHit> = None;
        let (ray, s) = self.ray(origin, dir, tmax)?;
        self.walk(ray, |i| {
            let tri = self.cpu_tree.primitive_indices[i];
            match intersect(origin, dir, &self.world[tri as usize]) {
                Some(t) if tri != skip && t > 0.0 && t < tmax && best.is_none_or(|b| t < b.t) => {
                    best = Some(TriHit { t, triangle: tri });
                    // The walk's new far end, in its shifted parameter, rounded outwards.
                    Some(((t - s) + (t - s).abs() * 1e-6 + 1e-30) as f32)
                }
                _ => None,
            }
        });
        best
    }

    /// Whether any triangle other than `skip` is hit with 0 < t < `tmax`; stops at the first.
    pub fn any_hit(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> bool {
        if self.world.is_empty() {
            return false;
        }
        let Some((ray, _)) = self.ray(origin, dir, tmax) else {
            return false;
        };
        let mut hit = false;
        self.walk(ray, |i| {
            let tri = self.cpu_tree.primitive_indices[i];
            match intersect(origin, dir, &self.world[tri as usize]) {
                Some(t) if tri != skip && t > 0.0 && t < tmax => {
                    hit = true;
                    Some(f32::NEG_INFINITY)
                }
                _ => None,
            }
        });
        hit
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.tree.nodes.len()
    }

    /// Bytes of the GPU form: 32-byte nodes and 48-byte full-f32 triangles in leaf order.
    pub fn gpu_bytes(&self) -> u64 {
        (self.node_count() * std::mem::size_of::<gpu::GpuNode>()
            + self.tree.primitive_indices.len() * std::mem::size_of::<super::GpuTri>()) as u64
    }
}

impl Accelerator for Bvh {
    fn name(&self) -> &'static str {
        "bvh"
    }

    fn closest(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> Option<TriHit> {
        Bvh::closest(self, origin, dir, tmax, skip)
    }

    fn any_hit(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> bool {
        Bvh::any_hit(self, origin, dir, tmax, skip)
    }

    fn stats(&self) -> BuildStats {
        let bytes = self.gpu_bytes();
        BuildStats {
            parameters: self.preset.name().to_string(),
            build_time: self.total_time,
            gpu_bytes: bytes,
            memory_bytes: (std::mem::size_of_val(self.tree.nodes.as_slice()) + 4 * self.tree.primitive_indices.len()) as u64,
            triangles: self.world.len(),
            description: format!(
                "BVH2 (obvhs, preset `{}`): {} nodes, depth {}, built in {:.1} ms ({:.1} ms core); {:.1} GPU bytes per triangle (32-byte nodes, 48-byte full-f32 triangles)",
                self.preset.name(),
                self.node_count(),
                self.depth,
                self.total_time.as_secs_f64() * 1e3,
                self.build_time.as_secs_f64() * 1e3,
                bytes as f64 / self.world.len() as f64
            ),
        }
    }

    fn gpu(&self, frame: &LocalFrame) -> anyhow::Result<GpuStructure> {
        gpu::structure(self, frame)
    }

    fn gpu_refusal(&self) -> Option<String> {
        gpu::too_deep(self.depth)
    }

    fn update(
        &mut self,
        method: super::UpdateMethod,
        moved: &Triangles,
        _object: u32,
        _step: DVec3,
    ) -> anyhow::Result<super::Updated> {
        use super::UpdateMethod::*;
        Ok(match method {
            Refit => {
                self.refit(moved);
                super::Updated::Refit
            }
            Rebuild => {
                *self = Bvh::build(moved, self.preset);
                super::Updated::Rebuilt
            }
            RebuildFastest => {
                *self = Bvh::build(moved, Preset::Fastest);
                super::Updated::Rebuilt
            }
            m => return Err(super::unknown_update(self, m)),
        })
    }
}

impl std::fmt::Debug for Bvh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Bvh({} triangles, {} nodes, {})",
            self.world.len(),
            self.node_count(),
            self.preset.name()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::brute_force;

    /// A closed box of 12 triangles with a pyramid on top, plus triangles with a corner at the
    /// origin and edges on the axes (the cases obvhs' own comment flags as leaky).
    fn triangles() -> Triangles {
        let c = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let mut positions = Vec::new();
        let quads = [
            [c(0., 0., 0.), c(1., 0., 0.), c(1., 1., 0.), c(0., 1., 0.)],
            [c(0., 0., 1.), c(1., 0., 1.), c(1., 1., 1.), c(0., 1., 1.)],
            [c(0., 0., 0.), c(1., 0., 0.), c(1., 0., 1.), c(0., 0., 1.)],
            [c(0., 1., 0.), c(1., 1., 0.), c(1., 1., 1.), c(0., 1., 1.)],
            [c(0., 0., 0.), c(0., 1., 0.), c(0., 1., 1.), c(0., 0., 1.)],
            [c(1., 0., 0.), c(1., 1., 0.), c(1., 1., 1.), c(1., 0., 1.)],
        ];
        for q in quads {
            positions.push([q[0], q[1], q[2]]);
            positions.push([q[0], q[2], q[3]]);
        }
        positions.push([c(0., 0., 1.), c(1., 0., 1.), c(0.5, 0.5, 2.)]);
        let n = positions.len();
        Triangles {
            positions,
            object_of: vec![0; n],
        }
    }

    /// Every preset agrees with brute force on seeded random rays (same triangle, same t).
    #[test]
    fn every_preset_matches_brute_force() {
        let tris = triangles();
        for preset in Preset::ALL {
            let bvh = Bvh::build(&tris, preset);
            let mut rng = 0x1234_5678u32;
            let mut next = || {
                rng = crate::sampling::rng::pcg(rng);
                crate::sampling::rng::to_unit(rng)
            };
            for _ in 0..4000 {
                let o = DVec3::new(next() * 6.0 - 3.0, next() * 6.0 - 3.0, next() * 6.0 - 2.0);
                let target = DVec3::new(next() * 1.4 - 0.2, next() * 1.4 - 0.2, next() * 2.4 - 0.2);
                let d = (target - o).normalize();
                let (a, b) = (bvh.closest(o, d, f64::INFINITY, u32::MAX), brute_force(&tris, o, d));
                assert_eq!(a.map(|h| h.triangle), b.map(|h| h.triangle), "{preset:?} o={o} d={d}");
                if let (Some(a), Some(b)) = (a, b) {
                    assert!((a.t - b.t).abs() < 1e-12);
                }
                assert_eq!(bvh.any_hit(o, d, f64::INFINITY, u32::MAX), b.is_some());
            }
        }
    }

    #[test]
    fn skip_and_tmax_are_honoured() {
        let bvh = Bvh::build(&triangles(), Preset::Medium);
        let (o, d) = (DVec3::new(0.3, 0.4, -1.0), DVec3::Z);
        let first = bvh.closest(o, d, f64::INFINITY, u32::MAX).unwrap();
        assert!((first.t - 1.0).abs() < 1e-12);
        let second = bvh.closest(o, d, f64::INFINITY, first.triangle).unwrap();
        assert!((second.t - 2.0).abs() < 1e-12);
        assert!(!bvh.any_hit(o, d, 0.999, u32::MAX));
        assert!(bvh.any_hit(o, d, 1.001, u32::MAX));
    }
}
